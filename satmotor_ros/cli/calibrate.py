# SPDX-License-Identifier: Apache-2.0
"""``satmotor calibrate``: fit the model to bench data and name the effect it lacks."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
import sys
from typing import Any

from satmotor_ros.cli._bench import (add_data_arguments, load_data, run_bench_command,
                                     samples_left_out)
from satmotor_ros.cli._common import add_motor_options
from satmotor_ros.cli._liquid import settle_liquid
from satmotor_ros.cli._output import check_target, output_dir, written_by
from satmotor_ros.identify import calibrate, Options
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.pipeline import AT_BOUND, IMPLAUSIBLE, Mode, MODES
from satmotor_ros.identify.report import write_report
from satmotor_ros.interface import MotorOptions


HELP = 'fit the model to bench data and find the effect it lacks'
DESCRIPTION = ('Fit the loss model to a bench table (CSV with "name [unit]" headers: speed, '
               'flow, p_in, p_out or p_a, p_b, and any other channels), a log of its own '
               'layout read through --columns, or a rosbag2 recording, test candidate effects '
               'by cross-validation, and write calibration.json, coefficients.yaml and '
               'report.md into --out.')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor calibrate``."""
    add_data_arguments(parser, MODES)
    parser.add_argument('--alpha', type=_alpha, default=0.05,
                        help='family-wise significance level of the effect test, between 0 '
                             'and 1 (default 0.05)')
    parser.add_argument('--folds', type=_folds, default=5,
                        help='cross-validation folds, at least 2 (default 5)')
    add_motor_options(parser, liquid_from_data=True, model_options=False)


def _alpha(text: str) -> float:
    """Read ``--alpha``: a level strictly between 0 and 1."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{text!r}: not a number') from None
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f'{text!r}: must be between 0 and 1')
    return value


def _folds(text: str) -> int:
    """Read ``--folds``: a whole number of at least 2."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{text!r}: not a whole number') from None
    if value < 2:
        raise argparse.ArgumentTypeError(f'{text!r}: must be at least 2')
    return value


def command(data: str, out: str, mode: Mode, alpha: float, folds: int,
            options: MotorOptions, columns: str = '', force: bool = False) -> int:
    """
    Calibrate and write the three outputs.

    Parameters
    ----------
    data, out, mode, columns : str
        DATA, ``--out``, ``--mode`` and ``--columns`` as :func:`add_data_arguments` parses
        them, [-]
    alpha : float
        Significance level, [-]
    folds : int
        Cross-validation folds, [-]
    options : MotorOptions
        The motor and the coefficient set to calibrate (its own liquid), [-]
    force : bool
        Replace an existing ``--out`` that calibrate did not write, [-]

    Returns
    -------
    int
        0 whether or not an effect was found; 1 with one line on stderr for
        unusable data or options.

    """
    return run_bench_command(out, lambda: _calibrate(data, out, mode, alpha, folds, options,
                                                     columns, force))


def _calibrate(data: str, out: str, mode: Mode, alpha: float, folds: int,
               options: MotorOptions, columns: str, force: bool) -> str:
    """Calibrate, write the outputs and return the summary line."""
    inputs = [name for name in (data, options.motor_file, columns) if name]
    check_target('--out', Path(out), inputs, force, written_by('calibrate'), 'calibrate')
    settled = settle_liquid(options, data, 'calibrate')
    options = settled.options
    spec = options.spec()
    table = load_data(data, columns, spec.geometry.displacement)
    table = replace(table, notes=table.notes + (f'liquid: {settled.source}',)
                    + ((f'WARNING: {settled.warning}',) if settled.warning else ()))
    cal = calibrate(table, options.liquid, spec, Options(alpha=alpha, n_folds=folds, mode=mode,
                                                         compare_families=not options.family))
    warnings = cal.warnings().get('warnings', [])
    for note in warnings:
        print(f'warning: {data}: {note}', file=sys.stderr)
    with output_dir('--out', out, 'calibrate', inputs, force) as tmp:
        summary = write_json(cal, tmp / 'calibration.json')
        write_yaml(cal, tmp / 'coefficients.yaml')
        write_report(cal, tmp, summary)
    target = Path(out)
    effect = summary['effect']
    kinds = [k for k in (IMPLAUSIBLE, AT_BOUND) if any(w.startswith(k) for w in warnings)]
    line = (f'WARNING {" and ".join(kinds)} (see report.md); ' if kinds else '') + \
        (f'WARNING: {settled.warning}; ' if settled.warning else '') + \
        f'effect: {effect}'
    if effect != 'none':
        line += (f' ({summary["regressor"]}, coefficient {summary["coefficient"]:.4g} '
                 f'{summary["unit"]})')
    runner = cal.selection.runner_up
    if runner is not None:
        line += f', near tie with {runner.label}'
    if len(summary['effects']) > 1:
        line += ', then ' + ', '.join(e['effect'] for e in summary['effects'][1:])
    line += f'; family {summary["family"]}'
    tie = summary['family_comparison'].get('near_tie')
    if tie:
        other = next(f for f in tie['families'] if f != summary['family'])
        line += f' (near tie with {other})'
    line += f'; liquid {settled.source}'
    return (f'{line}; {_errors(summary, cal.samples is not None)}; '
            f'wrote {target}/calibration.json, coefficients.yaml, report.md')


def _errors(summary: dict[str, Any], series: bool) -> str:
    """Say the errors before and after and the rows they are over, outliers named apart."""
    before, after = summary['error_before']['rmse_lpm'], summary['error_after']['rmse_lpm']
    n, left_out = summary['n_points'], len(summary['outliers'])
    unit = 'rows' if series else 'points'
    rows = f'{n - left_out} of {n} {unit}' if left_out else f'{n} {unit}'
    if series:
        rows += (f' of {summary["n_samples"]} samples (mode transient: every usable sample, '
                 'with the transient terms)')
    text = f'out-of-sample RMSE of Q_vl {before:.4g} -> {after:.4g} l/min over {rows}'
    if left_out:
        text += (f'; {left_out} isolated outlier(s) left out of it, with them '
                 f'{summary["error_before_with_outliers"]["rmse_lpm"]:.4g} -> '
                 f'{summary["error_after_with_outliers"]["rmse_lpm"]:.4g} l/min')
    return text + samples_left_out(summary['coverage'])
