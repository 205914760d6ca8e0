# SPDX-License-Identifier: Apache-2.0
"""The base fits the channel drop the data pin, keeps what they cannot, and says which."""

from dataclasses import replace
import json

import numpy as np
import pytest
from satmotor_ros.identify.base import _with_factor, EMPTIED, emptied, fit_base
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.pipeline import calibrate, Options
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model.families import FAMILY_NAMES
from satmotor_ros.model.families.defaults import default_motor
from satmotor_ros.model.units import CM3_PER_REV, LPM, MPA, RPM

SIZE = 4.92 * CM3_PER_REV  # a motor known by its displacement only


def _points(truth, noise, seed=1, count=400):
    """Steady points over 300-5000 rpm and 2-20 MPa, the flow of `truth` plus noise."""
    rng = np.random.default_rng(seed)
    speed = rng.uniform(300.0, 5000.0, count) * RPM
    dp = rng.uniform(2.0, 20.0, count) * MPA
    flow = truth.absorbency(speed, dp, errors='mask').flow
    ok = np.isfinite(flow)
    flow = flow + rng.normal(0.0, noise * LPM, count)
    return BenchTable(speed[ok], flow[ok], dp[ok] + 0.5 * MPA, np.full(int(ok.sum()), 0.5 * MPA))


def _truth(family, factor):
    spec = default_motor(family, SIZE)
    channel = MotorModel.from_spec(spec, 'oil').family.channel
    return spec, MotorModel.from_spec(_with_factor(spec, 'oil', channel, factor), 'oil')


@pytest.mark.parametrize('family', FAMILY_NAMES)
def test_a_plausible_channel_drop_is_fitted_for_every_family(family):
    spec, truth = _truth(family, 0.5)
    base = fit_base(spec, 'oil', _points(truth, 0.02))
    assert base.fitted and not any(k['coefficient'] in truth.family.channel for k in base.kept)
    for row in base.fitted:
        true = getattr(truth.coef, row['coefficient'])
        assert row['ci95'][0] <= true <= row['ci95'][1]
        assert row['value'] == pytest.approx(true, rel=0.15)
        assert row['packaged'] == getattr(MotorModel.from_spec(spec, 'oil').coef,
                                          row['coefficient'])
    assert base.channel_drop['used_mpa'] == pytest.approx(
        truth.equations.channel_drop(base.channel_drop['flow_lpm'] * LPM) / MPA, rel=0.15)
    fitted = MotorModel.from_spec(base.spec, 'oil')
    assert all(getattr(fitted.coef, r['coefficient']) == r['value'] for r in base.fitted)


def test_a_drop_the_data_cannot_see_is_kept_and_named():
    spec, truth = _truth('paszota', 1.0)
    base = fit_base(spec, 'oil', _points(truth, 0.5, count=40))
    assert not base.fitted and not base.changed and base.spec is spec
    kept = {k['coefficient']: k for k in base.kept}
    assert {'c_t', 'c_l', 'a_pv', 'a_nv'} <= set(kept)
    assert 'do not pin it' in kept['c_t']['why'] or 'spans' in kept['c_t']['why']
    assert kept['c_t']['value'] == MotorModel.from_spec(spec, 'oil').coef.c_t


def test_the_motor_s_own_coefficients_are_kept_not_refitted():
    packaged = load_motor()
    truth = MotorModel.from_spec(_with_factor(packaged, 'oil', ('c_t', 'c_l'), 0.3), 'oil')
    base = fit_base(packaged, 'oil', _points(truth, 0.02))
    assert not base.changed and base.spec is packaged
    assert "motor's own" in base.note


def test_the_guess_refuted_by_the_port_drop_is_not_kept_beyond_physics():
    spec, truth = _truth('sliwinski2017', 0.02)
    base = fit_base(spec, 'oil', _points(truth, 0.02))
    drop = base.channel_drop
    assert drop['packaged_mpa'] > 5.0  # the similarity guess
    # the rows below the guessed drop refute it; the profile is least at no drop, a bound:
    # the largest drop the data accept is kept, which holds the true one
    true = truth.equations.channel_drop(drop['flow_lpm'] * LPM) / MPA
    assert true < drop['used_mpa'] < 1.5, base.note
    kept = {k['coefficient']: k['why'] for k in base.kept}
    assert not base.fitted and 'refute' in kept['c_t'] and 'largest' in kept['c_t']


def test_the_calibration_writes_what_the_base_fitted_and_the_yaml_loads_it(tmp_path):
    spec, truth = _truth('sliwinski2017', 0.3)
    cal = calibrate(_points(truth, 0.02, count=120), 'oil', spec=spec)
    write_json(cal, tmp_path / 'calibration.json')
    base = json.loads((tmp_path / 'calibration.json').read_text())['family_comparison']['base']
    fitted = {f['coefficient']: f['value'] for f in base['fitted']}
    assert 'beta' in {k['coefficient'] for k in base['kept']}  # Table 1's exponents: kept
    assert set(fitted) == {'c_t', 'c_l'}
    write_yaml(cal, tmp_path / 'coefficients.yaml')
    loaded = MotorModel.from_spec(load_motor(tmp_path / 'coefficients.yaml'), 'oil')
    assert loaded.coef.c_t == pytest.approx(fitted['c_t'], rel=1e-12)
    assert loaded.coef.c_t < 0.6 * MotorModel.from_spec(spec, 'oil').coef.c_t


def _both_ways(truth, dp_mpa, seed=3, count=240):
    """Steady points at port drops `dp_mpa` (lo, hi), half turning each way, with noise."""
    rng = np.random.default_rng(seed)
    speed = rng.uniform(1000.0, 5000.0, count) * RPM
    dp = rng.uniform(*dp_mpa, count) * MPA
    flow = truth.absorbency(speed, dp, errors='mask').flow + rng.normal(0.0, 0.02 * LPM, count)
    ok = np.isfinite(flow)
    way = np.where(np.arange(count) % 2 == 0, 1.0, -1.0)[ok]
    low, high = np.full(int(ok.sum()), 0.5 * MPA), dp[ok] + 0.5 * MPA
    return BenchTable(way * speed[ok], way * flow[ok], np.where(way > 0, high, low),
                      np.where(way > 0, low, high))


def test_rows_below_the_packaged_drop_pin_a_small_drop_and_are_kept():
    spec, truth = _truth('sliwinski2017', 0.03)
    packaged = MotorModel.from_spec(spec, 'oil')
    table = _both_ways(truth, (1.0, 6.0))
    drops = packaged.equations.channel_drop(np.abs(table.flow))
    assert np.mean(np.abs(table.dp) < drops) > 0.5  # most rows: below the guessed drop
    cal = calibrate(table, 'oil', spec=spec)
    assert cal.base.fitted, cal.base.note
    drop = cal.base.channel_drop
    assert drop['packaged_mpa'] > 5.0 and drop['used_mpa'] < 0.5, cal.base.note
    low, high = cal.base.fitted[0]['ci95']
    assert low <= truth.coef.c_t <= high, cal.base.note
    envelope = cal.coverage['envelope']
    assert envelope['positive']['samples'] + envelope['negative']['samples'] == len(table)
    assert not cal.warnings()


def test_a_drop_that_empties_a_direction_is_warned_of():
    spec, truth = _truth('sliwinski2017', 0.03)
    table = _both_ways(truth, (1.0, 6.0))
    # a motor file's own drop (not a guess): kept, and most motor-mode samples are below it
    own = replace(spec, name='F11-5 (measured)')
    packaged = MotorModel.from_spec(own, 'oil')
    below = packaged.chamber_drop(table.dp, table.flow) * np.sign(table.dp) < 0.0
    positive, lost = int((table.dp > 0.0).sum()), int((below & (table.dp > 0.0)).sum())
    assert lost > positive / 2
    cal = calibrate(table, 'oil', spec=own, options=Options(compare_families=False))
    assert not cal.base.changed
    warned = [w for w in cal.warnings()['warnings'] if w.startswith(EMPTIED)]
    assert len(warned) == 1 and f'{lost} of {positive} samples with a positive drop' in warned[0]
    assert emptied(truth, table, cal.base) is None  # the true drop leaves them in


def test_the_profile_does_not_depend_on_the_units_of_a_term_fitted_beside_it():
    # a transient term is a pressure rate [Pa/s] beside flows [m^3/s]: 10^12 apart and more;
    # unscaled, lstsq's cut-off dropped the flows' small singular values at some factors
    # only, and the profile jumped there (a 'fitted' drop at the jump's edge)
    spec, truth = _truth('paszota', 0.5)
    points = _points(truth, 0.02)
    term = np.random.default_rng(3).normal(0.0, 1.0, len(points))
    bases = [fit_base(spec, 'oil', points, {'term': unit * term}) for unit in (1e-4, 1e14)]
    assert bases[0].fitted and bases[1].fitted, bases[1].note
    assert bases[1].channel_drop['factor'] == pytest.approx(bases[0].channel_drop['factor'],
                                                            rel=1e-4)
