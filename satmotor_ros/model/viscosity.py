# SPDX-License-Identifier: Apache-2.0
"""
Viscosity-temperature laws: Walther (ASTM D341) for mineral oil, Vogel for water.

The paper's model takes one viscosity per liquid; a ``viscosity_temperature``
effect (:mod:`.effects`) makes it follow the liquid temperature through one of
these laws. :data:`LAWS` is the one registry of laws: the model, the plant and
calibration all evaluate a law through :class:`ViscosityLaw`, and
:func:`standard_law` picks a liquid's law and pins it at the liquid's viscosity.

References
----------
.. [1] ASTM D341, "Standard Practice for Viscosity-Temperature Equations and
   Charts for Liquid Petroleum or Hydrocarbon Products".
.. [2] Vogel equation for water, mu = A 10^(B / (T - C)) with A = 2.414e-5 Pa*s,
   B = 247.8 K, C = 140 K (within 2.5 % from 0 to 370 degC); T. Al-Shemmeri,
   "Engineering Fluid Mechanics" (2012).

"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
import math

import numpy as np

from satmotor_ros.model._typing import ArrayLike, FloatArray
from satmotor_ros.model.coefficients import Liquid


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
        Water temperature, [degC]
    t_ref, nu_ref : float
        The reference point, as for :func:`walther_viscosity`, [degC], [m^2/s]
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


LAWS: dict[str, tuple[Callable[..., FloatArray], str]] = {
    'walther': (walther_viscosity, '-'),
    'vogel': (vogel_viscosity, 'K'),
}
"""The viscosity-temperature laws by name: function and the unit of its slope B."""


@dataclass(frozen=True)
class ViscosityLaw:
    """A viscosity-temperature law of :data:`LAWS` pinned at a reference viscosity."""

    law: str  # a key of LAWS: 'walther' (ASTM D341) or 'vogel'
    reference_temperature: float  # where the reference viscosity holds [degC]
    reference_viscosity: float  # kinematic viscosity there [m^2/s]
    standard_slope: float = math.nan  # B of the liquid's standard law [law unit]
    vogel_c: float = WATER_VOGEL[2]  # Vogel C [K]

    @property
    def unit(self) -> str:
        """Return the unit of the slope B."""
        return LAWS[self.law][1]

    def viscosity(self, temperature: ArrayLike, slope: float) -> FloatArray:
        """
        Evaluate the law with a given slope.

        Parameters
        ----------
        temperature : float or ndarray
            Liquid temperature, [degC]
        slope : float
            Walther B [-] or Vogel B [K]; 0 is a constant viscosity, [-]

        Returns
        -------
        ndarray
            Kinematic viscosity; NaN at or below the Vogel pole, [m^2/s]

        """
        if self.law == 'vogel':
            t = np.asarray(temperature, dtype=float)
            nu = vogel_viscosity(t, self.reference_temperature, self.reference_viscosity,
                                 slope, self.vogel_c)
            return np.where(t + KELVIN > self.vogel_c, nu, math.nan)
        return walther_viscosity(temperature, self.reference_temperature,
                                 self.reference_viscosity, slope)


def standard_law(liquid: Liquid, set_name: str = '') -> ViscosityLaw:
    """
    Choose the standard law for a liquid and pin it at the liquid's viscosity.

    Water (a set or liquid whose name says so) follows Vogel, anything else
    the Walther line of an ISO VG 46 mineral oil. The reference temperature is
    where that standard law gives the liquid's viscosity, so a slope of 0 means
    a constant viscosity and the standard slope the standard law.

    Parameters
    ----------
    liquid : Liquid
        The liquid, [-]
    set_name : str
        Name of the coefficient set, [-]

    Returns
    -------
    ViscosityLaw
        The pinned law.

    """
    nu = liquid.kinematic_viscosity
    if 'water' in f'{set_name} {liquid.name}'.lower():
        a, b, c = WATER_VOGEL
        t_ref = c + b / math.log10(nu * liquid.density / a) - KELVIN
        return ViscosityLaw('vogel', t_ref, nu, b)
    (t1, nu1), (t2, nu2) = ISO_VG46
    slope = walther_slope(t1, nu1, t2, nu2)
    w1, w = float(walther_w(nu1)), float(walther_w(nu))
    t_ref = (t1 + KELVIN) * 10.0 ** ((w1 - w) / slope) - KELVIN
    return ViscosityLaw('walther', t_ref, nu, slope)
