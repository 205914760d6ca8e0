# SPDX-License-Identifier: Apache-2.0
"""``satmotor validate``: the error of a given model on new data, without refitting."""

from __future__ import annotations

import argparse
from pathlib import Path

from satmotor_ros.cli._common import add_motor_options, fail, subcommand
from satmotor_ros.cli.calibrate import add_data_arguments, load_data
from satmotor_ros.identify import IdentificationError
from satmotor_ros.identify.pipeline import Mode
from satmotor_ros.identify.validate import validate
from satmotor_ros.identify.validation_report import write_validation
from satmotor_ros.interface import MotorOptions
from satmotor_ros.model import ModelError


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``satmotor validate`` and its options."""
    parser = subcommand(
        sub, 'validate', command, 'error of a given (calibrated) model on new data',
        'Hold a model (the packaged one, a motor file or a calibrated coefficients.yaml with '
        'its effects) against a bench CSV or a rosbag2 recording without refitting anything, '
        'and write validation.json, report.md and residuals.png into --out.')
    add_data_arguments(parser)
    add_motor_options(parser, liquid_required=True)


def command(data: str, out: str, mode: Mode, options: MotorOptions) -> int:
    """
    Validate the model on the data and write the three outputs.

    Parameters
    ----------
    data : str
        Bench CSV or rosbag2 directory, [-]
    out : str
        Output directory, [-]
    mode : str
        ``'auto'``, ``'points'`` or ``'series'``, [-]
    options : MotorOptions
        The model to validate, [-]

    Returns
    -------
    int
        0 with the error on stdout; 1 with one line on stderr for unusable data or options.

    """
    try:
        model = options.build_model()
        result = validate(load_data(data), model, options.liquid, mode)
        target = Path(out)
        target.mkdir(parents=True, exist_ok=True)
        summary = write_validation(result, target)
    except (IdentificationError, ModelError) as err:
        return fail(err)
    except OSError as err:
        return fail(f'--out {out!r}: {err.strerror}')
    error = summary['error']
    print(f'{model.name}, set {options.liquid}, effects: {result.describe_effects()}; '
          f'RMSE of Q_vl {error["rmse_lpm"]:.4g} l/min, mean {error["mean_abs_pct"]:.3g} %, max '
          f'{error["max_abs_lpm"]:.4g} l/min over {summary["n_points"]} points, nothing '
          f'refitted; wrote {target}/validation.json, report.md, residuals.png')
    return 0
