# SPDX-License-Identifier: Apache-2.0
"""
The motor inside the plant: the model library's single-point path, and its rebuilds.

The plant holds no loss equation of its own. Effects that change the motor
itself (viscosity following temperature, clearance wear) build a new
:class:`~satmotor_ros.model.MotorModel` with a changed liquid or geometry, but
only when the quantity has moved by more than a relative tolerance since the
last build, so a slow drift costs one rebuild per tolerance step.
"""

from __future__ import annotations

import dataclasses

from satmotor_ros.model import MotorModel


class MotorCache:
    """
    The current motor model for a viscosity and a clearance growth.

    Parameters
    ----------
    model : MotorModel
        The motor as configured (nominal viscosity, unworn clearances), [-]
    tolerance : float
        Relative change of viscosity, or of the mean clearance, that triggers a rebuild, [-]

    """

    def __init__(self, model: MotorModel, tolerance: float) -> None:
        """Start from the nominal motor."""
        self.base = model
        self.model = model
        self.tolerance = tolerance
        self.viscosity = model.liquid.kinematic_viscosity  # of the current build [m^2/s]
        self.clearance_growth = 0.0  # of the current build [m]
        self.leakage = 1.0  # factor on the family's leakage parts of the current build [-]
        geometry = model.geometry
        self._h0 = 0.5 * (geometry.clearance_rotor + geometry.clearance_satellites)
        self.rebuilds = 0

    def update(self, viscosity: float, clearance_growth: float, leakage: float = 1.0) -> bool:
        """
        Rebuild the model if viscosity, clearances or leakage moved beyond the tolerance.

        Parameters
        ----------
        viscosity : float
            Kinematic viscosity the liquid has now, [m^2/s]
        clearance_growth : float
            Growth of both axial clearances since new, [m]
        leakage : float
            Factor on the family's leakage parts since new (``leakage_wear``), [-]

        Returns
        -------
        bool
            True when the model was rebuilt.

        """
        tol = self.tolerance
        if (abs(viscosity - self.viscosity) <= tol * self.viscosity
                and abs(clearance_growth - self.clearance_growth) <= tol * self._h0
                and abs(leakage - self.leakage) <= tol * self.leakage):
            return False
        base = self.base
        liquid = dataclasses.replace(base.liquid, kinematic_viscosity=viscosity)
        geometry = dataclasses.replace(
            base.geometry,
            clearance_rotor=base.geometry.clearance_rotor + clearance_growth,
            clearance_satellites=base.geometry.clearance_satellites + clearance_growth)
        spec = base.coefficient_set
        if leakage != 1.0:
            family = base.family
            spec = dataclasses.replace(spec, coefficients=family.scaled(
                spec.coefficients, dict.fromkeys(family.leakage, leakage)))
        self.model = MotorModel(geometry, spec, base.valid_range, liquid,
                                base.displacement_law, base.name)
        self.viscosity = viscosity
        self.clearance_growth = clearance_growth
        self.leakage = leakage
        self.rebuilds += 1
        return True
