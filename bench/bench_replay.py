# SPDX-License-Identifier: Apache-2.0
"""
Benchmark ``satmotor replay`` on a 1-hour, 100 Hz bag of the four input topics.

The bag (flow_command, inlet_pressure, outlet_pressure, joint_states: 1.44e6 messages) is
generated in a temporary directory, not in the repository. Measured in the same run:
- baseline: rosbags' own reader iterating every raw message, no deserialisation;
- replay: read, decode, combine, predict, residual statistics (what ``satmotor replay BAG
  --no-plot`` does);
- replay --out: the same plus the CSV file.
Wall time and this process's CPU time are reported (the VM is shared: CPU time is the
steadier figure).

Run: ``python bench/bench_replay.py [--storage mcap|sqlite3] [--bag DIR] [--csv]``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
from pathlib import Path
import shutil
import sys
import tempfile
import time

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # this source tree's satmotor_ros

import numpy as np  # noqa: E402
from satmotor_ros.bags import encode_many, OutTopic, write_bag  # noqa: E402
from satmotor_ros.cli.main import main as satmotor  # noqa: E402
from satmotor_ros.interface import FLOAT64, FLUID_PRESSURE, JOINT_STATE  # noqa: E402
from satmotor_ros.model import MotorModel  # noqa: E402
from satmotor_ros.model.units import LPM, MPA  # noqa: E402


def generate(path: Path, storage: str, seconds: float, rate: float) -> int:
    """
    Write the input bag: pressures and joint states 1-2 ms before each flow_command.

    Parameters
    ----------
    path : pathlib.Path
        Bag directory to create, [-]
    storage : str
        ``'mcap'`` or ``'sqlite3'``, [-]
    seconds : float
        Length of the recording, [s]
    rate : float
        Rate of every topic, [Hz]

    Returns
    -------
    int
        Messages written.

    """
    n = int(seconds * rate)
    rng = np.random.default_rng(0)
    t = 1_700_000_000_000_000_000 + (np.arange(n) * (1e9 / rate)).astype(np.int64)
    flow = rng.uniform(5, 40, n) * LPM
    p_in = rng.uniform(5, 25, n) * MPA
    p_out = rng.uniform(0.1, 1.0, n) * MPA
    speed = MotorModel.default('oil').speed(flow, p_in - p_out).speed * rng.normal(1, 0.01, n)
    return write_bag(path, [
        OutTopic('/flow_command', FLOAT64, t + 3_000_000, encode_many(FLOAT64, {'data': flow})),
        OutTopic('/inlet_pressure', FLUID_PRESSURE, t + 1_000_000,
                 encode_many(FLUID_PRESSURE, {'fluid_pressure': p_in}, t)),
        OutTopic('/outlet_pressure', FLUID_PRESSURE, t + 1_500_000,
                 encode_many(FLUID_PRESSURE, {'fluid_pressure': p_out}, t)),
        OutTopic('/joint_states', JOINT_STATE, t + 2_000_000,
                 encode_many(JOINT_STATE, {'position': np.zeros(n), 'velocity': speed,
                                           'effort': np.zeros(n)}, t, joint='motor_shaft')),
    ], storage=storage)


def timed(fn):  # noqa: ANN001, ANN201
    """Run fn() and return (result, wall seconds, CPU seconds of this process)."""
    wall, cpu = time.perf_counter(), time.process_time()
    result = fn()
    return result, time.perf_counter() - wall, time.process_time() - cpu


def rosbags_raw(path: Path) -> int:
    """Iterate every raw message with rosbags' reader (no deserialisation)."""
    from rosbags.rosbag2 import Reader
    count = 0
    with Reader(path) as reader:
        for _ in reader.messages():
            count += 1
    return count


def replay(path: Path, *extra: str) -> int:
    """Run ``satmotor replay`` quietly; return its exit code."""
    with contextlib.redirect_stdout(io.StringIO()):
        return satmotor(['replay', str(path), '--no-plot', *extra])


def main() -> None:
    """Generate (or take) the bag, then time the baseline and the replays."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--storage', choices=('mcap', 'sqlite3'), default='mcap')
    parser.add_argument('--bag', type=Path, default=None, help='reuse this bag')
    parser.add_argument('--seconds', type=float, default=3600.0)
    parser.add_argument('--rate', type=float, default=100.0)
    parser.add_argument('--csv', action='store_true', help='also time replay --out CSV')
    parser.add_argument('--no-baseline', action='store_true')
    parser.add_argument('--keep', action='store_true', help='keep the generated bag')
    args = parser.parse_args()
    scratch = Path(tempfile.mkdtemp(prefix='satmotor_bench_replay_'))
    try:
        bag = args.bag
        if bag is None:
            bag = scratch / f'bag_{args.storage}'
            n, wall, _ = timed(lambda: generate(bag, args.storage, args.seconds, args.rate))
            print(f'generated {bag}: {n} messages in {wall:.1f} s')
        rows = []
        if not args.no_baseline:
            count, wall, cpu = timed(lambda: rosbags_raw(bag))
            rows.append((f'rosbags Reader, raw read of {count} messages', wall, cpu))
        code, wall, cpu = timed(lambda: replay(bag))
        assert code == 0, 'replay failed'
        rows.append(('satmotor replay (read, decode, combine, predict, stats)', wall, cpu))
        if args.csv:
            out = scratch / 'replay.csv'
            code, wall, cpu = timed(lambda: replay(bag, '--out', str(out)))
            assert code == 0, 'replay --out failed'
            rows.append((f'satmotor replay --out CSV ({out.stat().st_size / 1e6:.0f} MB)',
                         wall, cpu))
        print(f'{args.storage}, load {os.getloadavg()[0]:.1f}')
        print(f'{"case":60s} {"wall [s]":>9s} {"CPU [s]":>8s}')
        for name, wall, cpu in rows:
            print(f'{name:60s} {wall:9.2f} {cpu:8.2f}')
        if not args.no_baseline:
            print(f'replay / rosbags raw read: wall {rows[1][1] / rows[0][1]:.2f}x, '
                  f'CPU {rows[1][2] / rows[0][2]:.2f}x')
    finally:
        if args.keep:
            print(f'kept {scratch}')
        else:
            shutil.rmtree(scratch, ignore_errors=True)


if __name__ == '__main__':
    main()
