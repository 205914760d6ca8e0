# SPDX-License-Identifier: Apache-2.0
"""
The per-sample noise of the loss residual: a floor plus a part that grows with the flow's rate.

Two readings taken a little apart in time disagree in proportion to how fast the flow
changes (on the MBARI logs 0.05 l/min at rest, several l/min while the flow ramps), so a
sample's variance is modelled as var = a + b r^2, r = |d(q_t n)/dt|. a and b are fitted to
the residual Q_vl - Q_vl,baseline of the first samples: robustly, from the median of the
squared residual in ten groups of rate (median of a chi-square with one degree of freedom
is 0.455 of its mean), by non-negative least squares on relative errors, so that the quiet
groups fix the floor a as much as the loud ones fix b (on absolute errors the loud groups
set it, and a quiet bin's variance came out 2.5 times too small: a false alarm on one quiet
bin of a clean recording). The weights 1/var only make the estimate efficient; its level and
interval do not depend on them being right (:mod:`.detector` scales by the data's own
spread). A part growing with the flow (a flowmeter's "% of reading") was tried: fitted on
flowmeters without one it moved the weights between operating points for nothing, and one
more false alarm in 100 h came of it.
"""

from __future__ import annotations

import numpy as np
from satmotor_ros.model._typing import FloatArray
from scipy.optimize import nnls

RESOLUTION = 1.0e-9
"""Least noise a flow reading is taken to have, 6e-5 l/min (far below any flowmeter's
resolution): noise-free data still give finite weights, [m^3/s]."""

CHI2_MEDIAN = 0.454936
"""Median of a chi-square variable with one degree of freedom, [-]."""

GROUPS = 10
"""Groups of rate the variance is read in."""


def fit_variance(rate: FloatArray, residual: FloatArray) -> tuple[float, float]:
    """
    Fit var = a + b rate^2 to residuals, robustly.

    Parameters
    ----------
    rate : ndarray
        |d(q_t n)/dt| at the samples, [m^3/s^2]
    residual : ndarray
        Measured minus baseline loss, [m^3/s]

    Returns
    -------
    a : float
        Variance at rest, [m^6/s^2]
    b : float
        Growth with the rate squared, [s^2]

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> r = rng.uniform(0.0, 1e-3, 20000)
    >>> a, b = fit_variance(r, rng.normal(0.0, 1.0, r.size) * np.sqrt(1e-12 + 1e-6 * r ** 2))
    >>> bool(0.8e-12 < a < 1.25e-12 and 0.8e-6 < b < 1.25e-6)
    True

    """
    ok = np.isfinite(rate) & np.isfinite(residual)
    rate, residual = rate[ok], residual[ok]
    if residual.size < 2 * GROUPS or not np.any(rate > 0):  # no rate seen: the floor alone
        var = float(np.median(residual ** 2) / CHI2_MEDIAN) if residual.size else 1.0
        return max(var, RESOLUTION ** 2), 0.0
    groups = np.array_split(np.argsort(rate), GROUPS)
    x = np.array([np.median(rate[g] ** 2) for g in groups])
    y = np.array([np.median(residual[g] ** 2) / CHI2_MEDIAN for g in groups])
    design = np.column_stack([np.ones_like(x), x])
    scale = np.max(np.abs(design), axis=0)
    scale[scale == 0] = 1.0
    weight = 1.0 / np.maximum(y, RESOLUTION ** 2)  # relative errors
    coef, _ = nnls(design / scale * weight[:, None], y * weight)
    a, b = coef / scale
    floor = float(np.min(y))
    a = max(float(a), 0.5 * floor, RESOLUTION ** 2)
    return a, max(float(b), 0.0)


__all__ = ['fit_variance']
