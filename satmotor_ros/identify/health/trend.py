# SPDX-License-Identifier: Apache-2.0
"""
The slow trend of the leakage factor: a straight line by least squares with forgetting.

Why forgetting rather than a sliding window: wear is slow and nearly linear over tens of
hours, so the line should use all the history it can (a window short enough to follow the
wear throws away the points that fix the slope), yet a change of the wear rate must fade in
after a while; exponential forgetting with a time constant ``trend_hours`` does both with six
running sums (constant memory and cost), where a window would keep every point. A change
alarm restarts the line: a step is not a slope.

The points are the leakage factors of ``trend_point_s`` of operation each, equally weighted
(their scatter is the model's error at the operating points met more than the sample noise,
so weighting by information would let a few loaded minutes decide); the residual variance
is the line's own, and the slope's variance is inflated by (1 + phi)/(1 - phi), phi the
lag-one autocorrelation of the line's residuals, estimated as it runs.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
import math
from typing import Any

from scipy import stats

MIN_POINTS = 4
"""Fewest points for a slope with a residual estimate."""


@dataclass
class Trend:
    """Running sums of a straight line y = a + b x fitted with forgetting (x in hours)."""

    tau: float  # forgetting time constant [h]
    origin: float = math.nan  # x of the first point [h]
    last_x: float = math.nan  # [h]
    n: int = 0  # points added [-]
    sw: float = 0.0
    sx: float = 0.0
    sy: float = 0.0
    sxx: float = 0.0
    sxy: float = 0.0
    syy: float = 0.0
    last_residual: float = math.nan  # [-]
    rho_sum: float = 0.0  # forgetting sums of r_k r_(k-1) and r^2 for phi
    r2_sum: float = 0.0

    def add(self, x: float, y: float) -> None:
        """
        Add one point.

        Parameters
        ----------
        x : float
            Operating hours, [h]
        y : float
            Leakage factor, [-]

        """
        if self.n == 0:
            self.origin = x
        elif self.n >= MIN_POINTS:
            a, b = self._line()
            r = y - (a + b * (x - self.origin))
            if math.isfinite(self.last_residual):
                self.rho_sum = self.rho_sum * self._forget(x) + r * self.last_residual
                self.r2_sum = self.r2_sum * self._forget(x) + r * r
            self.last_residual = r
        lam = self._forget(x) if self.n else 1.0
        u = x - self.origin
        self.sw = lam * self.sw + 1.0
        self.sx = lam * self.sx + u
        self.sy = lam * self.sy + y
        self.sxx = lam * self.sxx + u * u
        self.sxy = lam * self.sxy + u * y
        self.syy = lam * self.syy + y * y
        self.last_x = x
        self.n += 1

    def _forget(self, x: float) -> float:
        return math.exp(-max(x - self.last_x, 0.0) / self.tau)

    def _line(self) -> tuple[float, float]:
        det = self.sw * self.sxx - self.sx * self.sx
        b = (self.sw * self.sxy - self.sx * self.sy) / det if det > 0 else 0.0
        return (self.sy - b * self.sx) / self.sw, b

    def estimate(self, x: float) -> tuple[float, float, float, float, float]:
        """
        Return the level at `x` and the slope, with their 95 % half-widths and phi.

        Parameters
        ----------
        x : float
            Operating hours where the level is wanted, [h]

        Returns
        -------
        tuple of float
            level [-], its half-width [-], slope [1/h], its half-width [1/h], phi [-];
            NaN before :data:`MIN_POINTS` points.

        """
        nan = math.nan
        det = self.sw * self.sxx - self.sx * self.sx
        if self.n < MIN_POINTS or det <= 0 or self.sw <= 2.0:
            return nan, nan, nan, nan, nan
        a, b = self._line()
        rss = (self.syy - 2 * a * self.sy - 2 * b * self.sxy + a * a * self.sw
               + 2 * a * b * self.sx + b * b * self.sxx)
        dof = self.sw - 2.0
        s2 = max(rss, 0.0) / dof
        phi = self.rho_sum / self.r2_sum if self.r2_sum > 0 else 0.0
        phi = min(max(phi, 0.0), 0.95)
        inflation = (1.0 + phi) / (1.0 - phi)
        u = x - self.origin
        mean = self.sx / self.sw
        sxx_c = det / self.sw
        q = float(stats.t.ppf(0.975, dof))
        level_hw = q * math.sqrt(s2 * inflation * (1.0 / self.sw + (u - mean) ** 2 / sxx_c))
        slope_hw = q * math.sqrt(s2 * inflation / sxx_c)
        return float(a + b * u), float(level_hw), float(b), float(slope_hw), float(phi)

    def state(self) -> dict[str, Any]:
        """Return the sums, for a saved state."""
        return asdict(self)


__all__ = ['MIN_POINTS', 'Trend']
