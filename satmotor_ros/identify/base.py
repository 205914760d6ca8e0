# SPDX-License-Identifier: Apache-2.0
"""
The base fits what the data identify: a family's channel drop, before any effect is tried.

A motor known by its displacement only (or a file for another motor) carries
coefficients scaled by similarity from the SM-0,75/25: for a 4.9 cm^3/rev motor the
channel drop of eq. (35) comes out at 9.4 MPa at 26 l/min, where the velocity head of
its passages gives a few tenths of an MPa. Kept fixed, such a guess makes a speed term
or a sensor gain absorb the mismatch, and the calibration names it as an effect.

So the base fits one factor f >= 0 on the coefficients the family's channel drop is
linear in (:attr:`Family.channel`: C_t and C_l of eq. (35), C_ich of eq. (27)), with
the factors of the linear parts refitted at every f (a profile), on the rows usable at
f = 0 (and, for the rows whose chambers see more than the port drop, at the range's top).
A motor-mode row whose port drop is below the channel drop at a factor stays in the
profile at that factor, with the chamber drop 0 as the engine runs it (channel-limited,
eq. (34) clamped): its loss, which the model then gives as (almost) none, counts against
the factor. Leaving such rows out would leave out exactly the rows that speak against a
large channel drop. The range is 0 to the larger of the packaged factor 1 and the
physical bound: the channel drop may not exceed the port drop (at the
:data:`PHYSICAL_QUANTILE` of the motor-mode rows, against noise). The factor is
*fitted* only where the data pin it: the profile's Huber objective at f (each row
standardised by its noise, :func:`~satmotor_ros.identify.noise.noise_model` of the residuals
at the kept value: a recording's fast moves, the noisiest rows, do not decide) must beat the
kept value's by chi2(1) at :data:`ALPHA` (its variance inflated by the correlation of
neighbouring samples of a time series), its 95 % profile interval must not span the
whole range, and its least must lie inside the range (at the range's top the data ask
for a drop at least that large, which is no estimate). Otherwise it is *kept*: the
packaged value (the bound only widens the range: a drop above the port drop is a
channel-limited point the engine runs, so capping the guess there is not the data's
call; when the kept drop leaves out most of a direction, :func:`emptied` says so); where the
data refute the packaged value but are least at no drop (a bound, not an estimate
either), the largest drop they accept (the top of the 95 % interval). The rows are read
without the channel drop (:func:`open_channels`), so the samples below the guessed drop
reach the profile. Every other nonlinear coefficient of the family (the exponents of
Table 1, the clearance law) is kept, as the data cannot separate it from the linear
factors (:mod:`.fit`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields, replace
import math
from typing import Any

import numpy as np
from satmotor_ros.identify.coverage import DIRECTIONS
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.fit import HUBER, huber_rho
from satmotor_ros.identify.noise import noise_model, rates_of
from satmotor_ros.identify.parts import loss_parts, NO_EFFECT
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import variance_inflation
from satmotor_ros.model import MotorModel, MotorSpec
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.families.defaults import DEFAULTS_NOTE
from satmotor_ros.model.units import LPM, MPA
from scipy import optimize, stats

ALPHA = 0.01
"""Level at which the fitted factor must beat the kept one, [-]."""

PHYSICAL_QUANTILE = 0.05
"""Share of the motor-mode rows whose port drop may fall below the channel drop (noise), [-]."""

GRID = 8
"""Log-spaced factors the profile starts from (beside 0 and the kept value), [-]."""

MIN_ROWS = 12
"""Fewest rows usable over the whole range of the factor for it to be fitted, [-]."""

EDGE = 1e-3
"""Share of the range within which a factor counts as at the range's end, [-]."""

EMPTIED = 'a direction emptied'
"""How the warning begins that the channel drop left out most of a direction's samples."""

EMPTIED_SHARE = 0.5
"""Share of a direction's samples whose loss to the channel drop is warned of, [-]."""

IRLS_STEPS = 6
"""Reweighted least-squares steps of the Huber fit of the linear factors at each factor, [-]."""


@dataclass(frozen=True)
class BaseFit:
    """What the base fitted and kept, and the motor it leaves the calibration with."""

    spec: MotorSpec  # the motor with the fitted (or kept) channel coefficients
    fitted: tuple[dict[str, Any], ...]  # {'coefficient', 'value', 'packaged', 'ci95', ...}
    kept: tuple[dict[str, Any], ...]  # {'coefficient', 'value', 'why'}
    channel_drop: dict[str, Any]  # the drop at the largest flow, packaged and as used
    note: str  # one sentence for the report

    @property
    def changed(self) -> bool:
        """Return whether the motor differs from the one given."""
        return bool(self.fitted) or self.channel_drop['factor'] != 1.0

    def as_dict(self) -> dict[str, Any]:
        """Return the record ``calibration.json`` holds under ``base``."""
        return {'fitted': list(self.fitted), 'kept': list(self.kept),
                'channel_drop': self.channel_drop, 'note': self.note}


def guessed(spec: MotorSpec) -> bool:
    """Return whether the coefficients are a family's defaults scaled by similarity to a size."""
    return spec.name.endswith(DEFAULTS_NOTE)


def open_channels(spec: MotorSpec, liquid: str) -> MotorSpec:
    """
    Return the motor without its channel drop when the base is to fit it (else as given).

    The rows the base profiles are read at the smallest factor, 0: read at the packaged
    drop, the samples whose port drop is below it, which speak against it, would be gone.
    """
    if not guessed(spec) or liquid not in spec.sets:
        return spec
    model = MotorModel.from_spec(spec, liquid)
    names = tuple(n for n in model.family.channel if getattr(model.coef, n) > 0.0)
    return _with_factor(spec, liquid, names, 0.0) if names else spec


def emptied(model: MotorModel, table: BenchTable, base: BaseFit) -> str | None:
    """
    Say when the model's channel drop leaves out most of a direction's samples.

    A sample is left out where the channels take more than its port drop (the chamber drop
    of eq. (34) below 0 at its flow).

    Parameters
    ----------
    model : MotorModel
        The model the calibration goes on with (its channel drop fitted or kept), [-]
    table : BenchTable
        The data as read, every sample, [-]
    base : BaseFit
        What the base fitted or kept, [-]

    Returns
    -------
    str or None
        The warning (beginning :data:`EMPTIED`), naming the count and the reason.

    """
    dp, flow = table.dp, table.flow
    with np.errstate(invalid='ignore'):
        finite = np.isfinite(dp) & np.isfinite(flow) & np.isfinite(table.speed)
        below = finite & (np.sign(dp) * model.chamber_drop(dp, flow) < 0.0)
    lost = []
    for name, sign in DIRECTIONS:
        way = finite & (np.sign(dp) == sign)
        count = int((below & way).sum())
        if way.any() and count > EMPTIED_SHARE * int(way.sum()):
            lost.append(f'{count} of {int(way.sum())} samples with a {name} drop')
    if not lost:
        return None
    drop = base.channel_drop
    at = (f' ({drop["used_mpa"]:.3g} MPa at {drop["flow_lpm"]:.3g} l/min)'
          if 'used_mpa' in drop else '')
    return (f'{EMPTIED}: {" and ".join(lost)} left out, their port drop below the channel '
            f'drop{at} ({base.note}): the fit does not speak for them')


def _with_factor(spec: MotorSpec, liquid: str, names: tuple[str, ...],
                 factor: float) -> MotorSpec:
    """Return `spec` with the coefficients `names` of `liquid`'s set times `factor`."""
    chosen = spec.sets[liquid]
    coef = chosen.coefficients
    coef = replace(coef, **{n: getattr(coef, n) * factor for n in names})
    return replace(spec, sets={**spec.sets, liquid: replace(chosen, coefficients=coef)})


def _kept_others(model: MotorModel, names: tuple[str, ...]) -> list[dict[str, Any]]:
    """Name every other nonlinear coefficient of the family, kept as the file gives it."""
    linear = {c for part in model.family.linear_parts(model.coef) for c in part.coefficients}
    return [{'coefficient': f.name, 'value': float(getattr(model.coef, f.name)),
             'why': 'not separable from the linear factors by Q, n and dp'}
            for f in fields(model.coef) if f.name not in linear and f.name not in names]


def _physical_bound(model: MotorModel, points: BenchTable) -> float:
    """Return the largest factor whose channel drop stays below the port drop in motor mode."""
    flow, dp = points.flow, points.dp
    motor = (flow * dp > 0.0) & (flow * points.speed > 0.0)
    drop = np.asarray(model.equations.channel_drop(np.abs(flow[motor])), dtype=float)
    ratio = np.abs(dp[motor]) / np.where(drop > 0.0, drop, np.nan)
    ratio = ratio[np.isfinite(ratio)]
    return float(np.quantile(ratio, PHYSICAL_QUANTILE)) if ratio.size else math.inf


class _Profile:
    """The base's Huber objective as a function of the channel factor, on fixed rows."""

    def __init__(self, spec: MotorSpec, liquid: str, names: tuple[str, ...],
                 points: BenchTable, nuisance: Mapping[str, FloatArray]) -> None:
        self.spec, self.liquid, self.names = spec, liquid, names
        self.points, self.nuisance = points, nuisance
        self.scale: FloatArray | None = None  # each row's noise, once estimated [m^3/s]
        self.seen: dict[float, float] = {}

    def residual(self, factor: float) -> FloatArray:
        """Return the base's residual at `factor`: the linear factors by Huber IRLS, [m^3/s]."""
        model = MotorModel.from_spec(_with_factor(self.spec, self.liquid, self.names, factor),
                                     self.liquid)
        parts, usable = loss_parts(model, self.points, clamp=True)
        if not usable.all():
            raise IdentificationError('a row left the usable range inside the profile')
        columns = [c.flow(NO_EFFECT) for c in parts.components]
        x = np.column_stack(columns + [np.asarray(v, dtype=float)
                                       for v in self.nuisance.values()])
        y = parts.loss
        precision = np.ones(y.size) if self.scale is None else 1.0 / self.scale ** 2
        weight = precision
        # each column to unit norm: the terms' units differ by 10^18 (a flow, a pressure
        # rate), and lstsq's cut-off would drop a small singular value at some factors only
        norm = np.linalg.norm(x, axis=0)
        x = x / np.where(norm > 0.0, norm, 1.0)
        for _ in range(IRLS_STEPS if self.scale is not None else 1):
            root = np.sqrt(weight)
            beta = np.linalg.lstsq(x * root[:, None], y * root, rcond=None)[0]
            r = y - x @ beta
            if self.scale is not None:
                z = np.abs(r) / self.scale
                weight = precision * np.where(z <= HUBER, 1.0, HUBER / np.maximum(z, 1e-300))
        return np.asarray(r, dtype=float)

    def __call__(self, factor: float) -> float:
        """Return the Huber objective (2 rho of the standardised residuals) at `factor`."""
        factor = float(factor)
        if factor not in self.seen:
            try:
                z = np.abs(self.residual(factor)) / (LPM if self.scale is None else self.scale)
                self.seen[factor] = float(np.sum(huber_rho(z)))
            except (IdentificationError, np.linalg.LinAlgError):
                self.seen[factor] = math.inf
        return self.seen[factor]


def fit_base(spec: MotorSpec, liquid: str, points: BenchTable,
             nuisance: Mapping[str, FloatArray] | None = None) -> BaseFit:
    """
    Fit the family's channel drop where the data pin it; keep it, and say so, where not.

    Parameters
    ----------
    spec : MotorSpec
        The motor (its family's coefficients for `liquid`), [-]
    liquid : str
        Coefficient set, [-]
    points : BenchTable
        The rows the calibration fits (steady points or a recording's bins), [-]
    nuisance : mapping of str to ndarray, optional
        Regressors fitted beside the factors at every row of `points` (a
        transient recording's terms), [SI]

    Returns
    -------
    BaseFit
        The motor to calibrate further and what was fitted and kept.

    """
    model = MotorModel.from_spec(spec, liquid)
    names = tuple(n for n in model.family.channel if getattr(model.coef, n) > 0.0)
    others = _kept_others(model, model.family.channel)
    if not guessed(spec):
        kept = [{'coefficient': n, 'value': float(getattr(model.coef, n)),
                 'why': "the motor's own (not scaled by similarity)"}
                for n in model.family.channel]
        return BaseFit(spec, (), tuple(kept + others), {'factor': 1.0},
                       "the channel drop is kept: the motor's own coefficients, not a guess "
                       'scaled by similarity')
    top = float(np.max(np.abs(points.flow))) if len(points) else 0.0
    packaged_drop = float(model.equations.channel_drop(top)) if top > 0.0 else 0.0

    def result(factor: float, fitted: list[dict[str, Any]], kept: list[dict[str, Any]],
               note: str) -> BaseFit:
        used = _with_factor(spec, liquid, names, factor) if factor != 1.0 else spec
        drop = {'flow_lpm': top / LPM, 'packaged_mpa': packaged_drop / MPA,
                'used_mpa': packaged_drop * factor / MPA, 'factor': factor}
        return BaseFit(used, tuple(fitted), tuple(kept + others), drop, note)

    if not names or top <= 0.0:
        kept = [{'coefficient': n, 'value': float(getattr(model.coef, n)),
                 'why': 'no channel drop to fit'} for n in model.family.channel]
        return result(1.0, [], kept, 'the channel drop is kept: the model has none to fit')
    bound = _physical_bound(model, points)
    # not pinned, the guess stands: the rows below its drop were weighed in the profile (a
    # drop above the port drop is a channel-limited point the engine runs, not beyond physics)
    kept_factor, why_kept = 1.0, 'the packaged value'
    if not math.isfinite(bound):
        return _kept(result, names, model, kept_factor, 'no motor-mode row bounds it')
    top_factor = max(1.0, bound)
    rows = _rows(spec, liquid, names, points, top_factor)
    profile = _Profile(spec, liquid, names, points.select(rows) if not rows.all() else points,
                       {k: np.asarray(v)[rows] for k, v in (nuisance or {}).items()})
    if int(rows.sum()) < MIN_ROWS:
        return _kept(result, names, model, kept_factor, 'too few rows usable over the range')
    try:
        residual = profile.residual(kept_factor)
    except (IdentificationError, np.linalg.LinAlgError) as err:
        return _kept(result, names, model, kept_factor, f'the base cannot be fitted ({err})')
    # each row weighed by its noise (:mod:`.noise`): a recording's fast moves do not decide
    profile.scale = noise_model(residual, points.flow[rows], 1 + len(profile.nuisance),
                                1e-6 * LPM, rates_of(profile.nuisance))
    best = _minimum(profile, top_factor, kept_factor)
    inflation = variance_inflation(profile.residual(best)) if points.time_series else 1.0
    gain = (profile(kept_factor) - profile(best)) / inflation
    limit = float(stats.chi2.ppf(1.0 - ALPHA, 1))
    low, high = 0.0, top_factor
    if gain > limit:  # the interval only matters for a factor that may be fitted
        low, high = _interval(profile, best, top_factor, profile(best)
                              + inflation * float(stats.chi2.ppf(0.95, 1)))
    spans = low <= top_factor * EDGE and high >= top_factor * (1.0 - EDGE)
    at_top = best >= top_factor * (1.0 - EDGE)
    if gain <= limit or spans or at_top:
        why = (f'the data do not pin it (profile: chi2 gain {gain:.3g} <= {limit:.3g}, '
               if gain <= limit else 'the 95 % profile interval spans the whole range ('
               if spans else 'the profile is least at the top of the range (')
        return _kept(result, names, model, kept_factor,
                     f'{why}factor range 0-{top_factor:.3g}); kept at {why_kept}')
    if best <= top_factor * EDGE:  # least at no drop: a bound, not an estimate
        return _kept(result, names, model, high,
                     f'the data refute the packaged drop (profile: chi2 gain {gain:.3g} > '
                     f'{limit:.3g}) and are least at no drop, a bound, not an estimate; kept at '
                     f'the largest the data accept, the top of the 95 % profile interval '
                     f'(factor 0-{high:.3g}, range 0-{top_factor:.3g})')
    open_top = high >= top_factor * (1.0 - EDGE)
    fitted = [{'coefficient': n, 'value': float(getattr(model.coef, n)) * best,
               'packaged': float(getattr(model.coef, n)),
               'ci95': [float(getattr(model.coef, n)) * low, float(getattr(model.coef, n)) * high],
               'factor': best, 'bounds': [0.0, float(getattr(model.coef, n)) * top_factor]}
              for n in names]
    note = (f'channel drop fitted: {packaged_drop * best / MPA:.3g} MPa at {top / LPM:.3g} '
            f'l/min (packaged {packaged_drop / MPA:.3g} MPa; factor {best:.3g}, 95 % '
            f'{low:.3g}-{high:.3g}{" (open: the top of the range)" if open_top else ""}, '
            f'range 0-{top_factor:.3g}, physical bound {bound:.3g})')
    return result(best, fitted, [], note)


def _kept(result: Callable[[float, list[dict[str, Any]], list[dict[str, Any]], str], BaseFit],
          names: tuple[str, ...], model: MotorModel, factor: float, why: str) -> BaseFit:
    kept = [{'coefficient': n, 'value': float(getattr(model.coef, n)) * factor, 'why': why}
            for n in names]
    return result(factor, [], kept, f'channel drop kept: {why}')


def _rows(spec: MotorSpec, liquid: str, names: tuple[str, ...], points: BenchTable,
          top: float) -> np.ndarray:
    """
    Return the rows usable, the chamber drop clamped at 0, over the factor's range 0 to `top`.

    A motor-mode row's chamber drop falls with the factor (clamped, it stays usable); a
    row whose chambers see more than the port drop (a pump's) may leave the model's limit
    at `top`: the rows usable at both ends are usable at every factor between.
    """
    usable = np.ones(len(points), dtype=bool)
    for factor in (0.0, top):
        at = MotorModel.from_spec(_with_factor(spec, liquid, names, factor), liquid)
        try:
            usable &= loss_parts(at, points, clamp=True)[1]
        except IdentificationError:
            return np.zeros(len(points), dtype=bool)
    return usable


def _interval(profile: _Profile, best: float, bound: float,
              level: float) -> tuple[float, float]:
    """Return the factors where the profile crosses `level` either side of `best`."""
    def crossing(end: float) -> float:
        if not profile(end) > level:
            return end
        return float(optimize.brentq(lambda f: profile(f) - level, min(best, end),
                                     max(best, end), xtol=1e-4 * max(bound, 1e-9),
                                     maxiter=30))
    return crossing(0.0), crossing(bound)


def _minimum(profile: _Profile, bound: float, kept: float) -> float:
    """Return the factor of least objective: a log grid, then a bounded search around it."""
    grid = sorted({0.0, kept, *np.geomspace(bound * 1e-3, bound, GRID)})
    values = [profile(f) for f in grid]
    i = int(np.argmin(values))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    if hi > lo:
        found = optimize.minimize_scalar(profile, bounds=(lo, hi), method='bounded',
                                         options={'xatol': 1e-3 * max(hi, 1e-9),
                                                  'maxiter': 12})
        if profile(float(found.x)) < values[i]:
            return float(found.x)
    return float(grid[i])


__all__ = ['ALPHA', 'BaseFit', 'EMPTIED', 'emptied', 'fit_base', 'guessed', 'open_channels']
