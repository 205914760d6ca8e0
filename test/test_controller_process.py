# SPDX-License-Identifier: Apache-2.0
"""
The installed ``speed_controller`` and ``virtual_motor``, each in a process of its own.

Both are found through the ament index of a colcon install and started as ``ros2 run``
starts them; the controller runs on the virtual motor's /clock and brings it to the
set-point given as a parameter, then to one given on ``speed_setpoint``.
"""

import os
import select
import time

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import qos_profile_sensor_data
from satmotor_ros.model.units import RPM
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64
import test_package_build as build

pytestmark = [pytest.mark.ros, pytest.mark.slow]

colcon_build = build.colcon_build  # the module-scoped build, as a fixture of this module
sourced_install = build.sourced_install

NAMESPACE = f'/controller_process_test_{os.getpid()}'


def _start(env, cwd, name, *ros_args):
    return build.start_installed(env, cwd, NAMESPACE, name, *ros_args)


_stop = build.stop_process


def _read_until(process, text, timeout=30.0):
    """Read the process's output until `text` appears, the output ends or the deadline."""
    fd, seen = process.stdout.fileno(), ''
    deadline = time.monotonic() + timeout
    while text not in seen and time.monotonic() < deadline:
        if select.select([fd], [], [], 0.1)[0]:
            chunk = os.read(fd, 4096)
            if not chunk:
                break
            seen += chunk.decode(errors='replace')
    return seen


def test_installed_controller_drives_the_installed_virtual_motor_on_sim_time(
        sourced_install, tmp_path):
    """600 rpm from the parameter, then 900 rpm from the topic, each within 1 %."""
    context = Context()
    context.init()
    executor = SingleThreadedExecutor(context=context)
    probe = rclpy.create_node('probe', namespace=NAMESPACE, context=context)
    executor.add_node(probe)
    joints = []
    probe.create_subscription(JointState, 'joint_states', joints.append,
                              qos_profile_sensor_data)
    setpoint = probe.create_publisher(Float64, 'speed_setpoint', 10)
    motor = _start(sourced_install, tmp_path, 'virtual_motor', '-p', 'clock_mode:=sim',
                   '-p', 'max_speedup:=5.0', '-p', 'load.torque:=30.0')
    controller = _start(sourced_install, tmp_path, 'speed_controller',
                        '-p', 'use_sim_time:=true', '-p', f'setpoint:={600.0 * RPM}')

    def near(target, publish=False):
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            if publish:
                setpoint.publish(Float64(data=target))
            executor.spin_once(timeout_sec=0.05)
            recent = [j.velocity[0] for j in joints[-20:]]
            if len(recent) == 20 and all(abs(v - target) < 0.01 * target for v in recent):
                return True
        return False
    try:
        assert near(600.0 * RPM), joints[-1].velocity if joints else 'no joint_states'
        assert near(900.0 * RPM, publish=True), joints[-1].velocity
    finally:
        results = [_stop(p) for p in (controller, motor)]
        executor.shutdown()
        probe.destroy_node()
        context.try_shutdown()
    for code, output in results:
        assert code == 0, output


@pytest.mark.parametrize('bad', ['feedforward:=psychic', 'kp:=-1.0'])
def test_installed_controller_falls_back_to_defaults_on_bad_parameters(
        sourced_install, tmp_path, bad):
    """A bad parameter override is reported in one line and the default used; it runs on."""
    process = _start(sourced_install, tmp_path, 'speed_controller', '-p', bad)
    seen = ''
    try:
        seen = _read_until(process, 'using the default')  # start-up takes long under load
        time.sleep(1.0)
        assert process.poll() is None, 'the controller died on a bad parameter'
    finally:
        code, rest = _stop(process)
    output = seen + rest
    assert code == 0, output
    assert bad.split(':=')[0] in output and 'using the default' in output
