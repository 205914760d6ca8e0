# SPDX-License-Identifier: Apache-2.0
"""Calibrated effects used outside the data they were fitted on are flagged EXTRAPOLATED (#14)."""

import copy
import json

from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from satmotor_ros.cli import validate as validate_cli
from satmotor_ros.identify import calibrate, write_csv
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.synthetic import generate, Injection, Plan, to_columns
from satmotor_ros.identify.validate import validate
from satmotor_ros.model import ConfigError, load_motor, MotorModel, PointStatus
from satmotor_ros.model.effects import Effect, effect_to_mapping
from satmotor_ros.model.engine.screening import FITTED_TOLERANCE
from satmotor_ros.model.io.config import default_config_path, motor_from_mapping
from satmotor_ros.model.motor import with_effects
from satmotor_ros.model.units import CM3_PER_REV, LPM, MPA, RPM
from satmotor_ros.options import MotorOptions
import yaml

EXTRAPOLATED = int(PointStatus.EXTRAPOLATED)
BASE = yaml.safe_load(default_config_path().read_text(encoding='utf-8'))
DP_I = (4 * MPA, 12 * MPA)  # the term's fitted chamber drops
SPEED = (20.0, 120.0)  # and speeds [rad/s]
P_CASE = (1e5, 3e5)  # the leakage's fitted case pressures [Pa]
TERM = Effect('term:dp^2*n', 2e-25, 'dp*n', options=(('dp', 2.0), ('n', 1.0)))
LEAK = Effect('external_leakage', 2e-12, 'p_case')
RANGES = {TERM.name: (('dp_i', *DP_I), ('speed', *SPEED)), LEAK.name: (('p_case', *P_CASE),)}


def _models(liquid='oil', effects=(TERM, LEAK)):
    """Return the model with the effects as hand-written (no range) and as calibrated (ranged)."""
    base = MotorModel.default(liquid)
    ranged = [Effect(**{**e.__dict__, 'fitted_range': RANGES[e.name]}) for e in effects]
    return with_effects(base, effects), with_effects(base, ranged)


PLAIN, RANGED = _models()


def _outside(value, low, high):
    slack = FITTED_TOLERANCE * (high - low)
    return not low - slack <= value <= high + slack


def _expected(point, p_case):
    """Return the flag the fitted ranges add at a computed point, independently of the model."""
    outside = (_outside(abs(point.dp_i), *DP_I) or _outside(abs(point.speed), *SPEED)
               or _outside(p_case, *P_CASE))
    return EXTRAPOLATED if outside else 0


points = given(flow=st.floats(0.5, 60.0), dp=st.floats(0.0, 24.0), p_case=st.floats(0.0, 6e5),
               sign=st.sampled_from([1.0, -1.0]))


@settings(max_examples=60, deadline=None)
@points
def test_the_ranges_add_extrapolated_exactly_outside_them_on_the_speed_map(flow, dp, p_case,
                                                                           sign):
    channels = {'p_case': p_case}
    plain = PLAIN.speed_point(sign * flow * LPM, dp_i=sign * dp * MPA, channels=channels)
    ranged = RANGED.speed_point(sign * flow * LPM, dp_i=sign * dp * MPA, channels=channels)
    assert ranged.speed == plain.speed or (np.isnan(ranged.speed) and np.isnan(plain.speed))
    if plain.status & int(PointStatus.NOT_FINITE | PointStatus.BEYOND_LIMIT
                          | PointStatus.NO_ROOT | PointStatus.NOT_CONVERGED):
        assert ranged.status == plain.status
    else:
        assert ranged.status == plain.status | _expected(plain, p_case)


@settings(max_examples=40, deadline=None)
@points
def test_the_ranges_add_extrapolated_exactly_outside_them_on_the_forward_map(flow, dp, p_case,
                                                                             sign):
    speed = sign * flow * 5.0  # up to 300 rad/s, beyond the fitted 120
    plain = PLAIN.absorbency_point(speed, dp=sign * dp * MPA, channels={'p_case': p_case})
    ranged = RANGED.absorbency_point(speed, dp=sign * dp * MPA, channels={'p_case': p_case})
    assert ranged.flow == plain.flow or (np.isnan(ranged.flow) and np.isnan(plain.flow))
    if not np.isnan(plain.flow):
        assert ranged.status == plain.status | _expected(plain, p_case)


@settings(max_examples=25, deadline=None)
@given(flow=st.lists(st.floats(0.5, 60.0), min_size=1, max_size=8),
       dp=st.floats(0.0, 24.0), p_case=st.floats(0.0, 6e5), sign=st.sampled_from([1.0, -1.0]))
def test_the_point_and_array_paths_flag_the_same_points(flow, dp, p_case, sign):
    q = sign * np.array(flow) * LPM
    channels = {'p_case': np.full(q.shape, p_case)}
    for model in (PLAIN, RANGED):
        array = model.speed(q, dp=sign * dp * MPA, channels=channels, errors='mask')
        single = [model.speed_point(float(x), dp=sign * dp * MPA, channels={'p_case': p_case})
                  for x in q]
        assert array.status.tolist() == [p.status for p in single]
        forward = model.absorbency(q * 1e4, dp_i=sign * dp * MPA, channels=channels,
                                   errors='mask')
        single = [model.absorbency_point(float(x) * 1e4, dp_i=sign * dp * MPA,
                                         channels={'p_case': p_case}) for x in q]
        assert forward.status.tolist() == [p.status for p in single]


def test_inside_every_range_the_status_is_that_of_the_hand_written_file():
    at = {'dp_i': 8 * MPA, 'channels': {'p_case': 2e5}}
    inside = RANGED.speed_point(12 * LPM, **at)
    assert 20.0 < inside.speed < 120.0 and inside.status == 0
    assert RANGED.speed_point(12 * LPM, dp_i=20 * MPA, channels={'p_case': 2e5}).status \
        == EXTRAPOLATED  # 20 MPa: inside the validated 2-25 MPa, beyond the term's data
    assert RANGED.speed_point(12 * LPM, dp_i=8 * MPA, channels={'p_case': 9e5}).status \
        == EXTRAPOLATED  # three times the fitted case pressure
    for p_case in (9e5, 0.0):
        assert PLAIN.speed_point(12 * LPM, dp_i=8 * MPA, channels={'p_case': p_case}).status == 0


def test_a_backwards_only_effect_is_checked_only_backwards():
    reverse = Effect('reverse_loss', 1e-15, fitted_range=(('dp_i', *DP_I), ('speed', *SPEED)))
    model = with_effects(MotorModel.default('oil'), [reverse])
    assert model.speed_point(12 * LPM, dp_i=20 * MPA).status == 0  # forward: not evaluated
    assert model.speed_point(-12 * LPM, dp_i=-20 * MPA).status == EXTRAPOLATED
    assert model.speed_point(-12 * LPM, dp_i=-8 * MPA).status == 0


def test_a_sensor_effect_is_checked_on_its_channel():
    gain = Effect('flow_sensor_gain', 0.01, 'flow',
                  fitted_range=(('flow', 5 * LPM, 20 * LPM),))
    model = with_effects(MotorModel.default('oil'), [gain])
    assert model.speed_point(12 * LPM, dp_i=8 * MPA).status == 0
    assert model.speed_point(40 * LPM, dp_i=8 * MPA).status == EXTRAPOLATED


# -- the file ----------------------------------------------------------------------------------

def _doc(effects):
    doc = copy.deepcopy(BASE)
    doc['coefficient_sets']['oil']['effects'] = effects
    doc['coefficient_sets']['oil']['coefficients']['external_leakage'] = LEAK.coefficient
    return doc


def _block(**fitted_range):
    block = effect_to_mapping(TERM)
    block['fitted_range'] = fitted_range
    return {TERM.name: block}


def test_the_ranges_round_trip_through_the_yaml():
    effects = {e.name: effect_to_mapping(e) for e in RANGED.effects}
    spec = motor_from_mapping(_doc(effects))
    assert spec.sets['oil'].effects == RANGED.effects
    assert {e.name: e.fitted_range for e in MotorModel.default('oil').effects} == {}


@pytest.mark.parametrize('fitted_range, says', [
    ({'dp_i': [1e6, 2e6]}, 'fitted_range has no range for speed'),
    ({'dp_i': [1e6, 2e6], 'speed': [1, 2], 'p_case': [0, 1]}, 'unknown quantity p_case'),
    ({'dp_i': [2e6, 1e6], 'speed': [1, 2]}, 'fitted_range.dp_i = [2000000.0, 1000000.0]'),
    ({'dp_i': [1e6, float('nan')], 'speed': [1, 2]}, 'fitted_range.dp_i'),
    ({'dp_i': [1e6], 'speed': [1, 2]}, 'fitted_range.dp_i'),
    ({'dp_i': '1-2 MPa', 'speed': [1, 2]}, 'fitted_range.dp_i'),
    ({'dp_i': [True, 2e6], 'speed': [1, 2]}, 'fitted_range.dp_i'),
])
def test_the_loader_refuses_a_bad_range_naming_the_field(fitted_range, says):
    with pytest.raises(ConfigError) as err:
        motor_from_mapping(_doc(_block(**fitted_range)))
    assert says in str(err.value) and 'term:dp^2*n' in str(err.value)
    assert '\n' not in str(err.value)


def test_the_loader_refuses_a_range_that_is_not_a_mapping():
    doc = _doc({TERM.name: {**effect_to_mapping(TERM), 'fitted_range': [1, 2]}})
    with pytest.raises(ConfigError, match=r'effects\.term:dp\^2\*n\.fitted_range must be a'):
        motor_from_mapping(doc)


# -- calibrate, load, evaluate, validate -------------------------------------------------------

@pytest.fixture(scope='module')
def calibration(tmp_path_factory):
    """Calibrate on case pressures of 0.05-0.3 MPa: coefficients.yaml, calibration.json."""
    tmp = tmp_path_factory.mktemp('fitted')
    injection = Injection.realistic('external_leakage', 1.0, 'water')
    plan = Plan(liquid='water', n_points=60, p_case_mpa=(0.05, 0.3))
    cal = calibrate(generate(plan, injection, seed=4), 'water')
    write_yaml(cal, tmp / 'coefficients.yaml')
    summary = write_json(cal, tmp / 'calibration.json')
    return cal, tmp / 'coefficients.yaml', summary, injection


def test_calibrate_writes_the_range_of_the_data_each_effect_was_fitted_on(calibration):
    cal, path, summary, _ = calibration
    p_case = cal.table.channels['p_case'][cal.inliers]
    (effect,) = load_motor(path).sets['water'].effects
    assert effect.name == 'external_leakage'
    assert effect.fitted_range == (('p_case', float(p_case.min()), float(p_case.max())),)
    assert 0.04 * MPA < p_case.min() and p_case.max() < 0.31 * MPA
    row = summary['effects'][0]
    assert row['fitted_range']['p_case'] == pytest.approx([p_case.min(), p_case.max()], 1e-4)
    assert 'fitted_range' in path.read_text() and json.dumps(summary)


def test_a_calibrated_file_flags_its_effect_beyond_the_fitted_data(calibration):
    _, path, _, _ = calibration
    model = MotorModel.from_spec(load_motor(path), 'water')
    inside = model.speed_point(20 * LPM, dp=10 * MPA, channels={'p_case': 0.2 * MPA})
    outside = model.speed_point(20 * LPM, dp=10 * MPA, channels={'p_case': 0.9 * MPA})
    assert inside.status == 0 and outside.status == EXTRAPOLATED
    array = model.speed(np.full(2, 20 * LPM), dp=10 * MPA,
                        channels={'p_case': np.array([0.2, 0.9]) * MPA})
    assert array.status.tolist() == [0, EXTRAPOLATED]


def test_validate_counts_the_points_beyond_the_fitted_data(calibration):
    _, path, _, injection = calibration
    model = MotorModel.from_spec(load_motor(path), 'water')
    same = validate(generate(Plan(liquid='water', n_points=60, p_case_mpa=(0.05, 0.3)),
                             injection, seed=5), model, 'water').summary()
    wider = validate(generate(Plan(liquid='water', n_points=60, p_case_mpa=(0.05, 0.9)),
                              injection, seed=5), model, 'water')
    summary = wider.summary()
    p_case = wider.table.channels['p_case']
    beyond = int((p_case > (0.3 + FITTED_TOLERANCE * 0.25) * MPA).sum())
    assert summary['n_extrapolated'] >= beyond > 20
    assert summary['n_extrapolated'] > same['n_extrapolated'] + 20
    assert summary['n_flagged'] == summary['n_invalid'] + summary['n_extrapolated']
    assert any('flagged EXTRAPOLATED' in note for note in wider.table.notes)


def test_the_validate_summary_line_and_report_say_how_many_points_are_extrapolated(
        calibration, tmp_path, capsys):
    _, path, _, injection = calibration
    table = generate(Plan(liquid='water', n_points=60, p_case_mpa=(0.05, 0.9)), injection,
                     seed=6)
    write_csv(tmp_path / 'today.csv', to_columns(table))
    out = tmp_path / 'val'
    code = validate_cli.command(str(tmp_path / 'today.csv'), str(out), 'auto',
                                MotorOptions('water', str(path)))
    line = capsys.readouterr().out
    summary = json.loads((out / 'validation.json').read_text())
    assert code == 0 and summary['n_extrapolated'] > 20
    assert f'over {summary["n_points"]} points ({summary["n_extrapolated"]} flagged ' \
           'EXTRAPOLATED)' in line
    assert f'{summary["n_extrapolated"]} points flagged EXTRAPOLATED' \
        in (out / 'report.md').read_text()


# -- a motor known by its displacement alone ---------------------------------------------------

def test_a_displacement_motor_scales_the_measured_speeds_and_keeps_the_drops():
    packaged = load_motor().valid_range
    for q, family in ((4.92 * CM3_PER_REV, 'paszota'), (300 * CM3_PER_REV, 'sliwinski2017')):
        model = MotorModel.for_displacement(q, family)
        scale = (q / load_motor().geometry.displacement) ** (1 / 3)
        r = model.valid_range
        assert (r.dp_min, r.dp_max) == (packaged.dp_min, packaged.dp_max)
        assert r.speed_max == pytest.approx(packaged.speed_max / scale)
        assert r.speed_min == pytest.approx(packaged.speed_min / scale)
    assert MotorModel.for_displacement(None, 'paszota').valid_range == packaged


def test_a_displacement_motor_flags_the_speeds_its_size_was_never_validated_at():
    small = MotorModel.for_displacement(4.92 * CM3_PER_REV, 'paszota')  # the MBARI F11-5
    assert small.absorbency_point(2500 * RPM, dp_i=10 * MPA).status == 0
    assert small.absorbency_point(4000 * RPM, dp_i=10 * MPA).status == EXTRAPOLATED
    large = MotorModel.for_displacement(100 * CM3_PER_REV)  # range 69-1036 rpm
    assert large.absorbency_point(600 * RPM, dp_i=10 * MPA).status == 0
    assert large.absorbency_point(1400 * RPM, dp_i=10 * MPA).status == EXTRAPOLATED
    assert large.absorbency(np.array([600, 1400]) * RPM, dp_i=10 * MPA).status.tolist() \
        == [0, EXTRAPOLATED]


def test_a_reverse_effect_is_ranged_on_the_rows_that_turn_backwards(tmp_path):
    """Forward rows up to 1500 rpm say nothing of a loss that acts only backwards."""
    from satmotor_ros.identify import calibrate, read_csv, write_csv
    from satmotor_ros.identify.synthetic import generate, Injection, Plan, to_columns
    inject = Injection('reverse_loss', 0.6 * LPM)
    forward = to_columns(generate(Plan(liquid='oil', n_points=80, speed_rpm=(100, 1500)),
                                  inject, seed=1))
    backward = to_columns(generate(Plan(liquid='oil', n_points=60, speed_rpm=(100, 300),
                                        reverse_share=1.0), inject, seed=2))
    write_csv(tmp_path / 'rev.csv', {k: (forward[k][0], np.concatenate([forward[k][1],
                                                                        backward[k][1]]))
                                     for k in forward})
    cal = calibrate(read_csv(tmp_path / 'rev.csv'), 'oil')
    [effect] = [e for e in cal.effects() if e.name == 'reverse_loss']
    speeds = {q: (lo, hi) for q, lo, hi in effect.fitted_range}['speed']
    backwards = cal.parts.speed[cal.parts.reverse & cal.inliers]
    assert speeds == (backwards.min(), backwards.max())
    assert speeds[1] < 310 * RPM  # not the forward rows' 1500 rpm
