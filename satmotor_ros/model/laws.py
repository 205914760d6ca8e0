# SPDX-License-Identifier: Apache-2.0
"""
The two laws for the change of displacement: the physical eq. (33) and the empirical eq. (39).

Each law gives its loss Delta Q_vl = Delta q * n, the slopes of that loss,
the lowest speed it is used at, and whether eq. (31)'s components are scaled
to add up to its loss. Every method works on Python floats and on arrays
alike, so the single-point path and the array maps share them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable

from satmotor_ros.model import losses as eq
from satmotor_ros.model._inline import inline_equations
from satmotor_ros.model._numeric import log, maximum, maximum_for
from satmotor_ros.model._typing import Real
from satmotor_ros.model.derived import DerivedCoefficients
from satmotor_ros.model.errors import ModelError
from satmotor_ros.model.units import MPA, RPM

Terms = Callable[[Real], tuple[Real, Real]]
"""A loss and one of its slopes as a function of one variable, the other held fixed: n > 0."""


class DisplacementLaw(ABC):
    """
    What a law of Delta q holds: the model's constants.

    Parameters
    ----------
    derived : DerivedCoefficients
        The model's constants, [-]

    """

    name = ''
    closed_form = False  # whether eq. (40) inverts it, with no solve
    has_floor = False  # whether it is used only above a floor speed
    shares = False  # whether eq. (31)'s components are scaled to add up to its :meth:`loss`

    def __init__(self, derived: DerivedCoefficients) -> None:
        """Keep the constants."""
        self.derived = derived
        # the floor rises with dp_i: below this speed a point may be under it, [rad/s]
        self.max_floor = float(self.floor(derived.dp_limit)) if self.has_floor else 0.0

    @abstractmethod
    def loss(self, speed: Real, dp_i: Real) -> Real:
        """Return Delta Q_vl = Delta q n, [m^3/s]."""

    @abstractmethod
    def at_pressure(self, dp_i: Real) -> tuple[Real, Terms[Real]]:
        """Return the floor speed [rad/s] and n -> (Delta Q_vl, its slope in n) at fixed dp_i."""

    @abstractmethod
    def at_speed(self, speed: Real) -> Terms[Real]:
        """Return dp_i -> (Delta Q_vl [m^3/s], its slope in dp_i [m^3/(s*Pa)]) at a fixed n."""

    @abstractmethod
    def floor(self, dp_i: Real) -> Real:
        """Return the lowest speed the law is used at, [rad/s]."""


class PhysicalLaw(DisplacementLaw):
    """Delta q of eq. (33): (C dp_i + C_id / sqrt(n)) m^2 H, the sum of eqs. (11)-(14)."""

    name = 'eq33'
    closed_form = True

    def loss(self, speed: Real, dp_i: Real) -> Real:
        """Return Delta Q_vl of eqs. (32)-(33), [m^3/s]."""
        d = self.derived
        return eq.displacement_loss(dp_i, speed, d.k_p, d.k_i)

    @inline_equations
    def at_pressure(self, dp_i: Real) -> tuple[Real, Terms[Real]]:
        """Return the floor speed [rad/s] and n -> (Delta Q_vl, its slope in n) at fixed dp_i."""
        k_p, k_i = self.derived.k_p, self.derived.k_i

        def terms(speed: Real) -> tuple[Real, Real]:
            return (eq.displacement_loss(dp_i, speed, k_p, k_i),
                    k_p * dp_i + 0.5 * k_i / speed ** 0.5)
        return 0.0 * dp_i, terms

    @inline_equations
    def at_speed(self, speed: Real) -> Terms[Real]:
        """Return dp_i -> (Delta Q_vl [m^3/s], its slope in dp_i [m^3/(s*Pa)]) at a fixed n."""
        k_p, k_i = self.derived.k_p, self.derived.k_i
        k_pn = k_p * speed

        def terms(dp_i: Real) -> tuple[Real, Real]:
            return eq.displacement_loss(dp_i, speed, k_p, k_i), k_pn
        return terms

    def floor(self, dp_i: Real) -> Real:
        """Return the lowest speed the law is used at: none, [rad/s]."""
        return 0.0 * dp_i


class EmpiricalLaw(DisplacementLaw):
    """
    Delta q of eq. (39): C_1/sqrt(n) dp_i^(C_2/sqrt(n)), shared as eq. (33) would split it.

    Below :data:`~satmotor_ros.model.losses.EMPIRICAL_DP_FLOOR` the chamber drop is
    taken at that floor (see :func:`~satmotor_ros.model.losses.displacement_change_empirical`),
    and at n = 0 the loss is 0 (no revolution, no displacement loss).
    """

    name = 'eq39'
    closed_form = False
    has_floor = True
    shares = True

    @inline_equations
    def loss(self, speed: Real, dp_i: Real) -> Real:
        """Return Delta Q_vl of eqs. (32), (39), [m^3/s]."""
        d = self.derived
        # at n = 0, Delta q at n = 1 (speed + True) times n = 0 is the loss: 0
        return eq.displacement_change_empirical(maximum(dp_i, eq.EMPIRICAL_DP_FLOOR),
                                                speed + (speed <= 0.0), d.c1_39,
                                                d.c2_39) * speed

    @inline_equations
    def at_pressure(self, dp_i: Real) -> tuple[Real, Terms[Real]]:
        """Return the floor speed [rad/s] and n -> (Delta Q_vl, its slope in n) at fixed dp_i."""
        # Delta Q_vl = C_1 s exp(a / s) with s = sqrt(n [rpm]), a = C_2 ln(dp_i [MPa])
        c1, c2 = self.derived.c1_39, self.derived.c2_39
        dp = maximum(dp_i, eq.EMPIRICAL_DP_FLOOR)
        c2_log_dp = c2 * log(dp / MPA)

        def terms(speed: Real) -> tuple[Real, Real]:
            loss = eq.displacement_change_empirical(dp, speed, c1, c2) * speed
            return loss, loss * (1.0 - c2_log_dp / (speed / RPM) ** 0.5) / (2.0 * speed)
        return eq.empirical_speed_floor(dp, c2), terms

    @inline_equations
    def at_speed(self, speed: Real) -> Terms[Real]:
        """Return dp_i -> (Delta Q_vl [m^3/s], its slope in dp_i [m^3/(s*Pa)]) at a fixed n."""
        c1, c2 = self.derived.c1_39, self.derived.c2_39
        moving = speed > 0.0
        safe = speed + (speed <= 0.0)  # at n = 0 the loss is 0 and flat: at n = 1, times 0
        c2_inv_s = moving * (c2 / (safe / RPM) ** 0.5)
        floor = eq.EMPIRICAL_DP_FLOOR
        clip = maximum_for(speed)

        def terms(dp_i: Real) -> tuple[Real, Real]:
            dp = clip(dp_i, floor)  # below the floor, eq. (39) is flat in dp_i
            loss = eq.displacement_change_empirical(dp, safe, c1, c2) * speed
            return loss, (dp_i > floor) * (loss * c2_inv_s / dp)
        return terms

    @inline_equations
    def floor(self, dp_i: Real) -> Real:
        """Return the lowest speed eq. (39) is used at, (C_2 ln dp_i)^2 rpm, [rad/s]."""
        return eq.empirical_speed_floor(dp_i, self.derived.c2_39)


LAWS = {'eq33': PhysicalLaw, 'eq39': EmpiricalLaw}
"""The displacement laws by name."""


def displacement_law(name: str, derived: DerivedCoefficients) -> DisplacementLaw:
    """
    Build the displacement law of a given name.

    Parameters
    ----------
    name : {'eq33', 'eq39'}
        The law, [-]
    derived : DerivedCoefficients
        The model's constants, [-]

    Returns
    -------
    DisplacementLaw
        The law (an :class:`EmpiricalLaw` for eq. (39)).

    Raises
    ------
    ModelError
        For an unknown name.

    """
    if name not in LAWS:
        msg = f"displacement_law = {name!r}: use 'eq33' or 'eq39'"
        raise ModelError(msg)
    return LAWS[name](derived)
