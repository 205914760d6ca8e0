# SPDX-License-Identifier: Apache-2.0
"""Steady operating points out of time series: windows where flow, pressures and speed hold."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.revolutions import sampled_revolutions
from satmotor_ros.model.units import LPM, MPA, RPM


@dataclass(frozen=True)
class SteadyTolerance:
    """
    When a stretch of samples counts as one steady operating point.

    A sample is steady when, over the `window` centred on it, the standard
    deviation of each of flow, p_in, p_out and speed is at most
    ``rel * |mean| + max(abs, 2 sigma)`` of that channel, where sigma is the
    channel's sample-to-sample noise estimated from the data (see
    :func:`sample_noise`), so that a noisy sensor does not hide every plateau.
    A steady run loses its first `settle` seconds (the tail of the
    transient), must then last `min_duration`, may not drift by more than the
    same tolerance between its first and last thirds (else it is split), and
    is cut into points of at most `max_duration` so that slow channels
    (temperature, time) keep their resolution.
    """

    flow_rel: float = 0.01  # [-]
    flow_abs: float = 0.05 * LPM  # [m^3/s]
    pressure_rel: float = 0.02  # [-]
    pressure_abs: float = 0.1 * MPA  # [Pa]
    speed_rel: float = 0.01  # [-]
    speed_abs: float = 2.0 * RPM  # [rad/s]
    window: float = 0.5  # [s]
    settle: float = 0.5  # [s]
    min_duration: float = 1.0  # [s]
    max_duration: float = 10.0  # [s]

    def __post_init__(self) -> None:
        """Reject negative tolerances and an empty window."""
        for name in ('flow_rel', 'flow_abs', 'pressure_rel', 'pressure_abs', 'speed_rel',
                     'speed_abs', 'settle'):
            if not getattr(self, name) >= 0.0:
                msg = f'SteadyTolerance.{name} = {getattr(self, name)!r}: must be >= 0'
                raise DataError(msg)
        if not 0.0 < self.window and 0.0 < self.min_duration <= self.max_duration:
            msg = 'SteadyTolerance: need window > 0 and 0 < min_duration <= max_duration'
            raise DataError(msg)


def _rolling(x: FloatArray, w: int) -> tuple[FloatArray, FloatArray]:
    """Centred moving mean and standard deviation over `w` samples (shrunk at the ends)."""
    n = x.size
    c1 = np.concatenate(([0.0], np.cumsum(x - x.mean())))
    c2 = np.concatenate(([0.0], np.cumsum((x - x.mean()) ** 2)))
    i = np.arange(n)
    lo = np.clip(i - w // 2, 0, n)
    hi = np.clip(i - w // 2 + w, 0, n)
    count = hi - lo
    mean = (c1[hi] - c1[lo]) / count
    var = np.maximum((c2[hi] - c2[lo]) / count - mean ** 2, 0.0)
    return mean + x.mean(), np.sqrt(var)


def sample_noise(x: FloatArray) -> float:
    """
    Estimate the white noise of a sampled signal from its successive differences.

    Parameters
    ----------
    x : ndarray
        Samples in time order, [any]

    Returns
    -------
    float
        1.4826 median|x[i+1] - x[i]| / sqrt(2): the standard deviation of the
        noise where the signal holds most of the time, [same unit as x]

    """
    if x.size < 3:
        return 0.0
    return float(1.4826 * np.median(np.abs(np.diff(x))) / np.sqrt(2.0))


def looks_like_series(table: BenchTable) -> bool:
    """
    Tell a time series (plateaus of many samples) from a table of steady points.

    Parameters
    ----------
    table : BenchTable
        Rows as read, [-]

    Returns
    -------
    bool
        True when there is a time column, at least 30 rows, and successive rows
        of speed and flow differ by far less (< 10 %) than their spread.

    """
    if 'time' not in table.channels or len(table) < 30:
        return False
    order = np.argsort(table.channels['time'], kind='stable')
    for x in (table.speed[order], table.flow[order]):
        spread = float(np.std(x))
        if spread == 0.0 or np.median(np.abs(np.diff(x))) >= 0.1 * spread:
            return False
    return True


def _channels(table: BenchTable, tol: SteadyTolerance) -> list[tuple[FloatArray, float, float]]:
    pairs = [(table.flow, tol.flow_rel, tol.flow_abs),
             (table.p_in, tol.pressure_rel, tol.pressure_abs),
             (table.p_out, tol.pressure_rel, tol.pressure_abs),
             (table.speed, tol.speed_rel, tol.speed_abs)]
    return [(x, rel, max(absolute, 2.0 * sample_noise(x))) for x, rel, absolute in pairs]


def _steady_mask(channels: list[tuple[FloatArray, float, float]], time: FloatArray,
                 window: float) -> np.ndarray:
    """Flag the samples whose centred `window` [s] is steady on every channel."""
    dt = float(np.median(np.diff(time))) if time.size > 1 else 1.0
    w = max(3, int(round(window / dt)) if dt > 0 else 3)
    steady = np.ones(time.size, dtype=bool)
    for x, rel, absolute in channels:
        mean, std = _rolling(x, w)
        steady &= std <= rel * np.abs(mean) + absolute
    return steady


def _drifts(channels: list[tuple[FloatArray, float, float]], lo: int, hi: int) -> bool:
    third = max((hi - lo) // 3, 1)
    for x, rel, absolute in channels:
        a, b = x[lo:lo + third].mean(), x[hi - third:hi].mean()
        if abs(a - b) > rel * abs(0.5 * (a + b)) + absolute:
            return True
    return False


def steady_runs(table: BenchTable, time: FloatArray,
                tol: SteadyTolerance) -> list[tuple[int, int]]:
    """
    Find the steady windows of a time series.

    Parameters
    ----------
    table : BenchTable
        Raw samples in time order, [-]
    time : ndarray
        Sample times, increasing, [s]
    tol : SteadyTolerance
        The tolerances, [-]

    Returns
    -------
    list of (int, int)
        Sample index ranges ``[start, stop)``, one per steady operating point.

    """
    channels = _channels(table, tol)
    mask = _steady_mask(channels, time, tol.window)
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    runs: list[tuple[int, int]] = []
    stack: list[tuple[int, int]] = []
    for a, b in zip(edges[::2], edges[1::2]):
        a = int(np.searchsorted(time, time[a] + tol.settle)) if tol.settle else int(a)
        stack.append((a, int(b)))
    while stack:
        lo, hi = stack.pop()
        if hi - lo < 3 or time[hi - 1] - time[lo] < tol.min_duration:
            continue
        if _drifts(channels, lo, hi):
            mid = (lo + hi) // 2
            stack.extend([(mid, hi), (lo, mid)])
            continue
        pieces = max(1, int(np.ceil((time[hi - 1] - time[lo]) / tol.max_duration)))
        bounds = np.linspace(lo, hi, pieces + 1).astype(int)
        runs.extend((int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:]) if b - a >= 3)
    return sorted(runs)


def extract_steady(table: BenchTable, tol: SteadyTolerance | None = None) -> BenchTable:
    """Average each steady window of a time series into one row: :func:`steady_windows`'s table."""
    return steady_windows(table, tol)[0]


def steady_windows(table: BenchTable,
                   tol: SteadyTolerance | None = None) -> tuple[BenchTable, int]:
    """
    Average each steady window of a time series into one operating point.

    Every channel is averaged over the window, so extra channels survive;
    a ``revolutions`` channel (cumulative shaft revolutions at the window's
    mean time, integrated over the raw samples) is added, and ``time`` is the
    window's mean time.

    Parameters
    ----------
    table : BenchTable
        Raw samples with a ``time`` channel, [-]
    tol : SteadyTolerance, optional
        The tolerances; the defaults when omitted, [-]

    Returns
    -------
    BenchTable
        One row per steady window, ``time_series`` False.
    int
        Samples in the windows, [-]

    Raises
    ------
    DataError
        If there is no time channel or no steady window.

    """
    tol = tol or SteadyTolerance()
    if 'time' not in table.channels:
        msg = "time series needs a 'time [s]' column to find steady windows"
        raise DataError(msg)
    time = table.channels['time']
    order = np.argsort(time, kind='stable')
    if np.any(np.diff(order) != 1):
        table = table.select(order)
        time = table.channels['time']
    runs = steady_runs(table, time, tol)
    if not runs:
        msg = (f'{table.source}: no steady window found in {len(table)} samples (flow, '
               f'pressures and speed must hold within tolerance for >= {tol.min_duration} s)')
        raise DataError(msg)
    revs = sampled_revolutions(table.speed, time)
    starts = np.array([a for a, _ in runs])
    stops = np.array([b for _, b in runs])

    def average(x: FloatArray) -> FloatArray:
        c = np.concatenate(([0.0], np.cumsum(np.where(np.isfinite(x), x, 0.0))))
        k = np.concatenate(([0], np.cumsum(np.isfinite(x))))
        with np.errstate(invalid='ignore', divide='ignore'):
            mean: FloatArray = (c[stops] - c[starts]) / (k[stops] - k[starts])  # Any to numpy
            return mean

    channels = {name: average(x) for name, x in table.channels.items()}
    channels['revolutions'] = average(revs)
    units = dict(table.units)
    units['revolutions'] = 'rev'
    used = int((stops - starts).sum())
    note = (f'time series of {len(table)} samples: {len(runs)} steady windows '
            f'({100.0 * used / len(table):.0f} % of the samples)')
    return BenchTable(average(table.speed), average(table.flow), average(table.p_in),
                      average(table.p_out), channels, units, table.source, False,
                      table.notes + (note,)), used
