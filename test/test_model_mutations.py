# SPDX-License-Identifier: Apache-2.0
"""Tests aimed at mistakes the rest of the suite let through (issue 5, item 5)."""

from dataclasses import replace

import numpy as np
import pytest

from satmotor_ros.model import Liquid, load_motor, MotorModel, PointStatus
from satmotor_ros.model.families.sliwinski2017 import losses as eq
from satmotor_ros.model.families.sliwinski2017.composition import Equations
from satmotor_ros.model.units import LPM, MPA, RPM

SPEC = load_motor()


def _model(liquid='oil', law='eq33', user=None, **coef_changes):
    cset = SPEC.sets[liquid]
    if coef_changes:
        cset = replace(cset, coefficients=replace(cset.coefficients, **coef_changes))
    return MotorModel(SPEC.geometry, cset, SPEC.valid_range, user, law)


@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_channel_drop_has_a_positive_laminar_term_as_eq35(liquid):
    coef, fluid = SPEC.sets[liquid].coefficients, SPEC.sets[liquid].liquid
    flow = np.array([1.0, 5.0, 20.0, 40.0])  # [l/min]
    mu_mpas = fluid.density * fluid.kinematic_viscosity * 1e3
    expected = coef.c_t * fluid.density * flow ** 2 + coef.c_l * mu_mpas * flow  # [Pa]
    got = eq.channel_pressure_drop(flow * LPM,
                                   *eq.channel_coefficients(fluid, coef))
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    laminar = got - coef.c_t * fluid.density * flow ** 2
    np.testing.assert_allclose(laminar, coef.c_l * mu_mpas * flow, rtol=1e-9)


def test_channel_drop_uses_the_user_liquids_density_and_viscosity():
    user = Liquid('dense', 20e-6, 1200.0, 1.6e9)
    model = _model('oil', user=user)
    coef = model.coef
    flow = 30.0  # [l/min]
    expected = (coef.c_t * 1200.0 * flow ** 2 + coef.c_l * 1200.0 * 20e-6 * 1e3 * flow)
    op = model.speed(flow * LPM, 10 * MPA)
    assert float(op.dp - op.dp_i) == pytest.approx(expected, rel=1e-12)
    point = model.speed_point(flow * LPM, 10 * MPA)
    assert point.dp - point.dp_i == pytest.approx(expected, rel=1e-9)
    forward = model.absorbency(float(op.speed), 10 * MPA)
    assert float(forward.dp_i) == pytest.approx(float(op.dp_i), rel=1e-9)


def test_the_chamber_drop_limit_is_where_flat_clearance_leakage_peaks():
    model = _model('oil')
    g, coef = model.geometry, model.coef
    h0 = 0.5 * (g.clearance_rotor + g.clearance_satellites)
    compliance = (coef.d_c * g.height * 1e3 + coef.d_k) * 1e-6 / MPA
    assert model.dp_limit == pytest.approx(h0 / (4 * compliance), rel=1e-12)
    assert model.dp_limit / MPA == pytest.approx(50.6, abs=0.05)
    liquid = model.liquid
    dp = model.dp_limit * np.array([0.999, 1.0, 1.001])
    h = eq.clearance_height(dp, *eq.clearance_coefficients(g, coef))
    q = eq.flat_clearance_leakage(dp, h, *eq.flat_clearance_coefficients(liquid, g, coef))
    assert q[1] > q[0] and q[1] > q[2]  # the maximum of eq. (1) with eq. (2)
    ok = model.speed(20 * LPM, dp_i=model.dp_limit * np.array([0.999, 1.001]), errors='mask')
    assert ok.status.tolist() == [PointStatus.EXTRAPOLATED, PointStatus.BEYOND_LIMIT]
    assert model.speed_point(20 * LPM, dp_i=model.dp_limit * 1.001).status \
        == PointStatus.BEYOND_LIMIT
    assert model.absorbency_point(100.0, dp_i=model.dp_limit * 0.999).status \
        == PointStatus.EXTRAPOLATED


def _central(f, x, step):
    return (f(x + step) - f(x - step)) / (2 * step)


@pytest.mark.parametrize('liquid', ['oil', 'water'])
@pytest.mark.parametrize('law', ['eq33', 'eq39'])
def test_analytic_slopes_match_finite_differences(liquid, law):
    model = _model(liquid, law)
    eqs = Equations(model.derived, model.law)
    speed = np.array([30.0, 150.0, 900.0, 1500.0]) * RPM
    dp_i = np.array([0.5, 3.0, 12.0, 24.0]) * MPA
    loss = model.law.loss(speed, dp_i)
    at_dp, d_speed = model.law.at_pressure(dp_i)[1](speed)
    at_n, d_dp = model.law.at_speed(speed)(dp_i)
    np.testing.assert_allclose(at_dp, loss, rtol=1e-14)
    np.testing.assert_allclose(at_n, loss, rtol=1e-14)
    np.testing.assert_allclose(d_speed, _central(lambda n: model.law.loss(n, dp_i), speed,
                                                 1e-4 * speed), rtol=1e-6)
    np.testing.assert_allclose(d_dp, _central(lambda p: model.law.loss(speed, p), dp_i,
                                              1e-5 * dp_i), rtol=1e-6, atol=1e-22)
    for dp in dp_i + 1.0 * MPA:  # the coupled residual's slope, through eqs. (1), (2), (5), (35)
        residual = eqs.flow_problem(float(speed[1]), float(dp), 0.0)[2]
        q = float(model.absorbency_point(float(speed[1]), float(dp)).flow)
        slope = residual(q)[1]
        assert slope == pytest.approx(_central(lambda x: residual(x)[0], q, 1e-6 * q), rel=1e-6)


@pytest.mark.parametrize('law', ['eq33', 'eq39'])
def test_solves_need_few_evaluations_with_right_slopes(law, monkeypatch):
    # a wrong slope still converges inside the bracket, but slowly: count the evaluations
    from satmotor_ros.model.engine import solve
    calls = []
    real = solve.solve_increasing

    def counting(func, *args, **kwargs):
        def counted(x):
            calls.append(1)
            return func(x)
        return real(counted, *args, **kwargs)

    from satmotor_ros.model.engine import forward, inverse
    monkeypatch.setattr(forward, 'solve_increasing', counting)
    monkeypatch.setattr(inverse, 'solve_increasing', counting)
    model = _model('water', law)
    model.absorbency(np.linspace(100, 1500, 50) * RPM, np.linspace(2, 25, 50) * MPA)
    assert len(calls) <= 6
    calls.clear()
    model.speed(np.linspace(5, 40, 50) * LPM, np.linspace(2, 25, 50) * MPA,
                method='iterative')
    assert len(calls) <= 7


@pytest.mark.parametrize('share', [0.0, 0.3, 0.8, 1.0])
def test_deformation_and_backlash_split_follows_the_share(share):
    model = _model('water', deformation_share=share)
    coef = model.coef
    rest = coef.c - eq.compressibility_coefficient(SPEC.sets['water'].liquid.bulk_modulus,
                                                   model.geometry, coef)
    assert model.c_dch == pytest.approx(share * rest, rel=1e-12, abs=1e-18)
    assert model.c_b == pytest.approx((1 - share) * rest, rel=1e-12, abs=1e-18)
    op = model.breakdown(500 * RPM, 10 * MPA)
    scale = eq.pressure_speed_coefficient(1.0, model.geometry) * 10 * MPA * 500 * RPM
    assert float(op.deformation) == pytest.approx(share * rest * scale, rel=1e-12, abs=1e-18)
    assert float(op.backlash) == pytest.approx((1 - share) * rest * scale, rel=1e-12,
                                               abs=1e-18)
    point = model.breakdown_point(500 * RPM, 10 * MPA)
    assert point.deformation == pytest.approx(float(op.deformation), rel=1e-12, abs=1e-18)
    assert point.backlash == pytest.approx(float(op.backlash), rel=1e-12, abs=1e-18)


def test_compressibility_share_follows_the_liquids_bulk_modulus():
    stiff = Liquid('stiff oil', 40e-6, 873.0, 3.2e9)
    base, model = _model('oil'), _model('oil', user=stiff)
    assert model.c_fc_beta == pytest.approx(base.c_fc_beta / 2, rel=1e-12)
    assert model.c_dch == base.c_dch and model.c_b == base.c_b
    assert model.c_lumped == pytest.approx(base.coef.c - base.c_fc_beta / 2, rel=1e-12)
    op = model.breakdown(500 * RPM, 10 * MPA)
    assert float(op.compressibility) == pytest.approx(
        float(base.breakdown(500 * RPM, 10 * MPA).compressibility) / 2, rel=1e-12)


def test_external_leakage_is_k_ex_times_p_ex_in_every_path():
    k_ex = 1e-12  # [m^3/(s*Pa)]
    model = _model('oil', external_leakage=k_ex)
    op = model.speed(10 * LPM, dp_i=10 * MPA, p_ex=2 * MPA)
    assert float(op.losses.external) == pytest.approx(2e-6, rel=1e-12)
    assert model.speed_point(10 * LPM, dp_i=10 * MPA, p_ex=2 * MPA).external \
        == pytest.approx(2e-6, rel=1e-12)
    assert float(model.breakdown(300 * RPM, 10 * MPA, p_ex=2 * MPA).external) \
        == pytest.approx(2e-6, rel=1e-12)
    assert float(model.breakdown(300 * RPM, 10 * MPA).external) == 0.0  # p_ex = 0 by default
    assert model.breakdown_point(300 * RPM, 10 * MPA, 2 * MPA).external \
        == pytest.approx(2e-6, rel=1e-12)
    no_ex = model.speed(10 * LPM, dp_i=10 * MPA)
    assert float(op.speed) < float(no_ex.speed)
    forward = model.absorbency(float(op.speed), 10 * MPA, p_ex=2 * MPA)
    back = model.speed(forward.flow, 10 * MPA, p_ex=2 * MPA)
    assert float(back.speed) == pytest.approx(float(op.speed), rel=1e-9)


def test_eq40_without_the_inertia_term_is_the_linear_solution():
    # C_id = 0 makes b = 0 in eq. (40): n = (Q - leakage) / (q_t + C dp_i m^2 H)
    model = _model('oil', c_id=0.0)
    flow, dp_i = np.array([5.0, 20.0, 40.0]) * LPM, np.array([2.0, 10.0, 25.0]) * MPA
    closed = model.speed(flow, dp_i=dp_i)
    iterative = model.speed(flow, dp_i=dp_i, method='iterative')
    np.testing.assert_allclose(closed.speed, iterative.speed, rtol=1e-12)
    leak = closed.losses.flat_clearance + closed.losses.commutation
    k_p = eq.pressure_speed_coefficient(model.c_lumped, model.geometry)
    np.testing.assert_allclose(closed.speed,
                               (flow - leak) / (model.geometry.displacement + k_p * dp_i),
                               rtol=1e-12)
    np.testing.assert_array_equal(closed.losses.inertia, 0.0)
    assert model.speed_point(20 * LPM, dp_i=10 * MPA).speed == pytest.approx(
        float(closed.speed[1]), rel=1e-12)


def test_a_motor_without_compliance_has_no_pressure_limit():
    model = _model('oil', d_c=0.0, d_k=0.0)
    assert model.dp_limit == float('inf')
    op = model.speed(20 * LPM, dp_i=80 * MPA)
    assert op.status == PointStatus.EXTRAPOLATED and float(op.speed) > 0.0


def test_viscosity_range_is_closed_and_checked_on_both_sides():
    cset = replace(SPEC.sets['oil'], viscosity_range=(30e-6, 50e-6))
    for nu, outside in [(30e-6 * (1.0 - 1e-9), False), (50e-6 * (1.0 + 1e-9), False),
                        (29.9e-6, True), (50.1e-6, True), (80e-6, True), (40e-6, False)]:
        model = MotorModel(SPEC.geometry, cset, SPEC.valid_range,
                           Liquid('user', nu, 873.0, 1.6e9))
        assert model.derived.liquid_extrapolated is outside, nu
    thick = MotorModel.from_spec(SPEC, 'oil', Liquid('cold oil', 60e-6, 873.0, 1.6e9))
    assert thick.speed_point(20 * LPM, 10 * MPA).status == PointStatus.EXTRAPOLATED


@pytest.mark.parametrize('liquid', ['oil', 'water'])
@pytest.mark.parametrize('law', ['eq33', 'eq39'])
def test_a_freshly_built_model_gives_the_same_points_on_both_paths(liquid, law):
    model = _model(liquid, law)  # built inside the test, so that a mutant is rebuilt too
    flow, dp = np.array([3.0, 12.0, 40.0]) * LPM, np.array([2.0, 0.5, 20.0]) * MPA
    ops = model.speed(flow, dp)
    forward = model.absorbency(ops.speed, dp)
    for i in range(3):
        p = model.speed_point(float(flow[i]), float(dp[i]))
        assert p.speed == pytest.approx(float(ops.speed[i]), rel=1e-12)
        assert p.total == pytest.approx(float(ops.losses.total[i]), rel=1e-12)
        f = model.absorbency_point(float(ops.speed[i]), float(dp[i]))
        assert f.flow == pytest.approx(float(forward.flow[i]), rel=1e-12)
        assert f.flow == pytest.approx(float(flow[i]), rel=1e-9)


@pytest.mark.parametrize('fn', ['external_leakage', 'chamber_pressure_drop', 'speed_loss',
                                'absorbency'])
def test_equation_functions_return_floats_for_integer_input(fn):
    from satmotor_ros.model.families.sliwinski2017 import speed as sp
    model = _model('oil', external_leakage=1e-12)
    calls = {
        'external_leakage': lambda: eq.external_leakage(np.array([3]), model.derived.k_ex),
        'chamber_pressure_drop': lambda: eq.chamber_pressure_drop(np.array([7]), np.array([2.0])),
        'speed_loss': lambda: sp.speed_loss(np.array([1]), np.array([2]), model.derived.qt),
        'absorbency': lambda: sp.absorbency(np.array([2]), np.array([1]), model.derived.qt),
    }
    assert calls[fn]().dtype == np.float64


def test_status_codes_are_spelled_out():
    from satmotor_ros.model import describe_status
    assert describe_status(0) == 'OK'
    assert describe_status(PointStatus.NO_ROOT) == 'NO_ROOT'
    assert describe_status(PointStatus.STALLED | PointStatus.EXTRAPOLATED) \
        == 'STALLED|EXTRAPOLATED'
    assert describe_status(PointStatus.NOT_CONVERGED | PointStatus.NEGATIVE) \
        == 'NEGATIVE|NOT_CONVERGED'
