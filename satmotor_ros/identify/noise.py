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

from collections.abc import Mapping, Sequence

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


RATE_TERMS = ('speed_lag', 'flow_lag')
"""Nuisance regressors of a time series' rows (:mod:`.transient`) that are rates of change of
the flow: the speed's times dQ/dn, and the flow reading's, [m^3/s^2]."""

ITERATIONS = 30
"""Most re-weighted fits of the noise model; it stops sooner once no point's noise moves by
more than :data:`SETTLED`, [-]."""

SETTLED = 1e-3
"""Relative change of every point's noise below which the noise model has settled, [-]."""


def rates_of(nuisance: Mapping[str, FloatArray] | None) -> tuple[FloatArray, ...]:
    """
    Return how fast the flow changes at each row, from a time series' nuisance regressors.

    Parameters
    ----------
    nuisance : mapping of str to ndarray, optional
        The rows' nuisance regressors (:data:`RATE_TERMS` among them for a time series), [SI]

    Returns
    -------
    tuple of ndarray
        The rate of change of the flow by the speed and by the flow reading (those present;
        none for steady points), [m^3/s^2]

    """
    return tuple(np.asarray(nuisance[k], dtype=float) for k in RATE_TERMS
                 if nuisance and k in nuisance)


def noise_model(residual: FloatArray, flow: FloatArray, n_params: int,
                floor: float, rates: Sequence[FloatArray] = ()) -> FloatArray:
    """
    Estimate each point's noise from the residuals of a fit: sigma^2 = a + b Q^2 (+ c_k r_k^2).

    With the rates of change of the flow (a time series' rows, :func:`rates_of`), a term
    c_k r_k^2 per rate carries the error of readings that are off in time by a varying amount
    (timing jitter between the flow and the speed readings: the spread grows with how fast
    the flow changes); it is not capped by :data:`MAX_RATIO`, and is kept only where the data
    ask for it (c_k >= 0).

    The coefficients are a non-negative least-squares fit of the squared residuals within
    four noise levels, weighted by 1 / sigma^2 (a squared residual's spread grows as its
    variance: unweighted, the few largest decide) and repeated with the band and the weights
    of the last fit until the noise settles. Started from one robust scale, the band first
    holds only the quiet points; it widens to the fast ones as the rate terms form.

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
    rates : sequence of ndarray
        Rates of change of the flow at each point (none for steady points), [m^3/s^2]

    Returns
    -------
    ndarray
        Noise at each point, [m^3/s]

    """
    scale = max(robust_scale(residual, n_params), floor)
    sigma = np.full(residual.size, scale)
    if residual.size >= MIN_HETERO_POINTS:
        drivers = [flow, *(r for r in rates if np.any(r))]
        design = np.column_stack([np.ones(residual.size)] + [
            (x / max(float(np.max(np.abs(x))), 1e-300)) ** 2 for x in drivers])
        least = (scale / MAX_RATIO) ** 2  # the quietest point's variance, at least
        for _ in range(ITERATIONS):  # the band and the weights follow the model as it forms
            inside = np.abs(residual) <= 4.0 * sigma
            weight = 1.0 / sigma[inside] ** 2  # a squared residual's spread grows as sigma^2
            coef, _ = optimize.nnls(design[inside] * weight[:, None],
                                    residual[inside] ** 2 * weight)
            if not np.sum(coef) > 0.0:
                break
            coef[0] = max(coef[0], (coef[0] + coef[1]) / MAX_RATIO ** 2, least)
            settled = np.sqrt(design @ coef)
            moved = float(np.max(np.abs(settled / sigma - 1.0)))
            sigma = settled
            if moved < SETTLED:
                break
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
