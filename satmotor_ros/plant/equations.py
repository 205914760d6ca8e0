# SPDX-License-Identifier: Apache-2.0
"""
The plant's own equations, one per function: lines, valves, friction, heat and viscosity.

The motor's volumetric losses are not here: they come from
:class:`satmotor_ros.model.MotorModel` (Śliwiński 2017, eqs. (31)-(36)). The
equations below are the standard lumped forms for a hydrostatic drive; the
paper gives none of them. Equation tags (P1)-(P8) are this package's own and
are listed in doc/plant.md. The line pressures (P1) and the relief valve (P2) are
solved implicitly with the shaft in :meth:`satmotor_ros.plant.Plant._solve`; the
viscosity follows the liquid's law (:mod:`satmotor_ros.model.viscosity`) through
the ``viscosity_temperature`` effect.
"""

from __future__ import annotations

import math


def return_flow(p_out: float, p_tank: float, back_pressure: float, conductance: float) -> float:
    r"""
    Compute the flow through the return-line back-pressure valve, eq. (P3).

    .. math:: Q_r = G_r\,(p_{out} - p_t - p_b)

    Negative below p_t + p_b: the back-pressure circuit feeds the outlet line
    (boost), so the outlet never runs dry while the motor turns.

    Parameters
    ----------
    p_out, p_tank : float
        Outlet-line and tank pressures, absolute, [Pa]
    back_pressure : float
        Back pressure p_b above tank, [Pa]
    conductance : float
        Valve slope G_r, [m^3/(s*Pa)]

    Returns
    -------
    float
        Flow from the outlet line to the tank, [m^3/s]

    """
    return conductance * (p_out - p_tank - back_pressure)


def friction_torque(speed: float, dp_i: float, displacement: float, viscous: float,
                    coulomb: float, pressure_share: float) -> float:
    r"""
    Compute the hydro-mechanical torque loss of a sliding shaft, eq. (P4).

    .. math:: T_{hm} = b\,\omega + \mathrm{sgn}(\omega)\,(T_c + c_p\,q_t\,|\Delta p_i|)

    Parameters
    ----------
    speed : float
        Shaft speed omega (non-zero: sliding), [rad/s]
    dp_i : float
        Pressure drop in the working chambers, [Pa]
    displacement : float
        Theoretical displacement q_t, [m^3/rad]
    viscous : float
        Viscous friction b, [N*m*s/rad]
    coulomb : float
        Coulomb friction T_c, [N*m]
    pressure_share : float
        Pressure-proportional friction c_p, [-]

    Returns
    -------
    float
        Friction torque opposing the motion, [N*m]

    """
    return viscous * speed + math.copysign(
        coulomb + pressure_share * displacement * abs(dp_i), speed)


def driving_torque(dp_i: float, displacement: float) -> float:
    r"""
    Compute the ideal torque of the working chambers, eq. (P5).

    .. math:: T_i = q_t\,\Delta p_i

    Parameters
    ----------
    dp_i : float
        Pressure drop in the working chambers, [Pa]
    displacement : float
        Theoretical displacement q_t, [m^3/rad]

    Returns
    -------
    float
        Ideal torque, [N*m]

    """
    return displacement * dp_i


def case_pressure(p_out: float, p_tank: float, offset: float, outlet_share: float) -> float:
    r"""
    Compute the case pressure from the outlet pressure, eq. (P6).

    .. math:: p_c = p_t + p_{c0} + s_c\,(p_{out} - p_t)

    Parameters
    ----------
    p_out, p_tank : float
        Outlet-line and tank pressures, absolute, [Pa]
    offset : float
        Case pressure above tank at p_out = p_t, [Pa]
    outlet_share : float
        Share s_c of the outlet gauge pressure seen in the case, [-]

    Returns
    -------
    float
        Case pressure, absolute, [Pa]

    """
    return p_tank + offset + outlet_share * (p_out - p_tank)


def temperature_rate(loss_power: float, temperature: float, ambient: float,
                     heat_capacity: float, cooling: float) -> float:
    r"""
    Compute the heating rate of the liquid, eq. (P8).

    .. math:: C_{th}\,\dot T = P_{loss} - hA\,(T - T_a)

    Parameters
    ----------
    loss_power : float
        Hydraulic and mechanical power lost in the circuit, [W]
    temperature : float
        Liquid temperature, [degC]
    ambient : float
        Ambient temperature, [degC]
    heat_capacity : float
        Heat capacity C_th of liquid and metal, [J/K]
    cooling : float
        Heat transfer hA to the ambient, [W/K]

    Returns
    -------
    float
        dT/dt, [K/s]

    """
    return (loss_power - cooling * (temperature - ambient)) / heat_capacity
