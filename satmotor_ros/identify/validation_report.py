# SPDX-License-Identifier: Apache-2.0
"""Write ``validation.json``, ``report.md`` and ``residuals.png``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from satmotor_ros.identify.plot_tools import portable
from satmotor_ros.identify.report import channel_axes, grid_note, plot_residual_grid
from satmotor_ros.identify.validate import Validation

FILES = ('validation.json', 'report.md', 'residuals.png')
"""What :func:`write_validation` puts into the output directory."""


def _plot_residuals(val: Validation, path: Path) -> None:
    """Plot the residual of Q_vl against speed, dp, flow, p_out and each channel."""
    plot_residual_grid(channel_axes(val.parts, val.table),
                       {f'{val.model.name} on {val.liquid}': val.residual},
                       f'Residual of the volumetric losses, nothing refitted (RMSE '
                       f'{val.error.rmse_lpm:.4g} l/min)', path,
                       {} if val.flagged is None else
                       {'flagged EXTRAPOLATED (outside the validated or fitted range)':
                        val.flagged})


def _coverage_lines(summary: dict[str, Any]) -> list[str]:
    """Say which samples the error is over and how many lie outside the calibrated envelope."""
    cov = summary['coverage']
    lines = ['## Coverage', '']
    if cov:
        lines.append(f'The error is over {cov["samples_used"]} of {cov["samples_total"]} '
                     f'samples ({100 * cov["fraction"]:.0f} %).')
    beyond = summary['outside_calibrated_envelope']
    if beyond['share'] is None:
        lines.append(f'{beyond["note"][0].upper()}{beyond["note"][1:]}: the share of the data '
                     'outside the range the model was fitted on is unknown.')
    else:
        share = 100 * beyond['share']
        lines.append(f'**{beyond["samples"]} of {beyond["of"]} samples ({share:.1f} %) lie '
                     'outside the envelope the model was calibrated on** (dp and n per '
                     'direction, `coverage` in the motor file): there the model extrapolates.')
    return lines + ['']


def _transient_lines(summary: dict[str, Any]) -> list[str]:
    """Say how the transient terms entered the error, and give the in-sample figure apart."""
    terms = summary.get('transient_terms')
    if terms is None:
        return []
    lines = [f'Transient terms (line compliance, sensor lags) in the error above: '
             f'{terms["error"]}; {terms["note"]}.']
    second = summary.get('error_transient_fitted_in_sample')
    if second is not None:
        lines.append(f'**In sample, not a validation**: with the transient terms fitted by '
                     f'least squares on these data, RMSE {second["rmse_lpm"]:.4g} l/min, mean '
                     f'{second["mean_abs_pct"]:.3g} %, max {second["max_abs_lpm"]:.4g} l/min '
                     '(`error_transient_fitted_in_sample`): it shows how much of the error the '
                     "bench's dynamics on these data explain, and is no figure of the "
                     'calibration.')
    return [' '.join(lines), '']


def _over(summary: dict[str, Any]) -> str:
    """Say what the error is over."""
    over = summary['error_over']
    if over['what'] == 'samples':
        return f'{over["n"]} samples (every usable sample the rows hold)'
    return f'{over["n"]} steady operating points'


def _bins_line(summary: dict[str, Any]) -> str:
    """Give the error over the rows' means of a time series, or ''."""
    bins = summary.get('error_over_bins')
    if bins is None:
        return ''
    e = bins['error']
    return (f' Over the {bins["n"]} rows (the means over short bins of samples that a '
            f'calibration fits) the same model gives RMSE {e["rmse_lpm"]:.4g} l/min, max '
            f'{e["max_abs_lpm"]:.4g} l/min: the noise a row averages out is in the figure '
            'above.')


def _report(val: Validation, summary: dict[str, Any]) -> str:
    """Return ``report.md``'s text."""
    err = val.error
    lines = [f'# Validation of {val.model.name} on {val.liquid}', '',
             f'Data: `{portable(val.table.source)}`, {_over(summary)}. '
             f'Effects in the model: {val.describe_effects()}.']
    lines += [f'- {note}' for note in val.table.notes]
    lines += ['', '## Error', '',
              '| RMSE [l/min] | mean abs [% of mean Q_vl] | max abs [l/min] |',
              '| --- | --- | --- |',
              f'| {err.rmse_lpm:.4g} | {err.mean_abs_pct:.3g} | {err.max_abs_lpm:.4g} |', '',
              'Errors are of the volumetric losses Q_vl = Q - q_t n, measured minus predicted, '
              f'over every {summary["error_over"]["what"][:-1]} used, computed as `satmotor '
              'calibrate` computes them, with nothing refitted: the whole table is out of '
              f'sample for the model.{_bins_line(summary)} Compare the RMSE with the '
              "calibration's `error_after` (and the sensor noise): much larger, or a trend "
              'in the plots below, means the calibration no longer holds.', '',
              *_transient_lines(summary),
              *_coverage_lines(summary),
              '## Residual against each channel', '',
              *grid_note(channel_axes(val.parts, val.table)), '![residuals](residuals.png)', '',
              '## validation.json', '', '```json', json.dumps(summary, indent=2), '```', '']
    return '\n'.join(lines)


def write_validation(val: Validation, out: Path) -> dict[str, Any]:
    """
    Write :data:`FILES` into `out`.

    The command writes into a temporary directory that becomes ``--out`` only when
    complete (:mod:`satmotor_ros.cli._output`), so a failure leaves no partial result.

    Parameters
    ----------
    val : Validation
        The result, [-]
    out : pathlib.Path
        Output directory (exists), [-]

    Returns
    -------
    dict
        The validation.json object.

    """
    summary = val.summary()
    (out / 'validation.json').write_text(json.dumps(summary, indent=2) + '\n', encoding='utf-8')
    (out / 'report.md').write_text(_report(val, summary), encoding='utf-8')
    _plot_residuals(val, out / 'residuals.png')
    return summary


__all__ = ['FILES', 'write_validation']
