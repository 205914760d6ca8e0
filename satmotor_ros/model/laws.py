# SPDX-License-Identifier: Apache-2.0
"""
The two laws for the change of displacement: the physical eq. (33) and the empirical eq. (39).

Each law gives its loss Delta Q_vl = Delta q * n, the slopes of that loss,
the lowest speed it is used at, and how its loss is shared among the
components of eq. (31). The array maps never branch on the law; only the
float-specialised single-point path (:mod:`.point`) inlines both.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from satmotor_ros.model import losses as eq
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.coefficients import LossCoefficients, MotorGeometry
from satmotor_ros.model.derived import DerivedCoefficients
from satmotor_ros.model.errors import ModelError
from satmotor_ros.model.units import MPA, RPM


class DisplacementLaw(ABC):
    """
    What a law of Delta q holds: the model's constants, geometry and coefficients.

    Parameters
    ----------
    derived : DerivedCoefficients
        The model's constants, [-]
    geometry : MotorGeometry
        Motor geometry, [-]
    coef : LossCoefficients
        Coefficient set, [-]

    """

    name = ''
    closed_form = False  # whether eq. (40) inverts it, with no solve
    has_floor = False  # whether it is used only above a floor speed

    def __init__(self, derived: DerivedCoefficients, geometry: MotorGeometry,
                 coef: LossCoefficients) -> None:
        """Keep the constants."""
        self.derived, self.geometry, self.coef = derived, geometry, coef

    @abstractmethod
    def loss(self, speed: FloatArray, dp_i: FloatArray) -> FloatArray:
        """Return Delta Q_vl = Delta q n, [m^3/s]."""

    @abstractmethod
    def slopes(self, speed: FloatArray, dp_i: FloatArray,
               loss: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Return d(Delta Q_vl)/dn [m^3/rad] and d(Delta Q_vl)/d(dp_i) [m^3/(s*Pa)]."""

    @abstractmethod
    def floor(self, dp_i: FloatArray) -> FloatArray:
        """Return the lowest speed the law is used at, [rad/s]."""

    @abstractmethod
    def share(self, parts: list[FloatArray], speed: FloatArray,
              dp_i: FloatArray) -> list[FloatArray]:
        """Return the components of eqs. (11)-(14) that add up to this law's loss, [m^3/s]."""


class PhysicalLaw(DisplacementLaw):
    """Delta q of eq. (33): (C dp_i + C_id / sqrt(n)) m^2 H, split by eqs. (11)-(14)."""

    name = 'eq33'
    closed_form = True

    def loss(self, speed: FloatArray, dp_i: FloatArray) -> FloatArray:
        """Return Delta Q_vl of eqs. (32)-(33), [m^3/s]."""
        return eq.displacement_loss(dp_i, speed, self.derived.c_lumped, self.coef.c_id,
                                    self.geometry)

    def slopes(self, speed: FloatArray, dp_i: FloatArray,
               loss: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Return d(Delta Q_vl)/dn [m^3/rad] and d(Delta Q_vl)/d(dp_i) [m^3/(s*Pa)]."""
        d = self.derived
        with np.errstate(divide='ignore'):
            return d.k_p * dp_i + 0.5 * d.k_i / np.sqrt(speed), d.k_p * speed

    def floor(self, dp_i: FloatArray) -> FloatArray:
        """Return the lowest speed the law is used at: none, [rad/s]."""
        return np.zeros_like(dp_i)

    def share(self, parts: list[FloatArray], speed: FloatArray,
              dp_i: FloatArray) -> list[FloatArray]:
        """Return the components of eqs. (11)-(14): they are this law's loss."""
        return parts


class EmpiricalLaw(DisplacementLaw):
    """Delta q of eq. (39): C_1/sqrt(n) dp_i^(C_2/sqrt(n)), shared as eq. (33) would split it."""

    name = 'eq39'
    closed_form = False
    has_floor = True

    def loss(self, speed: FloatArray, dp_i: FloatArray) -> FloatArray:
        """Return Delta Q_vl of eqs. (32), (39), [m^3/s]."""
        return eq.displacement_loss_empirical(dp_i, speed, self.coef)

    def slopes(self, speed: FloatArray, dp_i: FloatArray,
               loss: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Return d(Delta Q_vl)/dn [m^3/rad] and d(Delta Q_vl)/d(dp_i) [m^3/(s*Pa)]."""
        # Delta Q_vl = C_1 s exp(a / s) with s = sqrt(n [rpm]), a = C_2 ln(dp_i [MPa])
        c2 = self.coef.c2_39
        with np.errstate(divide='ignore', invalid='ignore'):
            inv_s = 1.0 / np.sqrt(speed / RPM)
            above = dp_i > eq.EMPIRICAL_DP_FLOOR  # below it, eq. (39) is flat in dp_i
            log_dp = np.log(np.where(above, dp_i, eq.EMPIRICAL_DP_FLOOR) / MPA)
            d_speed = loss * (1.0 - c2 * log_dp * inv_s) / (2.0 * speed)
            return d_speed, np.where(above, loss * c2 * inv_s / dp_i, 0.0)

    def floor(self, dp_i: FloatArray) -> FloatArray:
        """Return the lowest speed eq. (39) is used at, (C_2 ln dp_i)^2 rpm, [rad/s]."""
        return eq.empirical_speed_floor(dp_i, self.coef)

    def share(self, parts: list[FloatArray], speed: FloatArray,
              dp_i: FloatArray) -> list[FloatArray]:
        """Scale the components of eqs. (11)-(14) so that they add up to eq. (39)'s loss."""
        physical = parts[0] + parts[1] + parts[2] + parts[3]
        scale = np.divide(self.loss(speed, dp_i), physical, out=np.zeros_like(physical),
                          where=physical > 0.0)
        return [p * scale for p in parts]


LAWS = {'eq33': PhysicalLaw, 'eq39': EmpiricalLaw}
"""The displacement laws by name."""


def displacement_law(name: str, derived: DerivedCoefficients, geometry: MotorGeometry,
                     coef: LossCoefficients) -> DisplacementLaw:
    """
    Build the displacement law of a given name.

    Parameters
    ----------
    name : {'eq33', 'eq39'}
        The law, [-]
    derived : DerivedCoefficients
        The model's constants, [-]
    geometry : MotorGeometry
        Motor geometry, [-]
    coef : LossCoefficients
        Coefficient set, [-]

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
    return LAWS[name](derived, geometry, coef)
