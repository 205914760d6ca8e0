# SPDX-License-Identifier: Apache-2.0
"""``satmotor synthetic``: a bench table or recording from the model, effects injected."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from satmotor_ros.cli._common import CliError, fail
from satmotor_ros.cli._output import output_file
from satmotor_ros.identify.synthetic import (generate, generate_series, generate_transient,
                                             Injection, parse_injection, Plan, REALISTIC,
                                             REALISTIC_DYNAMICS, to_columns, with_outliers,
                                             write_bag_of)
from satmotor_ros.identify.table import BenchTable, write_csv

DESCRIPTION = ('Write a synthetic bench table (CSV), a 100 Hz time series or a rosbag2 '
               'recording from the model with effects injected and seeded noise: data to try '
               '`satmotor calibrate` and `satmotor validate` on, whose truth is known.')

_LEAST = {'points': 2, 'series': 2, 'transient': 0.1}  # option -> its smallest value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor synthetic``."""
    parser.add_argument('--liquid', default='oil', help='coefficient set (default: oil)')
    parser.add_argument('--effect', action='append', default=[],
                        help='NAME or NAME*SCALE (NAME one of '
                             f'{", ".join(REALISTIC)}), term:EXPR=LPM or threshold:dp=LPM@MPA; '
                             'repeatable (default: none)')
    parser.add_argument('--outlier', action='append', default=[], metavar='ROW:LPM',
                        help='add LPM l/min to the flow of row ROW (repeatable)')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--points', type=int, default=100, help='steady points (default 100)')
    parser.add_argument('--series', type=int, default=None, metavar='SAMPLES',
                        help='write a 100 Hz time series of this many samples instead')
    parser.add_argument('--transient', type=float, default=None, metavar='SECONDS',
                        help='write a 100 Hz recording of this length whose set-points change '
                             'every 0.6-1.5 s, with a line volume and sensor lags instead')
    parser.add_argument('--bag', choices=('mcap', 'sqlite3'), default=None,
                        help='write the time series as a rosbag2 bag (directory --out)')
    parser.add_argument('--out', required=True, help='CSV file (or bag directory) to write')
    parser.add_argument('--force', action='store_true',
                        help='replace an existing --out CSV that this command did not write')


def command(out: str, liquid: str = 'oil', effect: list[str] | None = None,
            outlier: list[str] | None = None, seed: int = 0, points: int = 100,
            series: int | None = None, transient: float | None = None, bag: str | None = None,
            force: bool = False) -> int:
    """
    Generate the data and write them.

    Parameters
    ----------
    out : str
        CSV file or bag directory, [-]
    liquid : str
        Coefficient set, [-]
    effect, outlier : list of str
        ``--effect`` and ``--outlier`` as typed, [-]
    seed : int
        Seed of the operating points and the noise, [-]
    points, series, transient : int, int or None, float or None
        Steady points; or samples of a time series; or seconds of a transient recording, [-]
    bag : {'mcap', 'sqlite3'} or None
        Write a bag of this storage rather than a CSV, [-]
    force : bool
        Replace an existing CSV that this command did not write, [-]

    Returns
    -------
    int
        0 with one line on stdout; 1 with one line on stderr for a bad option, a model that
        cannot be built, or an ``--out`` that exists and was not written by this command.

    """
    try:
        print(_write(out, liquid, effect or [], outlier or [], seed,
                     {'points': points, 'series': series, 'transient': transient}, bag, force))
    except (CliError, ValueError, OSError) as err:  # a model or bag error, an unwritable path
        return fail(err if str(err) else f'--out {out!r}: {err!r}')
    return 0


def _write(out: str, liquid: str, effects: list[str], outliers: list[str], seed: int,
           sizes: dict[str, float | None], bag: str | None, force: bool) -> str:
    """Write the data and return the line that says what was written."""
    for option, value in sizes.items():
        if value is not None and not value >= _LEAST[option]:
            raise CliError(f'--{option} {value!r}: must be at least {_LEAST[option]:g}')
        if value is not None and not math.isfinite(value):
            raise CliError(f'--{option} {value!r}: must be a finite number, at least '
                           f'{_LEAST[option]:g}')
    if seed < 0:  # numpy's own message would not name the option
        raise CliError(f'--seed {seed}: must be 0 or more')
    injections = [parse_injection(e, liquid) for e in effects] or [Injection()]
    try:
        rows, lpm = zip(*((int(r), float(v)) for r, v in
                          (o.split(':') for o in outliers))) if outliers else ((), ())
        if not all(math.isfinite(v) for v in lpm):
            raise ValueError('an outlier of NaN or infinite l/min')
    except ValueError:
        raise CliError(f'--outlier {outliers!r}: use ROW:LPM, e.g. 7:1.5') from None
    table = _generate(Plan(liquid=liquid, n_points=int(sizes['points'] or 0)), injections,
                      seed, sizes)
    if any(not 0 <= row < len(table) for row in rows):
        raise CliError(f'--outlier {outliers!r}: a row from 0 to {len(table) - 1}')
    if rows:
        table = with_outliers(table, rows, lpm)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    if bag:
        write_bag_of(out, table, bag)
    else:
        columns = to_columns(table)
        header = ','.join(f'{name} [{unit}]' for name, (unit, _) in columns.items())
        with output_file('--out', out, 'synthetic', lambda path: _has_header(path, header),
                         force=force) as temporary:
            write_csv(temporary, columns)
    described = ', '.join(f'{i.effect} (magnitude {i.magnitude:.4g})' for i in injections)
    return (f'wrote {out}: {len(table)} rows, {liquid}, {described}'
            + (f', outliers at rows {", ".join(map(str, rows))}' if rows else ''))


def _generate(plan: Plan, injections: list[Injection], seed: int,
              sizes: dict[str, float | None]) -> BenchTable:
    if sizes['transient'] is not None:
        return generate_transient(plan, injections, REALISTIC_DYNAMICS, seed,
                                  duration_s=sizes['transient'])
    if sizes['series'] is not None:
        return generate_series(plan, injections, seed, samples=int(sizes['series']))
    return generate(plan, injections, seed)


def _has_header(path: Path, header: str) -> bool:
    """Tell whether `path` is a table this command wrote: a file with the same header line."""
    try:
        with path.open('rb') as file:
            return path.is_file() and file.readline().rstrip(b'\r\n') == header.encode()
    except OSError:
        return False
