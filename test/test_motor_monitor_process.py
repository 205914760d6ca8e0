# SPDX-License-Identifier: Apache-2.0
"""
The installed ``motor_monitor`` watches the installed ``virtual_motor``, as ``ros2 run`` would.

Both come from the colcon install tree (the fixtures of test_package_build.py): the plant
runs on sim time, the monitor on ``use_sim_time``; the health topics and the diagnostics
come out, and SIGINT ends the monitor with status 0 and its state saved.
"""

import json
import os
import time

from diagnostic_msgs.msg import DiagnosticArray
import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from satmotor_ros.interface import CHANNELS, DIAGNOSTICS, HEALTH_TOPICS
from satmotor_ros.model.units import LPM
from std_msgs.msg import Float64
import test_package_build as build

colcon_build = build.colcon_build  # the module-scoped build, as a fixture of this module
sourced_install = build.sourced_install

pytestmark = [pytest.mark.ros, pytest.mark.slow]  # a colcon build, two processes

NAMESPACE = f'/monitor_process_test_{os.getpid()}'


@pytest.fixture()
def probe():
    """Give a context, executor and probe node in the test's namespace; shut down after."""
    context = Context()
    context.init()
    executor = SingleThreadedExecutor(context=context)
    node = rclpy.create_node('probe', namespace=NAMESPACE, context=context)
    executor.add_node(node)
    try:
        yield executor, node
    finally:
        executor.shutdown()
        node.destroy_node()
        context.try_shutdown()


def _spin_until(executor, done, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not done():
        executor.spin_once(timeout_sec=0.02)
    return done()


def test_installed_monitor_watches_the_installed_virtual_motor(
        sourced_install, tmp_path, probe):
    """Leakage factor near 1 on the healthy plant, diagnostics, state saved at SIGINT."""
    executor, node = probe
    factors, diagnostics = [], []
    node.create_subscription(Float64, HEALTH_TOPICS[0], factors.append, 10)
    node.create_subscription(DiagnosticArray, DIAGNOSTICS, diagnostics.append, 10)
    command = node.create_publisher(Float64, CHANNELS['flow'].topic, 10)
    state = tmp_path / 'health.json'
    plant = build.start_installed(sourced_install, tmp_path, NAMESPACE, 'virtual_motor',
                                  '-p', 'clock_mode:=sim', '-p', 'max_speedup:=20.0',
                                  '-p', 'load.torque:=40.0')
    monitor = build.start_installed(sourced_install, tmp_path, NAMESPACE, 'motor_monitor',
                                    '-p', 'use_sim_time:=true', '-p', 'learn_hours:=0.01',
                                    '-p', 'bin_s:=1.0', '-p', 'window_s:=10.0',
                                    '-p', f'state_file:={state}')
    try:
        def running():
            command.publish(Float64(data=20.0 * LPM))
            return len(factors) > 3
        assert _spin_until(executor, running), 'no health/leakage_factor'
        assert 0.5 < factors[-1].data < 2.0
        assert _spin_until(executor, lambda: any(
            s.name.endswith('motor health') for d in diagnostics for s in d.status))
        assert monitor.poll() is None
    finally:
        code, output = build.stop_process(monitor)
        build.stop_process(plant)
    assert code == 0, output
    saved = json.loads(state.read_text())
    assert saved['n_samples'] > 100  # the hours so far, kept for the next start
