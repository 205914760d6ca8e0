# SPDX-License-Identifier: Apache-2.0
"""The constants of every equation for one motor, coefficient set and liquid, derived once."""

from __future__ import annotations

from dataclasses import dataclass
import math

from satmotor_ros.model.coefficients import CoefficientSet, Liquid, MotorGeometry, ValidRange
from satmotor_ros.model.families._base import Bounds, bounds
from satmotor_ros.model.families.sliwinski2017 import losses as eq
from satmotor_ros.model.families.sliwinski2017.speed import effective_speed_coefficients


@dataclass(frozen=True)
class DerivedCoefficients(Bounds):
    """
    Per-model constants of eqs. (1)-(40), each read off the equation module's own helper.

    The range constants every family gives (qt, dp_limit, the validated range)
    are :class:`~satmotor_ros.model.families._base.Bounds`'.

    The equations then reduce to a few multiplications and powers, which both
    the array maps and the single-point path evaluate. ``c_lumped`` is the C of
    eq. (33) for the model's liquid (the fitted ``coef.c`` with the liquid's own
    compressibility share), not the fitted coefficient itself.
    """

    c_fc_beta: float  # C_fc*beta_l of eq. (11) for this liquid [1/(MPa*rev)]
    c_dch: float  # C_dch of eq. (12) [1/(MPa*rev)]
    c_b: float  # C_b of eq. (13) [1/(MPa*rev)]
    c_lumped: float  # C = C_fc*beta_l + C_dch + C_b of eq. (33) for this liquid [1/(MPa*rev)]
    h0: float  # unloaded clearance of eq. (2) [m]
    compliance: float  # h = h0 - compliance * dp_i, eq. (2) [m/Pa]
    lfg_k: float  # Q_Lfg = lfg_k * (h^3 dp_i)^lfg_e, eq. (1) [SI]
    lfg_e: float  # [-]
    com_k: float  # Q_C = com_k * dp_i^com_e, eq. (5) [SI]
    com_e: float  # gamma [-]
    k_fc: float  # Delta Q_fc = k_fc * dp_i * n, eq. (11) [m^3/(Pa*rad)]
    k_dch: float  # Delta Q_dch = k_dch * dp_i * n, eq. (12) [m^3/(Pa*rad)]
    k_b: float  # Delta Q_b = k_b * dp_i * n, eq. (13) [m^3/(Pa*rad)]
    k_p: float  # k_fc + k_dch + k_b as eq. (33) lumps them [m^3/(Pa*rad)]
    k_i: float  # Delta Q_id = k_i * n^0.5, eq. (14) [m^3/s/(rad/s)^0.5]
    k_ex: float  # Q_ex = k_ex * p_ex, eq. (24) [m^3/(s*Pa)]
    ch_a: float  # Delta p_ich = (ch_a * Q + ch_b) * Q, eq. (35) [Pa*s^2/m^6]
    ch_b: float  # [Pa*s/m^3]
    es_a0: float  # eq. (40) folded: see speed.effective_speed_coefficients
    es_a1: float
    es_scale: float
    es_b: float
    c1_39: float  # C_1 of eq. (39) [cm^3/rev (rev/min)^0.5]
    c2_39: float  # C_2 of eq. (39) [-]


def derive(geometry: MotorGeometry, coefficient_set: CoefficientSet, valid_range: ValidRange,
           liquid: Liquid) -> DerivedCoefficients:
    """
    Derive the constants of every equation for one motor and liquid.

    The arguments are those of :meth:`~satmotor_ros.model.families._base.Family.compose`.

    Returns
    -------
    DerivedCoefficients
        The constants.

    """
    coef = coefficient_set.coefficients
    c_fc_ref = eq.compressibility_coefficient(coefficient_set.liquid.bulk_modulus, geometry, coef)
    c_fc_beta = eq.compressibility_coefficient(liquid.bulk_modulus, geometry, coef)
    rest = coef.c - c_fc_ref
    c_dch = coef.deformation_share * rest
    c_b = rest - c_dch
    c_lumped = c_fc_beta + rest
    h0, compliance = eq.clearance_coefficients(geometry, coef)
    lfg_k, lfg_e = eq.flat_clearance_coefficients(liquid, geometry, coef)
    ch_a, ch_b = eq.channel_coefficients(liquid, coef)
    es = effective_speed_coefficients(c_lumped, coef.c_id, geometry)
    # Q_Lfg ~ (h^3 dp)^e rises with dp only while h - 3 s dp > 0 with h = h0 - s dp: dp < h0/4s
    dp_limit = h0 / (4.0 * compliance) if compliance > 0.0 else math.inf
    return DerivedCoefficients(
        **vars(bounds(geometry, coefficient_set, valid_range, liquid, dp_limit)),
        c_fc_beta=c_fc_beta, c_dch=c_dch, c_b=c_b, c_lumped=c_lumped,
        h0=h0, compliance=compliance, lfg_k=lfg_k, lfg_e=lfg_e,
        com_k=eq.commutation_coefficient(liquid, geometry, coef), com_e=coef.gamma,
        k_fc=eq.pressure_speed_coefficient(c_fc_beta, geometry),
        k_dch=eq.pressure_speed_coefficient(c_dch, geometry),
        k_b=eq.pressure_speed_coefficient(c_b, geometry),
        k_p=eq.pressure_speed_coefficient(c_lumped, geometry),
        k_i=eq.inertia_coefficient(coef.c_id, geometry), k_ex=coef.external_leakage,
        ch_a=ch_a, ch_b=ch_b, es_a0=es[0], es_a1=es[1], es_scale=es[2],
        es_b=es[3], c1_39=coef.c1_39, c2_39=coef.c2_39)
