# SPDX-License-Identifier: Apache-2.0
"""Spin a node until shutdown, as every node's ``main`` does."""

from __future__ import annotations

import sys

import rclpy
from rclpy.node import Node


_INTERRUPTED_TAKE = 'Unable to convert call argument'
"""What rclpy raises when SIGINT's KeyboardInterrupt lands inside a message's conversion."""


def spin(node: Node) -> None:
    """
    Spin `node` until its context shuts down.

    When SIGINT shuts the context down while the executor is taking a message,
    rclpy can raise a RuntimeError from the destroyed subscription ("Unable to
    convert call argument"). The same error comes when the signal's KeyboardInterrupt
    lands inside the conversion of a message's arguments, while the context is still up:
    pybind swallows the interrupt. Both races end the run as the signal meant to; the
    second is noted on stderr. Any other RuntimeError is raised.

    Parameters
    ----------
    node : rclpy.node.Node
        The node, [-]

    """
    try:
        rclpy.spin(node)
    except RuntimeError as err:
        if node.context.ok() and _INTERRUPTED_TAKE not in str(err):
            raise
        if node.context.ok():  # SIGINT's KeyboardInterrupt, swallowed by pybind's argument cast
            print(f'{node.get_name()}: stopped while taking a message ({err})', file=sys.stderr)
