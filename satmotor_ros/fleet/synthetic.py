# SPDX-License-Identifier: Apache-2.0
"""
A synthetic fleet to try ``satmotor fleet`` on: several motors, daily recordings.

``python -m satmotor_ros.fleet.synthetic ROOT`` writes it. The motors are the packaged
SM-0,75/25 on water with the synthetic generator's noise; a motor's leakage factor k
scales its measured volumetric losses (the flow becomes q_t n + k (Q - q_t n)):

- ``healthy`` (vessel_a): k = 1 every day; times from an epoch ``time`` column;
- ``wearing`` (vessel_b): k grows by :data:`WEAR_PER_DAY` a day; times from the file name;
- ``leak`` (rig_c): k = 1, then a step to :data:`LEAK_FACTOR` on day :data:`LEAK_DAY`;
  one directory per day, times from the path;
- ``patchy`` (tug_d, no fleet.yaml entry: its motor is the directory): k = 1, with a
  recording truncated mid-row, one of garbage bytes and one whose pressures are all zero;
- ``bagged`` (with ``bags=True``): k = 1, rosbag2 recordings, times from the bags.
"""

from __future__ import annotations

import argparse
from datetime import datetime, timezone
from pathlib import Path
import sys
from typing import NoReturn

import numpy as np

from satmotor_ros.identify.synthetic import (generate, generate_series, Injection, Plan,
                                             to_columns, write_bag_of)
from satmotor_ros.identify.table import BenchTable, write_csv
from satmotor_ros.options import MotorOptions

START = datetime(2026, 3, 1, 8, 0, tzinfo=timezone.utc).timestamp()
"""The first day's first recording, epoch [s]."""

WEAR_PER_DAY = 0.06
"""Growth of the wearing motor's leakage factor per day, [1/day]."""

LEAK_DAY, LEAK_FACTOR = 5, 1.6
"""The day the leaking motor's factor steps up, and to what, [-]."""

FLEET_YAML = """motors:
  - {pattern: "vessel_a/**", motor: healthy, liquid: water}
  - {pattern: "vessel_b/**", motor: wearing, liquid: water}
  - {pattern: "rig_c/**", motor: leak, liquid: water}
"""


def _scaled(table: BenchTable, factor: float) -> BenchTable:
    """Scale the measured volumetric losses by `factor`."""
    from dataclasses import replace
    displacement = MotorOptions(liquid='water').spec().geometry.displacement
    ideal = displacement * table.speed
    return replace(table, flow=ideal + factor * (table.flow - ideal))


def write_recording(path: Path, factor: float, seed: int, points: int,
                    epoch: float | None = None) -> None:
    """
    Write one steady-point recording whose volumetric losses are `factor` times healthy.

    Parameters
    ----------
    path : pathlib.Path
        The CSV to write (its directory made), [-]
    factor : float
        Leakage factor k, [-]
    seed : int
        The generator's seed, [-]
    points : int
        Steady points, [-]
    epoch : float, optional
        Epoch of the first row, written into the ``time`` column; None leaves it from 0, [s]

    """
    table = _scaled(generate(Plan(liquid='water', n_points=points), Injection(), seed), factor)
    columns = to_columns(table)
    if epoch is not None:
        columns['time'] = ('s', columns['time'][1] + epoch)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_csv(path, columns)


MOTORS = ('healthy', 'wearing', 'leak', 'patchy')
"""The motors of the fleet (``bagged`` is added by ``bags=True``)."""


def make_fleet(root: str | Path, days: int = 8, points: int = 40, bags: bool = False,
               seed: int = 0, motors: tuple[str, ...] = MOTORS) -> Path:
    """
    Write the synthetic fleet under `root`.

    Parameters
    ----------
    root : str or pathlib.Path
        Directory to write (made if missing), [-]
    days : int
        Daily recordings per motor, [-]
    points : int
        Steady points per recording, [-]
    bags : bool
        Add the ``bagged`` motor (rosbag2 time series; slower to write and to read), [-]
    seed : int
        Seed of the first recording; each further one adds one, [-]
    motors : tuple of str
        Which of :data:`MOTORS` to write, [-]

    Returns
    -------
    pathlib.Path
        `root`.

    """
    base = Path(root)
    base.mkdir(parents=True, exist_ok=True)
    (base / 'fleet.yaml').write_text(FLEET_YAML, encoding='utf-8')
    n = seed
    for day in range(days):
        when = START + day * 86400.0
        stamp = datetime.fromtimestamp(when, timezone.utc)
        recordings = {
            'healthy': (base / 'vessel_a' / f'day{day:02d}.csv', 1.0, when),
            'wearing': (base / 'vessel_b' / f'run_{stamp:%Y-%m-%d_%H%M}.csv',
                        1.0 + WEAR_PER_DAY * day, None),
            'leak': (base / 'rig_c' / f'{stamp:%Y-%m-%d}' / 'log.csv',
                     LEAK_FACTOR if day >= LEAK_DAY else 1.0, None),
            'patchy': (base / 'tug_d' / f'd{day:02d}.csv', 1.0, when + 3600.0)}
        for motor, (path, factor, epoch) in recordings.items():
            n += 1
            if motor in motors:
                write_recording(path, factor, n, points, epoch)
        if bags:
            n += 1
            table = generate_series(Plan(liquid='water', n_points=points, duration_s=600.0),
                                    Injection(), n)
            shifted = dict(table.channels)
            shifted['time'] = table.channels['time'] + (when - 1.7e9)
            from dataclasses import replace
            write_bag_of(base / 'bagged' / f'b{day:02d}', replace(table, channels=shifted),
                         custom_data={'satmotor.liquid': 'water'})
    if 'patchy' in motors:
        _damage(base / 'tug_d', days)
    return base


def _damage(directory: Path, days: int) -> None:
    """Zero one of the motor's recordings' pressures, truncate one mid-row, garble one."""
    zero = directory / f'd{min(4, days - 1):02d}.csv'
    lines = zero.read_text(encoding='utf-8').splitlines()
    names = [c.split('[')[0].strip() for c in lines[0].split(',')]
    cells = [line.split(',') for line in lines[1:]]
    for row in cells:
        for name in ('p_in', 'p_out'):
            row[names.index(name)] = '0'
    zero.write_text('\n'.join([lines[0], *(','.join(r) for r in cells)]) + '\n',
                    encoding='utf-8')
    truncated = directory / f'd{min(2, days - 1):02d}.csv'
    text = truncated.read_bytes()
    truncated.write_bytes(text[:len(text) * 2 // 3].rstrip(b'\n')[:-3])
    rng = np.random.default_rng(0)
    (directory / 'd99_garbage.csv').write_bytes(rng.integers(0, 256, 3000, dtype=np.uint8)
                                                .tobytes())


MAX_DAYS = 366
"""Most days ``main`` writes (a typo like --days 10000 would fill the disk), [-]."""

PROGRAM = 'python -m satmotor_ros.fleet.synthetic'
COMMAND = 'fleet-synthetic'
"""Names the fleet in its ROOT's output marker: only such a ROOT is replaced."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit code 1, as ``satmotor``'s."""

    def error(self, message: str) -> NoReturn:
        """Print the error in one line and exit 1."""
        self.exit(1, f'{PROGRAM}: error: {message}\n')


def _days(text: str) -> int:
    try:
        days = int(text)
    except ValueError:
        days = 0
    if not 1 <= days <= MAX_DAYS:
        raise argparse.ArgumentTypeError(f'{text!r}: need a whole number from 1 to {MAX_DAYS}')
    return days


def main(argv: list[str] | None = None) -> int:
    """
    Write the synthetic fleet: ``python -m satmotor_ros.fleet.synthetic ROOT [--bags]``.

    ROOT is written whole (a temporary directory renamed into place) and replaces only an
    earlier synthetic fleet, an empty directory, or anything with ``--force``.
    """
    from satmotor_ros.cli._common import CliError
    from satmotor_ros.cli._output import output_dir
    parser = _Parser(prog=PROGRAM, description='Write a synthetic fleet to try satmotor fleet.')
    parser.add_argument('root', metavar='ROOT', help='directory to write')
    parser.add_argument('--days', type=_days, default=14,
                        help=f'daily recordings per motor, 1 to {MAX_DAYS} (default 14)')
    parser.add_argument('--bags', action='store_true', help='add the bagged motor')
    parser.add_argument('--force', action='store_true',
                        help='replace a ROOT that is not an earlier synthetic fleet')
    try:
        args = parser.parse_args(argv)
    except SystemExit as stop:  # a bad argument (said in one line) or --help
        return int(stop.code or 0)
    try:
        with output_dir('ROOT', args.root, COMMAND, force=args.force) as tmp:
            make_fleet(tmp, days=args.days, bags=args.bags)
    except (CliError, OSError) as err:
        print(f'{PROGRAM}: error: {err}', file=sys.stderr)
        return 1
    print(f'wrote a synthetic fleet of {args.days} days under {args.root} '
          f'(try: satmotor fleet {args.root} --out FLEET_OUT)')
    return 0


__all__ = ['COMMAND', 'FLEET_YAML', 'LEAK_DAY', 'LEAK_FACTOR', 'MAX_DAYS', 'MOTORS', 'START',
           'WEAR_PER_DAY', 'main', 'make_fleet', 'write_recording']

if __name__ == '__main__':
    sys.exit(main())
