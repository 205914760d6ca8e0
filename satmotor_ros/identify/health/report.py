# SPDX-License-Identifier: Apache-2.0
"""Write ``monitor.json``, ``health.csv``, ``report.md`` and the plots of a monitor run."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.identify.health.records import (Estimate, HealthPoint, hours_json, hours_note,
                                                  unresolved)
from satmotor_ros.identify.health.run import MonitorRun
from satmotor_ros.identify.plot_tools import portable
from satmotor_ros.identify.report import pyplot
from satmotor_ros.model.units import MPA, RPM

FILES = ('monitor.json', 'health.csv', 'report.md', 'leakage_factor.png', 'detector.png')
"""What :func:`write_monitor` puts into the output directory."""

CSV_COLUMNS = ('time [s]', 'operating_time [h]', 'leakage_factor [-]', 'leakage_factor_low [-]',
               'leakage_factor_high [-]', 'bin_leakage_factor [-]', 'trend [-]',
               'trend_low [-]', 'trend_high [-]', 'detector_statistic [-]',
               'volumetric_efficiency [-]', 'learning [-]')
"""health.csv's header: one row per bin, the windowed factor with its 95 % interval (nan
before the first learning ends), learning 1 while the monitor learns."""


def _num(x: float, digits: int = 6) -> float | None:
    return float(f'{x:.{digits}g}') if math.isfinite(x) else None


def summary(run: MonitorRun) -> dict[str, Any]:
    """
    Build the monitor.json object (DESIGN.md, "Health output").

    Parameters
    ----------
    run : MonitorRun
        The run, [-]

    Returns
    -------
    dict
        ``alarms``, ``leakage_factor`` (time series with intervals), ``trend_per_hour``,
        ``hours_to_limit`` (a number: :data:`~.records.NEVER_HOURS` when the trend does
        not rise towards the limit; null only before there is a trend), ``n_samples``,
        ``n_skipped`` first, then the figures now, the detector and the recordings; times
        are seconds from the first sample, ``t0_s`` that sample on the data's own time column
        (``t0_epoch`` too for an epoch clock).

    """
    snap = run.snapshot
    to_limit = snap.hours_to_limit
    out: dict[str, Any] = {
        'alarms': [{**a.as_dict(), 'acknowledged': n < snap.acknowledged}
                   for n, a in enumerate(snap.alarms)],
        'leakage_factor': [{'time_s': _num(p.time_s, 9), **p.leakage_factor.as_dict(),
                            'learning': p.learning} for p in run.points],
        'trend_per_hour': _num(snap.trend_per_hour.value),
        'trend_per_hour_ci95': snap.trend_per_hour.as_dict()['ci95'],
        'hours_to_limit': hours_json(to_limit.value),
        'hours_to_limit_ci95': [hours_json(to_limit.low), hours_json(to_limit.high)],
        'hours_to_limit_note': hours_note(to_limit.value, snap.hours_to_limit_why),
        'n_samples': snap.n_samples, 'n_skipped': snap.n_skipped, 'skipped': snap.skipped,
        'n_used': snap.n_used,
        'timing': {k: _num(v) for k, v in snap.timing.items()},
        'limit_leakage_factor': _num(snap.limit_leakage_factor),
        'leakage_factor_now': snap.leakage_factor.as_dict(),
        'trend_now': snap.trend.as_dict(),
        'volumetric_efficiency_now': _num(snap.volumetric_efficiency),
        'volumetric_efficiency_reference': snap.volumetric_efficiency_reference.as_dict(),
        'reference_point': {'speed_rpm': _num(snap.reference_speed / RPM),
                            'dp_mpa': _num(snap.reference_dp / MPA)},
        'operating_hours': _num(snap.operating_hours),
        'recording_hours': _num(snap.recording_hours),
        'detector': {'threshold': _num(snap.threshold), 'statistic': _num(snap.statistic),
                     'learning': snap.learning,
                     'false_alarm_hours': run.settings.false_alarm_hours,
                     'change_fraction': run.settings.change_fraction,
                     'noise': {k: _num(v) for k, v in snap.noise.items()}},
        'baseline': portable(run.baseline),
        'recordings': [{'data': portable(r.source), 'samples': r.samples,
                        'start_s': _num(r.start_s, 9), 'end_s': _num(r.end_s, 9),
                        'shifted_s': _num(r.shifted_s, 9)} for r in run.recordings],
        'leakage_factor_identifiable': not unresolved(snap.leakage_factor,
                                                      run.settings.change_fraction),
        'notes': list(run.notes), 'flags': _flags(run), 't0_s': _num(run.t0_s, 12)}
    if run.t0_epoch is not None:
        out['t0_epoch'] = run.t0_epoch
    return out


def _flags(run: MonitorRun) -> list[str]:
    """Say what makes the figures suspect: a factor below 0 is no loss of this model."""
    factor = run.snapshot.leakage_factor
    flags = []
    if math.isfinite(factor.low) and factor.low < 0.0:
        flags.append(f"the leakage factor's interval reaches below 0 ({factor.low:.3g}): "
                     "the baseline's losses do not describe these data (check --motor, "
                     '--displacement, the units and the flow sign)')
    why = unresolved(factor, run.settings.change_fraction)
    if why:
        flags.append(why)
    return flags


def write_csv(points: tuple[HealthPoint, ...], path: Path) -> None:
    """Write health.csv: one row per bin, units in the header's brackets."""
    rows = np.array([[p.time_s, p.operating_hours, p.leakage_factor.value,
                      p.leakage_factor.low, p.leakage_factor.high, p.bin_factor,
                      p.trend.value, p.trend.low, p.trend.high, p.statistic,
                      p.volumetric_efficiency, float(p.learning)]
                     for p in points]).reshape(-1, len(CSV_COLUMNS))
    np.savetxt(path, rows, delimiter=',', header=','.join(CSV_COLUMNS), comments='',
               fmt='%.9g')


def _plot_leakage(run: MonitorRun, path: Path) -> None:
    """Plot the factor with its band, the bins, the trend and its projection, the alarms."""
    plt = pyplot()
    points, snap = run.points, run.snapshot
    fig, ax = plt.subplots(figsize=(10, 5))
    if points:
        hours = np.array([p.time_s for p in points]) / 3600.0
        value = np.array([p.leakage_factor.value for p in points])
        low = np.array([p.leakage_factor.low for p in points])
        high = np.array([p.leakage_factor.high for p in points])
        ax.plot(hours, [p.bin_factor for p in points], '.', color='0.75', ms=2,
                label=f"each {run.snapshot.timing.get('bin_s', run.settings.bin_s):.0f} s bin")
        ax.fill_between(hours, low, high, color='C0', alpha=0.25, lw=0,
                        label='95 % interval')
        ax.plot(hours, value, color='C0', lw=1.2,
                label=f'leakage factor over {run.settings.window_s:.0f} s')
        trend = np.array([p.trend.value for p in points])
        ax.plot(hours, trend, color='C2', lw=1.5, label='trend (level now, as it ran)')
        _projection(ax, run, hours[-1])
        finite = np.concatenate([value[np.isfinite(value)], trend[np.isfinite(trend)]])
        top = max(float(np.percentile(finite, 99.5)) if finite.size else 1.0,
                  snap.limit_leakage_factor) * 1.15
        ax.set_ylim(0.0, top)
    limit = snap.limit_leakage_factor
    if math.isfinite(limit):
        ax.axhline(limit, color='C3', ls='--', lw=1, label=f'limit {limit:.3g}')
    for number, alarm in enumerate(snap.alarms, start=1):
        color = 'C3' if alarm.kind == 'limit' else 'C1'
        ax.axvline(alarm.time_s / 3600.0, color=color, lw=1)
        # numbered: the table of report.md says what each was; labels would overlap here
        height = 0.98 - 0.06 * (number % 3)
        ax.annotate(f'{number} {alarm.kind}', (alarm.time_s / 3600.0, height),
                    xycoords=('data', 'axes fraction'), fontsize=8, color=color, ha='right',
                    va='top')
    ax.set_xlabel('time [h]')
    ax.set_ylabel('leakage factor: measured / baseline volumetric loss [-]')
    ax.set_title(f'Leakage factor against {portable(run.baseline)}')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc='lower right')  # the alarms' numbers are at the top
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _projection(ax: Any, run: MonitorRun, now_h: float) -> None:
    """Draw the trend's line on to the limit, and the interval of the hours to it."""
    snap = run.snapshot
    to_limit, level, slope = snap.hours_to_limit, snap.trend.value, snap.trend_per_hour.value
    if not (math.isfinite(to_limit.value) and math.isfinite(level) and to_limit.value > 0):
        return
    ratio = snap.recording_hours / snap.operating_hours if snap.operating_hours > 0 else 1.0
    end = now_h + to_limit.value
    ax.plot([now_h, end], [level, level + slope * to_limit.value / ratio], color='C2', ls=':',
            lw=1.5, label=f'projection: limit in {to_limit.value:.3g} h')
    low, high = to_limit.low, to_limit.high
    if math.isfinite(low):
        right = now_h + (high if math.isfinite(high) else 2.0 * to_limit.value)
        ax.axvspan(now_h + low, right, color='C3', alpha=0.08,
                   label='95 % interval of the crossing')


def _plot_detector(run: MonitorRun, path: Path) -> None:
    """Plot the change detector's statistic over its threshold, and the alarms."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(10, 3.2))
    if run.points:
        hours = np.array([p.time_s for p in run.points]) / 3600.0
        ax.plot(hours, [p.statistic for p in run.points], color='C1', lw=1,
                label='CUSUM statistic / threshold')
    ax.axhline(1.0, color='C3', ls='--', lw=1,
               label=f'threshold: a false alarm per {run.settings.false_alarm_hours:g} h')
    for alarm in run.snapshot.alarms:
        if alarm.kind == 'change':
            ax.axvline(alarm.time_s / 3600.0, color='C3', lw=1)
    ax.set_ylim(0.0, 1.3)
    ax.set_xlabel('time [h]')
    ax.set_ylabel('statistic [-]')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc='upper left')
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _estimate(e: Estimate, digits: int = 4) -> str:
    if not math.isfinite(e.value):
        return 'n/a' if math.isnan(e.value) else 'never (no rise towards the limit)'
    text = f'{e.value:.{digits}g}'
    if math.isfinite(e.low) or math.isfinite(e.high):
        text += f' (95 %: {e.low:.{digits}g} to {e.high:.{digits}g})'
    return text


def _report(run: MonitorRun, out: dict[str, Any]) -> str:
    snap = run.snapshot
    lines = [f'# Motor health against {portable(run.baseline)}', '',
             f'{snap.n_samples} samples in {len(run.recordings)} recording(s), '
             f'{snap.operating_hours:.3g} h of operation over {snap.recording_hours:.3g} h; '
             f'{snap.n_skipped} samples skipped (' + ', '.join(
                 f'{v} {k.replace("_", " ")}' for k, v in snap.skipped.items() if v) + ').', '']
    lines += [f'- {note}' for note in run.notes]
    lines += ['## Now', '', '| figure | value |', '| --- | --- |',
              f'| leakage factor, last {run.settings.window_s:.0f} s | '
              f'{_estimate(snap.leakage_factor)} |',
              f'| trend level | {_estimate(snap.trend)} |',
              f'| trend per hour of operation | {_estimate(snap.trend_per_hour)} |',
              f'| limit (leakage factor) | {snap.limit_leakage_factor:.4g} |',
              f'| hours to the limit | {_estimate(snap.hours_to_limit)} |',
              f'| volumetric efficiency now | {snap.volumetric_efficiency:.4g} |',
              f'| volumetric efficiency at the reference point '
              f'({snap.reference_speed / RPM:.4g} rpm, {snap.reference_dp / MPA:.4g} MPa) | '
              f'{_estimate(snap.volumetric_efficiency_reference)} |', '',
              'The leakage factor is the measured volumetric loss Q - q_t n over the '
              "baseline's, by weighted least squares over each bin (a sample's weight from its "
              "own noise, which grows with the flow's rate of change); 1 is the baseline.", '',
              '![leakage factor](leakage_factor.png)', '', '## Alarms', '']
    if snap.alarms:
        lines += ['| # | time [h] | kind | what | statistic | began [h] | before | after |',
                  '| --- | --- | --- | --- | --- | --- | --- | --- |']
        lines += [f'| {n} | {a.time_s / 3600:.4g} | {a.kind}'
                  f'{" (acknowledged)" if n <= snap.acknowledged else ""} | {a.what} | '
                  f'{a.statistic:.3g} | '
                  f'{a.change_s / 3600:.4g} | {a.before:.4g} | {a.after:.4g} |'
                  for n, a in enumerate(snap.alarms, start=1)]
    else:
        lines.append('None.')
    noise = snap.noise
    lines += ['', '## Change detector', '',
              f'A two-sided CUSUM of log-likelihood ratios for a change of '
              f'{100 * run.settings.change_fraction:.0f} % of the losses, on bin residuals '
              f'whitened by the noise model the data gave: variance inflation '
              f"{noise['bin_inflation']:.3g} over independent samples, lag-one "
              f"autocorrelation {noise['bin_autocorrelation']:.3g}. Its threshold "
              f'{snap.threshold:.3g} gives one false alarm per '
              f"{run.settings.false_alarm_hours:g} h of operation (Siegmund's approximation).",
              '', '![detector](detector.png)', '',
              '## monitor.json (without the time series)', '', '```json',
              json.dumps({k: v for k, v in out.items() if k != 'leakage_factor'}, indent=2),
              '```', '']
    return '\n'.join(lines)


def write_monitor(run: MonitorRun, out: Path) -> dict[str, Any]:
    """
    Write :data:`FILES` into `out`.

    Parameters
    ----------
    run : MonitorRun
        The run, [-]
    out : pathlib.Path
        Output directory (exists; the command's temporary one), [-]

    Returns
    -------
    dict
        The monitor.json object.

    """
    content = summary(run)
    (out / 'monitor.json').write_text(json.dumps(content, indent=1) + '\n', encoding='utf-8')
    write_csv(run.points, out / 'health.csv')
    (out / 'report.md').write_text(_report(run, content), encoding='utf-8')
    _plot_leakage(run, out / 'leakage_factor.png')
    _plot_detector(run, out / 'detector.png')
    return content


__all__ = ['CSV_COLUMNS', 'FILES', 'summary', 'write_csv', 'write_monitor']
