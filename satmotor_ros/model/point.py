# SPDX-License-Identifier: Apache-2.0
"""
One operating point on Python floats: the model at a few microseconds a call.

The array maps of :class:`~satmotor_ros.model.MotorModel` pay numpy's fixed
cost per call (tens of microseconds), which a 1 kHz plant cannot afford. This
module evaluates the same equations for a single point on Python floats. Every
constant comes from :class:`~satmotor_ros.model.derived.DerivedCoefficients`,
which reads it off the equation functions' own helpers; what is left here is
the form of each equation (a product, a power), and the tests hold it equal to
the equation functions and the array maps to 1e-12 on dense grids.
"""

from __future__ import annotations

import math

from satmotor_ros.model.derived import DerivedCoefficients
from satmotor_ros.model.errors import InvalidInputError
from satmotor_ros.model.losses import EMPIRICAL_DP_FLOOR
from satmotor_ros.model.results import Point, PointStatus
from satmotor_ros.model.solve import solve_increasing_scalar
from satmotor_ros.model.units import MPA, RPM

_CM3_PER_REV = 1.0e-6 / (2.0 * math.pi)  # one cm^3/rev in m^3/rad, as in losses.py
_NOT_FINITE = int(PointStatus.NOT_FINITE)
_NEGATIVE = int(PointStatus.NEGATIVE)
_BEYOND_LIMIT = int(PointStatus.BEYOND_LIMIT)
_STALLED = int(PointStatus.STALLED)
_CHANNEL_LIMITED = int(PointStatus.CHANNEL_LIMITED)
_EXTRAPOLATED = int(PointStatus.EXTRAPOLATED)
_FLOOR_MPA = EMPIRICAL_DP_FLOOR / MPA
_INF = math.inf
_NAN = math.nan
_new_point = tuple.__new__


def _invalid(status: int) -> Point:
    """Return the all-NaN point of an invalid element, as the array maps mask it."""
    return _new_point(Point, (_NAN,) * 12 + (status,))


def as_float(name: str, value: object) -> float:
    """
    Convert one scalar argument to a Python float, refusing what is not a number.

    Parameters
    ----------
    name : str
        Argument name, for the message, [-]
    value : object
        A real number (int, float, numpy scalar or 0-d array), [SI]

    Returns
    -------
    float
        The value.

    Raises
    ------
    InvalidInputError
        For a string, a bool, a sequence or anything else that is not one real number.

    """
    if isinstance(value, (str, bytes, bool)):
        msg = f'{name} = {value!r}: expected a number, got {type(value).__name__}'
        raise InvalidInputError(msg)
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        msg = f'{name} = {value!r}: expected one number, got {type(value).__name__}'
        raise InvalidInputError(msg) from None


def _screen(value: float) -> int:
    """Return the NOT_FINITE / NEGATIVE flags of one input."""
    if value != value or value == _INF or value == -_INF:
        return _NOT_FINITE
    return _NEGATIVE if value < 0.0 else 0


class PointEvaluator:
    """
    Evaluate single operating points of one model on Python floats.

    Parameters
    ----------
    derived : DerivedCoefficients
        The model's constants, [-]
    empirical : bool
        True for Delta q from eq. (39), False for eq. (33), [-]
    rtol : float
        Relative tolerance of the iterative solves, [-]

    """

    def __init__(self, derived: DerivedCoefficients, empirical: bool, rtol: float) -> None:
        """Keep the constants as attributes for quick access."""
        self.d = derived
        self.empirical = empirical
        self.rtol = rtol

    # -- equations ------------------------------------------------------------------------

    def leakage(self, dp_i: float, p_ex: float) -> tuple[float, float, float]:
        """Return Q_Lfg, Q_C and Q_ex of eqs. (1), (2), (5) and (24), [m^3/s]."""
        d = self.d
        h = d.h0 - d.compliance * dp_i
        q_ex = d.k_ex * p_ex if d.k_ex else 0.0
        return d.lfg_k * (h * h * h * dp_i) ** d.lfg_e, d.com_k * dp_i ** d.com_e, q_ex

    def empirical_loss(self, speed: float, dp_i: float) -> float:
        """Return Delta Q_vl = Delta q * n with Delta q of eq. (39), [m^3/s]."""
        if speed <= 0.0:
            return 0.0
        inv_sqrt_n = 1.0 / math.sqrt(speed / RPM)
        d = self.d
        dp_mpa = dp_i / MPA if dp_i > EMPIRICAL_DP_FLOOR else _FLOOR_MPA
        return (d.c1_39 * inv_sqrt_n * dp_mpa ** (d.c2_39 * inv_sqrt_n) * _CM3_PER_REV) * speed

    def displacement_loss(self, speed: float, dp_i: float) -> float:
        """Return Delta Q_vl of eq. (33) or (39), [m^3/s]."""
        if self.empirical:
            return self.empirical_loss(speed, dp_i)
        d = self.d
        return d.k_p * dp_i * speed + d.k_i * math.sqrt(speed)

    def speed_floor(self, dp_i: float) -> float:
        """Return the lowest speed at which eq. (39) is used, [rad/s]."""
        return (self.d.c2_39 * math.log(max(dp_i / MPA, 1.0))) ** 2 * RPM

    def _point(self, flow: float | None, speed: float, dp: float | None, dp_i: float,
               q_lfg: float, q_c: float, q_ex: float, status: int) -> Point:
        """
        Compose the loss breakdown of eq. (31) and the status into a :class:`Point`.

        A `flow` of None is the absorbency of eq. (36); a `dp` of None is dp_i
        plus the channel drop of eq. (35) at that flow.
        """
        d = self.d
        fc = d.k_fc * dp_i * speed
        dch = d.k_dch * dp_i * speed
        bl = d.k_b * dp_i * speed
        ine = d.k_i * math.sqrt(speed)
        if self.empirical:
            physical = fc + dch + bl + ine
            scale = self.empirical_loss(speed, dp_i) / physical if physical > 0.0 else 0.0
            fc, dch, bl, ine = fc * scale, dch * scale, bl * scale, ine * scale
        total = q_lfg + q_c + q_ex + ((fc + dch) + (bl + ine))
        if dp_i > d.dp_max or speed > d.speed_max:
            status |= _EXTRAPOLATED
        if flow is None:
            flow = d.qt * speed + total
        if dp is None:
            dp = dp_i + (d.ch_a * flow + d.ch_b) * flow
        return _new_point(Point, (flow, speed, dp, dp_i, q_lfg, q_c, fc, dch, bl, ine, q_ex,
                                  total, status))

    # -- maps -----------------------------------------------------------------------------

    def speed(self, flow: float, dp: float, port: bool, p_ex: float) -> Point:
        """
        Compute the inverse map n(Q, dp) at one point.

        Parameters
        ----------
        flow : float
            Flow into the motor Q, [m^3/s]
        dp : float
            Port drop if `port`, else chamber drop, [Pa]
        port : bool
            Whether `dp` is between the ports, [-]
        p_ex : float
            Pressure driving the external leakage, [Pa]

        Returns
        -------
        Point
            The operating point.

        """
        status = _screen(flow) | _screen(dp) | _screen(p_ex)
        if status:
            return _invalid(status)
        d = self.d
        if port:
            dp_i = dp - (d.ch_a * flow + d.ch_b) * flow
            if dp_i < 0.0:
                status = _CHANNEL_LIMITED
                dp_i = 0.0
        else:
            dp_i = dp
        if dp_i > d.dp_limit:
            return _invalid(_BEYOND_LIMIT)
        q_lfg, q_c, q_ex = self.leakage(dp_i, p_ex)
        leak = q_lfg + q_c + q_ex
        if self.empirical:
            speed = self._solve_speed(flow, dp_i, leak)
        else:
            x = flow - leak
            x = x * d.es_scale if x > 0.0 else 0.0
            two_a = d.es_a0 + d.es_a1 * dp_i
            if d.es_b == 0.0:
                speed = x / two_a
            else:
                root = x / (math.sqrt(two_a * x + d.es_b * d.es_b) + d.es_b)
                speed = root * root
        if speed == 0.0:
            status |= _STALLED
        return self._point(flow, speed, dp if port else None, dp_i, q_lfg, q_c, q_ex, status)

    def _solve_speed(self, flow: float, dp_i: float, leak: float) -> float:
        """Solve eq. (36) for n at given flow and dp_i (Newton, bracketed)."""
        qt = self.d.qt
        hi = max(flow - leak, 0.0) / qt
        lo = self.speed_floor(dp_i)
        if not (qt * lo + (self.displacement_loss(lo, dp_i) + leak) < flow and hi > lo):
            return 0.0
        empirical_loss = self.empirical_loss
        c2 = self.d.c2_39
        log_dp = math.log(dp_i / MPA) if dp_i > EMPIRICAL_DP_FLOOR else 0.0

        def residual(n: float) -> tuple[float, float]:
            loss = empirical_loss(n, dp_i)
            d_speed = loss * (1.0 - c2 * log_dp / math.sqrt(n / RPM)) / (2.0 * n)
            return qt * n + (loss + leak) - flow, qt + d_speed

        rtol = self.rtol
        n, _ = solve_increasing_scalar(residual, lo, hi, hi, rtol * hi + 1e-15, rtol * flow)
        return n

    def absorbency(self, speed: float, dp: float, port: bool, p_ex: float,
                   flow_guess: float | None) -> Point:
        """
        Compute the forward map Q(n, dp) at one point.

        Parameters
        ----------
        speed : float
            Shaft speed n, [rad/s]
        dp : float
            Port drop if `port`, else chamber drop, [Pa]
        port : bool
            Whether `dp` is between the ports, [-]
        p_ex : float
            Pressure driving the external leakage, [Pa]
        flow_guess : float or None
            Starting estimate of Q for the coupled solve, [m^3/s]

        Returns
        -------
        Point
            The operating point.

        """
        status = _screen(speed) | _screen(dp) | _screen(p_ex)
        if status:
            return _invalid(status)
        d = self.d
        if port:
            flow = self._solve_flow(speed, dp, p_ex, flow_guess)
            dp_i = dp - (d.ch_a * flow + d.ch_b) * flow
            if dp_i < 0.0:
                status = _CHANNEL_LIMITED
                dp_i = 0.0
        else:
            dp_i = dp
        if dp_i > d.dp_limit:
            return _invalid(_BEYOND_LIMIT)
        if self.empirical and 0.0 < speed < self.speed_floor(dp_i):
            return _invalid(_BEYOND_LIMIT)
        q_lfg, q_c, q_ex = self.leakage(dp_i, p_ex)
        return self._point(None, speed, dp if port else None, dp_i, q_lfg, q_c, q_ex, status)

    def _absorbed(self, speed: float, dp_cap: float, p_ex: float,
                  flow: float) -> tuple[float, float]:
        """Return the flow eq. (36) absorbs when Q = `flow` sets dp_i, and its slope in Q."""
        d = self.d
        dp_i = dp_cap - (d.ch_a * flow + d.ch_b) * flow
        if dp_i <= 0.0:
            dp_i = 0.0
        q_lfg, q_c, q_ex = self.leakage(dp_i, p_ex)
        loss = self.displacement_loss(speed, dp_i)
        absorbed = d.qt * speed + (loss + q_lfg + q_c + q_ex)
        if dp_i == 0.0:
            return absorbed, 0.0
        h = d.h0 - d.compliance * dp_i
        d_leak = q_lfg * d.lfg_e * (1.0 / dp_i - 3.0 * d.compliance / h) + q_c * d.com_e / dp_i
        if self.empirical:
            d_loss = (loss * d.c2_39 / math.sqrt(speed / RPM) / dp_i
                      if speed > 0.0 and dp_i > EMPIRICAL_DP_FLOOR else 0.0)
        else:
            d_loss = d.k_p * speed
        return absorbed, -(d_leak + d_loss) * (2.0 * d.ch_a * flow + d.ch_b)

    def _solve_flow(self, speed: float, dp: float, p_ex: float,
                    guess: float | None) -> float:
        """
        Solve eqs. (34)-(36) together for Q at given n and port dp.

        The flow absorbed falls as Q rises (more channel drop, less chamber
        drop), so each evaluation at Q brackets the root between Q and the
        flow absorbed there; Newton steps from `guess` stay inside it.
        """
        d = self.d
        dp_cap = dp if dp < d.dp_limit else d.dp_limit
        lo, hi = d.qt * speed, _INF
        x = guess if guess is not None and lo < guess < _INF else None
        if x is None:
            x = self._absorbed(speed, dp_cap, p_ex, 0.0)[0]  # no channel drop: an upper bound
            hi = x
        rtol = self.rtol
        for _ in range(60):
            absorbed, d_absorbed = self._absorbed(speed, dp_cap, p_ex, x)
            f = x - absorbed
            if f < 0.0:
                lo, hi = x, min(hi, absorbed)
            elif f > 0.0:
                lo, hi = max(lo, absorbed), x
            else:
                return x
            slope = 1.0 - d_absorbed
            newton = x - f / slope
            if lo <= newton <= hi:
                if abs(newton - x) <= rtol * x:
                    return newton
                x = newton
            elif hi - lo <= rtol * x:
                return x
            else:
                x = 0.5 * (lo + hi)
        return x
