# SPDX-License-Identifier: Apache-2.0
"""
Valves across the ports: a flow that bypasses the motor's chambers and channels.

A relief, bypass or anti-cavitation valve between ports A and B opens on the port drop
Δp = p_a - p_b, not on the chamber drop: its flow V(Δp) runs from the high- to the
low-pressure port beside the motor, so the channel drop of eq. (35) is the motor's own
flow's. The measured flow is Q = Q_m + V(Δp), Q_m the motor's (any quadrant, with every
other effect); V is added to the loss breakdown's ``total``. Given the port drop this is
explicit in both directions; given the chamber drop, the port drop follows from Q_m, and
the inverse map solves V = V(Δp(Q - V)) by a checked bracketed search. The effects are
those whose kind has :attr:`~.effects.EffectKind.bypass` (``threshold:dp``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
import math

from satmotor_ros.model.effects import Effect, kind_of
from satmotor_ros.model.engine.point import invalid_point
from satmotor_ros.model.engine.screening import CHECK, fitted_bounds, FLOW_ATOL, outside_fitted
from satmotor_ros.model.engine.solve import solve_increasing_scalar, Tolerance, with_secant_slope
from satmotor_ros.model.results import INVALID, Point, PointStatus

_INVALID = int(INVALID)
_EXTRAPOLATED = int(PointStatus.EXTRAPOLATED)
_TOLERANCE = Tolerance(0.0, 4e-16, maxiter=200)


def with_valve(point: Point, valve: float, flagged: bool) -> Point:
    """Return `point` (the motor's) with the valves' flow added to Q and Q_vl's total."""
    if point.status & _INVALID:
        return point
    status = point.status | (_EXTRAPOLATED if flagged else 0)
    return point._replace(flow=point.flow + valve, total=point.total + valve, status=status)


class Valves:
    """
    The port valves of a coefficient set, evaluated around the motor's maps.

    Parameters
    ----------
    effects : iterable of Effect
        The set's effects; those of a bypass kind are kept, [-]

    """

    def __init__(self, effects: Iterable[Effect]) -> None:
        """Keep each valve with its law and fitted range."""
        chosen = [(e, kind_of(e)) for e in effects]
        self._valves = tuple((e, kind.loss(e), fitted_bounds(e.fitted_range))
                             for e, kind in chosen if kind.bypass)

    def __bool__(self) -> bool:
        """Return whether there is a valve."""
        return bool(self._valves)

    def flow(self, dp: float) -> tuple[float, bool]:
        """
        Return the valves' flow at the port drop `dp` and whether one is read beyond its data.

        Parameters
        ----------
        dp : float
            p_a - p_b, [Pa]

        Returns
        -------
        tuple
            The flow from A to B (negative from B to A), [m^3/s], and the flag.

        """
        negative = dp < 0.0
        total, flagged = 0.0, False
        for effect, law, bounds in self._valves:
            if effect.acts(negative) and law is not None:
                total += float(law(0.0, dp))
                flagged = flagged or bool(bounds and outside_fitted(bounds, {'dp': abs(dp)}))
        return (-total if negative else total), flagged

    def absorbency(self, motor: Callable[..., Point], speed: float, port: bool, value: float,
                   p_ex: float, flow_guess: float | None, channels: object) -> Point:
        """Return Q(n, dp) = Q_m + V(dp): the motor's map `motor` plus the valves."""
        if port:
            valve, flagged = self.flow(value)
            guess = None if flow_guess is None else flow_guess - valve
            return with_valve(motor(speed, port, value, p_ex, guess, channels), valve, flagged)
        point = motor(speed, port, value, p_ex, flow_guess, channels)
        if point.status & _INVALID:
            return point
        return with_valve(point, *self.flow(point.dp))  # the port drop of the motor's flow

    def speed(self, motor: Callable[..., Point], flow: float, port: bool, value: float,
              p_ex: float, channels: object) -> Point:
        """Return n(Q, dp): the motor's inverse map `motor` at Q - V."""
        if port:
            valve, flagged = self.flow(value)
            return with_valve(motor(flow - valve, port, value, p_ex, channels), valve, flagged)
        first = motor(flow, port, value, p_ex, channels)
        if first.status & _INVALID:
            return first
        most = self.flow(first.dp)[0]
        if most == 0.0:
            return first
        s = 1.0 if most > 0.0 else -1.0

        def opened(m: float) -> Point:
            return motor(flow - s * m, port, value, p_ex, channels)

        def excess(m: float) -> float:  # m - G(m), G non-increasing: the mirrored search
            point = opened(m)
            return math.inf if point.status & _INVALID else m - s * self.flow(point.dp)[0]

        check = CHECK * abs(flow) + FLOW_ATOL
        hi = abs(most)
        m, failed = solve_increasing_scalar(with_secant_slope(excess, hi, excess(hi)), 0.0, hi,
                                            hi, _TOLERANCE, check, True)
        point = opened(m)
        if failed or point.status & _INVALID:
            return invalid_point(failed or int(point.status & _INVALID))
        valve, flagged = self.flow(point.dp)
        if not abs(s * m - valve) <= check + CHECK * abs(valve):
            return invalid_point(int(PointStatus.NOT_CONVERGED))
        return with_valve(point, s * m, flagged)


__all__ = ['Valves', 'with_valve']
