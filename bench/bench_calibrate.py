# SPDX-License-Identifier: Apache-2.0
"""
Benchmark ``satmotor calibrate`` end to end against one baseline fit measured in the same run.

Cases: a bench table of 100 steady points (target 2 s) and a time series of 10^5 samples
(target 10 s), each written as CSV and run through the ``calibrate`` command (read, steady
windows, fit, 18-candidate cross-validated selection, JSON, YAML, report with three PNGs).
The baseline is one bounded least-squares fit of the model without effect on the same
100 points: the unit of work the selection repeats ~110 times. The same 10^5 samples also
run as an MCAP bag of the DESIGN.md topics.

Run: ``.venv/bin/python bench/bench_calibrate.py [--repeat R]``.
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
from satmotor_ros.identify.synthetic import (generate, generate_series, Injection,  # noqa: E402
                                             Plan, write_bag_of)
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


def best(fn, repeat: int) -> float:
    """Return the best wall time of `repeat` calls, [s]."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main_bench() -> None:
    """Run the cases and print a table."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--repeat', type=int, default=3)
    args = parser.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix='bench_calibrate_'))
    plan = Plan(liquid='water')
    points = generate(plan, Injection.realistic('external_leakage', 1.0, 'water'), seed=1)
    series = generate_series(plan, Injection.realistic('clearance_wear', 1.0, 'water'), seed=1,
                             samples=100_000, rate=100.0, hold_s=8.0)
    write_bag_of(tmp / 'series_bag', series, 'mcap')
    cases = {'table, 100 points': to_csv(tmp / 'points.csv', points),
             'time series, 10^5 samples': to_csv(tmp / 'series.csv', series),
             'MCAP bag, 10^5 samples': tmp / 'series_bag'}
    parts, _ = loss_parts(MotorModel.default('water'), points)
    main(['calibrate', str(cases['table, 100 points']), '--liquid', 'water', '--out',
          str(tmp / 'warm')])  # imports and matplotlib font cache out of the timings
    base = best(lambda: LossFit().fit(parts), 20 * args.repeat)
    print(f'{platform.machine()}, Python {platform.python_version()}, '
          f'numpy {np.__version__}; best of {args.repeat}')
    print('| case | s | x one baseline fit | target |')
    print('| --- | ---: | ---: | ---: |')
    print(f'| baseline: one fit, 100 points | {base:.4f} | 1 | |')
    targets = {'table, 100 points': 2.0, 'time series, 10^5 samples': 10.0,
               'MCAP bag, 10^5 samples': 10.0}
    for name, path in cases.items():
        out = tmp / ('out_' + name.split(',')[0].replace(' ', '_'))
        argv = ['calibrate', str(path), '--liquid', 'water', '--out', str(out)]
        t = best(lambda: main(argv), args.repeat)
        print(f'| {name} | {t:.2f} | {t / base:.0f} | {targets[name]:g} s |')


if __name__ == '__main__':
    main_bench()
