# SPDX-License-Identifier: Apache-2.0
"""The trend's arithmetic: weighted least squares with forgetting, against a hand computation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from satmotor_ros.identify.health.trend import MIN_POINTS, Trend
from scipy import stats


def _points(n: int = 12, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Unevenly spaced hours from 3 h on, a line 1.2 + 0.05 x with noise."""
    rng = np.random.default_rng(seed)
    x = 3.0 + np.cumsum(rng.uniform(0.1, 0.5, n))
    return x, 1.2 + 0.05 * x + rng.normal(0.0, 0.02, n)


def _trend(x: np.ndarray, y: np.ndarray, tau: float) -> Trend:
    trend = Trend(tau)
    for xi, yi in zip(x, y):
        trend.add(float(xi), float(yi))
    return trend


def _by_hand(x: np.ndarray, y: np.ndarray, tau: float, at: float, phi: float):
    """Weighted least squares, weights exp(-(x_n - x_i)/tau), the interval of trend.py."""
    w = np.exp(-(x[-1] - x) / tau)
    b, a = np.polyfit(x, y, 1, w=np.sqrt(w))
    r = y - (a + b * x)
    dof = w.sum() - 2.0
    s2 = float(w @ r ** 2) / dof
    mean = float(w @ x) / w.sum()
    sxx = float(w @ (x - mean) ** 2)
    q = stats.t.ppf(0.975, dof) * math.sqrt((1 + phi) / (1 - phi))
    level_hw = q * math.sqrt(s2 * (1.0 / w.sum() + (at - mean) ** 2 / sxx))
    return a + b * at, level_hw, b, q * math.sqrt(s2 / sxx)


@pytest.mark.parametrize('tau', [1e9, 2.0])
def test_line_and_intervals_are_weighted_least_squares_with_forgetting(tau: float) -> None:
    """Level, slope and both half-widths as numpy.polyfit and the t quantile give them."""
    x, y = _points()
    trend = _trend(x, y, tau)
    level, level_hw, slope, slope_hw, phi = trend.estimate(x[-1] + 0.7)
    want = _by_hand(x, y, tau, x[-1] + 0.7, phi)
    assert (level, level_hw, slope, slope_hw) == pytest.approx(want, rel=1e-9)
    assert trend.n == len(x) and trend.sw == pytest.approx(np.exp(-(x[-1] - x) / tau).sum())


def test_phi_is_the_lag_one_correlation_of_the_one_step_residuals() -> None:
    """Each point's residual against the line before it; phi = sum r_k r_k-1 / sum r_k^2."""
    x = np.arange(14, dtype=float)
    y = 1.0 + 0.1 * x + 0.05 * np.sin(x / 3.0)  # slow, correlated departures
    trend = _trend(x, y, 1e12)
    residuals = []
    for k in range(MIN_POINTS, len(x)):
        b, a = np.polyfit(x[:k], y[:k], 1)
        residuals.append(y[k] - (a + b * x[k]))
    r = np.array(residuals)
    phi = float(r[1:] @ r[:-1]) / float(r[1:] @ r[1:])
    assert 0.0 < phi < 0.95
    assert trend.estimate(x[-1])[4] == pytest.approx(phi, rel=1e-6)


def test_alternating_residuals_give_no_negative_phi_and_few_points_no_line() -> None:
    """Phi is clipped at 0; fewer than MIN_POINTS points, or all at one x, give NaN."""
    x = np.arange(10, dtype=float)
    trend = _trend(x, 2.0 + 0.01 * x + 0.03 * (-1.0) ** x, 1e9)
    assert trend.estimate(9.0)[4] == 0.0
    few = _trend(x[:MIN_POINTS - 1], x[:MIN_POINTS - 1], 1e9)
    assert all(math.isnan(v) for v in few.estimate(1.0))
    assert all(math.isnan(v) for v in _trend(np.full(6, 2.0), x[:6], 1e9).estimate(2.0))


def _one_step_phi(x: np.ndarray, y: np.ndarray, tau: float) -> float:
    """Phi by hand: each point's residual against the weighted line before it, forgotten."""
    rho = r2 = 0.0
    last = math.nan
    for k in range(MIN_POINTS, len(x)):
        w = np.exp(-(x[k - 1] - x[:k]) / tau)
        b, a = np.polyfit(x[:k], y[:k], 1, w=np.sqrt(w))
        r = y[k] - (a + b * x[k])
        if math.isfinite(last):
            forget = math.exp(-(x[k] - x[k - 1]) / tau)
            rho, r2 = rho * forget + r * last, r2 * forget + r * r
        last = r
    return min(max(rho / r2, 0.0), 0.95)


@pytest.mark.parametrize('tau', [1e12, 3.0])
def test_phi_forgets_as_the_line_does_far_from_hour_zero(tau: float) -> None:
    """From 500 h on, with and without forgetting: phi as by hand."""
    x = 500.0 + 0.4 * np.arange(16)
    y = 1.0 + 0.1 * x + 0.05 * np.sin(x / 1.3)
    assert _trend(x, y, tau).estimate(x[-1])[4] == pytest.approx(_one_step_phi(x, y, tau),
                                                                 rel=1e-6)


def test_a_curve_gives_phi_at_its_cap_and_minutes_apart_still_a_slope() -> None:
    """Residuals of one sign: phi capped at 0.95; points a minute apart: the slope is fitted."""
    x = np.arange(30, dtype=float)
    curve = _trend(x, 1.0 + 0.1 * np.sqrt(x), 1e9)
    assert curve.rho_sum / curve.r2_sum > 0.99 and curve.estimate(29.0)[4] == 0.95
    x = np.arange(12, dtype=float)
    minutes = x / 60.0
    level, _, slope, _, _ = _trend(minutes, 1.0 + 0.3 * minutes, 1e9).estimate(minutes[-1])
    assert slope == pytest.approx(0.3) and level == pytest.approx(1.0 + 0.3 * minutes[-1])


def test_the_fewest_points_and_the_least_weight_still_give_a_line() -> None:
    """Exactly MIN_POINTS points (no residual pair yet), and forgetting that leaves sw < 3."""
    x = np.arange(MIN_POINTS, dtype=float)
    level, level_hw, slope, slope_hw, phi = _trend(x, 2.0 + 0.1 * x + 0.01 * (-1.0) ** x,
                                                   1e9).estimate(3.0)
    assert slope == pytest.approx(0.1, abs=0.02) and phi == 0.0 and slope_hw > 0.0
    x = np.arange(8, dtype=float)
    trend = _trend(x, 1.0 + 0.05 * x + 0.01 * np.cos(x), 2.0)
    assert 2.0 < trend.sw < 3.0
    assert all(math.isfinite(v) for v in trend.estimate(x[-1]))
