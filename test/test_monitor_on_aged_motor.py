# SPDX-License-Identifier: Apache-2.0
"""
The motor_monitor node watches the virtual motor ageing on its sim clock, in one process.

The plant runs in ``sim`` mode (1 kHz physics at a 5 ms step, topics at 10 Hz, a realistic
flowmeter noise); a leak to the case (``fault.*``) strikes at 600 s of its clock. The monitor
runs on ``use_sim_time`` and learns for 6 min. Twenty minutes of operation take about 40 s.
"""

import os
import time

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from satmotor_ros.interface import CHANNELS
from satmotor_ros.model.units import LPM, RPM
from satmotor_ros.nodes.motor_monitor import MotorMonitorNode
from satmotor_ros.nodes.virtual_motor import VirtualMotorNode
from std_msgs.msg import Float64

pytestmark = [pytest.mark.ros, pytest.mark.slow]

NAMESPACE = f'/aged_motor_test_{os.getpid()}'
FAULT_S, END_S = 600.0, 1200.0  # [s] of the plant's clock
LEAK = 3.0e-11  # k_ex [m^3/(s*Pa)]: about +30 % of the losses at this operating point


def _parameters(values):
    return [Parameter(k, value=v) for k, v in values.items()]


@pytest.fixture(scope='module')
def aged():
    """Run the plant and the monitor to END_S; the monitor's snapshots before and after."""
    context = Context()
    context.init()
    executor = SingleThreadedExecutor(context=context)
    plant_values = {
        'clock_mode': 'sim', 'publish_rate': 10.0, 'step': 0.005, 'load.torque': 40.0,
        'sensors.flow.noise': 0.05 * LPM, 'sensors.speed.noise': 0.5 * RPM,
        'fault.time': FAULT_S, 'fault.effect': 'external_leakage', 'fault.value': LEAK}
    monitor_values = {'use_sim_time': True, 'learn_hours': 0.1, 'input_timeout': 5.0,
                      'update_period': 5.0}
    plant = VirtualMotorNode(context=context, namespace=NAMESPACE,
                             parameter_overrides=_parameters(plant_values))
    monitor = MotorMonitorNode(context=context, namespace=NAMESPACE,
                               parameter_overrides=_parameters(monitor_values))
    probe = rclpy.create_node('probe', namespace=NAMESPACE, context=context)
    command = probe.create_publisher(Float64, CHANNELS['flow'].topic, 10)
    for node in (plant, monitor, probe):
        executor.add_node(node)
    before = None
    try:
        deadline = time.monotonic() + 600.0
        while plant.plant.state.time < END_S and time.monotonic() < deadline:
            command.publish(Float64(data=20.0 * LPM))
            for _ in range(20):
                executor.spin_once(timeout_sec=0.0)
            if before is None and plant.plant.state.time >= FAULT_S - 5.0:
                monitor.update()
                before = monitor.monitor.snapshot()
        monitor.update()
        yield before, monitor.monitor.snapshot(), monitor, plant.plant
    finally:
        executor.shutdown()
        for node in (plant, monitor, probe):
            node.destroy_node()
        context.try_shutdown()


def test_the_leakage_factor_steps_when_the_fault_strikes(aged):
    """1 within its interval before the leak; well above 1 after; hours of operation counted."""
    before, after, _, plant = aged
    assert plant.state.time >= END_S and plant.fault_struck
    assert not before.learning and abs(before.leakage_factor.value - 1.0) < 0.02
    assert after.leakage_factor.low > 1.2
    assert after.operating_hours == pytest.approx(END_S / 3600.0, rel=0.05)
    assert after.n_skipped < 0.01 * after.n_samples


def test_the_leak_is_a_change_alarm_within_minutes_and_the_node_says_error(aged):
    """One change alarm after the strike, within 5 min; /diagnostics level ERROR."""
    _, after, monitor, _ = aged
    changes = [a for a in after.alarms if a.kind == 'change']
    assert changes and FAULT_S <= changes[0].time_s <= FAULT_S + 300.0
    assert monitor.level(after)[0] == 2
