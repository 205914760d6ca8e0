# SPDX-License-Identifier: Apache-2.0
"""A vectorised, bracketed root finder for the model's implicit equations."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from satmotor_ros.model._typing import FloatArray


def solve_increasing(func: Callable[[FloatArray], FloatArray], lo: FloatArray, hi: FloatArray,
                     f_lo: FloatArray, f_hi: FloatArray, xtol: FloatArray,
                     ftol: FloatArray = 0.0, maxiter: int = 100) -> tuple[FloatArray, FloatArray]:
    """
    Find x in [lo, hi] with func(x) = 0, element by element (Illinois method).

    Regula falsi with the Illinois modification: every step stays inside the
    bracket, so it cannot diverge, and it converges superlinearly (order about
    1.44) where plain regula falsi would stall on one side.

    Parameters
    ----------
    func : callable
        Evaluates the residual for the whole array of estimates at once, [-]
    lo, hi : ndarray
        Bracket ends, lo <= hi, [x]
    f_lo, f_hi : ndarray
        func(lo) <= 0 and func(hi) >= 0, [f]
    xtol : ndarray or float
        An element is done once its bracket is narrower than this, [x]
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
    >>> x, ok = solve_increasing(lambda x: x * x - 2.0, np.array([0.0]), np.array([2.0]),
    ...                          np.array([-2.0]), np.array([2.0]), 1e-14)
    >>> round(float(x[0]), 12), bool(ok[0])
    (1.414213562373, True)

    """
    a, b = np.array(lo, dtype=float), np.array(hi, dtype=float)
    fa, fb = np.array(f_lo, dtype=float), np.array(f_hi, dtype=float)
    side = np.zeros(a.shape, dtype=np.int8)
    x = np.where(fb == 0.0, b, a)
    done = (b - a <= xtol) | (fa == 0.0) | (fb == 0.0)
    for _ in range(maxiter):
        if done.all():
            break
        span = fb - fa
        x_new = np.where(span > 0.0, b - fb * (b - a) / np.where(span > 0.0, span, 1.0),
                         0.5 * (a + b))
        x = np.where(done, x, x_new)
        fx = func(x)
        above = (fx > 0.0) & ~done
        below = (fx < 0.0) & ~done
        exact = (fx == 0.0) & ~done
        # Illinois: halve the stale end's residual when the same end moves twice in a row
        fa = np.where(above & (side == 1), 0.5 * fa, fa)
        fb = np.where(below & (side == -1), 0.5 * fb, fb)
        b, fb = np.where(above | exact, x, b), np.where(above | exact, fx, fb)
        a, fa = np.where(below | exact, x, a), np.where(below | exact, fx, fa)
        side = np.where(above, 1, np.where(below, -1, side)).astype(np.int8)
        done = done | exact | (b - a <= xtol) | (np.abs(fx) <= ftol)
    return x, done
