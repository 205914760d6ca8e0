# SPDX-License-Identifier: Apache-2.0
"""
Test-session setup shared by every test.

pytest imports this file before it collects any test module or doctest, so the ROS
environment below is in place before anything can import rclpy; subprocesses that the
tests start inherit it.
"""

import os

import pytest

# Discovery never leaves this machine, whatever the calling shell says.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

# A domain of the test session's own, unless the caller (Makefile, .ci/run) chose one.
# ROS documents 0..101 as the ids that are safe on Linux (higher ids reach into the
# ephemeral port range), and 0 is everyone's default, so use 1..101.
if not os.environ.get('ROS_DOMAIN_ID'):
    os.environ['ROS_DOMAIN_ID'] = str(1 + os.getpid() % 101)


@pytest.fixture()
def harness():
    """Give a test its own Context, node and executor, shut down afterwards."""
    from node_harness import Harness  # imports rclpy: only after the environment above
    h = Harness()
    try:
        yield h
    finally:
        h.close()
