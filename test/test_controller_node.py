# SPDX-License-Identifier: Apache-2.0
"""speed_controller and virtual_motor over real topics in one executor, on simulated time."""

import math
import os

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from node_harness import spin_until
import pytest
from rclpy.parameter import Parameter
from satmotor_ros.model.units import RPM
from satmotor_ros.nodes.speed_controller import SpeedControllerNode
from satmotor_ros.nodes.virtual_motor import VirtualMotorNode
from std_msgs.msg import Float64

NAMESPACE = f'/controller_test_{os.getpid()}'


@pytest.fixture()
def loop(ros):
    """Give the virtual motor (sim clock) and the controller (use_sim_time) in one executor."""
    context, executor, probe = ros
    motor = VirtualMotorNode(context=context, namespace=NAMESPACE, parameter_overrides=[
        Parameter('clock_mode', value='sim'), Parameter('load.torque', value=30.0),
        Parameter('liquid', value='water')])
    controller = SpeedControllerNode(context=context, namespace=NAMESPACE, parameter_overrides=[
        Parameter('use_sim_time', value=True), Parameter('liquid', value='water'),
        Parameter('setpoint', value=600.0 * RPM), Parameter('diagnostics_period', value=0.1)])
    for node in (motor, controller):
        executor.add_node(node)
    try:
        yield executor, motor, controller, probe
    finally:
        for node in (motor, controller):
            executor.remove_node(node)
            node.destroy_node()


def test_controller_brings_the_virtual_motor_to_the_setpoint_and_follows_the_topic(loop):
    """600 rpm from the parameter, then 900 rpm from speed_setpoint, within 1 %."""
    executor, motor, controller, probe = loop
    assert spin_until(executor, lambda: motor.plant.state.time > 3.0)
    assert motor.plant.state.speed == pytest.approx(600.0 * RPM, rel=0.01)
    setpoint = probe.create_publisher(Float64, 'speed_setpoint', 10)
    setpoint.publish(Float64(data=900.0 * RPM))
    assert spin_until(executor, lambda: controller.setpoint == 900.0 * RPM)
    start = motor.plant.state.time
    assert spin_until(executor, lambda: motor.plant.state.time > start + 3.0)
    assert motor.plant.state.speed == pytest.approx(900.0 * RPM, rel=0.01)


def test_a_negative_setpoint_drives_the_virtual_motor_backwards(loop):
    """-600 rpm on speed_setpoint: the motor reverses and holds it within 1 %, then forward."""
    executor, motor, controller, probe = loop
    assert spin_until(executor, lambda: motor.plant.state.time > 2.0)
    setpoint = probe.create_publisher(Float64, 'speed_setpoint', 10)
    setpoint.publish(Float64(data=-600.0 * RPM))
    assert spin_until(executor, lambda: controller.setpoint == -600.0 * RPM)
    start = motor.plant.state.time
    assert spin_until(executor, lambda: motor.plant.state.time > start + 4.0)
    assert motor.plant.state.speed == pytest.approx(-600.0 * RPM, rel=0.01)
    assert controller.command < 0.0 and controller.rejected == 0
    setpoint.publish(Float64(data=300.0 * RPM))
    start = motor.plant.state.time
    assert spin_until(executor, lambda: motor.plant.state.time > start + 4.0)
    assert motor.plant.state.speed == pytest.approx(300.0 * RPM, rel=0.01)


def test_controller_refuses_bad_setpoints_and_parameters(loop):
    """Set-points NaN and beyond 3000 rpm either way are refused and reported."""
    executor, motor, controller, probe = loop
    diagnostics = []
    probe.create_subscription(DiagnosticArray, '/diagnostics', diagnostics.append, 10)
    setpoint = probe.create_publisher(Float64, 'speed_setpoint', 10)
    assert spin_until(executor, lambda: motor.plant.state.time > 1.0)
    for bad in (math.nan, -4000.0 * RPM):
        setpoint.publish(Float64(data=bad))
    assert spin_until(executor, lambda: controller.rejected >= 2)
    assert controller.setpoint == 600.0 * RPM
    assert spin_until(executor, lambda: any(
        s.level == DiagnosticStatus.WARN and 'speed_setpoint.data = ' in s.message
        for d in diagnostics for s in d.status if 'speed loop' in s.name))
    (result,) = controller.set_parameters([Parameter('feedforward', value='psychic')])
    assert not result.successful and 'feedforward' in result.reason
    (result,) = controller.set_parameters([Parameter('feedforward', value='none')])
    assert result.successful and controller.law.params.feedforward == 'none'


def test_shipped_parameter_file_lists_every_parameter_at_its_default():
    """config/speed_controller.yaml cannot drift from the declared parameters."""
    from pathlib import Path

    from satmotor_ros.nodes.speed_controller import PARAMETERS
    import yaml
    path = Path(__file__).resolve().parent.parent / 'config' / 'speed_controller.yaml'
    flat = yaml.safe_load(path.read_text())['/**/speed_controller']['ros__parameters']
    assert flat == {spec.name: spec.default for spec in PARAMETERS}
