# SPDX-License-Identifier: Apache-2.0
"""A vectorised, bracketed Newton solver for the model's implicit equations."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from satmotor_ros.model._typing import FloatArray


def solve_increasing(func: Callable[[FloatArray], tuple[FloatArray, FloatArray]],
                     lo: FloatArray, hi: FloatArray, x0: FloatArray, xtol: FloatArray,
                     ftol: FloatArray = 0.0, maxiter: int = 60) -> tuple[FloatArray, FloatArray]:
    """
    Find x in [lo, hi] with f(x) = 0 for an increasing f, element by element.

    Newton's method kept inside a bracket: every evaluation narrows [lo, hi] to
    the side the root is on, and a Newton step that would leave the bracket
    (or a slope that is not positive and finite) is replaced by bisection. So
    it converges quadratically near the root and cannot diverge far from it.

    Parameters
    ----------
    func : callable
        Returns f(x) and df/dx for the whole array of estimates, [f], [f/x]
    lo, hi : ndarray
        Bracket with f(lo) <= 0 <= f(hi), [x]
    x0 : ndarray
        Starting estimates inside the bracket, [x]
    xtol : ndarray or float
        An element is done once its bracket, or its last Newton step, is
        narrower than this, [x]
    ftol : ndarray or float
        ... or once its residual is this small in magnitude, [f]
    maxiter : int
        Iteration limit, [-]

    Returns
    -------
    x : ndarray
        The root estimates, [x]
    converged : ndarray of bool
        False where `maxiter` ran out first.

    Examples
    --------
    >>> x, ok = solve_increasing(lambda x: (x * x - 2.0, 2.0 * x), np.array([0.0]),
    ...                          np.array([2.0]), np.array([2.0]), 1e-14)
    >>> round(float(x[0]), 12), bool(ok[0])
    (1.414213562373, True)

    """
    a, b = np.array(lo, dtype=float), np.array(hi, dtype=float)
    x = np.array(x0, dtype=float)
    done = b - a <= xtol
    for _ in range(maxiter):
        f, slope = func(x)
        np.copyto(a, x, where=f < 0.0)
        np.copyto(b, x, where=f > 0.0)
        done |= (np.abs(f) <= ftol) | (b - a <= xtol) | np.isnan(f)
        if done.all():
            break
        with np.errstate(divide='ignore', invalid='ignore'):
            newton = x - f / slope
        inside = (newton > a) & (newton < b)  # False for NaN: bisect instead
        np.copyto(x, np.where(inside, newton, 0.5 * (a + b)), where=~done)
        # a Newton step this small leaves an error of its square: done without re-evaluating
        done |= inside & (np.abs(f) <= xtol * slope)
    return x, done


def solve_increasing_scalar(func: Callable[[float], tuple[float, float]], lo: float, hi: float,
                            x0: float, xtol: float, ftol: float = 0.0,
                            maxiter: int = 60) -> tuple[float, bool]:
    """
    Find x in [lo, hi] with f(x) = 0 for an increasing f: one point, Python floats.

    The same bracketed Newton method as :func:`solve_increasing`, step for
    step, without numpy's per-call overhead.

    Parameters
    ----------
    func : callable
        Returns f(x) and df/dx, [f], [f/x]
    lo, hi : float
        Bracket with f(lo) <= 0 <= f(hi), [x]
    x0 : float
        Starting estimate inside the bracket, [x]
    xtol : float
        Done once the bracket, or the last Newton step, is narrower than this, [x]
    ftol : float
        ... or once the residual is this small in magnitude, [f]
    maxiter : int
        Iteration limit, [-]

    Returns
    -------
    x : float
        The root estimate, [x]
    converged : bool
        False if `maxiter` ran out first.

    Examples
    --------
    >>> x, ok = solve_increasing_scalar(lambda x: (x * x - 2.0, 2.0 * x), 0.0, 2.0, 2.0, 1e-14)
    >>> round(x, 12), ok
    (1.414213562373, True)

    """
    a, b, x = lo, hi, x0
    if b - a <= xtol:
        return x, True
    for _ in range(maxiter):
        f, slope = func(x)
        if f < 0.0:
            a = x
        elif f > 0.0:
            b = x
        if abs(f) <= ftol or b - a <= xtol or f != f:
            return x, True
        newton = x - f / slope if slope > 0.0 and slope != float('inf') else a - 1.0
        if a < newton < b:
            x = newton
            if abs(f) <= xtol * slope:
                return x, True
        else:
            x = 0.5 * (a + b)
    return x, False
