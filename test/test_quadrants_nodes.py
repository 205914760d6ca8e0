# SPDX-License-Identifier: Apache-2.0
"""The nodes keep the sign: reverse and pump mode through real rclpy topics."""

import os
import time

from node_harness import unique_namespace
import pytest
import rclpy
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from satmotor_ros.interface import CHANNELS
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.nodes.motor_model import MotorModelNode
from satmotor_ros.nodes.virtual_motor import VirtualMotorNode
from sensor_msgs.msg import FluidPressure, JointState
from std_msgs.msg import Float64


@pytest.mark.parametrize(('flow', 'p_in', 'p_out'), [
    (-5 * LPM, 0.5 * MPA, 25 * MPA),  # motor, turning backwards
    (5 * LPM, 0.5 * MPA, 20 * MPA),  # pump, driven forwards against the pressure
    (-5 * LPM, 20 * MPA, 0.5 * MPA),  # pump, driven backwards
])
def test_motor_model_predicts_signed_speed_and_losses(harness, flow, p_in, p_out):
    ns = unique_namespace('quadrants')
    node = MotorModelNode(context=harness.context, namespace=ns,
                          parameter_overrides=[Parameter('liquid', value='water')])
    harness.executor.add_node(node)
    try:
        motor = harness.motor(ns)
        harness.wait_connected(motor)
        expected = MotorModel.default('water').speed_point(flow, p_in - p_out)
        for _ in range(3):
            motor.inputs(p_in=p_in, p_out=p_out, speed=expected.speed + 1.0)
            harness.spin_for(0.03)
        motor.flow.publish(Float64(data=flow))
        assert harness.spin_until(lambda: motor.predicted and motor.losses['total']
                                  and motor.residual, 5.0)
        speed = motor.predicted[0].velocity[0]
        assert speed == pytest.approx(expected.speed, rel=1e-12)
        assert (speed > 0.0) == (flow > 0.0)  # a pump turns with its flow too
        assert motor.losses['total'][0].data == pytest.approx(expected.total, rel=1e-12)
        assert (motor.losses['total'][0].data > 0.0) == (p_in > p_out)  # high to low
        assert motor.residual[0].data == pytest.approx(1.0, rel=1e-9)
        assert not any(s.level >= 2 for s in motor.diagnostics)
    finally:
        harness.executor.remove_node(node)
        node.destroy_node()


@pytest.mark.ros
def test_virtual_motor_runs_backwards_on_a_negative_command():
    namespace = f'/vm_quadrants_{os.getpid()}'
    context = rclpy.context.Context()
    context.init()
    executor = rclpy.executors.SingleThreadedExecutor(context=context)
    probe = rclpy.create_node('probe', namespace=namespace, context=context)
    executor.add_node(probe)
    node = VirtualMotorNode(context=context, namespace=namespace, parameter_overrides=[
        Parameter('clock_mode', value='sim'), Parameter('load.torque', value=40.0),
        Parameter('liquid', value='water')])
    executor.add_node(node)
    try:
        command = probe.create_publisher(Float64, CHANNELS['flow'].topic, 10)
        joints, inlet, outlet, flow = [], [], [], []
        for kind, name, inbox in ((JointState, 'measured_speed', joints),
                                  (FluidPressure, 'p_in', inlet),
                                  (FluidPressure, 'p_out', outlet),
                                  (Float64, 'flow_measured', flow)):
            probe.create_subscription(kind, CHANNELS[name].topic, inbox.append,
                                      qos_profile_sensor_data)
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline and not (node.plant.state.time > 3.0
                                                   and len(joints) > 10 and len(flow) > 10):
            command.publish(Float64(data=-15.0 * LPM))
            executor.spin_once(timeout_sec=0.01)
        assert node.rejected == 0
        speed = joints[-1].velocity[0]
        dp = inlet[-1].fluid_pressure - outlet[-1].fluid_pressure
        assert speed < 0.0 and dp < -1.0 * MPA
        expected = float(MotorModel.default('water').speed(-15.0 * LPM, dp).speed)
        assert speed == pytest.approx(expected, rel=1e-3)
        assert flow[-1].data == pytest.approx(-15.0 * LPM, rel=1e-3)
    finally:
        executor.shutdown()
        node.destroy_node()
        probe.destroy_node()
        context.try_shutdown()
