# SPDX-License-Identifier: Apache-2.0
"""
Bounded, weighted and robust least-squares fit of the model's identifiable coefficients.

Of the 14 coefficients of Table 1 most are not identifiable from Q, n and dp
alone: A_1, A_2 and K of eq. (1) only appear as one product, C of eq. (33) is
a lump of three, and the exponents (beta, gamma) and the clearance law of
eq. (2) trade off against each other within any bench's noise. Following the
paper's own procedure (C and C_id from the speed-dependent part, the
leakage from the pressure-only part), the fit frees one factor per named
component of the model's Q_vl (:attr:`LossParts.components`: for eqs.
(31)-(33) s_L on the leakage of eqs. (1) and (5), s_C on C and s_id on
C_id), the coefficients of the nuisance regressors (:attr:`LossParts.nuisance`,
linear, without a prior) and the coefficients and shape parameters of any
number of effects. The exponents of Table 1 stay as packaged.

The factors trade off against a constant or a gain within a few tens of
noise levels (a flowmeter offset is mimicked by a larger C_id and leakage),
so the fit carries a weak Gaussian prior that each factor is 1 with a
standard deviation :data:`PRIOR_SD`: the packaged values are what the paper
measured, and a factor moves away from 1 only as far as the data insist.

Residuals are divided by each point's noise (a noise model estimated from the
data, :mod:`.noise`) and, when ``robust`` is set, pass through Huber's loss:
a gross outlier pulls the fit by a bounded amount instead of its square.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
import itertools
import math
from typing import TYPE_CHECKING

import numpy as np
from satmotor_ros.identify.candidates import Candidate
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.parts import LossParts, NO_EFFECT, predict_flow
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import Effect, Modifier
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

HUBER = 1.345
"""Huber's constant in noise standard deviations: 95 % efficiency on Gaussian noise, [-]."""

TUKEY = 4.685
"""Tukey's biweight constant in noise standard deviations (95 % efficiency), [-]."""

_EPS_ROOT = float(np.finfo(np.float64).eps ** 0.5)
"""Relative forward-difference step, scipy's '2-point' default, [-]."""


def written(x: float) -> float:
    """Return `x` to 5 significant digits, as calibration.json writes a fitted number."""
    return float(f'{float(x):.5g}')


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


def huber_rho(z: FloatArray, c: float = HUBER) -> FloatArray:
    """Return 2 rho(z), Huber's loss: z^2 within `c`, 2 c |z| - c^2 beyond, [-]."""
    a = np.abs(z)
    return np.where(a <= c, z * z, 2.0 * c * a - c * c)


def robust_root(z: FloatArray, c: float, redescending: bool = False) -> FloatArray:
    """
    Return sign(z) sqrt(2 rho(z)): Huber's rho, or Tukey's biweight rho if `redescending`.

    Least squares on these minimise the sum of rho. Huber's (:func:`huber_rho`) is smooth
    at |z| = c; under Tukey's a point beyond c weighs nothing.

    Parameters
    ----------
    z : ndarray
        Standardised residuals, [-]
    c : float
        Huber's or Tukey's constant (:data:`HUBER`, :data:`TUKEY`), [-]
    redescending : bool
        Tukey's biweight instead of Huber's, [-]

    Returns
    -------
    ndarray
        The transformed residuals, [-]

    """
    if redescending:
        u = np.minimum((z / c) ** 2, 1.0)
        return np.sign(z) * c * np.sqrt((1.0 - (1.0 - u) ** 3) / 3.0)
    out = np.array(z, dtype=float)  # z within c as it is; beyond c (the few) transformed
    beyond = ~(np.abs(out) <= c)
    tail = out[beyond]
    out[beyond] = np.sign(tail) * np.sqrt(np.maximum(huber_rho(tail, c), 0.0))
    return out


def robust_slope(z: FloatArray, c: float, redescending: bool = False) -> FloatArray:
    """
    Return the derivative of :func:`robust_root` in z, [-].

    Huber's: 1 within `c`, c / sqrt(2 c |z| - c^2) beyond. Tukey's: with u = (z / c)^2,
    (1 - u)^2 / sqrt(1 - u + u^2 / 3) within `c` (1 at z = 0: the root's cancellation
    written out), 0 beyond.
    """
    if redescending:
        u = np.minimum((z / c) ** 2, 1.0)
        slope: FloatArray = (1.0 - u) ** 2 / np.sqrt(1.0 - u + u * u / 3.0)
        return slope
    a = np.abs(z)
    with np.errstate(invalid='ignore'):
        huber: FloatArray = np.where(a <= c, 1.0,
                                     c / np.sqrt(np.maximum(2.0 * c * a - c * c, c * c)))
    return huber


def _forward_steps(x0: FloatArray, bounds: tuple[FloatArray, FloatArray]
                   ) -> FloatArray:
    """
    Return scipy's forward-difference steps at `x0` (``least_squares``' '2-point').

    sqrt(eps) sign(x0) max(1, |x0|), turned back where it would cross a bound and fits
    the other way, else the distance to the farther bound.
    """
    sign = (x0 >= 0).astype(float) * 2 - 1
    h = _EPS_ROOT * sign * np.maximum(1.0, np.abs(x0))
    lb, ub = bounds
    if np.all((lb == -np.inf) & (ub == np.inf)):
        return h
    out = h.copy()
    lower_dist, upper_dist = x0 - lb, ub - x0
    x = x0 + h
    violated = (x < lb) | (x > ub)
    fitting = np.abs(h) <= np.maximum(lower_dist, upper_dist)
    out[violated & fitting] *= -1
    forward = (upper_dist >= lower_dist) & ~fitting
    out[forward] = upper_dist[forward]
    backward = (upper_dist < lower_dist) & ~fitting
    out[backward] = -lower_dist[backward]
    return np.asarray(out, dtype=float)


@dataclass(frozen=True)
class FitReport:
    """Fitted parameters with 95 % confidence intervals and their correlations."""

    names: tuple[str, ...]  # components' factors, nuisance, then each effect and its shape
    values: FloatArray  # [-] for the factors, the unit of each coefficient or shape
    ci95: FloatArray  # shape (p, 2), same units
    rss: float  # residual sum of squares [(m^3/s)^2]
    n_points: int  # points fitted [-]
    covariance: FloatArray  # (p, p), of the values [their units squared]

    @property
    def correlation(self) -> FloatArray:
        """Return the correlation matrix of the fitted parameters, [-]."""
        sd = np.sqrt(np.maximum(np.diag(self.covariance), 1e-300))
        correlation: FloatArray = np.clip(self.covariance / np.outer(sd, sd), -1.0, 1.0)
        return correlation  # np.clip is Any to numpy's stubs


class LossFit:
    """
    Fit the components' factors, the nuisance terms and any effects by bounded least squares.

    Parameters
    ----------
    effects : sequence of Candidate
        The effects to fit with the model, in order; none gives the baseline, [-]
    sigma : float or ndarray, optional
        Noise of the measured flow at each point: residuals are divided by it and
        the factors get their prior; None fits in l/min without the prior, [m^3/s]
    robust : float
        Huber's constant applied to the standardised residuals; 0 for plain least
        squares, [-]
    redescending : bool
        Tukey's biweight (constant :data:`TUKEY`) instead of Huber's loss: a gross
        outlier then pulls the fit not at all, the fit no longer convex, [-]

    """

    def __init__(self, effects: Sequence[Candidate] = (), sigma: FloatArray | float | None = None,
                 robust: float = 0.0, redescending: bool = False) -> None:
        """Store the hyperparameters; nothing is fitted yet."""
        if sigma is not None and not np.all(np.asarray(sigma) > 0.0):
            msg = 'sigma: the noise must be > 0 at every point'
            raise IdentificationError(msg)
        if not robust >= 0.0:
            msg = f'robust = {robust!r}: must be >= 0'
            raise IdentificationError(msg)
        self.effects = tuple(effects)
        self.sigma = sigma
        self.robust = robust
        self.redescending = redescending

    def _layout(self, parts: LossParts) -> None:
        self.m_ = len(parts.components)
        self.names_ = parts.names
        self.typical_ = np.array([LPM / max(float(np.max(np.abs(x))), 1e-300)
                                  for x in parts.nuisance.values()])
        self.nuisance_names_ = tuple(parts.nuisance)

    def _effect_values(self, u: FloatArray) -> list[tuple[Candidate, float, tuple[float, ...]]]:
        out = []
        i = self.m_ + self.typical_.size
        for c in self.effects:
            theta = tuple(s_.to_unit[0] + s_.to_unit[1] * float(v)
                          for s_, v in zip(c.shape, u[i + 1:i + 1 + len(c.shape)]))
            out.append((c, float(u[i]) * c.typical, theta))
            i += 1 + len(c.shape)
        return out

    def _modifier(self, u: FloatArray) -> Modifier:
        mod = NO_EFFECT
        for c, k, theta in self._effect_values(u):
            mod = c.modify(k, *theta) if mod is NO_EFFECT else mod + c.modify(k, *theta)
        return mod

    def _predict(self, parts: LossParts, u: FloatArray, mod: Modifier | None = None,
                 flows: list[FloatArray] | None = None) -> FloatArray:
        q = self.typical_.size
        return predict_flow(parts, u[:self.m_], self._modifier(u) if mod is None else mod,
                            u[self.m_:self.m_ + q] * self.typical_ if q else None, flows)

    def _starts(self, parts: LossParts, start: FloatArray | None
                ) -> tuple[list[float], list[float], list[FloatArray]]:
        lower = [c.floor for c in parts.components] + [-np.inf] * self.typical_.size
        upper = [SCALE_MAX] * self.m_ + [np.inf] * self.typical_.size
        base = [max(1.0, c.floor + 1e-6) for c in parts.components] + [0.0] * self.typical_.size
        options: list[tuple[float, ...]] = [(v,) for v in base]
        for c in self.effects:
            lo, hi = c.bounds
            lower.append(lo / c.typical)
            upper.append(hi / c.typical)
            options.append((min(max(c.start / c.typical, lo / c.typical), hi / c.typical),))
            for s_ in c.shape:
                lower.append(s_.bounds[0])
                upper.append(s_.bounds[1])
                options.append(tuple(min(max(v, s_.bounds[0]), s_.bounds[1])
                                     for v in s_.starts))
        starts = [np.array(u, dtype=float) for u in itertools.product(*options)]
        if start is not None:
            k = len(start)
            for u in starts:
                u[:k] = np.clip(start, np.array(lower[:k]), np.array(upper[:k]))
            if k == len(lower):
                starts = starts[:1]
        # a start that sets an earlier effect's shape makes that shape's own starts one:
        # the same problem from the same point, fitted once (the first kept, as the best is)
        unique: dict[bytes, FloatArray] = {}
        for u in starts:
            unique.setdefault(u.tobytes(), u)
        return lower, upper, list(unique.values())

    def _problem(self, parts: LossParts, index: np.ndarray, lower: Sequence[float],
                 upper: Sequence[float]
                 ) -> tuple[Callable[..., FloatArray], Callable[[FloatArray], FloatArray]]:
        """
        Return the fit's residual at parameters u and its Jacobian (after :meth:`_layout`).

        The Jacobian is scipy's forward differences ('2-point' of ``least_squares``),
        column for column and to the bit, but the effects' modifier and the components
        under it, which the factors and nuisance coefficients leave as they are, are
        computed once per Jacobian instead of once per column.
        """
        flow = parts.flow[index]
        prior = self.sigma is not None
        sigma = np.broadcast_to(np.asarray(LPM if self.sigma is None else self.sigma,
                                           dtype=float), parts.flow.shape)[index]
        m, c, tukey = self.m_, self.robust, self.redescending
        every = index.size == len(parts) and bool(np.all(index == np.arange(index.size)))

        def residual(u: FloatArray, mod: Modifier | None = None,
                     flows: list[FloatArray] | None = None) -> FloatArray:
            predicted = self._predict(parts, u, mod, flows)
            z = (flow - (predicted if every else predicted[index])) / sigma
            if tukey or c:
                z = robust_root(z, TUKEY if tukey else c, tukey)
            return np.concatenate((z, (u[:m] - 1.0) / PRIOR_SD)) if prior else z

        bounds = (np.array(lower, dtype=float), np.array(upper, dtype=float))
        linear = m + self.typical_.size

        def jacobian(u: FloatArray) -> FloatArray:
            u = np.asarray(u, dtype=float)
            mod = self._modifier(u)
            flows = [component.flow(mod) for component in parts.components]
            f0 = residual(u, mod, flows)
            out = np.zeros((u.size, f0.size))
            # the factors and the nuisance coefficients: the prediction is linear in them,
            # d Q_m / d s_j = G_Q Q_j and d Q_m / d beta_l = G_Q x_l (eq. 36), and the
            # residual's slope is the robust loss's at z
            predicted = self._predict(parts, u, mod, flows)
            z = (flow - (predicted if every else predicted[index])) / sigma
            slope = -(robust_slope(z, TUKEY if tukey else c, tukey) if tukey or c
                      else np.ones(z.size)) / sigma
            gain = mod.flow_gain
            unit_gain = isinstance(gain, float | int) and gain == 1.0
            columns = [*flows, *(t * x for t, x in zip(self.typical_, parts.nuisance.values()))]
            for i, column in enumerate(columns):
                d = column if unit_gain else gain * column
                out[i, :z.size] = slope * (d if every else d[index])
                if prior and i < m:
                    out[i, z.size + i] = 1.0 / PRIOR_SD
            h = _forward_steps(u, bounds)
            for i in range(linear, u.size):  # the effects': scipy's forward differences
                v = u.copy()
                v[i] = u[i] + h[i]
                out[i] = (residual(v) - f0) / ((u[i] + h[i]) - u[i])
            transposed: FloatArray = out.T  # as scipy's own: a view, no copy
            return transposed

        return residual, jacobian

    def fit(self, parts: LossParts, index: np.ndarray | None = None,
            start: FloatArray | None = None) -> Self:
        """
        Fit on the points in `index` (all when omitted).

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        index : ndarray of int, optional
            Points to fit on, [-]
        start : ndarray, optional
            Initial values of the first parameters (e.g. a fit of the same model, or of
            the model without its last effect); the rest start from each combination of
            the shape parameters' starting values, [-]

        Returns
        -------
        LossFit
            Self, with ``u_``, ``rss_``, ``objective_``, ``n_``, ``jac_`` and ``active_``
            (which parameters ended on a bound, see :meth:`pinned`) set.

        """
        self._layout(parts)
        index = np.arange(len(parts)) if index is None else index
        flow = parts.flow[index]
        lower, upper, starts = self._starts(parts, start)
        residual, jacobian = self._problem(parts, index, lower, upper)
        best = None
        with np.errstate(all='ignore'):
            for u0 in starts:
                result = optimize.least_squares(residual, u0, jac=jacobian, bounds=(lower, upper),
                                                method='trf', x_scale=1.0, xtol=1e-6,
                                                ftol=1e-6)
                if np.all(np.isfinite(result.fun)) and (best is None or result.cost < best.cost):
                    best = result
        if best is None:
            msg = 'the fit produced non-finite residuals: the data are outside the model'
            raise IdentificationError(msg)
        self.u_ = best.x
        self.fun_ = np.asarray(best.fun, dtype=float)
        self.bounds_ = (np.array(lower, dtype=float), np.array(upper, dtype=float))
        self.jac_ = np.asarray(best.jac, dtype=float)
        self.active_ = np.asarray(best.active_mask, dtype=int)  # -1/+1: on a lower/upper bound
        self.n_ = int(index.size)
        self.objective_ = float(np.sum(best.fun[:self.n_] ** 2))
        self.rss_ = float(np.sum((flow - self._predict(parts, best.x)[index]) ** 2))
        return self

    def _check_fitted(self) -> None:
        if not hasattr(self, 'u_'):
            raise IdentificationError('LossFit is not fitted yet: call fit() first')

    def predict(self, parts: LossParts, index: np.ndarray | None = None,
                u: FloatArray | None = None) -> FloatArray:
        """
        Predict the measured flow at the points in `index`.

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        index : ndarray of int, optional
            Points to predict, [-]
        u : ndarray, optional
            Parameters other than the fitted ones (e.g. :meth:`without`), [-]

        Returns
        -------
        ndarray
            Predicted flow, [m^3/s]

        """
        self._check_fitted()
        flow = self._predict(parts, self.u_ if u is None else u)
        return flow if index is None else flow[index]

    def without(self, drop: np.ndarray) -> FloatArray:
        """
        Return the parameters refitted without some of the fitted points, by one Gauss-Newton step.

        From the fit's own optimum, one step on the remaining rows of its Jacobian
        (the prior's rows kept) is the exact refit of a model linear in its
        parameters and a close one otherwise: cross-validation without refitting.

        Parameters
        ----------
        drop : ndarray of int
            Positions among the fitted points (not table rows) to leave out, [-]

        Returns
        -------
        ndarray
            The parameters, within their bounds, [-]

        """
        self._check_fitted()
        keep = np.ones(self.fun_.size, dtype=bool)
        keep[drop] = False
        held = self._held()
        step = np.zeros(self.u_.size)
        step[~held] = np.linalg.lstsq(self.jac_[keep][:, ~held], -self.fun_[keep], rcond=None)[0]
        within: FloatArray = np.clip(self.u_ + step, *self.bounds_)  # numpy types it as Any
        return within

    def found(self) -> list[tuple[Candidate, Effect]]:
        """Return each effect's candidate with the effect at the fitted values (for the YAML)."""
        self._check_fitted()
        return [(c, c.as_effect(k, *theta)) for c, k, theta in self._effect_values(self.u_)]

    def last_modifier(self) -> Modifier:
        """Return what the last effect alone does to the prediction, at its fitted values."""
        self._check_fitted()
        if not self.effects:
            return NO_EFFECT
        c, k, theta = self._effect_values(self.u_)[-1]
        return c.modify(k, *theta)

    def pinned(self, effects_only: bool = False) -> list[tuple[str, float]]:
        """
        Return each parameter the fit left on a bound of its range, and the bound.

        A parameter on a bound is not an estimate: the data ask for a value beyond the
        range. Its interval (:meth:`report`) and a nested F-test of it assume a best fit
        inside the range, where the gradient is zero, and mean nothing there. On a bound
        means within the fit's ``xtol`` of it (relative, at least 1e-6 absolute in the
        fitted units): scipy's ``active_mask``.

        Parameters
        ----------
        effects_only : bool
            Only the effects' coefficients and shapes, not the components' factors, [-]

        Returns
        -------
        list of tuple
            ``(name, bound)`` per parameter on a bound, in the order of :meth:`report`;
            the bound in the parameter's unit, [-]

        """
        self._check_fitted()
        names, unit, offset = self._names_and_units()
        first = self.m_ + self.typical_.size if effects_only else 0
        bound = np.where(self.active_ < 0, *self.bounds_)
        valued = self._at_floor_value()
        return [(names[i], float(offset[i] + unit[i] * bound[i]))
                for i in np.flatnonzero(self.active_) if i >= first and not valued[i]]

    def _held(self) -> np.ndarray:
        """Return which parameters a refit without some points keeps (a valve's response time)."""
        return np.asarray([False] * (self.m_ + self.typical_.size) + [
            v for c in self.effects for v in (False, *(s_.floor_is_value for s_ in c.shape))],
            dtype=bool)

    def _at_floor_value(self) -> np.ndarray:
        """Return which parameters end on a floor that is a value of the physics (no lag)."""
        return self._held() & (self.active_ < 0)

    @property
    def effect_coefficient(self) -> float:
        """Return the fitted coefficient of the last effect, in its unit (no interval)."""
        self._check_fitted()
        if not self.effects:
            return math.nan
        return self.found()[-1][1].coefficient

    @property
    def n_params(self) -> int:
        """Return the number of fitted parameters."""
        self._check_fitted()
        return int(self.u_.size)

    def _names_and_units(self) -> tuple[tuple[str, ...], FloatArray, FloatArray]:
        names = list(self.names_)
        unit = [1.0] * self.m_ + list(self.typical_)
        offset = [0.0] * (self.m_ + self.typical_.size)
        names += [f'nuisance:{n}' for n in self.nuisance_names_]
        for c in self.effects:
            names.append(c.label)
            unit.append(c.typical)
            offset.append(0.0)
            for s_ in c.shape:
                names.append(f'{c.label} {s_.name}')
                unit.append(s_.to_unit[1])
                offset.append(s_.to_unit[0])
        return tuple(names), np.array(unit), np.array(offset)

    def report(self, inflation: float = 1.0) -> FitReport:
        """
        Summarise the fit with 95 % confidence intervals and correlations from the Jacobian.

        The covariance is s^2 (J^T J)^-1 with s^2 = sum rho / (N - p), and the
        half-width t_{0.975, N-p} times its root diagonal; J includes the
        prior's rows, so an interval never exceeds what the prior allows.
        Residuals correlated in time (a time series' samples) multiply the
        covariance and divide N by `inflation`.

        Parameters
        ----------
        inflation : float
            Variance inflation of the residuals, >= 1
            (:func:`~satmotor_ros.identify.transient.variance_inflation`), [-]

        Returns
        -------
        FitReport
            Parameters (factors [-], coefficients and shapes in their units) and intervals.

        Raises
        ------
        IdentificationError
            If a parameter is not determined (singular Jacobian); the message names it.

        """
        self._check_fitted()
        names, unit, offset = self._names_and_units()
        dof = max(self.n_ - self.n_params, 1)
        free = ~self._at_floor_value()  # a shape at a floor that is a value stays there: fixed
        jac = self.jac_[:, free]
        data_jac = jac[:self.n_]
        norms = np.linalg.norm(data_jac, axis=0)
        names_free = [n for n, f in zip(names, free) if f]
        if np.any(norms == 0.0):
            which = names_free[int(np.flatnonzero(norms == 0.0)[0])]
            msg = f'{which} is not determined by the data: it has no effect at these points'
            raise IdentificationError(msg)
        _, sv, vt = np.linalg.svd(data_jac / norms, full_matrices=False)
        if sv[-1] < 1e-8 * sv[0]:
            which = names_free[int(np.argmax(np.abs(vt[-1])))]
            msg = (f'{which} is not determined by the data: it trades off exactly against '
                   f'the other coefficients at these points')
            raise IdentificationError(msg)
        inflation = max(inflation, 1.0)
        s2 = self.objective_ / dof * inflation
        cov = np.zeros((free.size, free.size))
        scale = np.outer(unit[free], unit[free])
        cov[np.ix_(free, free)] = s2 * np.linalg.pinv(jac.T @ jac) * scale
        dof = max(int(self.n_ / inflation) - self.n_params, 1)
        half = special.stdtrit(dof, 0.975) * np.sqrt(np.maximum(np.diag(cov), 0.0))
        values = offset + self.u_ * unit
        ci = np.column_stack([values - half, values + half])
        return FitReport(names, values, ci, self.rss_, self.n_, cov)
