# SPDX-License-Identifier: Apache-2.0
"""Every family wears, one-sided leaks act one way: model, plant and calibration agree."""

import dataclasses

import numpy as np
import pytest
from satmotor_ros.identify.pipeline import calibrate, Options
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import ConfigError, MotorModel
from satmotor_ros.model.effects import check_effects, Effect, effect_from_mapping
from satmotor_ros.model.families import FAMILY_NAMES
from satmotor_ros.model.families.defaults import default_motor
from satmotor_ros.model.motor import with_effects
from satmotor_ros.model.units import CM3_PER_REV, LPM, MPA, RPM
from satmotor_ros.plant import ConstantLoad, Plant, PlantParams
from satmotor_ros.plant.config import params_from_flat

WEAR = {'sliwinski2017': 'clearance_wear', 'balawender': 'leakage_wear',
        'paszota': 'leakage_wear'}
RATE = {'clearance_wear': 2.0e-10, 'leakage_wear': 2.0e-4}  # per revolution
PLANT = {'clearance_wear': 1.0e-8, 'leakage_wear': 8.0e-3}  # per revolution, a fast wear


def _model(family):
    return MotorModel.from_spec(default_motor(family, 8.0 * CM3_PER_REV), 'oil')


@pytest.mark.parametrize('family', ['balawender', 'paszota'])
def test_leakage_wear_scales_the_family_leakage_with_revolutions(family):
    model = _model(family)
    worn = with_effects(model, [Effect('leakage_wear', 1e-3, 'revolutions', 100.0)])
    assert worn.channels == ('revolutions',)
    n, dp = 1500 * RPM, 12 * MPA
    new = worn.absorbency_point(n, dp, channels={'revolutions': 50.0})
    assert new.flow == model.absorbency_point(n, dp).flow  # before the reference: unworn
    old = worn.absorbency_point(n, dp, channels={'revolutions': 1100.0})  # leakage x 2
    doubled = dataclasses.replace(model.coefficient_set, coefficients=model.family.scaled(
        model.coef, dict.fromkeys(model.family.leakage, 2.0)))
    twice = MotorModel(model.geometry, doubled, model.valid_range, model.liquid)
    assert old.flow == pytest.approx(twice.absorbency_point(n, dp).flow, rel=1e-12)
    assert old.total > model.absorbency_point(n, dp).total
    back = worn.speed_point(old.flow, dp, channels={'revolutions': 1100.0})
    assert back.speed == pytest.approx(n, rel=1e-9)
    signed = worn.absorbency_point(-n, -dp, channels={'revolutions': 1100.0})
    assert signed.flow == pytest.approx(-old.flow, rel=1e-12)


@pytest.mark.parametrize(('kind', 'family'), [('leakage_wear', 'sliwinski2017'),
                                              ('clearance_wear', 'paszota')])
def test_each_wear_kind_is_refused_for_the_families_it_does_not_fit(kind, family):
    effect = effect_from_mapping(kind, {'coefficient': 1e-4, 'regressor': 'time',
                                        'reference': 0.0}, 'effects')
    with pytest.raises(ConfigError, match=f'{kind} applies to the'):
        check_effects([effect], 'effects', family)


@pytest.mark.parametrize('family', FAMILY_NAMES)
def test_the_plant_injects_wear_for_every_family(family):
    model = _model(family)
    kind = WEAR[family]
    params = params_from_flat({f'effects.{kind}': PLANT[kind]})
    worn = Plant(model, PlantParams(effects=params.effects), load=ConstantLoad(10.0))
    new = Plant(model, PlantParams(), load=ConstantLoad(10.0))
    for plant in (worn, new):
        plant.run(3000, 20 * LPM)
    assert worn.rebuilds >= 1
    assert worn.state.speed < new.state.speed  # a worn motor leaks more of the flow


def _worn_table(model, kind, seed=5, count=160):
    """Steady points in time order; the flow of the motor wearing by `kind` plus noise."""
    rng = np.random.default_rng(seed)
    speed = rng.uniform(300.0, 2500.0, count) * RPM
    dp = rng.uniform(3.0, 20.0, count) * MPA
    revolutions = np.linspace(0.0, 4000.0, count)
    worn = with_effects(model, [Effect(kind, RATE[kind], 'revolutions', 0.0)])
    flow = worn.absorbency(speed, dp, errors='mask',
                           channels={'revolutions': revolutions}).flow
    flow = flow + rng.normal(0.0, 0.01 * LPM, count)
    return BenchTable(speed, flow, dp + 0.5 * MPA, np.full(count, 0.5 * MPA),
                      {'revolutions': revolutions}, {'revolutions': 'rev'}, '<worn>')


@pytest.mark.parametrize('family', FAMILY_NAMES)
def test_calibration_finds_the_wear_of_every_family(family):
    model = _model(family)
    kind = WEAR[family]
    spec = default_motor(family, 8.0 * CM3_PER_REV)
    cal = calibrate(_worn_table(model, kind), 'oil', spec=spec,
                    options=Options(compare_families=False, mode='points'))
    found = cal.effects()
    assert found and found[0].kind == kind and found[0].regressor == 'revolutions'
    assert found[0].coefficient == pytest.approx(RATE[kind], rel=0.5)
    assert cal.effect_rows()[0]['p_value'] < 1e-6


def test_the_plant_opens_a_one_sided_valve_in_its_direction_only():
    model = MotorModel.default('oil')
    valve = params_from_flat({'effects.valve_conductance': 2e-11, 'effects.valve_crack': 1e6,
                              'effects.valve_direction': 'negative'}).effects
    assert valve[0].direction == 'negative' and valve[0].key == 'threshold:dp@negative'
    speeds = {}
    for name, effects in (('valve', valve), ('none', ())):
        for command in (20 * LPM, -20 * LPM):
            plant = Plant(model, PlantParams(effects=effects), load=ConstantLoad(40.0))
            plant.run(3000, command)
            speeds[name, command > 0] = plant.state.speed
    assert speeds['valve', True] == pytest.approx(speeds['none', True], rel=1e-9)
    assert abs(speeds['valve', False]) < 0.98 * abs(speeds['none', False])


def test_the_plant_s_outlet_leakage_follows_the_flow_in_reverse():
    k = 1.0e-12
    leak = params_from_flat({'effects.external_leakage': k,
                             'effects.leakage_driver': 'outlet'}).effects
    for command, load in ((20 * LPM, 60.0), (-20 * LPM, -60.0)):
        plant = Plant(MotorModel.default('water'), PlantParams(effects=leak),
                      load=ConstantLoad(load))
        plant.run(1500, command)
        state, tank = plant.state, plant.params.lines.tank_pressure
        outflow = state.outlet_pressure if command > 0 else state.inlet_pressure
        assert plant.flows.leakage == pytest.approx(k * (outflow - tank), rel=1e-9)
        assert abs(state.inlet_pressure - state.outlet_pressure) > 5 * MPA
