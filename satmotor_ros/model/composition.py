# SPDX-License-Identifier: Apache-2.0
"""The equations of one motor on one liquid composed over arrays: leakage, breakdown, drops."""

from __future__ import annotations

import numpy as np

from satmotor_ros.model import losses as eq
from satmotor_ros.model._typing import ArrayLike, FloatArray
from satmotor_ros.model.coefficients import Liquid, LossCoefficients, MotorGeometry
from satmotor_ros.model.derived import DerivedCoefficients
from satmotor_ros.model.laws import DisplacementLaw
from satmotor_ros.model.results import COMPONENTS, PointStatus
from satmotor_ros.model.screening import Status


class Equations:
    """
    Eqs. (1)-(36) for one motor, coefficient set, liquid and displacement law.

    Parameters
    ----------
    geometry : MotorGeometry
        Motor geometry, [-]
    coef : LossCoefficients
        Fitted coefficients, [-]
    liquid : Liquid
        Working liquid, [-]
    derived : DerivedCoefficients
        Constants derived for them, [-]
    law : DisplacementLaw
        Law of the change of displacement, eq. (33) or (39), [-]

    """

    def __init__(self, geometry: MotorGeometry, coef: LossCoefficients, liquid: Liquid,
                 derived: DerivedCoefficients, law: DisplacementLaw) -> None:
        """Keep the parts."""
        self.geometry, self.coef, self.liquid = geometry, coef, liquid
        self.derived, self.law = derived, law

    def leakage(self, dp_i: FloatArray,
                p_ex: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray | float]:
        """Return Q_Lfg, Q_C and Q_ex of eqs. (1), (2), (5) and (24), [m^3/s]."""
        g, coef = self.geometry, self.coef
        nu, rho = self.liquid.kinematic_viscosity, self.liquid.density
        h = eq.clearance_height(dp_i, g, coef)
        q_lfg = eq.flat_clearance_leakage(dp_i, h, nu, rho, g, coef)
        q_c = eq.commutation_leakage(dp_i, nu, rho, g, coef)
        q_ex = eq.external_leakage(p_ex, coef) if coef.external_leakage else 0.0
        return q_lfg, q_c, q_ex

    def leakage_slope(self, dp_i: FloatArray, q_lfg: FloatArray,
                      q_c: FloatArray) -> FloatArray:
        """Return d(Q_Lfg + Q_C)/d(dp_i) of eqs. (1), (2) and (5) at the given leakages."""
        d = self.derived
        h = eq.clearance_height(dp_i, self.geometry, self.coef)
        with np.errstate(divide='ignore', invalid='ignore'):
            return (q_lfg * d.lfg_e * (1.0 / dp_i - 3.0 * d.compliance / h)
                    + q_c * d.com_e / dp_i)

    def breakdown(self, speed: FloatArray, dp_i: FloatArray, q_lfg: FloatArray,
                  q_c: FloatArray, q_ex: FloatArray | float,
                  leak: FloatArray) -> dict[str, ArrayLike]:
        """Return the components of eq. (31) by name; `leak` is Q_Lfg + Q_C + Q_ex."""
        g, d = self.geometry, self.derived
        parts = self.law.share([eq.compressibility_loss(dp_i, speed, d.c_fc_beta, g),
                                eq.deformation_loss(dp_i, speed, d.c_dch, g),
                                eq.backlash_loss(dp_i, speed, d.c_b, g),
                                eq.inertia_loss(speed, self.coef.c_id, g)], speed, dp_i)
        total = leak + ((parts[0] + parts[1]) + (parts[2] + parts[3]))
        return dict(zip(COMPONENTS, (q_lfg, q_c, *parts, q_ex, total)))

    def channel_drop(self, flow: FloatArray) -> FloatArray:
        """Return the channel drop of eq. (35), [Pa]."""
        return eq.channel_pressure_drop(flow, self.liquid.kinematic_viscosity,
                                        self.liquid.density, self.coef)

    def chamber_drop(self, dp: FloatArray, flow: FloatArray, status: Status) -> FloatArray:
        """Return dp_i of eq. (34), clipped to 0 and flagged CHANNEL_LIMITED below it, [Pa]."""
        dp_i = eq.chamber_pressure_drop(dp, self.channel_drop(flow))
        if dp_i.size == 0 or dp_i.min() >= 0.0:
            return dp_i
        status |= (dp_i < 0.0) * np.uint8(PointStatus.CHANNEL_LIMITED)
        return np.maximum(dp_i, 0.0)
