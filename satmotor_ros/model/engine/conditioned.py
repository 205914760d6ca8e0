# SPDX-License-Identifier: Apache-2.0
"""
A coefficient set's effects (:mod:`.effects`) evaluated at measured channels.

Effects that change the motor build a variant of it: a viscosity from the
liquid temperature, clearances grown by wear (cached by value, so a steady
channel costs one build). Effects that add a loss to Q_vl (``channel:`` and
``term:``) are solved with eq. (36) by a bracketed root search on Python
floats whose residual is checked like every other solve of the model. Every
array map with effects is the single-point path applied element by element,
so the two agree exactly. A point that evaluates a calibrated effect outside
the data it was fitted on is flagged EXTRAPOLATED
(:func:`~satmotor_ros.model.engine.screening.outside_fitted`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace
import math

import numpy as np

from satmotor_ros.model._numeric import maximum
from satmotor_ros.model.coefficients import MotorGeometry
from satmotor_ros.model.effects import Conditions, Effect, kind_of
from satmotor_ros.model.effects._base import Loss
from satmotor_ros.model.engine.core import ModelCore
from satmotor_ros.model.engine.point import invalid_point
from satmotor_ros.model.engine.screening import (channel_limited, CHECK, check_errors,
                                                 fitted_bounds, FLOW_ATOL, outside_fitted,
                                                 raise_invalid)
from satmotor_ros.model.engine.solve import solve_increasing_scalar, Tolerance, with_secant_slope
from satmotor_ros.model.errors import ConfigError, InvalidInputError, ModelError
from satmotor_ros.model.results import from_table, INVALID, OperatingPoints, Point, PointStatus

Channels = Mapping[str, float]
_CACHE = 8
"""
Variants kept before the cache is cleared.

A steady channel (or a few alternating values) costs one build each. A channel that moves
every sample (a wear over time, a temperature) builds a variant per point whatever the
size, and a cache of thousands of live models makes each of Python's garbage collections
walk them all: 4 096 took a point of clearance wear from 37 to 118 us.
"""
_TOLERANCE = Tolerance(0.0, 4e-16, maxiter=200)  # the effects' solves, to the last bits
_EXPANSIONS = 60
_INVALID_FLAGS = int(INVALID)
_STALLED = int(PointStatus.STALLED)
_EXTRAPOLATED = int(PointStatus.EXTRAPOLATED)
_SCREENED = int(PointStatus.NOT_FINITE | PointStatus.NEGATIVE | PointStatus.BEYOND_LIMIT)


def _solve(excess: Callable[[float], float], lo: float, f_lo: float, hi: float,
           f_hi: float, check: float) -> tuple[float, bool]:
    """Find the root of an increasing `excess` in [lo, hi] (secant, bracketed), and check it."""
    start = hi - f_hi * (hi - lo) / (f_hi - f_lo)  # false position from the bracket's ends
    if not lo < start < hi:
        start = 0.5 * (lo + hi)
    x, failed = solve_increasing_scalar(with_secant_slope(excess, hi, f_hi), lo, hi, start,
                                        _TOLERANCE, check)
    return x, not failed and abs(excess(x)) <= check


def variant(bare: ModelCore, viscosity: float, growth: float, leakage: float) -> ModelCore:
    """
    Return the motor at another viscosity, with grown clearances and a worn leakage.

    Parameters
    ----------
    bare : ModelCore
        The motor as configured, [-]
    viscosity : float
        Kinematic viscosity of the liquid, [m^2/s]
    growth : float
        Growth of both axial clearances h_R and h_S, [m]
    leakage : float
        Factor on the family's leakage parts (:attr:`Family.leakage`), [-]

    Returns
    -------
    ModelCore
        The motor so changed.

    """
    g: MotorGeometry = bare.geometry
    if growth:
        g = replace(g, clearance_rotor=g.clearance_rotor + growth,
                    clearance_satellites=g.clearance_satellites + growth)
    liquid = bare.liquid
    if viscosity != liquid.kinematic_viscosity:
        liquid = replace(liquid, kinematic_viscosity=viscosity)
    spec = bare.coefficient_set
    if leakage != 1.0:
        family = bare.family
        spec = replace(spec, coefficients=family.scaled(
            spec.coefficients, dict.fromkeys(family.leakage, leakage)))
    return ModelCore(g, spec, bare.valid_range, liquid, bare.law_name)


class ConditionedModel:
    """
    The effects of a model's coefficient set, evaluated point by point.

    Parameters
    ----------
    core : ModelCore
        The motor without its effects, whose coefficient set has effects, [-]

    """

    def __init__(self, core: ModelCore) -> None:
        """Sort the effects by what they do and keep the motor without them."""
        every = [(kind_of(e), e) for e in core.coefficient_set.effects
                 if not kind_of(e).bypass]  # the port valves act beside the motor (valves.py)
        motor = [(kind, e) for kind, e in every if not kind.sensor]
        self._fitted = tuple((kind.reverse, e, fitted_bounds(e.fitted_range))
                             for kind, e in every if e.fitted_range)  # empty when none
        self.channels = tuple(sorted({c for kind, e in motor for c in kind.channels(e)}))
        self._conditioning = tuple((kind, e) for kind, e in motor
                                   if kind.reads_channel and e.regressor)
        losses = [(kind, e, kind.loss(e)) for kind, e in motor]
        # the extra losses acting in each frame: (shaft turning backwards, dp < 0)
        self._terms = {(reverse, negative): tuple(
            f for kind, e, f in losses
            if f is not None and (reverse or not kind.reverse) and e.acts(negative))
            for reverse in (False, True) for negative in (False, True)}
        self._bare = core
        self._variants: dict[tuple[float, float, float], ModelCore] = {}

    # -- conditions ------------------------------------------------------------------------

    def _channel(self, channels: Channels | None, effect: Effect, reverse: bool) -> float:
        name = kind_of(effect).channel_at(effect, reverse)
        if channels is None or name not in channels:
            given = ', '.join(channels) if channels else 'none'
            msg = (f'effect {effect.name} needs the channel {name!r} '
                   f'(channels given: {given})')
            raise ModelError(msg)
        return float(channels[name])

    def _variant(self, viscosity: float, growth: float, leakage: float) -> ModelCore:
        bare = self._bare
        if growth == 0.0 and leakage == 1.0 and viscosity == bare.liquid.kinematic_viscosity:
            return bare
        key = (viscosity, growth, leakage)
        model = self._variants.get(key)
        if model is None:
            model = variant(bare, viscosity, growth, leakage)
            if len(self._variants) >= _CACHE:
                self._variants.clear()
            self._variants[key] = model
        return model

    def conditions(self, channels: Channels | None, p_ex: float, reverse: bool = False,
                   negative: bool = False) -> tuple[ModelCore | None, float, float, int]:
        """
        Return the motor at the channels' values, p_ex, the constant extra loss and a status.

        Parameters
        ----------
        channels : mapping of str to float or None
            Measured channels by name (SI; temperature in degC), [-]
        p_ex : float
            Pressure driving the external leakage when no effect names one, [Pa]
        reverse : bool
            Whether the flow (and shaft) runs backwards: it leaves by port A, [-]
        negative : bool
            Whether dp = p_a - p_b < 0: only the effects acting there count, [-]

        Returns
        -------
        tuple
            The motor (None when the channels make it invalid), p_ex [Pa], the
            sum of the ``channel:`` losses [m^3/s] and the PointStatus flags.

        Raises
        ------
        ModelError
            When a channel an effect needs is not given.

        """
        values = [self._channel(channels, e, reverse) for _, e in self._conditioning]
        if any(not math.isfinite(v) for v in values):
            return None, p_ex, 0.0, int(PointStatus.NOT_FINITE)
        now = Conditions(self._bare.liquid.kinematic_viscosity, 0.0, p_ex, 0.0)
        for (kind, effect), x in zip(self._conditioning, values):
            if effect.acts(negative):
                now = kind.condition(effect, x, now)
        try:
            model = self._variant(now.viscosity, now.growth, now.leakage)
        except (ConfigError, OverflowError, ValueError):
            return None, now.p_ex, 0.0, int(PointStatus.BEYOND_LIMIT)
        if not math.isfinite(now.extra):
            return None, now.p_ex, 0.0, int(PointStatus.BEYOND_LIMIT)
        return model, now.p_ex, now.extra, 0

    def channel_drop(self, p_ex: float, channels: Channels | None) -> Callable[[float], float]:
        """
        Return Q -> the channel drop of eq. (35) of the motor at the channels' values, [Pa].

        Parameters
        ----------
        p_ex : float
            Pressure driving the external leakage when no effect names one, [Pa]
        channels : mapping of str to float or None
            Measured channels by name, [-]

        Returns
        -------
        callable
            The drop; NaN where the channels make the motor invalid.

        """
        model = self.conditions(channels, p_ex)[0]
        return model.eqs.channel_drop if model is not None else lambda flow: math.nan

    @staticmethod
    def _extra(speed: float, dp_i: float, constant: float, terms: tuple[Loss, ...]) -> float:
        try:
            return constant + sum(f(speed, dp_i) for f in terms) if terms else constant
        except OverflowError:
            return math.inf  # flagged BEYOND_LIMIT by _with_extra

    @staticmethod
    def _with_extra(model: ModelCore, point: Point, flow: float | None, dp: float | None,
                    extra: float, status: int) -> Point:
        """
        Return `point` with `extra` in Q_vl, and in Q when `flow` is None.

        A `dp` of None is dp_i plus the channel drop of eq. (35) at the final flow.
        """
        if point.status & _INVALID_FLAGS:
            return point
        values = point._asdict()
        total = values['total'] = point.total + extra
        q = values['flow'] = point.flow + extra if flow is None else flow
        if not (total >= 0.0 and q >= 0.0 and total < math.inf):
            # a negative or unbounded Q_vl, or flow out of the inlet: past the model
            return invalid_point(int(PointStatus.BEYOND_LIMIT))
        values['dp'] = point.dp_i + model.eqs.channel_drop(q) if dp is None else dp
        values['status'] = (point.status & ~_STALLED) | status
        return Point(**values)

    # -- maps ------------------------------------------------------------------------------

    def _flag_fitted(self, point: Point, channels: Channels | None, reverse: bool,
                     negative: bool) -> Point:
        """Return `point` flagged EXTRAPOLATED where it reads an effect outside its data."""
        if point.status & _INVALID_FLAGS:
            return point
        values = {**(channels or {}), 'flow': point.flow, 'speed': point.speed,
                  'dp_i': point.dp_i}
        if any(outside_fitted(bounds, values) for backwards, effect, bounds in self._fitted
               if (reverse or not backwards) and effect.acts(negative)):
            return point._replace(status=point.status | _EXTRAPOLATED)
        return point

    def speed_point(self, flow: float, dp: float, port: bool, p_ex: float,
                    channels: Channels | None, reverse: bool = False,
                    negative: bool = False) -> Point:
        """
        Compute the inverse map n(Q, dp) at one point with the effects.

        Parameters
        ----------
        flow : float
            Flow into the motor Q, [m^3/s]
        dp : float
            Port drop if `port`, else chamber drop, [Pa]
        port : bool
            Whether `dp` is between the ports, [-]
        p_ex : float
            Pressure driving the external leakage when no effect names one, [Pa]
        channels : mapping of str to float or None
            Measured channels by name, [-]
        reverse : bool
            Whether the shaft turns backwards (n < 0 before the magnitudes were
            taken): the effects keyed on that direction apply, [-]
        negative : bool
            Whether dp < 0 before the magnitudes were taken: the effects acting
            there apply (:attr:`Effect.direction`), [-]

        Returns
        -------
        Point
            The operating point; Q_vl holds the effects' extra loss.

        """
        point = self._speed(flow, dp, port, p_ex, channels, reverse, negative)
        return self._flag_fitted(point, channels, reverse, negative) if self._fitted else point

    def _speed(self, flow: float, dp: float, port: bool, p_ex: float,
               channels: Channels | None, reverse: bool, negative: bool) -> Point:
        model, p_ex, constant, status = self.conditions(channels, p_ex, reverse, negative)
        if model is None:
            return invalid_point(status)
        evaluator = model.point
        first = evaluator.speed(flow, dp, port, p_ex)
        terms = self._terms[reverse, negative]
        if not terms and constant == 0.0 or first.status & _SCREENED:
            return first  # no extra loss; or bad input or beyond the limit, whatever the effect
        dp_i = model.eqs.chamber_drop(dp, flow) if port else dp
        limited = int(channel_limited(dp_i))
        dp_i = maximum(dp_i, 0.0)

        def excess(n: float) -> float:
            at = evaluator.absorbency(n, dp_i, False, p_ex, None)
            return at.flow + self._extra(n, dp_i, constant, terms) - flow

        lo = model.eqs.law.floor(dp_i)
        f_lo = excess(lo)
        if f_lo != f_lo:
            return invalid_point(int(PointStatus.NO_ROOT))
        if f_lo >= 0.0:
            # eq. (39) has no answer between n = 0 and its speed floor (as in point.py),
            # unless the flow does not even cover the losses at rest: a stall
            if lo > 0.0 and not excess(0.0) >= 0.0:
                return invalid_point(int(PointStatus.NO_ROOT))
            speed, status = 0.0, _STALLED
        else:
            hi = max(2.0 * flow / model.derived.qt, 2.0 * lo, 1.0)
            f_hi = excess(hi)
            for _ in range(_EXPANSIONS):
                if not f_hi < 0.0:
                    break
                lo, f_lo, hi = hi, f_hi, 4.0 * hi
                f_hi = excess(hi)
            if not f_hi >= 0.0:
                return invalid_point(int(PointStatus.NO_ROOT))
            speed, done = _solve(excess, lo, f_lo, hi, f_hi, CHECK * abs(flow) + FLOW_ATOL)
            if not done:
                return invalid_point(int(PointStatus.NOT_CONVERGED))
            status = 0
        point = evaluator.absorbency(speed, dp_i, False, p_ex, None)
        return self._with_extra(model, point, flow, dp if port else None,
                                self._extra(speed, dp_i, constant, terms), status | limited)

    def absorbency_point(self, speed: float, dp: float, port: bool, p_ex: float,
                         flow_guess: float | None, channels: Channels | None,
                         reverse: bool = False, negative: bool = False) -> Point:
        """
        Compute the forward map Q(n, dp) at one point with the effects.

        Parameters
        ----------
        speed : float
            Shaft speed n, [rad/s]
        dp : float
            Port drop if `port`, else chamber drop, [Pa]
        port : bool
            Whether `dp` is between the ports, [-]
        p_ex : float
            Pressure driving the external leakage (no effect naming one), [Pa]
        flow_guess : float or None
            Starting estimate of Q for the coupled solve, [m^3/s]
        channels : mapping of str to float or None
            Measured channels by name, [-]
        reverse : bool
            Whether the shaft turns backwards: the effects keyed on it apply, [-]
        negative : bool
            Whether dp < 0 before the magnitudes were taken, [-]

        Returns
        -------
        Point
            The operating point; Q and Q_vl hold the effects' extra loss.

        """
        point = self._absorbency(speed, dp, port, p_ex, flow_guess, channels, reverse, negative)
        return self._flag_fitted(point, channels, reverse, negative) if self._fitted else point

    def _absorbency(self, speed: float, dp: float, port: bool, p_ex: float,
                    flow_guess: float | None, channels: Channels | None,
                    reverse: bool, negative: bool) -> Point:
        model, p_ex, constant, status = self.conditions(channels, p_ex, reverse, negative)
        if model is None:
            return invalid_point(status)
        evaluator = model.point
        first = evaluator.absorbency(speed, dp, port, p_ex, flow_guess)
        terms = self._terms[reverse, negative]
        if not terms and constant == 0.0 or first.status & _INVALID_FLAGS:
            return first
        if not port:
            return self._with_extra(model, first, None, None,
                                    self._extra(speed, dp, constant, terms),
                                    first.status & _STALLED)

        def chamber(q: float) -> float:
            out: float = maximum(model.eqs.chamber_drop(dp, q), 0.0)
            return out

        def excess(q: float) -> float:
            dp_i = chamber(q)
            at = evaluator.absorbency(speed, dp_i, False, p_ex, None)
            return q - at.flow - self._extra(speed, dp_i, constant, terms)

        q0 = first.flow
        step = abs(self._extra(speed, first.dp_i, constant, terms)) + abs(q0) * 1e-6 + 1e-12
        lo, hi = q0 - step, q0 + step
        f_lo, f_hi = excess(lo), excess(hi)
        for _ in range(_EXPANSIONS):
            if f_lo < 0.0 < f_hi:
                break
            step *= 4.0
            if not f_lo < 0.0:
                lo = q0 - step
                f_lo = excess(lo)
            if not f_hi > 0.0:
                hi = q0 + step
                f_hi = excess(hi)
        if not f_lo < 0.0 < f_hi:
            return invalid_point(int(PointStatus.NO_ROOT))
        flow, done = _solve(excess, lo, f_lo, hi, f_hi, CHECK * abs(q0) + FLOW_ATOL)
        if not done:
            return invalid_point(int(PointStatus.NOT_CONVERGED))
        dp_i = chamber(flow)
        limited = int(channel_limited(model.eqs.chamber_drop(dp, flow)))
        point = evaluator.absorbency(speed, dp_i, False, p_ex, None)
        point = self._with_extra(model, point, None, dp,
                                 self._extra(speed, dp_i, constant, terms),
                                 (point.status & _STALLED) | limited)
        return point if point.status & _INVALID_FLAGS else point._replace(flow=flow)


def points_to_array(points: list[Point], shape: tuple[int, ...], geometry: MotorGeometry,
                    names: tuple[str, ...], inputs: tuple[np.ndarray, ...],
                    errors: str) -> OperatingPoints:
    """
    Assemble single points into read-only :class:`OperatingPoints`.

    Parameters
    ----------
    points : list of Point
        The points, in C order of `shape`, [-]
    shape : tuple of int
        Broadcast shape of the inputs, [-]
    geometry : MotorGeometry
        The motor, [-]
    names : tuple of str
        Names of the inputs, for the error of ``errors='raise'``, [-]
    inputs : tuple of ndarray
        The inputs broadcast to `shape`, quoted in that error, [SI]
    errors : {'raise', 'mask'}
        Raise on the first invalid element (quoting `inputs`), or keep it as NaN, [-]

    Returns
    -------
    OperatingPoints
        The points as arrays.

    Raises
    ------
    InvalidInputError
        With ``errors='raise'``, naming the first invalid element and its flags.

    """
    table = np.array([p[:12] for p in points], dtype=float).reshape(-1, 12)
    status = np.array([p.status for p in points], dtype=np.uint8)
    if errors == 'raise':
        raise_invalid(status, names, inputs)
    return from_table(table, status, shape, geometry)


def map_points(point: Callable[..., Point], first: tuple[str, object],
               second: tuple[str, object], p_ex: object, channels: Mapping[str, object] | None,
               geometry: MotorGeometry, errors: str) -> OperatingPoints:
    """
    Evaluate a single-point function over broadcast arrays (the array maps with effects).

    Parameters
    ----------
    point : callable
        ``point(a, b, p_ex, channels) -> Point`` on floats, [-]
    first, second : tuple of (str, array_like)
        The two inputs by name (flow or speed; dp or dp_i), [SI]
    p_ex : array_like
        Pressure driving the external leakage, [Pa]
    channels : mapping of str to array_like, or None
        Measured channels by name, [-]
    geometry : MotorGeometry
        The motor the points belong to (their speed loss reads q_t), [-]
    errors : {'raise', 'mask'}
        Raise on the first invalid element, or keep it as NaN, [-]

    Returns
    -------
    OperatingPoints
        The points, each from `point`.

    """
    check_errors(errors)
    names = (first[0], second[0], 'p_ex', *(channels or {}))
    values = (first[1], second[1], p_ex, *(channels or {}).values())
    try:
        arrays = np.broadcast_arrays(*(_as_array(n, v) for n, v in zip(names, values)))
    except ValueError as err:
        msg = f'{", ".join(names)}: shapes do not broadcast ({err})'
        raise InvalidInputError(msg) from None
    shape = arrays[0].shape if arrays else ()
    flat = [a.reshape(-1).tolist() for a in arrays]
    keys = names[3:]
    points = [point(a, b, c, dict(zip(keys, rest)))
              for a, b, c, *rest in zip(*flat)] if flat[0] else []
    return points_to_array(points, shape, geometry, names, tuple(arrays), errors)


def _as_array(name: str, value: object) -> np.ndarray:
    array = np.asarray(value)
    if array.dtype.kind not in 'iuf':
        msg = f'{name} = {value!r}: expected numbers, got {array.dtype}'
        raise InvalidInputError(msg)
    return array.astype(float)
