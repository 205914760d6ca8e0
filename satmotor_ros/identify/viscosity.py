# SPDX-License-Identifier: Apache-2.0
"""
Viscosity-temperature laws pinned at a coefficient set's viscosity.

Each law (Walther for oil, Vogel for water, :mod:`satmotor_ros.model.viscosity`)
is pinned at the coefficient set's own viscosity: the reference temperature is
where the standard law for the liquid gives the set's viscosity, so a slope of
0 means a constant viscosity (the packaged model) and the standard slope means
the standard law.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from satmotor_ros.model._typing import ArrayLike, FloatArray
from satmotor_ros.model.coefficients import Liquid
from satmotor_ros.model.viscosity import (ISO_VG46, KELVIN, vogel_viscosity, walther_slope,
                                          walther_viscosity, walther_w, WATER_VOGEL)


@dataclass(frozen=True)
class ViscosityLaw:
    """A viscosity-temperature law pinned at a coefficient set's viscosity."""

    law: str  # 'walther' (ASTM D341) or 'vogel'
    reference_temperature: float  # where the set's viscosity holds [degC]
    reference_viscosity: float  # the set's kinematic viscosity [m^2/s]
    standard_slope: float  # B of the standard law: [-] (walther) or [K] (vogel)
    unit: str  # unit of the slope

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
            Kinematic viscosity, [m^2/s]

        """
        if self.law == 'vogel':
            return vogel_viscosity(temperature, self.reference_temperature,
                                   self.reference_viscosity, slope)
        return walther_viscosity(temperature, self.reference_temperature,
                                 self.reference_viscosity, slope)


def standard_law(liquid: Liquid, set_name: str) -> ViscosityLaw:
    """
    Choose the standard law for a coefficient set and pin it at the set's viscosity.

    Water (a set or liquid whose name says so) follows Vogel, anything else
    the Walther line of an ISO VG 46 mineral oil.

    Parameters
    ----------
    liquid : Liquid
        The set's liquid, [-]
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
        return ViscosityLaw('vogel', t_ref, nu, b, 'K')
    (t1, nu1), (t2, nu2) = ISO_VG46
    slope = walther_slope(t1, nu1, t2, nu2)
    t_walther = (t1 + KELVIN) * 10.0 ** ((walther_w(nu1) - walther_w(nu)) / slope) - KELVIN
    return ViscosityLaw('walther', float(t_walther), nu, slope, '-')
