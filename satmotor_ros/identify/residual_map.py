# SPDX-License-Identifier: Apache-2.0
"""
Where the model misses: the residual over every row as a map of signed dp and speed.

The report's ``residual_map.png`` shows, before and after the effects, the out-of-sample
residual of every row (every steady point or window; a time series' every sample, outliers
included, :mod:`.sample_error`)
coloured on a map of the signed drop and the signed speed, so that a knee (a valve that
opens at the top of the drop in one direction) or a corner shows at a glance; below,
the residual's mean in bins of the signed drop and of the signed speed. The module also
writes the report's section on the coverage, the errors over every row and the regions
the model misses.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.identify.pipeline import Calibration
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import LPM, MPA, RPM

SCATTER_MAX = 600
"""Most rows drawn as points; more are drawn as hexagonal cells of the mean residual."""

PROFILE_BINS = 40
"""Bins of equal width of the signed drop (and speed) for the residual's mean profile, [-]."""


def measured_frame(cal: Calibration, error: FloatArray) -> FloatArray:
    """Return a residual of the rows' frame as measured minus predicted flow, as read, [m^3/s]."""
    return error * cal.parts.sign


def _map(ax: Any, dp: FloatArray, n: FloatArray, residual: FloatArray, limit: float,
         title: str) -> Any:
    """Draw one map panel and return its colour mapping."""
    order = np.argsort(np.abs(residual))  # the largest misses on top
    style: dict[str, Any] = {'cmap': 'RdBu_r', 'vmin': -limit, 'vmax': limit}
    if dp.size <= SCATTER_MAX:
        drawn = ax.scatter(dp[order], n[order], c=residual[order], s=14, edgecolors='none',
                           **style)
    else:
        drawn = ax.hexbin(dp, n, C=residual, reduce_C_function=np.mean, gridsize=36,
                          mincnt=1, **style)
    ax.axvline(0.0, color='0.5', lw=0.6)
    ax.axhline(0.0, color='0.5', lw=0.6)
    ax.set_xlabel('dp = p_in - p_out [MPa]')
    ax.set_ylabel('n [rpm]')
    ax.set_title(title, fontsize=9)
    return drawn


def _profile(ax: Any, x: FloatArray, residuals: dict[str, FloatArray], label: str) -> None:
    """Draw the mean residual in bins of equal width of `x` (bins of 3 rows or more)."""
    if not np.ptp(x) > 0.0:
        return
    edges = np.linspace(float(np.min(x)), float(np.max(x)), PROFILE_BINS + 1)
    which = np.clip(np.searchsorted(edges, x, side='right') - 1, 0, edges.size - 2)
    counts = np.bincount(which, minlength=edges.size - 1)
    centre = np.array([np.median(x[which == k]) if counts[k] else np.nan
                       for k in range(edges.size - 1)])
    for name, r in residuals.items():
        mean = np.bincount(which, weights=r, minlength=edges.size - 1) / np.maximum(counts, 1)
        at = counts >= 3
        ax.plot(centre[at], mean[at] / LPM, 'o-', ms=3, lw=1, label=name)
    ax.axhline(0.0, color='k', lw=0.8)
    ax.set_xlabel(label)
    ax.set_ylabel('mean residual [l/min]')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)


def _residuals(cal: Calibration) -> tuple[FloatArray, ...]:
    """Return dp [MPa], n [rpm], the residual before and after [m^3/s] and the outliers."""
    if cal.over is None:
        p = cal.parts
        return (p.sign * p.dp / MPA, p.rotation * p.speed / RPM,
                measured_frame(cal, cal.selection.baseline.cv_error),
                measured_frame(cal, cal.forward.final.cv_error), cal.forward.outliers)
    data = cal.over.data
    p, at = data.parts, cal.over.kept()
    sign = np.asarray(p.sign) * np.ones(len(data))
    return ((sign * p.dp / MPA)[at], (p.rotation * p.speed / RPM)[at],
            (sign * cal.over.residual[0])[at], (sign * cal.over.residual[-1])[at],
            cal.forward.outliers[data.row][at])


def plot_residual_map(cal: Calibration, path: Path) -> None:
    """
    Plot the residual over every row against signed dp and n, before and after the effects.

    Parameters
    ----------
    cal : Calibration
        The result, [-]
    path : pathlib.Path
        PNG file to write, [-]

    """
    import matplotlib
    matplotlib.use('Agg')  # file only, as the report's other plots
    from matplotlib import pyplot as plt
    dp, n, before, after, isolated = _residuals(cal)
    limit = float(np.quantile(np.abs(np.concatenate([before, after])), 0.98)) / LPM
    limit = limit if limit > 0.0 else 1.0
    found = ' + '.join(s.label for s in cal.found) or 'no effect found'
    fig, axes = plt.subplots(2, 2, figsize=(12, 8.6))
    drawn = _map(axes[0, 0], dp, n, before / LPM, limit, 'before: the model fitted without '
                 'an effect')
    _map(axes[0, 1], dp, n, after / LPM, limit, f'after: {found}'[:70])
    for ax in axes[0]:
        ax.plot(dp[isolated], n[isolated], 'x', color='k', ms=4, mew=0.8,
                label='isolated outlier' if isolated.any() else None)
        if isolated.any():
            ax.legend(fontsize=7, loc='lower left')
    fig.subplots_adjust(left=0.07, right=0.87, bottom=0.07, top=0.92, hspace=0.3, wspace=0.22)
    bar = fig.colorbar(drawn, cax=fig.add_axes((0.895, 0.55, 0.013, 0.37)))
    bar.set_label('measured - predicted flow, out of sample [l/min]')
    profiles = {'before': before, 'after': after} if cal.found else {'no effect': before}
    _profile(axes[1, 0], dp, profiles, 'dp = p_in - p_out [MPa]')
    _profile(axes[1, 1], n, profiles, 'n [rpm]')
    what = (f'{dp.size} samples, in {len(cal.parts)} rows' if cal.over is not None
            else f'{dp.size} rows')
    fig.suptitle(f'Residual over every {"sample" if cal.over is not None else "row"} ({what}, '
                 'outliers included), by signed drop and speed', fontsize=11)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def coverage_section(cal: Calibration, summary: dict[str, Any]) -> list[str]:
    """
    Write the report's lines on the rows used, the errors over every row and the misses.

    Parameters
    ----------
    cal : Calibration
        The result, [-]
    summary : dict
        The calibration.json object, [-]

    Returns
    -------
    list of str
        Markdown lines.

    """
    cov = summary['coverage']
    over = summary['error_over']
    lines = [f'## Coverage and the error over every {over["what"].removesuffix("s")}', '',
             f'Mode `{cal.mode}`: {cal.mode_reason}. The fit used {cov["samples_used"]} of '
             f'{cov["samples_total"]} samples ({100 * cov["fraction"]:.0f} %)'
             + (f', spanning {100 * cov["envelope_share"]:.0f} % of the operating envelope'
                if 'envelope_share' in cov else '') + '. Its envelope per direction of the '
             'drop:', '',
             '| direction | dp [MPa] | n [rpm] | samples |', '| --- | --- | --- | --- |']
    for name, env in cov['envelope'].items():
        lines.append(f'| {name} | {env["dp_mpa"][0]:.4g} to {env["dp_mpa"][1]:.4g} | '
                     f'{env["speed_rpm"][0]:.4g} to {env["speed_rpm"][1]:.4g} | '
                     f'{env["samples"]} |')
    rows = [('before (no effect)', summary['error_before'],
             summary['error_before_with_outliers']),
            ('after', summary['error_after'], summary['error_after_with_outliers'])]
    lines += ['', '| model | RMSE [l/min] | max abs [l/min] | RMSE, outliers included | '
              'max abs, outliers included |', '| --- | --- | --- | --- | --- |']
    lines += [f'| {name} | {a["rmse_lpm"]:.4g} | {a["max_abs_lpm"]:.4g} | {b["rmse_lpm"]:.4g} | '
              f'{b["max_abs_lpm"]:.4g} |' for name, a, b in rows]
    lines += ['', f'Out of sample (cross-validated), over the {over["n"]} {over["what"]} the '
              f'fit used that are not in an outlier; the second pair of figures is over all '
              f'{over["n_with_outliers"]}, the isolated outliers listed below included.', '']
    lines += _bins_lines(summary)
    missed = summary['missed_regions']
    if not missed:
        return lines + ['No region of the operating space or of time where the final model '
                        'misses by more than the outlier limit on several neighbouring rows.', '']
    lines += [f'**The final model misses {len(missed)} region(s)**: outliers that cluster in '
              'the operating space or in time are structure, not bad rows; they stayed in the '
              'fits, and no candidate explained them. The largest (rows times mean miss):', '',
              '| kind | rows | direction | dp [MPa] | n [rpm] | time [s] | mean miss [l/min] |',
              '| --- | --- | --- | --- | --- | --- | --- |']
    for r in missed[:REGIONS_SHOWN]:
        time = r.get('time_s')
        lines.append(f'| {r["kind"]} | {r["rows"]} | {r["direction"]} | {r["dp_mpa"][0]:.4g} '
                     f'to {r["dp_mpa"][1]:.4g} | {r["speed_rpm"][0]:.4g} to '
                     f'{r["speed_rpm"][1]:.4g} | '
                     + (f'{time[0]:.4g} to {time[1]:.4g}' if time else '-')
                     + f' | {r["mean_residual_lpm"]:+.4g} |')
    return lines + ['', 'See `residual_map.png`: where the map stays coloured after the '
                    'effects, the model lacks something.', '']


def _bins_lines(summary: dict[str, Any]) -> list[str]:
    """Give a time series' errors over the rows the fit reads (bins' means) beside the samples'."""
    bins = summary.get('error_over_bins')
    if bins is None:
        return []
    b, a = bins['error_before'], bins['error_after']
    before, after = summary['error_before'], summary['error_after']
    worse = []
    if after['rmse_lpm'] >= before['rmse_lpm'] and summary['effects']:
        worse = [f'**Over every sample the effects found do not lower the error** '
                 f'({before["rmse_lpm"]:.4g} -> {after["rmse_lpm"]:.4g} l/min, max '
                 f'{before["max_abs_lpm"]:.4g} -> {after["max_abs_lpm"]:.4g}): they were '
                 "chosen over the rows (the bins' means), where they cut it; at single "
                 'samples, which reach beyond the means, they miss by more than they gain '
                 '(the map below shows where).', '']
    ratio = after['rmse_lpm'] / max(a['rmse_lpm'], 1e-300)
    return worse + [
        f'The fit reads the samples as {bins["n_with_outliers"]} rows, each the mean over a '
        f'short bin ({summary["bin_size"]} sample steps); over the {bins["n"]} rows that are '
        f'not outliers the same errors are {b["rmse_lpm"]:.4g} -> {a["rmse_lpm"]:.4g} l/min '
        f'(max {b["max_abs_lpm"]:.4g} -> {a["max_abs_lpm"]:.4g}; `error_over_bins`). A '
        "row's mean averages out the sensors' noise and the fast motion within its bin, "
        f'which the samples keep: the figures over every sample are {ratio:.3g} times those '
        'over the rows after the effects.', '']


REGIONS_SHOWN = 8
"""Most regions the report's table lists (calibration.json lists them all)."""


__all__ = ['PROFILE_BINS', 'REGIONS_SHOWN', 'SCATTER_MAX', 'coverage_section',
           'measured_frame', 'plot_residual_map']
