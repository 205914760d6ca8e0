# SPDX-License-Identifier: Apache-2.0
"""The virtual_motor node in-process: real topics, parameters refused with a reason, bad input."""

import math
import os
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from node_harness import spin_until
import pytest
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from satmotor_ros.model import MotorModel
from satmotor_ros.model.effects import Effect
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.nodes.virtual_motor import all_parameters, VirtualMotorNode
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64

NAMESPACE = f'/vm_node_test_{os.getpid()}'


def _motor(context, executor, **overrides):
    params = [Parameter(k, value=v) for k, v in {'clock_mode': 'sim', **overrides}.items()]
    node = VirtualMotorNode(context=context, namespace=NAMESPACE, parameter_overrides=params)
    executor.add_node(node)
    return node


def _collect(probe, kind, topic, qos=qos_profile_sensor_data):
    got = []
    probe.create_subscription(kind, topic, got.append, qos)
    return got


def test_commanded_flow_turns_the_shaft_at_the_models_speed(ros):
    """Pressures, flow, speed and temperature come out; the speed settles on eq. (40)."""
    context, executor, probe = ros
    node = _motor(context, executor, **{'load.torque': 40.0, 'liquid': 'water'})
    command = probe.create_publisher(Float64, 'flow_command', 10)
    joints = _collect(probe, JointState, 'joint_states')
    inlet = _collect(probe, FluidPressure, 'inlet_pressure')
    outlet = _collect(probe, FluidPressure, 'outlet_pressure')
    case = _collect(probe, FluidPressure, 'case_pressure')
    flow = _collect(probe, Float64, 'flow_measured')
    temperature = _collect(probe, Temperature, 'fluid_temperature')
    clock = _collect(probe, Clock, '/clock', 10)

    def settled():
        command.publish(Float64(data=15.0 * LPM))
        return node.plant.state.time > 3.0 and len(joints) > 10 and len(outlet) > 10
    assert spin_until(executor, settled)
    assert all(len(x) > 10 for x in (inlet, case, flow, temperature, clock))
    speed = joints[-1].velocity[0]
    assert joints[-1].name == ['motor_shaft']
    dp = inlet[-1].fluid_pressure - outlet[-1].fluid_pressure
    expected = float(MotorModel.default('water').speed(15.0 * LPM, dp).speed)
    assert speed == pytest.approx(expected, rel=1e-3)
    assert 1.0 * MPA < dp < 27.0 * MPA
    assert flow[-1].data == pytest.approx(15.0 * LPM, rel=1e-3)
    assert case[-1].fluid_pressure > 101325.0
    stamps = [c.clock.sec + 1e-9 * c.clock.nanosec for c in clock]
    assert stamps == sorted(stamps) and stamps[-1] > 2.5


def test_bad_commands_are_refused_held_and_reported(ros):
    """A NaN or absurd flow (either sign): the node keeps the last good command, says so."""
    context, executor, probe = ros
    node = _motor(context, executor, diagnostics_period=0.05)
    command = probe.create_publisher(Float64, 'flow_command', 10)
    load = probe.create_publisher(Float64, 'load_torque', 10)
    diagnostics = _collect(probe, DiagnosticArray, '/diagnostics', 10)
    assert spin_until(executor, lambda: (command.publish(Float64(data=10.0 * LPM)),
                                         node.plant.state.time > 0.5)[1])
    for bad in (math.nan, -1.0, 1.0, math.inf):
        command.publish(Float64(data=bad))
    assert spin_until(executor, lambda: node.rejected >= 4)
    load.publish(Float64(data=math.nan))
    assert spin_until(executor, lambda: node.rejected >= 5)
    assert 'load torque nan' in node.last_rejection
    assert spin_until(executor, lambda: any(
        s.level == DiagnosticStatus.WARN and 'refused' in s.message
        for d in diagnostics for s in d.status))
    assert node._command == pytest.approx(10.0 * LPM)
    before = node.plant.state.time
    assert spin_until(executor, lambda: node.plant.state.time > before + 0.5)
    assert node.plant.state.speed > 0.0


def test_parameters_are_refused_with_a_reason_and_the_old_value_kept(ros):
    """Out of range, unknown liquid, bad enum: refused with a reason; a good change applies."""
    context, executor, _ = ros
    node = _motor(context, executor)
    cases = [('shaft.inertia', -1.0, 'shaft.inertia'), ('liquid', 'honey', 'honey'),
             ('effects.leakage_driver', 'nowhere', 'leakage_driver'),
             ('load.kind', 'wind', 'load.kind'), ('clock_mode', 'lunar', 'clock_mode')]
    for name, value, reason in cases:
        before = node.get_parameter(name).value
        (result,) = node.set_parameters([Parameter(name, value=value)])
        assert not result.successful and reason in result.reason, result.reason
        assert node.get_parameter(name).value == before
    result = node.set_parameters_atomically([
        Parameter('liquid', value='water'), Parameter('effects.flow_sensor_offset', value=1e-5)])
    assert result.successful
    assert node.plant.model.liquid.name == 'tap water'
    assert node.plant.params.effects == (Effect('flow_sensor_offset', 1e-5, '1'),)


def test_every_parameter_has_a_unit_and_numbers_a_range(ros):
    """Descriptors carry '[unit]' and a range for every float parameter."""
    context, executor, _ = ros
    node = _motor(context, executor)
    for spec in all_parameters():
        (desc,) = node.describe_parameters([spec.name])
        assert desc.description.endswith(']'), spec.name
        if isinstance(spec.default, float):
            assert desc.floating_point_range, spec.name


def _flatten(tree, prefix=''):
    for key, value in tree.items():
        if isinstance(value, dict):
            yield from _flatten(value, f'{prefix}{key}.')
        else:
            yield f'{prefix}{key}', value


def test_shipped_parameter_file_lists_every_parameter_at_its_default():
    """config/virtual_motor.yaml cannot drift from the declared parameters."""
    from pathlib import Path

    import yaml
    path = Path(__file__).resolve().parent.parent / 'config' / 'virtual_motor.yaml'
    doc = yaml.safe_load(path.read_text())
    flat = dict(_flatten(doc['/**/virtual_motor']['ros__parameters']))
    assert flat == {spec.name: spec.default for spec in all_parameters()}


def test_wall_clock_mode_keeps_pace_with_the_wall_clock(ros):
    """clock_mode 'wall': simulated time follows the wall clock; no /clock is published."""
    context, executor, probe = ros
    node = VirtualMotorNode(context=context, namespace=NAMESPACE)
    executor.add_node(node)
    clock = _collect(probe, Clock, '/clock', qos_profile_sensor_data)
    start = time.monotonic()
    spin_until(executor, lambda: time.monotonic() - start > 1.5, timeout=3.0)
    elapsed = time.monotonic() - start
    assert node.plant.state.time == pytest.approx(elapsed, abs=0.3)
    assert not clock


def test_every_message_carries_its_own_tick(ros):
    """The refilled messages: each one has the stamp, readings and frame of its own tick."""
    context, executor, probe = ros
    node = _motor(context, executor, **{'load.torque': 40.0, 'frame_id': 'rig',
                                        'sensors.inlet_pressure.noise': 1.0e4})
    node._command = 20.0 * LPM
    joints = _collect(probe, JointState, 'joint_states')
    inlet = _collect(probe, FluidPressure, 'inlet_pressure')
    clock = _collect(probe, Clock, '/clock', 10)
    assert spin_until(executor, lambda: len(joints) > 20 and len(inlet) > 20 and len(clock) > 20)

    def seconds(stamp):
        return stamp.sec + 1e-9 * stamp.nanosec
    ticks = {seconds(c.clock) for c in clock}
    for stamps in ([seconds(j.header.stamp) for j in joints],
                   [seconds(p.header.stamp) for p in inlet]):
        assert all(b - a == pytest.approx(0.01, abs=1e-9) for a, b in zip(stamps, stamps[1:]))
        assert set(stamps) <= ticks
    angles = [j.position[0] for j in joints]
    assert all(b > a for a, b in zip(angles, angles[1:]))
    assert len({p.fluid_pressure for p in inlet}) == len(inlet)  # seeded noise: all differ
    assert {p.header.frame_id for p in inlet} == {'rig'} and inlet[-1].variance == 1.0e8
    node.set_parameters([Parameter('joint_name', value='shaft_2'),
                         Parameter('frame_id', value='rig_2'),
                         Parameter('sensors.inlet_pressure.noise', value=2.0e4)])
    count, pressures = len(joints), len(inlet)
    assert spin_until(executor, lambda: len(joints) > count + 2 and len(inlet) > pressures + 2)
    assert joints[-1].name == ['shaft_2'] and joints[-1].header.frame_id == 'rig_2'
    assert inlet[-1].header.frame_id == 'rig_2' and inlet[-1].variance == 4.0e8


def test_clock_mode_and_max_speedup_switch_at_run_time(ros):
    """Free-running sim, then wall clock, then paced sim: each keeps its own pace."""
    context, executor, probe = ros
    node = _motor(context, executor)
    clock = _collect(probe, Clock, '/clock', 10)

    def pace(seconds):
        sim0, wall0 = node.plant.state.time, time.monotonic()
        spin_until(executor, lambda: time.monotonic() - wall0 > seconds, timeout=seconds + 1)
        return (node.plant.state.time - sim0) / (time.monotonic() - wall0)
    assert pace(0.5) > 3.0  # as fast as possible is far faster than the wall clock
    assert node.set_parameters([Parameter('clock_mode', value='wall')])[0].successful
    spin_until(executor, lambda: False, timeout=0.05)
    published = len(clock)
    assert pace(1.0) == pytest.approx(1.0, abs=0.2)
    spin_until(executor, lambda: False, timeout=0.1)
    assert len(clock) == published  # no /clock on the wall clock
    assert node.set_parameters([Parameter('clock_mode', value='sim'),
                                Parameter('max_speedup', value=2.0)])[0].successful
    assert 1.3 < pace(1.0) < 2.3  # rcl timers skip missed periods: under load only below 2
    assert len(clock) > published
    assert node.set_parameters([Parameter('max_speedup', value=0.0)])[0].successful
    assert pace(0.5) > 3.0


def test_lockstep_takes_one_period_per_flow_command(ros):
    """clock_mode 'lockstep': time advances one period per answer; unanswered ones wait."""
    context, executor, probe = ros
    node = _motor(context, executor, clock_mode='lockstep', lockstep_wait=0.3, paused=True,
                  diagnostics_period=0.01)
    clock = _collect(probe, Clock, '/clock', 10)
    diagnostics = _collect(probe, DiagnosticArray, '/diagnostics', 10)
    command = probe.create_publisher(Float64, f'{NAMESPACE}/flow_command', 10)
    spin_until(executor, lambda: command.get_subscription_count() > 0)
    spin_until(executor, lambda: False, timeout=0.3)
    assert node.plant.state.time == 0.0 and not clock  # paused: no step, nothing published
    assert node.set_parameters([Parameter('paused', value=False)])[0].successful
    # the start and the first period go out at once; then each period waits for its answer
    assert spin_until(executor, lambda: len(clock) == 2)
    for answered in range(1, 51):
        command.publish(Float64(data=10.0 * LPM))
        assert spin_until(executor, lambda: len(clock) == answered + 2)
    assert node.plant.state.time == pytest.approx(0.51, abs=1e-12)
    for wait in (0.31, 0.3, 0.31, 0.3):  # a restart takes no period and publishes nothing
        assert node.set_parameters([Parameter('paused', value=True)])[0].successful
        assert node.set_parameters([Parameter('paused', value=False),
                                    Parameter('lockstep_wait', value=wait)])[0].successful
    spin_until(executor, lambda: False, timeout=0.1)
    assert len(clock) == 52 and node.plant.state.time == pytest.approx(0.51, abs=1e-12)
    command.publish(Float64(data=10.0 * LPM))
    assert spin_until(executor, lambda: len(clock) == 53)
    stamps = [c.clock.sec * 1_000_000_000 + c.clock.nanosec for c in clock]
    assert stamps == [10_000_000 * k for k in range(53)]  # whole periods, none twice
    assert node.unanswered_steps == 0
    assert node.plant.state.speed > 0.0
    wall0 = time.monotonic()  # no answer: each period is taken after lockstep_wait
    assert spin_until(executor, lambda: len(clock) == 55, timeout=5.0)
    assert time.monotonic() - wall0 >= 0.55
    assert node.unanswered_steps == 2
    assert spin_until(executor, lambda: any('lockstep' in st.message for d in diagnostics
                                            for st in d.status))
    warned = [st.message for d in diagnostics for st in d.status
              if st.level == DiagnosticStatus.WARN]
    assert '1 lockstep period(s) taken with no flow_command within lockstep_wait' in warned
    answered_time = [d for d in diagnostics if d.header.stamp.nanosec <= 520_000_000]
    assert answered_time and all(st.level == DiagnosticStatus.OK for d in answered_time
                                 for st in d.status), [(d.header.stamp.nanosec, st.message)
                                                       for d in answered_time for st in d.status
                                                       if st.level != DiagnosticStatus.OK]
    assert node.set_parameters([Parameter('paused', value=True)])[0].successful
    spin_until(executor, lambda: False, timeout=0.7)
    assert len(clock) == 55 and node.plant.state.time == pytest.approx(0.54, abs=1e-12)
