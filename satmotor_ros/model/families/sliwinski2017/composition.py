# SPDX-License-Identifier: Apache-2.0
"""
The equations of one motor on one liquid, composed: leakage, breakdown, drops, residuals.

:class:`Equations` is what the single-point path (:mod:`.point`) and the array
maps (:mod:`.inverse`, :mod:`.forward`) share: every composition calls the equation
functions of :mod:`.losses`, :mod:`.speed` and the displacement law with the
model's constants, and works on Python floats and on arrays alike. The maps
add only screening, status flags and the solver (:mod:`.solve`); a motor family
with other equations provides another object with these callables.
"""

from __future__ import annotations

from collections.abc import Callable

from satmotor_ros.model._inline import inline_equations, inline_per_class
from satmotor_ros.model._numeric import log, maximum, minimum
from satmotor_ros.model._typing import Real
from satmotor_ros.model.families.sliwinski2017.derived import DerivedCoefficients
from satmotor_ros.model.families.sliwinski2017.laws import DisplacementLaw
from satmotor_ros.model.families.sliwinski2017.losses import (chamber_pressure_drop,
                                                              channel_pressure_drop,
                                                              clearance_height,
                                                              commutation_leakage,
                                                              displacement_change_at_root,
                                                              displacement_change_empirical,
                                                              displacement_loss, empirical_drop,
                                                              empirical_speed_floor,
                                                              external_leakage,
                                                              flat_clearance_leakage, inertia_loss,
                                                              pressure_speed_loss)
from satmotor_ros.model.families.sliwinski2017.speed import absorbency, effective_speed

_LAW_EQUATIONS = (displacement_change_at_root, displacement_change_empirical, displacement_loss,
                  empirical_drop, empirical_speed_floor, log)
"""What the laws' static methods call: their expressions are inlined here and read these names."""

Residual = Callable[[Real], tuple[Real, Real]]
"""x -> (f(x), df/dx) for :mod:`.solve`."""

_TINY_DROP = 1e-300  # [Pa]; below the resolution of any dp_i but 0
_TINY_FLOW = 1e-300  # [m^3/s]; below the resolution of any loss but 0


class Equations:
    """
    Eqs. (1)-(40) for one motor, coefficient set, liquid and displacement law.

    Parameters
    ----------
    derived : DerivedCoefficients
        The model's constants, [-]
    law : DisplacementLaw
        Law of the change of displacement, eq. (33) or (39), [-]

    """

    channel_drop: Callable[[Real], Real]
    """Q -> the channel drop of eq. (35), [Pa]."""
    chamber_drop: Callable[[Real, Real], Real]
    """(dp, Q) -> dp_i of eqs. (34)-(35), unclipped (negative where the channels take it all)."""
    leakage: Callable[[Real, Real], tuple[Real, Real, Real | float]]
    """(dp_i, p_ex) -> Q_Lfg, Q_C and Q_ex of eqs. (1), (2), (5) and (24), [m^3/s]."""
    breakdown: Callable[[Real, Real, Real], tuple[Real, Real, Real, Real, Real]]
    """
    (n, dp_i, leak) -> Delta Q_fc, Delta Q_dch, Delta Q_b, Delta Q_id and Q_vl of eq. (31).

    `leak` is Q_Lfg + Q_C + Q_ex; the law shares its loss among eqs. (11)-(14).
    """
    closed_form_speed: Callable[[Real, Real, Real], Real]
    """(Q, dp_i, leak) -> n of eq. (40), for the law of eq. (33), [rad/s]."""

    speed_problem: Callable[[Real, Real, Real], tuple[Real, Real, Residual[Real]]]
    """(Q, dp_i, leak) -> eq. (36) at fixed dp_i posed for the solver: lo, hi, residual."""
    flow_problem: Callable[[Real, Real, Real], tuple[Real, Callable[[], Real], Residual[Real]]]
    """(n, dp, p_ex) -> eqs. (34)-(36) at fixed n and port dp for the solver: lo, upper, f."""

    def __init__(self, derived: DerivedCoefficients, law: DisplacementLaw) -> None:
        """Keep the parts and bind the constants into the compositions, once per model."""
        self.derived, self.law = derived, law
        self.closed_form = law.closed_form
        self.channel_drop, self.chamber_drop = _drops(derived)
        self.leakage = _leakage(derived)
        self.breakdown = _breakdown(derived, law)
        self.closed_form_speed = _closed_form_speed(derived)
        self.speed_problem = _speed_problem(derived, law)
        self.flow_problem = _flow_problem(derived, law)


# The builders below bind a model's constants into closures once, so that a call reads them
# from its own cells, and @inline_equations puts the equation functions' expressions in place
# of their calls: on a Python float, lookups and calls would cost as much as the arithmetic.

@inline_equations
def _drops(d: DerivedCoefficients) -> tuple[Callable[[Real], Real], Callable[[Real, Real], Real]]:
    """Return the channel drop Q -> dp_ich of eq. (35) and (dp, Q) -> dp_i of eq. (34)."""
    ch_a, ch_b = d.ch_a, d.ch_b

    def channel_drop(flow: Real) -> Real:
        return channel_pressure_drop(flow, ch_a, ch_b)

    def chamber_drop(dp: Real, flow: Real) -> Real:
        return chamber_pressure_drop(dp, channel_pressure_drop(flow, ch_a, ch_b))
    return channel_drop, chamber_drop


@inline_equations
def _leakage(d: DerivedCoefficients) -> Callable[[Real, Real], tuple[Real, Real, Real | float]]:
    """Return (dp_i, p_ex) -> Q_Lfg, Q_C, Q_ex of eqs. (1), (2), (5) and (24)."""
    h0, compliance, k_lfg, e_lfg, k_c, gamma, k_ex = (d.h0, d.compliance, d.lfg_k, d.lfg_e,
                                                      d.com_k, d.com_e, d.k_ex)

    def leakage(dp_i: Real, p_ex: Real) -> tuple[Real, Real, Real | float]:
        h = clearance_height(dp_i, h0, compliance)
        return (flat_clearance_leakage(dp_i, h, k_lfg, e_lfg),
                commutation_leakage(dp_i, k_c, gamma),
                external_leakage(p_ex, k_ex) if k_ex else 0.0)
    return leakage


@inline_per_class('law')
def _breakdown(d: DerivedCoefficients, law: DisplacementLaw) -> Callable[
        [Real, Real, Real], tuple[Real, Real, Real, Real, Real]]:
    """Return (n, dp_i, leak) -> the components of eq. (31) and Q_vl, as the law shares them."""
    k_fc, k_dch, k_b, k_i = d.k_fc, d.k_dch, d.k_b, d.k_i
    shares, (a, b) = law.shares, law.constants

    def breakdown(speed: Real, dp_i: Real, leak: Real) -> tuple[Real, Real, Real, Real, Real]:
        fc, dch, bl, ine = (pressure_speed_loss(dp_i, speed, k_fc),
                            pressure_speed_loss(dp_i, speed, k_dch),
                            pressure_speed_loss(dp_i, speed, k_b), inertia_loss(speed, k_i))
        if shares:  # scaled to add up to the law's loss; parts of 0 stay 0
            scale = law.loss_at(speed, dp_i, a, b) / (fc + dch + bl + ine + _TINY_FLOW)
            fc, dch, bl, ine = fc * scale, dch * scale, bl * scale, ine * scale
        return fc, dch, bl, ine, leak + ((fc + dch) + (bl + ine))
    return breakdown


def _closed_form_speed(d: DerivedCoefficients) -> Callable[[Real, Real, Real], Real]:
    """Return (Q, dp_i, leak) -> n of eq. (40)."""
    a0, a1, scale, b = d.es_a0, d.es_a1, d.es_scale, d.es_b
    speed = effective_speed

    def closed_form_speed(flow: Real, dp_i: Real, leak: Real) -> Real:
        return speed(flow, dp_i, leak, a0, a1, scale, b)
    return closed_form_speed


@inline_per_class('law')
def _speed_problem(d: DerivedCoefficients, law: DisplacementLaw) -> Callable[
        [Real, Real, Real], tuple[Real, Real, Residual[Real]]]:
    """Return :meth:`Equations.speed_problem` for one model."""
    qt, (a, b) = d.qt, law.constants

    def speed_problem(flow: Real, dp_i: Real, leak: Real) -> tuple[Real, Real, Residual[Real]]:
        """
        Return eq. (36) at fixed dp_i posed for the solver: a bracket of n and the residual.

        The upper end puts the whole flow past the leakage through the
        displacement; the lower end is the law's floor speed. Where eq. (36)
        already takes the flow at a floor above 0 (residual >= 0 there), the
        law has no root.

        Parameters
        ----------
        flow : float or ndarray
            Flow into the motor Q, [m^3/s]
        dp_i : float or ndarray
            Chamber pressure drop, [Pa]
        leak : float or ndarray
            Q_Lfg + Q_C + Q_ex, [m^3/s]

        Returns
        -------
        lo : float or ndarray
            Lower end, [rad/s]
        hi : float or ndarray
            Upper end, [rad/s]
        residual : callable
            n -> (Q(n) - flow [m^3/s], its slope [m^3/rad]), n > 0.

        """
        floor, p, p_slope = law.pressure_state(dp_i, a, b)

        def residual(speed: Real) -> tuple[Real, Real]:
            loss, slope = law.speed_terms(speed, p, p_slope, a, b)
            return absorbency(speed, loss + leak, qt) - flow, qt + slope
        return floor, maximum(flow - leak, 0.0) / qt, residual
    return speed_problem


@inline_per_class('law')
def _flow_problem(d: DerivedCoefficients, law: DisplacementLaw) -> Callable[
        [Real, Real, Real], tuple[Real, Callable[[], Real], Residual[Real]]]:
    """Return :meth:`Equations.flow_problem` for one model."""
    ch_a, ch_b, h0, compliance, k_lfg, e_lfg, k_c, gamma, qt, k_ex, limit = (
        d.ch_a, d.ch_b, d.h0, d.compliance, d.lfg_k, d.lfg_e, d.com_k, d.com_e, d.qt, d.k_ex,
        d.dp_limit)
    a, b = law.constants
    two_ch_a, three_compliance = 2.0 * ch_a, 3.0 * compliance  # the slopes' factors

    def flow_problem(speed: Real, dp: Real,
                     p_ex: Real) -> tuple[Real, Callable[[], Real], Residual[Real]]:
        """
        Return eqs. (34)-(36) at fixed n and port dp posed for the solver (``mirror=True``).

        The residual is Q - A(Q), A(Q) the flow absorbed with the chamber drop
        that Q leaves. A falls as Q rises (more channel drop, less chamber
        drop), so q_t n bounds the root from below and A(0) from above, and
        A at any estimate bounds it from the other side. The drop is capped at
        the model's limit, where the maps flag the point anyway.

        Parameters
        ----------
        speed : float or ndarray
            Shaft speed n, [rad/s]
        dp : float or ndarray
            Port pressure drop, [Pa]
        p_ex : float or ndarray
            Pressure driving the external leakage, [Pa]

        Returns
        -------
        lo : float or ndarray
            q_t n, [m^3/s]
        upper : callable
            () -> A(0), the upper bound and a start two Newton steps from the root, [m^3/s]
        residual : callable
            Q -> (Q - A(Q) [m^3/s], its slope [-]).

        """
        dp_cap = minimum(dp, limit)
        s, s_slope = law.speed_state(speed, a, b)
        base = absorbency(speed, external_leakage(p_ex, k_ex) if k_ex else 0.0 * p_ex, qt)

        def residual(flow: Real) -> tuple[Real, Real]:
            # eq. (34), clipped at 0 where the channels take the whole drop: x (x > 0) is
            # max(x, 0) for a float (-0.0 is 0) and an array alike, without a call
            dp_i = chamber_pressure_drop(dp_cap, channel_pressure_drop(flow, ch_a, ch_b))
            dp_i *= dp_i > 0.0
            h = clearance_height(dp_i, h0, compliance)
            q_lfg = flat_clearance_leakage(dp_i, h, k_lfg, e_lfg)
            q_c = commutation_leakage(dp_i, k_c, gamma)
            loss, d_loss = law.pressure_terms(dp_i, speed, s, s_slope, a, b)
            # d(Q_Lfg + Q_C)/d(dp_i); the leakages are 0 at dp_i = 0, and so is their slope
            inv_dp = 1.0 / (dp_i + _TINY_DROP)
            d_leak = q_lfg * e_lfg * (inv_dp - three_compliance / h) + q_c * gamma * inv_dp
            return (flow - (base + (loss + q_lfg + q_c)),
                    1.0 + (dp_i > 0.0) * ((d_leak + d_loss) * (two_ch_a * flow + ch_b)))

        def upper() -> Real:
            h = clearance_height(dp_cap, h0, compliance)
            return base + (law.pressure_terms(dp_cap, speed, s, s_slope, a, b)[0]
                           + flat_clearance_leakage(dp_cap, h, k_lfg, e_lfg)
                           + commutation_leakage(dp_cap, k_c, gamma))
        return qt * speed, upper, residual
    return flow_problem
