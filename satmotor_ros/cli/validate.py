# SPDX-License-Identifier: Apache-2.0
"""``satmotor validate``: the error of a given model on new data, without refitting."""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from satmotor_ros.cli._bench import (add_data_arguments, load_data, run_bench_command,
                                     samples_left_out)
from satmotor_ros.cli._common import add_motor_options
from satmotor_ros.cli._liquid import settle_liquid
from satmotor_ros.cli._output import check_target, output_dir, written_by
from satmotor_ros.identify.coverage import calibrated_envelope
from satmotor_ros.identify.pipeline import Mode, MODES
from satmotor_ros.identify.validate import calibrated_dynamics, validate
from satmotor_ros.identify.validation_report import write_validation
from satmotor_ros.interface import MotorOptions


HELP = 'error of a given (calibrated) model on new data'
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
    return run_bench_command(out, lambda: _validate(data, out, mode, options, columns, force))


def _validate(data: str, out: str, mode: Mode, options: MotorOptions, columns: str,
              force: bool) -> str:
    """Validate, write the outputs and return the summary line."""
    inputs = [name for name in (data, options.motor_file, columns) if name]
    check_target('--out', Path(out), inputs, force, written_by('validate'), 'validate')
    settled = settle_liquid(options, data, 'validate')
    options = settled.options
    model = options.build_model()
    table = load_data(data, columns, model.geometry.displacement)
    table = replace(table, notes=table.notes + (f'liquid: {settled.source}',)
                    + ((f'WARNING: {settled.warning}',) if settled.warning else ()))
    motor_file = options.motor_file
    result = validate(table, model, options.liquid, mode,
                      calibrated=calibrated_envelope(motor_file) if motor_file else None,
                      dynamics=calibrated_dynamics(motor_file) if motor_file else None)
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
            f'max {error["max_abs_lpm"]:.4g} l/min over {summary["n_points"]} points{flagged}, '
            f'{_refitted(summary)}; wrote {target}/validation.json, report.md, residuals.png')


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
