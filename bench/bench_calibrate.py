# SPDX-License-Identifier: Apache-2.0
"""
Benchmark ``satmotor calibrate`` end to end against one baseline fit measured in the same run.

Cases, each run through the ``calibrate`` command (read, rows, fit, the cross-validated
selection over every candidate, JSON, YAML, report with its PNGs):

- a bench table of 100 steady points (target 3 s);
- a transient recording of 10^5 samples (1000 s at 100 Hz, set-points every 0.6-1.5 s, a
  line volume and sensor lags): every sample used (``--mode auto`` picks ``transient``:
  no steady window), as CSV and as an MCAP bag of the DESIGN.md topics (target 10 s);
- a time series of 10^5 samples with 8 s plateaus, read as its 125 steady windows;
- a real trajectory of 10^5 samples: the vendored MBARI log ``2021.07.26T10.51.44.exp``
  (test/data/real/mbari_pto, 22 001 samples at 50 Hz) tiled 5 times with its time continued,
  calibrated as the README calls it (``--columns mbari_pto``, every usable sample; a
  one-sided valve among the candidates, evaluated at every sample).

The baseline is one bounded least-squares fit of the model without effect on the same
100 points: the unit of work the selection repeats ~110 times. The CPU time of the best
run stands beside its wall time: on a machine shared with other jobs the wall time
measures the load as much as the code.

Run: ``PYTHONPATH=. .venv/bin/python bench/bench_calibrate.py [--repeat R] [--only real]``.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import platform
import tempfile
import time

os.environ.setdefault('OMP_NUM_THREADS', '1')
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

import numpy as np  # noqa: E402

from satmotor_ros.cli import main  # noqa: E402
from satmotor_ros.identify import loss_parts, LossFit, write_csv  # noqa: E402
from satmotor_ros.identify.synthetic import (generate, generate_series,  # noqa: E402
                                             generate_transient, Injection, Plan,
                                             REALISTIC_DYNAMICS, write_bag_of)
from satmotor_ros.model import MotorModel  # noqa: E402
from satmotor_ros.model.units import LPM, MPA, RPM  # noqa: E402


def to_csv(path: Path, table) -> Path:
    """Write a generated table as a bench CSV in hydraulic units."""
    columns = {'time': ('s', table.channels['time']), 'speed': ('rpm', table.speed / RPM),
               'flow': ('l/min', table.flow / LPM), 'p_in': ('MPa', table.p_in / MPA),
               'p_out': ('MPa', table.p_out / MPA),
               'temperature': ('degC', table.channels['temperature']),
               'p_case': ('MPa', table.channels['p_case'] / MPA),
               'aux': ('V', table.channels['aux'])}
    write_csv(path, columns)
    return path


REAL_LOG = Path(__file__).resolve().parent.parent / 'test' / 'data' / 'real' / 'mbari_pto' / \
    '2021.07.26T10.51.44.exp'
"""A recording of the real rig, in the repository."""

REAL_ARGS = ('--columns', 'mbari_pto', '--liquid', 'oil', '--displacement', '0.30 in^3/rev')
"""How the README calibrates it."""


def tiled(path: Path, log: Path, times: int) -> Path:
    """Write `log` repeated `times` times, each copy's time continued after the last, [-]."""
    lines = log.read_text().splitlines()
    head = [line for line in lines if line.startswith('#')]
    rows = [line.split() for line in lines if line.strip() and not line.startswith('#')]
    t = np.array([float(r[0]) for r in rows])
    span = t[-1] - t[0] + float(np.median(np.diff(t)))
    out = list(head)
    for k in range(times):
        out += [' '.join([f'{float(r[0]) + k * span:.2f}', *r[1:]]) for r in rows]
    path.write_text('\n'.join(out) + '\n')
    return path


def best(fn, repeat: int) -> tuple[float, float]:
    """Return the best wall time of `repeat` calls and that call's CPU time, [s]."""
    times = []
    for _ in range(repeat):
        start, cpu = time.perf_counter(), time.process_time()
        fn()
        times.append((time.perf_counter() - start, time.process_time() - cpu))
    return min(times)


def main_bench() -> None:
    """Run the cases and print a table."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--repeat', type=int, default=3)
    parser.add_argument('--only', choices=('real',), help='the baseline and the real case only')
    args = parser.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix='bench_calibrate_'))
    plan = Plan(liquid='water')
    points = generate(plan, Injection.realistic('external_leakage', 1.0, 'water'), seed=1)
    table = to_csv(tmp / 'points.csv', points)
    cases = {}
    if args.only != 'real':
        series = generate_series(plan, Injection.realistic('clearance_wear', 1.0, 'water'),
                                 seed=1, samples=100_000, rate=100.0, hold_s=8.0)
        transient = generate_transient(plan, Injection.realistic('external_leakage', 1.0,
                                                                 'water'),
                                       REALISTIC_DYNAMICS, seed=1, duration_s=1000.0)
        write_bag_of(tmp / 'transient_bag', transient, 'mcap')
        cases = {'table, 100 points': table,
                 'transient CSV, 10^5 samples, every sample': to_csv(tmp / 'transient.csv',
                                                                     transient),
                 'transient MCAP bag, 10^5 samples, every sample': tmp / 'transient_bag',
                 'plateaus CSV, 10^5 samples, steady windows': to_csv(tmp / 'series.csv',
                                                                      series)}
    cases['real MBARI log tiled 5x, 110 005 samples, every sample'] = tiled(
        tmp / 'real_x5.exp', REAL_LOG, 5)
    parts, _ = loss_parts(MotorModel.default('water'), points)
    main(['calibrate', str(table), '--liquid', 'water', '--out',
          str(tmp / 'warm')])  # imports and matplotlib font cache out of the timings
    base, _ = best(lambda: LossFit().fit(parts), 20 * args.repeat)
    print(f'{platform.machine()}, Python {platform.python_version()}, '
          f'numpy {np.__version__}; best of {args.repeat}')
    print('| case | s | CPU s | x one baseline fit | target |')
    print('| --- | ---: | ---: | ---: | ---: |')
    print(f'| baseline: one fit, 100 points | {base:.4f} | | 1 | |')
    for k, (name, path) in enumerate(cases.items()):
        out = tmp / f'out_{k}'
        argv = ['calibrate', str(path), '--out', str(out),
                *(REAL_ARGS if name.startswith('real') else ('--liquid', 'water'))]
        t, cpu = best(lambda: main(argv), args.repeat)
        target = 3.0 if name.startswith('table') else 10.0
        print(f'| {name} | {t:.2f} | {cpu:.2f} | {t / base:.0f} | {target:g} s |')


if __name__ == '__main__':
    main_bench()
