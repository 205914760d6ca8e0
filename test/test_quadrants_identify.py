# SPDX-License-Identifier: Apache-2.0
"""Four-quadrant data in calibration, and the loss keyed on the direction of rotation."""

from dataclasses import replace
import json

import numpy as np
import pytest

from satmotor_ros.cli.main import main
from satmotor_ros.identify import calibrate
from satmotor_ros.identify.parts import loss_parts, predict_flow
from satmotor_ros.identify.synthetic import generate, Injection, Plan, to_columns
from satmotor_ros.identify.table import BenchTable, read_csv, write_csv
from satmotor_ros.model import load_motor, MotorModel, PointStatus
from satmotor_ros.model.effects import effect_from_mapping, effect_to_mapping
from satmotor_ros.model.units import LPM, MPA, RPM

FOUR = Plan(n_points=160, reverse_share=0.5, pump_share=0.3)
K = 4e-15  # reverse_loss coefficient [m^3/(Pa*rad)]: ~1 l/min at 25 MPa and 1500 rpm


def _with(effects, liquid='oil', law='eq33'):
    spec = load_motor()
    coef = replace(spec.sets[liquid], effects=tuple(effects))
    return MotorModel(spec.geometry, coef, spec.valid_range, displacement_law=law)


def _mirrored(table):
    return BenchTable(-table.speed, -table.flow, table.p_out, table.p_in, table.channels,
                      table.units, table.source)


@pytest.mark.parametrize('family', ['sliwinski2017', 'balawender', 'paszota'])
def test_loss_parts_of_a_mirrored_table_are_the_forward_parts(family):
    model = MotorModel.for_displacement(None, family)
    table = generate(Plan(n_points=40), Injection(), seed=2)
    forward, usable = loss_parts(model, table)
    mirrored, usable_m = loss_parts(model, _mirrored(table))
    assert (usable == usable_m).all()
    for name in ('flow', 'speed', 'dp', 'dp_i', 'displacement'):
        np.testing.assert_array_equal(getattr(mirrored, name), getattr(forward, name))
    for mine, theirs in zip(mirrored.components, forward.components):
        for (_, a), (_, b) in zip(mine.pieces, theirs.pieces):
            np.testing.assert_array_equal(a, b)
    assert (mirrored.sign == -1.0).all() and (mirrored.reverse).all()
    assert (forward.sign == 1.0).all() and not forward.reverse.any()


def test_loss_parts_predict_every_quadrant_of_the_model_exactly():
    model = MotorModel.default('water')
    rng = np.random.default_rng(4)
    n = rng.uniform(100, 1500, 200) * RPM * rng.choice([-1.0, 1.0], 200)
    dp = rng.uniform(2, 25, 200) * MPA * rng.choice([-1.0, 1.0], 200)
    flow = model.absorbency(n, dp).flow
    p_low = np.full(200, 0.5 * MPA)
    table = BenchTable(n, flow, p_low + np.maximum(dp, 0), p_low + np.maximum(-dp, 0))
    parts, usable = loss_parts(model, table)
    pump_with_leak = flow * n < 0  # a pump slower than its leakage: no flow the model gives
    assert (usable == ~pump_with_leak).all() or usable.sum() >= 190
    np.testing.assert_allclose(predict_flow(parts, np.ones(3)), parts.flow, rtol=1e-9)


def test_clean_four_quadrant_data_find_no_effect():
    cal = calibrate(generate(FOUR, Injection(), seed=5), 'oil')
    assert cal.chosen is None, cal.selection.verdict


def test_calibration_finds_that_the_two_directions_differ():
    table = generate(FOUR, Injection('reverse_loss', 0.6 * LPM), seed=6)
    cal = calibrate(table, 'oil')
    assert cal.chosen is not None and cal.chosen.effect == 'reverse_loss', cal.selection.verdict
    injected = 0.6 * LPM / np.max(np.abs(cal.parts.dp_i * cal.parts.speed)[cal.parts.reverse])
    low, high = cal.final.ci95[3]
    assert low <= injected * 1.05 and high >= injected * 0.95 and low > 0.0
    assert cal.error_before.rmse_lpm >= 3 * cal.error_after.rmse_lpm


def test_the_direction_candidate_needs_both_directions():
    cal = calibrate(generate(Plan(n_points=60), Injection(), seed=1), 'oil')
    assert any(s.startswith('reverse_loss: the data turn one way only') for s in cal.skipped)
    assert all(c.effect != 'reverse_loss' for c in cal.candidates)


def test_reverse_loss_acts_only_backwards_and_is_continuous_at_rest():
    effect = effect_from_mapping('reverse_loss', {'coefficient': K}, 'test')
    assert effect_from_mapping('reverse_loss', effect_to_mapping(effect), 'yaml') == effect
    model, bare = _with([effect]), MotorModel.default('oil')
    for dp in (10 * MPA, -10 * MPA):
        ahead = model.absorbency_point(500 * RPM, dp=dp)
        assert ahead.flow == pytest.approx(bare.absorbency_point(500 * RPM, dp=dp).flow,
                                           rel=1e-12)
        back = model.absorbency_point(-500 * RPM, dp_i=dp)
        plain = bare.absorbency_point(-500 * RPM, dp_i=dp)
        extra = K * 10 * MPA * 500 * RPM * np.sign(dp)  # with the other losses, high to low
        assert back.flow - plain.flow == pytest.approx(extra, rel=1e-9)
        assert back.total - plain.total == pytest.approx(extra, rel=1e-9)
        # 0 at rest, and only k |dp_i| |n| near it: continuous through zero speed
        assert model.absorbency_point(0.0, dp_i=dp) == bare.absorbency_point(0.0, dp_i=dp)
        near = model.absorbency_point(-1e-6, dp_i=dp).flow - bare.absorbency_point(
            -1e-6, dp_i=dp).flow
        assert near == pytest.approx(K * dp * 1e-6, rel=1e-6)
        for n in (-900 * RPM, -20 * RPM):  # the inverse map solves with the effect too
            q = model.absorbency_point(n, dp=dp).flow
            assert model.speed_point(q, dp=dp).speed == pytest.approx(n, rel=1e-8)


def test_reverse_loss_in_the_array_maps_equals_the_points():
    model = _with([effect_from_mapping('reverse_loss', {'coefficient': K}, 'test')], 'water')
    n = np.array([-1000.0, -300.0, 0.0, 300.0]) * RPM
    dp = np.array([15.0, -15.0, 5.0, -5.0]) * MPA
    op = model.absorbency(n, dp)
    for i in range(4):
        point = model.absorbency_point(float(n[i]), dp=float(dp[i]))
        assert op.flow[i] == pytest.approx(point.flow, rel=1e-12)
        assert not op.status[i] & PointStatus.NO_ROOT


@pytest.mark.slow
def test_a_bench_csv_with_port_pressures_and_signed_speed_calibrates(tmp_path):
    table = generate(FOUR, Injection('reverse_loss', 0.6 * LPM), seed=6)
    columns = to_columns(table)
    columns['p_a'], columns['p_b'] = columns.pop('p_in'), columns.pop('p_out')
    write_csv(tmp_path / 'bench.csv', columns)
    back = read_csv(tmp_path / 'bench.csv')
    assert (back.speed < 0).any() and (back.flow < 0).any() and (back.dp < 0).any()
    assert main(['calibrate', str(tmp_path / 'bench.csv'), '--liquid', 'oil',
                 '--out', str(tmp_path / 'out')]) == 0
    summary = json.loads((tmp_path / 'out' / 'calibration.json').read_text())
    assert summary['effect'] == 'reverse_loss'
