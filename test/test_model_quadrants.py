# SPDX-License-Identifier: Apache-2.0
"""Four-quadrant operation of the model: the signed rule, checked with hypothesis."""

import math

from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

from satmotor_ros.model import InvalidInputError, load_motor, MotorModel, PointStatus
from satmotor_ros.model.effects import effect_from_mapping
from satmotor_ros.model.engine.forward import absorbency_map
from satmotor_ros.model.engine.inverse import speed_map
from satmotor_ros.model.units import LPM, MPA, RPM

SPEC = load_motor()
MODELS = {(liquid, law): MotorModel.default(liquid, law)
          for liquid in ('oil', 'water') for law in ('eq33', 'eq39')}
MODELS.update({('oil', family): MotorModel.for_displacement(None, family)
               for family in ('balawender', 'paszota')})  # one signed layer for every family
keys = st.sampled_from(sorted(MODELS))
signs = st.sampled_from([1.0, -1.0])
ports = st.booleans()
speeds = st.floats(10.0, 1500.0)  # [rpm]
drops = st.floats(0.5, 25.0)  # [MPa]
PROPERTY = settings(max_examples=120, deadline=None, derandomize=True)
INVALID = int(PointStatus.NO_ROOT | PointStatus.NOT_CONVERGED | PointStatus.BEYOND_LIMIT
              | PointStatus.NOT_FINITE | PointStatus.NEGATIVE)


def _dp(port, value):
    return {'dp': value} if port else {'dp_i': value}


@PROPERTY
@given(key=keys, n=speeds, dp=drops, sn=signs, sd=signs, port=ports)
def test_forward_map_is_antisymmetric(key, n, dp, sn, sd, port):
    model = MODELS[key]
    a = model.absorbency_point(sn * n * RPM, **_dp(port, sd * dp * MPA))
    b = model.absorbency_point(-sn * n * RPM, **_dp(port, -sd * dp * MPA))
    assert a.status == b.status and not a.status & INVALID
    assert tuple(b[:12]) == tuple(-v for v in a[:12])  # bit for bit


@PROPERTY
@given(key=keys, q=st.floats(0.05, 55.0), dp=drops, sq=signs, sd=signs, port=ports)
def test_inverse_map_is_antisymmetric(key, q, dp, sq, sd, port):
    model = MODELS[key]
    a = model.speed_point(sq * q * LPM, **_dp(port, sd * dp * MPA))
    b = model.speed_point(-sq * q * LPM, **_dp(port, -sd * dp * MPA))
    assert a.status == b.status
    np.testing.assert_array_equal(np.array(b[:12]), -np.array(a[:12]))


@PROPERTY
@given(key=keys, n=speeds, dp=drops, sn=signs, sd=signs, port=ports)
def test_losses_run_from_the_high_to_the_low_pressure_port(key, n, dp, sn, sd, port):
    model = MODELS[key]
    point = model.absorbency_point(sn * n * RPM, **_dp(port, sd * dp * MPA))
    loss = point.flow - model.geometry.displacement * point.speed
    # 0 only where the channels take the whole port drop and the family loses nothing at 0
    assert math.copysign(1.0, loss) == sd and loss != 0.0 or loss == point.dp_i == 0.0
    assert point.total == pytest.approx(loss, rel=1e-9)
    assert all(math.copysign(1.0, c) == sd or c == 0.0 for c in point[4:12])


@PROPERTY
@given(key=keys, n=speeds, dp=drops, sn=signs, sd=signs, port=ports)
def test_signed_maps_round_trip_in_every_quadrant(key, n, dp, sn, sd, port):
    model = MODELS[key]
    forward = model.absorbency_point(sn * n * RPM, **_dp(port, sd * dp * MPA))
    back = model.speed_point(forward.flow, **_dp(port, sd * dp * MPA))
    assert not back.status & INVALID
    if forward.flow * sn < 0.0:
        # a pump turned slower than its leakage runs back: the flow goes with the pressure,
        # below the stall leakage, and the inverse map reads it as a stalled motor
        assert sn != sd and back.speed == 0.0 and back.status & PointStatus.STALLED
        return
    assert back.speed == pytest.approx(sn * n * RPM, rel=1e-8)
    assert back.dp_i == pytest.approx(forward.dp_i, rel=1e-9)


@PROPERTY
@given(key=st.sampled_from([k for k in sorted(MODELS) if k[1] != 'eq39']), dp=drops, sd=signs,
       port=ports, log_eps=st.floats(-9.0, -3.0))
def test_flow_is_continuous_through_zero_speed(key, dp, sd, port, log_eps):
    # not eq. (39): it is not used between n = 0 and its floor speed (BEYOND_LIMIT)
    model = MODELS[key]
    eps = 10.0 ** log_eps * RPM
    kw = _dp(port, sd * dp * MPA)
    at_rest = model.absorbency_point(0.0, **kw)
    assert at_rest.flow == pytest.approx(
        sd * model.absorbency_point(0.0, **_dp(port, dp * MPA)).flow)
    qt = model.geometry.displacement
    for n in (eps, -eps):
        # the loss approaches its value at rest at least as fast as |n|^0.4 (eq. 14: 0.5;
        # Paszota's a_nv: 0.439), the flow by q_t n more
        loss = model.absorbency_point(n, **kw).total - at_rest.total
        at_1rpm = model.absorbency_point(math.copysign(RPM, n), **kw).total - at_rest.total
        assert abs(loss) <= 1.01 * abs(at_1rpm) * (eps / RPM) ** 0.4 + 1e-18
        assert abs(model.absorbency_point(n, **kw).flow - at_rest.flow - loss) <= 1.01 * qt * eps


@PROPERTY
@given(key=keys, n=speeds, sn=signs, log_eps=st.floats(-6.0, 0.0))
def test_flow_through_zero_pressure_jumps_only_by_the_pressureless_loss(key, n, sn, log_eps):
    # a loss with no pressure behind it (eq. 14) has no direction: across dp = 0 the flow
    # jumps by twice that loss and nothing else; at rest (n = 0) it is continuous
    model = MODELS[key]
    eps = 10.0 ** log_eps
    up = model.absorbency_point(sn * n * RPM, dp_i=eps)
    down = model.absorbency_point(sn * n * RPM, dp_i=-eps)
    zero = model.absorbency_point(abs(n) * RPM, dp_i=0.0).total
    # the pressure-driven part shrinks with eps like the stall leakage (dp^beta, beta > 0.4)
    at_1pa = model.absorbency_point(abs(n) * RPM, dp_i=1.0).total - zero
    assert abs(up.flow - down.flow - 2.0 * zero) <= 2.02 * at_1pa * eps ** 0.4 + 1e-18
    rest = [model.absorbency_point(0.0, dp_i=d).flow for d in (eps, -eps)]
    at_1mpa = model.absorbency_point(0.0, dp_i=MPA).flow
    assert rest[0] == -rest[1] and 0.0 <= rest[0] <= at_1mpa * (eps / MPA) ** 0.5


@PROPERTY
@given(key=keys, n=speeds, dp=drops, sd=signs)
def test_pump_chambers_deliver_the_port_rise_plus_the_channel_drop(key, n, dp, sd):
    model = MODELS[key]
    point = model.absorbency_point(-sd * n * RPM, dp=sd * dp * MPA)
    if point.flow * point.speed > 0.0:  # a pump that delivers: its flow runs against dp
        assert abs(point.dp_i) > abs(point.dp) and math.copysign(1.0, point.dp_i) == sd
    drop = model.chamber_drop(point.dp, point.flow)
    assert float(drop) == pytest.approx(point.dp_i, rel=1e-12)
    motor = model.absorbency_point(sd * n * RPM, dp=sd * dp * MPA)
    assert abs(motor.dp_i) < abs(motor.dp)


def test_pump_delivers_less_than_its_displacement_and_a_motor_absorbs_more():
    model = MODELS['oil', 'eq33']
    qt = model.geometry.displacement
    pump = model.absorbency_point(1000 * RPM, dp=-20 * MPA)
    motor = model.absorbency_point(1000 * RPM, dp=20 * MPA)
    assert 0.0 < pump.flow < qt * 1000 * RPM < motor.flow
    assert pump.speed == 1000 * RPM and pump.status == PointStatus.EXTRAPOLATED  # not measured
    assert motor.status == 0


def test_stall_under_pressure_leaks_towards_the_low_port():
    model = MODELS['water', 'eq33']
    ahead = model.absorbency_point(0.0, dp=10 * MPA)
    behind = model.absorbency_point(0.0, dp=-10 * MPA)
    assert ahead.flow > 0.0 and behind.flow == -ahead.flow
    stalled = model.speed_point(0.5 * ahead.flow, dp=10 * MPA)
    assert stalled.speed == 0.0 and stalled.status & PointStatus.STALLED


def test_forward_results_are_the_magnitude_maps_bit_for_bit():
    model = MODELS['oil', 'eq39']
    n = np.linspace(0.0, 1500.0, 41) * RPM
    dp = np.linspace(0.0, 25.0, 41) * MPA
    mixed = model.absorbency(np.concatenate([n, -n]), np.concatenate([dp, dp]), errors='mask')
    plain = absorbency_map(model._equations, model.geometry, n, 'dp', dp, 0.0, 'mask')
    np.testing.assert_array_equal(mixed.flow[:41], plain.flow)
    np.testing.assert_array_equal(mixed.status[:41], plain.status)
    q = np.linspace(0.0, 50.0, 41) * LPM
    inverse = speed_map(model._equations, model.geometry, q, 'dp', dp, 0.0, 'mask', False)
    signed = model.speed(np.concatenate([q, -q]), np.concatenate([dp, -dp]))
    np.testing.assert_array_equal(signed.speed[:41], inverse.speed)
    np.testing.assert_array_equal(signed.speed[41:], -inverse.speed)


@pytest.mark.parametrize('key', sorted(MODELS))
def test_array_maps_equal_the_point_maps_in_every_quadrant(key):
    model = MODELS[key]
    rng = np.random.default_rng(3)
    n = rng.uniform(-1500, 1500, 200) * RPM
    dp = rng.uniform(-25, 25, 200) * MPA
    forward = model.absorbency(n, dp, errors='mask')
    points = [model.absorbency_point(float(a), float(b)) for a, b in zip(n, dp)]
    np.testing.assert_allclose(forward.flow, [p.flow for p in points], rtol=1e-12)
    np.testing.assert_array_equal(forward.status, [p.status for p in points])
    back = model.speed(forward.flow, dp, errors='mask')
    delivers = forward.flow * n > 0.0  # else a pump slower than its leakage: read as stalled
    np.testing.assert_allclose(back.speed[delivers], n[delivers], rtol=1e-8)
    assert (back.status[~delivers] & PointStatus.STALLED).all()


def test_a_flow_no_pump_speed_can_deliver_is_no_root_and_raises():
    # an extra loss growing as n^2 outgrows the displacement: a pump delivers at most
    # max(q_t n - Q_vl), and a larger flow against the pressure has no speed
    coef = SPEC.sets['oil']
    effect = effect_from_mapping('term:n^2', {'coefficient': 2e-8}, 'test')
    from dataclasses import replace
    model = MotorModel(SPEC.geometry, replace(coef, effects=(effect,)), SPEC.valid_range)
    small = model.speed_point(-2 * LPM, dp=10 * MPA)
    assert not small.status & INVALID and small.speed < 0.0
    huge = model.speed_point(-50 * LPM, dp=10 * MPA)
    assert huge.status == PointStatus.NO_ROOT and math.isnan(huge.speed)
    with pytest.raises(InvalidInputError, match='NO_ROOT'):
        model.speed(np.array([-2.0, -50.0]) * LPM, 10 * MPA)


def test_a_pump_flow_beyond_the_measured_speeds_is_computed_and_flagged_extrapolated():
    model = MODELS['oil', 'eq33']
    point = model.speed_point(-60 * LPM, dp=10 * MPA)
    assert point.speed < -1500 * RPM and point.status == PointStatus.EXTRAPOLATED
    assert model.absorbency_point(point.speed, dp=10 * MPA).flow == pytest.approx(-60 * LPM)


def test_pump_mode_beyond_the_pressure_limit_is_flagged_not_computed():
    model = MODELS['oil', 'eq33']
    limit = model.dp_limit
    point = model.absorbency_point(-1000 * RPM, dp=limit * 0.999)
    assert point.status & PointStatus.BEYOND_LIMIT and math.isnan(point.flow)
    assert model.speed_point(-10 * LPM, dp=limit * 1.01).status & PointStatus.BEYOND_LIMIT


def test_nan_and_negative_external_pressure_stay_refused():
    model = MODELS['oil', 'eq33']
    assert model.speed_point(math.nan, dp=-1e6).status == PointStatus.NOT_FINITE
    assert model.absorbency_point(-1.0, dp=-1e6, p_ex=-5.0).status & PointStatus.NEGATIVE
