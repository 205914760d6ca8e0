# SPDX-License-Identifier: Apache-2.0
"""
Calibration on data as it really comes: bad rows, several effects, forms not in a list.

Each table comes from the model with the effects injected (seeded noise); each
test would fail if its feature broke: the outlier would decide the answer, the
second effect would be missed, the exponent or the threshold would be wrong.
"""

from dataclasses import replace

import numpy as np
import pytest

from satmotor_ros.identify import calibrate, loss_parts, LossFit, Options
from satmotor_ros.identify.effects import CalibratedModel
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.report import write_report
from satmotor_ros.identify.synthetic import generate, Injection, Plan, with_outliers
from satmotor_ros.model import MotorModel
from satmotor_ros.model.effects import effect_from_mapping
from satmotor_ros.model.motor import with_effects
from satmotor_ros.model.units import LPM, MPA, RPM


def _effects(cal):
    return [e['effect'] for e in cal.summary()['effects']]


@pytest.mark.parametrize(('liquid', 'effect', 'scale'), [
    ('water', 'external_leakage', 1.0), ('oil', 'viscosity_temperature', 1.0),
    ('water', 'clearance_wear', 1.0), ('oil', 'channel:aux', 1.0),
    ('water', 'flow_sensor_offset', 2.0)])
@pytest.mark.parametrize('size', [1.5, -1.5])
def test_one_bad_row_in_a_short_table_hides_no_effect_and_is_listed(liquid, effect, scale,
                                                                    size):
    table = generate(Plan(liquid=liquid, n_points=26),
                     Injection.realistic(effect, scale, liquid), seed=3)
    cal = calibrate(with_outliers(table, [7], [size]), liquid)
    assert _effects(cal)[:1] == [effect], cal.selection.verdict
    outliers = cal.summary()['outliers']
    assert [o['row'] for o in outliers] == [7]
    assert outliers[0]['residual_lpm'] == pytest.approx(size, abs=0.2)


@pytest.mark.parametrize('seed', [0, 1])
def test_clean_table_with_a_bad_row_says_none(seed):
    table = with_outliers(generate(Plan(liquid='oil', n_points=30), Injection(), seed=seed),
                          [11], [2.0])
    cal = calibrate(table, 'oil')
    assert cal.summary()['effect'] == 'none', cal.selection.verdict
    assert [o['row'] for o in cal.summary()['outliers']] == [11]


@pytest.mark.parametrize('plan', [
    Plan(liquid='oil', noise_flow_rel=0.004),  # noise grows with the flow (8x at the top)
    Plan(liquid='water', noise_flow_lpm=0.08),  # four times the usual noise
    Plan(liquid='oil', n_points=24, temperature_c=(30.0, 60.0)),  # temperature drifts, no effect
], ids=['heteroscedastic', 'noisy', 'drift'])
@pytest.mark.parametrize('seed', [0, 1])
def test_clean_data_with_nuisances_says_none(plan, seed):
    cal = calibrate(generate(plan, Injection(), seed=seed), plan.liquid)
    assert cal.summary()['effect'] == 'none', cal.selection.verdict
    assert cal.summary()['effects'] == []


def test_heteroscedastic_noise_is_modelled():
    plan = Plan(liquid='oil', noise_flow_rel=0.004)
    cal = calibrate(generate(plan, Injection(), seed=2), 'oil')
    sigma = cal.forward.sigma
    truth = plan.noise_lpm(cal.parts.flow, cal.model) * LPM
    top, low = np.argmax(cal.parts.flow), np.argmin(cal.parts.flow)
    assert sigma[top] / sigma[low] > 0.5 * truth[top] / truth[low] > 1.5


PAIRS = [
    ('water', Injection.realistic('external_leakage', 1.0, 'water'),
     Injection.realistic('viscosity_temperature', 1.0, 'water')),
    ('oil', Injection.realistic('clearance_wear', 1.0, 'oil'),
     Injection.realistic('channel:aux', 1.5, 'oil')),
    ('oil', Injection.realistic('external_leakage', 1.0, 'oil'),
     Injection('term:dp^0.76', 0.8 * LPM)),
]


@pytest.mark.slow
@pytest.mark.parametrize(('liquid', 'first', 'second'), PAIRS,
                         ids=[f'{a.effect}+{b.effect}' for _, a, b in PAIRS])
def test_two_effects_are_found_one_after_the_other(tmp_path, liquid, first, second):
    plan = Plan(liquid=liquid)
    table = generate(plan, (first, second), seed=7)
    # the effect search within eqs. (31)-(33): pinned, since a family whose baseline bends
    # with dp (paszota's) absorbs part of an unmodelled dp^0.76 term before any effect is tried
    cal = calibrate(table, liquid, options=Options(compare_families=False))
    summary = write_json(cal, tmp_path / 'calibration.json')
    found = _effects(cal)
    assert len(found) == 2, [s.verdict for s in cal.forward.steps]
    for truth in (first, second):
        kind = truth.effect.partition(':')[0]
        assert any(f.partition(':')[0] == kind for f in found), found
    assert summary['effect'] == found[0]  # the top level is the first effect
    steps = [e['error_after']['rmse_lpm'] for e in summary['effects']]
    noise = float(np.sqrt(np.mean(plan.noise_lpm(table.flow, cal.model) ** 2)))
    assert summary['error_before']['rmse_lpm'] > steps[0] > steps[1]
    assert summary['error_after']['rmse_lpm'] == steps[1] < 1.5 * noise
    # coefficients.yaml holds both, and the model evaluates them together
    write_yaml(cal, tmp_path / 'coefficients.yaml')
    calibrated = CalibratedModel.load(tmp_path / 'coefficients.yaml', liquid)
    assert len(calibrated.model.effects) == 2
    channels = {**table.channels, 'p_out': table.p_out}
    predicted, _ = calibrated.measured_flow(table.speed, channels, dp=table.dp)
    assert np.sqrt(np.mean((table.flow - predicted) ** 2)) / LPM < 1.5 * noise
    report = write_report(cal, tmp_path, summary).read_text()
    assert report.count('`+ ') == 0 and '+ `' in report  # the error after each step


FORMS = [('oil', 'term:dp^0.76', 1.0), ('oil', 'term:dp^3*n', 1.0),
         ('water', 'term:dp^1.5*n^2', 1.0)]


@pytest.mark.parametrize(('liquid', 'effect', 'size'), FORMS, ids=[f for _, f, _ in FORMS])
def test_a_power_term_is_found_with_its_exponents(liquid, effect, size):
    cal = calibrate(generate(Plan(liquid=liquid), Injection(effect, size * LPM), seed=5), liquid)
    row = cal.summary()['effects'][0]
    assert row['effect'].startswith('term:'), cal.selection.verdict
    truth = dict(zip(('dp', 'n'), (0.0, 0.0)))
    for factor in effect.partition(':')[2].split('*'):
        name, _, power = factor.partition('^')
        truth[name] = float(power or 1.0)
    for name, value in truth.items():
        if value:
            low, high = row['exponents_ci95'][name]
            assert low <= value <= high, row
        else:
            assert row['exponents'][name] == 0.0
    assert row['expression'] == row['effect'].partition(':')[2]


def test_a_physical_speed_loss_is_not_blamed_on_a_sensor_alone():
    """A loss ~ n^0.7 and a gain error look alike: the report names both, or the term."""
    cal = calibrate(generate(Plan(liquid='oil'), Injection('term:n^0.7', 1.0 * LPM), seed=3),
                    'oil')
    first = cal.summary()['effect']
    if not first.startswith('term:'):
        verdict = cal.selection.verdict
        assert 'term:n^0.' in verdict and 'explain the data equally well' in verdict


def test_a_valve_cracking_at_18_mpa_is_found_with_its_threshold():
    injection = Injection('threshold:dp', 2.0 * LPM, shape=(('reference', 18 * MPA),))
    cal = calibrate(generate(Plan(liquid='oil'), injection, seed=2), 'oil')
    row = cal.summary()['effects'][0]
    assert row['effect'] == 'threshold:dp', cal.selection.verdict
    low, high = row['threshold']['ci95']
    assert low - 0.3 * MPA <= 18 * MPA <= high + 0.3 * MPA
    assert row['threshold']['unit'] == 'Pa' and row['exponent'] == pytest.approx(1.0, abs=0.3)
    assert cal.error_before.rmse_lpm > 10 * cal.error_after.rmse_lpm


def test_the_report_names_the_pairs_the_data_cannot_separate(tmp_path):
    """Speed and pressure rose together: the leakage and the speed terms trade off."""
    plan = Plan(liquid='oil', n_points=40)
    table = generate(plan, Injection(), seed=4)
    order = np.argsort(table.speed)
    dp = np.sort(table.dp)  # the highest drop at the highest speed
    table = replace(table, p_in=table.p_out[order] + dp, p_out=table.p_out[order],
                    speed=table.speed[order], flow=table.flow)
    model = MotorModel.default('oil')
    table = replace(table, flow=model.absorbency(table.speed, dp=table.dp).flow)
    cal = calibrate(table, 'oil', options=Options(mode='points'))
    corr = cal.final.correlation
    assert np.max(np.abs(corr - np.eye(len(corr)))) > 0.95
    report = write_report(cal, tmp_path, write_json(cal, tmp_path / 'c.json')).read_text()
    assert 'The data cannot separate these pairs' in report


def test_several_fitted_forms_compose_in_the_model_and_the_plant():
    from satmotor_ros.plant import ConstantLoad, Plant, PlantParams
    term = effect_from_mapping('term:dp^0.76', {'coefficient': 1e-9,
                                                'exponents': {'dp': 0.76, 'n': 0.0}}, 'e')
    valve = effect_from_mapping('threshold:dp', {'coefficient': 2e-12, 'reference': 18e6,
                                                 'exponent': 1.0}, 'e')
    leak = effect_from_mapping('external_leakage', {'coefficient': 5e-12}, 'e')
    base = MotorModel.default('oil')
    both = with_effects(base, (term, valve, leak))
    n, dp = np.array([500.0, 500.0]) * RPM, np.array([10.0, 22.0]) * MPA
    plain = base.absorbency(n, dp=dp).flow
    flow = both.absorbency(n, dp=dp, channels={'p_case': np.full(2, 0.3e6)}).flow
    extra = flow - plain
    assert np.all(extra > 0.0)
    assert extra[1] - extra[0] > 2e-12 * 3.9e6  # the valve opened above 18 MPa only
    point = both.absorbency(float(n[1]), dp=float(dp[1]), channels={'p_case': 0.3e6})
    assert np.ravel(point.flow)[0] == pytest.approx(flow[1], rel=1e-6)
    # the virtual motor injects them (the bench's truth) and settles where the model says
    plant = Plant(base, PlantParams(effects=(term, valve)), ConstantLoad(60.0))
    plant.run(3000, 20 * LPM)
    for _ in range(40):
        before = plant.state
        plant.run(500, 20 * LPM)
        if all(abs(a - b) <= 1e-10 * abs(b) for a, b in zip(plant.state[1:4], before[1:4])):
            break
    state = plant.state
    expected = with_effects(base, (term, valve)).speed_point(
        20 * LPM, state.inlet_pressure - state.outlet_pressure)
    assert state.speed == pytest.approx(expected.speed, rel=1e-6)


def test_nuisance_regressors_are_fitted_without_being_effects():
    table = generate(Plan(liquid='oil'), Injection(), seed=1)
    parts, _ = loss_parts(MotorModel.default('oil'), table)
    x = np.random.default_rng(0).normal(0.0, 1.0, len(parts))
    spoiled = replace(parts, flow=parts.flow + 0.3 * LPM * x).with_nuisance({'dpdt': x})
    fit = LossFit(sigma=0.03 * LPM).fit(spoiled)
    report = fit.report()
    assert report.names[-1] == 'nuisance:dpdt'
    low, high = report.ci95[-1]
    assert low <= 0.3 * LPM <= high
    with pytest.raises(Exception, match='nuisance regressor'):
        parts.with_nuisance({'bad': np.ones(3)})
