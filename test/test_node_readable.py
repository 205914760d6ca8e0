# SPDX-License-Identifier: Apache-2.0
"""Logs and diagnostics a person reads: hydraulic units, no 'nan', no OK beside an ERROR."""

from diagnostic_msgs.msg import DiagnosticArray
from node_harness import unique_namespace
import pytest
from rclpy.parameter import Parameter
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM
from satmotor_ros.nodes.motor_model import MotorModelNode
from satmotor_ros.nodes.speed_controller import SpeedControllerNode
from satmotor_ros.nodes.virtual_motor import VirtualMotorNode
from std_msgs.msg import Float64


def _values(status):
    return {kv.key: kv.value for kv in status.values}


def _node(harness, *overrides):
    ns = unique_namespace('readable')
    node = MotorModelNode(context=harness.context, namespace=ns,
                          parameter_overrides=list(overrides))
    harness.executor.add_node(node)
    motor = harness.motor(ns)
    harness.wait_connected(motor)
    return node, motor


def _close(harness, node):
    harness.executor.remove_node(node)
    node.destroy_node()


def test_an_error_of_the_inputs_shows_no_model_status_ok_and_no_nan(harness):
    node, motor = _node(harness)
    try:
        assert harness.spin_until(lambda: motor.diagnostics, 5.0)
        status = motor.diagnostics[-1]
        values = _values(status)
        assert status.level == b'\x02' and 'flow_command: no message received' in status.message
        assert values['model status'] == 'not run'
        assert values['speed [rpm]'] == 'n/a' and values['losses/total [l/min]'] == 'n/a'
        assert values['flow_command.data [l/min]'] == 'n/a'
        assert values['liquid'] == 'oil' and values['liquid_source'] == 'default'
        assert not [k for k, v in values.items() if 'nan' in v.lower()], values
        assert not [k for k in values if 'm^3/s' in k or '[Pa]' in k or 'rad/s' in k], values
    finally:
        _close(harness, node)


def test_a_prediction_is_shown_in_l_min_mpa_and_rpm_and_logged_without_ok_ok(harness, capfd):
    node, motor = _node(harness, Parameter('liquid', value='water'))
    try:
        for _ in range(3):
            motor.inputs(p_in=20 * MPA, p_out=0.5 * MPA, speed=50.0)
            harness.spin_for(0.03)
        motor.flow.publish(Float64(data=20 * LPM))
        assert harness.spin_until(lambda: motor.predicted, 5.0)
        motor.diagnostics.clear()
        assert harness.spin_until(lambda: motor.diagnostics, 5.0)
        values = _values(motor.diagnostics[-1])
        expected = MotorModel.default('water').speed_point(20 * LPM, 19.5 * MPA)
        assert values['flow_command.data [l/min]'] == '20.0000'
        assert values['inlet_pressure.fluid_pressure [MPa]'] == '20.0000'
        assert float(values['speed [rpm]']) == pytest.approx(expected.speed / RPM, abs=0.006)
        assert float(values['losses/total [l/min]']) == pytest.approx(expected.total / LPM,
                                                                      abs=6e-5)
        assert values['model status'] == 'OK' and values['liquid_source'] == 'parameter'
        log = capfd.readouterr().err
        assert 'prediction OK' in log and 'OK: OK' not in log, log
        assert 'liquid: water' in log and 'the default' not in log, log
    finally:
        _close(harness, node)


def test_the_plant_and_the_controller_report_in_rpm_l_min_and_mpa(harness):
    ns = unique_namespace('loop')
    motor = VirtualMotorNode(context=harness.context, namespace=ns, parameter_overrides=[
        Parameter('clock_mode', value='sim'), Parameter('max_speedup', value=5.0),
        Parameter('diagnostics_period', value=0.2)])
    controller = SpeedControllerNode(context=harness.context, namespace=ns, parameter_overrides=[
        Parameter('use_sim_time', value=True), Parameter('setpoint', value=-300.0 * RPM),
        Parameter('liquid', value='oil'), Parameter('diagnostics_period', value=0.2)])
    seen = {}

    def take(msg):
        for status in msg.status:
            if status.name.startswith(ns):
                seen[status.name.rpartition(': ')[2]] = _values(status)
    harness.node.create_subscription(DiagnosticArray, '/diagnostics', take, 100)
    for node in (motor, controller):
        harness.executor.add_node(node)
    try:
        assert harness.spin_until(lambda: {'plant', 'speed loop'} <= set(seen)
                                  and seen['speed loop']['speed [rpm]'] != 'n/a', 20.0), seen
        plant, loop = seen['plant'], seen['speed loop']
        assert plant['liquid'] == 'oil' and plant['liquid_source'] == 'default'
        assert loop['liquid_source'] == 'parameter'
        assert loop['setpoint [rpm]'] == '-300.00'
        for values in (plant, loop):
            assert not [k for k in values if 'm^3/s' in k or 'rad/s' in k or '[Pa]' in k]
            assert not [v for v in values.values() if 'nan' in v.lower()], values
        assert float(plant['inlet_pressure [MPa]']) > 0.0
        assert float(loop['flow_command [l/min]']) < 0.0  # backwards
    finally:
        for node in (motor, controller):
            harness.executor.remove_node(node)
            node.destroy_node()


def test_a_value_that_shows_as_zero_has_no_sign():
    from satmotor_ros.nodes._diagnostics import human
    assert human(-1e-21, 'm^3/s') == ('l/min', '0.0000')
    assert human(-2.0 * RPM, 'rad/s') == ('rpm', '-2.00')
    assert human(float('nan'), 'Pa') == ('MPa', 'n/a') and human(None, 's') == ('s', 'n/a')
