# SPDX-License-Identifier: Apache-2.0
"""
The per-sample noise of the loss residual: a floor, and parts that grow with rate and flow.

Two readings taken a little apart in time disagree in proportion to how fast the flow
changes (on the MBARI logs 0.05 l/min at rest, several l/min while the flow ramps), and a
flowmeter's error is partly a share of its reading (its "% of reading" class), so a sample's
variance is modelled as var = a + b r^2 + c q^2, r = |d(q_t n)/dt|, q = |q_t n + Q_vl,b| the
flow the baseline gives (not the flow read: weights that fell with the reading's own noise
would bias the leakage factor low, by 1.5 % on the MBARI trajectories).
a, b and c are fitted to the residual Q_vl - Q_vl,baseline of the first samples: robustly,
from the median of the squared residual in cells of rate and flow (median of a chi-square
with one degree of freedom is 0.455 of its mean), by non-negative least squares. Without
the reading's part, the bins at high flow of a "% of reading" flowmeter were noisier than
the model said and the detector alarmed on clean recordings about once in 15 h (1 000 h
stated). The weights 1/var only make the estimate efficient; its level and interval do not
depend on them being right (:mod:`.detector` scales by the data's own spread).
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
"""Groups of rate the variance is read in (times :data:`FLOW_GROUPS` of flow)."""

FLOW_GROUPS = 4
"""Groups of flow within each group of rate."""

CELL_SAMPLES = 20
"""Fewest samples a cell of rate and flow needs to count."""


def fit_variance(rate: FloatArray, residual: FloatArray,
                 flow: FloatArray | None = None) -> tuple[float, float, float]:
    """
    Fit var = a + b rate^2 + c flow^2 to residuals, robustly.

    Parameters
    ----------
    rate : ndarray
        |d(q_t n)/dt| at the samples, [m^3/s^2]
    residual : ndarray
        Measured minus baseline loss, [m^3/s]
    flow : ndarray, optional
        The flow at the samples (the baseline's); None: no part that grows with it, [m^3/s]

    Returns
    -------
    a : float
        Variance at rest, [m^6/s^2]
    b : float
        Growth with the rate squared, [s^2]
    c : float
        Growth with the flow squared, [-]

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> q = rng.uniform(1e-4, 1e-3, 20000)
    >>> a, b, c = fit_variance(np.zeros(q.size), rng.normal(0.0, 1e-6 + 0.01 * q), q)
    >>> bool(c > 10 * a / 1e-3 ** 2)
    True

    """
    flow = np.zeros_like(rate) if flow is None else np.abs(flow)
    ok = np.isfinite(rate) & np.isfinite(residual) & np.isfinite(flow)
    rate, residual, flow = rate[ok], residual[ok], flow[ok]
    if residual.size < 2 * GROUPS:
        var = float(np.median(residual ** 2) / CHI2_MEDIAN) if residual.size else 1.0
        return max(var, RESOLUTION ** 2), 0.0, 0.0
    rows = []
    for group in np.array_split(np.argsort(rate), GROUPS):
        cells = np.array_split(group[np.argsort(flow[group])], FLOW_GROUPS)
        for cell in cells if cells[-1].size >= CELL_SAMPLES else [group]:
            rows.append((np.median(rate[cell] ** 2), np.median(flow[cell] ** 2),
                         np.median(residual[cell] ** 2) / CHI2_MEDIAN, cell.size))
    x_rate, x_flow, y, count = (np.array(col, dtype=float) for col in zip(*rows))
    # scale the columns to 1 so the solver's tolerance means the same for each
    design = np.column_stack([np.ones_like(y), x_rate, x_flow])
    scale = np.max(np.abs(design), axis=0)
    scale[scale == 0] = 1.0
    # relative errors: the quiet cells (low flow, at rest) fix the floor a as much as the
    # loud ones fix b and c; absolute errors let the loud cells set it and left the quiet
    # samples' variance 2.5 times too small (an alarm on one quiet bin)
    weight = np.sqrt(count) / np.maximum(y, RESOLUTION ** 2)
    coef, _ = nnls(design / scale * weight[:, None], y * weight)
    a, b, c = coef / scale
    floor = float(np.min(y))
    a = max(float(a), 0.5 * floor, RESOLUTION ** 2)
    return a, max(float(b), 0.0), max(float(c), 0.0)


__all__ = ['fit_variance']
