# SPDX-License-Identifier: Apache-2.0
"""
Benchmark ``satmotor fleet``: throughput on 1 and 2 Dask workers, and the engine's overhead.

The fleet is the synthetic one (:mod:`satmotor_ros.fleet.synthetic`: four motors, daily
bench tables, three damaged recordings). Each configuration processes the same recordings
into a fresh output directory, doing exactly the work of ``satmotor fleet`` (a baseline
calibration per motor, then the health step per recording, done-markers written):

- plain loop, 1 process: the tasks called one after the other in this process (each motor's
  baseline, its recordings, then its monitor chain, as ``run_on`` does);
- plain loop, N processes: a ``ProcessPoolExecutor`` of N processes, one motor at a time
  each (the baseline, then its recordings), as a shell loop per motor would;
- Dask, N workers: :func:`satmotor_ros.fleet.engine.run_on` on a local cluster of N worker
  processes (one thread each).

The processes of both are started and have imported the package before the clock starts,
so the figures compare the engines on the same work; the cluster's start is timed apart.
Targets (issue 24): 2 workers >= 1.7x the throughput of 1, Dask <= 10 % over the plain loop
at equal workers.

Run: ``.venv/bin/python bench/bench_fleet.py [--days D] [--points P] [--repeat R]``.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import multiprocessing
import os
from pathlib import Path
import platform
import tempfile
import time
from typing import NamedTuple

os.environ.setdefault('OMP_NUM_THREADS', '1')
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

import psutil  # noqa: E402

from satmotor_ros.fleet.chain import monitor_step  # noqa: E402
from satmotor_ros.fleet.config import FleetConfig, load_fleet  # noqa: E402
from satmotor_ros.fleet.discover import discover, Motor  # noqa: E402
from satmotor_ros.fleet.engine import connect, plan, run_on  # noqa: E402
from satmotor_ros.fleet.synthetic import make_fleet  # noqa: E402
from satmotor_ros.fleet.tasks import (calibrate_baseline, process_recording,  # noqa: E402
                                      RunOptions)


def _warm(wait: float = 0.0) -> int:
    """Import what a task imports (numpy, scipy, matplotlib, the package): the worker's start."""
    time.sleep(wait)
    import satmotor_ros.cli.calibrate  # noqa: F401
    import satmotor_ros.cli.validate  # noqa: F401
    import satmotor_ros.fleet.health  # noqa: F401
    import satmotor_ros.identify.report  # noqa: F401
    return os.getpid()


def _motor(motor: Motor, run: RunOptions) -> int:
    """Do one motor as a plain loop: its baseline, each recording, then its monitor chain."""
    chain_from = plan([motor], run).chain_from  # what run_on chains: the same work
    baseline = calibrate_baseline(motor, run)
    for rec in motor.recordings:
        process_recording(rec, motor.rule, baseline, run)
    if motor.motor in chain_from:
        before = None
        for rec in motor.recordings[chain_from[motor.motor]:]:
            before = monitor_step(rec, motor.rule, baseline, run, before)
    return len(motor.recordings)


def _cpu(pids: set[int]) -> float:
    """CPU seconds (user + system) used so far by these processes and by this one, [s]."""
    total = time.process_time()
    for pid in pids:
        process = psutil.Process(pid)
        for each in [process, *process.children(recursive=True)]:
            times = each.cpu_times()
            total += times.user + times.system
    return total


class Measure(NamedTuple):
    """One configuration's figures."""

    wall: float  # from the first task sent to the last result [s]
    cpu: float  # CPU of the workers and of this process (client, local scheduler) [s]
    start: float  # the cluster's start, warm-up included (nan for the plain loop) [s]
    load: float  # the machine's 1-minute load average before it [-]


def _plain(motors: list[Motor], out: Path, workers: int) -> Measure:
    run = RunOptions(str(out), liquid='water')
    load = os.getloadavg()[0]
    if workers == 1:
        _warm()
        cpu, start = _cpu(set()), time.perf_counter()
        for motor in motors:
            _motor(motor, run)
        return Measure(time.perf_counter() - start, _cpu(set()) - cpu, float('nan'), load)
    context = multiprocessing.get_context('spawn')
    with ProcessPoolExecutor(workers, mp_context=context) as pool:
        pids = {f.result() for f in [pool.submit(_warm, 1.0) for _ in range(2 * workers)]}
        assert len(pids) == workers, pids  # each took one warm-up at least (they wait 1 s)
        cpu, start = _cpu(pids), time.perf_counter()
        done = sum(f.result() for f in [pool.submit(_motor, m, run) for m in motors])
        measured = Measure(time.perf_counter() - start, _cpu(pids) - cpu, float('nan'), load)
    assert done == sum(len(m.recordings) for m in motors)
    return measured


def _dask(motors: list[Motor], out: Path, workers: int) -> Measure:
    run = RunOptions(str(out), liquid='water')
    load = os.getloadavg()[0]
    begin = time.perf_counter()
    with connect(workers) as (client, placed):
        pids = set(client.run(_warm).values())
        started = time.perf_counter() - begin
        assert placed.workers == workers == len(pids)
        work = plan(motors, run)
        cpu, start = _cpu(pids), time.perf_counter()
        markers = run_on(client, work, run)
        measured = Measure(time.perf_counter() - start, _cpu(pids) - cpu, started, load)
    assert len(markers) == sum(len(m.recordings) for m in motors)
    return measured


def main() -> None:
    """Run the benchmark and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--days', type=int, default=10)
    parser.add_argument('--points', type=int, default=60)
    parser.add_argument('--repeat', type=int, default=1)
    args = parser.parse_args()
    print(f'{platform.processor() or platform.machine()}, {os.cpu_count()} cores; '
          f'{args.days} days x 4 motors, {args.points} points per recording')
    with tempfile.TemporaryDirectory() as tmp:
        root = make_fleet(Path(tmp) / 'root', days=args.days, points=args.points)
        config = load_fleet(root / 'fleet.yaml') if (root / 'fleet.yaml').is_file() \
            else FleetConfig()
        motors = discover(root, config)
        n = sum(len(m.recordings) for m in motors)
        rows: dict[str, list[Measure]] = {}
        for r in range(args.repeat):
            for name, fn in (('plain loop, 1 process', lambda o: _plain(motors, o, 1)),
                             ('Dask, 1 worker', lambda o: _dask(motors, o, 1)),
                             ('plain loop, 2 processes', lambda o: _plain(motors, o, 2)),
                             ('Dask, 2 workers', lambda o: _dask(motors, o, 2))):
                got = fn(Path(tmp) / f'{name.replace(" ", "_")}_{r}')
                rows.setdefault(name, []).append(got)
                print(f'  {name}: {got.wall:.2f} s wall ({n / got.wall:.2f} recordings/s), '
                      f'{got.cpu:.2f} s CPU, load {got.load:.1f}'
                      + (f', cluster start {got.start:.2f} s' if got.start == got.start
                         else ''), flush=True)
    wall = {k: min(m.wall for m in v) for k, v in rows.items()}
    cpu = {k: min(m.cpu for m in v) for k, v in rows.items()}
    p1, d1 = wall['plain loop, 1 process'], wall['Dask, 1 worker']
    p2, d2 = wall['plain loop, 2 processes'], wall['Dask, 2 workers']
    print(f'{n} recordings (best of {args.repeat}; wall figures need a quiet machine):')
    print(f'  throughput, Dask 2 workers over 1: {d1 / d2:.2f}x (target >= 1.7x); '
          f'plain loop 2 over 1: {p1 / p2:.2f}x')
    print(f'  Dask over the plain loop, wall: 1 worker {100 * (d1 / p1 - 1):+.1f} %, '
          f'2 workers {100 * (d2 / p2 - 1):+.1f} % (target <= 10 %)')
    c1, c2 = cpu['Dask, 1 worker'] / cpu['plain loop, 1 process'], \
        cpu['Dask, 2 workers'] / cpu['plain loop, 2 processes']
    print(f'  Dask over the plain loop, CPU: 1 worker {100 * (c1 - 1):+.1f} %, '
          f'2 workers {100 * (c2 - 1):+.1f} %')


if __name__ == '__main__':
    main()
