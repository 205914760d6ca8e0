# SPDX-License-Identifier: Apache-2.0
"""
The few numpy functions the equations need, fast on a Python float and elementwise on arrays.

Arithmetic operators and ``** 0.5`` already serve both; numpy's functions cost a
microsecond on a float, and :mod:`math`'s refuse arrays. These dispatch on the
argument's type, so that one equation function serves the single-point path and
the array maps alike.
"""

from __future__ import annotations

import math

import numpy as np

from satmotor_ros.model._typing import Real


def maximum(x: Real, floor: float) -> Real:
    """Return the larger of `x` and `floor`, elementwise; NaN stays NaN, as in numpy."""
    # one expression, so that a composition or the single-point path inlines it
    return (floor if x < floor else x) if type(x) is float else np.maximum(x, floor)


def log(x: Real) -> Real:
    """Return the natural logarithm of `x`, elementwise."""
    if type(x) is float:
        return math.log(x)
    out: Real = np.log(x)
    return out


def minimum(x: Real, ceiling: float) -> Real:
    """Return the smaller of `x` and `ceiling`, elementwise; NaN stays NaN, as in numpy."""
    if type(x) is float:
        return ceiling if x > ceiling else x
    out: Real = np.minimum(x, ceiling)
    return out
