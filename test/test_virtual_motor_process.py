# SPDX-License-Identifier: Apache-2.0
"""
The installed ``virtual_motor`` in a process of its own, found and started as ``ros2 run`` would.

The package is built with colcon (the fixtures of test_package_build.py), the executable
looked up through the ament index, and the test talks to it over real DDS: commands in,
pressures, speed and /clock out, bad commands survived, clean exit on SIGINT.
"""

import math
import os

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from node_harness import spin_until
import pytest
from rclpy.qos import qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from satmotor_ros.model.units import LPM, MPA
from sensor_msgs.msg import FluidPressure, JointState
from std_msgs.msg import Float64
import test_package_build as build

pytestmark = [pytest.mark.ros, pytest.mark.slow]

colcon_build = build.colcon_build  # the module-scoped build, as a fixture of this module
sourced_install = build.sourced_install

NAMESPACE = f'/vm_process_test_{os.getpid()}'


def _start(env, cwd, name, *ros_args):
    return build.start_installed(env, cwd, NAMESPACE, name, *ros_args)


_stop = build.stop_process


def _settled(joints, window=0.5, rel=0.01):
    """Tell whether the speed moved by less than `rel` over the last `window` s of stamps."""
    if not joints:
        return False
    stamps = [j.header.stamp.sec + 1e-9 * j.header.stamp.nanosec for j in joints]
    if stamps[-1] - stamps[0] < window:
        return False
    recent = [j.velocity[0] for j, t in zip(joints, stamps) if t >= stamps[-1] - window]
    return max(recent) - min(recent) <= rel * abs(recent[-1])


def test_installed_virtual_motor_runs_on_sim_time_and_survives_bad_commands(
        sourced_install, tmp_path, ros):
    """Command in, pressures and speed out, /clock advancing; NaN and -1 refused; SIGINT: 0."""
    _, executor, node = ros
    clock, joints, inlet, diagnostics = [], [], [], []
    node.create_subscription(Clock, '/clock', clock.append, qos_profile_sensor_data)
    node.create_subscription(JointState, 'joint_states', joints.append, qos_profile_sensor_data)
    node.create_subscription(FluidPressure, 'inlet_pressure', inlet.append,
                             qos_profile_sensor_data)
    node.create_subscription(DiagnosticArray, '/diagnostics', diagnostics.append, 10)
    command = node.create_publisher(Float64, 'flow_command', 10)
    process = _start(sourced_install, tmp_path, 'virtual_motor', '-p', 'clock_mode:=sim',
                     '-p', 'max_speedup:=5.0', '-p', 'load.torque:=30.0',
                     '-p', 'diagnostics_period:=0.2')
    try:
        def turning():
            command.publish(Float64(data=10.0 * LPM))
            return bool(joints) and joints[-1].velocity[0] > 10.0
        assert spin_until(executor, turning), 'no speed on joint_states'
        assert spin_until(executor, lambda: inlet[-1].fluid_pressure > 1.0 * MPA)
        assert spin_until(executor, lambda: len(clock) > 5)
        sim_time = [c.clock.sec + 1e-9 * c.clock.nanosec for c in clock]
        assert sim_time == sorted(sim_time)
        assert spin_until(executor, lambda: (command.publish(Float64(data=10.0 * LPM)),
                                             _settled(joints))[1]), 'speed never settled'

        for bad in (math.nan, -1.0):
            command.publish(Float64(data=bad))
        assert spin_until(executor, lambda: any(
            s.level == DiagnosticStatus.WARN and 'refused' in s.message
            for d in diagnostics for s in d.status)), 'bad commands not reported'
        speed = joints[-1].velocity[0]
        count = len(clock)
        assert spin_until(executor, lambda: len(clock) > count + 20)
        assert process.poll() is None, 'the node died on a bad command'
        assert joints[-1].velocity[0] == pytest.approx(speed, rel=0.05)  # command held
    finally:
        code, output = _stop(process)
    assert code == 0, output
    assert 'not a finite number' in output


@pytest.mark.parametrize('bad', ['liquid:=honey', 'clock_mode:=lunar', 'publish_rate:=0.0'])
def test_installed_virtual_motor_refuses_bad_start_parameters_in_one_line(
        sourced_install, tmp_path, bad):
    """An unknown liquid or clock mode, a rate out of range at start-up: exit 1, one line."""
    process = _start(sourced_install, tmp_path, 'virtual_motor', '-p', bad)
    code, output = process.wait(timeout=30.0), process.stdout.read()
    assert code == 1, output
    name, value = bad.split(':=')
    lines = [line for line in output.splitlines() if line.startswith('virtual_motor: ')]
    assert len(lines) == 1 and name in lines[0] and value.strip("'") in lines[0], output
    assert 'Traceback' not in output
