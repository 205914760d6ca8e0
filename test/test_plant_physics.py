# SPDX-License-Identifier: Apache-2.0
"""The plant on its own: steady state equals the model, mass balance, relief valve, stability."""

import dataclasses
import math

from hypothesis import given, settings, strategies as st
import pytest

from satmotor_ros.model import MotorModel
from satmotor_ros.model.effects import Effect, effect_from_mapping
from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA
from satmotor_ros.plant import (ConstantLoad, LineParams, Plant, PlantError,
                                PlantParams, ShaftParams, SpeedProportionalLoad, StepLoad)
from satmotor_ros.plant import params as records
from satmotor_ros.plant.config import params_from_flat
from satmotor_ros.plant.controller import ControllerParams

MODELS = {name: MotorModel.default(name) for name in ('oil', 'water')}


def _settle(plant, flow, steps=1500):
    """Run until speed and pressures stop changing (to 1e-10), at most 40 times `steps`."""
    plant.run(steps, flow)
    for _ in range(40):
        before = plant.state
        plant.run(steps // 4, flow)
        after = plant.state
        if all(abs(a - b) <= 1e-10 * abs(b) for a, b in zip(after[1:4], before[1:4])):
            break
    return plant.state


@pytest.mark.parametrize('liquid', ['oil', 'water'])
@pytest.mark.parametrize('flow_lpm', [3.0, 20.0, 40.0])
@pytest.mark.parametrize('load', [5.0, 110.0])
def test_plant_steady_state_equals_model_eqs_36_and_40(liquid, flow_lpm, load):
    """At rest the shaft turns at eq. (40)'s speed for the flow and port drop the plant holds."""
    model = MODELS[liquid]
    plant = Plant(model, load=ConstantLoad(load))
    state = _settle(plant, flow_lpm * LPM)
    plant.run(10, flow_lpm * LPM)
    assert plant.state.speed == pytest.approx(state.speed, rel=1e-9), 'not settled'
    dp = state.inlet_pressure - state.outlet_pressure
    assert plant.flows.relief == 0.0
    expected = model.speed(flow_lpm * LPM, dp)
    assert state.speed == pytest.approx(float(expected.speed), rel=1e-8)
    assert plant.chamber_pressure_drop == pytest.approx(float(expected.dp_i), rel=1e-8)
    forward = model.absorbency(state.speed, dp)
    assert float(forward.flow) == pytest.approx(flow_lpm * LPM, rel=1e-8)
    # the torque balance of the shaft, eqs. (P4)-(P5), holds as well
    shaft = plant.params.shaft
    dp_i = plant.chamber_pressure_drop
    friction = (shaft.viscous_friction * state.speed + shaft.coulomb_friction
                + shaft.pressure_friction * model.geometry.displacement * dp_i)
    assert model.geometry.displacement * dp_i - friction == pytest.approx(load, rel=1e-8)


def _volumes(plant):
    k = plant.model.liquid.bulk_modulus
    lines = plant.params.lines
    state = plant.state
    return (lines.inlet_volume / k * state.inlet_pressure,
            lines.outlet_volume / k * state.outlet_pressure)


@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_plant_lines_conserve_volume_through_steps_of_flow_and_load(liquid):
    """Compressed volume in each line changes by exactly what flows in minus what flows out."""
    params = PlantParams(effects=(Effect('external_leakage', 2.0e-13, 'p_case'),))
    plant = Plant(MODELS[liquid], params, load=StepLoad(20.0, 90.0, 0.15))
    dt = params.step
    stored_in, stored_out = _volumes(plant)
    through_in = through_out = 0.0
    for i in range(400):
        plant.step((10.0 if i < 100 else 35.0) * LPM)
        f = plant.flows
        through_in += dt * (f.command - f.motor - f.relief - f.leakage + f.cavitation_in)
        through_out += dt * (f.motor - f.model_external - f.returned + f.cavitation_out)
        now_in, now_out = _volumes(plant)
        scale = dt * f.command
        assert now_in - stored_in == pytest.approx(through_in, abs=1e-9 * scale)
        assert now_out - stored_out == pytest.approx(through_out, abs=1e-9 * scale)
        stored_in, stored_out, through_in, through_out = now_in, now_out, 0.0, 0.0


@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_relief_valve_holds_the_inlet_of_a_blocked_shaft(liquid):
    """With the shaft locked all the flow but the leakage goes over the relief valve (P2)."""
    params = PlantParams(shaft=ShaftParams(locked=True))
    plant = Plant(MODELS[liquid], params)
    flow = 40.0 * LPM
    state = _settle(plant, flow, 2000)
    f = plant.flows
    relief = params.relief
    expected = (params.lines.tank_pressure + relief.cracking_pressure
                + f.relief / relief.conductance)
    assert state.inlet_pressure == pytest.approx(expected, rel=1e-9)
    assert state.speed == 0.0
    assert f.relief + f.motor == pytest.approx(flow, rel=1e-9)
    assert 0.0 < f.motor < 0.1 * flow  # what leaks through the standing motor


@pytest.mark.slow
def test_a_million_steps_of_water_with_a_blocked_shaft_stay_finite_and_bounded():
    """10^6 default steps, water, locked shaft, full flow on and off: no NaN, valve holds."""
    params = PlantParams(shaft=ShaftParams(locked=True))
    plant = Plant(MODELS['water'], params)
    ceiling = params.lines.tank_pressure + params.relief.cracking_pressure + 2.5 * MPA
    peak = 0.0
    for block in range(100):
        plant.run(10_000, (45.0 if block % 2 == 0 else 0.0) * LPM)
        state = plant.state
        assert all(math.isfinite(v) for v in state)
        peak = max(peak, state.inlet_pressure)
    assert plant.state.time == pytest.approx(1000.0)
    assert params.relief.cracking_pressure < peak - params.lines.tank_pressure < ceiling
    assert plant.invalid_points == 0


def test_a_passive_load_brakes_and_never_drives_the_shaft():
    """A brake torque above the motor's stalls it at exactly zero; below, it turns forward."""
    plant = Plant(MODELS['oil'], load=ConstantLoad(500.0))
    plant.run(3000, 10.0 * LPM)
    assert plant.state.speed == 0.0
    plant.load = ConstantLoad(20.0)
    plant.run(3000, 10.0 * LPM)
    assert plant.state.speed > 0.0


def test_static_friction_holds_a_stalled_shaft_under_pressure():
    """A shaft whose dry friction exceeds the driving torque stays at exactly zero speed."""
    params = PlantParams(shaft=ShaftParams(coulomb_friction=500.0))
    plant = Plant(MODELS['water'], params)
    plant.run(100_000, 20.0 * LPM)
    assert plant.state.speed == 0.0
    assert plant.flows.relief > 0.0


def test_flow_step_settles_to_the_model_steady_state():
    """A flow step 10 -> 30 l/min under a fan-like load settles within a second to eq. (40)."""
    model = MODELS['water']
    plant = Plant(model, load=SpeedProportionalLoad(coefficient=0.2, offset=5.0))
    plant.run(1000, 10.0 * LPM)
    speeds = []
    for _ in range(1000):
        plant.step(30.0 * LPM)
        speeds.append(plant.state.speed)
    state = plant.state
    expected = float(model.speed(30.0 * LPM, state.inlet_pressure - state.outlet_pressure).speed)
    assert state.speed == pytest.approx(expected, rel=1e-6)
    settled = next(i for i, s in enumerate(speeds) if all(
        abs(x - expected) < 0.02 * expected for x in speeds[i:]))
    assert settled * plant.params.step < 0.5


def test_bad_commands_are_refused_and_leave_the_state_alone():
    """A NaN or absurd flow (either sign), or a NaN load torque, raise PlantError naming it."""
    plant = Plant(MODELS['oil'])
    plant.run(50, 10.0 * LPM)
    before = plant.state
    for bad in (math.nan, -1.0, 1.0, math.inf):  # a negative command reverses the pump
        with pytest.raises(PlantError, match='flow_command'):
            plant.step(bad)
        assert plant.check_command(bad) is not None
    with pytest.raises(PlantError, match='load_torque'):
        plant.step(1.0e-4, math.nan)
    assert plant.state == before
    assert plant.check_command(1.0e-4) is None


def test_overrunning_load_drives_the_shaft_backwards_without_nan():
    """An active load above what the pressure can hold turns the motor into a pump: finite."""
    plant = Plant(MODELS['oil'], PlantParams(active_load=True), load=ConstantLoad(200.0))
    plant.run(3000, 5.0 * LPM)
    state = plant.state
    assert state.speed < 0.0
    assert all(math.isfinite(v) for v in state)
    assert plant.flows.relief > 0.0


def test_smaller_lines_and_a_longer_step_stay_stable_on_water():
    """A 10 ms step with 10 cm^3 lines (stiff on water) still settles on the model."""
    model = MODELS['water']
    params = PlantParams(step=1.0e-2, lines=LineParams(inlet_volume=1.0e-5,
                                                       outlet_volume=1.0e-5))
    plant = Plant(model, params, load=ConstantLoad(60.0))
    plant.run(500, 25.0 * LPM)
    state = plant.state
    expected = model.speed(25.0 * LPM, state.inlet_pressure - state.outlet_pressure)
    assert state.speed == pytest.approx(float(expected.speed), rel=1e-8)


def test_parameter_records_reject_bad_values_naming_the_field():
    """Records check every field on construction."""
    with pytest.raises(PlantError, match=r'ShaftParams.inertia = -1'):
        ShaftParams(inertia=-1.0)
    with pytest.raises(PlantError, match='leakage_driver'):
        params_from_flat({'effects.leakage_driver': 'nowhere'})
    with pytest.raises(PlantError, match=r'PlantParams.step'):
        PlantParams(step=math.nan)
    assert dataclasses.replace(PlantParams(), step=2e-3).step == 2e-3


RECORDS = (records.LineParams, records.ReliefParams, records.ShaftParams, records.ThermalParams,
           records.CaseParams, records.SensorParams, records.PlantParams, ControllerParams)


@pytest.mark.parametrize('record', RECORDS, ids=lambda r: r.__name__)
def test_every_ranged_field_of_every_record_refuses_a_value_beyond_its_range(record):
    """Each record is Bounded: above its range or NaN, every ranged field is refused by name."""
    ranged = [(f.name, f.metadata['range']) for f in dataclasses.fields(record)
              if f.metadata.get('range') is not None]
    assert ranged
    for name, (_, high) in ranged:
        for bad in (2.0 * abs(high) + 1.0, math.nan):
            with pytest.raises(PlantError, match=rf'{record.__name__}\.{name} = '):
                record(**{name: bad})


@settings(max_examples=25, deadline=None, derandomize=True)
@given(liquid=st.sampled_from(['oil', 'water']),
       flows=st.lists(st.floats(0.0, 60.0), min_size=3, max_size=6),
       loads=st.lists(st.floats(0.0, 150.0), min_size=3, max_size=6))
def test_any_command_sequence_keeps_the_plant_finite_bounded_and_balanced(liquid, flows,
                                                                          loads):
    """Random flow and brake steps: finite, p within [vapour, relief], speed bounded, balanced."""
    params = PlantParams()
    plant = Plant(MODELS[liquid], params)
    lines, relief = params.lines, params.relief
    ceiling = lines.tank_pressure + relief.cracking_pressure + 60.0 * LPM / relief.conductance
    dt = params.step
    for flow, load in zip(flows, loads):
        for _ in range(150):
            before_in, before_out = _volumes(plant)
            plant.step(flow * LPM, load)
            state, f = plant.state, plant.flows
            assert all(math.isfinite(v) for v in state)
            assert lines.vapour_pressure <= state.inlet_pressure <= ceiling
            assert lines.vapour_pressure <= state.outlet_pressure <= ceiling
            # bounded: the compressed lines may overshoot the speed the largest flow drives
            # or creep a released shaft backwards, but never run it away
            assert abs(state.speed) <= 2.0 * 60.0 * LPM / MODELS[liquid].geometry.displacement
            after_in, after_out = _volumes(plant)
            net_in = dt * (f.command - f.motor - f.relief - f.leakage + f.cavitation_in)
            assert after_in - before_in == pytest.approx(net_in, abs=1e-9 * dt * 1e-3)


def test_a_calibrated_coefficient_file_runs_in_the_plant_with_its_effect():
    """A set with effects: the plant supplies their channels and settles to the model's state."""
    base = MODELS['water']
    effects = (effect_from_mapping('external_leakage', {'regressor': 'p_out',
                                                        'coefficient': 4e-12}, 'e'),
               effect_from_mapping('term:dp^2*n', {'coefficient': 1e-21}, 'e'))
    coef = dataclasses.replace(base.coef, external_leakage=4e-12)
    calibrated = MotorModel(base.geometry, dataclasses.replace(
        base.coefficient_set, coefficients=coef, effects=effects), base.valid_range)
    plant = Plant(calibrated, load=ConstantLoad(60.0))
    state = _settle(plant, 20 * LPM)
    dp = state.inlet_pressure - state.outlet_pressure
    channels = {'p_out': state.outlet_pressure - ATMOSPHERE}
    expected = calibrated.speed_point(20 * LPM, dp, channels=channels)
    assert state.speed == pytest.approx(expected.speed, rel=1e-8)
    plain = _settle(Plant(base, load=ConstantLoad(60.0)), 20 * LPM)
    assert state.speed < plain.speed - 1.0  # the extra losses cost speed
