# SPDX-License-Identifier: Apache-2.0
"""The console scripts drop rclpy's traceback for a Task a start-up signal cut short."""

from types import SimpleNamespace

from satmotor_ros.nodes.launch import _quiet_cut_short_tasks


class Future:

    def __del__(self):  # the qualname rclpy's is: Future.__del__
        pass


def test_only_a_cut_short_tasks_attribute_error_is_dropped():
    seen = []
    error = AttributeError("'Task' object has no attribute '_exception'")
    half_built = SimpleNamespace(exc_value=error, object=Future.__del__)
    _quiet_cut_short_tasks(half_built, seen.append)
    assert seen == []
    for other in (SimpleNamespace(exc_value=ValueError('x'), object=Future.__del__),
                  SimpleNamespace(exc_value=AttributeError('x'), object=print)):
        _quiet_cut_short_tasks(other, seen.append)
    assert len(seen) == 2
