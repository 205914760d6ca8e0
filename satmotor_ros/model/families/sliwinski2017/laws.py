# SPDX-License-Identifier: Apache-2.0
"""
The two laws for the change of displacement: the physical eq. (33) and the empirical eq. (39).

Each law gives its loss Delta Q_vl = Delta q * n, the slopes of that loss,
the lowest speed it is used at, and whether eq. (31)'s components are scaled
to add up to its loss. Every method works on Python floats and on arrays
alike, so the single-point path and the array maps share them.

A law writes each of these once, as a static method of one expression of its
two constants (``a, b = law.constants``), so that the compositions
(:mod:`.composition`) inline them in their residuals
(:func:`~satmotor_ros.model._inline.inline_per_class`); the methods of
:class:`DisplacementLaw` give the same values one call at a time.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable

from satmotor_ros.model._inline import inline_per_class
from satmotor_ros.model._numeric import log, maximum  # noqa: F401 (empirical_drop's, inlined)
from satmotor_ros.model._typing import Real
from satmotor_ros.model.errors import ModelError
from satmotor_ros.model.families.sliwinski2017.derived import DerivedCoefficients
from satmotor_ros.model.families.sliwinski2017.losses import (displacement_change_at_root,
                                                              displacement_change_empirical,
                                                              displacement_loss,
                                                              EMPIRICAL_DP_FLOOR, empirical_drop,
                                                              empirical_speed_floor, inertia_loss,
                                                              pressure_speed_loss)
from satmotor_ros.model.units import MPA, RPM

Terms = Callable[[Real], tuple[Real, Real]]
"""A loss and one of its slopes as a function of one variable, the other held fixed: n > 0."""


class DisplacementLaw(ABC):
    """
    What a law of Delta q holds: the model's constants.

    A law writes its equations as static methods of one expression each, of
    its two constants ``a, b`` (:attr:`constant_names`); the ``*_state`` values
    are what a solve at fixed dp_i or at fixed n computes once.

    Parameters
    ----------
    derived : DerivedCoefficients
        The model's constants, [-]

    """

    name = ''
    closed_form = False  # whether eq. (40) inverts it, with no solve
    has_floor = False  # whether it is used only above a floor speed
    shares = False  # whether eq. (31)'s components are scaled to add up to its :meth:`loss`
    constant_names: tuple[str, str] = ('', '')  # the two constants a, b in `derived`

    def __init__(self, derived: DerivedCoefficients) -> None:
        """Keep the constants."""
        self.derived = derived
        self.constants: tuple[float, float] = (getattr(derived, self.constant_names[0]),
                                               getattr(derived, self.constant_names[1]))
        # the floor rises with dp_i: below this speed a point may be under it, [rad/s]
        self.max_floor = float(self.floor(derived.dp_limit)) if self.has_floor else 0.0

    @staticmethod
    @abstractmethod
    def loss_at(speed: Real, dp_i: Real, a: float, b: float) -> Real:
        """Return Delta Q_vl = Delta q n, [m^3/s]."""

    @staticmethod
    @abstractmethod
    def floor_at(dp_i: Real, a: float, b: float) -> Real:
        """Return the lowest speed the law is used at, [rad/s]."""

    @staticmethod
    @abstractmethod
    def pressure_state(dp_i: Real, a: float, b: float) -> tuple[Real, Real, Real]:
        """Return the floor speed [rad/s] and the two values its terms read at fixed dp_i."""

    @staticmethod
    @abstractmethod
    def speed_terms(speed: Real, p: Real, p_slope: Real, a: float,
                    b: float) -> tuple[Real, Real]:
        """Return Delta Q_vl [m^3/s] and its slope in n [m^3/rad] from the pressure state."""

    @staticmethod
    @abstractmethod
    def speed_state(speed: Real, a: float, b: float) -> tuple[Real, Real]:
        """Return the two values the terms in dp_i read at fixed n."""

    @staticmethod
    @abstractmethod
    def pressure_terms(dp_i: Real, speed: Real, s: Real, s_slope: Real, a: float,
                       b: float) -> tuple[Real, Real]:
        """Return Delta Q_vl [m^3/s] and its slope in dp_i [m^3/(s*Pa)] from the speed state."""

    @inline_per_class('self')
    def loss(self, speed: Real, dp_i: Real) -> Real:
        """Return Delta Q_vl = Delta q n, [m^3/s]."""
        a, b = self.constants
        return self.loss_at(speed, dp_i, a, b)

    @inline_per_class('self')
    def floor(self, dp_i: Real) -> Real:
        """Return the lowest speed the law is used at, [rad/s]."""
        a, b = self.constants
        return self.floor_at(dp_i, a, b)

    @inline_per_class('self')
    def at_pressure(self, dp_i: Real) -> tuple[Real, Terms[Real]]:
        """Return the floor speed [rad/s] and n -> (Delta Q_vl, its slope in n) at fixed dp_i."""
        a, b = self.constants
        floor, p, p_slope = self.pressure_state(dp_i, a, b)

        def terms(speed: Real) -> tuple[Real, Real]:
            return self.speed_terms(speed, p, p_slope, a, b)
        return floor, terms

    @inline_per_class('self')
    def at_speed(self, speed: Real) -> Terms[Real]:
        """Return dp_i -> (Delta Q_vl [m^3/s], its slope in dp_i [m^3/(s*Pa)]) at a fixed n."""
        a, b = self.constants
        s, s_slope = self.speed_state(speed, a, b)

        def terms(dp_i: Real) -> tuple[Real, Real]:
            return self.pressure_terms(dp_i, speed, s, s_slope, a, b)
        return terms


class PhysicalLaw(DisplacementLaw):
    """Delta q of eq. (33): (C dp_i + C_id / sqrt(n)) m^2 H, the sum of eqs. (11)-(14)."""

    name = 'eq33'
    closed_form = True
    constant_names = ('k_p', 'k_i')

    @staticmethod
    def loss_at(speed: Real, dp_i: Real, k_p: float, k_i: float) -> Real:
        """Return Delta Q_vl of eqs. (32)-(33), [m^3/s]."""
        return displacement_loss(dp_i, speed, k_p, k_i)

    @staticmethod
    def floor_at(dp_i: Real, k_p: float, k_i: float) -> Real:
        """Return the lowest speed the law is used at: none, [rad/s]."""
        return 0.0 * dp_i

    @staticmethod
    def pressure_state(dp_i: Real, k_p: float, k_i: float) -> tuple[Real, Real, Real]:
        """Return the floor (none), dp_i and the slope's part k_p dp_i at fixed dp_i."""
        return 0.0 * dp_i, dp_i, k_p * dp_i

    @staticmethod
    def speed_terms(speed: Real, dp_i: Real, k_p_dp: Real, k_p: float,
                    k_i: float) -> tuple[Real, Real]:
        """Return Delta Q_vl of eq. (33) [m^3/s] and its slope in n [m^3/rad]."""
        return displacement_loss(dp_i, speed, k_p, k_i), k_p_dp + 0.5 * k_i / speed ** 0.5

    @staticmethod
    def speed_state(speed: Real, k_p: float, k_i: float) -> tuple[Real, Real]:
        """Return the inertia part of eq. (33), eq. (14), and the slope in dp_i, k_p n."""
        return inertia_loss(speed, k_i), k_p * speed

    @staticmethod
    def pressure_terms(dp_i: Real, speed: Real, inertia: Real, k_pn: Real, k_p: float,
                       k_i: float) -> tuple[Real, Real]:
        """Return Delta Q_vl of eq. (33) [m^3/s] and its slope in dp_i [m^3/(s*Pa)]."""
        # displacement_loss, its inertia part held from speed_state
        return pressure_speed_loss(dp_i, speed, k_p) + inertia, k_pn


class EmpiricalLaw(DisplacementLaw):
    """
    Delta q of eq. (39): C_1/sqrt(n) dp_i^(C_2/sqrt(n)), shared as eq. (33) would split it.

    Below :data:`~.losses.EMPIRICAL_DP_FLOOR` the chamber drop is
    taken at that floor (see :func:`~.losses.displacement_change_empirical`),
    and at n = 0 the loss is 0 (no revolution, no displacement loss).
    """

    name = 'eq39'
    closed_form = False
    has_floor = True
    shares = True
    constant_names = ('c1_39', 'c2_39')

    @staticmethod
    def loss_at(speed: Real, dp_i: Real, c1: float, c2: float) -> Real:
        """Return Delta Q_vl of eqs. (32), (39), [m^3/s]."""
        # at n = 0, Delta q at n = 1 (speed + True) times n = 0 is the loss: 0
        return displacement_change_empirical(empirical_drop(dp_i),
                                             speed + (speed <= 0.0), c1, c2) * speed

    @staticmethod
    def floor_at(dp_i: Real, c1: float, c2: float) -> Real:
        """Return the lowest speed eq. (39) is used at, (C_2 ln dp_i)^2 rpm, [rad/s]."""
        return empirical_speed_floor(dp_i, c2)

    @staticmethod
    def pressure_state(dp_i: Real, c1: float, c2: float) -> tuple[Real, Real, Real]:
        """Return the floor speed [rad/s], dp_i clipped at the floor [Pa] and C_2 ln dp_i."""
        # Delta Q_vl = C_1 s exp(a / s) with s = sqrt(n [rpm]), a = C_2 ln(dp_i [MPa])
        dp = empirical_drop(dp_i)
        return empirical_speed_floor(dp, c2), dp, c2 * log(dp / MPA)

    @staticmethod
    def speed_terms(speed: Real, dp: Real, c2_log_dp: Real, c1: float,
                    c2: float) -> tuple[Real, Real]:
        """Return Delta Q_vl of eq. (39) [m^3/s] and its slope in n [m^3/rad], n > 0."""
        loss = displacement_change_empirical(dp, speed, c1, c2) * speed
        return loss, loss * (1.0 - c2_log_dp / (speed / RPM) ** 0.5) / (2.0 * speed)

    @staticmethod
    def speed_state(speed: Real, c1: float, c2: float) -> tuple[Real, Real]:
        """Return 1/sqrt(n [rpm]) (at n = 1 where n = 0: times 0) and C_2/sqrt(n), 0 at n = 0."""
        safe = speed + (speed <= 0.0)  # at n = 0 the loss is 0 and flat: at n = 1, times 0
        return 1.0 / (safe / RPM) ** 0.5, (speed > 0.0) * (c2 / (safe / RPM) ** 0.5)

    @staticmethod
    def pressure_terms(dp_i: Real, speed: Real, inv_sqrt_n: Real, c2_inv_s: Real, c1: float,
                       c2: float) -> tuple[Real, Real]:
        """Return Delta Q_vl of eq. (39) [m^3/s] and its slope in dp_i [m^3/(s*Pa)]."""
        dp = empirical_drop(dp_i)  # below the floor, eq. (39) is flat in dp_i
        loss = displacement_change_at_root(dp, inv_sqrt_n, c1, c2) * speed
        return loss, (dp_i > EMPIRICAL_DP_FLOOR) * (loss * c2_inv_s / dp)


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
