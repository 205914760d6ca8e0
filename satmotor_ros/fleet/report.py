# SPDX-License-Identifier: Apache-2.0
"""Write ``fleet.json``, ``fleet.md`` and the plots, each whole (temporary name, then rename)."""

from __future__ import annotations

from datetime import datetime, timezone
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.cli._output import png_metadata
from satmotor_ros.fleet.config import FLEET_PLOT, PLOTS, REPORT_JSON, REPORT_MD
from satmotor_ros.fleet.health import RATIO
from satmotor_ros.fleet.summary import BY_MONITOR, MIN_TREND_POINTS, MIXED


def _replace(path: Path, text: str) -> None:
    temporary = path.with_name(f'.{path.name}.partial-{os.getpid()}')
    temporary.write_text(text, encoding='utf-8')
    os.replace(temporary, path)


def _digest(text: bytes) -> str:
    import hashlib
    return hashlib.blake2b(text, digest_size=16).hexdigest()


def not_ours(out: Path, motors: list[str]) -> list[str]:
    """
    Return the report files in `out` a fleet run did not write (never replaced, --force or not).

    fleet.json and fleet.md are ours when their content is what the last report wrote (its
    digest in DIR's marker; a marker from before the digests takes them at its word), a plot
    when its PNG says ``satmotor fleet`` wrote it.

    Parameters
    ----------
    out : pathlib.Path
        DIR, [-]
    motors : list of str
        The motors whose plots this run draws, [-]

    Returns
    -------
    list of str
        Their paths relative to `out`; empty when every one may be replaced.

    """
    from satmotor_ros.cli._output import MARKER, png_by
    from satmotor_ros.fleet.resume import read_marker
    marker = read_marker(out / MARKER) or {}
    written = marker.get('report') if marker.get('command') == 'fleet' else {}
    found = []
    for name in (REPORT_JSON, REPORT_MD):
        path = out / name
        if path.is_symlink() or path.exists() and (
                not path.is_file() or written is not None
                and (written or {}).get(name) != _digest(path.read_bytes())):
            found.append(name)
    for name in [*motors, FLEET_PLOT]:
        path = out / PLOTS / f'{name}.png'
        if (path.exists() or path.is_symlink()) and not png_by('fleet')(path):
            found.append(f'{PLOTS}/{name}.png')
    return found


def write_report(out: Path, motors: list[dict[str, Any]], header: dict[str, Any]) -> None:
    """
    Write the fleet's report into `out`.

    Parameters
    ----------
    out : pathlib.Path
        DIR, [-]
    motors : list of dict
        The motors' entries, ranked, [-]
    header : dict
        Run facts for the report's head (root, when, counts, cluster), [-]

    """
    (out / PLOTS).mkdir(parents=True, exist_ok=True)
    _drop_plots(out, {m['motor'] for m in motors})
    for motor in motors:
        plot_motor(out / PLOTS / f"{motor['motor']}.png", motor)
    plot_fleet(out / PLOTS / f'{FLEET_PLOT}.png', motors)
    texts = {REPORT_JSON: json.dumps({**header, 'motors': motors}, indent=1) + '\n',
             REPORT_MD: markdown(motors, header)}
    for name, text in texts.items():
        _replace(out / name, text)
    from satmotor_ros.cli._output import MARKER  # the report's digests: what is ours
    _replace(out / MARKER, json.dumps({'command': 'fleet', 'report': {
        name: _digest(text.encode('utf-8')) for name, text in texts.items()}}) + '\n')


def _drop_plots(out: Path, motors: set[str]) -> None:
    """Remove the plots the last report drew of motors this one has not (gone, renamed)."""
    from satmotor_ros.cli._output import png_by
    from satmotor_ros.fleet.resume import read_marker
    earlier = (read_marker(out / REPORT_JSON) or {}).get('motors')
    for entry in earlier if isinstance(earlier, list) else ():
        name = entry.get('motor') if isinstance(entry, dict) else None
        if isinstance(name, str) and name not in motors and '/' not in name \
                and name.lower() != FLEET_PLOT and png_by('fleet')(out / PLOTS / f'{name}.png'):
            (out / PLOTS / f'{name}.png').unlink(missing_ok=True)


def _days(value: float | None) -> str:
    return 'not drifting to it' if value is None else f'{value:.1f}'


def trend_text(motor: dict[str, Any]) -> str:
    """Return a motor's trend per day for fleet.md, or why it has none."""
    value = motor.get('trend_per_day')
    if value is not None:
        return f'{value:+.4f}'
    n = len(motor.get('leakage_factor') or [])
    if n < MIN_TREND_POINTS:
        return f'n/a ({n} recording(s) with a figure, fewer than {MIN_TREND_POINTS})'
    return (f'n/a (fewer than {MIN_TREND_POINTS} recordings since the last step, or all '
            'at one time)')


def markdown(motors: list[dict[str, Any]], header: dict[str, Any]) -> str:
    """
    Render fleet.md: the ranking, then each motor's figures, alarms and refusals.

    Parameters
    ----------
    motors : list of dict
        The motors' entries, ranked, [-]
    header : dict
        Run facts, [-]

    Returns
    -------
    str
        The Markdown text.

    """
    lines = [f"# Fleet report: {header['root']}", '',
             f"{header['recordings']} recordings of {len(motors)} motors; "
             f"{header['refused']} refused; {header['ran']} processed in this run, "
             f"{header['reused']} already done. Written {header['written']}.", '',
             f"Leakage factor: measured volumetric losses over the motor's baseline "
             f"(estimator {header['estimator']}); limit {header['limit']:g}. Motors ranked "
             'soonest to the limit first.', '',
             '![fleet](plots/fleet.png)', '',
             '| rank | motor | recordings | refused | last leakage factor [95 % interval] '
             '| trend per day | days to limit | alarms |',
             '| --- | --- | --- | --- | --- | --- | --- | --- |']
    for i, m in enumerate(motors, 1):
        last = m['leakage_factor'][-1] if m['leakage_factor'] else None
        shown = (f"{last['value']:.3f} [{last['ci95'][0]:.3f}, {last['ci95'][1]:.3f}]"
                 if last else 'none')
        lines.append(f"| {i} | {m['motor']} | {m['recordings']} | {len(m['refused'])} | "
                     f"{shown} | {trend_text(m)} | {_days(m['days_to_limit'])} | "
                     f"{len(m['alarms'])} |")
    for m in motors:
        lines += ['', f"## {m['motor']}", '',
                  f"Liquid {m['liquid'] or 'as each recording records it'}; baseline: "
                  f"{m['baseline']}; recording times from: {', '.join(m['time_sources'])}.", '',
                  f"Estimator: {_estimator(m)}; trend per day on {m.get('trend_clock', '')}.",
                  '',
                  f"![{m['motor']}](plots/{m['motor']}.png)", '']
        lines.append('Alarms:' if m['alarms'] else 'No alarm.')
        lines += [f"- {a['date']} **{a['kind']}**: {a['what']}" for a in m['alarms']]
        if m['refused']:
            lines += ['', 'Refused recordings (whole, not salvaged):']
            lines += [f"- `{r['path']}`: {r['reason']}" for r in m['refused']]
        if m.get('undated'):
            lines += ['', 'Warning: recordings with no time of their own (none in the data or '
                      "the path), only their file's modification time, which may be a copy's: "
                      "kept out of this motor's trend, days to the limit, alarms and ranking "
                      '(give them a date in the path, or an epoch time column):']
            lines += [f"- `{u['recording']}` (file modified {u['date']}): leakage factor "
                      f"{u['value']:.3g}" for u in m['undated']]
        if m.get('warnings'):
            lines += ['', 'Rows dropped from recordings used (as `satmotor calibrate` drops '
                      'them, and warns):']
            lines += [f"- `{w['path']}`: {w['warning']}" for w in m['warnings']]
        if m.get('monitor_refused'):
            lines += ['', "Recordings the health monitor's step refused or failed on (its state "
                      'passed on unchanged; their points are their ratios):']
            lines += [f"- `{r['path']}` ({r['status']}): {r['reason']}"
                      for r in m['monitor_refused']]
        if m['leakage_factor']:
            lines += ['', '| date | time from | recording | leakage factor | 95 % interval '
                      '| by |', '| --- | --- | --- | --- | --- | --- |']
            lines += [f"| {p['date']} | {p.get('time_source', '')} | `{p['recording']}` | "
                      f"{p['value']:.4f} | [{p['ci95'][0]:.4f}, {p['ci95'][1]:.4f}] | "
                      f'{_by(p)} |' for p in m['leakage_factor']]
    return '\n'.join(lines) + '\n'


def _by(point: dict[str, Any]) -> str:
    """Say which estimator gave a point, and why not the monitor where it gave a figure."""
    why = point.get('monitor_unused')
    return str(point.get('estimator', '')) + (f' (monitor not taken: {why})' if why else '')


def _estimator(motor: dict[str, Any]) -> str:
    """Say which estimator gave a motor's figures."""
    if motor.get('estimator') == BY_MONITOR:
        return ("the health monitor (`satmotor monitor`'s), run through the recordings in "
                'time order')
    if motor.get('estimator') == MIXED:
        return ("the health monitor's figure where it is the recording's, the ratio where not "
                '(each point says which; the table below)')
    return (f'{RATIO}: per recording, the ratio of measured to baseline losses, its interval '
            "widened by the residuals' autocorrelation")


def _pyplot() -> Any:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    return plt


def _dates(series: list[dict[str, Any]]) -> list[datetime]:
    return [datetime.fromisoformat(p['date']).astimezone(timezone.utc).replace(tzinfo=None)
            for p in series]


def _save(fig: Any, path: Path) -> None:
    temporary = path.with_name(f'.{path.name}.partial-{os.getpid()}')
    fig.savefig(temporary, dpi=80, format='png', metadata=png_metadata('fleet'))
    os.replace(temporary, path)


def plot_motor(path: Path, motor: dict[str, Any]) -> None:
    """
    Plot one motor: the leakage factor with its interval, the trend to the limit, alarms.

    Parameters
    ----------
    path : pathlib.Path
        The PNG, [-]
    motor : dict
        Its fleet.json entry, [-]

    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.2))
    try:
        series = motor['leakage_factor']
        if series:
            dates = _dates(series)
            values = np.array([p['value'] for p in series])
            lo = values - np.array([p['ci95'][0] for p in series])
            hi = np.array([p['ci95'][1] for p in series]) - values
            ax.errorbar(dates, values, yerr=[lo, hi], fmt='o-', ms=4, capsize=2,
                        label='leakage factor, 95 % interval')
            _draw_projection(ax, motor, dates, values)
        ax.axhline(motor['limit'], color='tab:red', ls='--', lw=1,
                   label=f"limit {motor['limit']:g}")
        ax.axhline(1.0, color='0.6', lw=0.8)
        for i, alarm in enumerate(motor['alarms']):
            when = datetime.fromisoformat(alarm['date']).replace(tzinfo=None)
            ax.axvline(when, color='tab:orange' if alarm['kind'] == 'change' else 'tab:red',
                       lw=1, label=f"{alarm['kind']} alarm" if i == 0 else None)
        days = motor['days_to_limit']
        title = f"{motor['motor']}: " + (
            f'{days:.1f} days to the limit' if days is not None
            else 'not drifting toward the limit')
        if motor['refused']:
            title += f", {len(motor['refused'])} recording(s) refused"
        ax.set_title(title)
        ax.set_ylabel('leakage factor (measured / baseline Q_vl) [-]')
        ax.set_xlabel('date (UTC)')
        ax.legend(loc='upper left', fontsize=8)
        fig.autofmt_xdate()
        fig.tight_layout()
        _save(fig, path)
    finally:
        plt.close(fig)


def _draw_projection(ax: Any, motor: dict[str, Any], dates: list[datetime],
                     values: np.ndarray) -> None:
    from datetime import timedelta
    trend, days = motor['trend_per_day'], motor['days_to_limit']
    if trend is None or days is None or days <= 0:
        return
    end = dates[-1] + timedelta(days=days)
    ax.plot([dates[-1], end], [values[-1], motor['limit']], ':', color='tab:red',
            label=f'trend {trend:+.3f}/day to the limit')


def plot_fleet(path: Path, motors: list[dict[str, Any]]) -> None:
    """
    Plot the fleet: every motor's leakage factor over dates, and the days to the limit.

    Parameters
    ----------
    path : pathlib.Path
        The PNG, [-]
    motors : list of dict
        The motors' entries, ranked, [-]

    """
    plt = _pyplot()
    fig, (ax, bars) = plt.subplots(1, 2, figsize=(12, 4.5),
                                   gridspec_kw={'width_ratios': [2.2, 1]})
    try:
        limit = motors[0]['limit'] if motors else 2.0
        for m in motors:
            if m['leakage_factor']:
                ax.plot(_dates(m['leakage_factor']), [p['value'] for p in m['leakage_factor']],
                        'o-', ms=3, label=m['motor'])
        ax.axhline(limit, color='tab:red', ls='--', lw=1, label=f'limit {limit:g}')
        ax.set_ylabel('leakage factor [-]')
        ax.set_xlabel('date (UTC)')
        ax.set_title('Leakage factor of every motor')
        hits = [p for m in motors for a in m['alarms'] for p in m['leakage_factor']
                if p['recording'] == a.get('recording')]
        if hits:
            ax.plot(_dates(hits), [p['value'] for p in hits], 'x', color='k', ms=9,
                    label='alarm')
        ax.legend(fontsize=7, ncol=2)
        names = [m['motor'] for m in motors][::-1]
        days = [m['days_to_limit'] or 0.0 for m in motors][::-1]
        bars.barh(names, days, color='tab:red')
        for y, m in enumerate(motors[::-1]):
            if m['days_to_limit'] is None:
                last = 'no figure' if m['last'] is None else f"now {m['last']:.2f}"
                bars.text(0.0, y, f' not drifting toward it ({last})', va='center', fontsize=8)
            elif m['alarms']:
                bars.text(m['days_to_limit'], y, f" {len(m['alarms'])} alarm(s)",
                          va='center', fontsize=8)
        bars.set_xlabel('days to the limit from the last recording')
        bars.set_title('Ranking, soonest first (top)')
        fig.autofmt_xdate()
        fig.tight_layout()
        _save(fig, path)
    finally:
        plt.close(fig)


__all__ = ['not_ours', 'PLOTS', 'markdown', 'plot_fleet', 'plot_motor', 'trend_text',
           'write_report']
