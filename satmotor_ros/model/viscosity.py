# SPDX-License-Identifier: Apache-2.0
"""
Viscosity-temperature laws: Walther (ASTM D341) for mineral oil, Vogel for water.

The paper's model takes one viscosity per liquid; a calibrated
``viscosity_temperature`` effect (:mod:`.effects`) makes it follow the liquid
temperature through one of these laws.

References
----------
.. [1] ASTM D341, "Standard Practice for Viscosity-Temperature Equations and
   Charts for Liquid Petroleum or Hydrocarbon Products".
.. [2] Vogel equation for water, mu = A 10^(B / (T - C)) with A = 2.414e-5 Pa*s,
   B = 247.8 K, C = 140 K (within 2.5 % from 0 to 370 degC); T. Al-Shemmeri,
   "Engineering Fluid Mechanics" (2012).

"""

from __future__ import annotations

import math

import numpy as np

from satmotor_ros.model._typing import ArrayLike, FloatArray

KELVIN = 273.15
"""0 degC in K."""

ISO_VG46 = ((40.0, 46.0e-6), (100.0, 6.8e-6))
"""ISO VG 46 mineral oil (as Total Azolla ZS 46): nu at 40 and 100 degC, [degC], [m^2/s]."""

WATER_VOGEL = (2.414e-5, 247.8, 140.0)
"""Vogel constants of water: A [Pa*s], B [K], C [K], ref. [2]."""


def walther_w(nu: ArrayLike) -> FloatArray:
    """Return W = log10(log10(nu_cSt + 0.7)) of ASTM D341 for nu in m^2/s, [-]."""
    return np.log10(np.log10(np.asarray(nu, dtype=float) * 1.0e6 + 0.7))


def walther_slope(t1: float, nu1: float, t2: float, nu2: float) -> float:
    r"""
    Compute the ASTM D341 slope B through two viscosities, ref. [1].

    .. math:: B = \frac{W(\nu_1) - W(\nu_2)}{\log_{10} T_2 - \log_{10} T_1},
        \quad W = \log_{10}\log_{10}(\nu + 0.7)

    Parameters
    ----------
    t1 : float
        First temperature, [degC]
    nu1 : float
        Kinematic viscosity at `t1`, [m^2/s]
    t2 : float
        Second temperature, [degC]
    nu2 : float
        Kinematic viscosity at `t2`, [m^2/s]

    Returns
    -------
    float
        Slope B, [-]

    Examples
    --------
    >>> round(walther_slope(40.0, 46e-6, 100.0, 6.8e-6), 3)
    3.684

    """
    return float((walther_w(nu1) - walther_w(nu2))
                 / (math.log10(t2 + KELVIN) - math.log10(t1 + KELVIN)))


def walther_viscosity(temperature: ArrayLike, t_ref: float, nu_ref: float,
                      slope: float) -> FloatArray:
    r"""
    Compute the kinematic viscosity of an oil by the Walther equation, ref. [1].

    .. math:: W(\nu) = W(\nu_{ref}) - B\,(\log_{10} T - \log_{10} T_{ref})

    with nu in cSt and T in K; valid for nu >= 2 cSt.

    Parameters
    ----------
    temperature : float or ndarray
        Liquid temperature, [degC]
    t_ref : float
        Temperature at which the viscosity is `nu_ref`, [degC]
    nu_ref : float
        Kinematic viscosity at `t_ref`, [m^2/s]
    slope : float
        Walther slope B; 0 gives a constant viscosity, [-]

    Returns
    -------
    ndarray
        Kinematic viscosity, [m^2/s]

    """
    t = np.asarray(temperature, dtype=float) + KELVIN
    w = walther_w(nu_ref) - slope * (np.log10(t) - math.log10(t_ref + KELVIN))
    return (10.0 ** (10.0 ** w) - 0.7) * 1.0e-6


def vogel_viscosity(temperature: ArrayLike, t_ref: float, nu_ref: float, slope: float,
                    t_inf: float = WATER_VOGEL[2]) -> FloatArray:
    r"""
    Compute the kinematic viscosity of water by the Vogel equation, ref. [2].

    .. math:: \nu = \nu_{ref}\,10^{B\,(1/(T - C) - 1/(T_{ref} - C))}

    The density of water changes by < 1 % over 10-60 degC, so the kinematic
    viscosity follows the dynamic one.

    Parameters
    ----------
    temperature : float or ndarray
        Liquid temperature, [degC]
    t_ref : float
        Temperature at which the viscosity is `nu_ref`, [degC]
    nu_ref : float
        Kinematic viscosity at `t_ref`, [m^2/s]
    slope : float
        Vogel B; 0 gives a constant viscosity, [K]
    t_inf : float
        Vogel C, [K]

    Returns
    -------
    ndarray
        Kinematic viscosity, [m^2/s]

    """
    t = np.asarray(temperature, dtype=float) + KELVIN
    return nu_ref * 10.0 ** (slope * (1.0 / (t - t_inf) - 1.0 / (t_ref + KELVIN - t_inf)))
