# SPDX-License-Identifier: Apache-2.0
"""
The nodes' console scripts (what ``ros2 run satmotor_ros NODE`` starts).

A node module imports rclpy and numpy, which takes a good part of a second. A
Ctrl-C in that window would end in a KeyboardInterrupt traceback; here it ends
the start-up quietly with status 130, as a shell reports an interrupted program (and
rclpy's garbage-collector traceback for a Task the signal cut short is not printed).
Without ROS 2 (a pip install alone) a node ends in one line naming what it needs.
"""

from __future__ import annotations

import importlib
import sys
from typing import Any

from satmotor_ros.ros_runtime import require_ros


def _quiet_cut_short_tasks(unraisable: Any, hook: Any = sys.unraisablehook) -> None:
    # rclpy: a signal inside a Task's __init__ leaves it without the state Future.__del__
    # reads, and the garbage collector then prints a traceback for a start-up already ended
    if (isinstance(unraisable.exc_value, AttributeError)
            and getattr(unraisable.object, '__qualname__', '') == 'Future.__del__'):
        return
    hook(unraisable)


def _launch(module: str) -> None:
    sys.unraisablehook = _quiet_cut_short_tasks
    try:
        require_ros(module)
        main = importlib.import_module(f'satmotor_ros.nodes.{module}').main
    except KeyboardInterrupt:
        raise SystemExit(130) from None
    main()


def motor_model() -> None:
    """Run the motor_model node."""
    _launch('motor_model')


def virtual_motor() -> None:
    """Run the virtual_motor node."""
    _launch('virtual_motor')


def speed_controller() -> None:
    """Run the speed_controller node."""
    _launch('speed_controller')


def motor_monitor() -> None:
    """Run the motor_monitor node."""
    _launch('motor_monitor')
