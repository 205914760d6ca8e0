# SPDX-License-Identifier: Apache-2.0
"""Each effect and sensor error changes what it should and nothing else; sensors are seeded."""

import dataclasses
import math

import numpy as np
import pytest

from satmotor_ros.model import MotorModel
from satmotor_ros.model.effects import Effect
from satmotor_ros.model.units import LPM
from satmotor_ros.model.viscosity import ViscosityLaw
from satmotor_ros.plant import (ConstantLoad, Plant, PlantParams, SensorParams, SensorSet,
                                ThermalParams)
from satmotor_ros.plant.config import params_from_flat

MODEL = MotorModel.default('water')
FLOW = 20.0 * LPM
LOAD = 60.0
STEPS = 1500


def _effects(**values):
    """Return the effects the virtual_motor node parameters ``effects.<name>`` inject."""
    return params_from_flat({f'effects.{k}': v for k, v in values.items()}).effects


def _run(effects=(), thermal=None, sensors=None, seed=0):
    params = PlantParams(effects=effects, thermal=thermal or ThermalParams(),
                         sensors=sensors or SensorSet(), seed=seed)
    plant = Plant(MODEL, params, load=ConstantLoad(LOAD))
    readings = []
    for _ in range(STEPS // 100):
        plant.run(100, FLOW)
        readings.append(plant.measure())
    return plant, readings


BASE, BASE_READINGS = _run()


def test_no_effect_is_on_by_default_and_sensors_read_the_truth():
    """Default plant: no rebuilds, no leakage, every reading equals the state."""
    assert BASE.rebuilds == 0
    assert BASE.flows.leakage == 0.0
    last, state = BASE_READINGS[-1], BASE.state
    assert last.speed == state.speed and last.inlet_pressure == state.inlet_pressure
    assert last.flow == pytest.approx(BASE.flows.motor, rel=1e-12)
    assert last.temperature == state.temperature


@pytest.mark.parametrize(('field', 'value', 'channel'), [
    ('flow_sensor_offset', 0.5 * LPM, 'flow'),
    ('flow_sensor_gain', 0.03, 'flow'),
    ('speed_sensor_gain', -0.02, 'speed'),
])
def test_sensor_errors_change_only_their_reading(field, value, channel):
    """The state is bit-identical; one channel reads gain*(1+e)*x + offset; the others true."""
    plant, readings = _run(_effects(**{field: value}))
    assert plant.state == BASE.state
    for got, true in zip(readings, BASE_READINGS):
        for name in got._fields:
            if name != channel:
                assert getattr(got, name) == getattr(true, name), name
        expected = getattr(true, channel)
        if field.endswith('offset'):
            expected += value
        else:
            expected *= 1.0 + value
        assert getattr(got, channel) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize('driver', ['case', 'outlet'])
def test_external_leakage_takes_k_times_the_driving_pressure_past_the_model(driver):
    """Q_x = k p_driver leaves the inlet line: the flowmeter reads the model's Q plus Q_x."""
    k = 1.0e-12
    plant, readings = _run(_effects(external_leakage=k, leakage_driver=driver))
    state, flows = plant.state, plant.flows
    tank = plant.params.lines.tank_pressure
    drive = (plant.case_pressure() if driver == 'case' else state.outlet_pressure) - tank
    assert flows.leakage == pytest.approx(k * drive, rel=1e-12)
    assert flows.leakage > 0.0
    dp = state.inlet_pressure - state.outlet_pressure
    model_flow = float(MODEL.absorbency(state.speed, dp).flow)
    assert readings[-1].flow == pytest.approx(model_flow + k * drive, rel=1e-6)
    assert state.speed < BASE.state.speed  # less flow reaches the displacement
    assert plant.rebuilds == 0 and plant.model is MODEL


def test_viscosity_follows_temperature_and_rebuilds_the_model():
    """Hot water is thinner: nu follows Vogel's law through T_ref; more leakage, lower speed."""
    thermal = ThermalParams(initial=70.0, reference=40.0, heat_capacity=1.0e3)
    slope = 247.8  # Vogel B of water [K]
    plant, _ = _run(_effects(viscosity_temperature=slope), thermal)
    cold, _ = _run(thermal=thermal)  # same heat, effect off
    law = ViscosityLaw('vogel', 40.0, MODEL.liquid.kinematic_viscosity)
    nu_law = float(law.viscosity(plant.state.temperature, slope))
    assert plant.model.liquid.kinematic_viscosity == pytest.approx(nu_law, rel=0.006)
    assert nu_law < 0.75 * MODEL.liquid.kinematic_viscosity
    assert plant.rebuilds >= 1
    assert cold.rebuilds == 0
    assert plant.state.speed < cold.state.speed
    assert plant.model.geometry == MODEL.geometry  # nothing else about the motor changed


def test_clearance_wear_grows_both_clearances_with_revolutions():
    """h_R and h_S grow by rate*revolutions (within the rebuild tolerance); speed drops."""
    rate = 1.0e-8
    plant, _ = _run(_effects(clearance_wear=rate))
    revolutions = plant.state.angle / (2.0 * math.pi)  # the shaft never turned back
    grown = plant.model.geometry.clearance_rotor - MODEL.geometry.clearance_rotor
    h0 = 0.5 * (MODEL.geometry.clearance_rotor + MODEL.geometry.clearance_satellites)
    assert grown == pytest.approx(rate * revolutions, abs=0.005 * h0)
    assert plant.model.geometry.clearance_satellites - MODEL.geometry.clearance_satellites \
        == pytest.approx(grown)
    assert plant.rebuilds >= 2
    assert plant.state.speed < BASE.state.speed
    assert plant.model.liquid == MODEL.liquid


def test_sensor_noise_is_seeded_and_has_the_configured_spread():
    """Same seed, same readings; another seed differs; the spread matches the setting."""
    noisy = SensorSet(inlet_pressure=SensorParams(noise=1.0e4))
    first = [r.inlet_pressure for r in _run(sensors=noisy, seed=7)[1]]
    again = [r.inlet_pressure for r in _run(sensors=noisy, seed=7)[1]]
    other = [r.inlet_pressure for r in _run(sensors=noisy, seed=8)[1]]
    assert first == again and first != other
    plant = Plant(MODEL, PlantParams(sensors=noisy, seed=3))
    plant.run(10, 0.0)
    reads = np.array([plant.measure().inlet_pressure for _ in range(4000)])
    assert reads.std() == pytest.approx(1.0e4, rel=0.05)
    assert reads.mean() == pytest.approx(plant.state.inlet_pressure, abs=1.0e3)


def test_sensor_bias_gain_and_rate_sample_and_hold():
    """Reading = gain*x + bias, refreshed only every 1/rate seconds."""
    sensors = SensorSet(speed=SensorParams(bias=0.5, gain=2.0, rate=100.0))
    plant = Plant(MODEL, PlantParams(sensors=sensors), load=ConstantLoad(10.0))
    reads, truth = [], []
    for _ in range(200):
        plant.step(FLOW)
        reads.append(plant.measure().speed)
        truth.append(plant.state.speed)
    changes = [i for i in range(1, 200) if reads[i] != reads[i - 1]]
    assert changes and all(b - a == 10 for a, b in zip(changes, changes[1:]))
    for i in changes:
        assert reads[i] == pytest.approx(2.0 * truth[i] + 0.5, rel=1e-12)


def test_effect_records_are_frozen():
    """Parameters cannot change under a running plant."""
    with pytest.raises(dataclasses.FrozenInstanceError):
        _effects(external_leakage=1e-12)[0].coefficient = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        PlantParams().effects = ()


def test_flat_parameter_table_round_trips_and_names_bad_values():
    """Every dotted name maps to a field with unit and range; bad values name the field."""
    from satmotor_ros.plant.config import flat_from_params, parameter_specs, params_from_flat
    specs = {s.name: s for s in parameter_specs()}
    assert specs['lines.inlet_volume'].unit == 'm^3'
    assert specs['sensors.flow.noise'].unit == 'm^3/s'
    assert specs['effects.external_leakage'].low == 0.0
    assert all(s.description and s.unit for s in specs.values())
    params = params_from_flat({'effects.external_leakage': 1e-12, 'sensors.speed.rate': 50.0})
    assert params.effects == (Effect('external_leakage', 1e-12, 'p_case'),)
    assert params.sensors.speed.rate == 50.0
    assert params_from_flat(flat_from_params(params)) == params
    with pytest.raises(Exception, match=r'ShaftParams.inertia = -1'):
        params_from_flat({'shaft.inertia': -1.0})
    with pytest.raises(Exception, match='unknown plant parameter'):
        params_from_flat({'shaft.mass': 1.0})


def test_reconfigure_keeps_the_state_and_applies_the_new_parameters():
    """A new liquid or effect takes hold from the next step without a jump in the state."""
    plant, _ = _run()
    before = plant.state
    plant.reconfigure(dataclasses.replace(plant.params, effects=_effects(
        flow_sensor_offset=1e-5)), MotorModel.default('oil'))
    assert plant.state == before
    assert plant.model.liquid.name != MODEL.liquid.name
    plant.step(FLOW)
    assert plant.measure().flow == pytest.approx(plant.flows.motor + 1e-5, rel=1e-12)
