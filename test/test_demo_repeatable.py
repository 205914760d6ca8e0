# SPDX-License-Identifier: Apache-2.0
"""``satmotor demo`` twice, as real processes: the same messages, the same metrics."""

from pathlib import Path
import re
import subprocess
import sys

import pytest
from rosbags.highlevel import AnyReader

pytestmark = [pytest.mark.ros, pytest.mark.slow]

ROOT = Path(__file__).resolve().parent.parent


def _demos(*outs: Path) -> None:
    """Run the demos at the same time, on the same ROS domain."""
    runs = [subprocess.Popen([sys.executable, '-m', 'satmotor_ros.cli', 'demo', '--liquid',
                              'water', '--duration', '3', '--no-loop', '--quiet', '--out',
                              str(out)], cwd=ROOT, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL) for out in outs]
    assert [run.wait(timeout=300) for run in runs] == [0] * len(runs)


def _messages(out: Path) -> dict[tuple[str, str], list[tuple[int, bytes]]]:
    """Every message of every bag but ``/diagnostics`` (wall-clock figures), by run."""
    found: dict[tuple[str, str], list[tuple[int, bytes]]] = {}
    for bag in sorted((out / 'bags').iterdir()):
        with AnyReader([bag]) as reader:
            for connection, stamp, raw in reader.messages():
                if connection.topic != '/diagnostics':
                    found.setdefault((bag.name, connection.topic), []).append(
                        (stamp, bytes(raw)))
    return found


def _metrics(out: Path) -> str:
    report = (out / 'report.md').read_text(encoding='utf-8')
    return report[:report.index('## Runs')]


def _runs(out: Path) -> str:
    report = (out / 'report.md').read_text(encoding='utf-8')
    return report[report.index('## Runs'):]


def test_two_demo_runs_log_the_same_messages_and_metrics(tmp_path):
    """
    The controller answers every 10 ms period of simulated time, in both runs alike.

    The two run side by side on one domain: neither sees the other's /clock.
    """
    first, second = tmp_path / 'first', tmp_path / 'second'
    _demos(first, second)
    messages = _messages(first)
    assert messages == _messages(second)
    assert _metrics(first) == _metrics(second)
    for run in ('water_model', 'water_none'):
        commands = messages[(run, '/flow_command')]
        # one command per period from the first controller tick at 10 ms to the end at 3 s
        assert [stamp for stamp, _ in commands] == [10_000_000 * k for k in range(1, 301)]
        clock = messages[(run, '/clock')]
        assert [stamp for stamp, _ in clock] == [10_000_000 * k for k in range(301)]
    runs = re.findall(r'^\| water / \w+ \|.*\| (\d+) \| `bags/', _runs(first), re.M)
    assert runs == ['0', '0']  # no period was taken without its answer
