# SPDX-License-Identifier: Apache-2.0
"""
The motor model: loss breakdown, forward map Q(n, dp) and inverse map n(Q, dp).

:class:`MotorModel` composes the equation functions of
:mod:`~satmotor_ros.model.losses` and :mod:`~satmotor_ros.model.speed` for one
motor, one coefficient set and one liquid. Every method is vectorised over
arrays of operating points and screens its inputs element by element: with
``errors='raise'`` (the default) the first bad element raises
:class:`InvalidInputError` naming the argument, index and value; with
``errors='mask'`` bad elements come back as NaN and are flagged in
``status`` (see :class:`PointStatus`) while the rest of the batch is computed.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

import numpy as np
import numpy.typing as npt

from satmotor_ros.model import losses as eq
from satmotor_ros.model._typing import ArrayLike, FloatArray
from satmotor_ros.model.coefficients import (CoefficientSet, Liquid, MotorGeometry,
                                             ValidRange)
from satmotor_ros.model.config import load_motor, MotorSpec
from satmotor_ros.model.derived import derive
from satmotor_ros.model.errors import InvalidInputError, ModelError
from satmotor_ros.model.point import as_float, PointEvaluator
from satmotor_ros.model.results import (COMPONENTS, INVALID, LossBreakdown, OperatingPoints,
                                        Point, PointStatus)
from satmotor_ros.model.solve import solve_increasing
from satmotor_ros.model.speed import absorbency, effective_speed
from satmotor_ros.model.units import MPA, RPM

Errors = Literal['raise', 'mask']
DisplacementLaw = Literal['eq33', 'eq39']


_CHUNK = 8192
"""
Elements solved at once by the iterative maps.

Temporaries of this size stay in cache, and a chunk stops iterating as soon as
its own elements converge: 3-4x faster than solving a whole batch at once. A
closed-form evaluation is a single pass, where chunking would only add a copy.
"""

_RTOL = 1e-13
"""Relative tolerance of the iterative maps: Newton polishes well below it, bisection to it."""

At = tuple[int, tuple[int, ...]]
"""Where a chunk sits in the batch: flat offset and the batch's shape (for error messages)."""


def _screen(name: str, unit: str, value: FloatArray,
            errors: Errors) -> npt.NDArray[np.uint8] | None:
    """Flag non-finite and negative elements; None when there are none (the usual case)."""
    if value.size == 0 or (value.min() >= 0.0 and value.max() < np.inf):
        return None
    not_finite = ~np.isfinite(value)
    negative = value < 0.0
    if errors == 'raise':
        at = (0, value.shape)
        if not_finite.any():
            _raise_first(name, unit, value, not_finite, 'not finite', at)
        _raise_first(name, unit, value, negative, 'negative', at)
    return (not_finite * np.uint8(PointStatus.NOT_FINITE)
            | negative * np.uint8(PointStatus.NEGATIVE)).astype(np.uint8)


def _raise_first(name: str, unit: str, value: FloatArray, bad: npt.NDArray[np.bool_],
                 why: str, at: At) -> None:
    first = int(np.flatnonzero(bad)[0])
    offset, shape = at
    index = ', '.join(str(i) for i in np.unravel_index(offset + first, shape)) if shape else ''
    where = f'{name}[{index}]' if shape else name
    count = int(bad.sum())
    tail = f' ({count} element{"s" if count > 1 else ""} of this kind)' if len(shape) else ''
    msg = f'{where} = {float(value.flat[first])!r} {unit}: {why}{tail}'
    raise InvalidInputError(msg)


_Chunk = dict[str, np.ndarray]
"""Results of one chunk by field name: OperatingPoints fields and COMPONENTS."""


def _join(parts: list[_Chunk], shape: tuple[int, ...]) -> _Chunk:
    joined = {}
    for key in parts[0]:
        values = [p[key] for p in parts]
        scalar = [np.ndim(v) == 0 for v in values]
        if all(scalar):  # a component that is 0 throughout (no Q_ex)
            joined[key] = np.zeros(shape)  # calloc'd: no pages written
            continue
        if any(scalar):  # 0 in some chunks, masked to NaN in others
            values = [np.broadcast_to(v, p['status'].shape) for v, p in zip(values, parts)]
        joined[key] = (np.concatenate(values) if len(values) > 1 else values[0]).reshape(shape)
    return joined


class MotorModel:
    """
    The volumetric-loss and speed model of one satellite motor on one liquid.

    Parameters
    ----------
    geometry : MotorGeometry
        Motor geometry, [-]
    coefficient_set : CoefficientSet
        Loss coefficients and the liquid they were fitted on, [-]
    valid_range : ValidRange
        Range the coefficients were validated over, [-]
    liquid : Liquid, optional
        Working liquid; the set's own liquid when omitted. Another liquid keeps
        the set's fitted coefficients and changes nu, rho and the
        compressibility share of C (eqs. 9-11), [-]
    displacement_law : {'eq33', 'eq39'}
        Delta q from the physical eq. (33) (default) or the empirical eq. (39), [-]
    name : str
        Name of the motor, for reports, [-]

    Examples
    --------
    >>> from satmotor_ros.model.units import LPM, MPA, RPM
    >>> oil = MotorModel.default('oil')
    >>> op = oil.speed(5 * LPM, dp_i=25 * MPA)
    >>> round(float(op.speed) / RPM, 1)
    133.2

    """

    def __init__(self, geometry: MotorGeometry, coefficient_set: CoefficientSet,
                 valid_range: ValidRange, liquid: Liquid | None = None,
                 displacement_law: DisplacementLaw = 'eq33', name: str = 'motor') -> None:
        """Derive the liquid-dependent coefficients once."""
        if displacement_law not in ('eq33', 'eq39'):
            msg = f"displacement_law = {displacement_law!r}: use 'eq33' or 'eq39'"
            raise ModelError(msg)
        self.name = name
        self.geometry = geometry
        self.coefficient_set = coefficient_set
        self.valid_range = valid_range
        self.liquid = liquid if liquid is not None else coefficient_set.liquid
        self.displacement_law = displacement_law
        self.coef = coefficient_set.coefficients
        d = self.derived = derive(geometry, coefficient_set, valid_range, self.liquid)
        self.c_fc_beta, self.c_dch, self.c_b, self.c = d.c_fc_beta, d.c_dch, d.c_b, d.c_lumped
        self._h_slope = -d.compliance  # dh/dp_i [m/Pa]
        self._k_p, self._k_i = d.k_p, d.k_i
        self._channel_a, self._channel_b = d.ch_a, d.ch_b
        self.dp_limit = d.dp_limit
        self._point = PointEvaluator(d, displacement_law == 'eq39', _RTOL)

    @classmethod
    def from_spec(cls, spec: MotorSpec, coefficients: str = 'oil', liquid: Liquid | None = None,
                  displacement_law: DisplacementLaw = 'eq33') -> MotorModel:
        """
        Build a model from a loaded :class:`MotorSpec`.

        Parameters
        ----------
        spec : MotorSpec
            The motor, [-]
        coefficients : str
            Name of the coefficient set, e.g. ``'oil'`` or ``'water'``, [-]
        liquid : Liquid, optional
            A user liquid run on that set, [-]
        displacement_law : {'eq33', 'eq39'}
            Law for Delta q, [-]

        Returns
        -------
        MotorModel
            The model.

        """
        if coefficients not in spec.sets:
            msg = (f'coefficient set {coefficients!r} is not in {spec.source} '
                   f'(has: {", ".join(spec.sets)})')
            raise ModelError(msg)
        return cls(spec.geometry, spec.sets[coefficients], spec.valid_range, liquid,
                   displacement_law, spec.name)

    @classmethod
    def default(cls, coefficients: str = 'oil',
                displacement_law: DisplacementLaw = 'eq33') -> MotorModel:
        """
        Build the packaged SM-0,75/25 model for oil or water.

        Parameters
        ----------
        coefficients : str
            ``'oil'`` or ``'water'``, [-]
        displacement_law : {'eq33', 'eq39'}
            Law for Delta q, [-]

        Returns
        -------
        MotorModel
            The model.

        """
        return cls.from_spec(load_motor(), coefficients, None, displacement_law)

    # -- building blocks ------------------------------------------------------------------

    def _leakage(self, dp_i: FloatArray, p_ex: FloatArray) -> tuple[FloatArray, ...]:
        nu, rho = self.liquid.kinematic_viscosity, self.liquid.density
        h = eq.clearance_height(dp_i, self.geometry, self.coef)
        q_lfg = eq.flat_clearance_leakage(dp_i, h, nu, rho, self.geometry, self.coef)
        q_c = eq.commutation_leakage(dp_i, nu, rho, self.geometry, self.coef)
        q_ex = eq.external_leakage(p_ex, self.coef) if self.coef.external_leakage else 0.0
        return q_lfg, q_c, q_ex

    def _displacement_loss(self, speed: FloatArray, dp_i: FloatArray) -> FloatArray:
        if self.displacement_law == 'eq39':
            return eq.displacement_loss_empirical(dp_i, speed, self.coef)
        return eq.displacement_loss(dp_i, speed, self.c, self.coef.c_id, self.geometry)

    def _displacement_loss_slopes(self, speed: FloatArray, dp_i: FloatArray,
                                  loss: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Return d(Delta Q_vl)/dn and d(Delta Q_vl)/d(dp_i) of eq. (33) or (39) at `loss`."""
        with np.errstate(divide='ignore', invalid='ignore'):
            if self.displacement_law == 'eq39':
                # Delta Q_vl = C_1 s exp(a / s) with s = sqrt(n [rpm]), a = C_2 ln(dp_i [MPa])
                inv_s = 1.0 / np.sqrt(speed / RPM)
                above = dp_i > eq.EMPIRICAL_DP_FLOOR  # below it, eq. (39) is flat in dp_i
                log_dp = np.log(np.where(above, dp_i, eq.EMPIRICAL_DP_FLOOR) / MPA)
                d_speed = loss * (1.0 - self.coef.c2_39 * log_dp * inv_s) / (2.0 * speed)
                return d_speed, np.where(above, loss * self.coef.c2_39 * inv_s / dp_i, 0.0)
            return (self._k_p * dp_i + 0.5 * self._k_i / np.sqrt(speed),
                    self._k_p * speed)

    def _leakage_slope(self, dp_i: FloatArray, q_lfg: FloatArray,
                       q_c: FloatArray) -> FloatArray:
        """Return d(Q_Lfg + Q_C)/d(dp_i) of eqs. (1), (2) and (5) at the given leakages."""
        h = eq.clearance_height(dp_i, self.geometry, self.coef)
        e = 1.0 / (2.0 - self.coef.beta)
        with np.errstate(divide='ignore', invalid='ignore'):
            return (q_lfg * e * (1.0 / dp_i + 3.0 * self._h_slope / h)
                    + q_c * self.coef.gamma / dp_i)

    def _breakdown(self, speed: FloatArray, dp_i: FloatArray, q_lfg: FloatArray,
                   q_c: FloatArray, q_ex: FloatArray | float,
                   leak: FloatArray) -> dict[str, FloatArray]:
        """Return the components of eq. (31); `leak` is Q_Lfg + Q_C + Q_ex."""
        g = self.geometry
        parts = [eq.compressibility_loss(dp_i, speed, self.c_fc_beta, g),
                 eq.deformation_loss(dp_i, speed, self.c_dch, g),
                 eq.backlash_loss(dp_i, speed, self.c_b, g),
                 eq.inertia_loss(speed, self.coef.c_id, g)]
        if self.displacement_law == 'eq39':
            # eq. (39) has no physical split: share its Delta Q_vl in eq. (33)'s proportions
            physical = parts[0] + parts[1] + parts[2] + parts[3]
            scale = np.divide(eq.displacement_loss_empirical(dp_i, speed, self.coef), physical,
                              out=np.zeros_like(physical), where=physical > 0.0)
            parts = [p * scale for p in parts]
        total = leak + ((parts[0] + parts[1]) + (parts[2] + parts[3]))
        return dict(zip(COMPONENTS, (q_lfg, q_c, *parts, q_ex, total)))

    def _prepare(self, named: dict[str, tuple[ArrayLike, str]],
                 errors: Errors) -> tuple[list[FloatArray], npt.NDArray[np.uint8]]:
        if errors not in ('raise', 'mask'):
            msg = f"errors = {errors!r}: use 'raise' or 'mask'"
            raise ModelError(msg)
        values = [np.asarray(v, dtype=float) for v, _ in named.values()]
        flags = [_screen(name, unit, value, errors)
                 for (name, (_, unit)), value in zip(named.items(), values)]
        arrays = np.broadcast_arrays(*values)
        status = np.zeros(arrays[0].shape, dtype=np.uint8)
        for flag in flags:
            if flag is not None:
                status |= flag
        return arrays, status

    def _run(self, core: Callable[..., _Chunk], arrays: list[FloatArray],
             status: npt.NDArray[np.uint8], given: dict[str, FloatArray],
             iterative: bool) -> OperatingPoints:
        """Evaluate `core`, in chunks if `iterative`; inputs in `given` are returned as given."""
        shape = status.shape
        bad = status != 0 if status.any() else None
        clean = arrays if bad is None else [np.where(bad, 0.0, a) for a in arrays]
        flat = [a.reshape(-1) for a in clean]  # a view where it can be, e.g. broadcast scalars
        flat_status = status.ravel()
        chunk = _CHUNK if iterative else max(flat_status.size, 1)
        parts = [core(*(a[i:i + chunk] for a in flat), flat_status[i:i + chunk], (i, shape))
                 for i in range(0, max(flat_status.size, 1), chunk)]
        fields_ = _join(parts, shape)
        invalid = (fields_['status'] & int(INVALID)) != 0
        for name, value in given.items():
            fields_[name] = np.where(invalid, np.nan, value) if invalid.any() else value
        losses = LossBreakdown(**{k: fields_.pop(k) for k in COMPONENTS})
        return OperatingPoints(losses=losses, geometry=self.geometry, **fields_)

    def _channel_drop(self, flow: FloatArray) -> FloatArray:
        return eq.channel_pressure_drop(flow, self.liquid.kinematic_viscosity,
                                        self.liquid.density, self.coef)

    def _chamber_drop(self, dp: FloatArray, flow: FloatArray,
                      status: npt.NDArray[np.uint8]) -> FloatArray:
        dp_i = eq.chamber_pressure_drop(dp, self._channel_drop(flow))
        if dp_i.size == 0 or dp_i.min() >= 0.0:
            return dp_i
        status |= (dp_i < 0.0) * np.uint8(PointStatus.CHANNEL_LIMITED)
        return np.maximum(dp_i, 0.0)

    def _check_limits(self, dp_i: FloatArray, dp_name: str, dp_value: FloatArray,
                      status: npt.NDArray[np.uint8], errors: Errors, at: At) -> FloatArray:
        if dp_i.size == 0 or dp_i.max() <= self.dp_limit:
            return dp_i
        beyond = dp_i > self.dp_limit
        if errors == 'raise':
            _raise_first(dp_name, 'Pa', dp_value, beyond,
                         f'chamber pressure drop beyond the model limit '
                         f'{self.dp_limit / MPA:.1f} MPa, where eq. (2) closes the clearance'
                         f' so fast that eq. (1) would fall with pressure', at)
        status |= beyond * np.uint8(PointStatus.BEYOND_LIMIT)
        return np.where(beyond, 0.0, dp_i)

    def _finish(self, given: tuple[str, ...], status: npt.NDArray[np.uint8],
                **values: FloatArray) -> _Chunk:
        """Flag extrapolation and NaN the invalid; drop the inputs in `given`."""
        speed, dp_i = values['speed'], values['dp_i']
        limits = self.valid_range
        if speed.size and (dp_i.max() > limits.dp_max or speed.max() > limits.speed_max):
            status |= ((dp_i > limits.dp_max) | (speed > limits.speed_max)) \
                * np.uint8(PointStatus.EXTRAPOLATED)
        chunk = {k: v for k, v in values.items() if k not in given}
        invalid = (status & int(INVALID)) != 0 if status.any() else None
        if invalid is not None and invalid.any():
            status &= np.where(invalid, np.uint8(INVALID), np.uint8(0xFF))  # no STALLED etc.
            chunk = {k: np.where(invalid, np.nan, v) for k, v in chunk.items()}
        chunk['status'] = status
        return chunk

    # -- public maps -----------------------------------------------------------------------

    def speed(self, flow: ArrayLike, dp: ArrayLike | None = None, *,
              dp_i: ArrayLike | None = None, p_ex: ArrayLike = 0.0, errors: Errors = 'raise',
              method: Literal['auto', 'iterative'] = 'auto') -> OperatingPoints:
        """
        Compute the effective speed and losses from flow and pressure (inverse map).

        With eq. (33) this is the closed form of eq. (40); with eq. (39), or
        with ``method='iterative'``, eq. (36) is solved for n numerically.

        Parameters
        ----------
        flow : float or ndarray
            Flow into the motor Q, [m^3/s]
        dp : float or ndarray, optional
            Pressure drop between the ports; eqs. (34)-(35) give dp_i, [Pa]
        dp_i : float or ndarray, optional
            Pressure drop in the working chambers, instead of `dp`, [Pa]
        p_ex : float or ndarray
            Pressure driving the external leakage, eq. (24), [Pa]
        errors : {'raise', 'mask'}
            Raise on the first invalid element, or return it as NaN, [-]
        method : {'auto', 'iterative'}
            Force the numerical solver even where eq. (40) applies, [-]

        Returns
        -------
        OperatingPoints
            Speed, speed loss, losses and status per element.

        """
        dp_name, dp_value = self._which_dp(dp, dp_i)
        if method not in ('auto', 'iterative'):
            msg = f"method = {method!r}: use 'auto' or 'iterative'"
            raise ModelError(msg)
        arrays, status = self._prepare(
            {'flow': (flow, 'm^3/s'), dp_name: (dp_value, 'Pa'), 'p_ex': (p_ex, 'Pa')}, errors)
        closed_form = self.displacement_law == 'eq33' and method == 'auto'
        given = {'flow': arrays[0], 'dp': arrays[1]} if dp is not None else {'flow': arrays[0]}

        def core(q: FloatArray, dpv: FloatArray, pex: FloatArray,
                 status: npt.NDArray[np.uint8], at: At) -> _Chunk:
            chamber = dpv if dp is None else self._chamber_drop(dpv, q, status)
            chamber = self._check_limits(chamber, dp_name, dpv, status, errors, at)
            q_lfg, q_c, q_ex = self._leakage(chamber, pex)
            leak = q_lfg + q_c + q_ex
            if closed_form:
                n = effective_speed(q, chamber, leak, self.c, self.coef.c_id, self.geometry)
            else:
                n = self._solve_speed(q, chamber, leak)
            if n.size and n.min() == 0.0:
                status |= (n == 0.0) * np.uint8(PointStatus.STALLED)
            losses = self._breakdown(n, chamber, q_lfg, q_c, q_ex, leak)
            port = dpv if dp is not None else chamber + self._channel_drop(q)
            return self._finish(tuple(given), status, flow=q, speed=n, dp=port, dp_i=chamber,
                                **losses)

        return self._run(core, arrays, status, given, not closed_form)

    def _solve_speed(self, flow: FloatArray, dp_i: FloatArray, leak: FloatArray) -> FloatArray:
        """Solve eq. (36) for n at given flow and dp_i (Newton, bracketed)."""
        qt = self.geometry.displacement
        hi = np.maximum(flow - leak, 0.0) / qt  # all of it through the displacement
        lo = (eq.empirical_speed_floor(dp_i, self.coef) if self.displacement_law == 'eq39'
              else np.zeros_like(hi))
        moving = (absorbency(lo, self._displacement_loss(lo, dp_i) + leak, self.geometry) < flow) \
            & (hi > lo)

        def residual(n: FloatArray) -> tuple[FloatArray, FloatArray]:
            loss = self._displacement_loss(n, dp_i)
            return (absorbency(n, loss + leak, self.geometry) - flow,
                    qt + self._displacement_loss_slopes(n, dp_i, loss)[0])

        lo, hi = np.where(moving, lo, 0.0), np.where(moving, hi, 0.0)
        n, _ = solve_increasing(residual, lo, hi, hi, xtol=_RTOL * hi + 1e-15)
        return np.where(moving, n, 0.0)

    def absorbency(self, speed: ArrayLike, dp: ArrayLike | None = None, *,
                   dp_i: ArrayLike | None = None, p_ex: ArrayLike = 0.0,
                   errors: Errors = 'raise') -> OperatingPoints:
        """
        Compute the flow the motor absorbs at a speed and pressure (forward map).

        With `dp_i` this is eq. (36) directly. With port `dp`, the channel drop
        of eq. (35) depends on the very flow being computed, so eq. (36) and
        eq. (34) are solved together numerically.

        Parameters
        ----------
        speed : float or ndarray
            Shaft speed n, [rad/s]
        dp : float or ndarray, optional
            Pressure drop between the ports, [Pa]
        dp_i : float or ndarray, optional
            Pressure drop in the working chambers, instead of `dp`, [Pa]
        p_ex : float or ndarray
            Pressure driving the external leakage, eq. (24), [Pa]
        errors : {'raise', 'mask'}
            Raise on the first invalid element, or return it as NaN, [-]

        Returns
        -------
        OperatingPoints
            Absorbency, losses and status per element.

        """
        dp_name, dp_value = self._which_dp(dp, dp_i)
        arrays, status = self._prepare(
            {'speed': (speed, 'rad/s'), dp_name: (dp_value, 'Pa'), 'p_ex': (p_ex, 'Pa')}, errors)
        given = {'speed': arrays[0], 'dp': arrays[1]} if dp is not None else {'speed': arrays[0]}

        def core(n: FloatArray, dpv: FloatArray, pex: FloatArray,
                 status: npt.NDArray[np.uint8], at: At) -> _Chunk:
            if dp is None:
                chamber = dpv
            else:
                chamber = self._chamber_drop(dpv, self._solve_flow(n, dpv, pex), status)
            chamber = self._check_limits(chamber, dp_name, dpv, status, errors, at)
            if self.displacement_law == 'eq39':
                self._check_empirical_floor(n, chamber, status, errors, at)
            q_lfg, q_c, q_ex = self._leakage(chamber, pex)
            leak = q_lfg + q_c + q_ex
            losses = self._breakdown(n, chamber, q_lfg, q_c, q_ex, leak)
            flow = absorbency(n, losses['total'], self.geometry)
            port = dpv if dp is not None else chamber + self._channel_drop(flow)
            return self._finish(tuple(given), status, flow=flow, speed=n, dp=port, dp_i=chamber,
                                **losses)

        return self._run(core, arrays, status, given, dp is not None)

    def _check_empirical_floor(self, n: FloatArray, dp_i: FloatArray,
                               status: npt.NDArray[np.uint8], errors: Errors, at: At) -> None:
        below = (n > 0.0) & (n < eq.empirical_speed_floor(dp_i, self.coef))
        if below.any():
            if errors == 'raise':
                _raise_first('speed', 'rad/s', n, below,
                             'below the floor of eq. (39), where its loss diverges', at)
            status |= below * np.uint8(PointStatus.BEYOND_LIMIT)

    def _solve_flow(self, speed: FloatArray, dp: FloatArray, p_ex: FloatArray) -> FloatArray:
        """Solve eqs. (34)-(36) together for Q at given n and port dp (Newton, bracketed)."""
        qt = self.geometry.displacement
        dp_cap = np.minimum(dp, self.dp_limit)

        def residual(flow: FloatArray) -> tuple[FloatArray, FloatArray]:
            dp_i = np.maximum(dp_cap - self._channel_drop(flow), 0.0)
            q_lfg, q_c, q_ex = self._leakage(dp_i, p_ex)
            loss = self._displacement_loss(speed, dp_i)
            absorbed = absorbency(speed, loss + q_lfg + q_c + q_ex, self.geometry)
            d_loss = self._displacement_loss_slopes(speed, dp_i, loss)[1]
            d_absorbed = np.where(dp_i > 0.0, (self._leakage_slope(dp_i, q_lfg, q_c) + d_loss)
                                  * (2.0 * self._channel_a * flow + self._channel_b), 0.0)
            return flow - absorbed, 1.0 + d_absorbed

        # The flow absorbed falls as the flow rises (more channel drop, less chamber drop): the
        # flow without any channel drop is an upper bound, q_t n a lower one.
        q_lfg, q_c, q_ex = self._leakage(dp_cap, p_ex)
        upper = absorbency(speed, self._displacement_loss(speed, dp_cap) + q_lfg + q_c + q_ex,
                           self.geometry)
        flow, _ = solve_increasing(residual, qt * speed, upper, upper,
                                   xtol=_RTOL * upper + 1e-18)
        return flow

    @staticmethod
    def _which_dp(dp: ArrayLike | None, dp_i: ArrayLike | None) -> tuple[str, ArrayLike]:
        if (dp is None) == (dp_i is None):
            raise ModelError('give exactly one of dp (between the ports) and dp_i (chambers)')
        return ('dp', dp) if dp is not None else ('dp_i', dp_i)

    def breakdown(self, speed: ArrayLike, dp_i: ArrayLike, p_ex: ArrayLike = 0.0,
                  errors: Errors = 'raise') -> LossBreakdown:
        """
        Compute the loss components at given speed and chamber pressure drop, eq. (31).

        Parameters
        ----------
        speed : float or ndarray
            Shaft speed n, [rad/s]
        dp_i : float or ndarray
            Pressure drop in the working chambers, [Pa]
        p_ex : float or ndarray
            Pressure driving the external leakage, eq. (24), [Pa]
        errors : {'raise', 'mask'}
            Raise on the first invalid element, or return it as NaN, [-]

        Returns
        -------
        LossBreakdown
            Every component of eq. (31) and their total, [m^3/s]

        """
        return self.absorbency(speed, dp_i=dp_i, p_ex=p_ex, errors=errors).losses

    # -- single points ---------------------------------------------------------------------

    def speed_point(self, flow: float, dp: float | None = None, *, dp_i: float | None = None,
                    p_ex: float = 0.0) -> Point:
        """
        Compute the inverse map n(Q, dp) at one operating point, on Python floats.

        Equal to :meth:`speed` with ``errors='mask'`` to 1e-12, at a few
        microseconds a call. Bad values never raise: the point comes back NaN
        with its :class:`PointStatus` flags.

        Parameters
        ----------
        flow : float
            Flow into the motor Q, [m^3/s]
        dp : float, optional
            Pressure drop between the ports, [Pa]
        dp_i : float, optional
            Pressure drop in the working chambers, instead of `dp`, [Pa]
        p_ex : float
            Pressure driving the external leakage, eq. (24), [Pa]

        Returns
        -------
        Point
            The operating point.

        Raises
        ------
        ModelError
            If not exactly one of `dp` and `dp_i` is given, or an argument is not a number.

        """
        if dp is None:
            if dp_i is None:
                self._which_dp(dp, dp_i)
            port, value = False, dp_i
        elif dp_i is None:
            port, value = True, dp
        else:
            self._which_dp(dp, dp_i)
        if type(flow) is not float:
            flow = as_float('flow', flow)
        if type(value) is not float:
            value = as_float('dp' if port else 'dp_i', value)
        if type(p_ex) is not float:
            p_ex = as_float('p_ex', p_ex)
        return self._point.speed(flow, value, port, p_ex)

    def absorbency_point(self, speed: float, dp: float | None = None, *,
                         dp_i: float | None = None, p_ex: float = 0.0,
                         flow_guess: float | None = None) -> Point:
        """
        Compute the forward map Q(n, dp) at one operating point, on Python floats.

        Equal to :meth:`absorbency` with ``errors='mask'`` to 1e-12. With a port
        `dp`, eqs. (34)-(36) are solved together; `flow_guess` (for instance
        the previous step's flow) starts that solve near its root.

        Parameters
        ----------
        speed : float
            Shaft speed n, [rad/s]
        dp : float, optional
            Pressure drop between the ports, [Pa]
        dp_i : float, optional
            Pressure drop in the working chambers, instead of `dp`, [Pa]
        p_ex : float
            Pressure driving the external leakage, eq. (24), [Pa]
        flow_guess : float, optional
            Starting estimate of Q for the coupled solve; ignored unless it is
            finite and above q_t*n, [m^3/s]

        Returns
        -------
        Point
            The operating point.

        Raises
        ------
        ModelError
            If not exactly one of `dp` and `dp_i` is given, or an argument is not a number.

        """
        if dp is None:
            if dp_i is None:
                self._which_dp(dp, dp_i)
            port, value = False, dp_i
        elif dp_i is None:
            port, value = True, dp
        else:
            self._which_dp(dp, dp_i)
        if type(speed) is not float:
            speed = as_float('speed', speed)
        if type(value) is not float:
            value = as_float('dp' if port else 'dp_i', value)
        if type(p_ex) is not float:
            p_ex = as_float('p_ex', p_ex)
        if flow_guess is not None and type(flow_guess) is not float:
            flow_guess = as_float('flow_guess', flow_guess)
        return self._point.absorbency(speed, value, port, p_ex, flow_guess)

    def breakdown_point(self, speed: float, dp_i: float, p_ex: float = 0.0) -> Point:
        """
        Compute the loss components at one speed and chamber pressure drop, eq. (31).

        Parameters
        ----------
        speed : float
            Shaft speed n, [rad/s]
        dp_i : float
            Pressure drop in the working chambers, [Pa]
        p_ex : float
            Pressure driving the external leakage, eq. (24), [Pa]

        Returns
        -------
        Point
            The operating point (its flow is the absorbency of eq. 36).

        """
        if type(speed) is not float:
            speed = as_float('speed', speed)
        if type(dp_i) is not float:
            dp_i = as_float('dp_i', dp_i)
        if type(p_ex) is not float:
            p_ex = as_float('p_ex', p_ex)
        return self._point.absorbency(speed, dp_i, False, p_ex, None)
