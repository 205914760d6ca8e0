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
import math

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
        geometry = model.geometry
        self._h0 = 0.5 * (geometry.clearance_rotor + geometry.clearance_satellites)
        self.rebuilds = 0

    def update(self, viscosity: float, clearance_growth: float) -> bool:
        """
        Rebuild the model if viscosity or clearances moved beyond the tolerance.

        Parameters
        ----------
        viscosity : float
            Kinematic viscosity the liquid has now, [m^2/s]
        clearance_growth : float
            Growth of both axial clearances since new, [m]

        Returns
        -------
        bool
            True when the model was rebuilt.

        """
        tol = self.tolerance
        if (abs(viscosity - self.viscosity) <= tol * self.viscosity
                and abs(clearance_growth - self.clearance_growth) <= tol * self._h0):
            return False
        base = self.base
        liquid = dataclasses.replace(base.liquid, kinematic_viscosity=viscosity)
        geometry = dataclasses.replace(
            base.geometry,
            clearance_rotor=base.geometry.clearance_rotor + clearance_growth,
            clearance_satellites=base.geometry.clearance_satellites + clearance_growth)
        self.model = MotorModel(geometry, base.coefficient_set, base.valid_range, liquid,
                                base.displacement_law, base.name)
        self.viscosity = viscosity
        self.clearance_growth = clearance_growth
        self.rebuilds += 1
        return True


def mirrored_point(model: MotorModel, speed: float, dp: float, flow_guess: float | None,
                   channels: dict[str, float] | None = None
                   ) -> tuple[float, float, float, float, int]:
    """
    Evaluate the motor at any sign of speed and pressure drop.

    The paper's model covers n >= 0 and dp >= 0. A shaft driven backwards, or a
    pressure drop reversed by an overrunning load, is mapped onto that domain
    by symmetry: the losses at (|n|, |dp|) flow from the higher to the lower
    pressure, and the displacement flow follows the shaft.

    Parameters
    ----------
    model : MotorModel
        The motor, [-]
    speed : float
        Shaft speed, any sign, [rad/s]
    dp : float
        Port pressure drop p_in - p_out, any sign, [Pa]
    flow_guess : float or None
        Warm start of the port-drop solve, [m^3/s]
    channels : dict, optional
        Channels a calibrated coefficient set's effects read, [-]

    Returns
    -------
    tuple
        Flow into the inlet port [m^3/s], dp_i [Pa], external leakage [m^3/s],
        the speed-driven inertia loss [m^3/s] and the PointStatus flags.

    """
    qt = model.geometry.displacement
    a_speed, a_dp = abs(speed), abs(dp)
    guess = None if flow_guess is None else qt * a_speed + abs(flow_guess - qt * speed)
    pt = model.absorbency_point(a_speed, a_dp, flow_guess=guess, channels=channels)
    loss = pt.flow - qt * a_speed - pt.inertia
    sign = 1.0 if dp >= 0.0 else -1.0
    return (qt * speed + math.copysign(pt.inertia, speed) + sign * loss,
            math.copysign(pt.dp_i, dp), pt.external, pt.inertia, pt.status)
