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
        """
        Solve eq. (36) with eq. (39) for n at given flow and dp_i (Newton, bracketed).

        Like the coupled solve, it stops without a confirming evaluation once
        two Newton evaluations show that the error left is far below tolerance.
        """
        d = self.d
        qt = d.qt
        hi = max(flow - leak, 0.0) / qt
        lo = self.speed_floor(dp_i)
        if not (qt * lo + (self.empirical_loss(lo, dp_i) + leak) < flow and hi > lo):
            return 0.0
        above = dp_i > EMPIRICAL_DP_FLOOR
        dp_mpa = dp_i / MPA if above else _FLOOR_MPA
        log_dp = math.log(dp_mpa)
        c1, c2 = d.c1_39, d.c2_39
        rtol = self.rtol
        x = hi
        last_x = last_slope = _NAN
        for _ in range(60):
            inv_sqrt_n = 1.0 / math.sqrt(x / RPM)
            loss = (c1 * inv_sqrt_n * dp_mpa ** (c2 * inv_sqrt_n) * _CM3_PER_REV) * x
            f = qt * x + (loss + leak) - flow
            if f < 0.0:
                lo = x
            elif f > 0.0:
                hi = x
            else:
                return x
            slope = qt + loss * (1.0 - c2 * log_dp * inv_sqrt_n) / (2.0 * x)
            step = f / slope
            newton = x - step
            if lo < newton < hi:
                size = abs(step)
                if size <= rtol * x:
                    return newton
                if (abs(slope - last_slope) * size * size
                        <= 1e-3 * rtol * x * abs(x - last_x) * slope):
                    return newton
                last_x, last_slope, x = x, slope, newton
            elif hi - lo <= rtol * x:
                return x
            else:
                last_x, last_slope, x = x, _NAN, 0.5 * (lo + hi)
        return x

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

    def _solve_flow(self, speed: float, dp: float, p_ex: float,
                    guess: float | None) -> float:
        """
        Solve eqs. (34)-(36) together for Q at given n and port dp.

        The flow absorbed, A(Q), falls as Q rises (more channel drop, less
        chamber drop), so every evaluation brackets the root of f = Q - A(Q)
        between Q and A(Q); Newton steps from `guess` stay inside the bracket.
        Once two evaluations give the curvature, a step whose predicted error
        (curvature * step^2) is far below the tolerance ends the solve without
        one more evaluation to confirm it.
        """
        d = self.d
        dp_cap = dp if dp < d.dp_limit else d.dp_limit
        ch_a, ch_b, h0, compliance = d.ch_a, d.ch_b, d.h0, d.compliance
        lfg_k, lfg_e, com_k, com_e = d.lfg_k, d.lfg_e, d.com_k, d.com_e
        base = d.qt * speed + 0.0  # q_t n
        q_ex = d.k_ex * p_ex if d.k_ex else 0.0
        empirical = self.empirical
        if empirical:
            inv_sqrt_n = 1.0 / math.sqrt(speed / RPM) if speed > 0.0 else 0.0
            c1, c2 = d.c1_39 * inv_sqrt_n, d.c2_39 * inv_sqrt_n
        else:
            k_pn, ine = d.k_p * speed, d.k_i * math.sqrt(speed)
        rtol = self.rtol
        lo, hi = base, _INF
        x = guess if guess is not None and lo < guess < _INF else dp_cap * 0.0
        last_x = last_slope = _NAN
        for _ in range(60):
            dp_i = dp_cap - (ch_a * x + ch_b) * x
            if dp_i <= 0.0:
                dp_i = 0.0
            h = h0 - compliance * dp_i
            q_lfg = lfg_k * (h * h * h * dp_i) ** lfg_e
            q_c = com_k * dp_i ** com_e
            if empirical:
                above = dp_i > EMPIRICAL_DP_FLOOR
                dp_mpa = dp_i / MPA if above else _FLOOR_MPA
                loss = (c1 * dp_mpa ** c2 * _CM3_PER_REV) * speed
                d_loss = loss * c2 / dp_i if above else 0.0
            else:
                loss = k_pn * dp_i + ine
                d_loss = k_pn
            absorbed = base + (loss + q_lfg + q_c + q_ex)
            f = x - absorbed
            if f < 0.0:
                lo = x if x > lo else lo
                hi = absorbed if absorbed < hi else hi
            elif f > 0.0:
                hi = x if x < hi else hi
                lo = absorbed if absorbed > lo else lo
            else:
                return x
            if dp_i > 0.0:
                d_leak = (q_lfg * lfg_e * (1.0 / dp_i - 3.0 * compliance / h)
                          + q_c * com_e / dp_i)
                slope = 1.0 + (d_leak + d_loss) * (2.0 * ch_a * x + ch_b)
            else:
                slope = _NAN  # the kink at dp_i = 0: no curvature estimate across it
            step = f / slope if dp_i > 0.0 else f
            newton = x - step
            if lo <= newton <= hi:
                size = abs(step)
                if size <= rtol * x:
                    return newton
                # two Newton evaluations on the smooth side give the curvature, and with it
                # the error left after this step
                if (abs(slope - last_slope) * size * size
                        <= 1e-3 * rtol * x * abs(x - last_x) * slope):
                    return newton
                last_x, last_slope, x = x, slope, newton
            elif hi - lo <= rtol * x:
                return x
            else:
                last_x, last_slope, x = x, _NAN, 0.5 * (lo + hi)
        return x
