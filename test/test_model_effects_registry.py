# SPDX-License-Identifier: Apache-2.0
"""One effect kind, one file: a kind registered alone reaches the model, plant, data and fit."""

import importlib

import numpy as np
import pytest
from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.parts import loss_parts
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model.effects import (Effect, effect_from_mapping, effect_to_mapping, EffectKind,
                                        KINDS, PlantParameter, ranked, register, unregister)
from satmotor_ros.model.motor import with_effects
from satmotor_ros.model.units import LPM
from satmotor_ros.model.viscosity import standard_law
from satmotor_ros.plant import ConstantLoad, Plant
from satmotor_ros.plant.config import parameter_specs, params_from_flat
import yaml

K = 2.0e-11  # coefficient of the test kind [m^3/s/(rad/s)^3]


class CubicSpeedLoss(EffectKind):
    """A kind no shipped file has: an extra loss k n^3, defined only here."""

    name = 'cubic_speed_loss'
    unit = 'm^3/s/(rad/s)^3'
    source = 'test'
    evaluation = 'extra loss k n^3 in Q_vl'
    plant_parameters = (PlantParameter('cubic_speed_loss', 0.0, 'k of the test loss',
                                       'm^3/s/(rad/s)^3', 0.0, 1.0e-8),)

    def loss(self, effect):
        """Return k n^3."""
        k = effect.coefficient
        return lambda n, dp_i: k * n ** 3

    def from_plant(self, values):
        """Return the effect of the node parameter, None at 0."""
        k = values['cubic_speed_loss']
        return Effect(self.name, k) if k else None

    def plant_values(self, effect):
        """Return the node parameter of `effect`."""
        return {'cubic_speed_loss': 0.0 if effect is None else effect.coefficient}


@pytest.fixture
def cubic():
    """Register the test kind for one test."""
    kind = register(CubicSpeedLoss())
    try:
        yield kind
    finally:
        unregister(kind.name)
    assert 'cubic_speed_loss' not in KINDS


def test_shipped_kinds_are_found_one_per_file():
    """Every shipped kind is registered from its own module, in the library's order."""
    names = [k.name for k in ranked()]
    assert names == ['flow_sensor_offset', 'flow_sensor_gain', 'speed_sensor_gain',
                     'external_leakage', 'viscosity_temperature', 'clearance_wear',
                     'leakage_wear', 'channel',
                     'reverse_loss', 'term', 'threshold']
    for name in names:  # each from the file named after it
        assert importlib.import_module(f'satmotor_ros.model.effects.{name}').KIND is KINDS[name]


def test_a_new_kind_reaches_yaml_and_the_model(cubic, tmp_path):
    """The YAML block loads, writes back the same, and the model adds k n^3 to Q_vl."""
    effect = effect_from_mapping('cubic_speed_loss', {'coefficient': K}, 'effects')
    assert effect_from_mapping(effect.name, effect_to_mapping(effect), 'effects') == effect
    doc = yaml.safe_load(open(load_motor().source, encoding='utf-8'))  # the packaged motor
    doc['coefficient_sets']['oil']['effects'] = {'cubic_speed_loss': effect_to_mapping(effect)}
    path = tmp_path / 'motor.yaml'
    path.write_text(yaml.safe_dump(doc))
    model = MotorModel.from_spec(load_motor(path), 'oil')
    base = MotorModel.default('oil')
    speed, dp_i = np.array([50.0, 100.0, 150.0]), np.array([5e6, 10e6, 15e6])
    extra = model.absorbency(speed, dp_i=dp_i).flow - base.absorbency(speed, dp_i=dp_i).flow
    np.testing.assert_allclose(extra, K * speed ** 3, rtol=1e-9)
    point = model.speed_point(30 * LPM, 12e6)  # the inverse map solves with it too
    assert point.status == 0
    assert point.speed < base.speed_point(30 * LPM, 12e6).speed


def test_a_new_kind_is_injected_by_the_plant_through_its_node_parameter(cubic):
    """effects.cubic_speed_loss is a plant parameter; the plant settles on the model with it."""
    spec = {s.name: s for s in parameter_specs()}['effects.cubic_speed_loss']
    assert (spec.unit, spec.low, spec.high) == ('m^3/s/(rad/s)^3', 0.0, 1.0e-8)
    params = params_from_flat({'effects.cubic_speed_loss': K})
    assert params.effects == (Effect('cubic_speed_loss', K),)
    base = MotorModel.default('water')
    plant = Plant(base, params, load=ConstantLoad(60.0))
    plant.run(6000, 20 * LPM)
    state = plant.state
    truth = with_effects(base, params.effects)
    expected = truth.speed_point(20 * LPM, state.inlet_pressure - state.outlet_pressure)
    assert state.speed == pytest.approx(expected.speed, rel=1e-6)
    plain = Plant(base, load=ConstantLoad(60.0))
    plain.run(6000, 20 * LPM)
    assert state.speed < plain.state.speed - 0.3  # the extra loss costs speed


def test_a_new_kind_is_injected_into_synthetic_data_and_offered_as_a_candidate(cubic):
    """Synthetic data carries its loss (scaled to the magnitude); the library offers it."""
    plan = Plan(liquid='oil', n_points=60)
    clean = generate(plan, Injection('none'), seed=3)
    dirty = generate(plan, Injection('cubic_speed_loss', 1.0 * LPM), seed=3)
    extra = dirty.flow - clean.flow
    speed = clean.speed  # same seed: same points and noise
    assert np.max(extra) == pytest.approx(1.0 * LPM, rel=0.05)
    assert np.corrcoef(extra, speed ** 3)[0, 1] > 0.999
    model = MotorModel.default('oil')
    parts, _ = loss_parts(model, dirty)
    library, _ = build_library(parts, dirty.channels, standard_law(model.liquid, 'oil'))
    (candidate,) = [c for c in library if c.effect == 'cubic_speed_loss']
    np.testing.assert_allclose(candidate.modify(K).additive, K * parts.speed ** 3)
    assert candidate.as_effect(K) == Effect('cubic_speed_loss', K)


def test_two_kinds_compose_in_one_coefficient_set(cubic):
    """Effects of several kinds are evaluated together: their losses add up."""
    base = MotorModel.default('oil')
    term = effect_from_mapping('term:dp^2', {'coefficient': 1e-20}, 'effects')
    both = with_effects(base, (Effect('cubic_speed_loss', K), term))
    speed, dp_i = np.array([60.0, 120.0]), np.array([8e6, 16e6])
    extra = both.absorbency(speed, dp_i=dp_i).flow - base.absorbency(speed, dp_i=dp_i).flow
    np.testing.assert_allclose(extra, K * speed ** 3 + 1e-20 * dp_i ** 2, rtol=1e-9)
