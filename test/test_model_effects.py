# SPDX-License-Identifier: Apache-2.0
"""A coefficient set's ``effects:`` block is data that the model evaluates as documented."""

import copy
import math

import numpy as np
import pytest
from satmotor_ros.model import (COMPONENTS, ConfigError, INVALID, InvalidInputError, load_motor,
                                ModelError, MotorModel, PointStatus)
from satmotor_ros.model.effects import flow_reading
from satmotor_ros.model.engine.solve import solve_increasing_scalar, Tolerance, with_secant_slope
from satmotor_ros.model.io.config import default_config_path, motor_from_mapping
from satmotor_ros.model.units import LPM, MPA, RPM
from satmotor_ros.model.viscosity import vogel_viscosity, walther_slope, walther_viscosity
import yaml

BASE = yaml.safe_load(default_config_path().read_text(encoding='utf-8'))
OIL = MotorModel.default('oil')
WATER = MotorModel.default('water')


def _doc_with(liquid, effects, **coefficients):
    doc = copy.deepcopy(BASE)
    entry = doc['coefficient_sets'][liquid]
    entry['effects'] = effects
    entry['coefficients'].update(coefficients)
    return doc


def model_with(liquid, effects, **coefficients):
    return MotorModel.from_spec(motor_from_mapping(_doc_with(liquid, effects, **coefficients)),
                                liquid)


def balance(model, point):
    return abs(model.geometry.displacement * point.speed + point.total - point.flow) / point.flow


EFFECTS = {
    'external_leakage': ({'external_leakage': {'regressor': 'p_out', 'coefficient': 2e-12}},
                         {'p_in': 9.0 * MPA, 'p_out': 0.8 * MPA}),
    'viscosity_temperature': ({'viscosity_temperature': {
        'regressor': 'temperature', 'coefficient': 3.7, 'law': 'walther',
        'reference_temperature': 45.0, 'reference_viscosity': 40e-6}}, {'temperature': 60.0}),
    'clearance_wear': ({'clearance_wear': {'regressor': 'revolutions', 'coefficient': 1e-9,
                                           'reference': 100.0}}, {'revolutions': 1100.0}),
    'channel:aux': ({'channel:aux': {'coefficient': 0.3 * LPM, 'reference': 1.0}},
                    {'aux': 3.0}),
    'term:dp^2*n': ({'term:dp^2*n': {'coefficient': 2e-21}}, {}),
}


@pytest.mark.parametrize('name', list(EFFECTS))
@pytest.mark.parametrize('law', ['eq33', 'eq39'])
def test_each_effect_keeps_the_balance_and_round_trips(name, law):
    effects, channels = EFFECTS[name]
    extra = {'external_leakage': 2e-12} if name == 'external_leakage' else {}
    doc = copy.deepcopy(BASE)
    doc['coefficient_sets']['oil']['effects'] = effects
    doc['coefficient_sets']['oil']['coefficients'].update(extra)
    model = MotorModel.from_spec(motor_from_mapping(doc), 'oil', displacement_law=law)
    bare = MotorModel.default('oil', law)
    assert model.channels == tuple(sorted(channels))
    for speed in (120 * RPM, 700 * RPM, 1500 * RPM):
        for dp in (3 * MPA, 12 * MPA, 24 * MPA):
            fwd = model.absorbency_point(speed, dp, channels=channels)
            assert not fwd.status & ~int(PointStatus.EXTRAPOLATED), fwd
            assert fwd.flow > bare.absorbency_point(speed, dp).flow  # every effect leaks more
            assert balance(model, fwd) < 1e-9
            assert fwd.dp == dp
            back = model.speed_point(fwd.flow, dp, channels=channels)
            assert back.speed == pytest.approx(speed, rel=1e-9)
            assert back.dp_i == pytest.approx(fwd.dp_i, rel=1e-9)
            assert back.dp == dp and back.flow == fwd.flow
            assert balance(model, back) < 1e-9
            inner = model.speed_point(fwd.flow, dp_i=fwd.dp_i, channels=channels)
            assert inner.speed == pytest.approx(speed, rel=1e-9)
            assert inner.dp == pytest.approx(dp, rel=1e-9)
            chamber = model.absorbency_point(speed, dp_i=fwd.dp_i, channels=channels)
            assert chamber.flow == pytest.approx(fwd.flow, rel=1e-9)


def test_extra_losses_are_what_the_yaml_says():
    speed, dp_i = 600 * RPM, 15 * MPA
    bare = OIL.breakdown_point(speed, dp_i)
    channel = model_with('oil', EFFECTS['channel:aux'][0])
    assert (channel.breakdown_point(speed, dp_i, channels={'aux': 3.0}).total - bare.total
            == pytest.approx(0.3 * LPM * (3.0 - 1.0), rel=1e-12))
    term = model_with('oil', EFFECTS['term:dp^2*n'][0])
    assert (term.breakdown_point(speed, dp_i).total - bare.total
            == pytest.approx(2e-21 * dp_i ** 2 * speed, rel=1e-12))
    leak = model_with('oil', EFFECTS['external_leakage'][0], external_leakage=2e-12)
    pt = leak.breakdown_point(speed, dp_i, p_ex=5 * MPA, channels={'p_out': 0.8 * MPA})
    assert pt.external == pytest.approx(2e-12 * 0.8 * MPA, rel=1e-12)  # the channel, not p_ex


def test_viscosity_and_wear_change_the_liquid_and_the_clearances():
    speed, dp_i = 600 * RPM, 15 * MPA
    visc = model_with('oil', EFFECTS['viscosity_temperature'][0])
    nu = float(walther_viscosity(60.0, 45.0, 40e-6, 3.7))
    thinner = MotorModel(OIL.geometry, OIL.coefficient_set, OIL.valid_range,
                         OIL.liquid.__class__('thin', nu, OIL.liquid.density,
                                              OIL.liquid.bulk_modulus))
    got = visc.breakdown_point(speed, dp_i, channels={'temperature': 60.0})
    assert got.flat_clearance == thinner.breakdown_point(speed, dp_i).flat_clearance
    at_ref = visc.breakdown_point(speed, dp_i, channels={'temperature': 45.0})
    assert at_ref.flat_clearance == pytest.approx(OIL.breakdown_point(speed, dp_i).flat_clearance,
                                                  rel=1e-12)
    wear = model_with('oil', EFFECTS['clearance_wear'][0])
    g = OIL.geometry
    worn = MotorModel(g.__class__(g.displacement, g.module, g.height, g.clearance_rotor + 1e-6,
                                  g.clearance_satellites + 1e-6, g.commutation_diameter),
                      OIL.coefficient_set, OIL.valid_range)
    got = wear.breakdown_point(speed, dp_i, channels={'revolutions': 1100.0})
    assert got.flat_clearance == pytest.approx(worn.breakdown_point(speed, dp_i).flat_clearance,
                                               rel=1e-12)
    unworn = wear.breakdown_point(speed, dp_i, channels={'revolutions': 0.0})  # clamped at 0
    assert unworn.total == pytest.approx(OIL.breakdown_point(speed, dp_i).total, rel=1e-12)


def test_viscosity_laws_match_their_references():
    assert walther_slope(40.0, 46e-6, 100.0, 6.8e-6) == pytest.approx(3.684, abs=1e-3)
    slope = walther_slope(40.0, 46e-6, 100.0, 6.8e-6)
    assert float(walther_viscosity(100.0, 40.0, 46e-6, slope)) == pytest.approx(6.8e-6,
                                                                                rel=1e-9)
    # water: 1.0 mm^2/s at 20 degC falls to about 0.66 at 40 degC (Vogel B = 247.8 K)
    nu40 = float(vogel_viscosity(40.0, 20.0, 1.0e-6, 247.8))
    assert 0.63e-6 < nu40 < 0.69e-6


def test_array_path_is_the_point_path_element_by_element():
    model = model_with('water', {**EFFECTS['viscosity_temperature'][0],
                                 'channel:aux': {'coefficient': 0.1 * LPM, 'reference': 0.0}})
    rng = np.random.default_rng(5)
    flow = rng.uniform(5, 40, 50) * LPM
    dp = rng.uniform(2, 20, 50) * MPA
    temperature = rng.uniform(20, 50, 50)
    aux = rng.uniform(0, 2, 50)
    op = model.speed(flow, dp, channels={'temperature': temperature, 'aux': aux})
    for i in range(50):
        pt = model.speed_point(flow[i], dp[i],
                               channels={'temperature': temperature[i], 'aux': aux[i]})
        got = (op.flow[i], op.speed[i], op.dp[i], op.dp_i[i],
               *(op.losses.as_dict()[c][i] for c in COMPONENTS), op.status[i])
        assert got == tuple(pt)
    assert op.geometry is model.geometry
    with pytest.raises(ModelError, match="errors = 'ignore'"):
        model.speed(flow, dp, errors='ignore', channels={'temperature': temperature, 'aux': aux})
    assert not op.speed.flags.writeable and op.speed.base is not flow


def test_missing_or_bad_channels_are_named():
    model = model_with('oil', EFFECTS['viscosity_temperature'][0])
    with pytest.raises(ModelError, match="channel 'temperature'"):
        model.speed_point(10 * LPM, 10 * MPA)
    pt = model.speed_point(10 * LPM, 10 * MPA, channels={'temperature': math.nan})
    assert pt.status == PointStatus.NOT_FINITE and math.isnan(pt.speed)
    with pytest.raises(InvalidInputError, match='temperature'):
        model.speed([10 * LPM, 20 * LPM], 10 * MPA, channels={'temperature': [20.0, math.inf]})
    masked = model.speed([10 * LPM, 20 * LPM], 10 * MPA, errors='mask',
                         channels={'temperature': [20.0, math.inf]})
    assert list(masked.status) == [int(PointStatus.EXTRAPOLATED), int(PointStatus.NOT_FINITE)]
    with pytest.raises(InvalidInputError, match='broadcast'):
        model.speed([10 * LPM, 20 * LPM], 10 * MPA, channels={'temperature': [1.0, 2.0, 3.0]})


def test_a_term_that_takes_all_the_flow_stalls_the_shaft():
    model = model_with('oil', {'term:dp^0.5': {'coefficient': 1e-7}})
    pt = model.speed_point(1 * LPM, 20 * MPA)
    assert pt.speed == 0.0 and pt.status & PointStatus.STALLED


def test_sensor_effects_convert_readings_only():
    gain = model_with('oil', {'flow_sensor_gain': {'coefficient': 0.05},
                              'speed_sensor_gain': {'coefficient': -0.02}})
    assert gain.channels == ()
    assert gain.true_flow(10.5) == pytest.approx(10.0)
    assert gain.true_speed(98.0) == pytest.approx(100.0)
    assert gain.speed_point(20 * LPM, 10 * MPA) == OIL.speed_point(20 * LPM, 10 * MPA)
    offset = model_with('oil', {'flow_sensor_offset': {'coefficient': 1e-5}})
    assert offset.true_flow(3e-5) == pytest.approx(2e-5)


@pytest.mark.parametrize('effects, match', [
    ({'leakage': {'coefficient': 1.0}}, 'unknown effect'),
    ({'channel': {'coefficient': 1.0, 'reference': 0.0}}, 'unknown effect'),
    ({'term:dp^x': {'coefficient': 1.0}}, "term 'dp\\^x' is not a product of powers"),
    ({'term:dp^.': {'coefficient': 1.0}}, "term 'dp\\^\\.' is not a product of powers"),
    ({'term:dp^1.2.3': {'coefficient': 1.0}}, "term 'dp\\^1.2.3' is not a product"),
    ({'term:n^11': {'coefficient': 1.0}}, 'at most 10'),
    ({'term:dp^0': {'coefficient': 1.0}}, 'each power above 0'),
    ({'threshold:dp': {'coefficient': 1.0, 'reference': 1e7, 'exponent': 272}},
     'exponent = 272.0: must be > 0 and at most 10'),
    ({'threshold:dp': {'coefficient': -1e-11, 'reference': 1e7}}, r'coefficient = -1e-11: must'),
    ({'threshold:dp@negative': {'coefficient': 1e-11, 'reference': -5e6,
                                'direction': 'negative'}}, r'reference = -5000000.0: must be'),
    ({'viscosity_temperature': {'coefficient': 3.0, 'law': 'walther', 'reference_temperature':
                                -708.0, 'reference_viscosity': 4e-5}},
     r'reference_temperature = -708.0: must be from -273 to 10000'),
    ({'viscosity_temperature': {'coefficient': 3.0, 'law': 'walther', 'reference_temperature':
                                40.0, 'reference_viscosity': 0.0}},
     r'reference_viscosity = 0.0: must be from 1e-08 to 1'),
    ({'term:dp^2': {'coefficient': 1.0, 'exponents': {'dp': 3.0}}}, "the id says 'dp\\^2'"),
    ({'threshold:dp': {'coefficient': 1.0}}, 'missing key.*reference'),
    ({'threshold:n': {'coefficient': 1.0, 'reference': 1e7}}, 'use threshold:dp'),
    ({'clearance_wear': {'coefficient': 1e-9, 'regressor': 'hours', 'reference': 0.0}},
     "regressor = 'hours'"),
    ({'clearance_wear': {'coefficient': 1e-9, 'regressor': 'time'}}, 'missing key.*reference'),
    ({'viscosity_temperature': {'coefficient': 3.0, 'law': 'arrhenius',
                                'reference_temperature': 40.0,
                                'reference_viscosity': 4e-5}}, "law = 'arrhenius'"),
    ({'flow_sensor_gain': {'coefficient': 'big'}}, "coefficient = 'big'"),
    ({'flow_sensor_gain': {'coefficient': 0.9}}, r'coefficient = 0.9'),
    ({'speed_sensor_gain': {'coefficient': -0.5}}, r'coefficient = -0.5'),
    ({'channel:aux': {'coefficient': 1.0, 'reference': 0.0, 'regressor': 'other'}},
     'reads its own channel'),
    ({'flow_sensor_gain': 0.1}, 'must be a mapping'),
    ({'flow_sensor_gain': {'coefficient': 0.1, 'colour': 'red'}}, 'unknown key.*colour'),
    ({'external_leakage': {'coefficient': 3e-12, 'regressor': 'p_case'}},
     'differs from coefficients.external_leakage'),
])
def test_bad_effect_blocks_are_refused_naming_the_key(effects, match):
    doc = copy.deepcopy(BASE)
    doc['coefficient_sets']['oil']['effects'] = effects
    with pytest.raises(ConfigError, match=match):
        motor_from_mapping(doc)


def test_packaged_config_has_no_effects():
    assert load_motor().sets['oil'].effects == () and OIL.channels == ()
    assert WATER.true_flow(1.0) == 1.0 and WATER.true_speed(2.0) == 2.0


def test_dp_of_a_chamber_drop_point_includes_the_channel_drop_of_the_extra_flow():
    model = model_with('oil', EFFECTS['channel:aux'][0])
    pt = model.absorbency_point(600 * RPM, dp_i=15 * MPA, channels={'aux': 3.0})
    back = model.absorbency_point(600 * RPM, pt.dp, channels={'aux': 3.0})
    assert back.flow == pytest.approx(pt.flow, rel=1e-9)
    assert back.dp_i == pytest.approx(15 * MPA, rel=1e-9)


def test_flags_of_the_point_survive_the_extra_loss():
    model = model_with('oil', EFFECTS['term:dp^2*n'][0])
    slow = model.absorbency_point(50 * RPM, 10 * MPA)  # below the validated 100 rpm
    assert slow.status == PointStatus.EXTRAPOLATED
    assert model.speed_point(slow.flow, 10 * MPA).status == PointStatus.EXTRAPOLATED
    bare = OIL.speed_point(40 * LPM, 0.05 * MPA)
    limited = model.speed_point(40 * LPM, 0.05 * MPA)  # the channels take the whole drop
    assert bare.status & PointStatus.CHANNEL_LIMITED and limited.dp_i == 0.0
    assert limited.status == bare.status
    assert limited.speed == pytest.approx(bare.speed, rel=1e-12)
    forward = model.absorbency_point(600 * RPM, 0.05 * MPA)
    assert forward.status & PointStatus.CHANNEL_LIMITED and forward.dp_i == 0.0


def test_an_extra_loss_without_a_root_is_flagged_not_returned():
    gain = model_with('oil', {'term:n^2': {'coefficient': -2e-8}})  # Q(n) turns back down
    pt = gain.speed_point(60 * LPM, 10 * MPA)
    assert pt.status == PointStatus.NO_ROOT and math.isnan(pt.speed)
    ok = gain.speed_point(2 * LPM, 10 * MPA)
    assert not ok.status & INVALID and balance(gain, ok) < 1e-9
    # eq. (39) has no answer between n = 0 and its speed floor: a flow just above the losses
    # at rest has no root with or without the effect
    empirical = MotorModel.from_spec(motor_from_mapping(_doc_with(
        'oil', {'term:dp^0.5': {'coefficient': 1e-12}})), 'oil', displacement_law='eq39')
    at_rest = empirical.breakdown_point(0.0, 20 * MPA).total
    assert empirical.speed_point(1.001 * at_rest, dp_i=20 * MPA).status == PointStatus.NO_ROOT
    assert empirical.speed_point(0.999 * at_rest, dp_i=20 * MPA).status & PointStatus.STALLED


def test_wear_beyond_any_clearance_is_beyond_the_limit():
    wear = model_with('oil', EFFECTS['clearance_wear'][0])
    pt = wear.speed_point(10 * LPM, 10 * MPA, channels={'revolutions': 1e9})
    assert pt.status == PointStatus.BEYOND_LIMIT and math.isnan(pt.speed)


def test_root_search_stops_on_nan_and_converges_fast():
    calls = []

    def cubic(x):
        calls.append(x)
        return x ** 3 - 2.0

    # the effects' residuals have no derivative: the solver steps along the secant
    root, status = solve_increasing_scalar(with_secant_slope(cubic, 4.0, 62.0), 0.0, 4.0, 2.0,
                                           Tolerance(0.0, 1e-15))
    assert status == 0 and root == pytest.approx(2.0 ** (1 / 3), rel=1e-15) and len(calls) < 40
    _, status = solve_increasing_scalar(with_secant_slope(lambda x: math.nan, 1.0, 1.0), 0.0,
                                        1.0, 0.5, Tolerance(0.0, 1e-15))
    assert status == PointStatus.NO_ROOT


def test_water_follows_the_vogel_law():
    model = model_with('water', {'viscosity_temperature': {
        'coefficient': 247.8, 'law': 'vogel', 'reference_temperature': 20.0,
        'reference_viscosity': 1.0e-6, 'vogel_c': 140.0}})
    nu = float(vogel_viscosity(45.0, 20.0, 1.0e-6, 247.8, 140.0))
    thin = MotorModel(WATER.geometry, WATER.coefficient_set, WATER.valid_range,
                      WATER.liquid.__class__('w', nu, WATER.liquid.density,
                                             WATER.liquid.bulk_modulus))
    got = model.breakdown_point(600 * RPM, 10 * MPA, channels={'temperature': 45.0})
    assert got.commutation == thin.breakdown_point(600 * RPM, 10 * MPA).commutation
    assert 0.58e-6 < nu < 0.62e-6  # water at 45 degC: about 0.60 mm^2/s


def test_flow_reading_inverts_true_flow():
    for block in ({'flow_sensor_gain': {'coefficient': 0.05}},
                  {'flow_sensor_offset': {'coefficient': 2e-5}}):
        model = model_with('oil', block)
        assert flow_reading(model.effects, model.true_flow(3e-4)) == pytest.approx(3e-4)
        assert flow_reading(model.effects, 3e-4) != 3e-4


def test_without_a_leakage_effect_p_ex_drives_eq_24_on_both_paths():
    model = model_with('oil', EFFECTS['term:dp^2*n'][0], external_leakage=1e-12)
    speed = np.array([300.0, 900.0]) * RPM
    p_ex = np.array([0.5, 2.0]) * MPA
    forward = model.absorbency(speed, 10 * MPA, p_ex=p_ex)
    inverse = model.speed(forward.flow, 10 * MPA, p_ex=p_ex)
    np.testing.assert_allclose(inverse.speed, speed, rtol=1e-9)
    for i in range(2):
        pt = model.absorbency_point(float(speed[i]), 10 * MPA, p_ex=float(p_ex[i]))
        assert pt.external == pytest.approx(1e-12 * p_ex[i], rel=1e-12)
        assert forward.flow[i] == pt.flow


def test_a_stall_under_eq39_stays_a_stall_with_an_effect():
    doc = _doc_with('oil', {'term:dp^2*n': {'coefficient': 1e-30}})
    model = MotorModel.from_spec(motor_from_mapping(doc), 'oil', displacement_law='eq39')
    bare = MotorModel.default('oil', 'eq39')
    for flow in (0.01 * LPM, 0.3 * LPM, 3 * LPM):
        got, ref = model.speed_point(flow, dp_i=12 * MPA), bare.speed_point(flow, dp_i=12 * MPA)
        assert got.status == ref.status
        assert got.speed == pytest.approx(ref.speed, rel=1e-9, abs=1e-12)
    assert model.speed_point(0.01 * LPM, dp_i=12 * MPA).status & PointStatus.STALLED


def test_effects_that_leave_the_model_are_beyond_its_limit():
    beyond = int(PointStatus.BEYOND_LIMIT)
    gain = model_with('oil', {'channel:x': {'coefficient': 1e-5, 'reference': 0.0}})
    assert gain.absorbency_point(1.0, dp_i=10 * MPA, channels={'x': -1.0}).status == beyond
    assert gain.speed_point(0.0, 10 * MPA, channels={'x': -1.0}).status == beyond  # Q_vl < 0
    steep = model_with('oil', {'channel:x': {'coefficient': 10.0, 'reference': 0.0}})
    assert steep.speed_point(20 * LPM, 10 * MPA, channels={'x': 1e308}).status == beyond
    pump = model_with('oil', {'term:dp^0.5': {'coefficient': -1e-8}})
    assert pump.absorbency_point(1.0, 10 * MPA).status == beyond  # flow out of the inlet
    huge = model_with('oil', {'term:n^2': {'coefficient': 1e-9}})
    masked = huge.absorbency([100.0, 1e160], dp_i=10 * MPA, errors='mask')
    assert int(masked.status[0]) in (0, int(PointStatus.EXTRAPOLATED))
    assert masked.status[1] == beyond
    cold = model_with('water', {'viscosity_temperature': {
        'coefficient': 800.0, 'law': 'vogel', 'reference_temperature': 40.0,
        'reference_viscosity': 46e-6}})
    for t in (-140.0, -273.15):  # at or below the Vogel pole, C = 140 K
        assert cold.speed_point(20 * LPM, 10 * MPA, channels={'temperature': t}).status == beyond
