# SPDX-License-Identifier: Apache-2.0
"""
The model's loss components at measured operating points, and how an effect modifies them.

The measured volumetric loss is Q_vl = Q - q_t n (eq. 31 read backwards).
The model gives it as the sum of the leakage (eqs. 1, 5, 24) and the
speed-dependent part (eqs. 11-14, 33), evaluated at the measured speed and
at the chamber drop dp_i = dp - dp_ich(Q) of eqs. (34)-(35), where Q is the
measured flow, so no equation has to be solved per point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import Modifier
from satmotor_ros.model.losses import channel_pressure_drop, clearance_height

SCALES = ('leakage_scale', 'c_scale', 'c_id_scale')
"""The identifiable model coefficients, as factors on the packaged values."""


@dataclass(frozen=True)
class LossParts:
    """Model components at the measured points, each for unit scale factors, [m^3/s]."""

    flow: FloatArray  # measured Q [m^3/s]
    speed: FloatArray  # measured n [rad/s]
    dp: FloatArray  # port drop [Pa]
    dp_i: FloatArray  # chamber drop, eq. (34) [Pa]
    displacement: FloatArray  # q_t n [m^3/s]
    flat_clearance: FloatArray  # Q_Lfg, eq. (1) [m^3/s]
    commutation: FloatArray  # Q_C, eq. (5) [m^3/s]
    pressure_speed: FloatArray  # dQ_fc + dQ_dch + dQ_b, eqs. (11)-(13) [m^3/s]
    inertia: FloatArray  # dQ_id, eq. (14) [m^3/s]
    clearance: FloatArray  # h, eq. (2) [m]
    clearance_satellites: float  # h_S [m]
    h_exponent: float  # Q_Lfg ~ h^(3/(2-beta)), eq. (1) [-]
    hs_exponent: float  # Q_C ~ h_S^C_2, eq. (5) [-]
    nu_exponent_lfg: float  # Q_Lfg ~ nu^(-beta/(2-beta)), eq. (1) [-]
    nu_exponent_c: float  # Q_C ~ nu^(-gamma), eq. (5) [-]

    @property
    def loss(self) -> FloatArray:
        """Measured volumetric loss Q_vl = Q - q_t n, [m^3/s]."""
        return self.flow - self.displacement

    def __len__(self) -> int:
        """Return the number of points."""
        return int(self.flow.size)


NO_EFFECT = Modifier()
"""The model as it is."""


def predict_flow(parts: LossParts, scales: FloatArray, mod: Modifier = NO_EFFECT) -> FloatArray:
    r"""
    Predict the measured flow from the scaled components and an effect, eq. (36).

    .. math:: Q_m = G_Q\left[\frac{q_t n_m}{G_n} + s_L(Q_{Lfg} \phi_L + Q_C \phi_C)
        + s_C \frac{\Delta Q_{C}}{G_n} + \frac{s_{id}\,\Delta Q_{id}}{\sqrt{G_n}}
        + Q_{add}\right] + b

    Parameters
    ----------
    parts : LossParts
        Components at the measured points, [-]
    scales : ndarray
        Factors on the leakage, C and C_id, [-]
    mod : Modifier
        The effect's gains, factors and extra terms, [-]

    Returns
    -------
    ndarray
        Predicted measured flow, [m^3/s]

    """
    g = mod.speed_gain
    inner = (parts.displacement / g
             + scales[0] * (parts.flat_clearance * mod.flat_clearance
                            + parts.commutation * mod.commutation)
             + scales[1] * parts.pressure_speed / g
             + scales[2] * parts.inertia / np.sqrt(g) + mod.additive)
    return mod.flow_gain * inner + mod.offset


def loss_parts(model: MotorModel, table: BenchTable) -> tuple[LossParts, np.ndarray]:
    """
    Evaluate the model's components at the table's points.

    Parameters
    ----------
    model : MotorModel
        The packaged (or user) model for the liquid, [-]
    table : BenchTable
        Steady operating points, [-]

    Returns
    -------
    LossParts
        Components at the usable points.
    ndarray of bool
        Which rows of `table` were usable (finite, forward flow and speed,
        dp_i within the model's limit).

    Raises
    ------
    IdentificationError
        If no point is usable.

    """
    if model.family.name != 'sliwinski2017':  # the fit below scales that family's parts
        msg = (f'calibrating the {model.family.name} family is not supported yet '
               '(its linear parts: model.family.linear_parts); use --family sliwinski2017')
        raise IdentificationError(msg)
    coef = model.coef
    flow, speed, dp = table.flow, table.speed, table.dp
    d = model.derived
    dp_i = dp - channel_pressure_drop(np.maximum(flow, 0.0), d.ch_a, d.ch_b)
    usable = (np.isfinite(flow) & np.isfinite(speed) & np.isfinite(dp) & (flow > 0.0)
              & (speed >= 0.0) & (dp_i >= 0.0) & (dp_i < model.dp_limit))
    if not usable.any():
        msg = (f'{table.source}: no usable point (need flow > 0, speed >= 0 and a chamber '
               f'pressure drop between 0 and {model.dp_limit / 1e6:.1f} MPa)')
        raise IdentificationError(msg)
    n, dpi = speed[usable], dp_i[usable]
    losses = model.breakdown(n, dpi)
    beta = coef.beta
    parts = LossParts(
        flow=flow[usable].copy(), speed=n.copy(), dp=dp[usable].copy(), dp_i=dpi.copy(),
        displacement=model.geometry.displacement * n,
        flat_clearance=losses.flat_clearance, commutation=losses.commutation,
        pressure_speed=losses.compressibility + losses.deformation + losses.backlash,
        inertia=losses.inertia, clearance=clearance_height(dpi, d.h0, d.compliance),
        clearance_satellites=model.geometry.clearance_satellites,
        h_exponent=3.0 / (2.0 - beta), hs_exponent=coef.c2,
        nu_exponent_lfg=-beta / (2.0 - beta), nu_exponent_c=-coef.gamma)
    return parts, usable
