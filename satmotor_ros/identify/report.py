# SPDX-License-Identifier: Apache-2.0
"""The calibration report: ``report.md`` with PNG plots beside it."""

from __future__ import annotations

from dataclasses import replace
import json
from pathlib import Path
from types import ModuleType

import numpy as np

from satmotor_ros.identify.output import effect_block, fitted_coefficients
from satmotor_ros.identify.parts import LossParts, SCALES
from satmotor_ros.identify.pipeline import Calibration
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import TERMS
from satmotor_ros.model.units import LPM, MPA, RPM

_UNITS = {'time': ('s', 1.0), 'revolutions': ('rev', 1.0), 'temperature': ('degC', 1.0),
          'p_case': ('MPa', MPA), 'p_out': ('MPa', MPA), 'p_in': ('MPa', MPA)}


def pyplot() -> ModuleType:
    """Return matplotlib's pyplot on the file-only Agg backend."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot
    return pyplot


def channel_axes(parts: LossParts, table: BenchTable) -> dict[str, FloatArray]:
    """
    Map ``'label [unit]'`` to speed, dp, flow, p_out and each finite channel at the points.

    Parameters
    ----------
    parts : LossParts
        The model's components at the points, [-]
    table : BenchTable
        The same points, with their channels, [-]

    Returns
    -------
    dict
        Each quantity in the unit of its label.

    """
    out = {'n [rpm]': parts.speed / RPM, 'dp [MPa]': parts.dp / MPA,
           'flow [l/min]': parts.flow / LPM, 'p_out [MPa]': table.p_out / MPA}
    for name, x in table.channels.items():
        unit, scale = _UNITS.get(name, (table.units.get(name, '') or '-', 1.0))
        if np.all(np.isfinite(x)):
            out[f'{name} [{unit}]'] = x / scale
    return out


def _regressors(cal: Calibration) -> dict[str, FloatArray]:
    """Map ``'label [unit]'`` to the channels (:func:`channel_axes`) and a chosen term."""
    parts = cal.parts
    out = channel_axes(parts, cal.table)
    chosen = cal.chosen
    if chosen is not None and chosen.effect.startswith('term:'):
        out[f'{chosen.regressor} [SI]'] = TERMS[chosen.regressor][0](parts.speed, parts.dp_i)
    return out


def plot_residual_grid(axes_data: dict[str, FloatArray], residuals: dict[str, FloatArray],
                       title: str, path: Path) -> None:
    """
    Plot residuals of Q_vl against each quantity, one panel per quantity, three a row.

    Parameters
    ----------
    axes_data : dict
        ``'label [unit]'`` to the quantity at the points (:func:`channel_axes`), [-]
    residuals : dict
        Legend label to the residual at the same points, [m^3/s]
    title : str
        The figure's title, [-]
    path : pathlib.Path
        PNG file to write, [-]

    """
    plt = pyplot()
    cols = 3
    rows = int(np.ceil(len(axes_data) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(12, 3.0 * rows), squeeze=False)
    for ax, (label, x) in zip(axes.flat, axes_data.items()):
        for name, residual in residuals.items():
            ax.plot(x, residual / LPM, 'o', ms=3, alpha=0.6, label=name)
        ax.axhline(0.0, color='k', lw=0.8)
        ax.set_xlabel(label)
        ax.set_ylabel('residual of Q_vl [l/min]')
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(axes_data):]:
        ax.set_visible(False)
    axes.flat[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.5 / rows, top=1 - 0.35 / rows,
                        hspace=0.45, wspace=0.3)
    fig.savefig(path, dpi=80, format='png')
    plt.close(fig)


def _plot_residuals(cal: Calibration, path: Path) -> None:
    """Plot the out-of-sample residual of Q_vl against each regressor, before and after."""
    residuals = {'before (no effect)': cal.selection.baseline.cv_error}
    chosen = cal.selection.chosen
    if chosen is not None:
        residuals[f'after ({chosen.label})'] = chosen.cv_error
    plot_residual_grid(_regressors(cal), residuals, 'Out-of-sample residual of the volumetric '
                       'losses against each regressor', path)


def _fitted_model(cal: Calibration) -> MotorModel:
    spec = cal.model.coefficient_set
    coef = replace(fitted_coefficients(cal), external_leakage=0.0)
    return MotorModel(cal.model.geometry, replace(spec, coefficients=coef),
                      cal.model.valid_range, cal.model.liquid)


def _plot_characteristics(cal: Calibration, path: Path) -> None:
    """Plot measured Q_vl against dp with the model's curves, and measured against predicted."""
    plt = pyplot()
    parts = cal.parts
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    edges = np.quantile(parts.speed, np.linspace(0, 1, 5))
    group = np.clip(np.searchsorted(edges, parts.speed, side='right') - 1, 0, 3)
    fitted = _fitted_model(cal)
    dp_i = np.linspace(max(parts.dp_i.min(), 1e3), parts.dp_i.max(), 60)
    colors = plt.rcParams['axes.prop_cycle'].by_key()['color']
    for g in range(4):
        at = group == g
        if not at.any():
            continue
        n = float(np.median(parts.speed[at]))
        c = colors[g % len(colors)]
        left.plot(parts.dp_i[at] / MPA, parts.loss[at] / LPM, 'o', ms=3, color=c,
                  label=f'measured, n ~ {n / RPM:.0f} rpm')
        left.plot(dp_i / MPA, cal.model.breakdown(n, dp_i).total / LPM, '--', color=c, lw=1)
        left.plot(dp_i / MPA, fitted.breakdown(n, dp_i).total / LPM, '-', color=c, lw=1.2)
    left.set_xlabel('chamber pressure drop dp_i [MPa]')
    left.set_ylabel('volumetric losses Q_vl = Q - q_t n [l/min]')
    left.set_title('dashed: packaged model; solid: fitted (without effect)', fontsize=9)
    left.legend(fontsize=7)
    left.grid(alpha=0.3)
    measured = parts.loss / LPM
    before = measured - cal.selection.baseline.cv_error / LPM
    right.plot(measured, before, 'o', ms=3, alpha=0.6, label='before (no effect)')
    if cal.selection.chosen is not None:
        after = measured - cal.selection.chosen.cv_error / LPM
        right.plot(measured, after, 'o', ms=3, alpha=0.6,
                   label=f'after ({cal.selection.chosen.label})')
    lim = [min(measured.min(), before.min()), max(measured.max(), before.max())]
    right.plot(lim, lim, 'k-', lw=0.8)
    right.set_xlabel('measured Q_vl [l/min]')
    right.set_ylabel('predicted Q_vl, out of sample [l/min]')
    right.legend(fontsize=8)
    right.grid(alpha=0.3)
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.12, top=0.93, wspace=0.22)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _plot_ranking(cal: Calibration, path: Path) -> None:
    """Plot the candidates' cross-validated errors against the baseline's."""
    plt = pyplot()
    ranking = cal.selection.ranking[:15]
    fig, ax = plt.subplots(figsize=(8, 0.35 * len(ranking) + 1.5))
    labels = [s.label for s in ranking][::-1]
    values = [s.cv_rmse / LPM for s in ranking][::-1]
    chosen = cal.chosen.label if cal.chosen else None
    runner = cal.selection.runner_up.label if cal.selection.runner_up else None
    colors = ['tab:orange' if lab == chosen else 'tab:olive' if lab == runner else 'tab:blue'
              for lab in labels]
    ax.barh(labels, values, color=colors)
    ax.axvline(cal.selection.baseline.cv_rmse / LPM, color='k', ls='--', label='no effect')
    ax.set_xlabel('cross-validated RMSE of Q_vl [l/min]')
    ax.set_title('Candidate effects (orange: chosen, olive: near tie)', fontsize=10)
    ax.legend(fontsize=8, loc='lower right')
    fig.subplots_adjust(left=0.35, right=0.97, bottom=1.0 / (0.35 * len(ranking) + 1.5),
                        top=1 - 0.4 / (0.35 * len(ranking) + 1.5))
    fig.savefig(path, dpi=80)
    plt.close(fig)


PLOTS = {'residuals': _plot_residuals, 'characteristics': _plot_characteristics,
         'ranking': _plot_ranking}
"""The report's plots: ``<name>.png`` beside ``report.md``, in the report's order."""


def _table(rows: list[list[str]], header: list[str]) -> str:
    lines = ['| ' + ' | '.join(header) + ' |', '|' + ' --- |' * len(header)]
    lines += ['| ' + ' | '.join(row) + ' |' for row in rows]
    return '\n'.join(lines)


def write_report(cal: Calibration, out: Path, summary: dict[str, object]) -> Path:
    """
    Write ``report.md`` and its three PNG plots into `out`.

    Parameters
    ----------
    cal : Calibration
        The result, [-]
    out : pathlib.Path
        Output directory (exists), [-]
    summary : dict
        The calibration.json object, [-]

    Returns
    -------
    pathlib.Path
        The report's path.

    """
    for name, plot in PLOTS.items():
        plot(cal, out / f'{name}.png')
    sel = cal.selection
    lines = [f'# Calibration of {cal.spec.name} on {cal.liquid}', '',
             f'Data: `{cal.table.source}`, {len(cal.parts)} steady operating points.']
    lines += [f'- {note}' for note in cal.table.notes]
    lines += ['', '## Result', '', f'**Effect: `{summary["effect"]}`** — {sel.verdict}.', '']
    if sel.runner_up is not None:
        lines += [f'Runner-up: `{sel.runner_up.label}`. The two explain the data almost '
                  'equally well; believe the choice only as far as the physics of your bench '
                  'supports it.', '']
    before, after = cal.error_before, cal.error_after
    lines += [_table([
        ['packaged model (in sample)', f'{cal.error_packaged.rmse_lpm:.4g}',
         f'{cal.error_packaged.mean_abs_pct:.3g}', f'{cal.error_packaged.max_abs_lpm:.4g}'],
        ['fitted, no effect (out of sample)', f'{before.rmse_lpm:.4g}',
         f'{before.mean_abs_pct:.3g}', f'{before.max_abs_lpm:.4g}'],
        ['fitted with the effect (out of sample)', f'{after.rmse_lpm:.4g}',
         f'{after.mean_abs_pct:.3g}', f'{after.max_abs_lpm:.4g}']],
        ['model', 'RMSE [l/min]', 'mean abs [% of mean Q_vl]', 'max abs [l/min]']), '',
        'Errors are of the volumetric losses Q_vl = Q - q_t n, by '
        f'{min(5, len(cal.parts))}-fold cross-validation.', '', '## Fitted coefficients', '',
        'Factors on the packaged values (95 % confidence intervals from the Jacobian; the fit '
        'has a weak prior that each factor is 1 ± 0.3):', '']
    rows = []
    for name, value, (lo, hi) in zip(cal.final.names, cal.final.values, cal.final.ci95):
        rows.append([name, f'{value:.5g}', f'[{lo:.5g}, {hi:.5g}]'])
    lines += [_table(rows, ['coefficient', 'value', 'ci95']), '']
    lines += ['`leakage_scale` multiplies A_1 (eq. 1) and C_1 (eq. 5), `c_scale` C (eq. 33), '
              '`c_id_scale` C_id (eq. 14). The other coefficients of Table 1 are not '
              'identifiable from Q, n and dp and keep their packaged values.', '']
    lines += ['## Candidates', '', _table(
        [[f'`{s.label}`', f'{s.cv_rmse / LPM:.4g}', f'{s.p_value:.2g}',
          f'{s.fit.effect_coefficient:.4g} {s.candidate.unit if s.candidate else ""}']
         for s in sel.ranking],
        ['candidate', 'CV RMSE [l/min]', 'p (F-test)', 'coefficient']), '',
        f'No effect: CV RMSE {sel.baseline.cv_rmse / LPM:.4g} l/min. An effect is accepted '
        f'when p < {sel.alpha:g}/{len(sel.ranking)} (Bonferroni) and it cuts the CV error by '
        'more than 5 %.', '']
    lines += ['Library:', ''] + [f'- {c.description}' for c in cal.candidates]
    if cal.skipped:
        lines += ['', 'Not tested:', ''] + [f'- {why}' for why in cal.skipped]
    block = effect_block(cal)
    if block:
        lines += ['', '## The effect in `coefficients.yaml`', '', '```json',
                  json.dumps(block, indent=2), '```']
    lines += ['', '## Plots', '']
    for name in PLOTS:
        lines += [f'![{name}]({name}.png)', '']
    lines += ['## calibration.json', '', '```json', json.dumps(summary, indent=2), '```', '']
    path = out / 'report.md'
    path.write_text('\n'.join(lines), encoding='utf-8')
    return path


__all__ = ['PLOTS', 'SCALES', 'channel_axes', 'plot_residual_grid', 'pyplot', 'write_report']
