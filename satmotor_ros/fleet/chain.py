# SPDX-License-Identifier: Apache-2.0
"""
One health monitor per motor over its recordings in time order: a chain of tasks.

Each step runs ``satmotor monitor``'s estimator
(:class:`~satmotor_ros.identify.health.HealthMonitor`) over one recording, resumed from the
state file the step before saved (:data:`STATE`, a small JSON file beside that recording's
outputs: a worker reads it by path), writes what ``satmotor monitor --state`` writes into
``DIR/<motor>/<recording>/monitor`` and saves the state for the next. A step's marker
(:data:`STEP`) is keyed by the step before (``prev``) and its own recording, so a changed
recording redoes itself and every step after it. A refused recording, or one without a
time column, passes the state on unchanged. Steady-point tables (a point a minute) leave the
monitor's bins empty: it writes its output and no figure, and the fleet's view of such a
motor is the recordings' ratios (:mod:`~satmotor_ros.fleet.summary`).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from satmotor_ros.fleet.config import MotorRule
from satmotor_ros.fleet.discover import Motor, Recording
from satmotor_ros.fleet.resume import (content_of, HashCache, options_key, read_marker,
                                       stat_of)
from satmotor_ros.fleet.tasks import (columns_of, input_of, load_screened, MONITOR_DIR,
                                      motor_options, no_baseline, output_conflict, Refused,
                                      rule_identity, RunOptions, STATE, STEP)

CHAIN = 'monitor-chain-v2'
"""Names the chain in each step's key: a new one redoes every step."""

STEADY = 'no time column: the health monitor has nothing to watch'


def step_options(rule: MotorRule, run: RunOptions, baseline_key: str) -> str:
    """Hash what a step depends on besides its data and the step before."""
    return options_key({'rule': rule_identity(rule), 'liquid': run.liquid,
                        'baseline': baseline_key, 'chain': CHAIN})


def read_step(directory: Path) -> dict[str, Any] | None:
    """Return a step's marker, or None (none, or unreadable)."""
    return read_marker(directory / STEP)


def valid_steps(motor: Motor, run: RunOptions, baseline_key: str,
                hashes: HashCache | None = None) -> list[dict[str, Any]]:
    """
    Return the markers of the motor's first steps that still hold, in time order.

    A step holds when it was run after the step that holds before it, on the same options,
    on its recording as it is now (same stat, or same content: known to `hashes`, else
    hashed), with its outputs there.
    """
    options = step_options(motor.rule, run, baseline_key)
    held: list[dict[str, Any]] = []
    prev = ''
    for rec in motor.recordings:
        marker = read_step(Path(run.out) / motor.motor / rec.name)
        if marker is None or marker.get('prev') != prev or marker.get('options') != options:
            break
        state = marker.get('state', '')
        if state and not Path(state).is_file():
            break
        if marker.get('conflict') and not output_conflict(Path(marker['conflict']), 'monitor'):
            break  # the user's monitor/ went: the step can run now
        if marker.get('status') == 'done' and not (
                Path(run.out) / motor.motor / rec.name / MONITOR_DIR / 'monitor.json').is_file():
            break
        try:
            if marker.get('stat') != stat_of(rec.path) and marker.get('content') != (
                    hashes.content(rec.path) if hashes is not None else content_of(rec.path)):
                break
        except OSError:
            break
        held.append(marker)
        prev = str(marker.get('chain', ''))
    return held


def monitor_step(rec: Recording, rule: MotorRule, baseline: dict[str, Any], run: RunOptions,
                 before: dict[str, Any] | None) -> dict[str, Any]:
    """
    Run the motor's monitor over one recording, resumed from the step before.

    Parameters
    ----------
    rec : Recording
        The recording to monitor, [-]
    rule : MotorRule
        Its motor's fleet.yaml entry, [-]
    baseline : dict
        Its motor's baseline, [-]
    run : RunOptions
        The run's options, [-]
    before : dict or None
        The marker of the step before (its ``chain`` and ``state``); None for the first, [-]

    Returns
    -------
    dict
        The step's marker: ``status`` ('done', 'steady' or 'refused'), ``reason``,
        ``chain``, ``state`` (the state file after it, '' none yet) and ``result`` (the
        monitor's figures after this recording, its alarms so far with their final names).

    """
    out = Path(run.out) / rec.motor / rec.name
    prev = str(before.get('chain', '')) if before else ''
    state = str(before.get('state', '')) if before else ''
    marker: dict[str, Any] = {'recording': rec.relative, 'prev': prev,
                              'options': step_options(rule, run, baseline.get('key', '')),
                              **input_of(rec)}
    marker['chain'] = options_key({'prev': prev, 'content': marker['content'],
                                   'options': marker['options']})
    try:
        if not baseline.get('coefficients'):
            raise no_baseline(baseline, rec)
        table, _ = load_screened(rec, motor_options(rule, run), columns_of(rule, run))
        if table.channels.get('time') is None:
            marker.update(status='steady', reason=STEADY, state=state, result=None)
        else:
            result = _watch(table, baseline, state, out)
            marker.update(status='done', reason='', state=str(out / STATE), result=result)
    except _Conflict as err:  # monitor/ holds what we did not write: kept, said, redone when
        marker.update(status='refused', reason=str(err), state=state, result=None,  # it goes
                      conflict=str(out / MONITOR_DIR))
    except Refused as err:
        marker.update(status='refused', reason=str(err), state=state, result=None)
    _write(out, marker)
    return marker


class _Conflict(Refused):
    """The step's output directory holds what the monitor did not write: the step refused."""


def _watch(table: Any, baseline: dict[str, Any], state: str, out: Path) -> dict[str, Any]:
    """Resume the monitor, run it over `table`, write its output and save its state."""
    from satmotor_ros.cli._common import CliError
    from satmotor_ros.cli._output import output_dir
    from satmotor_ros.identify import IdentificationError
    from satmotor_ros.identify.health import HealthMonitor, HealthSettings
    from satmotor_ros.identify.health.records import NEVER_HOURS
    from satmotor_ros.identify.health.report import write_monitor
    from satmotor_ros.identify.health.run import monitor_recordings
    from satmotor_ros.model import ModelError
    try:
        base = _baseline(baseline)
        monitor = (HealthMonitor.resume(state, base) if state
                   else HealthMonitor(base, HealthSettings()))
        given, skipped = monitor.n_samples, sum(monitor.skipped.values())  # before this one
        run = monitor_recordings([table], base, monitor=monitor)
        out.mkdir(parents=True, exist_ok=True)
        with output_dir('--out', out / MONITOR_DIR, 'monitor') as tmp:
            content = write_monitor(run, tmp)
        monitor.save(out / STATE)
    except CliError as err:  # output_dir: monitor/ is not ours
        raise _Conflict(f'the health monitor: {str(err).strip().splitlines()[0]}') from None
    except (IdentificationError, ModelError, OSError) as err:
        text = str(err).strip().splitlines()
        raise Refused('the health monitor: ' + (text[0] if text else type(err).__name__)) \
            from None
    hours = content.get('hours_to_limit')  # NEVER_HOURS: not drifting; calendar hours
    snap = run.snapshot  # its alarms carry their final names (update()'s may be 'pending')
    span = run.recordings[0] if run.recordings else None
    per_hour = content.get('trend_per_hour')  # per OPERATING hour
    return {'leakage_factor': snap.leakage_factor.as_dict(), 'learning': snap.learning,
            'trend_per_hour': per_hour,
            'trend_per_day': calendar_trend_per_day(per_hour, snap.operating_hours,
                                                    snap.recording_hours),
            'operating_hours': snap.operating_hours, 'recording_hours': snap.recording_hours,
            'hours_to_limit': None if hours == NEVER_HOURS else hours,  # days_to_limit null
            'alarms': [a.as_dict() for a in snap.alarms],
            'span_s': [span.start_s + monitor.t0, span.end_s + monitor.t0] if span else None,
            'n_samples': snap.n_samples, 'n_skipped': snap.n_skipped,  # since the first
            'recording_samples': snap.n_samples - given,  # this recording's
            'recording_skipped': snap.n_skipped - skipped}


def calendar_trend_per_day(per_hour: float | None, operating_hours: float,
                           recording_hours: float) -> float | None:
    """
    Return the monitor's trend per calendar day from its trend per operating hour.

    A day of calendar time holds 24 operating_hours / recording_hours hours of operation
    (the motor's share of time in operation since the monitor's first sample).

    Parameters
    ----------
    per_hour : float or None
        The trend per operating hour, [1/h]
    operating_hours, recording_hours : float
        Operation, and time since the first sample, [h]

    Returns
    -------
    float or None
        The trend per calendar day, [1/day]; None without a trend.

    """
    if per_hour is None or recording_hours <= 0.0:
        return None
    return 24.0 * per_hour * min(operating_hours / recording_hours, 1.0)


def _baseline(baseline: dict[str, Any]) -> Any:
    """Build the monitor's baseline as ``satmotor monitor`` does for a motor file."""
    from satmotor_ros.identify.calibrated import Calibrated
    from satmotor_ros.identify.health import Baseline
    from satmotor_ros.options import MotorOptions
    options = MotorOptions(liquid=baseline['liquid'], motor_file=baseline['coefficients'])
    return Baseline(options.build_model(), Calibrated(options.motor_file).envelope,
                    options.motor_file)


def _write(directory: Path, marker: dict[str, Any]) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    temporary = directory / f'{STEP}.partial-{os.getpid()}'
    temporary.write_text(json.dumps(marker, indent=1, sort_keys=True) + '\n', encoding='utf-8')
    os.replace(temporary, directory / STEP)


__all__ = ['CHAIN', 'STEADY', 'calendar_trend_per_day', 'monitor_step', 'read_step',
           'step_options', 'valid_steps']
