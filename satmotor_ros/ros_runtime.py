# SPDX-License-Identifier: Apache-2.0
"""
What the ROS entry points need from ROS 2, checked before anything else is imported.

A ``pip install`` brings the library and the CLI but not ROS 2: rclpy and the message
packages come from a ROS 2 Kilted installation or its Python wheels. Without them a node,
or ``satmotor demo``, ends in one line that says so, not in an import traceback.
"""

from __future__ import annotations

import importlib
import sys

ROS_MODULES = ('rclpy', 'builtin_interfaces.msg', 'rcl_interfaces.msg', 'std_msgs.msg',
               'sensor_msgs.msg', 'diagnostic_msgs.msg', 'rosgraph_msgs.msg')
"""The ROS 2 Python packages the nodes and the demo import."""

MISSING_ROS = (
    "needs ROS 2 Kilted's Python packages (rclpy, std_msgs, sensor_msgs, diagnostic_msgs): "
    'source /opt/ros/kilted/setup.bash, or pip install ros-kilted-rclpy ros-kilted-std-msgs '
    'ros-kilted-sensor-msgs ros-kilted-diagnostic-msgs')
"""What to do when they cannot be imported (after the program's name)."""


def ros_problem() -> str | None:
    """
    Try to import the ROS 2 packages the nodes use.

    Returns
    -------
    str or None
        The module that failed and why (``"rclpy: No module named 'rclpy'"``), or None.

    """
    for module in ROS_MODULES:
        try:
            importlib.import_module(module)
        except ImportError as err:  # also a broken install: a missing shared library
            return f'{module}: {err}'
    return None


def require_ros(program: str) -> None:
    """
    End the program with one line on stderr and status 1 if ROS 2 cannot be imported.

    Parameters
    ----------
    program : str
        The program's name, which starts the line (``'motor_model'``), [-]

    Raises
    ------
    SystemExit
        With status 1 when a ROS 2 package is missing.

    """
    problem = ros_problem()
    if problem is not None:
        print(f'{program}: {MISSING_ROS} (cannot import {problem})', file=sys.stderr)
        raise SystemExit(1)
