# SPDX-License-Identifier: Apache-2.0
"""A signal at any moment of a node's start-up ends it quietly, never with a traceback."""

import os
import signal
import subprocess
import sys
import time

from node_harness import unique_namespace
import pytest

pytestmark = [pytest.mark.ros, pytest.mark.slow]

QUIET = {0, 130, -signal.SIGTERM}
"""Quiet ends: done, interrupted during the imports, killed by SIGTERM before rclpy's handler."""


@pytest.mark.parametrize('node', ['motor_model', 'virtual_motor', 'speed_controller'])
def test_signal_during_start_up_ends_the_node_quietly(node):
    # as the console script does; 'started' marks the end of the interpreter's own start-up
    # and of importing the 1.5 ms launcher, which no program can guard: the signal then lands
    # anywhere in the node's imports (most of the start-up), rclpy.init or its construction
    code = (f'from satmotor_ros.nodes.launch import {node}; print("started", flush=True); '
            f'{node}()')
    seen = []
    for k, delay in enumerate([0.0, 0.15, 0.3, 0.5, 0.7, 1.0, 1.3]):
        sig = signal.SIGINT if k % 2 == 0 else signal.SIGTERM
        proc = subprocess.Popen(
            [sys.executable, '-c', code, '--ros-args', '-r', f'__ns:={unique_namespace(node)}'],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ.copy())
        assert proc.stdout.readline() == 'started\n'
        time.sleep(delay)
        proc.send_signal(sig)
        try:
            out, err = proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            pytest.fail(f'{node} did not stop {delay} s into its start-up ({sig.name})')
        assert 'Traceback' not in err, f'{sig.name} after {delay} s:\n{err}'
        assert proc.returncode in QUIET, (delay, sig.name, proc.returncode, out, err)
        seen.append(proc.returncode)
    assert 0 in seen  # at least one signal reached a running node, which ended normally
