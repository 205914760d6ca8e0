# SPDX-License-Identifier: Apache-2.0
"""Shaft revolutions from speed: the one integration the plant, prediction and calibration use."""

from __future__ import annotations

import math
from typing import overload

import numpy as np

from satmotor_ros.model._typing import ArrayLike, FloatArray

_TWO_PI = 2.0 * math.pi


@overload
def revolutions(speed: float, dt: float, start: float = 0.0) -> float:
    ...


@overload
def revolutions(speed: FloatArray, dt: ArrayLike, start: float = 0.0) -> FloatArray:
    ...


def revolutions(speed: ArrayLike, dt: ArrayLike, start: float = 0.0) -> float | FloatArray:
    r"""
    Count the shaft revolutions turned at `speed` held for `dt`, in either direction.

    .. math:: N_k = N_0 + \frac{1}{2\pi}\sum_{j \le k} |\omega_j|\,\Delta t_j

    Wear and the ``revolutions`` channel count every turn, so the speed's sign
    does not matter. On floats this is one step (the plant, a node); on arrays
    the running sum (a recording: pass the mean speed of each interval for the
    trapezoid rule).

    Parameters
    ----------
    speed : float or ndarray
        Shaft speed over each step, [rad/s]
    dt : float or ndarray
        Length of each step, [s]
    start : float
        Revolutions before the first step, [rev]

    Returns
    -------
    float or ndarray
        Revolutions after each step, [rev]

    Examples
    --------
    >>> revolutions(2.0 * math.pi, 0.5, 1.0)
    1.5
    >>> revolutions(np.array([2.0, -2.0]) * math.pi, 1.0).tolist()
    [1.0, 2.0]

    """
    if isinstance(speed, float) and isinstance(dt, float):
        return start + abs(speed) * dt / _TWO_PI
    return start + np.cumsum(np.abs(speed) * np.asarray(dt, dtype=float)) / _TWO_PI


def sampled_revolutions(speed: FloatArray, time: FloatArray) -> FloatArray:
    """
    Count the revolutions at each sample of a recording (trapezoid rule).

    Parameters
    ----------
    speed : ndarray
        Shaft speed at each sample, [rad/s]
    time : ndarray
        Sample times, increasing, [s]

    Returns
    -------
    ndarray
        Revolutions since the first sample, [rev]

    """
    steps = revolutions(0.5 * (speed[1:] + speed[:-1]), np.diff(time))
    return np.concatenate(([0.0], steps))
