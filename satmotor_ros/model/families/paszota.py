# SPDX-License-Identifier: Apache-2.0
"""
The ``paszota`` family: Paszota and Mączyszyn's eq. (29), composed for one motor.

Any constant-displacement motor: the volumetric losses are one power law of
the chamber drop, the speed and the viscosity (eq. 29; eq. 30 is the pump's).
The chamber drop is the port drop less the channel drop of the paper's
eq. (35), whose coefficients default to Table 1's for oil. See
doc/families.md for the defaults.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
import math
from typing import Any, cast

from satmotor_ros.model._numeric import maximum
from satmotor_ros.model._typing import Real
from satmotor_ros.model.coefficients import (CoefficientSet, FieldError, Liquid, MotorGeometry,
                                             ValidRange)
from satmotor_ros.model.families import paszota_losses as eq
from satmotor_ros.model.families._base import (Bounds, bounds, Family, inverse_dp, LinearPart,
                                               SM_DISPLACEMENT, SplitEquations, Terms)
from satmotor_ros.model.families.sliwinski2017.losses import (channel_coefficients,
                                                              channel_pressure_drop)
from satmotor_ros.model.units import MPA, RPM


@dataclass(frozen=True)
class PaszotaCoefficients:
    """
    Coefficients of eq. (29) for one motor, SI; defaults fitted to the SM-0,75/25.

    k_g and the exponents are the least-squares fit of log Q_vl to the paper's
    own model of the SM-0,75/25 on oil and water over its measured range
    (``doc/families.py``); p_n and n_t are the top of that range, nu_n
    the paper's 35 cSt. ``c_t`` and ``c_l`` are eq. (35)'s, in the paper's units
    (Q in l/min, mu in mPa*s -> Pa), Table 1's oil values.
    """

    k_g: float = 0.0470  # Q_l / Q_Pt at p_n, n_t and nu_n [-]
    a_pv: float = 0.482  # exponent of dp_i / p_n, > 0 [-]
    a_nv: float = 0.439  # exponent of n / n_t, >= 0 [-]
    a_vv: float = -0.248  # exponent of nu / nu_n [-]
    p_n: float = 25.0 * MPA  # nominal pressure [Pa]
    n_t: float = 1500.0 * RPM  # theoretical speed of the motor at Q_Pt = q_t n_t [rad/s]
    nu_n: float = eq.REFERENCE_VISCOSITY  # related viscosity nu_n [m^2/s]
    c_t: float = 1.26  # turbulent channel coefficient of eq. (35), Q in l/min -> Pa
    c_l: float = 0.684  # laminar channel coefficient of eq. (35), mu in mPa*s, Q in l/min -> Pa
    external_leakage: float = 0.0  # lumped Q_ex = k p_ex, eq. (24) [m^3/(s*Pa)]

    def __post_init__(self) -> None:
        """Reject coefficients the equations cannot use, naming the field."""
        for name, low, strict in (('k_g', 0.0, False), ('a_pv', 0.0, True),
                                  ('a_nv', 0.0, False), ('p_n', 0.0, True),
                                  ('n_t', 0.0, True), ('nu_n', 0.0, True), ('c_t', 0.0, False),
                                  ('c_l', 0.0, False), ('external_leakage', 0.0, False)):
            value = getattr(self, name)
            if not (math.isfinite(value) and (value > low if strict else value >= low)):
                raise FieldError('coefficients', name, f'{value!r} is outside '
                                 f'{"(" if strict else "["}{low}, inf)')
        if not (math.isfinite(self.a_vv) and abs(self.a_vv) < 10.0):
            raise FieldError('coefficients', 'a_vv', f'{self.a_vv!r} is outside (-10, 10)')


@dataclass(frozen=True)
class PaszotaConstants(Bounds):
    """The constants of eq. (29) for one motor and liquid."""

    k_l: float  # k_g Q_Pt (nu/nu_n)^a_vv: Q_l at p_n and n_t [m^3/s]
    a_pv: float  # [-]
    a_nv: float  # [-]
    p_n: float  # [Pa]
    n_t: float  # [rad/s]
    ch_a: float  # Delta p_ich = (ch_a Q + ch_b) Q, eq. (35) [Pa*s^2/m^6]
    ch_b: float  # [Pa*s/m^3]
    k_ex: float  # Q_ex = k_ex p_ex [m^3/(s*Pa)]


def constants(geometry: MotorGeometry, coefficient_set: CoefficientSet,
              valid_range: ValidRange, liquid: Liquid) -> PaszotaConstants:
    """
    Derive the constants of eq. (29) for one motor and liquid.

    The arguments are those of :meth:`~satmotor_ros.model.families._base.Family.compose`.

    Returns
    -------
    PaszotaConstants
        The constants.

    """
    c = cast(PaszotaCoefficients, coefficient_set.coefficients)
    q = geometry.displacement
    factor = eq.viscosity_factor(liquid.kinematic_viscosity, c.nu_n, c.a_vv)
    ch_a, ch_b = channel_coefficients(liquid, c)
    base = bounds(geometry, coefficient_set, valid_range, liquid, math.inf)
    return PaszotaConstants(**vars(base), k_l=c.k_g * q * c.n_t * factor, a_pv=c.a_pv,
                            a_nv=c.a_nv, p_n=c.p_n, n_t=c.n_t, ch_a=ch_a, ch_b=ch_b,
                            k_ex=c.external_leakage)


def _terms(d: PaszotaConstants) -> Terms:
    """Return eq. (29) as :class:`Terms`: the whole loss is the unlocated rest of the breakdown."""
    q, k_l, a_pv, a_nv, p_n, n_t = d.qt, d.k_l, d.a_pv, d.a_nv, d.p_n, d.n_t
    ch_a, ch_b, k_ex = d.ch_a, d.ch_b, d.k_ex

    def losses(speed: Real, dp_i: Real) -> Real:
        return eq.motor_leakage(dp_i, speed, 1.0, k_l, p_n, n_t, a_pv, a_nv, 1.0)

    def moving(speed: Real, dp_i: Real) -> tuple[Real, Real, Real, Real, Real]:
        zero = 0.0 * speed
        return zero, zero, zero, zero, losses(speed, dp_i)

    def moving_slopes(speed: Real, dp_i: Real) -> tuple[Real, Real]:
        loss = losses(speed, dp_i)
        return a_nv * loss * inverse_dp(speed), a_pv * loss * inverse_dp(dp_i)

    def closed_speed(flow: Real, dp_i: Real, lost: Real) -> Real:
        return maximum(flow - lost - losses(1.0 + 0.0 * dp_i, dp_i), 0.0) / q

    # eq. (36) is linear in n only where the loss does not depend on n
    closed: Callable[..., Any] | None = closed_speed if a_nv == 0.0 else None
    return Terms(channel=lambda flow: channel_pressure_drop(flow, ch_a, ch_b),
                 channel_slope=lambda flow: 2.0 * ch_a * flow + ch_b,
                 leak=lambda dp_i: (0.0 * dp_i, 0.0 * dp_i), leak_slope=lambda dp_i: 0.0 * dp_i,
                 external=lambda p_ex: k_ex * p_ex, moving=moving, moving_slopes=moving_slopes,
                 closed_speed=closed)


class Paszota(Family):
    """
    Paszota and Mączyszyn's model of a constant-displacement motor, eq. (29).

    Breakdown: the model does not show the sources of the losses, so only
    ``total`` holds eq. (29) (plus ``external``, Q_ex = k p_ex, 0 by default);
    every other component is 0.
    """

    name = 'paszota'
    leakage = ('losses',)  # eq. (29): the whole loss, no source told apart
    title = "Paszota and Maczyszyn's model of any constant-displacement motor, eqs. (29)-(30)"
    equations = 'eqs. (29)-(30)'
    coefficients_type = PaszotaCoefficients
    components = {'external': 'external Q_ex, eq. (24)', 'total': 'total Q_l, eq. (29)'}
    quantities = {'p_n': ('pressure', 'Pa'), 'n_t': ('speed', 'rad/s'),
                  'nu_n': ('viscosity', 'm^2/s')}

    def compose(self, geometry: MotorGeometry, coefficient_set: CoefficientSet,
                valid_range: ValidRange, liquid: Liquid, law: str) -> SplitEquations:
        """Compose eq. (29) and the channel drop of eqs. (34)-(35): see :meth:`Family.compose`."""
        self.check_law(law)
        d = constants(geometry, coefficient_set, valid_range, liquid)
        terms = _terms(d)

        def linear(speed: Real, dp_i: Real, p_ex: Real) -> tuple[Real, Real]:
            return terms.moving(speed, dp_i)[4], d.k_ex * p_ex + 0.0 * speed
        return SplitEquations(d, terms, 'eq29', linear)

    def linear_parts(self, coefficients: Any) -> tuple[LinearPart, ...]:
        """Return ``losses`` (k_g; its speed exponent is a_nv) and ``external``."""
        return (LinearPart('losses', 'eq. (29)', ('k_g',), coefficients.a_nv),
                LinearPart('external', 'eq. (24), lumped', ('external_leakage',), 0.0))

    def default_coefficients(self, packaged: CoefficientSet,
                             displacement: float) -> PaszotaCoefficients:
        """Return the defaults; eq. (35) scaled for a similar motor: c_t ~ q^(-4/3), c_l ~ 1/q."""
        ratio = displacement / SM_DISPLACEMENT
        base = PaszotaCoefficients()
        return PaszotaCoefficients(c_t=base.c_t * ratio ** (-4.0 / 3.0),
                                   c_l=base.c_l / ratio)
