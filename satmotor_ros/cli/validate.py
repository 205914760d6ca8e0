# SPDX-License-Identifier: Apache-2.0
"""``satmotor validate``: the error of a given model on new data, without refitting."""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from satmotor_ros.cli._bench import (add_data_arguments, open_bench, run_bench_command,
                                     samples_left_out)
from satmotor_ros.cli._common import add_motor_options
from satmotor_ros.cli._output import output_dir
from satmotor_ros.identify import BenchTable
from satmotor_ros.identify.calibrated import Calibrated
from satmotor_ros.identify.pipeline import Mode, MODES
from satmotor_ros.identify.validate import validate
from satmotor_ros.identify.validation_report import write_validation
from satmotor_ros.options import MotorOptions


DESCRIPTION = ('Hold a model (the packaged one, a motor file or a calibrated coefficients.yaml '
               'with its effects) against a bench CSV or a rosbag2 recording without refitting '
               'anything, and write validation.json, report.md and residuals.png into --out.')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor validate``."""
    add_data_arguments(parser, MODES)
    add_motor_options(parser, liquid_from_data=True)


def command(data: str, out: str, mode: Mode, options: MotorOptions, columns: str = '',
            force: bool = False) -> int:
    """
    Validate the model on the data and write the three outputs.

    Parameters
    ----------
    data, out, mode, columns : str
        DATA, ``--out``, ``--mode`` and ``--columns`` as :func:`add_data_arguments` parses
        them, [-]
    options : MotorOptions
        The model to validate, [-]
    force : bool
        Replace an existing ``--out`` that validate did not write, [-]

    Returns
    -------
    int
        0 with the error on stdout; 1 with one line on stderr for unusable data or options.

    """
    return run_bench_command(out, lambda: validate_into(
        data, out, mode, options, columns, force))


def validate_into(data: str, out: str, mode: Mode, options: MotorOptions, columns: str,
                  force: bool, table: BenchTable | None = None) -> str:
    """
    Validate, write the outputs and return the summary line ``command`` prints.

    `table` and the errors are as for :func:`~satmotor_ros.cli.calibrate.calibrate_into`.
    """
    inputs, settled, table = open_bench('validate', data, out, options, columns, force, table)
    options = settled.options
    model = options.build_model()
    motor_file = options.motor_file
    written = Calibrated(motor_file) if motor_file else None
    result = validate(table, model, options.liquid, mode,
                      calibrated=written.envelope if written else None,
                      dynamics=written.dynamics if written else None,
                      speed_delay=written.speed_delay if written else None)
    with output_dir('--out', out, 'validate', inputs, force) as tmp:
        summary = write_validation(result, tmp)
    target = Path(out)
    error = summary['error']
    outside = summary['n_extrapolated']
    flagged = f' ({outside} flagged EXTRAPOLATED)' if outside else ''
    if summary['n_invalid']:
        flagged += f'; {summary["n_invalid"]} left out where the model flags them invalid'
    flagged += samples_left_out(summary['coverage'])
    beyond = summary['outside_calibrated_envelope']
    if beyond['share']:
        flagged += (f'; {beyond["samples"]} of {beyond["of"]} samples '
                    f'({100 * beyond["share"]:.0f} %) outside the calibrated envelope')
    return ((f'WARNING: {settled.warning}; ' if settled.warning else '')
            + f'{model.name}, set {settled.source}, effects: {result.describe_effects()}; '
            f'RMSE of Q_vl {error["rmse_lpm"]:.4g} l/min, mean {error["mean_abs_pct"]:.3g} %, '
            f'max {error["max_abs_lpm"]:.4g} l/min over {_over(summary)}{flagged}, '
            f'{_refitted(summary)}; wrote {target}/validation.json, report.md, residuals.png')


def _over(summary: Mapping[str, Any]) -> str:
    """Say what the error is over: samples (the rows' figure beside it) or points."""
    over = summary['error_over']
    text = f'{over["n"]} {over["what"]}'
    bins = summary.get('error_over_bins')
    if bins is not None:
        text += f' (over the {bins["n"]} rows\' means: RMSE {bins["error"]["rmse_lpm"]:.4g} l/min)'
    return text


def _refitted(summary: Mapping[str, Any]) -> str:
    """Say how the transient terms entered the error, and the in-sample second figure."""
    terms = summary.get('transient_terms')
    if terms is None:
        return 'nothing refitted'
    text = f'nothing refitted ({terms["error"]})'
    second = summary.get('error_transient_fitted_in_sample')
    if second is not None:
        text += (f'; in sample, with the transient terms fitted on these data (not a '
                 f'validation): RMSE {second["rmse_lpm"]:.4g} l/min')
    return text
