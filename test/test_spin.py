# SPDX-License-Identifier: Apache-2.0
"""The nodes' shared spin: a SIGINT race ends the run, any other RuntimeError is raised."""

import pytest
import rclpy
from rclpy.context import Context
from satmotor_ros.nodes import _spin

pytestmark = pytest.mark.ros


def _spin_raising(message, capsys):
    context = Context()
    context.init()
    node = rclpy.create_node('spinner', context=context)

    def fail():
        raise RuntimeError(message)
    node.create_timer(0.001, fail)
    rclpy_spin = rclpy.spin
    try:
        rclpy.spin = lambda n: rclpy_spin(n, executor=rclpy.executors.SingleThreadedExecutor(
            context=context))
        _spin.spin(node)
        return capsys.readouterr().err
    finally:
        rclpy.spin = rclpy_spin
        node.destroy_node()
        context.try_shutdown()


def test_an_interrupted_message_take_ends_the_run_with_a_note(capsys):
    """A KeyboardInterrupt swallowed by pybind's cast: the run ends, stderr says so."""
    err = _spin_raising("Unable to convert call argument '0' to Python object", capsys)
    assert 'spinner: stopped while taking a message' in err


def test_any_other_runtime_error_is_raised(capsys):
    """A RuntimeError that is not the race propagates while the context is up."""
    with pytest.raises(RuntimeError, match='plant exploded'):
        _spin_raising('plant exploded', capsys)
