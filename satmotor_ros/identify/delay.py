# SPDX-License-Identifier: Apache-2.0
r"""
The base fits the delay between the speed and the flow readings of a time series.

Two sensors logged by one recorder need not be read at the same instant: a speed computed
from an encoder's counts over a window, a flow from a filtered piston speed, a bus that
forwards one reading later than the other. A pure delay :math:`d` of the speed reading
behind the flow reading,

.. math:: n_{read}(t) = n(t - d) \quad\Rightarrow\quad Q_{meas}(t) = Q(n_{read}(t + d), ...)
   \qquad (D1)

is no first-order lag: the lag terms (T2, T3 of :mod:`.transient`) take its first order in
:math:`d\,\dot n` only, and on fast moves the rest is left to the effects (a valve that
seems to open at the starts of moves, a leak, an impossible line volume). So the base
profiles the fit over :math:`d` (both signs; the speed read at :math:`t + d`) before any
effect is tried. The delay takes only what a first-order lag cannot: the lags stay the lag
terms' job.

The profile is that of the base's Huber objective on the rows the recording gives at
:math:`d = 0` (:func:`~.transient.transient_samples`), without the lag terms: at each
:math:`d` the rows' mean speed is the shifted signal's exact trapezoid mean and the
displacement flow :math:`q_t \bar n` follows it; the model's components and the line
volumes stay (the losses are small against :math:`q_t n`, so the profile's location does
not hinge on them), and the linear factors are refitted (IRLS at a robust scale of the
residuals, fixed across :math:`d`). The rows whose bins come within the range of their
stretch's ends are left out of the profile, so every :math:`d` is judged on the same rows.
A grid of :data:`GRID_SECONDS` over :math:`\pm` :data:`MAX_SECONDS` (at most
:data:`MAX_SHARE` of the recording) finds the least, a bounded search refines it below the
sample step. The delay is *fitted* only where the data pin it: (1) the base *with* its lag
terms (the speed lag's regressor following :math:`d`) must gain more at the least than at
:math:`d = 0`, divided by the variance inflation of the correlated residuals
(:func:`~.transient.variance_inflation`), than chi2(1) at :data:`ALPHA` over the number of
independent delays the range holds (one per bin length: a search over the range, not one
test); (2) the delay must beat the best first-order lag of either reading, applied in its
own shape (a filter, without the derivatives whose noise shrinks the lag terms), by the same
limit; (3) the least must lie inside the range (at its end the data ask for a delay at least
that large, no estimate) and (4) one sample step or more from 0 (a shorter shift is within
the samples' own timing, whose jitter the real logs show). Otherwise :math:`d = 0` is
*kept*, and said why.

A fitted delay is applied to every sample (:func:`shifted`) before the rows are read for the
effects, the errors and the report; the samples at a stretch's end the shift cannot serve
(their speed would be read past the stretch) are left out and counted.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
from typing import Any

import numpy as np
from satmotor_ros.identify.fit import HUBER, huber_rho
from satmotor_ros.identify.noise import MAD, RATE_TERMS
from satmotor_ros.identify.parts import NO_EFFECT
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import (END_SAMPLES, flow_per_speed, Samples, segments,
                                             smooth, variance_inflation)
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import LPM
from scipy import optimize, signal, stats

ALPHA = 0.01
"""Level at which a fitted delay must beat none, over the range's independent delays, [-]."""

MAX_SECONDS = 1.5
"""Largest delay profiled, either sign, [s]: several sensor filters' worth, short against a
move."""

MAX_SHARE = 0.05
"""Largest delay profiled as a share of the recording's duration, [-]."""

GRID_SECONDS = 0.05
"""Step of the profile's grid (at least the sample step), [s]."""

MIN_ROWS = 20
"""Fewest rows the profile must keep for a delay to be fitted, [-]."""

IRLS_STEPS = 6
"""Reweighted least-squares steps of the Huber fit at each delay, [-]."""

EDGE = 0.5
"""A least within this many grid steps of the range's end counts as at the end, [-]."""


@dataclass(frozen=True)
class DelayFit:
    """The delay of the speed reading behind the flow reading, fitted or kept at 0."""

    seconds: float  # d of eq. (D1): the speed is read at t + d [s]
    fitted: bool  # the data pin it (else kept at 0)
    note: str  # one sentence for the report: fitted or kept, and why
    ci95: tuple[float, float] | None = None  # profile interval of a fitted delay [s]
    gain: float = math.nan  # the profile's chi2 gain over d = 0 (inflation divided out) [-]
    limit: float = math.nan  # the gain it had to beat [-]
    rmse_at_zero: float = math.nan  # the base's residual at d = 0 (profile rows) [m^3/s]
    rmse_at_delay: float = math.nan  # the base's residual at d [m^3/s]
    span: float = 0.0  # the range profiled, +-span [s]
    gain_over_lag: float = math.nan  # the delay's chi2 gain over the best first-order lag [-]
    unserved: int = 0  # samples at stretch ends the shift could not serve, left out [-]

    def as_dict(self) -> dict[str, Any]:
        """Return the record ``calibration.json`` holds under ``speed_delay``."""
        out: dict[str, Any] = {'seconds': _round(self.seconds), 'unit': 's',
                               'fitted': self.fitted, 'note': self.note}
        if self.ci95 is not None:
            out['ci95'] = [_round(v) for v in self.ci95]
        if math.isfinite(self.gain):
            out.update(gain=_round(self.gain), limit=_round(self.limit),
                       range_s=[-_round(self.span), _round(self.span)])
        if math.isfinite(self.gain_over_lag):
            out['gain_over_lag'] = _round(self.gain_over_lag)
        if math.isfinite(self.rmse_at_zero):
            out.update(rmse_at_zero_lpm=_round(self.rmse_at_zero / LPM),
                       rmse_at_delay_lpm=_round(self.rmse_at_delay / LPM))
        out['samples_unserved'] = self.unserved
        return out


def _round(x: float) -> float:
    return float(f'{x:.4g}')


def kept(why: str) -> DelayFit:
    """Return the delay kept at 0, saying why."""
    return DelayFit(0.0, False, f'speed delay kept at 0: {why}')


def _kept(measured: DelayFit, why: str) -> DelayFit:
    """Return the delay kept at 0 with the profile's figures, saying why."""
    return replace(measured, seconds=0.0, fitted=False, note=kept(why).note)


def shifted(table: BenchTable, seconds: float, gap: float) -> tuple[BenchTable, int]:
    """
    Read the speed of each sample at t + `seconds`, eq. (D1), within its stretch.

    The speed (and a ``revolutions`` channel) is interpolated linearly between the samples
    of the stretch without a gap (:func:`~.transient.segments`) the sample belongs to; a
    sample whose t + `seconds` falls outside its stretch is left out, and counted.

    Parameters
    ----------
    table : BenchTable
        Samples with a ``time`` channel, [-]
    seconds : float
        The delay d of the speed reading behind the flow reading, [s]
    gap : float
        A time step over `gap` times the median step cuts the series, [-]

    Returns
    -------
    BenchTable
        The samples in time order, the speed shifted, a note saying so.
    int
        Samples left out at the stretches' ends.

    """
    if seconds == 0.0:
        return table, 0
    order = np.argsort(table.channels['time'], kind='stable')
    if np.any(np.diff(order) != 1):
        table = table.select(order)
    time = table.channels['time']
    first, _ = segments(time, gap)
    starts = np.flatnonzero(first)
    ends = np.append(starts[1:], time.size)
    keep = np.zeros(time.size, dtype=bool)
    speed = np.full(time.size, np.nan)
    revs = table.channels.get('revolutions')
    turned = np.full(time.size, np.nan) if revs is not None else None
    for lo, hi in zip(starts, ends):
        t = time[lo:hi]
        at = t + seconds
        inside = (at >= t[0]) & (at <= t[-1])
        keep[lo:hi] = inside
        speed[lo:hi] = np.interp(at, t, table.speed[lo:hi])
        if turned is not None and revs is not None:
            turned[lo:hi] = np.interp(at, t, revs[lo:hi])
    channels = dict(table.channels)
    if turned is not None:
        channels['revolutions'] = turned
    out = replace(table, speed=speed, channels=channels)
    lost = int((~keep).sum())
    note = (f'speed read {seconds:+.3g} s later than logged (the fitted delay of the speed '
            f'reading behind the flow reading, eq. D1)'
            + (f'; {lost} samples at the ends of stretches left out: their shifted speed '
               'lies past the stretch' if lost else ''))
    return out.select(keep, note), lost


class _Profile:
    """The base's Huber objective on fixed rows as a function of the speed delay."""

    def __init__(self, samples: Samples, model: MotorModel, span: float, gap: float,
                 lags: bool) -> None:
        raw = samples.samples
        time = raw.channels['time']
        a, b = samples.bounds
        first, _ = segments(time, gap)
        stretch = np.cumsum(first) - 1
        starts = np.flatnonzero(first)
        ends = np.append(starts[1:], time.size) - 1
        lo_t, hi_t = time[starts[stretch[a]]], time[ends[stretch[a]]]
        self.rows = (time[a] - span >= lo_t) & (time[b] + span <= hi_t)
        a, b = a[self.rows], b[self.rows]
        parts = samples.parts
        self.ta, self.tb = time[a], time[b]
        self.sign = np.asarray(parts.sign * np.ones(len(parts)))[self.rows]
        speed = np.where(np.isfinite(raw.speed), raw.speed, 0.0)
        self.time = time
        self.area = _area(time, speed)
        self.area_flow = _area(time, np.where(np.isfinite(raw.flow), raw.flow, 0.0))
        self.smooth = smooth(speed, first, END_SAMPLES)
        self.speed, self.step = speed, samples.step
        self.raw_flow = np.where(np.isfinite(raw.flow), raw.flow, 0.0)
        self.starts = np.append(starts, time.size)
        self.filtered: dict[float, tuple[FloatArray, FloatArray]] = {}
        self.qt = model.geometry.displacement
        self.mean0 = self._mean(0.0)
        self.displacement = parts.displacement[self.rows]
        self.flow = parts.flow[self.rows]
        self.fixed = [np.asarray(c.flow(NO_EFFECT), dtype=float)[self.rows]
                      for c in parts.components]
        self.nuisance = {k: np.asarray(v)[self.rows] for k, v in parts.nuisance.items()
                         if lags or k not in RATE_TERMS}
        self.dq_dn = flow_per_speed(parts, self.qt)[self.rows]
        self.scale = 0.0
        self.seen: dict[tuple[float, float], float] = {}

    def _mean(self, d: float) -> FloatArray:
        # the trapezoid mean of the piecewise-linear speed over [t_a + d, t_b + d]
        f = np.interp(np.concatenate((self.ta, self.tb)) + d, self.time, self.area)
        return np.asarray((f[self.ta.size:] - f[:self.ta.size]) / (self.tb - self.ta))

    def _lagged(self, lag: float) -> tuple[FloatArray, FloatArray]:
        """Return the running areas of the speed and the flow, one of them lagged by |lag|."""
        if lag not in self.filtered:
            speed, flow = self.speed, self.raw_flow
            if lag > 0.0:  # the flow reading lags: the model's flow (~ q_t n) seen through it
                speed = _first_order(speed, self.starts, self.step, lag)
            else:  # the speed reading lags: the flow seen through the same lag matches it
                flow = _first_order(flow, self.starts, self.step, -lag)
            self.filtered[lag] = (_area(self.time, speed), _area(self.time, flow))
        return self.filtered[lag]

    def _row_means(self, area: FloatArray, d: float) -> FloatArray:
        f = np.interp(np.concatenate((self.ta, self.tb)) + d, self.time, area)
        return np.asarray((f[self.ta.size:] - f[:self.ta.size]) / (self.tb - self.ta))

    def residual(self, d: float, lag: float = 0.0) -> FloatArray:
        """
        Return the base's residual at delay `d` (Huber IRLS at the fixed scale), [m^3/s].

        With `lag` the lag terms are out and a first-order lag of |lag| is applied
        instead, on the speed (> 0: the flow reading lags) or the flow reading (< 0: the
        speed reading lags): the lag's own shape, without a derivative's noise.
        """
        mean, flow = self._mean(d), self.flow
        if lag:
            speed_area, flow_area = self._lagged(lag)
            mean = self._row_means(speed_area, d)
            flow = flow + self.sign * (self._row_means(flow_area, 0.0)
                                       - self._row_means(self.area_flow, 0.0))
        loss = flow - (self.displacement + self.sign * self.qt * (mean - self.mean0))
        nuisance = dict(self.nuisance)
        if 'speed_lag' in nuisance:
            ends = np.interp(np.concatenate((self.ta, self.tb)) + d, self.time, self.smooth)
            dn = self.sign * (ends[self.ta.size:] - ends[:self.ta.size]) / (self.tb - self.ta)
            nuisance['speed_lag'] = self.dq_dn * dn
        x = np.column_stack(self.fixed + list(nuisance.values()))
        weight = np.ones(loss.size)
        for _ in range(IRLS_STEPS if self.scale > 0.0 else 1):
            root = np.sqrt(weight)
            beta = np.linalg.lstsq(x * root[:, None], loss * root, rcond=None)[0]
            r = loss - x @ beta
            if self.scale > 0.0:
                z = np.abs(r) / self.scale
                weight = np.where(z <= HUBER, 1.0, HUBER / np.maximum(z, 1e-300))
        return np.asarray(r, dtype=float)

    def __call__(self, d: float, lag: float = 0.0) -> float:
        """Return the Huber objective (2 rho of the scaled residuals) at `d` (and `lag`)."""
        key = (float(d), float(lag))
        if key not in self.seen:
            self.seen[key] = float(np.sum(huber_rho(self.residual(*key) / self.scale)))
        return self.seen[key]


def _area(time: FloatArray, x: FloatArray) -> FloatArray:
    """Return the running trapezoid integral of `x` over `time`, 0 at the first sample."""
    return np.concatenate(([0.0], np.cumsum(0.5 * (x[1:] + x[:-1]) * np.diff(time))))


def _first_order(x: FloatArray, starts: np.ndarray, step: float, tau: float) -> FloatArray:
    """Return `x` through a first-order lag of `tau` (per stretch, from its first value)."""
    keep = float(np.exp(-step / tau))
    out = np.empty_like(x)
    for lo, hi in zip(starts[:-1], starts[1:]):
        out[lo:hi], _ = signal.lfilter([1.0 - keep], [1.0, -keep], x[lo:hi],
                                       zi=[keep * x[lo]])
    return out


def fit_delay(samples: Samples, model: MotorModel, gap: float = 3.0) -> DelayFit:
    """
    Profile the base over the delay of the speed reading; fit it where the data pin it.

    Parameters
    ----------
    samples : Samples
        A time series' rows read at d = 0 (:func:`~.transient.transient_samples`), [-]
    model : MotorModel
        The model they were read with, [-]
    gap : float
        A time step over `gap` times the median step cuts the series, [-]

    Returns
    -------
    DelayFit
        The delay fitted, or 0 kept, and why.

    """
    time = samples.samples.channels['time']
    duration = float(np.nanmax(time) - np.nanmin(time)) if time.size else 0.0
    grid_step = max(GRID_SECONDS, samples.step)
    span = min(MAX_SECONDS, MAX_SHARE * duration)
    count = int(math.floor(span / grid_step))
    if count < 2:
        return kept(f'the recording ({duration:.3g} s) is too short to profile a delay')
    span = count * grid_step
    pure = _Profile(samples, model, span, gap, lags=False)
    rows = int(pure.rows.sum())
    if rows < MIN_ROWS:
        return kept(f'{rows} rows lie {span:.3g} s or more inside their stretch '
                    f'(need >= {MIN_ROWS})')
    if not _scaled(pure, 0.0):
        return kept('the base fits the rows exactly')
    grid = grid_step * np.arange(-count, count + 1)
    values = np.array([pure(d) for d in grid])
    i = int(np.argmin(values))
    best = float(grid[i])
    if 0 < i < grid.size - 1:
        found = optimize.minimize_scalar(pure, bounds=(grid[i - 1], grid[i + 1]),
                                         method='bounded',
                                         options={'xatol': 0.01 * grid_step, 'maxiter': 20})
        if pure(float(found.x)) < values[i]:
            best = float(found.x)
    # the test: the base with its lags at the least against at no delay, each on the
    # alternative's robust scale (as the channel drop's): a first-order lag the lag terms
    # represent gains nothing from a delay
    full = _Profile(samples, model, span, gap, lags=True)
    if not _scaled(full, best):
        return kept('the base fits the rows exactly at the least')
    inflation = variance_inflation(full.residual(best))
    gain = (full(0.0) - full(best)) / inflation
    independent = max(1, int(round(2.0 * span / (samples.bin_size * samples.step))))
    limit = float(stats.chi2.ppf(1.0 - ALPHA / independent, 1))
    rms0 = float(np.sqrt(np.mean(full.residual(0.0) ** 2)))
    rms = float(np.sqrt(np.mean(full.residual(best) ** 2)))
    said = DelayFit(0.0, False, '', None, gain, limit, rms0, rms, span)
    profiled = (f'profile over {-span:.3g} to {span:.3g} s on {rows} rows: least at '
                f'{best:+.3g} s, chi2 gain {gain:.3g} with the lags')
    if gain <= limit:
        return _kept(said, f'the data do not pin it ({profiled} <= {limit:.3g}, chi2(1) at '
                     f'{ALPHA:g} over {independent} independent delays)')
    if abs(best) >= span - EDGE * grid_step:
        return _kept(said, f'the profile is least at the end of the range ({profiled}): '
                     'a bound, not an estimate')
    if abs(best) < samples.step:
        return _kept(said, f'the least is within one sample step ({samples.step:.3g} s) of 0 '
                     f"({profiled}): the samples' own timing, not a delay")
    # a first-order lag of either reading (its own shape, :meth:`_Profile.residual`) is the
    # lag terms' job: the delay must fit better than the best of them by the same limit
    _scaled(pure, best)
    pure_inflation = variance_inflation(pure.residual(best))
    lags = [float(v) for v in grid if v]
    lag = lags[int(np.argmin([pure(0.0, v) for v in lags]))]
    over = (pure(0.0, lag) - pure(best)) / pure_inflation
    said = replace(said, gain_over_lag=over)
    if over <= limit:
        return _kept(said, f'a first-order lag of the {"flow" if lag > 0 else "speed"} '
                     f'reading ({abs(lag):.3g} s) fits as well ({profiled}; chi2 gain '
                     f'of the delay over the lag {over:.3g} <= {limit:.3g}): the lag '
                     'terms take it')
    level = pure(best) + pure_inflation * float(stats.chi2.ppf(0.95, 1))
    ci95 = (_crossing(pure, best, -span, level), _crossing(pure, best, span, level))
    note = (f'speed delay fitted: the speed reading lags the flow reading by {best:.3g} s '
            f'(95 % {ci95[0]:.3g} to {ci95[1]:.3g} s; {profiled} > {limit:.3g}, over the best '
            f'first-order lag {over:.3g}); the base '
            f'error {rms0 / LPM:.3g} -> {rms / LPM:.3g} l/min on the profile rows')
    return replace(said, seconds=best, fitted=True, note=note, ci95=ci95)


def _scaled(profile: _Profile, d: float) -> bool:
    """Fix the profile's scale at the robust spread of its least-squares residual at `d`."""
    profile.scale, profile.seen = 0.0, {}
    r = profile.residual(d)
    profile.scale = MAD * float(np.median(np.abs(r - np.median(r))))
    return profile.scale > 0.0


def _crossing(profile: _Profile, best: float, end: float, level: float) -> float:
    """Return the delay where the profile crosses `level` between `best` and `end`."""
    if not profile(end) > level:
        return end
    return float(optimize.brentq(lambda d: profile(d) - level, min(best, end), max(best, end),
                                 xtol=1e-3, maxiter=40))


__all__ = ['ALPHA', 'DelayFit', 'fit_delay', 'kept', 'shifted']
