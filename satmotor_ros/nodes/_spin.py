# SPDX-License-Identifier: Apache-2.0
"""Spin a node until shutdown, as every node's ``main`` does."""

from __future__ import annotations

import rclpy
from rclpy.node import Node


def spin(node: Node) -> None:
    """
    Spin `node` until its context shuts down.

    When SIGINT shuts the context down while the executor is taking a message,
    rclpy can raise a RuntimeError from the destroyed subscription ("Unable to
    convert call argument"); that race ends the run as the signal meant to, so
    it is not reported. A RuntimeError while the context is still up is.

    Parameters
    ----------
    node : rclpy.node.Node
        The node, [-]

    """
    try:
        rclpy.spin(node)
    except RuntimeError:
        if node.context.ok():
            raise
