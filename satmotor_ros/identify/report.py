# SPDX-License-Identifier: Apache-2.0
"""The calibration report: ``report.md`` with PNG plots beside it."""

from __future__ import annotations

from dataclasses import replace
import json
from pathlib import Path
import textwrap
from types import ModuleType
from typing import Any

import numpy as np

from satmotor_ros.identify.output import effect_block, fitted_coefficients
from satmotor_ros.identify.parts import LossParts
from satmotor_ros.identify.pipeline import AT_BOUND, Calibration, one_sided
from satmotor_ros.identify.plot_tools import (draw_beyond, MARK_STYLES, portable,
                                              residual_colors, robust_limits, unique_legend)
from satmotor_ros.identify.residual_map import coverage_section, plot_residual_map
from satmotor_ros.identify.selection import at_bound, Errors
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import transient_section
from satmotor_ros.identify.valve_reach import says
from satmotor_ros.interface import SPEED_SETPOINT
from satmotor_ros.limits import PLOT_MAX_PANELS
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import coefficients_without, effect_name
from satmotor_ros.model.units import LPM, MPA, RPM

UNSEPARABLE = 0.95
"""|correlation| of two fitted parameters beyond which the data cannot tell them apart."""

_UNITS = {'time': ('s', 1.0), 'revolutions': ('rev', 1.0), 'temperature': ('degC', 1.0),
          'p_case': ('MPa', MPA), 'p_out': ('MPa', MPA), 'p_in': ('MPa', MPA),
          SPEED_SETPOINT: ('rpm', RPM)}  # the demo's set-point topic, SI (rad/s)


def pyplot() -> ModuleType:
    """Return matplotlib's pyplot on the file-only Agg backend."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot
    return pyplot


def channel_axes(parts: LossParts, table: BenchTable) -> dict[str, FloatArray]:
    """
    Map ``'label [unit]'`` to speed, dp, flow, p_out and each finite channel at the points.

    Speed, dp and flow are signed as measured (four quadrants, doc/quadrants.md), not the
    magnitudes the fit works on, so that a residual that depends on the direction shows.

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
    out = {'n [rpm]': table.speed / RPM, 'dp [MPa]': table.dp / MPA,
           'flow [l/min]': table.flow / LPM, 'p_out [MPa]': table.p_out / MPA}
    for name, x in table.channels.items():
        # '?' where nothing says the unit: '-' would claim the channel dimensionless
        unit, scale = _UNITS.get(name, (table.units.get(name, '') or '?', 1.0))
        if np.all(np.isfinite(x)):
            out[f'{name} [{unit}]'] = x / scale
    return out


LABEL_MAX = 44
"""Most characters of a label on a plot (a CSV column's name can be of any length), [-]."""


def short_label(label: str) -> str:
    """
    Cut a plot's label to :data:`LABEL_MAX` characters, keeping a ``' [unit]'`` at its end.

    Parameters
    ----------
    label : str
        E.g. ``'a_very_long_channel_name [V]'``, [-]

    Returns
    -------
    str
        The label, or its start, an ellipsis and the unit, [-]

    """
    if len(label) <= LABEL_MAX:
        return label
    name, bracket, unit = label.rpartition(' [')
    if not bracket or len(unit) > LABEL_MAX // 2:
        name, unit = label, ''
    tail = f' [{unit}' if unit else ''
    return name[:LABEL_MAX - len(tail) - 1] + '…' + tail


def plot_residual_grid(axes_data: dict[str, FloatArray], residuals: dict[str, FloatArray],
                       title: str, path: Path,
                       marks: dict[str, np.ndarray] | None = None) -> None:
    """
    Plot residuals of Q_vl against each quantity, one panel per quantity, three a row.

    Only the first :data:`~satmotor_ros.limits.PLOT_MAX_PANELS` quantities are plotted
    (:func:`grid_note` says so in the report). With several residuals the first (before)
    is drawn small and grey and the last on top in a strong colour, so that what an effect
    changed shows. The residual axis ends where :func:`robust_limits` says: points beyond
    are drawn at the edge as triangles and counted in the panel.

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
    marks : dict, optional
        Legend label to a boolean mask of the points to ring (e.g. outliers, points flagged
        EXTRAPOLATED), ringed at the last residual; empty masks are left out, [-]

    """
    plt = pyplot()
    axes_data = dict(list(axes_data.items())[:PLOT_MAX_PANELS])
    marks = {k: m for k, m in (marks or {}).items() if np.any(m)}
    cols = 3
    rows = int(np.ceil(len(axes_data) / cols))
    height = 3.0 * rows  # [inch]
    fig, axes = plt.subplots(rows, cols, figsize=(12, height), squeeze=False)
    series = [(name, r / LPM) for name, r in residuals.items()]
    limits = robust_limits(np.concatenate([y for _, y in series]))
    several = len(series) > 1
    colors = residual_colors(len(series))
    handles: dict[str, Any] = {}
    for ax, (label, x) in zip(axes.flat, axes_data.items()):
        beyond = np.zeros(len(x), dtype=bool)
        for k, ((name, y), color) in enumerate(zip(series, colors)):
            faint = several and k == 0
            (line,) = ax.plot(x, np.clip(y, *limits), 'o', ms=2.5 if faint else 3.5,
                              alpha=0.5 if faint else 0.85, color=color, zorder=2 + k,
                              mec='none', label=name)
            handles.setdefault(name, line)
            beyond |= draw_beyond(ax, x, y, limits, color)
        last = series[-1][1]
        for (name, mask), style in zip(marks.items(), MARK_STYLES):
            (ring,) = ax.plot(x[mask], np.clip(last[mask], *limits), ls='none', zorder=6,
                              label=name, **style)
            handles.setdefault(name, ring)
        if beyond.any():
            ax.text(0.98, 0.97, f'{int(beyond.sum())} beyond the axis (drawn at its edge)',
                    transform=ax.transAxes, ha='right', va='top', fontsize=7, color='0.3')
        ax.set_ylim(*limits)
        ax.axhline(0.0, color='k', lw=0.8)
        ax.set_xlabel(short_label(label))
        ax.set_ylabel('residual of Q_vl [l/min]')
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(axes_data):]:
        ax.set_visible(False)
    # one legend for the figure, between the title and the panels: a long label (several
    # effects) inside a panel would cover its points and run past the figure's edge
    ncol = min(len(handles), 2)
    legend_rows = int(np.ceil(len(handles) / ncol))
    fig.suptitle(title, y=1 - 0.1 / height, va='top')
    fig.legend(list(handles.values()), list(handles), loc='upper center', ncol=ncol,
               fontsize=8, frameon=False, bbox_to_anchor=(0.5, 1 - 0.4 / height))
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.6 / height,
                        top=1 - (0.65 + 0.2 * legend_rows) / height, hspace=0.45, wspace=0.3)
    fig.savefig(path, dpi=80, format='png')
    plt.close(fig)


def grid_note(axes_data: dict[str, FloatArray]) -> list[str]:
    """Return the report's sentence on quantities left out of the residual grid, if any."""
    if len(axes_data) <= PLOT_MAX_PANELS:
        return []
    return [f'The residual plot shows the first {PLOT_MAX_PANELS} of {len(axes_data)} '
            'quantities (the cap SATMOTOR_PLOT_MAX_PANELS, doc/outputs.md); the others are '
            'not plotted.', '']


def _plot_residuals(cal: Calibration, path: Path) -> None:
    """Plot the out-of-sample residual of Q_vl against each regressor, before and after."""
    residuals = {'before (no effect)': cal.selection.baseline.cv_error}
    labels = []
    for score in cal.found:
        labels.append(score.label)
        residuals[f'after {" + ".join(labels)}'] = score.cv_error
    plot_residual_grid(channel_axes(cal.parts, cal.table), residuals, 'Out-of-sample residual '
                       'of the volumetric losses against each regressor', path,
                       {'outlier (left out of the fit and the errors)': cal.forward.outliers})


QUADRANT_MARKERS = {'motor, forward': 'o', 'motor, reverse': 's', 'pump, forward': '^',
                    'pump, reverse': 'v'}
"""The marker of each quadrant's points (doc/quadrants.md) in the characteristics plot."""


def quadrants(parts: LossParts) -> np.ndarray:
    """
    Name the quadrant of each point: motor or pump, forward or reverse (doc/quadrants.md).

    Parameters
    ----------
    parts : LossParts
        The model's components at the points (their frame and rotation), [-]

    Returns
    -------
    ndarray of str
        A key of :data:`QUADRANT_MARKERS` per point; a stalled shaft counts as forward motor.

    """
    n = len(parts)
    rotation = np.broadcast_to(np.asarray(parts.rotation, dtype=float), n)
    sign = np.broadcast_to(np.asarray(parts.sign, dtype=float), n)
    mode = np.where(rotation * sign < 0.0, 'pump', 'motor')
    return np.char.add(mode, np.where(rotation < 0.0, ', reverse', ', forward'))


def _fitted_model(cal: Calibration) -> MotorModel:
    spec = cal.model.coefficient_set
    coef = coefficients_without(cal.effects(), fitted_coefficients(cal))
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
    quadrant = quadrants(parts)
    signed = set(quadrant) != {'motor, forward'}
    for g in range(4):
        at = group == g
        if not at.any():
            continue
        n = float(np.median(parts.speed[at]))
        c = colors[g % len(colors)]
        left.plot([], [], 'o', ms=3, color=c,
                  label=f'measured, {"|n|" if signed else "n"} ~ {n / RPM:.0f} rpm')
        for name, marker in QUADRANT_MARKERS.items():
            here = at & (quadrant == name)
            left.plot(parts.dp_i[here] / MPA, parts.loss[here] / LPM, marker, ms=3, color=c)
        left.plot(dp_i / MPA, cal.model.breakdown(n, dp_i).total / LPM, '--', color=c, lw=1)
        left.plot(dp_i / MPA, fitted.breakdown(n, dp_i).total / LPM, '-', color=c, lw=1.2)
    if signed:  # the model's loss is the same function of |n| and |dp_i| in every quadrant
        for name, marker in QUADRANT_MARKERS.items():
            if (quadrant == name).any():
                left.plot([], [], marker, ms=4, color='0.35', label=name)
    outlier = cal.forward.outliers
    limits = robust_limits(parts.loss / LPM)
    if outlier.any():
        left.plot(parts.dp_i[outlier] / MPA, np.clip(parts.loss[outlier] / LPM, *limits),
                  ls='none', label='outlier (left out)', clip_on=False, **MARK_STYLES[0])
    left.set_ylim(*limits)
    beyond = int(draw_beyond(left, parts.dp_i / MPA, parts.loss / LPM, limits, '0.3').sum())
    if beyond:
        left.text(0.98, 0.03, f'{beyond} beyond the axis (drawn at its edge)',
                  transform=left.transAxes, ha='right', va='bottom', fontsize=7, color='0.3')
    left.set_xlabel(f'chamber pressure drop {"|dp_i|" if signed else "dp_i"} [MPa]')
    left.set_ylabel('volumetric losses Q_vl = ' + ('sign(dp) (Q - q_t n)' if signed
                                                   else 'Q - q_t n') + ' [l/min]')
    left.set_title('dashed: packaged model; solid: fitted (without effect)', fontsize=9)
    unique_legend(left, fontsize=7)
    left.grid(alpha=0.3)
    measured = parts.loss / LPM
    before = measured - cal.selection.baseline.cv_error / LPM
    right.plot(measured, before, 'o', ms=3, alpha=0.6, label='before (no effect)')
    if cal.found:
        after = measured - cal.forward.final.cv_error / LPM
        right.plot(measured, after, 'o', ms=3, alpha=0.6,  # several effects: several lines
                   label=textwrap.fill(f'after ({" + ".join(s.label for s in cal.found)})', 48))
    lim = robust_limits(np.concatenate([measured, before]))
    if outlier.any():
        right.plot(np.clip(measured[outlier], *lim), np.clip(before[outlier], *lim), ls='none',
                   label='outlier (left out)', clip_on=False, **MARK_STYLES[0])
    right.plot(lim, lim, 'k-', lw=0.8)
    right.set_xlim(*lim)
    right.set_ylim(*lim)
    far = (measured < lim[0]) | (measured > lim[1]) | (before < lim[0]) | (before > lim[1])
    if far.any():
        right.plot(np.clip(measured[far], *lim), np.clip(before[far], *lim), 'D', ms=6,
                   color='0.3', clip_on=False, zorder=5,
                   label=f'{int(far.sum())} beyond the axes (drawn at the edge)')
    right.set_xlabel('measured Q_vl [l/min]')
    right.set_ylabel('predicted Q_vl, out of sample [l/min]')
    # the points run from lower left to upper right
    unique_legend(right, fontsize=8, loc='lower right')
    right.grid(alpha=0.3)
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.12, top=0.93, wspace=0.22)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _plot_ranking(cal: Calibration, path: Path) -> None:
    """Plot the candidates' cross-validated errors against the baseline's."""
    plt = pyplot()
    ranking = cal.selection.ranking[:15]
    # constrained layout makes room for the longest label, cut (a CSV column's name may be
    # long) so that the bars keep most of the width
    fig, ax = plt.subplots(figsize=(8, 0.35 * len(ranking) + 1.5), layout='constrained')
    labels = [short_label(s.label) for s in ranking][::-1]
    values = [s.cv_rmse / LPM for s in ranking][::-1]
    chosen = cal.found[0] if cal.found else None
    runner = cal.selection.runner_up
    colors = ['tab:orange' if s is chosen else 'tab:olive' if s is runner else
              'tab:gray' if s.fit.pinned(effects_only=True) else 'tab:blue'
              for s in ranking][::-1]
    ax.barh(range(len(labels)), values, color=colors, tick_label=labels)
    ax.axvline(cal.selection.baseline.cv_rmse / LPM, color='k', ls='--')
    ax.set_xlabel('cross-validated RMSE of Q_vl [l/min]')
    grey = ', grey: at a bound' if 'tab:gray' in colors else ''
    fig.suptitle(f'Candidate effects\n(orange: chosen, olive: near tie{grey}; dashed: no effect)',
                 fontsize=10)
    fig.savefig(path, dpi=80)
    plt.close(fig)


PLOTS = {'residual_map': plot_residual_map, 'residuals': _plot_residuals,
         'characteristics': _plot_characteristics, 'ranking': _plot_ranking}
"""The report's plots: ``<name>.png`` beside ``report.md``, in the report's order."""


def _table(rows: list[list[str]], header: list[str]) -> str:
    lines = ['| ' + ' | '.join(header) + ' |', '|' + ' --- |' * len(header)]
    lines += ['| ' + ' | '.join(row) + ' |' for row in rows]
    return '\n'.join(lines)


def _errors_row(name: str, e: Errors) -> list[str]:
    return [name, f'{e.rmse_lpm:.4g}', f'{e.mean_abs_pct:.3g}', f'{e.max_abs_lpm:.4g}']


SAME_FIGURE = 0.005
"""Relative difference below which a step's plain figure is the table's, [-]."""


def _refitted(cal: Calibration, step: int) -> str:
    """
    Flag a step whose plain figures are not the table's for the same effects.

    A step after the first refits the effects found so far under its own noise weights and
    judges its candidates against that refit over its own rows: its plain RMSE is then another
    figure than the table's (that of the effects' own step, over the final model's rows).

    Parameters
    ----------
    cal : Calibration
        The result, [-]
    step : int
        The step, from 1, [-]

    Returns
    -------
    str
        '' when the figures agree (or for the first step); else a sentence that gives both.

    """
    if step < 2:
        return ''
    baseline, found = cal.forward.steps[step - 1].baseline, cal.found[:step - 1]
    table = cal.row_errors(found[-1]).rmse_lpm  # the verdicts' figures are over the rows
    if abs(baseline.rmse / LPM - table) <= SAME_FIGURE * table:
        return ''
    left_out = cal.forward.steps[step - 1].left_out
    rows = int(np.count_nonzero(~left_out))
    same_rows = float(np.sqrt(np.mean(baseline.cv_error[cal.inliers] ** 2))) / LPM
    effects = ' + '.join(f'`{effect_name(e)}`' for e in cal.effects()[:step - 1])
    return (f" **Not the table's figures:** this step refits {effects} under its own noise "
            f'weights and judges against that refit over its {rows} rows, plain RMSE '
            f"{baseline.rmse / LPM:.4g} l/min ({same_rows:.4g} over the table's rows), where "
            f'{"the rows give" if cal.over is not None else "the table gives"} {table:.4g} '
            f'l/min for the same effects as fitted at step '
            f'{step - 1} (the model written)')


def _samples(cal: Calibration) -> int:
    """Return the samples the errors are over (a time series read with every sample)."""
    return int(cal.over.kept(cal.forward.outliers).sum()) if cal.over is not None else 0


def _steps(cal: Calibration) -> list[str]:
    """List the forward selection's steps: the verdicts and the error after each effect."""
    lines = []
    for i, step in enumerate(cal.forward.steps, 1):
        lines.append(f'{i}. {step.verdict}.' + _refitted(cal, i))
    lines += [f'- {note}.' for note in (one_sided(score.added, effect) for score, effect in
                                        zip(cal.found, cal.effects())) if note]
    rows = [_errors_row('packaged model (in sample)', cal.error_packaged),
            _errors_row('fitted, no effect', cal.error_before)]
    names = []
    for score, effect in zip(cal.found, cal.effects()):
        names.append(f'`{effect_name(effect)}`')
        rows.append(_errors_row(f'+ {" + ".join(names)}', cal.errors(score)))
    header = ['model', 'RMSE [l/min]', 'mean abs [% of mean Q_vl]', 'max abs [l/min]']
    return lines + ['', _table(rows, header), '',
                    'Errors are of the volumetric losses Q_vl = Q - q_t n, out of sample '
                    f'({min(cal.n_folds, len(cal.parts))}-fold cross-validation), '
                    + (f'at every sample the rows hold ({_samples(cal)} samples, those of '
                       'an outlier row left out; a sample takes the fit '
                       "that did not see its row's fold)" if cal.over is not None else
                       'at the points that are not outliers')
                    + ': the plain figures a user reads. The selection '
                    'chooses by another figure, the cross-validated error of the residuals '
                    "weighted by the noise model and passed through Huber's loss (the "
                    "candidates' table below), and keeps an effect only if the plain RMSE "
                    'falls too' + (" (both over the rows the fit reads, the bins' means: the "
                                   "verdicts' figures are those of `error_over_bins`)"
                                   if cal.over is not None else '') + '.']


def _outliers(cal: Calibration, summary: dict[str, Any]) -> list[str]:
    rows = summary['outliers']
    sigma = cal.forward.sigma / LPM
    lines = ['## Outliers and noise', '',
             f'Noise of the measured flow estimated from the residuals: {np.min(sigma):.3g} to '
             f'{np.max(sigma):.3g} l/min (a floor plus a share of the reading). Each step weighs '
             "the points by it and by Huber's loss, and leaves out the points that are "
             'isolated outliers even under its best-fitting model; outliers that cluster with '
             'their neighbours stay in (see the regions above).', '']
    if not rows:
        return lines + ['No outlier.', '']
    keys = list(dict.fromkeys(k for r in rows for k in r))  # a spike's keys after the rest
    cells = [['' if r.get(k) is None else str(r[k]) for k in keys] for r in rows]
    return lines + [_table(cells, keys), '',
                    'These points decide nothing: they are left out of the fits and of the '
                    'first error figures (the second pair includes them).', '']


def _identifiability(cal: Calibration) -> list[str]:
    """Give the fitted parameters' correlations and name the pairs the data cannot separate."""
    names = cal.final.names
    corr = cal.final.correlation
    lines = ['## Identifiability', '', 'Correlations of the fitted parameters (final fit):', '',
             _table([[f'`{n}`'] + [f'{v:+.2f}' for v in row] for n, row in zip(names, corr)],
                    ['', *[f'`{n}`' for n in names]]), '']
    pairs = [(names[i], names[j], corr[i, j]) for i in range(len(names))
             for j in range(i + 1, len(names)) if abs(corr[i, j]) > UNSEPARABLE]
    if not pairs:
        return lines + [f'No pair is correlated beyond |r| = {UNSEPARABLE}: the data separate '
                        'every fitted parameter.', '']
    lines += [f'The data cannot separate these pairs (|r| > {UNSEPARABLE}): each trades off '
              'against the other, so only their combination is determined; measure where they '
              'differ (e.g. speed and pressure varied independently) to tell them apart.', '']
    return lines + [f'- `{a}` and `{b}`: r = {r:+.3f}' for a, b, r in pairs] + ['']


def _families(cal: Calibration) -> list[str]:
    """Describe the model family and how it was chosen (the structure before the effect)."""
    comparison = cal.family_comparison()
    lines = ['## Model family', '', f'**{cal.model.family.name}**: {comparison["verdict"]}.', '']
    lines += _base(cal)
    if comparison.get('near_tie'):
        note = comparison['near_tie']['note']
        lines += [f'**{note[0].upper()}{note[1:]}.**', '']  # family names keep their case
    if not comparison['families']:
        return lines
    rows = [[f'`{f["family"]}`', ', '.join(f['factors']) or '-',
             *(f'{f["cv_error"][k]:.4g}' if f['cv_error'] else '-'
               for k in ('rmse_lpm', 'mean_abs_pct', 'max_abs_lpm')), f.get('note', '')]
            for f in comparison['families']]
    lines += [_table(rows, ['family', 'factors fitted', 'RMSE [l/min]', 'mean abs [%]',
                            'max abs [l/min]', 'note']), '',
              f'Each family refitted without any effect on the same {comparison["n_points"]} '
              'points (those no family calls an outlier), errors of Q_vl out of sample '
              "(cross-validated). The motor's own family is kept unless another cuts its "
              'error by more than the least gain an effect must bring; `--family` pins it.', '']
    return lines


def _base(cal: Calibration) -> list[str]:
    """Say what the base fitted (speed delay, channel drop) and which coefficients it kept."""
    delay = cal.delay
    said = ([f'**Delay of the speed reading, before any effect** '
             f'(`satmotor_ros.identify.delay`): {delay.note}'
             + (f'; {delay.unserved} samples at the ends of stretches left out (their '
                'shifted speed lies past the stretch)' if delay.unserved else '') + '.', '']
            if delay is not None else [])
    if cal.base is None:
        return said
    base = cal.base
    fitted = [f'`{f["coefficient"]}` = {f["value"]:.4g} (packaged {f["packaged"]:.4g}, 95 % '
              f'[{f["ci95"][0]:.4g}, {f["ci95"][1]:.4g}])' for f in base.fitted]
    if delay is not None and delay.fitted and delay.ci95 is not None:
        fitted.append(f'`speed_delay` = {delay.seconds:.4g} s (95 % [{delay.ci95[0]:.4g}, '
                      f'{delay.ci95[1]:.4g}])')
    kept = ', '.join(f'`{k["coefficient"]}` = {k["value"]:.4g}' for k in base.kept)
    if delay is not None and not delay.fitted:
        kept += (', ' if kept else '') + '`speed_delay` = 0 s'
    return said + [f'**Base, before any effect**: {base.note}.', '',
                   f'- fitted: {"; ".join(fitted) or "none"}',
                   f'- kept (the data cannot pin them): {kept or "none"}', '']


def _written_effects(summary: dict[str, Any]) -> list[str]:
    """List the effects as calibration.json and coefficients.yaml write them (SI)."""
    effects = summary.get('effects') or []
    if not effects:
        return []
    rows = []
    for e in effects:
        fitted = e.get('exponents_ci95') or {}
        shape = ', '.join([f"exponent of {k} {e['exponents'][k]:.4g} [{lo:.4g}, {hi:.4g}]"
                           for k, (lo, hi) in fitted.items()]
                          + ([f"threshold {e['threshold']['value']:.5g} "
                              f"{e['threshold']['unit']}"] if e.get('threshold') else []))
        rows.append([f"`{e['name']}`", f"{e['coefficient']:.5g} {e['unit']}",
                     f"[{e['ci95'][0]:.5g}, {e['ci95'][1]:.5g}]", shape or '-'])
    return ['The effects as `calibration.json` and `coefficients.yaml` write them, the '
            'coefficient k in SI. For a fitted form the fit estimates its size (the rows above: '
            'the extra loss at the largest regressor value) and k follows from the size and the '
            'exponents, so the interval of k also carries the uncertainty of the exponents and '
            'can be much wider than that of the size; a k that cannot be negative (a valve, a '
            'leak) has it on the log scale, where the exponents enter linearly and the '
            'interval stays above 0.', '',
            _table(rows, ['effect', 'coefficient k', 'ci95', 'fitted shape']), '']


def write_report(cal: Calibration, out: Path, summary: dict[str, object]) -> Path:
    """
    Write ``report.md`` and its PNG plots (:data:`PLOTS`) into `out`.

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
    found = ', '.join(f'`{effect_name(e)}`' for e in cal.effects()) or '`none`'
    data = (f'{len(cal.parts)} rows of {cal.samples.n_samples} samples'
            if cal.samples is not None else f'{len(cal.parts)} steady operating points')
    lines = [f'# Calibration of {cal.spec.name} on {cal.liquid}', '',
             f'Data: `{portable(cal.table.source)}`, {data}. '
             f'Mode `{cal.mode}`: {cal.mode_reason}.']
    lines += [f'- {note}' for note in cal.table.notes]
    lines += [f'- **{note}**' for note in cal.warnings().get('warnings', [])
              if note.startswith(AT_BOUND)]
    lines += [''] + _families(cal)
    lines += ['## Result', '', f'**Effects: {found}**, found one after the other:', '']
    lines += _steps(cal) + ['']
    reach = [says(e) for e in summary.get('effects') or []]  # type: ignore[attr-defined]
    lines += [f'{text}.' for text in reach if text] + ([''] if any(reach) else [])
    lines += coverage_section(cal, summary)
    for step in cal.forward.steps:
        if step.runner_up is not None and step.chosen is not None:
            lines += [f'Runner-up of `{step.chosen.label}`: `{step.runner_up.label}`. The two '
                      'explain the data almost equally well; believe the choice only as far as '
                      'the physics of your bench supports it.', '']
    lines += ['## Fitted coefficients', '',
              'Factors on the packaged values, then the effects (95 % confidence intervals from '
              'the Jacobian; the fit has a weak prior that each factor is 1 ± 0.3):', '']
    pinned = dict(cal.forward.final.fit.pinned())
    rows = [[name, f'{value:.5g}', f'[{lo:.5g}, {hi:.5g}]' if name not in pinned else
             f'- ({AT_BOUND}: not an estimate)']
            for name, value, (lo, hi) in zip(cal.final.names, cal.final.values, cal.final.ci95)]
    lines += [_table(rows, ['parameter', 'value', 'ci95']), '']
    lines += _written_effects(summary)
    lines += [f'`{c.name}` multiplies {c.describes or c.name}.' for c in cal.parts.components]
    lines += [('The other coefficients of Table 1 are not identifiable from Q, n and dp and keep '
               'their packaged values.') if cal.model.family.name == 'sliwinski2017' else
              (f"The family's other coefficients ({cal.model.family.name}, doc/families.md) "
               'keep their values.'), '']
    if cal.samples is not None:
        lines += transient_section(summary, cal.inflation)
    lines += _identifiability(cal) + _outliers(cal, summary)
    lines += ['## Candidates of the first step', '', _table(
        [[f'`{s.label}`', f'{s.cv_rmse / LPM:.4g}', f'{s.p_value:.2g}',
          f'{s.fit.effect_coefficient:.4g} {s.candidate.unit if s.candidate else ""}'
          + (f' ({AT_BOUND}: {at_bound(s)})' if s.fit.pinned(effects_only=True) else '')]
         for s in sel.ranking],
        ['candidate', 'CV error [l/min]', 'p (F-test)', 'coefficient']), '',
        f'No effect: CV error {sel.baseline.cv_rmse / LPM:.4g} l/min (noise-weighted, through '
        f"Huber's loss). An effect is accepted when p < {sel.alpha:g}/{len(sel.ranking)} "
        '(Bonferroni) and it cuts the CV error by more than 5 %; then the loop tests the '
        f'rest on top of it. A candidate marked {AT_BOUND} is never accepted: its fit ended on '
        'a bound of its range, so its value is the bound, not an estimate, and its p-value '
        'and interval mean nothing.', '']
    lines += ['Library:', ''] + [f'- {c.description}' for c in cal.candidates]
    if cal.skipped:
        lines += ['', 'Not tested:', ''] + [f'- {why}' for why in cal.skipped]
    block = effect_block(cal)
    if block:
        lines += ['', '## The effects in `coefficients.yaml`', '', '```json',
                  json.dumps(block, indent=2), '```']
    lines += ['', '## Plots', ''] + grid_note(channel_axes(cal.parts, cal.table))
    for name in PLOTS:
        lines += [f'![{name}]({name}.png)', '']
    lines += ['## calibration.json', '', '```json', json.dumps(summary, indent=2), '```', '']
    path = out / 'report.md'
    path.write_text('\n'.join(lines), encoding='utf-8')
    return path


__all__ = ['LABEL_MAX', 'PLOTS', 'QUADRANT_MARKERS', 'channel_axes', 'grid_note',
           'plot_residual_grid', 'pyplot', 'quadrants', 'short_label', 'write_report']
