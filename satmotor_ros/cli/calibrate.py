# SPDX-License-Identifier: Apache-2.0
"""``satmotor calibrate``: fit the model to bench data and name the effect it lacks."""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
from typing import Any

from satmotor_ros.cli._bench import (add_data_arguments, open_bench, run_bench_command,
                                     samples_left_out)
from satmotor_ros.cli._common import add_motor_options, number_option
from satmotor_ros.cli._output import output_dir
from satmotor_ros.identify import BenchTable, calibrate, Options
from satmotor_ros.identify.base import EMPTIED
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.pipeline import AT_BOUND, IMPLAUSIBLE, Mode, MODES
from satmotor_ros.identify.report import write_report
from satmotor_ros.options import MotorOptions


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


_alpha = number_option(float, lambda value: 0.0 < value < 1.0, 'must be between 0 and 1')
"""Read ``--alpha``: a level strictly between 0 and 1."""

_folds = number_option(int, lambda value: value >= 2, 'must be at least 2')
"""Read ``--folds``: a whole number of at least 2."""


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
    return run_bench_command(out, lambda: calibrate_into(
        data, out, mode, alpha, folds, options, columns, force))


def calibrate_into(data: str, out: str, mode: Mode, alpha: float, folds: int,
                   options: MotorOptions, columns: str, force: bool,
                   table: BenchTable | None = None) -> str:
    """
    Calibrate, write the outputs and return the summary line ``command`` prints.

    The arguments are those of :func:`command`, and `table`: `data` already loaded by
    :func:`~satmotor_ros.cli._bench.load_data` (``satmotor fleet`` screens it first), or None
    to read it here. The errors are those :func:`~satmotor_ros.cli._bench.run_bench_command`
    reports (CliError, IdentificationError, ModelError, OSError).
    """
    inputs, settled, table = open_bench('calibrate', data, out, options, columns, force, table)
    options = settled.options
    spec = options.spec()
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
    kinds = [k for k in (IMPLAUSIBLE, EMPTIED, AT_BOUND) if any(w.startswith(k) for w in warnings)]
    line = (f'WARNING {" and ".join(kinds)} (see report.md); ' if kinds else '') + \
        (f'WARNING: {settled.warning}; ' if settled.warning else '') + \
        f'effect: {summary["name"]}'
    if effect != 'none':
        line += (f' ({summary["regressor"]}, coefficient {summary["coefficient"]:.4g} '
                 f'{summary["unit"]})')
    runner = cal.selection.runner_up
    if runner is not None:
        line += f', near tie with {runner.label}'
    if len(summary['effects']) > 1:
        line += ', then ' + ', '.join(e['name'] for e in summary['effects'][1:])
    line += f'; family {summary["family"]}'
    tie = summary['family_comparison'].get('near_tie')
    if tie:
        other = next(f for f in tie['families'] if f != summary['family'])
        line += f' (near tie with {other})'
    line += f'; liquid {settled.source}'
    return (f'{line}; {_errors(summary, cal.samples is not None)}; '
            f'wrote {target}/calibration.json, coefficients.yaml, report.md')


def _errors(summary: dict[str, Any], series: bool) -> str:
    """Say the errors before and after and what they are over, outliers named apart."""
    before, after = summary['error_before']['rmse_lpm'], summary['error_after']['rmse_lpm']
    over = summary['error_over']
    n, total = over['n'], over['n_with_outliers']
    left_out = total - n
    unit = over['what']
    counted = f'{n} of {total} {unit}' if left_out else f'{n} {unit}'
    text = f'out-of-sample RMSE of Q_vl {before:.4g} -> {after:.4g} l/min over {counted}'
    if series:
        bins = summary['error_over_bins']
        text += (f' (mode transient: every usable sample, with the transient terms; over the '
                 f"fit's {bins['n']} rows, means of {summary['bin_size']} sample steps, "
                 f"{bins['error_before']['rmse_lpm']:.4g} -> "
                 f"{bins['error_after']['rmse_lpm']:.4g} l/min)")
    outliers = sum(1 for o in summary['outliers'] if 'sample' not in o)
    if outliers:
        text += (f'; {outliers} isolated outlier(s) ({left_out} {unit}) left out of it, with '
                 f'them {summary["error_before_with_outliers"]["rmse_lpm"]:.4g} -> '
                 f'{summary["error_after_with_outliers"]["rmse_lpm"]:.4g} l/min')
    return text + samples_left_out(summary['coverage'])
