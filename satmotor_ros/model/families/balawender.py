# SPDX-License-Identifier: Apache-2.0
"""
The ``balawender`` family: the earlier literature's model, eqs. (15)-(28), composed for one motor.

The coefficients are the oil's (index O of the paper). A working liquid whose
kinematic viscosity is below ``low_viscosity_below`` (default 2 cSt: water,
HFA-E emulsions) takes the low-viscosity variant: eqs. (16), (18), (22)-(23),
(26) and (28), with the oil named in the coefficients as the reference.
Above it (any oil) the liquid is the O of eqs. (15), (17), (20)-(21), (24),
(25), (27). See doc/families.md for the reading of the garbled equations and
the defaults.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any, cast

from satmotor_ros.model._numeric import maximum
from satmotor_ros.model._typing import Real
from satmotor_ros.model.coefficients import (CoefficientSet, FieldError, Liquid, MotorGeometry,
                                             ValidRange)
from satmotor_ros.model.families import balawender_losses as eq
from satmotor_ros.model.families._base import (Bounds, bounds, Family, inverse_dp, LinearPart,
                                               SplitEquations, Terms)
from satmotor_ros.model.units import CST


@dataclass(frozen=True)
class BalawenderCoefficients:
    """
    Coefficients of eqs. (15)-(28) for one motor, SI; defaults fitted to the SM-0,75/25.

    C_vl, C_ol and C_ot are the least-squares fit (relative error) of eqs. (15)
    and (16) to the paper's own model of the SM-0,75/25 on oil and on water over
    its measured range (2-25 MPa, 100-1500 rpm), C_ich of eq. (27) to its oil
    channel drop (eq. 35), B_h from eq. (2); ``doc/families.py`` fits them. The
    equations are dimensionless in these coefficients, so the defaults carry
    over to any displacement.
    """

    c_vl: float = 3.76e-9  # C_vl,O of eq. (17) [1/Pa]
    c_ol: float = 1.44e-9  # C_ol,O of eq. (20) [-]
    c_ot: float = 3.60e-6  # C_ot,O of eq. (21) [-]
    b_h: float = -4.945e-9  # B_h of eq. (20): relative clearance change [1/Pa]; from eq. (2)
    c_ich: float = 414.0  # C_ich,O of eq. (27) [-]
    k_ex: float = 1.0  # k_ex of eq. (16): external leakage E / O [-]
    external_leakage: float = 0.0  # C_ex,O q/mu_o of eq. (24), at the oil below [m^3/(s*Pa)]
    oil_viscosity: float = 40.0 * CST  # nu of the oil O the coefficients belong to [m^2/s]
    oil_density: float = 873.0  # rho_o [kg/m^3]
    oil_bulk_modulus: float = 1.6e9  # K_O of eq. (19) [Pa]
    low_viscosity_below: float = 2.0 * CST  # a liquid below takes eqs. (16)-(28)'s E [m^2/s]

    def __post_init__(self) -> None:
        """Reject coefficients the equations cannot use, naming the field."""
        for name in ('c_vl', 'c_ol', 'c_ot', 'c_ich', 'k_ex', 'external_leakage',
                     'low_viscosity_below'):
            _check(name, getattr(self, name), 0.0, math.inf)
        for name, high in (('oil_viscosity', 1.0), ('oil_density', 1.0e5),
                           ('oil_bulk_modulus', 1.0e12)):
            _check(name, getattr(self, name), 0.0, high, strict=True)
        _check('b_h', self.b_h, -1.0e-6, 1.0e-6)


def _check(name: str, value: float, low: float, high: float, strict: bool = False) -> None:
    if not (math.isfinite(value) and (value > low if strict else value >= low) and value < high):
        raise FieldError('coefficients', name, f'{value!r} is outside '
                         f'{"(" if strict else "["}{low}, {high})')


@dataclass(frozen=True)
class BalawenderConstants(Bounds):
    """The constants of eqs. (15)-(28) for one motor and liquid."""

    low_viscosity: bool  # the variant of eqs. (16)-(28) applies [-]
    mu_o: float  # mu_o of eqs. (20), (22)-(24): the liquid's own, or the oil's [Pa*s]
    rho_o: float  # rho_o of eqs. (21), (27)-(28) [kg/m^3]
    mu_e: float  # mu_E of eqs. (22)-(23) (the liquid's; = mu_o for oil) [Pa*s]
    k_c: float  # eq. (19), 1 for oil [-]
    k_ps: float  # Delta Q_vl = k_ps dp_i n, eqs. (17)-(18) [m^3/(Pa*rad)]
    k_ch: float  # Delta p_ich = k_ch Q^2, eqs. (26)-(28) at omega = Q/q [Pa*s^2/m^6]
    k_ext: float  # Q_ex = k_ext p_ex, eqs. (16), (24) [m^3/(s*Pa)]


def constants(geometry: MotorGeometry, coefficient_set: CoefficientSet,
              valid_range: ValidRange, liquid: Liquid) -> BalawenderConstants:
    """
    Derive the constants of the family's equations for one motor and liquid.

    The arguments are those of :meth:`~satmotor_ros.model.families._base.Family.compose`.

    Returns
    -------
    BalawenderConstants
        The constants; a liquid below ``low_viscosity_below`` gets the variant's.

    """
    c = cast(BalawenderCoefficients, coefficient_set.coefficients)
    q = geometry.displacement
    low = liquid.kinematic_viscosity < c.low_viscosity_below
    mu_ref = c.oil_density * c.oil_viscosity
    mu_o, rho_o = (mu_ref, c.oil_density) if low else (liquid.dynamic_viscosity, liquid.density)
    k_c = eq.compressibility_ratio(c.oil_bulk_modulus, liquid.bulk_modulus) if low else 1.0
    # eq. (27) at the speed of the flow, omega = Q/q; eq. (28) carries it to the liquid's rho
    k_h = eq.channel_ratio(liquid.density, rho_o, 1.0, 1.0)
    k_ch = k_h * eq.channel_pressure_drop_oil(1.0 / q, rho_o, q, c.c_ich)
    c_ex = c.external_leakage * mu_ref / q  # C_ex,O of eq. (24)
    k_ext = eq.external_leakage_oil(1.0, mu_o, q, c_ex) * (c.k_ex if low else 1.0)
    # Q_l ~ dp (1 + b dp)^3 rises while 1 + 4 b dp > 0; k_s dp^(-3/7) makes that 4/7 + ...
    if c.b_h < 0.0:
        dp_limit = -4.0 / (25.0 * c.b_h) if low else -1.0 / (4.0 * c.b_h)
    else:
        dp_limit = math.inf
    base = bounds(geometry, coefficient_set, valid_range, liquid, dp_limit)
    return BalawenderConstants(
        **vars(base), low_viscosity=low, mu_o=mu_o, rho_o=rho_o,
        mu_e=liquid.dynamic_viscosity, k_c=k_c,
        k_ps=eq.pressure_speed_loss_low_viscosity(1.0, 1.0, q, c.c_vl, k_c), k_ch=k_ch,
        k_ext=k_ext)


def _terms(d: BalawenderConstants, c: BalawenderCoefficients) -> Terms:
    """Return the family's loss as :class:`Terms`; the breakdown slots are documented there."""
    q, b_h, k_ps, k_ch, k_ext = d.qt, c.b_h, d.k_ps, d.k_ch, d.k_ext
    c_ol, c_ot, mu_o, rho_o, mu_e = c.c_ol, c.c_ot, d.mu_o, d.rho_o, d.mu_e
    transition = eq.LAMINAR_TRANSITION

    def oil_parts(dp_i: Real) -> tuple[Real, Real]:
        return (eq.laminar_leakage(dp_i, mu_o, q, c_ol, b_h),
                eq.turbulent_leakage(dp_i, rho_o, q, c_ot))

    def oil_slope(dp_i: Real, laminar: Real, turbulent: Real) -> Real:
        inv = inverse_dp(dp_i)
        return laminar * (inv + 3.0 * b_h / (1.0 + b_h * dp_i)) + 0.5 * turbulent * inv

    if d.low_viscosity:
        def leak(dp_i: Real) -> tuple[Real, Real]:
            laminar, turbulent = oil_parts(dp_i)
            return eq.leakage_ratio(dp_i, mu_o, mu_e) * (laminar + turbulent), 0.0 * dp_i

        def leak_slope(dp_i: Real) -> Real:
            laminar, turbulent = oil_parts(dp_i)
            k_s = eq.leakage_ratio(dp_i, mu_o, mu_e)
            d_k_s = (dp_i > transition) * (eq.TURBULENT_EXPONENT * k_s * inverse_dp(dp_i))
            out: Real = d_k_s * (laminar + turbulent) + k_s * oil_slope(dp_i, laminar, turbulent)
            return out
    else:
        def leak(dp_i: Real) -> tuple[Real, Real]:
            laminar, turbulent = oil_parts(dp_i)
            return laminar + turbulent, 0.0 * dp_i

        def leak_slope(dp_i: Real) -> Real:
            return oil_slope(dp_i, *oil_parts(dp_i))

    def moving(speed: Real, dp_i: Real) -> tuple[Real, Real, Real, Real, Real]:
        zero = 0.0 * speed
        return k_ps * dp_i * speed, zero, zero, zero, zero

    def closed_speed(flow: Real, dp_i: Real, lost: Real) -> Real:
        return maximum(flow - lost, 0.0) / (q + k_ps * dp_i)

    return Terms(channel=lambda flow: k_ch * flow * flow,
                 channel_slope=lambda flow: 2.0 * k_ch * flow, leak=leak, leak_slope=leak_slope,
                 external=lambda p_ex: k_ext * p_ex, moving=moving,
                 moving_slopes=lambda speed, dp_i: (k_ps * dp_i, k_ps * speed),
                 closed_speed=closed_speed)


class Balawender(Family):
    """
    The earlier literature's model, eqs. (15)-(28), with its low-viscosity variant.

    Breakdown: ``flat_clearance`` is the clearance leakage Q_l + Q_t (eqs. 20-21;
    times k_s of eqs. 22-23 for a low-viscosity liquid), ``compressibility`` the
    pressure-and-speed loss Delta Q_vl (eqs. 17-18, scaled by the bulk moduli as
    eq. 19 scales compressibility), ``external`` Q_ex (eq. 24); the family has
    no commutation, deformation, backlash or inertia component: those are 0.
    """

    name = 'balawender'
    channel = ('c_ich',)  # eq. (27)
    leakage = ('laminar', 'turbulent')  # eqs. (20)-(23)
    title = 'the earlier literature model, eqs. (15)-(28), with its low-viscosity variant'
    equations = 'eqs. (15)-(28)'
    coefficients_type = BalawenderCoefficients
    quantities = {'oil_viscosity': ('viscosity', 'm^2/s'), 'oil_density': ('density', 'kg/m^3'),
                  'oil_bulk_modulus': ('pressure', 'Pa'),
                  'low_viscosity_below': ('viscosity', 'm^2/s')}
    components = {'flat_clearance': 'clearances Q_l + Q_t, eqs. (20)-(23)',
                  'compressibility': 'pressure x speed dQ_vl, eqs. (17)-(19)',
                  'external': 'external Q_ex, eqs. (16), (24)',
                  'total': 'total Q_vl, eqs. (15)-(16)'}

    def compose(self, geometry: MotorGeometry, coefficient_set: CoefficientSet,
                valid_range: ValidRange, liquid: Liquid, law: str) -> SplitEquations:
        """Compose eqs. (15)-(28) for one motor and liquid: see :meth:`Family.compose`."""
        self.check_law(law)
        d = constants(geometry, coefficient_set, valid_range, liquid)
        c = cast(BalawenderCoefficients, coefficient_set.coefficients)
        return SplitEquations(d, _terms(d, c), 'eq16' if d.low_viscosity else 'eq15',
                              _linear(d, c))

    def linear_parts(self, coefficients: Any) -> tuple[LinearPart, ...]:
        """Return ``pressure_speed`` (C_vl), ``laminar`` (C_ol), ``turbulent`` (C_ot), external."""
        return (LinearPart('pressure_speed', 'eqs. (17)-(19)', ('c_vl',), 1.0),
                LinearPart('laminar', 'eqs. (20), (22)-(23)', ('c_ol',), 0.0),
                LinearPart('turbulent', 'eqs. (21)-(23)', ('c_ot',), 0.0),
                LinearPart('external', 'eqs. (16), (24)', ('external_leakage',), 0.0))

    def default_coefficients(self, packaged: CoefficientSet,
                             displacement: float) -> BalawenderCoefficients:
        """Return the defaults: dimensionless, the same for every displacement."""
        return BalawenderCoefficients()


def _linear(d: BalawenderConstants, c: BalawenderCoefficients) -> Any:
    """Return (n, dp_i, p_ex) -> the linear parts of Q_vl (:meth:`Balawender.linear_parts`)."""
    q = d.qt

    def linear(speed: Real, dp_i: Real, p_ex: Real) -> tuple[Real, Real, Real, Real]:
        k_s = eq.leakage_ratio(dp_i, d.mu_o, d.mu_e) if d.low_viscosity else 1.0
        return (d.k_ps * dp_i * speed, k_s * eq.laminar_leakage(dp_i, d.mu_o, q, c.c_ol, c.b_h),
                k_s * eq.turbulent_leakage(dp_i, d.rho_o, q, c.c_ot), d.k_ext * p_ex + 0.0 * speed)
    return linear
