# SPDX-License-Identifier: Apache-2.0
"""The node as a library class: added to the caller's own executor, parameters checked."""

from node_harness import Harness, unique_namespace
import pytest
from rclpy.parameter import Parameter
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.nodes.motor_model import MotorModelNode, PARAMETERS
from std_msgs.msg import Float64


@pytest.fixture()
def harness():
    """Give a test its own Context, node and executor, shut down afterwards."""
    h = Harness()
    try:
        yield h
    finally:
        h.close()


def test_node_joins_a_user_executor_and_predicts(harness):
    ns = unique_namespace('inproc')
    node = MotorModelNode(context=harness.context, namespace=ns,
                          parameter_overrides=[Parameter('liquid', value='water')])
    harness.executor.add_node(node)
    try:
        motor = harness.motor(ns)
        harness.wait_connected(motor)
        for _ in range(3):
            motor.inputs(p_in=25 * MPA, p_out=0.5 * MPA)
            harness.spin_for(0.03)
        motor.flow.publish(Float64(data=5 * LPM))
        assert harness.spin_until(lambda: motor.predicted, 5.0)
        expected = MotorModel.default('water').speed_point(5 * LPM, 24.5 * MPA)
        assert motor.predicted[0].velocity[0] == pytest.approx(expected.speed, rel=1e-15)
    finally:
        harness.executor.remove_node(node)
        node.destroy_node()


@pytest.mark.parametrize(('name', 'value', 'reason'), [
    ('publish_rate', 0.0, 'publish_rate'),
    ('viscosity', -1e-6, 'viscosity'),
    ('liquid', 'mercury', "liquid = 'mercury': not a coefficient set"),
    ('displacement_law', 'eq34', 'use one of eq33, eq39'),
    ('motor_file', '/does/not/exist.yaml', '/does/not/exist.yaml'),
    ('joint_name', '', 'must not be empty'),
    ('input_timeout', 'soon', "input_timeout = 'soon': must be a number [s]"),
    ('qos_depth', 2.5, 'qos_depth'),
])
def test_bad_parameter_is_rejected_with_its_reason_and_the_old_value_kept(
        harness, name, value, reason):
    node = MotorModelNode(context=harness.context, namespace=unique_namespace('params'))
    try:
        old = node.get_parameter(name).value
        (result,) = node.set_parameters([Parameter(name, value=value)])
        assert not result.successful and reason in result.reason, result.reason
        assert node.get_parameter(name).value == old
    finally:
        node.destroy_node()


def test_every_parameter_states_its_unit_and_range():
    for spec in PARAMETERS:
        desc = spec.descriptor()
        assert desc.description.endswith(']'), spec.name
        if isinstance(spec.default, float):
            assert desc.floating_point_range, spec.name
        if spec.choices:
            assert all(c in desc.additional_constraints for c in spec.choices)
