# SPDX-License-Identifier: Apache-2.0
"""
The fleet's view: per motor the leakage factor over dates, its trend, alarms, ranking.

Where the motor's recordings are time series, its one health monitor
(:mod:`~satmotor_ros.fleet.chain`, ``satmotor monitor``'s estimator run over them in time
order) gives the leakage factor after each recording where that figure is the recording's
(:func:`monitor_unfit`: fast enough, enough samples, an interval), and the trend, the hours
to the limit and the alarms when its figures are taken throughout. A recording whose monitor
figure is not valid (a steady-point table, which the monitor cannot watch; a recording the
monitor is still learning on) gets its ratio (:mod:`~satmotor_ros.fleet.health`), and each
point says which (``estimator``). For ratios: the trend is a
least-squares line through the recordings since the motor's last change
alarm (a step is not wear); the days to the limit are where that line meets it, counted
from the last recording. A change is a step between consecutive recordings larger than
both their intervals and the motor's own day-to-day scatter allow
(:data:`CHANGE_SIGMAS`), with the wear trend taken out.

Trends are per calendar day. A recording's time is calendar time whichever way it was found
(a bag's start, an epoch ``time`` column, a date in its path); but the monitor's own clock is
calendar time only when the samples carry epoch times: recordings whose clock starts again
(a ``time`` column from 0) are laid end to end on it, a few seconds apart, so its trend is
per hour *recorded*. For such a motor the trend per day and the days to the limit are the
line through the monitor's figure after each recording against the recordings' times
(as above, since the last step in those figures), and ``trend_clock`` says which clock each
motor's trend is on.
"""

from __future__ import annotations

from datetime import datetime, timezone
from typing import Any

import numpy as np

DAY = 86400.0
"""Seconds in a day, [s]."""

LIMIT = 2.0
"""Default limit of the leakage factor, as the health monitor's ``limit_leakage_factor``."""

CHANGE_SIGMAS = 4.0
"""A step between consecutive recordings this many standard deviations out is a change."""

MIN_STEP = 0.05
"""Smallest step of the leakage factor called a change, whatever the noise, [-]."""

MIN_TREND_POINTS = 3
"""Fewest recordings a trend is fitted on, [-]."""

EPOCH_S = 9.0e8
"""A monitor clock beyond this is epoch seconds (as the fleet's discovery reads a time column)."""

BY_MONITOR, BY_RATIO, MIXED = 'monitor', 'ratio', 'monitor+ratio'
"""Which estimator gave a figure (each point's ``estimator``) and a motor's (``estimator``)."""

LEARNING = 'the monitor gave no interval (still learning)'
"""Why a recording's monitor figure is not taken while the monitor learns."""

MONITOR_MIN_RATE = 0.5
"""Fewest samples a second a recording's monitor figure is taken at, [1/s]: the monitor's
10 s bins hold 5 samples; a steady-point table (a point a minute) gets its ratio."""

MONITOR_MIN_SAMPLES = 150
"""Fewest usable samples a recording's monitor figure is taken on, [-]: the monitor's 300 s
window at :data:`MONITOR_MIN_RATE`, so the figure is this recording's."""

RECORDING_TIMES = "calendar: the recordings' times"
MONITOR_EPOCH = "calendar: the monitor's epoch clock"
"""What a motor's trend per day is reckoned on (``trend_clock``)."""


def motor_view(motor: str, liquid: str, markers: list[dict[str, Any]],
               baseline: dict[str, Any] | None, limit: float = LIMIT,
               steps: list[dict[str, Any]] | None = None) -> dict[str, Any]:
    """
    Build one motor's entry of fleet.json.

    Parameters
    ----------
    motor : str
        Motor id, [-]
    liquid : str
        Its liquid ('' when each recording settles its own), [-]
    markers : list of dict
        Its recordings' done-markers in time order, [-]
    baseline : dict or None
        Its baseline (which recording, or the motor file), [-]
    limit : float
        Limit of the leakage factor, [-]
    steps : list of dict, optional
        Its monitor chain's step markers in time order, [-]

    Returns
    -------
    dict
        The DESIGN.md "Fleet output" entry, plus ``baseline``, ``limit``, ``time_sources``,
        ``last`` (the latest leakage factor), ``estimator`` (:data:`BY_MONITOR`,
        :data:`BY_RATIO` or :data:`MIXED`) and ``trend_clock`` (:data:`RECORDING_TIMES` or
        :data:`MONITOR_EPOCH`); each point of ``leakage_factor`` says its recording's
        ``time_source``, its ``estimator`` and, for a ratio where the monitor gave a figure
        not taken, why (``monitor_unused``, :func:`monitor_unfit`); ``monitor_refused``
        lists the recordings (not refused whole) whose monitor step was refused or failed,
        with the one-line reason; ``undated`` the recordings timed only by their file's
        modification time where others of the motor have a time of their own (kept out of
        its time line: :func:`_split_undated`); ``warnings`` the rows a used recording's
        reader dropped (``path``, ``warning``: what ``satmotor calibrate`` warns of).

    """
    markers, undated = _split_undated(markers)
    apart = {m['recording'] for m in undated}
    view = _motor_view(motor, liquid, markers, baseline, limit,
                       [s for s in steps or () if s['recording'] not in apart])
    view['recordings'] += len(undated)
    view['undated'] = [{**_ratio_point(m), 'time': m.get('time')} for m in undated]
    refused = {r['path'] for r in view['refused']}  # a recording refused whole says it there
    view['monitor_refused'] = [{'path': s['recording'], 'reason': s.get('reason', ''),
                                'status': s.get('status')} for s in steps or ()
                               if s.get('status') in ('refused', 'failed')
                               and s['recording'] not in refused]
    return view


def _split_undated(markers: list[dict[str, Any]]) \
        -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """
    Split off the used recordings timed only by their file's mtime, where others are not.

    A file's modification time is when it was copied or touched as often as when it was
    recorded: among recordings timed by their data or their path, one placed by it lands
    days or months off (the day of the copy) and would bend the trend, the days to the
    limit and the ranking. It is kept out of the motor's time line and listed apart, its
    factor with it. A motor whose recordings all have only their mtime keeps them all.
    """
    from satmotor_ros.fleet.discover import MTIME
    timed = any(m.get('time_source') != MTIME for m in markers if m.get('status') == 'done')
    if not timed:
        return markers, []
    apart = [m for m in markers if m.get('status') == 'done' and m.get('result')
             and m.get('time_source') == MTIME]
    return [m for m in markers if m not in apart], apart


def _motor_view(motor: str, liquid: str, markers: list[dict[str, Any]],
                baseline: dict[str, Any] | None, limit: float,
                steps: list[dict[str, Any]]) -> dict[str, Any]:
    points = [m for m in markers if m.get('status') == 'done' and m.get('result')]
    watched = [s for s in steps if s.get('status') == 'done' and s.get('result')]
    if any(not monitor_unfit(s) for s in watched):
        return _monitored(motor, liquid, markers, watched, baseline, limit)
    unfit = {s['recording']: monitor_unfit(s) for s in watched}
    series = [_ratio_point(m, unfit.get(m['recording'], '')) for m in points]
    times = np.array([m['time'] for m in points], dtype=float)
    alarms, trend, days = _ratio_alarms_and_trend(series, times, limit)
    return _view(motor, liquid, markers, series, trend, days, alarms, baseline, limit, BY_RATIO,
                 RECORDING_TIMES)


def monitor_unfit(step: dict[str, Any]) -> str:
    """
    Say why the monitor's figure after a recording is not that recording's; '' when it is.

    The figure is the recording's when the recording's samples come at
    :data:`MONITOR_MIN_RATE` or faster on average (the monitor's 10 s bins and 5 min window
    are built for time series: on a steady-point table, a point a minute, its factor is not
    the calibrated one), the recording gave it :data:`MONITOR_MIN_SAMPLES` usable samples
    (else the figure is mostly the recordings' before it, still in its window), and the
    figure has a value and an interval (the monitor past learning).

    Parameters
    ----------
    step : dict
        A monitor chain step's marker (:func:`~satmotor_ros.fleet.chain.monitor_step`), [-]

    Returns
    -------
    str
        '' when the figure is valid for its recording, else one line saying why not.

    """
    result = step.get('result') or {}
    if step.get('status') != 'done' or not result:
        return f"the monitor's step is {step.get('status', 'missing')}"
    n = int(result.get('recording_samples') or 0)  # this recording's, not the monitor's
    skipped = int(result.get('recording_skipped') or 0)
    span = result.get('span_s') or [0.0, 0.0]
    seconds = float(span[1]) - float(span[0])
    rate = (n - 1) / seconds if seconds > 0 and n > 1 else 0.0
    if rate < MONITOR_MIN_RATE:
        return (f'{rate:.3g} samples/s, below the {MONITOR_MIN_RATE:g} the monitor is built '
                'for')
    if n - skipped < MONITOR_MIN_SAMPLES:
        return (f'{n - skipped} usable samples, fewer than {MONITOR_MIN_SAMPLES} (its '
                "window is still the recordings' before)")
    return '' if _interval(step) else LEARNING


def _ratio_point(marker: dict[str, Any], unfit: str = '') -> dict[str, Any]:
    """Return a recording's ratio figure as a point of ``leakage_factor``."""
    point = {'date': marker['date'], 'value': marker['result']['leakage_factor'],
             'ci95': marker['result']['ci95'], 'recording': marker['recording'],
             'time_source': marker.get('time_source', ''), 'estimator': BY_RATIO}
    if unfit:
        point['monitor_unused'] = unfit
    return point


def _ratio_alarms_and_trend(series: list[dict[str, Any]], times: np.ndarray,
                            limit: float) -> tuple[list[dict[str, Any]], float | None,
                                                   float | None]:
    """Return the change and limit alarms of a series, its trend and days to the limit."""
    values = np.array([s['value'] for s in series], dtype=float)
    half = np.array([(s['ci95'][1] - s['ci95'][0]) / 2.0 for s in series], dtype=float)
    alarms, start = _changes(series, times, values, half)
    crossed = next((s for s in series if s['value'] >= limit), None)
    if crossed is not None:
        alarms.append({'date': crossed['date'], 'kind': 'limit',
                       'what': f"leakage factor {crossed['value']:.3g} reached the limit "
                               f'{limit:g}', 'recording': crossed['recording']})
    alarms.sort(key=lambda a: a['date'])
    trend, days = _trend(times[start:], values[start:], limit)
    return alarms, trend, days


def _view(motor: str, liquid: str, markers: list[dict[str, Any]],
          series: list[dict[str, Any]], trend: float | None, days: float | None,
          alarms: list[dict[str, Any]], baseline: dict[str, Any] | None, limit: float,
          estimator: str, clock: str) -> dict[str, Any]:
    refused = [{'path': m['recording'], 'reason': m.get('reason', ''),
                'status': m.get('status')} for m in markers if m.get('status') != 'done']
    sources = sorted({m.get('time_source', '') for m in markers})
    times = [float(m['time']) for m in markers
             if m.get('status') == 'done' and isinstance(m.get('time'), (int, float))]
    warned = [{'path': m['recording'], 'warning': w} for m in markers
              if m.get('status') == 'done' for w in m.get('warnings') or ()]
    return {'motor': motor, 'liquid': liquid, 'recordings': len(markers), 'refused': refused,
            'warnings': warned, 'leakage_factor': series, 'trend_per_day': trend,
            'days_to_limit': days,
            'alarms': alarms, 'limit': limit, 'last': series[-1]['value'] if series else None,
            'baseline': _baseline_line(baseline), 'time_sources': sources,
            'estimator': estimator, 'trend_clock': clock,
            'last_time': max(times) if times else None}


def _monitored(motor: str, liquid: str, markers: list[dict[str, Any]],
               watched: list[dict[str, Any]], baseline: dict[str, Any] | None,
               limit: float) -> dict[str, Any]:
    """
    Build the view from the motor's one monitor where its figures are valid, else the ratios.

    A recording whose monitor figure is unfit (:func:`monitor_unfit`) gets its ratio. The
    monitor's own trend and days are the motor's only when every point is the monitor's on
    an epoch clock; else the line through the points against the recordings' times.
    """
    dates = {m['recording']: m['date'] for m in markers}
    times = {m['recording']: m for m in markers}
    steps = {s['recording']: s for s in watched}
    ratios = {m['recording']: m for m in markers if m.get('status') == 'done' and m.get('result')}
    order = [m['recording'] for m in markers]
    order += [s['recording'] for s in watched if s['recording'] not in set(order)]
    series = []
    for recording in order:
        step = steps.get(recording)
        unfit = monitor_unfit(step) if step else ''
        if step is not None and not unfit:
            series.append({'date': dates.get(recording, ''), 'recording': recording,
                           'time_source': times.get(recording, {}).get('time_source', ''),
                           **step['result']['leakage_factor'], 'estimator': BY_MONITOR})
        elif recording in ratios:
            series.append(_ratio_point(ratios[recording], unfit))
    fit = {p['recording'] for p in series if p['estimator'] == BY_MONITOR}
    last = watched[-1]['result']
    alarms = []
    for alarm in last.get('alarms', []):  # the snapshot's: each with its final name
        recording = raised_in(alarm, watched)
        if recording not in fit:  # raised on figures the fleet does not take
            continue
        alarms.append({'date': dates.get(recording, ''), 'kind': alarm.get('kind', 'change'),
                       'what': f"{_named(alarm.get('what', 'unexplained'))} (in {recording})",
                       'recording': recording, 'source': 'monitor'})
    alarms = _on_the_calendar(alarms, series, times, limit)
    holds = _monitor_trend_holds(series, watched)
    if holds and last.get('trend_per_day') is not None:
        hours = last.get('hours_to_limit')  # calendar hours; the trend per calendar day
        return _view(motor, liquid, markers, series, last.get('trend_per_day'),
                     None if hours is None else hours / 24.0, alarms, baseline, limit,
                     BY_MONITOR, MONITOR_EPOCH)
    # no trend of the monitor's (each day's jump a change to it): the calendar line below
    if not holds and len(fit) < len(series):  # the ratios' steps and limit where they hold
        timed = [p for p in series if times.get(p['recording'], {}).get('time') is not None]
        ratio_alarms, _, _ = _ratio_alarms_and_trend(
            timed, np.array([float(times[p['recording']]['time']) for p in timed]), limit)
        alarms += [a for a in ratio_alarms if a['recording'] not in fit
                   and not (a['kind'] == 'limit' and any(b['kind'] == 'limit' for b in alarms))]
        alarms.sort(key=lambda a: a['date'])
    trend, days = _calendar_trend(series, times, limit)
    return _view(motor, liquid, markers, series, trend, days, alarms, baseline, limit,
                 BY_MONITOR if holds or len(fit) == len(series) else MIXED, RECORDING_TIMES)


def _on_the_calendar(alarms: list[dict[str, Any]], series: list[dict[str, Any]],
                     times: dict[str, dict[str, Any]], limit: float) -> list[dict[str, Any]]:
    """
    Keep the monitor's change alarms whose step stands out on the calendar too.

    The monitor's clock is its operating time: between two recordings a day apart it sees
    no time pass, so a day's wear is a jump to it, and its detector rightly calls a jump
    of some per cent a step (twice in eight days of 0.06 a day, relearning after each).
    On the calendar that jump is the trend. A change alarm of the monitor's is the motor's
    where the ratios' rule (:func:`_changes`) over the points against the recordings' times
    finds a change at its recording too; with fewer than three timed points there is no
    calendar to judge by, and the monitor's alarms stand.
    """
    timed = [p for p in series if times.get(p['recording'], {}).get('time') is not None]
    if len(timed) < 3:
        return alarms
    found, _, _ = _ratio_alarms_and_trend(
        timed, np.array([float(times[p['recording']]['time']) for p in timed]), limit)
    steps = {a['recording'] for a in found if a['kind'] == 'change'}
    return [a for a in alarms if a['kind'] != 'change' or a['recording'] in steps]


def _named(what: str) -> str:
    """Return a monitor alarm's name; its 'pending' said as what it waits for."""
    from satmotor_ros.identify.health import HealthSettings
    from satmotor_ros.identify.health.monitor import PENDING
    if what != PENDING:
        return what
    return ('not named yet by the monitor: it names a change once it has learned '
            f'{HealthSettings().learn_hours:g} h of operation after it, and the recordings '
            'since hold less')


def raised_in(alarm: dict[str, Any], watched: list[dict[str, Any]]) -> str:
    """
    Return the recording the monitor raised an alarm in, on one clock.

    An alarm's ``time_s`` is on the monitor's own clock, seconds from its first sample; a
    step's ``span_s`` is its recording's first and last sample on the data's clock (epoch
    seconds where the data give them). The monitor's first sample is the first step's first:
    the steps before it (refused, steady) gave it no sample. An alarm before every span (or
    with no time) is the first recording's.

    Parameters
    ----------
    alarm : dict
        One of the monitor's alarms (``Alarm.as_dict``), [-]
    watched : list of dict
        The motor's done monitor steps in time order, [-]

    Returns
    -------
    str
        The recording the alarm was raised in, [-]

    """
    spans = [(s['result'].get('span_s'), s['recording']) for s in watched]
    spans = [(float(span[0]), recording) for span, recording in spans if span]
    if not spans:
        return str(watched[0]['recording'])
    at = spans[0][0] + float(alarm.get('time_s') or 0.0)  # the data's clock
    where = [recording for start, recording in spans if start <= at]
    return str(where[-1] if where else spans[0][1])


def _monitor_trend_holds(series: list[dict[str, Any]], watched: list[dict[str, Any]]) -> bool:
    """
    Whether the monitor's own trend is the motor's: an epoch clock, and its figures taken.

    Every point from the monitor's first valid figure on is its, and the ones before are the
    recordings it learned on (no interval yet): no recording fed it figures the fleet refused.
    """
    first = next((i for i, p in enumerate(series) if p['estimator'] == BY_MONITOR), None)
    return first is not None \
        and all(p['estimator'] == BY_MONITOR for p in series[first:]) \
        and all(p.get('monitor_unused') == LEARNING for p in series[:first]) \
        and all((s['result'].get('span_s') or [0.0])[0] > EPOCH_S for s in watched)


def _interval(step: dict[str, Any]) -> bool:
    """Whether a step's figure has a value and an interval (none while the monitor learns)."""
    figure = step['result']['leakage_factor']
    bounds = figure.get('ci95') or (None, None)
    return figure.get('value') is not None and all(b is not None for b in bounds)


def _calendar_trend(series: list[dict[str, Any]], markers: dict[str, dict[str, Any]],
                    limit: float) -> tuple[float | None, float | None]:
    """
    Fit the monitor's figures against the recordings' times, since the last step.

    The steps are found as for the ratios (:func:`_changes`) in the figures' own series: the
    monitor's alarms cannot tell a step from a drift its windows saw pass (both say which
    part of the losses grew), and a drift is the trend.
    """
    timed = [p for p in series if markers.get(p['recording'], {}).get('time') is not None]
    times = np.array([float(markers[p['recording']]['time']) for p in timed])
    values = np.array([float(p['value']) for p in timed])
    half = np.array([(p['ci95'][1] - p['ci95'][0]) / 2.0 for p in timed])
    _, start = _changes(timed, times, values, half)
    return _trend(times[start:], values[start:], limit)


def _baseline_line(baseline: dict[str, Any] | None) -> str:
    if not baseline:
        return 'none'
    if baseline.get('recording'):
        return f"calibrated on {baseline['recording']}"
    if baseline.get('coefficients'):
        return f"motor file {baseline['coefficients']}"
    return str(baseline.get('reason', 'none'))


def _changes(series: list[dict[str, Any]], times: np.ndarray, values: np.ndarray,
             half: np.ndarray) -> tuple[list[dict[str, Any]], int]:
    """
    Return the change alarms and the index the current regime starts at.

    A day-to-day step is a change when it stands out of the motor's other steps (their
    median is the wear rate, their spread the noise) by :data:`CHANGE_SIGMAS` of the two
    recordings' intervals and that spread, and by :data:`MIN_STEP` at least. With one other
    step (three recordings) the faster step is judged by how far the middle recording lies
    off the line through the other two, half the steps' difference, and the slower is not a
    change: a steady wear (two like steps) is a trend, a flat step then a jump one change.
    """
    alarms: list[dict[str, Any]] = []
    start = 0
    se = half / 1.96
    steps = np.diff(values) / np.maximum(np.diff(times) / DAY, 1.0 / 24.0)
    for i in range(1, len(series)):
        others = np.delete(steps, i - 1)
        days = max((times[i] - times[i - 1]) / DAY, 1.0 / 24.0)
        typical = _wear_rate(steps[i - 1], others) * days
        spread = 1.4826 * float(np.median(np.abs(others - np.median(others)))) * days \
            if others.size >= 2 else 0.0
        step = values[i] - values[i - 1] - typical
        sigma = float(np.hypot(np.hypot(se[i], se[i - 1]), spread))
        if abs(step) > max(CHANGE_SIGMAS * sigma, MIN_STEP):
            before = values[i - 1]
            alarms.append({'date': series[i]['date'], 'kind': 'change',
                           'what': f'leakage factor {before:.3g} -> {values[i]:.3g} '
                                   f'({100 * (values[i] / before - 1):+.0f} %) since '
                                   f"{series[i - 1]['date'][:10]}, "
                                   f'{abs(step) / max(sigma, 1e-12):.0f} sigma beyond the trend',
                           'recording': series[i]['recording']})
            start = i
    return alarms, start


def _wear_rate(own: float, others: np.ndarray) -> float:
    """Return the wear rate a step is judged against: the other steps' median, per day."""
    if others.size >= 2:
        return float(np.median(others))
    if others.size == 1:  # three recordings: the middle one's distance from the line
        other = float(others[0])  # through the ends, (own - other) / 2, on the faster step
        return own if abs(own) <= abs(other) else (own + other) / 2.0
    return 0.0  # two recordings: a step cannot be told from wear


def _trend(t: np.ndarray, v: np.ndarray, limit: float) -> tuple[float | None, float | None]:
    """
    Return the trend per day and the days from the last recording to the limit.

    The days are None when the slope's one-sided 97.5 % Student bound is not above zero:
    a motor whose drift the data cannot tell from noise is not given a date (with three
    recordings the bound is 12.7 standard errors, not 2).
    """
    from scipy.stats import t as student  # only when a fleet is summarised
    slope, se = _slope(t, v)
    if v.size and v[-1] >= limit:
        return slope, 0.0
    if slope is None or slope - float(student.ppf(0.975, v.size - 2)) * se <= 0.0:
        return slope, None
    days = t / DAY
    now = float(np.mean(v) + slope * (days[-1] - np.mean(days)))
    return slope, max((limit - now) / slope, 0.0)


def _slope(t: np.ndarray, v: np.ndarray) -> tuple[float | None, float]:
    """Return the least-squares slope per day and its standard error."""
    if v.size < MIN_TREND_POINTS or np.ptp(t) <= 0:
        return None, 0.0
    days = t / DAY - np.mean(t / DAY)
    slope = float(days @ (v - np.mean(v)) / (days @ days))
    scatter = float(np.sum((v - np.mean(v) - slope * days) ** 2)) / (v.size - 2)
    return slope, (scatter / float(days @ days)) ** 0.5


NEAR = 0.1
"""A motor whose last factor is within this share of the way from 1 to its limit is near it,
[-]: with no trend to project (a step just before, too few recordings since) it is ranked as
if it reached the limit now, not after every motor that has a projection."""


def rank(motors: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """
    Order motors soonest to the limit first, on one calendar.

    A motor past its limit comes first, then by the days from the fleet's latest recording
    to the date each motor's trend reaches its limit (a motor last recorded long ago has used
    some of its days since; a motor near its limit with no trend counts as reaching it now);
    motors not drifting toward it follow, by their latest leakage factor (highest first), and
    those with no figure at all last.

    Parameters
    ----------
    motors : list of dict
        :func:`motor_view` entries, [-]

    Returns
    -------
    list of dict
        The same entries, ranked.

    """
    known = [m['last_time'] for m in motors if m.get('last_time') is not None]
    now = max(known) if known else None

    def key(m: dict[str, Any]) -> tuple[int, float, str]:
        days, last, limit = m['days_to_limit'], m['last'], m.get('limit', LIMIT)
        if last is None:
            return (3, 0.0, m['motor'])
        if last >= limit or days == 0.0:
            return (0, -last, m['motor'])
        if days is not None:
            return (1, days - _days_since(m, now), m['motor'])
        if last >= limit - NEAR * (limit - 1.0):
            return (1, 0.0, m['motor'])
        return (2, -last, m['motor'])
    return sorted(motors, key=key)


def _days_since(motor: dict[str, Any], now: float | None) -> float:
    """Return the days from a motor's latest recording to the fleet's latest (0 if unknown)."""
    last = motor.get('last_time')
    return 0.0 if now is None or last is None else (now - float(last)) / DAY


def iso_now() -> str:
    """Return the current UTC time, ISO 8601 to the second."""
    return datetime.now(timezone.utc).isoformat(timespec='seconds')


__all__ = ['BY_MONITOR', 'BY_RATIO', 'CHANGE_SIGMAS', 'DAY', 'EPOCH_S', 'LIMIT', 'MIN_STEP',
           'LEARNING', 'MIN_TREND_POINTS', 'MIXED', 'MONITOR_EPOCH', 'MONITOR_MIN_RATE',
           'MONITOR_MIN_SAMPLES', 'NEAR', 'RECORDING_TIMES', 'iso_now', 'monitor_unfit',
           'motor_view', 'raised_in', 'rank']
