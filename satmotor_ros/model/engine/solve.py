# SPDX-License-Identifier: Apache-2.0
"""
The model's one root solver: bracketed Newton with a checked residual, on floats or arrays.

:func:`solve_increasing_scalar` (one point, Python floats, a few hundred
nanoseconds an iteration) and :func:`solve_increasing` (whole arrays, element by
element) run the same algorithm step for step:

1. evaluate f and df/dx at the estimate and narrow the bracket [lo, hi] to the
   side the root is on (with ``mirror``, also to ``x - f``, see below); stop
   at an exact root, or at a NaN residual (NO_ROOT);
2. end on a Newton step that stays in the bracket and is below the tolerance
   (it leaves an error of the order of its square), or whose error, predicted
   from the curvature the last two Newton evaluations show, is a thousandth
   of the tolerance, provided that curvature also explains the residual here
   (a jump does not pass: its pieces are straight);
3. otherwise take the Newton step if it stays in the bracket and does not go
   back to the point evaluated before (as it would across a jump); else stop
   if the bracket is narrower than the tolerance, accepted only if
   ``|f| <= check`` there (else it closed on a jump: NO_ROOT), or bisect.

Every result carries a status: 0, ``NOT_CONVERGED`` (the iterations ran out) or
``NO_ROOT`` (a NaN residual, or a bracket that closed with a residual beyond
``check``), as :class:`~satmotor_ros.model.results.PointStatus` flags. Nothing
here knows the motor: callers pass the residual of their own equations.
"""

from __future__ import annotations

from collections.abc import Callable
import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.results import PointStatus

_NO_ROOT = int(PointStatus.NO_ROOT)
_NOT_CONVERGED = int(PointStatus.NOT_CONVERGED)
_NAN = math.nan
CURVATURE_MARGIN = 1e-3
"""Predicted error, as a share of the tolerance, below which a Newton step ends the solve."""


class Tolerance(NamedTuple):
    """When a solve is done, and how large a residual a closed bracket may leave."""

    xtol: float  # done once the bracket or the last Newton step is below xtol ... [x]
    rtol: float = 0.0  # ... plus rtol |x| [-]
    check_rtol: float = 0.0  # a closed bracket may leave |f| <= check + check_rtol |x| [f/x]
    maxiter: int = 60  # iteration limit [-]


def solve_increasing_scalar(func: Callable[[float], tuple[float, float]], lo: float,
                            hi: float, x: float, tol: Tolerance, check: float = math.inf,
                            mirror: bool = False) -> tuple[float, int]:
    """
    Find x in [lo, hi] with f(x) = 0 for an increasing f, on Python floats.

    Parameters
    ----------
    func : callable
        Returns f(x) and df/dx, [f], [f/x]
    lo : float
        Lower end of the bracket, f(lo) <= 0, [x]
    hi : float
        Upper end, f(hi) >= 0; may be inf with `mirror`, [x]
    x : float
        Starting estimate inside the bracket, [x]
    tol : Tolerance
        When the solve is done, [-]
    check : float
        Largest |f| accepted where the bracket closes (plus ``tol.check_rtol |x|``), [f]
    mirror : bool
        f(x) = x - g(x) with g non-increasing: then g(x) = x - f(x) bounds the
        root from the other side, [-]

    Returns
    -------
    x : float
        The root estimate, [x]
    status : int
        0, or the NOT_CONVERGED / NO_ROOT flag.

    Examples
    --------
    >>> x, status = solve_increasing_scalar(lambda x: (x * x - 2.0, 2.0 * x), 0.0, 2.0, 2.0,
    ...                                     Tolerance(1e-14))
    >>> round(x, 12), status
    (1.414213562373, 0)

    """
    xtol, rtol, check_rtol, maxiter = tol
    if hi - lo <= xtol + rtol * (x if x >= 0.0 else -x):
        return x, 0
    last_x = last_slope = nan = _NAN
    margin = CURVATURE_MARGIN
    for _ in range(maxiter):
        f, slope = func(x)
        if f < 0.0:
            lo = x
            if mirror and x - f < hi:
                hi = x - f
        elif f > 0.0:
            hi = x
            if mirror and x - f > lo:
                lo = x - f
        else:
            return x, (0 if f == 0.0 else _NO_ROOT)
        band = xtol + rtol * (x if x >= 0.0 else -x)
        if slope > 0.0:  # else no usable slope: bisect
            step = f / slope
            newton = x - step
            if lo <= newton <= hi:
                size = step if step >= 0.0 else -step
                if size <= band:
                    return newton, 0
                if last_slope == last_slope:  # a curvature needs two Newton evaluations
                    moved = x - last_x if x > last_x else last_x - x
                    bend = slope - last_slope if slope > last_slope else last_slope - slope
                    if (size * bend * size <= margin * band * moved * slope
                            and (f if f > 0.0 else -f) <= bend * moved):
                        return newton, 0
                if newton != last_x:  # not back to where it was: a jump's pieces are straight
                    last_x, last_slope, x = x, slope, newton
                    continue
        if hi - lo <= band:
            return x, (0 if abs(f) <= check + check_rtol * abs(x) else _NO_ROOT)
        last_x, last_slope, x = x, nan, 0.5 * (lo + hi)
    return x, _NOT_CONVERGED


def solve_increasing(func: Callable[[FloatArray], tuple[FloatArray, FloatArray]],
                     lo: FloatArray, hi: FloatArray, x0: FloatArray, tol: Tolerance,
                     check: FloatArray | float = math.inf,
                     mirror: bool = False) -> tuple[FloatArray, npt.NDArray[np.uint8]]:
    """
    Find x in [lo, hi] with f(x) = 0 for an increasing f, element by element.

    The algorithm of :func:`solve_increasing_scalar`, run on whole arrays:
    `func` is called on every element until all are done.

    Parameters
    ----------
    func : callable
        Returns f(x) and df/dx for the whole array of estimates, [f], [f/x]
    lo : ndarray
        Lower ends of the brackets, f(lo) <= 0, [x]
    hi : ndarray
        Upper ends, f(hi) >= 0, or inf with `mirror`, [x]
    x0 : ndarray
        Starting estimates inside the brackets, [x]
    tol : Tolerance
        When an element is done, [-]
    check : float or ndarray
        Largest |f| accepted where a bracket closes, per element, [f]
    mirror : bool
        As in the scalar form, for every element, [-]

    Returns
    -------
    x : ndarray
        The root estimates, [x]
    status : ndarray of uint8
        0, or the NOT_CONVERGED / NO_ROOT flag, per element.

    Examples
    --------
    >>> x, status = solve_increasing(lambda x: (x * x - 2.0, 2.0 * x), np.array([0.0]),
    ...                              np.array([2.0]), np.array([2.0]), Tolerance(1e-14))
    >>> round(float(x[0]), 12), int(status[0])
    (1.414213562373, 0)

    """
    xtol, rtol, check_rtol, maxiter = tol
    a, b = np.array(lo, dtype=float), np.array(hi, dtype=float)
    x = np.array(x0, dtype=float)
    done = b - a <= xtol + rtol * np.abs(x)
    rejected = np.zeros(x.shape, dtype=bool)
    last_x = np.full(x.shape, np.nan)
    last_slope = np.full(x.shape, np.nan)
    first = True
    # a done element's bracket and estimate may change below: only `x` of the others is kept
    for _ in range(maxiter):
        if done.all():
            break
        f, slope = func(x)
        below, above = f < 0.0, f > 0.0
        # putmask, not copyto(where=): the sign of f is mixed, and copyto slows down on mixed masks
        if mirror:
            other = x - f
            np.putmask(b, below, np.minimum(b, other))
            np.putmask(a, above, np.maximum(a, other))
        np.putmask(a, below, x)
        np.putmask(b, above, x)
        band = np.abs(x)
        band *= rtol
        band += xtol
        with np.errstate(divide='ignore', invalid='ignore', over='ignore'):
            step = f / slope
            newton = x - step
            size = np.abs(step)
            # a slope that is not > 0 (or NaN) is not usable: bisect
            bracketed = (slope > 0.0) & (newton >= a) & (newton <= b)
            small = size <= band
            if not first:  # the curvature needs two Newton evaluations
                moved = np.abs(x - last_x)
                bend = np.abs(slope - last_slope)
                small |= ((np.abs(f) <= bend * moved)
                          & (bend * size * size <= CURVATURE_MARGIN * band * moved * slope))
            small &= bracketed
            take = small | (bracketed & (newton != last_x))  # these move to their Newton step
            exact = ~(below | above)  # f == 0, or NaN
            settled = ~done & (exact | ((b - a <= band) & ~take))
            if settled.any():  # an exact root, a NaN, or a closed bracket
                accepted = np.abs(f) <= check + check_rtol * np.abs(x)
                rejected |= settled & (np.isnan(f) | (~exact & ~accepted))
                done |= settled
        first = False
        go = ~done & ~small
        np.copyto(last_x, x, where=go)
        np.copyto(last_slope, slope, where=go)
        np.copyto(x, newton, where=~done & take)
        halve = go & ~take
        if halve.any():
            np.copyto(last_slope, np.nan, where=halve)
            np.copyto(x, 0.5 * (a + b), where=halve)
        done |= small
    status = np.where(done, np.where(rejected, np.uint8(_NO_ROOT), np.uint8(0)),
                      np.uint8(_NOT_CONVERGED))
    return x, status


def with_secant_slope(func: Callable[[float], float], x: float,
                      fx: float) -> Callable[[float], tuple[float, float]]:
    """
    Give a residual without a derivative the slope of the secant through its last evaluation.

    Parameters
    ----------
    func : callable
        f(x), increasing, [f]
    x : float
        A point already evaluated (a bracket end), [x]
    fx : float
        f there, [f]

    Returns
    -------
    callable
        x -> (f(x), secant slope) for :func:`solve_increasing_scalar`; the slope is
        NaN (bisect) where the secant is not usable.

    """
    last = [x, fx]

    def residual(x: float) -> tuple[float, float]:
        f = func(x)
        run = x - last[0]
        slope = (f - last[1]) / run if run else math.nan
        last[0], last[1] = x, f
        # an end at +-inf gives an infinite slope, whose Newton step of 0 would look converged
        return f, (slope if -math.inf < slope < math.inf else math.nan)
    return residual
