# SPDX-License-Identifier: Apache-2.0
"""
The noise of the measured flow, estimated from the residuals of a fit, and the outliers.

A flowmeter's error is usually a floor plus a share of the reading, so the
noise model is sigma_i^2 = a + b Q_i^2 (a, b >= 0), fitted to the squared
residuals that lie within a generous robust band and scaled so that the
median |residual| / sigma is what Gaussian noise gives. Points beyond
:func:`outlier_limit` standard deviations are outliers.
"""

from __future__ import annotations

import numpy as np

from satmotor_ros.model._typing import FloatArray
from scipy import optimize, special

MAD = 1.4826
"""Standard deviation of Gaussian noise per median absolute deviation, [-]."""

MIN_HETERO_POINTS = 20
"""Fewest points for a noise that grows with the flow; fewer give a constant noise."""

MAX_RATIO = 10.0
"""Largest ratio of the noisiest to the quietest point's noise the model may give, [-]."""

OUTLIER_FAMILY = 0.05
"""Chance that any point of a clean table is called an outlier, [-]."""


def robust_scale(residual: FloatArray, n_params: int = 0) -> float:
    """
    Estimate the standard deviation of zero-mean noise from residuals, robust to outliers.

    Parameters
    ----------
    residual : ndarray
        Residuals of a fit, [any unit]
    n_params : int
        Parameters the fit used (the residuals are that much smaller), [-]

    Returns
    -------
    float
        1.4826 median |residual| sqrt(N / (N - p)), [unit of the residuals]

    """
    n = residual.size
    return float(MAD * np.median(np.abs(residual)) * np.sqrt(n / max(n - n_params, 1)))


def noise_model(residual: FloatArray, flow: FloatArray, n_params: int,
                floor: float, rate: FloatArray | None = None) -> FloatArray:
    """
    Estimate each point's noise from the residuals of a fit: sigma^2 = a + b Q^2 (+ c Q'^2).

    With the rate of change of the flow (a time series' rows), a third term c (dQ/dt)^2
    carries the error of readings that are off in time by a varying amount (timing
    jitter: the spread grows with how fast the flow changes); it is not capped by
    :data:`MAX_RATIO`, and is kept only where the data ask for it (c >= 0).

    Parameters
    ----------
    residual : ndarray
        Measured minus fitted flow, [m^3/s]
    flow : ndarray
        Measured flow, [m^3/s]
    n_params : int
        Parameters of the fit, [-]
    floor : float
        Least noise (noise-free data), [m^3/s]
    rate : ndarray, optional
        Rate of change of the flow at each point, [m^3/s^2]

    Returns
    -------
    ndarray
        Noise at each point, [m^3/s]

    """
    scale = max(robust_scale(residual, n_params), floor)
    sigma = np.full(residual.size, scale)
    if residual.size >= MIN_HETERO_POINTS:
        x2 = (flow / max(float(np.max(np.abs(flow))), 1e-300)) ** 2
        r2 = np.zeros_like(x2) if rate is None else (
            rate / max(float(np.max(np.abs(rate))), 1e-300)) ** 2
        for _ in range(3):  # the band follows the noise model as it forms
            inside = np.abs(residual) <= 4.0 * sigma
            design = np.column_stack([np.ones(int(inside.sum())), x2[inside], r2[inside]])
            (a, b, c), _ = optimize.nnls(design, residual[inside] ** 2)
            if not a + b > 0.0:
                break
            a = max(a, (a + b) / MAX_RATIO ** 2)
            sigma = np.sqrt(a + b * x2 + c * r2)
    ratio = np.abs(residual) / sigma
    sigma = sigma * MAD * float(np.median(ratio)) * np.sqrt(
        residual.size / max(residual.size - n_params, 1))
    floored: FloatArray = np.maximum(sigma, floor)  # numpy types it as Any
    return floored


def outlier_limit(n: int) -> float:
    """
    Return the |residual| / sigma beyond which a point of `n` is an outlier.

    Parameters
    ----------
    n : int
        Number of points, [-]

    Returns
    -------
    float
        The Gaussian quantile that a clean table of `n` points exceeds with chance
        :data:`OUTLIER_FAMILY` (Bonferroni), at least 3.5, [-]

    """
    return max(3.5, float(special.ndtri(1.0 - 0.5 * OUTLIER_FAMILY / max(n, 1))))


def outliers(residual: FloatArray, sigma: FloatArray) -> np.ndarray:
    """
    Flag the points whose residual lies beyond :func:`outlier_limit` noise levels.

    Parameters
    ----------
    residual : ndarray
        Measured minus fitted flow, [m^3/s]
    sigma : ndarray
        Noise at each point, [m^3/s]

    Returns
    -------
    ndarray of bool
        True at an outlier.

    """
    return np.abs(residual) / sigma > outlier_limit(residual.size)
