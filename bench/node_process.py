# SPDX-License-Identifier: Apache-2.0
"""
A node process driven by a bench: start it, feed it while spinning, drain, stop it.

The benches that measure a node in a process of its own (``bench_node.py``,
``bench_monitor_node.py``) and the one that runs a listener beside an in-process node
(``bench_plant.py``) share this loop: a private context, node and executor in this
process; a feeder thread publishing on a fixed schedule while this thread spins; a drain
of the last outputs; then SIGINT to the process and a kill if its shutdown sticks (its
numbers are taken by then).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
import os
from pathlib import Path
import signal
import subprocess
import sys
import threading
import time
import uuid

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
ROOT = Path(__file__).resolve().parent.parent
"""The source tree whose satmotor_ros the node processes run."""

from rclpy.context import Context  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.node import Node  # noqa: E402


def cpu_seconds(pid: int) -> float:
    """Return the CPU time (user + system) process `pid` has used so far, [s]."""
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def start(code: str, *ros_args: str) -> subprocess.Popen[bytes]:
    """Run Python `code` in a process of its own on this source tree, with ``--ros-args``."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        filter(None, (str(ROOT), os.environ.get('PYTHONPATH')))))
    return subprocess.Popen([sys.executable, '-c', code, '--ros-args', *ros_args], env=env)


def stop(proc: subprocess.Popen[bytes], timeout: float = 10.0) -> None:
    """Stop `proc` with SIGINT, as Ctrl-C would; kill it if it is not gone in `timeout` s."""
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout)
    except subprocess.TimeoutExpired:  # stuck in its shutdown: its numbers are taken
        proc.kill()
        proc.wait()


@contextmanager
def driver(proc: subprocess.Popen[bytes] | None = None) -> Iterator[
        tuple[Node, SingleThreadedExecutor]]:
    """
    Give a node and its executor in a context of their own; on exit, close them, stop `proc`.

    The context is initialised without arguments: the bench's own options are not rcl's
    (``NAME:=VALUE`` would be read as a remapping).
    """
    context = Context()
    context.init(args=[])
    node = Node(f'bench_{uuid.uuid4().hex[:8]}', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    try:
        yield node, executor
    finally:
        executor.shutdown()
        node.destroy_node()
        context.try_shutdown()
        if proc is not None:
            stop(proc)


def spin_until(executor: SingleThreadedExecutor, ready: Callable[[], bool],
               timeout: float = 30.0) -> bool:
    """Spin until `ready()` holds or `timeout` s pass; return whether it holds."""
    deadline = time.monotonic() + timeout
    while not (done := ready()) and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    return done


def spin_feeding(executor: SingleThreadedExecutor, feed: Callable[[], None],
                 drain: float) -> None:
    """Run `feed` in a thread while spinning, then spin `drain` s more for the last outputs."""
    feeder = threading.Thread(target=feed)
    feeder.start()
    while feeder.is_alive():
        executor.spin_once(timeout_sec=0.01)
    end = time.monotonic() + drain
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.01)


def on_schedule(rate: float, n: int, publish: Callable[[int], None]) -> Callable[[], None]:
    """Return a feed that calls `publish(k)` for k < `n` at `rate` Hz from its start."""
    def feed() -> None:
        period = 1.0 / rate
        begin = time.monotonic()
        for k in range(n):
            target = begin + k * period
            while (now := time.monotonic()) < target:
                time.sleep(min(target - now, 2e-4))
            publish(k)
    return feed
