# SPDX-License-Identifier: Apache-2.0
"""The plant in reverse: a negative command turns the shaft backwards, relief on either line."""

import math

import pytest

from satmotor_ros.model import MotorModel
from satmotor_ros.model.effects import Effect
from satmotor_ros.model.motor import with_effects
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.plant import ConstantLoad, Plant, PlantParams, ShaftParams
from test_plant_physics import _settle

MODELS = {name: MotorModel.default(name) for name in ('oil', 'water')}


@pytest.mark.parametrize('liquid', ['oil', 'water'])
@pytest.mark.parametrize('flow_lpm', [3.0, 30.0])
def test_a_negative_command_settles_on_the_mirror_of_the_positive_one(liquid, flow_lpm):
    model = MODELS[liquid]
    ahead = _settle(Plant(model, load=ConstantLoad(60.0)), flow_lpm * LPM)
    plant = Plant(model, load=ConstantLoad(60.0))
    back = _settle(plant, -flow_lpm * LPM)
    assert back.speed == pytest.approx(-ahead.speed, rel=1e-8) and back.speed < 0.0
    assert back.inlet_pressure == pytest.approx(ahead.outlet_pressure, rel=1e-8)
    assert back.outlet_pressure == pytest.approx(ahead.inlet_pressure, rel=1e-8)
    dp = back.inlet_pressure - back.outlet_pressure
    assert back.speed == pytest.approx(float(model.speed(-flow_lpm * LPM, dp).speed), rel=1e-8)
    assert plant.chamber_pressure_drop < 0.0
    f = plant.flows
    assert f.command == pytest.approx(-flow_lpm * LPM) and f.motor == pytest.approx(f.command)
    assert f.returned == pytest.approx(flow_lpm * LPM, rel=1e-8)  # out of line A


@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_the_relief_valve_of_line_b_holds_a_reversed_blocked_shaft(liquid):
    params = PlantParams(shaft=ShaftParams(locked=True))
    plant = Plant(MODELS[liquid], params)
    state = _settle(plant, -40.0 * LPM, 2000)
    f = plant.flows
    relief = params.relief
    expected = (params.lines.tank_pressure + relief.cracking_pressure
                + f.relief / relief.conductance)
    assert state.outlet_pressure == pytest.approx(expected, rel=1e-9)
    assert state.inlet_pressure < 2 * MPA and state.speed == 0.0
    assert f.relief - f.motor == pytest.approx(40.0 * LPM, rel=1e-9)  # motor: B -> A leakage
    assert -0.1 * 40.0 * LPM < f.motor < 0.0


def test_an_overrunning_load_makes_a_pump_of_a_reversed_drive():
    """A load driving the shaft forwards against a reversed command: finite, pump mode."""
    plant = Plant(MODELS['oil'], PlantParams(active_load=True), load=ConstantLoad(-200.0))
    plant.run(3000, -5.0 * LPM)
    state = plant.state
    assert state.speed > 0.0 and all(math.isfinite(v) for v in state)
    assert plant.flows.relief > 0.0
    assert plant.invalid_points == 0


def test_the_shaft_reverses_through_zero_without_a_jump():
    plant = Plant(MODELS['water'], load=ConstantLoad(20.0))
    plant.run(2000, 20.0 * LPM)
    speeds = []
    for i in range(4000):
        plant.step((20.0 - 0.01 * i) * LPM)
        speeds.append(plant.state.speed)
        assert all(math.isfinite(v) for v in plant.state)
    assert speeds[0] > 0.0 > speeds[-1]
    assert max(abs(b - a) for a, b in zip(speeds, speeds[1:])) < 0.05 * abs(speeds[0])
    assert plant.invalid_points == 0


def test_an_injected_reverse_loss_acts_on_the_reversed_plant_only():
    effect = Effect('reverse_loss', 4e-15)
    model = MODELS['oil']
    params = PlantParams(effects=(effect,))
    ahead = _settle(Plant(model, params, load=ConstantLoad(60.0)), 20.0 * LPM)
    plain = _settle(Plant(model, load=ConstantLoad(60.0)), 20.0 * LPM)
    assert ahead.speed == pytest.approx(plain.speed, rel=1e-9)
    back = _settle(Plant(model, params, load=ConstantLoad(60.0)), -20.0 * LPM)
    dp = back.inlet_pressure - back.outlet_pressure
    assert back.speed > -plain.speed  # the extra loss costs speed backwards
    expected = with_effects(model, (effect,)).speed_point(-20.0 * LPM, dp).speed
    assert back.speed == pytest.approx(expected, rel=1e-8)
