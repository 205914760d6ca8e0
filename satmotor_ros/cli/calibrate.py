# SPDX-License-Identifier: Apache-2.0
"""``satmotor calibrate``: fit the model to bench data and name the effect it lacks."""

from __future__ import annotations

import argparse
from pathlib import Path

from satmotor_ros.cli._common import fail
from satmotor_ros.identify import BenchTable, calibrate, DataError, IdentificationError, Options
from satmotor_ros.identify import read_csv
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.report import write_report
from satmotor_ros.model import load_motor, ModelError


def add_parser(sub: argparse._SubParsersAction) -> None:
    """
    Register the subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``satmotor`` subparsers, [-]

    """
    parser = sub.add_parser(
        'calibrate', help='fit the model to bench data and find the effect it lacks',
        description='Fit the loss model to a bench table (CSV with "name [unit]" headers: '
                    'speed, flow, p_in, p_out, and any other channels) or a rosbag2 '
                    'recording, test candidate effects by cross-validation, and write '
                    'calibration.json, coefficients.yaml and report.md into --out.')
    parser.add_argument('data', metavar='DATA', help='bench CSV or rosbag2 directory')
    parser.add_argument('--liquid', required=True,
                        help="coefficient set to calibrate: 'oil' or 'water' (or a set of "
                             '--motor)')
    parser.add_argument('--out', required=True, metavar='DIR', help='output directory')
    parser.add_argument('--motor', default=None, metavar='YAML',
                        help='motor specification (default: the packaged SM-0,75/25)')
    parser.add_argument('--mode', choices=('auto', 'points', 'series'), default='auto',
                        help='rows are steady points, a time series, or decide from the data '
                             '(default: auto)')
    parser.add_argument('--alpha', type=float, default=0.05,
                        help='family-wise significance level of the effect test (default 0.05)')
    parser.add_argument('--folds', type=int, default=5,
                        help='cross-validation folds (default 5)')
    parser.set_defaults(command=command)


def load_data(data: str) -> BenchTable:
    """
    Load a bench CSV, or a rosbag2 directory through :mod:`satmotor_ros.bags`.

    Parameters
    ----------
    data : str
        Path as typed, [-]

    Returns
    -------
    BenchTable
        The data in SI.

    Raises
    ------
    DataError
        If the path is missing or cannot be read.

    """
    path = Path(data)
    if not path.exists():
        msg = f'DATA {data!r}: no such file or directory'
        raise DataError(msg)
    if path.is_dir():
        from satmotor_ros.identify.bag import read_bag
        return read_bag(path)
    return read_csv(path)


def command(data: str, liquid: str, out: str, motor: str | None, mode: str, alpha: float,
            folds: int) -> int:
    """
    Calibrate and write the three outputs.

    Parameters
    ----------
    data : str
        Bench CSV or rosbag2 directory, [-]
    liquid : str
        Coefficient set, [-]
    out : str
        Output directory, [-]
    motor : str or None
        Motor YAML, [-]
    mode : str
        ``'auto'``, ``'points'`` or ``'series'``, [-]
    alpha : float
        Significance level, [-]
    folds : int
        Cross-validation folds, [-]

    Returns
    -------
    int
        0 whether or not an effect was found; 1 with one line on stderr for
        unusable data or options.

    """
    try:
        spec = load_motor(motor)
        if liquid not in spec.sets:
            msg = f'--liquid {liquid!r}: not a coefficient set of {spec.name} (has: ' \
                  f'{", ".join(spec.sets)})'
            raise IdentificationError(msg)
        table = load_data(data)
        cal = calibrate(table, liquid, spec, Options(alpha=alpha, n_folds=folds, mode=mode))
        target = Path(out)
        target.mkdir(parents=True, exist_ok=True)
        summary = write_json(cal, target / 'calibration.json')
        write_yaml(cal, target / 'coefficients.yaml')
        write_report(cal, target, summary)
    except (IdentificationError, ModelError) as err:
        return fail(err)
    except OSError as err:
        return fail(f'--out {out!r}: {err.strerror}')
    effect = summary['effect']
    before, after = summary['error_before']['rmse_lpm'], summary['error_after']['rmse_lpm']
    line = f'effect: {effect}'
    if effect != 'none':
        line += (f' ({summary["regressor"]}, coefficient {summary["coefficient"]:.4g} '
                 f'{summary["unit"]})')
    runner = cal.selection.runner_up
    if runner is not None:
        line += f', near tie with {runner.label}'
    print(f'{line}; out-of-sample RMSE of Q_vl {before:.4g} -> {after:.4g} l/min over '
          f'{summary["n_points"]} points; wrote {target}/calibration.json, coefficients.yaml, '
          'report.md')
    return 0
