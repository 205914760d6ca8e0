# SPDX-License-Identifier: Apache-2.0
"""
Bounded least-squares fit of the model's identifiable coefficients (and one effect).

Of the 14 coefficients of Table 1 most are not identifiable from Q, n and dp
alone: A_1, A_2 and K of eq. (1) only appear as one product, C of eq. (33) is
a lump of three, and the exponents (beta, gamma) and the clearance law of
eq. (2) trade off against each other within any bench's noise. Following the
paper's own procedure (C and C_id from the speed-dependent part, the
leakage from the pressure-only part), the fit frees three factors on the
packaged values: s_L on the leakage of eqs. (1) and (5) (A_1 and C_1), s_C
on C and s_id on C_id, plus the coefficient of at most one candidate
effect. The exponents stay as packaged.

Even these three trade off against a constant or a gain within a few tens of
noise levels (a flowmeter offset is mimicked by a larger C_id and leakage),
so the fit carries a weak Gaussian prior that each factor is 1 with a
standard deviation :data:`PRIOR_SD`: the packaged values are what the paper
measured, and a factor moves away from 1 only as far as the data insist.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import TYPE_CHECKING

import numpy as np
from satmotor_ros.identify.candidates import Candidate
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.parts import LossParts, NO_EFFECT, predict_flow, SCALES
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import LPM, MPA, RPM
from scipy import optimize, special

if TYPE_CHECKING:  # typing.Self is Python 3.11+
    from typing_extensions import Self

MIN_POINTS = 8
"""Fewest points for 3 coefficients, one effect and a residual estimate."""

MIN_SPREAD = 0.10
"""Least relative spread (max - min) / max of speed and of dp for the fit to separate terms."""

PRIOR_SD = 0.3
"""Prior standard deviation of each factor on a packaged coefficient, [-]."""

SCALE_MAX = 20.0
"""Largest factor on a packaged coefficient the fit may return, [-]."""


def check_identifiable(parts: LossParts) -> None:
    """
    Refuse data that cannot determine the three coefficients.

    Parameters
    ----------
    parts : LossParts
        Components at the usable points, [-]

    Raises
    ------
    IdentificationError
        If there are too few points, one speed only or one pressure only.

    """
    n = len(parts)
    if n < MIN_POINTS:
        msg = (f'too few points: {n} usable operating points, need >= {MIN_POINTS} to fit '
               f'the leakage, C and C_id and test one effect')
        raise IdentificationError(msg)
    for name, x, unit, scale, which in (
            ('speed', parts.speed, 'rpm', RPM, 'C_id (eq. 14) cannot be told from C '
             '(eq. 33) and the leakage (eqs. 1, 5)'),
            ('pressure drop', parts.dp, 'MPa', MPA, 'the leakage (eqs. 1, 5) cannot be '
             'told from C (eq. 33) and C_id (eq. 14)')):
        spread = float(np.ptp(x) / np.max(x)) if np.max(x) > 0 else 0.0
        if spread < MIN_SPREAD:
            msg = (f'one {name} only ({np.min(x) / scale:.4g}-{np.max(x) / scale:.4g} {unit}, '
                   f'spread {100 * spread:.1f} % < {100 * MIN_SPREAD:.0f} %): {which}; '
                   f'measure at several {name}s')
            raise IdentificationError(msg)


@dataclass(frozen=True)
class FitReport:
    """Fitted coefficients with 95 % confidence intervals."""

    names: tuple[str, ...]  # SCALES, then the effect's label if any
    values: FloatArray  # [-] for the scales, the effect's unit for its coefficient
    ci95: FloatArray  # shape (p, 2), same units
    rss: float  # residual sum of squares [(m^3/s)^2]
    n_points: int  # points fitted [-]


class LossFit:
    """
    Fit s_L, s_C, s_id and one effect coefficient by bounded least squares.

    Parameters
    ----------
    candidate : Candidate, optional
        The effect to fit with the model; none gives the baseline, [-]
    c_floor : float
        Smallest factor on C: the compressibility share C_fc beta_l of
        eqs. (9)-(11) is known from the bulk modulus, [-]
    noise : float
        Noise of the measured flow that weighs the prior against the data
        (the prior residual is (s - 1) noise / PRIOR_SD); 0 fits without
        the prior, [m^3/s]

    """

    def __init__(self, candidate: Candidate | None = None, c_floor: float = 0.0,
                 noise: float = 0.0) -> None:
        """Store the hyperparameters; nothing is fitted yet."""
        if not 0.0 <= c_floor < SCALE_MAX:
            msg = f'c_floor = {c_floor!r}: must be in [0, {SCALE_MAX})'
            raise IdentificationError(msg)
        if not noise >= 0.0:
            msg = f'noise = {noise!r}: must be >= 0'
            raise IdentificationError(msg)
        self.candidate = candidate
        self.c_floor = c_floor
        self.noise = noise

    def _unpack(self, u: FloatArray) -> tuple[FloatArray, float]:
        coef = u[3] * self.candidate.typical if self.candidate is not None else 0.0
        return u[:3], coef

    def _predict(self, parts: LossParts, u: FloatArray) -> FloatArray:
        scales, coef = self._unpack(u)
        mod = self.candidate.modify(coef) if self.candidate is not None else NO_EFFECT
        return predict_flow(parts, scales, mod)

    def fit(self, parts: LossParts, index: np.ndarray | None = None) -> Self:
        """
        Fit on the points in `index` (all when omitted).

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        index : ndarray of int, optional
            Points to fit on, [-]

        Returns
        -------
        LossFit
            Self, with ``u_``, ``rss_``, ``n_`` and ``jac_`` set.

        """
        index = np.arange(len(parts)) if index is None else index
        flow = parts.flow[index]
        lower = [0.0, self.c_floor, 0.0]
        upper = [SCALE_MAX] * 3
        u0 = [1.0, max(1.0, self.c_floor + 1e-6), 1.0]
        if self.candidate is not None:
            lo, hi = self.candidate.bounds
            typ = self.candidate.typical
            lower.append(lo / typ)
            upper.append(hi / typ)
            u0.append(min(max(self.candidate.start / typ, lo / typ), hi / typ))

        weight = self.noise / PRIOR_SD / LPM
        n_data = index.size

        def residual(u: FloatArray) -> FloatArray:
            data = (flow - self._predict(parts, u)[index]) / LPM
            return np.concatenate((data, (u[:3] - 1.0) * weight)) if weight else data

        with np.errstate(all='ignore'):
            result = optimize.least_squares(residual, np.array(u0), bounds=(lower, upper),
                                            method='trf', x_scale=1.0, xtol=1e-10, ftol=1e-10)
        if not np.all(np.isfinite(result.fun)):
            msg = 'the fit produced non-finite residuals: the data are outside the model'
            raise IdentificationError(msg)
        self.u_ = result.x
        self.jac_ = np.asarray(result.jac, dtype=float)
        self.rss_ = float(np.sum(result.fun[:n_data] ** 2)) * LPM ** 2
        self.n_ = int(index.size)
        return self

    def _check_fitted(self) -> None:
        if not hasattr(self, 'u_'):
            raise IdentificationError('LossFit is not fitted yet: call fit() first')

    def predict(self, parts: LossParts, index: np.ndarray | None = None) -> FloatArray:
        """
        Predict the measured flow at the points in `index`.

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        index : ndarray of int, optional
            Points to predict, [-]

        Returns
        -------
        ndarray
            Predicted flow, [m^3/s]

        """
        self._check_fitted()
        flow = self._predict(parts, self.u_)
        return flow if index is None else flow[index]

    @property
    def effect_coefficient(self) -> float:
        """Return the fitted coefficient of the candidate effect, in its unit (no interval)."""
        self._check_fitted()
        if self.candidate is None:
            return math.nan
        return float(self.u_[3] * self.candidate.typical)

    @property
    def n_params(self) -> int:
        """Return the number of fitted coefficients."""
        return 3 + (self.candidate is not None)

    def report(self) -> FitReport:
        """
        Summarise the fit with 95 % confidence intervals from the Jacobian.

        The covariance is s^2 (J^T J)^-1 with s^2 = RSS / (N - p), and the
        half-width t_{0.975, N-p} times its root diagonal; J includes the
        prior's rows, so an interval never exceeds what the prior allows.

        Returns
        -------
        FitReport
            Coefficients (scales [-], effect in its unit) and intervals.

        Raises
        ------
        IdentificationError
            If a coefficient is not determined (singular Jacobian); the
            message names it.

        """
        self._check_fitted()
        names = SCALES + ((self.candidate.label,) if self.candidate is not None else ())
        dof = max(self.n_ - self.n_params, 1)
        jac = self.jac_
        data_jac = jac[:self.n_]
        norms = np.linalg.norm(data_jac, axis=0)
        if np.any(norms == 0.0):
            which = names[int(np.flatnonzero(norms == 0.0)[0])]
            msg = f'{which} is not determined by the data: it has no effect at these points'
            raise IdentificationError(msg)
        _, sv, vt = np.linalg.svd(data_jac / norms, full_matrices=False)
        if sv[-1] < 1e-8 * sv[0]:
            which = names[int(np.argmax(np.abs(vt[-1])))]
            msg = (f'{which} is not determined by the data: it trades off exactly against '
                   f'the other coefficients at these points')
            raise IdentificationError(msg)
        s2 = self.rss_ / LPM ** 2 / dof
        cov = s2 * np.linalg.inv(jac.T @ jac)
        half = special.stdtrit(dof, 0.975) * np.sqrt(np.maximum(np.diag(cov), 0.0))
        unit = np.ones(self.n_params)
        if self.candidate is not None:
            unit[3] = self.candidate.typical
        values = self.u_ * unit
        ci = np.column_stack([values - half * unit, values + half * unit])
        return FitReport(names, values, ci, self.rss_, self.n_)
