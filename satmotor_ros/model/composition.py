# SPDX-License-Identifier: Apache-2.0
"""
The equations of one motor on one liquid, composed: leakage, breakdown, drops, residuals.

:class:`Equations` is what the single-point path (:mod:`.point`) and the array
maps (:mod:`.inverse`, :mod:`.forward`) share: every method calls the equation
functions of :mod:`.losses`, :mod:`.speed` and the displacement law with the
model's constants, and works on Python floats and on arrays alike. The maps
add only screening, status flags and the solver (:mod:`.solve`); a motor family
with other equations provides another object with these methods.
"""

from __future__ import annotations

from collections.abc import Callable

from satmotor_ros.model._numeric import maximum, maximum_for, minimum
from satmotor_ros.model._typing import Real
from satmotor_ros.model.derived import DerivedCoefficients
from satmotor_ros.model.laws import DisplacementLaw
from satmotor_ros.model.losses import (chamber_pressure_drop, channel_pressure_drop,
                                       clearance_height, commutation_leakage, external_leakage,
                                       flat_clearance_leakage, inertia_loss, pressure_speed_loss)
from satmotor_ros.model.speed import absorbency, effective_speed

Residual = Callable[[Real], tuple[Real, Real]]
"""x -> (f(x), df/dx) for :mod:`.solve`."""

_TINY_DROP = 1e-300  # [Pa]; below the resolution of any dp_i but 0


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

    def __init__(self, derived: DerivedCoefficients, law: DisplacementLaw) -> None:
        """Keep the parts."""
        self.derived, self.law = derived, law
        self.closed_form = law.closed_form
        d = derived
        # the constants each composition needs, unpacked in one step on the float path
        self._channel = (d.ch_a, d.ch_b)
        self._leakage = (d.h0, d.compliance, d.lfg_k, d.lfg_e, d.com_k, d.com_e, d.k_ex)
        self._parts = (d.k_fc, d.k_dch, d.k_b, d.k_i)
        self._coupled = (d.ch_a, d.ch_b, d.h0, d.compliance, d.lfg_k, d.lfg_e, d.com_k, d.com_e,
                         d.qt, d.k_ex, d.dp_limit)

    # -- pressure drops --------------------------------------------------------------------

    def channel_drop(self, flow: Real) -> Real:
        """Return the channel drop of eq. (35), [Pa]."""
        return channel_pressure_drop(flow, *self._channel)

    def chamber_drop(self, dp: Real, flow: Real) -> Real:
        """Return dp_i of eqs. (34)-(35), unclipped (negative where the channels take it all)."""
        return chamber_pressure_drop(dp, channel_pressure_drop(flow, *self._channel))

    # -- losses ----------------------------------------------------------------------------

    def leakage(self, dp_i: Real,
                p_ex: Real) -> tuple[Real, Real, Real | float]:
        """Return Q_Lfg, Q_C and Q_ex of eqs. (1), (2), (5) and (24), [m^3/s]."""
        h0, compliance, k_lfg, e_lfg, k_c, gamma, k_ex = self._leakage
        h = clearance_height(dp_i, h0, compliance)
        return (flat_clearance_leakage(dp_i, h, k_lfg, e_lfg),
                commutation_leakage(dp_i, k_c, gamma),
                external_leakage(p_ex, k_ex) if k_ex else 0.0)

    def breakdown(self, speed: Real, dp_i: Real,
                  leak: Real) -> tuple[Real, ...]:
        """
        Return Delta Q_fc, Delta Q_dch, Delta Q_b, Delta Q_id and Q_vl of eq. (31), [m^3/s].

        `leak` is Q_Lfg + Q_C + Q_ex; the law shares its loss among eqs. (11)-(14).
        """
        k_fc, k_dch, k_b, k_i = self._parts
        fc, dch, bl, ine = (pressure_speed_loss(dp_i, speed, k_fc),
                            pressure_speed_loss(dp_i, speed, k_dch),
                            pressure_speed_loss(dp_i, speed, k_b), inertia_loss(speed, k_i))
        if self.law.shares:
            fc, dch, bl, ine = self.law.share((fc, dch, bl, ine), speed, dp_i)
        return fc, dch, bl, ine, leak + ((fc + dch) + (bl + ine))

    # -- the inverse map n(Q, dp_i) --------------------------------------------------------

    def closed_form_speed(self, flow: Real, dp_i: Real,
                          leak: Real) -> Real:
        """Return n of eq. (40), for the law of eq. (33), [rad/s]."""
        d = self.derived
        return effective_speed(flow, dp_i, leak, d.es_a0, d.es_a1, d.es_scale, d.es_b)

    def speed_problem(self, flow: Real, dp_i: Real,
                      leak: Real) -> tuple[Real, Real, Residual[Real]]:
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
        qt = self.derived.qt
        floor, terms = self.law.at_pressure(dp_i)

        def residual(speed: Real) -> tuple[Real, Real]:
            loss, slope = terms(speed)
            return absorbency(speed, loss + leak, qt) - flow, qt + slope
        return floor, maximum(flow - leak, 0.0) / qt, residual

    # -- the forward map Q(n, dp) with the channel drop coupled -----------------------------

    def flow_problem(self, speed: Real, dp: Real,
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
        ch_a, ch_b, h0, compliance, k_lfg, e_lfg, k_c, gamma, qt, k_ex, limit = self._coupled
        dp_cap = minimum(dp, limit)
        clip = maximum_for(dp_cap)
        terms = self.law.at_speed(speed)
        base = absorbency(speed, external_leakage(p_ex, k_ex) if k_ex else 0.0 * p_ex, qt)
        channel, clearance = channel_pressure_drop, clearance_height
        flat, commutation = flat_clearance_leakage, commutation_leakage

        def residual(flow: Real) -> tuple[Real, Real]:
            # eq. (34), clipped at 0 where the channels take the whole drop
            dp_i = clip(dp_cap - channel(flow, ch_a, ch_b), 0.0)
            h = clearance(dp_i, h0, compliance)
            q_lfg, q_c = flat(dp_i, h, k_lfg, e_lfg), commutation(dp_i, k_c, gamma)
            loss, d_loss = terms(dp_i)
            # d(Q_Lfg + Q_C)/d(dp_i); the leakages are 0 at dp_i = 0, and so is their slope
            inv_dp = 1.0 / (dp_i + _TINY_DROP)
            d_leak = q_lfg * e_lfg * (inv_dp - 3.0 * compliance / h) + q_c * gamma * inv_dp
            return (flow - (base + (loss + q_lfg + q_c)),
                    1.0 + (dp_i > 0.0) * ((d_leak + d_loss) * (2.0 * ch_a * flow + ch_b)))

        def upper() -> Real:
            h = clearance(dp_cap, h0, compliance)
            return base + (terms(dp_cap)[0] + flat(dp_cap, h, k_lfg, e_lfg)
                           + commutation(dp_cap, k_c, gamma))
        return qt * speed, upper, residual
