# SPDX-License-Identifier: Apache-2.0
"""
Four-quadrant operation: signed flow, speed and pressure drop over a model at magnitudes.

One rule, for every motor family (doc/quadrants.md): positive flow enters port A,
dp = p_a - p_b, and every volumetric loss runs from the higher- to the lower-pressure
port, so that

    Q = q_t n + sign(dp) Q_vl(|n|, |dp|)

with Q_vl the family's loss at the magnitudes. Mirroring by s = sign(dp) (the sign of
the flow or speed where dp = 0) turns every point into one with dp >= 0 and the loss
running forward: a shaft that turns with the flow there (n' >= 0) is the motor mode
the families already compute; a shaft turned against it (n' < 0) is pump mode,
Q' = -(q_t |n'| - Q_vl), solved here with the model's checked solver on the
family's own single-point path at a chamber drop. The channel drop of eq. (35) runs
with the flow, dp_i = dp - sign(Q) dp_ich(|Q|): in pump mode the chambers deliver the
port's pressure rise plus the channels' drop.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
import math
from typing import Protocol

import numpy as np

from satmotor_ros.model._typing import FloatArray, Real
from satmotor_ros.model.coefficients import MotorGeometry
from satmotor_ros.model.engine.point import invalid_point
from satmotor_ros.model.engine.screening import (CHECK, check_errors, FLOW_ATOL, numbers,
                                                 raise_first, raise_invalid, SPEED_SOLVE)
from satmotor_ros.model.engine.solve import solve_increasing_scalar, Tolerance, with_secant_slope
from satmotor_ros.model.errors import InvalidInputError
from satmotor_ros.model.results import (COMPONENTS, from_table, INVALID, OperatingPoints, Point,
                                        PointStatus)

Channels = Mapping[str, float] | None
_INVALID = int(INVALID)
_STALLED = int(PointStatus.STALLED)
_CHANNEL_LIMITED = int(PointStatus.CHANNEL_LIMITED)
_EXTRAPOLATED = int(PointStatus.EXTRAPOLATED)
_NO_ROOT = int(PointStatus.NO_ROOT)
_NOT_CONVERGED = int(PointStatus.NOT_CONVERGED)
_INF = math.inf
_EXPANSIONS = 80
"""Doublings of the speed bracket of a pump-mode solve before it is flagged NO_ROOT."""
_FLOW_SOLVE = Tolerance(FLOW_ATOL, 1e-13, CHECK, maxiter=200)
_SPEED_SOLVE = SPEED_SOLVE._replace(maxiter=200)
UNITS = {'flow': ('m^3/s', 'Pa'), 'speed': ('rad/s', 'Pa')}


class Magnitudes(Protocol):
    """A motor family's single-point path at magnitudes (dp >= 0, the loss running forward)."""

    qt: float  # theoretical displacement q_t [m^3/rad]

    def speed(self, flow: float, dp: float, port: bool, p_ex: float, channels: Channels,
              reverse: bool, negative: bool) -> Point:
        """Return n(Q, dp) in motor mode, Q >= 0 (shaft backwards, dp < 0 before mirroring)."""

    def absorbency(self, speed: float, dp: float, port: bool, p_ex: float,
                   flow_guess: float | None, channels: Channels, reverse: bool,
                   negative: bool) -> Point:
        """Return Q(n, dp) in motor mode, n >= 0."""

    def channel_drop(self, p_ex: float, channels: Channels) -> Callable[[float], float]:
        """Return Q >= 0 -> the channel drop of eq. (35) at these conditions, [Pa]."""


def mirror(point: Point, s: float) -> Point:
    """
    Return a point of the mirrored frame in the signed one: every field times `s`.

    Parameters
    ----------
    point : Point
        A point computed with dp >= 0, [-]
    s : float
        +1 or -1, the sign of the port drop (of the flow or speed where it is 0), [-]

    Returns
    -------
    Point
        Flow, speed, drops and every loss component with the sign of the quadrant.

    """
    if s > 0.0 or point.status & _INVALID:
        return point
    return Point._make((*(-v for v in point[:12]), point.status))


def direction(dp: Real, other: Real) -> Real:
    """
    Return the sign the losses run with: that of dp, or of the flow or speed where dp = 0.

    The one quadrant rule, for a Python float and an array alike (where dp is NaN, the
    sign of `other` too).

    Parameters
    ----------
    dp : float or ndarray
        Pressure drop p_a - p_b (port or chamber), [Pa]
    other : float or ndarray
        The given flow or speed, [m^3/s] or [rad/s]

    Returns
    -------
    float or ndarray
        +1.0 or -1.0.

    """
    forward, backward = dp > 0.0, dp < 0.0
    return (1.0 * forward - 1.0 * backward
            + (1.0 - forward - backward) * (1.0 - 2.0 * (other < 0.0)))


def odd_drop(drop: Callable[[float], float], flow: float) -> float:
    """Return the channel drop along a flow of either sign: sign(Q) dp_ich(|Q|), [Pa]."""
    return drop(flow) if flow >= 0.0 else -drop(-flow)


class Quadrants:
    """
    The signed single-point maps of a motor over its family's maps at magnitudes.

    Parameters
    ----------
    magnitudes : Magnitudes
        The family's single-point path with the model's effects, [-]

    """

    def __init__(self, magnitudes: Magnitudes) -> None:
        """Keep the maps at magnitudes."""
        self.maps = magnitudes
        self.qt = magnitudes.qt

    def speed(self, flow: float, dp: float, port: bool, p_ex: float,
              channels: Channels) -> Point:
        """
        Compute n(Q, dp) for any signs of Q and dp.

        Parameters
        ----------
        flow : float
            Flow entering port A, [m^3/s]
        dp : float
            p_a - p_b at the ports if `port`, else in the chambers, [Pa]
        port : bool
            Whether `dp` is between the ports, [-]
        p_ex : float
            Pressure driving the external leakage, eq. (24), [Pa]
        channels : mapping or None
            Measured channels the effects read, [-]

        Returns
        -------
        Point
            Q and the losses at n, signed.

        """
        if not (abs(flow) < _INF and abs(dp) < _INF):  # flagged NOT_FINITE at the magnitudes
            return self.maps.speed(abs(flow), abs(dp), port, p_ex, channels, False, False)
        s = direction(dp, flow)
        q, d = s * flow, s * dp
        if q >= 0.0:  # the flow runs with the pressure: motor mode, turning with s
            return mirror(self.maps.speed(q, d, port, p_ex, channels, s < 0.0, s < 0.0), s)
        return mirror(self._pump_speed(-q, d, port, p_ex, channels, s > 0.0, s < 0.0), s)

    def absorbency(self, speed: float, dp: float, port: bool, p_ex: float,
                   flow_guess: float | None, channels: Channels) -> Point:
        """
        Compute Q(n, dp) for any signs of n and dp.

        Parameters
        ----------
        speed : float
            Shaft speed, positive in the direction positive flow drives, [rad/s]
        dp : float
            p_a - p_b at the ports if `port`, else in the chambers, [Pa]
        port : bool
            Whether `dp` is between the ports, [-]
        p_ex : float
            Pressure driving the external leakage, [Pa]
        flow_guess : float or None
            Starting estimate of Q for the coupled solve, [m^3/s]
        channels : mapping or None
            Measured channels the effects read, [-]

        Returns
        -------
        Point
            The operating point, signed.

        """
        if not (abs(speed) < _INF and abs(dp) < _INF):
            return self.maps.absorbency(abs(speed), abs(dp), port, p_ex, None, channels,
                                        False, False)
        s = direction(dp, speed)
        n, d = s * speed, s * dp
        guess = None if flow_guess is None else s * flow_guess
        if n >= 0.0:
            return mirror(self.maps.absorbency(n, d, port, p_ex, guess, channels, s < 0.0,
                                               s < 0.0), s)
        return mirror(self._pump_flow(-n, d, port, p_ex, guess, channels, s > 0.0, s < 0.0), s)

    # -- pump mode, in the mirrored frame: dp >= 0, the shaft turning backwards ---------------

    def _pump_point(self, at: Point, flow: float, speed: float, dp: float | None,
                    drop: Callable[[float], float], status: int) -> Point:
        """
        Return the pump-mode point of the losses `at` (dp None: dp_i plus the channel drop).

        Always EXTRAPOLATED: the coefficients were measured on a motor, not a pump.
        """
        dp_i = at.dp_i
        if dp is None:
            dp = dp_i + odd_drop(drop, flow)
        return Point(flow, speed, dp, dp_i, *at[4:12],
                     (at.status & ~_STALLED) | status | _EXTRAPOLATED)

    def _pump_speed(self, delivered: float, d: float, port: bool, p_ex: float,
                    channels: Channels, reverse: bool, negative: bool) -> Point:
        """Solve q_t m - Q_vl(m, dp_i) = `delivered` for m > 0, the point at n = -m."""
        maps, qt = self.maps, self.qt
        drop = maps.channel_drop(p_ex, channels)
        dp_i = d + drop(delivered) if port else d

        def at(speed: float) -> Point:
            return maps.absorbency(speed, dp_i, False, p_ex, None, channels, reverse,
                                   negative)

        stall = at(0.0)
        if stall.status & _INVALID:
            return stall

        def excess(speed: float) -> float:  # below the family's floor: below the root
            point = at(speed)
            return -_INF if point.status & _INVALID else qt * speed - point.total - delivered

        lo, hi = 0.0, (delivered + stall.total) / qt
        f_hi = excess(hi)
        for _ in range(_EXPANSIONS):
            if f_hi >= 0.0 or f_hi != f_hi:
                break
            lo, hi = hi, 2.0 * hi
            f_hi = excess(hi)
        if not f_hi >= 0.0:  # the loss grows as fast as the displacement: no speed delivers it
            return invalid_point(_NO_ROOT)
        check = CHECK * delivered + FLOW_ATOL
        speed, failed = solve_increasing_scalar(with_secant_slope(excess, hi, f_hi), lo, hi,
                                                hi, _SPEED_SOLVE, check)
        point = at(speed)
        if failed or point.status & _INVALID:
            return invalid_point(failed or int(point.status & _INVALID))
        if not abs(qt * speed - point.total - delivered) <= check:
            return invalid_point(_NO_ROOT)
        return self._pump_point(point, -delivered, -speed, d if port else None, drop, 0)

    def _pump_flow(self, speed: float, d: float, port: bool, p_ex: float,
                   flow_guess: float | None, channels: Channels, reverse: bool,
                   negative: bool) -> Point:
        """Return Q = -(q_t m - Q_vl(m, dp_i)) at n = -m, dp_i from eqs. (34)-(35) if `port`."""
        maps, qt = self.maps, self.qt
        drop = maps.channel_drop(p_ex, channels)

        def at(dp_i: float) -> Point:
            return maps.absorbency(speed, dp_i, False, p_ex, None, channels, reverse,
                                   negative)

        first = at(d)
        if first.status & _INVALID:
            return first
        if not port:
            return self._pump_point(first, qt * -speed + first.total, -speed, None, drop, 0)

        def chamber(delivered: float) -> float:
            return d + odd_drop(drop, delivered)

        beyond = [0]  # the flags of a point beyond the family's limit, once one was seen

        def excess(delivered: float) -> float:  # D - g(D), g non-increasing: mirror=True
            point = at(max(chamber(delivered), 0.0))
            if point.status & _INVALID:  # beyond the family's limit: above the root
                beyond[0] = int(point.status & _INVALID)
                return _INF
            return delivered - (qt * speed - point.total)

        g0 = qt * speed - first.total  # what the pump delivers at the port drop itself
        lo, hi = (0.0, g0) if g0 >= 0.0 else (g0, 0.0)
        start = hi if flow_guess is None or not lo < -flow_guess < hi else -flow_guess
        delivered, failed = (g0, 0) if g0 == 0.0 else solve_increasing_scalar(
            with_secant_slope(excess, lo, excess(lo)), lo, hi, start, _FLOW_SOLVE,
            FLOW_ATOL, True)
        dp_i = chamber(delivered)
        point = at(max(dp_i, 0.0))
        if failed or point.status & _INVALID:  # closed on the limit: the point is beyond it
            return invalid_point(beyond[0] or failed or int(point.status & _INVALID))
        if not abs(delivered - (qt * speed - point.total)) <= CHECK * abs(delivered) + FLOW_ATOL:
            return invalid_point(beyond[0] or _NO_ROOT)
        return self._pump_point(point, -delivered, -speed, d, drop,
                                _CHANNEL_LIMITED if dp_i < 0.0 else 0)


def signed_map(point: Callable[[float, float, float], Point],
               magnitudes: Callable[..., OperatingPoints],
               first: tuple[str, object], second: tuple[str, object], p_ex: object,
               geometry: MotorGeometry, errors: str) -> OperatingPoints:
    """
    Evaluate an array map at any signs: the array map itself where every element is forward.

    Parameters
    ----------
    point : callable
        ``point(a, b, p_ex) -> Point``, the signed single-point map (without channels), [-]
    magnitudes : callable
        ``magnitudes(a, b, p_ex, errors) -> OperatingPoints``, the family's array map, [-]
    first : tuple of (str, array_like)
        Flow or speed, by name, [SI]
    second : tuple of (str, array_like)
        ``dp`` or ``dp_i``, [Pa]
    p_ex : array_like
        Pressure driving the external leakage, [Pa]
    geometry : MotorGeometry
        The motor, [-]
    errors : {'raise', 'mask'}
        Raise on the first invalid element, or keep it as NaN, [-]

    Returns
    -------
    OperatingPoints
        The points, signed.

    Raises
    ------
    InvalidInputError
        With ``errors='raise'``, naming the first invalid element and its flags.

    """
    check_errors(errors)
    a, b = numbers(first[0], first[1]), numbers(second[0], second[1])
    if not ((a < 0.0).any() or (b < 0.0).any()):  # forward motor mode: the map as it is
        return magnitudes(first[1], second[1], p_ex, errors)
    if errors == 'raise':
        for (name, _), unit, value in zip((first, second), UNITS[first[0]], (a, b)):
            bad = ~np.isfinite(value)
            if bad.any():
                raise_first(name, unit, value, bad, 'not finite', (0, value.shape))
    try:
        a, b, c = np.broadcast_arrays(a, b, numbers('p_ex', p_ex))
    except ValueError:
        msg = (f'the shapes of the arguments do not broadcast together: {first[0]} {a.shape}, '
               f'{second[0]} {b.shape}')
        raise InvalidInputError(msg) from None
    with np.errstate(invalid='ignore'):
        s = direction(b, a)
        pump = s * a < 0.0
    shape = a.shape
    forward = magnitudes(np.where(pump, 0.0, np.abs(a)), np.abs(b), c, 'mask')
    table = np.stack([forward.flow, forward.speed, forward.dp, forward.dp_i,
                      *(getattr(forward.losses, k) for k in COMPONENTS)], axis=-1)
    table = (table * s[..., None]).reshape(-1, 12)
    status = forward.status.reshape(-1).copy()
    a, b, c = a.reshape(-1), b.reshape(-1), c.reshape(-1)
    for i in np.flatnonzero(pump):
        p = point(float(a[i]), float(b[i]), float(c[i]))
        table[i], status[i] = p[:12], p.status
    if errors == 'raise':
        raise_invalid(status, (first[0], second[0]), (a, b))
    return from_table(table, status, shape, geometry)


def chamber_drop(drop: Callable[[FloatArray], FloatArray], dp: FloatArray,
                 flow: FloatArray) -> FloatArray:
    """
    Return the chamber drop of eqs. (34)-(35) for flows of either sign, [Pa].

    Parameters
    ----------
    drop : callable
        Q >= 0 -> the channel drop of eq. (35), [Pa]
    dp : ndarray
        p_a - p_b at the ports, [Pa]
    flow : ndarray
        Flow entering port A, [m^3/s]

    Returns
    -------
    ndarray
        dp - sign(Q) dp_ich(|Q|), unclipped, [Pa]

    """
    return dp - np.sign(flow) * drop(np.abs(flow))
