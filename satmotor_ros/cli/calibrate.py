# SPDX-License-Identifier: Apache-2.0
"""``satmotor calibrate``: fit the model to bench data and name the effect it lacks."""

from __future__ import annotations

import argparse
from pathlib import Path

from satmotor_ros.cli._common import add_motor_options, fail, subcommand
from satmotor_ros.identify import BenchTable, calibrate, DataError, IdentificationError, Options
from satmotor_ros.identify import read_csv
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.pipeline import Mode
from satmotor_ros.identify.report import write_report
from satmotor_ros.interface import MotorOptions
from satmotor_ros.model import ModelError


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``satmotor calibrate`` and its options."""
    parser = subcommand(
        sub, 'calibrate', command, 'fit the model to bench data and find the effect it lacks',
        'Fit the loss model to a bench table (CSV with "name [unit]" headers: speed, flow, '
        'p_in, p_out, and any other channels) or a rosbag2 recording, test candidate effects '
        'by cross-validation, and write calibration.json, coefficients.yaml and report.md '
        'into --out.')
    add_data_arguments(parser)
    parser.add_argument('--alpha', type=float, default=0.05,
                        help='family-wise significance level of the effect test (default 0.05)')
    parser.add_argument('--folds', type=int, default=5,
                        help='cross-validation folds (default 5)')
    add_motor_options(parser, liquid_required=True, model_options=False)


def add_data_arguments(parser: argparse.ArgumentParser) -> None:
    """
    Add DATA, ``--out`` and ``--mode``: what the commands that read bench data share.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser, [-]

    """
    parser.add_argument('data', metavar='DATA', help='bench CSV or rosbag2 directory')
    parser.add_argument('--out', required=True, metavar='DIR', help='output directory')
    parser.add_argument('--mode', choices=('auto', 'points', 'series'), default='auto',
                        help='rows are steady points, a time series, or decide from the data '
                             '(default: auto)')


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


def command(data: str, out: str, mode: Mode, alpha: float, folds: int,
            options: MotorOptions) -> int:
    """
    Calibrate and write the three outputs.

    Parameters
    ----------
    data : str
        Bench CSV or rosbag2 directory, [-]
    out : str
        Output directory, [-]
    mode : str
        ``'auto'``, ``'points'`` or ``'series'``, [-]
    alpha : float
        Significance level, [-]
    folds : int
        Cross-validation folds, [-]
    options : MotorOptions
        The motor and the coefficient set to calibrate (its own liquid), [-]

    Returns
    -------
    int
        0 whether or not an effect was found; 1 with one line on stderr for
        unusable data or options.

    """
    try:
        spec = options.spec()
        table = load_data(data)
        cal = calibrate(table, options.liquid, spec,
                        Options(alpha=alpha, n_folds=folds, mode=mode))
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
