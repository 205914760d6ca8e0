# SPDX-License-Identifier: Apache-2.0
"""The health monitor's inputs, settings and outputs: plain frozen records, all SI."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
import math
import sys
from typing import Any

import numpy as np

from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model._typing import FloatArray

SKIP_REASONS = ('stalled', 'outside_envelope', 'outside_model', 'stale', 'non_finite',
                'implausible', 'parked')
"""Why a sample is not used, as :attr:`HealthSnapshot.skipped` counts them (``implausible``:
a finite reading outside the physical envelope, :data:`.baseline.GROSS`; ``parked``: below
``min_speed`` with no flow but leakage, :data:`.baseline.PARKED_FLOW`; ``stalled``: below
``min_speed`` with flow passing)."""

NEVER_HOURS = sys.float_info.max
"""``hours_to_limit`` in ``monitor.json`` when the trend does not rise towards the limit: the
topic's inf (DESIGN.md), written as the largest double since JSON has no Infinity (jq writes
an infinity so too); it reads back as a float no real figure reaches, [h]."""


def hours_json(x: float) -> float | None:
    """
    Return hours to the limit as ``monitor.json`` writes them.

    Parameters
    ----------
    x : float
        Hours; inf when the trend does not rise towards the limit, NaN with no trend yet, [h]

    Returns
    -------
    float or None
        6 digits; :data:`NEVER_HOURS` for inf; None (null) for NaN: no figure yet.

    """
    if math.isnan(x):
        return None
    if math.isinf(x):
        return NEVER_HOURS if x > 0 else -NEVER_HOURS
    return float(f'{x:.6g}')


def hours_note(x: float, why: str = '') -> str:
    """
    Say what an hours-to-limit figure means, as ``monitor.json`` and the diagnostics do.

    Parameters
    ----------
    x : float
        Hours to the limit, [h]
    why : str
        The estimator's reason for a 0 or a NaN (:attr:`HealthSnapshot.hours_to_limit_why`), [-]

    Returns
    -------
    str
        One line.

    """
    if why and (math.isnan(x) or x == 0.0):  # the estimator's reason for these two
        return why
    if math.isnan(x):
        return 'null: not enough operation for a trend yet'
    if math.isinf(x):
        return ('never: the trend does not rise significantly towards the limit (its 95 % '
                'interval holds no rise); written as the largest double, 1.7976931348623157e308 '
                '(JSON has no Infinity); ci95[0] is the soonest crossing it allows')
    return "hours of the recording's time from the last sample (95 % interval in ci95)"


@dataclass(frozen=True)
class HealthSamples:
    """
    A block of samples in time order, all SI (temperature in degC).

    ``p_case`` and ``temperature`` are optional; ``stale`` marks samples whose inputs the
    caller knows to be old (a node's topic that stopped), which are counted and skipped.
    """

    time: FloatArray  # [s] on the data's own clock
    speed: FloatArray  # signed shaft speed [rad/s]
    flow: FloatArray  # flow into port A [m^3/s]
    p_in: FloatArray  # port A (inlet when the flow is positive) [Pa]
    p_out: FloatArray  # port B [Pa]
    p_case: FloatArray | None = None  # case pressure [Pa]
    temperature: FloatArray | None = None  # oil temperature [degC]
    stale: np.ndarray | None = None  # bool: the caller's inputs are old here

    def __post_init__(self) -> None:
        """Check that every channel has one value per sample."""
        n = np.shape(self.time)
        for name in ('speed', 'flow', 'p_in', 'p_out', 'p_case', 'temperature', 'stale'):
            value = getattr(self, name)
            if value is not None and np.shape(value) != n:
                msg = f'{name}: {np.shape(value)} values for {n} times'
                raise DataError(msg)

    def __len__(self) -> int:
        """Return the number of samples."""
        return int(np.size(self.time))

    @classmethod
    def from_table(cls, table: BenchTable) -> HealthSamples:
        """
        Take the samples of a time-series bench table (its ``time`` channel is required).

        Parameters
        ----------
        table : BenchTable
            A bench CSV, a bag or a user's log as the readers give it, [-]

        Returns
        -------
        HealthSamples
            Its samples.

        Raises
        ------
        DataError
            If the table has no time column.

        """
        if 'time' not in table.channels:
            msg = f'{table.source}: time: no time column (the monitor needs samples in time order)'
            raise DataError(msg)
        channels = table.channels
        return cls(np.asarray(channels['time'], dtype=float), table.speed, table.flow,
                   table.p_in, table.p_out, channels.get('p_case'), channels.get('temperature'))

    def take(self, keep: slice | np.ndarray) -> HealthSamples:
        """Return the samples selected by `keep` (a slice or a mask)."""
        def pick(x: np.ndarray | None) -> np.ndarray | None:
            return None if x is None else x[keep]
        return HealthSamples(self.time[keep], self.speed[keep], self.flow[keep],
                             self.p_in[keep], self.p_out[keep], pick(self.p_case),
                             pick(self.temperature), pick(self.stale))


@dataclass(frozen=True)
class HealthSettings:
    """
    How the monitor judges: the false-alarm interval, the limits, the windows.

    Only ``false_alarm_hours`` and the limits are choices of the user; the noise model the
    detector's threshold comes from is estimated from the data (:mod:`.detector`).
    """

    false_alarm_hours: float = 1000.0  # mean operating hours between false change alarms [h]
    limit_leakage_factor: float = 2.0  # leakage factor at which the motor is worn out [-]
    limit_volumetric_efficiency: float | None = None  # instead: eta_v at the reference [-]
    change_fraction: float = 0.2  # relative change of the losses the detector is tuned to [-]
    learn_hours: float = 0.25  # operation that teaches the noise model and the level [h]
    bin_s: float = 10.0  # shortest bin, the detector's time step (8 sample steps at least) [s]
    window_s: float = 300.0  # the window of the windowed leakage factor [s]
    trend_hours: float = 200.0  # forgetting time constant of the trend [h]
    trend_point_s: float = 600.0  # bins are pooled into trend points this long [s]
    reference_hours: float = 10.0  # forgetting time constant of the detector's level [h]
    reference_speed: float | None = None  # [rad/s]; None: typical of the learning data
    reference_dp: float | None = None  # [Pa]; None: typical of the learning data
    min_speed: float = 0.5  # below it a sample is stalled [rad/s]
    max_gap_s: float = 5.0  # a longer step is no operation (and than 3 sample steps) [s]
    explain: bool = True  # on a change, run the calibration's candidates (what changed)
    explain_s: float = 900.0  # raw samples kept for that before a change [s]

    def __post_init__(self) -> None:
        """Refuse values that mean nothing, naming the field."""
        positive = ('false_alarm_hours', 'change_fraction', 'learn_hours', 'bin_s', 'window_s',
                    'trend_hours', 'trend_point_s', 'reference_hours', 'max_gap_s',
                    'explain_s')
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                msg = f'{name} = {value!r}: need a finite number > 0'
                raise DataError(msg)
        if not (math.isfinite(self.limit_leakage_factor) and self.limit_leakage_factor > 0):
            msg = f'limit_leakage_factor = {self.limit_leakage_factor!r}: need a number > 0'
            raise DataError(msg)
        eta = self.limit_volumetric_efficiency
        if eta is not None and not 0.0 < eta < 1.0:
            msg = f'limit_volumetric_efficiency = {eta!r}: need a number in (0, 1)'
            raise DataError(msg)
        if self.min_speed < 0 or self.window_s < self.bin_s or self.trend_point_s < self.bin_s:
            msg = (f'min_speed = {self.min_speed!r}, window_s = {self.window_s!r}, '
                   f'trend_point_s = {self.trend_point_s!r}: need min_speed >= 0 and windows '
                   f'of at least bin_s = {self.bin_s!r}')
            raise DataError(msg)

    def differences(self, other: HealthSettings,
                    names: Iterable[str]) -> dict[str, tuple[Any, Any]]:
        """
        Name the settings among `names` that differ from `other`'s.

        A resumed state keeps the settings its history was judged with; ``satmotor monitor``
        and the ``motor_monitor`` node both refuse to carry it on under others (this rule).

        Parameters
        ----------
        other : HealthSettings
            The settings given now, [-]
        names : iterable of str
            The fields to compare (those the caller lets a user set), [-]

        Returns
        -------
        dict
            Field -> (this one's value, `other`'s), in the order of `names`; empty if alike.

        """
        return {name: (getattr(self, name), getattr(other, name)) for name in names
                if getattr(self, name) != getattr(other, name)}


def unresolved(factor: Estimate, change_fraction: float) -> str:
    """
    Say why the windowed leakage factor is not identifiable, or '' when it is.

    The factor is the measured loss over the baseline's, by least squares over the window:
    its 95 % half-width is 1.96 times the residual noise over the baseline's loss (summed over
    the window, the bins' correlation counted). Where that half-width exceeds
    ``change_fraction``, the window cannot tell the baseline from a change of the size the
    detector is tuned to: the baseline's losses are small against the residual noise, and
    the value depends on how the samples are weighted more than on the motor.

    Parameters
    ----------
    factor : Estimate
        The windowed leakage factor with its 95 % interval (NaN while learning), [-]
    change_fraction : float
        The relative change the detector is tuned to, [-]

    Returns
    -------
    str
        The reason with the numbers, or '' (identifiable, or no interval yet).

    """
    half = (factor.high - factor.low) / 2.0
    if not (math.isfinite(half) and half > change_fraction):
        return ''
    return (f'the leakage factor is not identifiable: its 95 % interval '
            f'[{factor.low:.3g}, {factor.high:.3g}] (half-width {half:.3g}) is wider than the '
            f"change the detector is tuned to ({change_fraction:g}): the baseline's losses "
            'are small against the residual noise, the value says little about the motor')


@dataclass(frozen=True)
class Estimate:
    """A figure with its 95 % interval (NaN where the data do not give one)."""

    value: float
    low: float = math.nan
    high: float = math.nan

    def as_dict(self) -> dict[str, float | list[float | None] | None]:
        """Return ``{'value', 'ci95'}`` with None for NaN and infinity (JSON), 9 digits."""
        def clean(x: float) -> float | None:
            return float(f'{x:.9g}') if math.isfinite(x) else None
        return {'value': clean(self.value), 'ci95': [clean(self.low), clean(self.high)]}


@dataclass(frozen=True)
class Alarm:
    """A change or a crossed limit, raised once per condition."""

    time_s: float  # when it was raised, on the data's clock [s]
    kind: str  # 'change' or 'limit'
    what: str  # the effect the candidates name, 'unexplained', or the limit crossed
    statistic: float  # the detector's statistic over its threshold (>= 1), or the factor [-]
    change_s: float = math.nan  # where the change began (the detector's estimate) [s]
    before: float = math.nan  # leakage factor before the change [-]
    after: float = math.nan  # leakage factor after it: over the detector's excursion when
    # raised, the level learned since the change once learned [-]

    def as_dict(self) -> dict[str, float | str | None]:
        """Return the alarm as monitor.json writes it."""
        def clean(x: float) -> float | None:
            return float(f'{x:.6g}') if math.isfinite(x) else None
        return {'time_s': clean(self.time_s), 'kind': self.kind, 'what': self.what,
                'statistic': clean(self.statistic), 'change_s': clean(self.change_s),
                'before': clean(self.before), 'after': clean(self.after)}


@dataclass(frozen=True)
class HealthPoint:
    """The figures at the end of one bin: the time series monitor.json and health.csv hold."""

    time_s: float  # end of the bin [s]
    operating_hours: float  # operation since the first sample [h]
    leakage_factor: Estimate  # windowed (window_s) [-]
    bin_factor: float  # this bin's own estimate [-]
    trend: Estimate  # the trend's level now [-]
    statistic: float  # detector statistic over its threshold [-]
    volumetric_efficiency: float  # at the bin's operating point, with the windowed factor [-]
    learning: bool = False  # the monitor was learning: before the first learning ends the
    # factor has no interval (NaN), its noise correlation not yet known


@dataclass(frozen=True)
class HealthSnapshot:
    """Everything the monitor knows now."""

    time_s: float  # last sample [s]
    operating_hours: float  # [h]
    recording_hours: float  # time since the first sample [h]
    learning: bool  # still learning the noise model and the level
    leakage_factor: Estimate  # windowed [-]
    trend: Estimate  # the trend's level now [-]
    trend_per_hour: Estimate  # slope per operating hour [1/h]
    hours_to_limit: Estimate  # in hours of the recording's time, from the last sample [h]
    operating_hours_to_limit: Estimate  # in operating hours [h]
    limit_leakage_factor: float  # the limit as a leakage factor [-]
    volumetric_efficiency: float  # at the current operating point [-]
    volumetric_efficiency_reference: Estimate  # at the reference point [-]
    reference_speed: float  # [rad/s]
    reference_dp: float  # [Pa]
    statistic: float  # detector statistic over its threshold [-]
    threshold: float  # the detector's threshold, in log-likelihood units [-]
    noise: dict[str, float]  # the residual's noise model as estimated
    n_samples: int  # samples given [-]
    n_skipped: int  # samples not used [-]
    skipped: dict[str, int] = field(default_factory=dict)  # reason -> count
    alarms: tuple[Alarm, ...] = ()  # every alarm raised
    change_s: float = math.nan  # start of the last change [s]
    what_changed: str = ''  # its explanation ('' before any change)
    acknowledged: int = 0  # the first this many alarms are acknowledged [-]
    in_limit: bool = False  # the limit is crossed (monitor.limit_crossed), not yet cleared
    hours_to_limit_why: str = ''  # why hours_to_limit is 0 (crossed) or NaN (no trend since
    # the first sample or the last change, and how far it is); '' for a figure of the trend
    timing: dict[str, float] = field(default_factory=dict)  # the sample step, bin, gap [s]
    n_used: dict[str, int] = field(default_factory=dict)  # where the samples not skipped went:
    # noise_model (the first third of the learning), bins (with a factor), open (the bin not
    # yet closed, with a thin one joining it), held (until the sample step is known) [-]

    @property
    def unacknowledged(self) -> tuple[Alarm, ...]:
        """Return the alarms raised since the last acknowledgement, in time order."""
        return self.alarms[self.acknowledged:]


__all__ = ['Alarm', 'Estimate', 'HealthPoint', 'HealthSamples', 'HealthSettings',
           'HealthSnapshot', 'hours_json', 'hours_note', 'NEVER_HOURS', 'SKIP_REASONS',
           'unresolved']
