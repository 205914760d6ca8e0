# SPDX-License-Identifier: Apache-2.0
"""A vectorised, bracketed Newton solver for the model's implicit equations."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from satmotor_ros.model._typing import ArrayLike, FloatArray


def solve_increasing(func: Callable[[FloatArray], tuple[FloatArray, FloatArray]],
                     lo: FloatArray, hi: FloatArray, x0: FloatArray, xtol: ArrayLike,
                     ftol: ArrayLike = 0.0, maxiter: int = 60,
                     rtol: float = 0.0) -> tuple[FloatArray, FloatArray]:
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
        narrower than this plus `rtol` times its estimate, [x]
    ftol : ndarray or float
        ... or once its residual is this small in magnitude, [f]
    maxiter : int
        Iteration limit, [-]
    rtol : float
        Tolerance relative to the current estimate, added to `xtol`, [-]

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
    done = b - a <= xtol + rtol * np.abs(x)
    for _ in range(maxiter):
        if done.all():
            break
        f, slope = func(x)
        np.copyto(a, x, where=f < 0.0)
        np.copyto(b, x, where=f > 0.0)
        tol = xtol + rtol * np.abs(x) if rtol else xtol
        done |= (np.abs(f) <= ftol) | (b - a <= tol) | np.isnan(f)
        if done.all():
            break
        with np.errstate(divide='ignore', invalid='ignore'):
            newton = x - f / slope
        # inclusive: a step below the resolution of x lands on a bracket end (False for NaN)
        inside = (newton >= a) & (newton <= b)
        np.copyto(x, np.where(inside, newton, 0.5 * (a + b)), where=~done)
        # a Newton step this small leaves an error of its square: done without re-evaluating
        done |= inside & (np.abs(f) <= tol * slope)
    return x, done
