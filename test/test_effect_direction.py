# SPDX-License-Identifier: Apache-2.0
"""Effects that act for one sign of dp = p_a - p_b: YAML, model, plant and candidates."""

import copy

from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.fit import LossFit
from satmotor_ros.identify.parts import loss_parts
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import ConfigError, INVALID, MotorModel, PointStatus
from satmotor_ros.model.effects import Effect, effect_from_mapping, effect_to_mapping
from satmotor_ros.model.io.config import default_config_path, motor_from_mapping
from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA, RPM
from satmotor_ros.model.viscosity import standard_law
from satmotor_ros.prediction import Combiner, predict, Rule
import yaml

BASE = yaml.safe_load(default_config_path().read_text(encoding='utf-8'))
BARE = MotorModel.default('oil')
VALVE = {'coefficient': 2.0e-10, 'reference': 18.0 * MPA, 'exponent': 1.0}


def model_with(effects):
    doc = copy.deepcopy(BASE)
    doc['coefficient_sets']['oil']['effects'] = effects
    return MotorModel.from_spec(motor_from_mapping(doc), 'oil')


NEGATIVE = model_with({'threshold:dp@negative': {**VALVE, 'direction': 'negative'}})
POSITIVE = model_with({'threshold:dp': {**VALVE, 'direction': 'positive'}})


def test_a_one_sided_effect_round_trips_through_its_yaml_block():
    effect = NEGATIVE.effects[0]
    assert (effect.name, effect.direction, effect.key) == (
        'threshold:dp', 'negative', 'threshold:dp@negative')
    block = effect_to_mapping(effect)
    assert block['direction'] == 'negative'
    assert effect_from_mapping(effect.key, block, 'effects') == effect
    two_sided = effect_from_mapping('threshold:dp', VALVE, 'effects')
    assert two_sided.direction == 'both' and effect_to_mapping(two_sided)['direction'] == 'both'


def test_both_sides_may_differ_but_may_not_overlap():
    model = model_with({'threshold:dp@negative': {**VALVE, 'direction': 'negative'},
                        'threshold:dp@positive': {**VALVE, 'reference': 22.0 * MPA}})
    assert sorted(e.direction for e in model.effects) == ['negative', 'positive']
    with pytest.raises(ConfigError, match='more than one threshold:dp'):
        model_with({'threshold:dp': VALVE, 'threshold:dp@negative': VALVE})


@pytest.mark.parametrize(('key', 'block', 'match'), [
    ('threshold:dp', {**VALVE, 'direction': 'down'}, 'direction'),
    ('threshold:dp@negative', {**VALVE, 'direction': 'positive'}, '@negative'),
    ('threshold:dp@both', VALVE, '@both'),
    ('flow_sensor_gain', {'coefficient': 0.01, 'direction': 'negative'}, 'unknown key'),
    ('clearance_wear@negative', {'coefficient': 1e-9, 'regressor': 'time',
                                 'reference': 0.0}, 'acts in both directions'),
])
def test_a_bad_direction_is_refused_naming_it(key, block, match):
    with pytest.raises(ConfigError, match=match):
        effect_from_mapping(key, block, 'effects')


@settings(max_examples=60, deadline=None)
@given(speed=st.floats(20.0, 2000.0), drop=st.floats(1.0, 30.0),
       quadrant=st.sampled_from([(1, 1), (-1, -1), (-1, 1), (1, -1)]))
def test_a_one_sided_valve_acts_on_its_side_only_point_equal_to_array(speed, drop, quadrant):
    n, dp = quadrant[0] * speed * RPM, quadrant[1] * drop * MPA
    for model, side in ((NEGATIVE, -1), (POSITIVE, 1)):
        point = model.absorbency_point(n, dp)
        bare = BARE.absorbency_point(n, dp)
        array = model.absorbency(np.array([n, n]), np.array([dp, dp]), errors='mask')
        assert array.flow[0] == point.flow or point.flow != point.flow
        assert array.status[0] == point.status
        if quadrant[1] != side or abs(dp) <= VALVE['reference']:
            assert point.flow == pytest.approx(bare.flow, rel=1e-12, abs=1e-15)
        elif not point.status & int(PointStatus.NO_ROOT | PointStatus.BEYOND_LIMIT):
            # the valve passes flow from the high- to the low-pressure port
            assert (point.flow - bare.flow) * side > 0.0
        back = model.speed_point(point.flow, dp)
        # where the leak outgrows a pump's displacement the flow no longer tells the speed
        if point.flow * n > 0.0 and back.speed == back.speed:
            assert back.speed == pytest.approx(n, rel=1e-7, abs=1e-6)
            assert model.speed(np.array([point.flow]), np.array([dp]),
                               errors='mask').speed[0] == back.speed


def _four_quadrants(model, rng, count=600):
    """Rows over the four quadrants (|dp| to 28 MPa), the flow of `model` plus noise."""
    speed = rng.uniform(150.0, 1500.0, count) * RPM * rng.choice([-1.0, 1.0], count)
    dp = rng.uniform(2.0, 28.0, count) * MPA * rng.choice([-1.0, 1.0], count)
    flow = model.absorbency(speed, dp, errors='mask').flow
    keep = np.isfinite(flow)
    flow = flow + rng.normal(0.0, 0.02 * LPM, count)
    p_out = np.full(count, 0.5 * MPA) + np.maximum(-dp, 0.0)
    return BenchTable(speed[keep], flow[keep], (p_out + dp)[keep], p_out[keep],
                      source='<four quadrants>')


def test_the_one_sided_candidate_finds_the_side_and_the_crack_pressure():
    table = _four_quadrants(NEGATIVE, np.random.default_rng(3))
    parts, _ = loss_parts(BARE, table)
    candidates, _ = build_library(parts, {}, standard_law(BARE.liquid, 'oil'))
    valves = {c.direction: c for c in candidates if c.effect == 'threshold:dp'}
    assert set(valves) == {'both', 'positive', 'negative'}
    fits = {d: LossFit([c], sigma=0.02 * LPM).fit(parts) for d, c in valves.items()}
    best = min(fits, key=lambda d: fits[d].rss_)
    assert best == 'negative'
    assert fits['negative'].rss_ < 0.2 * fits['both'].rss_
    effect = fits['negative'].found()[-1][1]
    assert effect.direction == 'negative' and effect.key == 'threshold:dp@negative'
    assert effect.reference == pytest.approx(VALVE['reference'], rel=0.05)


def test_one_direction_of_data_offers_no_one_sided_candidate():
    table = _four_quadrants(BARE, np.random.default_rng(4))
    forward = table.dp > 0.0
    table = BenchTable(table.speed[forward], table.flow[forward], table.p_in[forward],
                       table.p_out[forward])
    parts, _ = loss_parts(BARE, table)
    candidates, _ = build_library(parts, {}, standard_law(BARE.liquid, 'oil'))
    assert [c.direction for c in candidates if c.effect == 'threshold:dp'] == ['both']


def test_on_data_of_one_sign_the_valve_may_crack_near_the_top():
    # a relief cracking above 94 % of the rows: the threshold must reach beyond the 85 %
    # quantile, where a valve on both sides of two-sided data stops
    crack = 26.5 * MPA
    table = _four_quadrants(model_with({'threshold:dp': {**VALVE, 'reference': crack}}),
                            np.random.default_rng(5), 800)
    forward = table.dp > 0.0
    table = BenchTable(table.speed[forward], table.flow[forward], table.p_in[forward],
                       table.p_out[forward])
    parts, _ = loss_parts(BARE, table)
    assert np.mean(parts.dp > crack) < 0.08
    candidates, _ = build_library(parts, {}, standard_law(BARE.liquid, 'oil'))
    valve = next(c for c in candidates if c.effect == 'threshold:dp')
    fit = LossFit([valve], sigma=0.02 * LPM).fit(parts)
    assert not fit.pinned(effects_only=True)
    assert fit.found()[-1][1].reference == pytest.approx(crack, rel=0.02)


def test_a_one_sided_term_acts_where_its_direction_says():
    model = model_with({'term:dp@positive': {'coefficient': 1e-9, 'direction': 'positive'}})
    assert model.absorbency_point(-500 * RPM, -10 * MPA).flow == pytest.approx(
        BARE.absorbency_point(-500 * RPM, -10 * MPA).flow, rel=1e-12)
    assert model.absorbency_point(500 * RPM, 10 * MPA).flow > BARE.absorbency_point(
        500 * RPM, 10 * MPA).flow


def test_the_outflow_port_drives_the_outlet_leakage_in_reverse():
    k = 3e-12
    doc = copy.deepcopy(BASE)
    doc['coefficient_sets']['oil']['coefficients']['external_leakage'] = k
    doc['coefficient_sets']['oil']['effects'] = {
        'external_leakage': {'regressor': 'p_out', 'coefficient': k}}
    model = MotorModel.from_spec(motor_from_mapping(doc), 'oil')
    assert model.channels == ('p_in', 'p_out')
    ports = {'p_in': 2.0 * MPA, 'p_out': 12.0 * MPA}  # port A low: the flow leaves by A
    backwards = model.absorbency_point(-800 * RPM, -10 * MPA, channels=ports)
    assert backwards.external == pytest.approx(-k * ports['p_in'], rel=1e-9)
    forward = model.absorbency_point(800 * RPM, 10 * MPA,
                                     channels={'p_in': 12.0 * MPA, 'p_out': 2.0 * MPA})
    assert forward.external == pytest.approx(k * 2.0 * MPA, rel=1e-9)
    assert backwards.flow == pytest.approx(-forward.flow, rel=1e-12)


def test_a_one_sided_effect_is_written_by_key_and_loads():
    doc = copy.deepcopy(BASE)
    doc['coefficient_sets']['oil']['effects'] = {
        e.key: effect_to_mapping(e) for e in (Effect('threshold:dp', 1e-10, 'dp', 1e7,
                                                     options=(('exponent', 1.5),),
                                                     direction='negative'),)}
    spec = motor_from_mapping(yaml.safe_load(yaml.safe_dump(doc)))
    (effect,) = spec.sets['oil'].effects
    assert (effect.direction, effect.option('exponent')) == ('negative', 1.5)


@settings(max_examples=40, deadline=None)
@given(speed=st.floats(200.0, 2000.0), drop=st.floats(19.0, 28.0),
       quadrant=st.sampled_from([(1, 1), (-1, -1), (-1, 1), (1, -1)]))
def test_the_valve_opens_on_the_port_drop_beside_the_motor(speed, drop, quadrant):
    """Q = Q_motor(n, dp) + k (|dp| - x_c) on the port drop, whichever drop is given."""
    n, dp = quadrant[0] * speed * RPM, quadrant[1] * drop * MPA
    both = model_with({'threshold:dp': VALVE})
    point, motor = both.absorbency_point(n, dp), BARE.absorbency_point(n, dp)
    valve = np.sign(dp) * VALVE['coefficient'] * (abs(dp) - VALVE['reference'])
    if point.status & int(INVALID) or motor.status & int(INVALID):
        return
    assert point.flow == pytest.approx(motor.flow + valve, rel=1e-12, abs=1e-15)
    assert point.total == pytest.approx(motor.total + valve, rel=1e-12, abs=1e-15)
    assert (point.dp, point.dp_i) == (motor.dp, motor.dp_i)  # the valve's flow skips the channels
    chamber = both.absorbency_point(n, dp_i=point.dp_i)
    assert chamber.flow == pytest.approx(point.flow, rel=1e-9)
    back = both.speed_point(point.flow, dp_i=point.dp_i)
    if motor.flow * n > 0.0:  # motor mode: the flow tells the speed
        assert back.speed == pytest.approx(n, rel=1e-7)
        assert back.dp == pytest.approx(dp, rel=1e-9)


def test_a_set_of_valves_only_maps_arrays_through_the_point_path():
    model = model_with({'threshold:dp@negative': {**VALVE, 'direction': 'negative'}})
    speed = np.array([800.0, -800.0, -800.0]) * RPM
    dp = np.array([25.0, -25.0, -10.0]) * MPA
    array = model.absorbency(speed, dp)
    points = [model.absorbency_point(float(n), float(d)) for n, d in zip(speed, dp)]
    assert list(array.flow) == [p.flow for p in points]
    assert array.flow[1] < BARE.absorbency_point(-800 * RPM, -25 * MPA).flow
    flows = model.speed(array.flow, dp)
    assert np.allclose(flows.speed, speed, rtol=1e-7)


def test_the_prediction_motor_model_publishes_applies_the_valve_on_its_side_only():
    """What the motor_model node computes: the valve acts where p_b > p_a only."""
    rule = Rule(timeout=0.5)
    valve = model_with({'threshold:dp@negative': {**VALVE, 'coefficient': 5e-12,
                                                  'direction': 'negative'}})
    speeds = {}
    for model in (valve, BARE):
        for sign in (1.0, -1.0):
            combiner = Combiner(rule)
            high, low = 25 * MPA + ATMOSPHERE, 0.5 * MPA + ATMOSPHERE
            combiner.update('p_in', high if sign > 0 else low, 0)
            combiner.update('p_out', low if sign > 0 else high, 0)
            combiner.update('flow', sign * 20 * LPM, 1_000_000)
            pred = predict(model, combiner.snapshot(1_000_000), rule.timeout)
            speeds[model is valve, sign] = pred.output('speed')
    assert speeds[True, 1.0] == speeds[False, 1.0]
    assert 0.9 * abs(speeds[False, -1.0]) < abs(speeds[True, -1.0]) < abs(speeds[False, -1.0])
