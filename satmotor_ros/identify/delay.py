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
test); (2) the delay must beat the best first-order lag of either reading, and the delay
with a first-order lag free beside it (a joint search over both, nested models) must beat
that lag alone, each by the same limit, the lag applied in its own shape
(:meth:`_Profile.residual`: without the derivatives whose noise shrinks the lag terms) and
each row weighed by its noise (:func:`~.noise.noise_model`: the timing jitter grows with
how fast the flow changes); a negative delay, the speed read before the flow, is a flow
lag's first-order twin and is kept only so; (3) the least must lie inside the range (at its
end the data ask for a delay at least that large, no estimate) and (4) one sample step or
more from 0, as the joint search's delay, on the same side (a shorter shift is within the
samples' own timing, whose jitter the real logs show). Otherwise :math:`d = 0` is *kept*,
and said why.

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
from satmotor_ros.identify.noise import MAD, noise_model, RATE_TERMS, rates_of
from satmotor_ros.identify.parts import NO_EFFECT
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import (END_SAMPLES, first_order, flow_per_speed, Samples,
                                             segments, smooth, variance_inflation)
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import LPM
from scipy import optimize, stats

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

LAGGED_KEPT = 8
"""Lagged signals the profile keeps at once (each two running areas of the samples), [-]."""

JOINT_EVALUATIONS = 60
"""Most profile evaluations of each joint (delay, lag) search, [-]."""

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
        self.smooth = smooth(speed, first, END_SAMPLES)
        self.speed, self.step = speed, samples.step
        self.starts = np.append(starts, time.size)
        self.filtered: dict[float, FloatArray] = {}
        self.qt = model.geometry.displacement
        self.mean0 = self._mean(0.0)
        self.displacement = parts.displacement[self.rows]
        self.flow = parts.flow[self.rows]
        self.fixed = [np.asarray(c.flow(NO_EFFECT), dtype=float)[self.rows]
                      for c in parts.components]
        self.nuisance = {k: np.asarray(v)[self.rows] for k, v in parts.nuisance.items()
                         if lags or k not in RATE_TERMS}
        self.dq_dn = flow_per_speed(parts, self.qt)[self.rows]
        self.scale: FloatArray | float = 0.0  # each row's noise (or one for all) [m^3/s]
        self.rates = rates_of({k: np.asarray(v)[self.rows] for k, v in parts.nuisance.items()})
        self.seen: dict[tuple[float, float], float] = {}

    def _mean(self, d: float) -> FloatArray:
        # the trapezoid mean of the piecewise-linear speed over [t_a + d, t_b + d]
        f = np.interp(np.concatenate((self.ta, self.tb)) + d, self.time, self.area)
        return np.asarray((f[self.ta.size:] - f[:self.ta.size]) / (self.tb - self.ta))

    def _lagged(self, lag: float) -> FloatArray:
        """Return the running area of the speed through a first-order lag of `lag`."""
        if lag not in self.filtered:
            if len(self.filtered) >= LAGGED_KEPT:  # each holds a signal's length: keep a few
                del self.filtered[next(iter(self.filtered))]
            lagged = first_order(self.speed, self.starts, self.step, lag)
            self.filtered[lag] = _area(self.time, lagged)
        return self.filtered[lag]

    def _rate(self, d: float) -> FloatArray:
        """Return each row's mean rate of change of the (smoothed) speed read at `d`."""
        ends = np.interp(np.concatenate((self.ta, self.tb)) + d, self.time, self.smooth)
        return np.asarray((ends[self.ta.size:] - ends[:self.ta.size]) / (self.tb - self.ta))

    def _row_means(self, area: FloatArray, d: float) -> FloatArray:
        f = np.interp(np.concatenate((self.ta, self.tb)) + d, self.time, area)
        return np.asarray((f[self.ta.size:] - f[:self.ta.size]) / (self.tb - self.ta))

    def residual(self, d: float, lag: float = 0.0) -> FloatArray:
        """
        Return the base's residual at delay `d` (Huber IRLS at the fixed scale), [m^3/s].

        With `lag` (the profile without the lag terms) a first-order lag of |lag| is
        applied in its own shape: > 0, the flow reading lags, and the model's flow is seen
        through the lag (the speed filtered, no derivative whose noise shrinks it); < 0, the
        speed reading lags, and the speed is the reading plus |lag| times its rate (the
        lag's exact inverse; the rate of a row is its ends' difference over its length).
        """
        if lag > 0.0:  # the flow reading lags: the model's flow (~ q_t n) seen through it
            mean = self._row_means(self._lagged(lag), d)
        elif lag < 0.0:  # the speed reading lags: the speed is the reading's lead, exactly
            mean = self._mean(d) - lag * self._rate(d)
        else:
            mean = self._mean(d)
        loss = self.flow - (self.displacement + self.sign * self.qt * (mean - self.mean0))
        nuisance = dict(self.nuisance)
        if 'speed_lag' in nuisance:
            nuisance['speed_lag'] = self.dq_dn * self.sign * self._rate(d)
        x = np.column_stack(self.fixed + list(nuisance.values()))
        scaled = bool(np.all(self.scale > 0.0))
        weight = np.ones(loss.size) / (self.scale ** 2 if scaled else 1.0)
        for _ in range(IRLS_STEPS if scaled else 1):
            root = np.sqrt(weight)
            beta = np.linalg.lstsq(x * root[:, None], loss * root, rcond=None)[0]
            r = loss - x @ beta
            if scaled:
                z = np.abs(r) / self.scale
                weight = np.where(z <= HUBER, 1.0, HUBER / np.maximum(z, 1e-300)) \
                    / self.scale ** 2
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
    # lag terms' job: the delay is fitted jointly with the best such lag and must beat the
    # best lag alone, on the same rows and scale, by the same limit (nested models)
    _scaled(pure, best, noise=True)
    lag = _best_lag(pure, grid)
    joint, joint_lag = _joint(pure, [(best, 0.0), (0.0, lag)], span, grid_step)
    pure_inflation = variance_inflation(pure.residual(joint, joint_lag))
    over = (pure(0.0, lag) - pure(joint, joint_lag)) / pure_inflation
    alone = (pure(0.0, lag) - pure(best)) / pure_inflation
    said = replace(said, gain_over_lag=min(over, alone))
    reading = f'{"flow" if lag > 0 else "speed"} reading ({abs(lag):.3g} s)'
    if min(over, alone) <= limit:
        return _kept(said, f'a first-order lag of the {reading} fits as well ({profiled}; '
                     f'the delay gains {alone:.3g} over the lag alone, and with the lag free '
                     f'{over:.3g} at {joint:+.3g} s; need > {limit:.3g} both): the lag terms '
                     'take it')
    if abs(joint) < samples.step or joint * best < 0.0:
        return _kept(said, f'with a first-order lag of the {reading} free, the least is '
                     f'at {joint:+.3g} s ({profiled}), within one sample step '
                     f'({samples.step:.3g} s) of 0 or across it: the lag terms take it')
    _scaled(pure, best)  # the interval on the profile that found the least
    inflation = variance_inflation(pure.residual(best))
    level = pure(best) + inflation * float(stats.chi2.ppf(0.95, 1))
    ci95 = (_crossing(pure, best, -span, level), _crossing(pure, best, span, level))
    note = (f'speed delay fitted: the speed reading lags the flow reading by {best:.3g} s '
            f'(95 % {ci95[0]:.3g} to {ci95[1]:.3g} s; {profiled} > {limit:.3g}; over the '
            f'best first-order lag alone, the {reading}, it gains {alone:.3g}, and with '
            f'that lag free {over:.3g}); the base error {rms0 / LPM:.3g} -> '
            f'{rms / LPM:.3g} l/min on the profile rows')
    return replace(said, seconds=best, fitted=True, note=note, ci95=ci95)


def _best_lag(profile: _Profile, grid: np.ndarray) -> float:
    """Return the first-order lag (> 0 of the flow reading, < 0 of the speed's) fitting best."""
    lags = np.array([v for v in grid if v])
    values = [profile(0.0, float(v)) for v in lags]
    i = int(np.argmin(values))
    lo = lags[i - 1] if i > 0 else lags[i]
    hi = lags[i + 1] if i < lags.size - 1 else lags[i]
    if lo * hi <= 0.0:  # the grid's neighbours across 0: refine on the best one's side
        lo, hi = (lags[i] / 2.0, lags[i + 1]) if lags[i] > 0 else (lags[i - 1], lags[i] / 2.0)
    found = optimize.minimize_scalar(lambda v: profile(0.0, v), bounds=(lo, hi),
                                     method='bounded', options={'xatol': 1e-3, 'maxiter': 20})
    return float(found.x) if profile(0.0, float(found.x)) < values[i] else float(lags[i])


def _joint(profile: _Profile, starts: list[tuple[float, float]], span: float,
           step: float) -> tuple[float, float]:
    """Return the (delay, lag) of the least of the profile, searched from each of `starts`."""
    def objective(x: FloatArray) -> float:
        return profile(float(x[0]), float(x[1])) if x[1] else profile(float(x[0]))

    best: tuple[float, tuple[float, float]] = (math.inf, starts[0])
    for d, lag in starts:
        simplex = np.array([(d, lag), (d + step, lag), (d, lag + step)])
        found = optimize.minimize(objective, simplex[0], method='Nelder-Mead',
                                  bounds=[(-span, span), (-span, span)],
                                  options={'initial_simplex': simplex, 'xatol': 1e-3,
                                           'fatol': 1e-2, 'maxfev': JOINT_EVALUATIONS})
        if found.fun < best[0]:
            best = (float(found.fun), (float(found.x[0]), float(found.x[1])))
    return best[1]


def _scaled(profile: _Profile, d: float, lag: float = 0.0, noise: bool = False) -> bool:
    """
    Fix the profile's scale from its least-squares residual at `d` (and `lag`).

    One robust spread for every row; with `noise`, each row's noise (:mod:`.noise`: a
    floor, and a part that grows with how fast the flow changes, the timing jitter of the
    readings), so a recording's fast moves weigh by what they can tell.
    """
    profile.scale, profile.seen = 0.0, {}
    r = profile.residual(d, lag)
    if noise:
        profile.scale = noise_model(r, profile.flow, len(profile.fixed) + 1, 1e-6 * LPM,
                                    profile.rates)
    else:
        profile.scale = MAD * float(np.median(np.abs(r - np.median(r))))
    return bool(np.all(profile.scale > 0.0))


def _crossing(profile: _Profile, best: float, end: float, level: float) -> float:
    """Return the delay where the profile crosses `level` between `best` and `end`."""
    if not profile(end) > level:
        return end
    return float(optimize.brentq(lambda d: profile(d) - level, min(best, end), max(best, end),
                                 xtol=1e-3, maxiter=40))


__all__ = ['ALPHA', 'DelayFit', 'fit_delay', 'kept', 'shifted']
