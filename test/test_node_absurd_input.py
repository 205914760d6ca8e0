# SPDX-License-Identifier: Apache-2.0
"""One absurd joint_states message latches nothing in motor_model (issue 25 item 4)."""

import math

from node_harness import unique_namespace
import pytest
from rclpy.parameter import Parameter
from satmotor_ros.model.io.config import default_config_path
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.nodes.motor_model import MotorModelNode
from std_msgs.msg import Float64
import yaml


def _wear_file(tmp_path):
    """Write the packaged motor with a wear-by-revolutions effect on oil: 1e-12 m per rev."""
    motor = yaml.safe_load(default_config_path().read_text(encoding='utf-8'))
    motor['coefficient_sets']['oil']['effects'] = {
        'clearance_wear': {'regressor': 'revolutions', 'coefficient': 1e-12, 'reference': 0.0}}
    path = tmp_path / 'worn.yaml'
    path.write_text(yaml.safe_dump(motor, allow_unicode=True), encoding='utf-8')
    return path


def _predict(harness, motor, speed):
    """Publish fresh inputs and one flow command; return the predicted speed."""
    motor.inputs(p_in=20 * MPA, p_out=0.5 * MPA, speed=speed)
    harness.spin_for(0.03)
    motor.predicted.clear()
    motor.flow.publish(Float64(data=20 * LPM))
    assert harness.spin_until(lambda: motor.predicted, 5.0)
    return motor.predicted[-1].velocity[0]


@pytest.mark.parametrize('absurd', [6.3e8, 1e308])
def test_an_absurd_speed_is_refused_and_latches_nothing(harness, tmp_path, absurd):
    ns = unique_namespace('absurd')
    node = MotorModelNode(context=harness.context, namespace=ns, parameter_overrides=[
        Parameter('motor_file', value=str(_wear_file(tmp_path))),
        Parameter('liquid', value='oil')])
    harness.executor.add_node(node)
    try:
        motor = harness.motor(ns)
        harness.wait_connected(motor)
        before = [_predict(harness, motor, 100.0) for _ in range(3)][-1]
        motor.diagnostics.clear()
        for _ in range(3):  # the broken message is the latest speed for several predictions
            _predict(harness, motor, absurd)
        assert harness.spin_until(lambda: any(s.level == b'\x01' for s in motor.diagnostics),
                                  5.0), [s.message for s in motor.diagnostics]
        warned = next(s for s in motor.diagnostics if s.level == b'\x01')
        assert f'joint_states.velocity = {absurd!r} rad/s: beyond any motor' in warned.message
        assert node._progress.revolutions < 100.0  # 100 rad/s over a few seconds: ~16 rev
        after = [_predict(harness, motor, 100.0) for _ in range(3)][-1]
        assert math.isfinite(after) and after == pytest.approx(before, rel=1e-6)
        motor.diagnostics.clear()
        while len(motor.diagnostics) < 2:  # a whole report period of good speeds: OK again
            _predict(harness, motor, 100.0)
        assert motor.diagnostics[-1].level == b'\x00', motor.diagnostics[-1].message
    finally:
        harness.executor.remove_node(node)
        node.destroy_node()
