# SPDX-License-Identifier: Apache-2.0
"""
One monitor over whole recordings, in time order: what ``satmotor monitor`` and fleet run.

Recordings are taken in the order given. Each one's own time column is kept where it runs on
after the one before (epoch times, a log that continues); a recording whose clock starts
again (each bench CSV at 0 s, each bag at its first message) is placed after the one before,
:data:`GAP_S` later, so no operation is counted across the gap and no sample goes back in
time. Epoch clocks (beyond :data:`EPOCH_S`) are reported from their first sample, with
``t0_epoch``; an epoch-stamped recording that reaches back into what the monitor has seen
(the same file sent again to a resumed state) gives only its samples after that, or none: an
epoch clock is the time, and moving it on would count the same operation twice.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
import math

import numpy as np

from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.health.baseline import Baseline
from satmotor_ros.identify.health.monitor import HealthMonitor
from satmotor_ros.identify.health.records import (HealthPoint, HealthSamples, HealthSettings,
                                                  HealthSnapshot)
from satmotor_ros.identify.table import BenchTable

BLOCK = 200_000
"""Samples handed to the monitor at a time (its cost is per sample; this bounds memory)."""

GAP_S = 60.0
"""Time put between a recording and the next when the next one's clock starts again, [s]."""

EPOCH_S = 1.0e8
"""A time column beyond this (about three years in seconds) is an epoch clock, [s]."""


@dataclass(frozen=True)
class Recording:
    """Where one recording's samples went on the monitor's clock."""

    source: str  # the file or bag
    samples: int  # [-]
    start_s: float  # its first sample on the monitor's clock, from the first recording's [s]
    end_s: float  # its last [s]
    shifted_s: float  # added to its own time column (0: its clock used as it is) [s]


@dataclass(frozen=True)
class MonitorRun:
    """The monitor after every recording: its snapshot, its time series, the recordings."""

    snapshot: HealthSnapshot
    points: tuple[HealthPoint, ...]
    recordings: tuple[Recording, ...]
    settings: HealthSettings
    baseline: str  # where the baseline came from
    t0_epoch: float | None = None  # epoch seconds of the first sample, where the data give them
    t0_s: float = math.nan  # the first sample on its own time column: time_s + t0_s is the
    # data's time (plus a recording's shifted_s where its clock started again) [s]
    notes: tuple[str, ...] = field(default=())


STALE_SHARE = 0.5
"""A recording more of whose samples than this do not advance in time has no time column."""


def _in_time_order(tables: list[BenchTable], notes: list[str]) -> list[BenchTable]:
    """Sort recordings whose clocks are all epoch clocks by their first sample."""
    firsts = []
    for table in tables:
        time = np.asarray(table.channels.get('time', []), dtype=float)
        finite = time[np.isfinite(time)]
        firsts.append(float(finite[0]) if finite.size else math.nan)
    if not tables or not all(f > EPOCH_S for f in firsts):
        return tables
    order = sorted(range(len(tables)), key=lambda i: firsts[i])
    if order != list(range(len(tables))):
        notes.append('the recordings were given out of time order; taken by their epoch '
                     'clocks: ' + ', '.join(tables[i].source for i in order))
    return [tables[i] for i in order]


def clock_shift(last_s: float, first_s: float) -> float:
    """
    Return what to add to a clock that starts again, so it runs on after the samples before.

    A time at or before the last one monitored, on a clock that is not an epoch clock (a
    recording's own, a simulation clock that restarted, a replay), is placed :data:`GAP_S`
    after the last one: no operation is counted across the gap, no sample goes back in
    time. ``satmotor monitor`` applies it per recording, the ``motor_monitor`` node per
    ``joint_states`` stamp that goes back.

    Parameters
    ----------
    last_s : float
        The last sample monitored, on the monitor's clock (NaN or -inf: none yet), [s]
    first_s : float
        The first sample of what comes next, on its own clock, [s]

    Returns
    -------
    float
        The shift; 0 when the clock runs on, or is an epoch clock (which is the time), [s]

    """
    if math.isfinite(last_s) and first_s <= last_s and first_s <= EPOCH_S:
        return last_s + GAP_S - first_s
    return 0.0


def monitor_recordings(tables: Sequence[BenchTable], baseline: Baseline,
                       settings: HealthSettings | None = None,
                       monitor: HealthMonitor | None = None) -> MonitorRun:
    """
    Run one monitor over recordings in the order given.

    Parameters
    ----------
    tables : sequence of BenchTable
        Time series (a ``time`` channel each), [-]
    baseline : Baseline
        The healthy motor, [-]
    settings : HealthSettings, optional
        The monitor's settings, [-]
    monitor : HealthMonitor, optional
        A monitor to continue (resumed from a state file); a new one otherwise, [-]

    Returns
    -------
    MonitorRun
        The figures after the last sample, the time series and where each recording went.

    """
    monitor = monitor or HealthMonitor(baseline, settings)
    points: list[HealthPoint] = []
    recordings: list[Recording] = []
    notes: list[str] = []
    last = monitor.t_last
    first_time = math.nan
    tables = _in_time_order(list(tables), notes)
    for table in tables:
        samples = HealthSamples.from_table(table)
        time = samples.time
        finite = time[np.isfinite(time)]
        if not finite.size:
            continue
        shift = 0.0
        if math.isfinite(last) and finite[0] <= last and finite[0] > EPOCH_S:
            newer = time > last
            notes.append(f'{table.source}: {int(np.count_nonzero(~newer))} of {len(samples)} '
                         'samples are at or before the last one monitored (its epoch clock): '
                         'left out, already counted')
            if not newer.any():
                continue
            samples = samples.take(newer)
            time = samples.time
            finite = time[np.isfinite(time)]
        elif shift := clock_shift(last, float(finite[0])):
            notes.append(f'{table.source}: its clock starts again; placed {GAP_S:.0f} s after '
                         'the recording before it')
        if shift:
            samples = HealthSamples(time + shift, samples.speed, samples.flow, samples.p_in,
                                    samples.p_out, samples.p_case, samples.temperature)
        if math.isnan(first_time):
            first_time = float(finite[0] + shift)
        stale = monitor.skipped['stale']
        for start in range(0, len(samples), BLOCK):
            monitor.update(samples.take(slice(start, start + BLOCK)))
            points += monitor.pop_points()
        if monitor.skipped['stale'] - stale > STALE_SHARE * len(samples):
            msg = (f'{table.source}: time: {monitor.skipped["stale"] - stale} of '
                   f'{len(samples)} samples do not advance in time: is it the time column?')
            raise DataError(msg)
        origin = monitor.t0
        recordings.append(Recording(table.source, len(samples), float(finite[0] + shift - origin),
                                    float(finite[-1] + shift - origin), shift))
        last = float(finite[-1] + shift)
    monitor.flush()  # fewer samples than tell their step: taken with the steps there are
    points += monitor.pop_points()
    epoch = monitor.t0 if math.isfinite(monitor.t0) and monitor.t0 > EPOCH_S else None
    return MonitorRun(monitor.snapshot(), tuple(points), tuple(recordings), monitor.settings,
                      baseline.source, epoch, monitor.t0, tuple(notes))


__all__ = ['BLOCK', 'clock_shift', 'EPOCH_S', 'GAP_S', 'monitor_recordings', 'MonitorRun',
           'Recording']
