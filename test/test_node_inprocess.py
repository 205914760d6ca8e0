# SPDX-License-Identifier: Apache-2.0
"""The node as a library class: added to the caller's own executor, parameters checked."""

from node_harness import unique_namespace
import pytest
from rclpy.parameter import Parameter
from satmotor_ros.interface import LOSS_COMPONENTS, LOSSES_ARRAY, LOSSES_PREFIX
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.nodes.motor_model import MotorModelNode, PARAMETERS
from std_msgs.msg import Float64


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


@pytest.mark.parametrize(('fmt', 'every'), [('array', 1), ('both', 1), ('array', 3)])
def test_losses_as_one_array_named_by_its_layout_and_thinned(harness, fmt, every):
    """losses_format 'array': one Float64MultiArray on losses instead of eight topics."""
    ns = unique_namespace('losses')
    node = MotorModelNode(context=harness.context, namespace=ns, parameter_overrides=[
        Parameter('losses_format', value=fmt), Parameter('losses_every', value=every)])
    harness.executor.add_node(node)
    try:
        motor = harness.motor(ns)
        harness.wait_connected(motor)
        for _ in range(3):
            motor.inputs(p_in=20 * MPA, p_out=0.5 * MPA)
            harness.spin_for(0.03)
        flows = [(5 + k) * LPM for k in range(6)]
        for flow in flows:
            motor.flow.publish(Float64(data=flow))
            harness.spin_for(0.02)
        assert harness.spin_until(lambda: len(motor.predicted) == len(flows), 5.0)
        assert harness.spin_until(lambda: len(motor.losses_array) == len(flows) // every, 5.0)
        harness.spin_for(0.2)
        assert len(motor.losses_array) == len(flows) // every
        (dim,) = motor.losses_array[0].layout.dim
        assert dim.label.split(',') == list(LOSS_COMPONENTS) and dim.size == 8
        model = MotorModel.default('oil')
        for k, msg in enumerate(motor.losses_array):
            point = model.speed_point(flows[(k + 1) * every - 1], 19.5 * MPA)
            assert list(msg.data) == [getattr(point, c) for c in LOSS_COMPONENTS]
        per_topic = len(motor.losses['total'])
        assert per_topic == (len(flows) if fmt == 'both' else 0)
    finally:
        harness.executor.remove_node(node)
        node.destroy_node()


@pytest.mark.parametrize('module', ['motor_model', 'speed_controller', 'virtual_motor'])
def test_every_node_takes_the_same_motor_and_liquid_parameters(harness, module):
    """One declaration (nodes._parameters.MOTOR_PARAMETERS) and one MotorOptions.build_model."""
    import importlib

    from satmotor_ros.nodes._parameters import MOTOR_PARAMETERS
    node_module = importlib.import_module(f'satmotor_ros.nodes.{module}')
    cls = next(getattr(node_module, n) for n in dir(node_module)
               if n.endswith('Node') and n != 'Node')
    overrides = [Parameter('liquid', value='water'), Parameter('viscosity', value=2.0e-6),
                 Parameter('displacement_law', value='eq39')]
    node = cls(context=harness.context, namespace=unique_namespace(module),
               parameter_overrides=overrides)
    try:
        for spec in MOTOR_PARAMETERS:
            assert node.has_parameter(spec.name), spec.name
        model = {'motor_model': lambda: node._model, 'speed_controller': lambda: node.law.model,
                 'virtual_motor': lambda: node.plant.model}[module]()
        assert model.coefficient_set.name == 'water' and model.displacement_law == 'eq39'
        assert model.liquid.kinematic_viscosity == 2.0e-6
        assert model.liquid.name == 'user liquid on the water set'
    finally:
        node.destroy_node()


def test_losses_format_changed_at_run_time_keeps_only_its_publishers(harness):
    ns = unique_namespace('fmt')
    node = MotorModelNode(context=harness.context, namespace=ns)
    harness.executor.add_node(node)

    def counts():
        return (harness.node.count_publishers(f'{ns}/{LOSSES_PREFIX}total'),
                harness.node.count_publishers(f'{ns}/{LOSSES_ARRAY}'))
    try:
        assert harness.spin_until(lambda: counts() == (1, 0), 5.0), counts()
        for fmt, expected in (('array', (0, 1)), ('both', (1, 1)), ('topics', (1, 0))):
            (result,) = node.set_parameters([Parameter('losses_format', value=fmt)])
            assert result.successful
            assert harness.spin_until(lambda: counts() == expected, 5.0), (fmt, counts())
    finally:
        harness.executor.remove_node(node)
        node.destroy_node()
