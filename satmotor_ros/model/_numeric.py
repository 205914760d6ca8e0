# SPDX-License-Identifier: Apache-2.0
"""
The few numpy functions the equations need, fast on a Python float and elementwise on arrays.

Arithmetic operators and ``** 0.5`` already serve both; numpy's functions cost a
microsecond on a float, and :mod:`math`'s refuse arrays. These dispatch on the
argument's type, so that one equation function serves the single-point path and
the array maps alike.
"""

from __future__ import annotations

from collections.abc import Callable
import math

import numpy as np

from satmotor_ros.model._typing import Real


def maximum(x: Real, floor: float) -> Real:
    """Return the larger of `x` and `floor`, elementwise; NaN stays NaN, as in numpy."""
    if type(x) is float:
        return floor if x < floor else x
    return np.maximum(x, floor)


def log(x: Real) -> Real:
    """Return the natural logarithm of `x`, elementwise."""
    if type(x) is float:
        return math.log(x)
    return np.log(x)


def minimum(x: Real, ceiling: float) -> Real:
    """Return the smaller of `x` and `ceiling`, elementwise; NaN stays NaN, as in numpy."""
    if type(x) is float:
        return ceiling if x > ceiling else x
    return np.minimum(x, ceiling)


def maximum_for(like: Real) -> Callable[[Real, float], Real]:
    """
    Return the elementwise maximum for values of the kind of `like`, for a loop to reuse.

    The builtin :func:`max` for a float (a C call, NaN kept as the first
    argument), :func:`numpy.maximum` for an array: the choice of
    :func:`maximum` made once instead of on every call.
    """
    return max if type(like) is float else np.maximum
