# SPDX-License-Identifier: Apache-2.0
"""Run a node until shutdown: every node's ``main``."""

from __future__ import annotations

from collections.abc import Callable
import sys
from typing import Protocol

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from satmotor_ros.limits import BAD_OVERRIDES


class NodeMain(Protocol):
    """A node's console-script ``main``."""

    def __call__(self, args: list[str] | None = None) -> None:
        """Run the node; `args` is the command line (ROS arguments included)."""


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


def node_main(make_node: Callable[[], Node], name: str) -> NodeMain:
    """
    Make a node's ``main`` (its console script): run the node until shut down.

    The ``main`` initialises rclpy, builds the node and spins it. Ctrl-C, SIGTERM and an
    external shutdown end the run quietly, also while the node is being built (rclpy's
    signal handler shuts the context down, and building the rest of the node then fails:
    that failure is the signal's doing, not an error). Bad start-up parameters (a
    ValueError or OSError from `make_node`) print one line and exit with status 1,
    without a traceback. A SATMOTOR_* cap variable that changes nothing is logged as an
    ERROR and the node runs on the default. The node is destroyed and rclpy shut down in
    every case.

    Parameters
    ----------
    make_node : callable
        Builds the node in the initialised default context, [-]
    name : str
        The executable's name, which prefixes the one-line error, [-]

    Returns
    -------
    NodeMain
        ``main(args=None)``, `args` being the command line (ROS arguments included).

    """
    def main(args: list[str] | None = None) -> None:
        node, initialised = None, False
        try:
            rclpy.init(args=args)
            initialised = True
            for bad in BAD_OVERRIDES:  # a node runs on: a wrong cap variable never stops it
                rclpy.logging.get_logger(name).error(f'{bad}; {bad.instead}')
            node = make_node()
            spin(node)
        except (KeyboardInterrupt, ExternalShutdownException):
            pass
        except Exception as err:
            if initialised and not rclpy.ok():  # a signal shut rclpy down during the build
                return
            if not isinstance(err, (ValueError, OSError)):
                raise
            print(f'{name}: {err}')  # bad start-up parameters: one line, no traceback
            raise SystemExit(1) from None
        finally:
            if node is not None:
                node.destroy_node()
            rclpy.try_shutdown()

    main.__doc__ = f'Run ``{name}`` until shut down; `args` is the command line.'
    return main
