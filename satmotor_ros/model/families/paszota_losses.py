# SPDX-License-Identifier: Apache-2.0
"""
Paszota and Mączyszyn's volumetric losses, eqs. (29)-(30) of [1]_: one function per equation.

The losses of a constant-displacement motor or pump as one power law of the
pressure drop, the speed and the viscosity, each related to a reference value
[2]_ [3]_. The description does not show the sources of the losses (the
paper's words): it gives their sum only. Plain arithmetic, correct on a
Python float and on an array alike; inputs are assumed valid.

References
----------
.. [1] P. Śliwiński, "The influence of water and mineral oil on volumetric
   losses in a hydraulic motor", Polish Maritime Research 24 (2017).
.. [2] Z. Paszota, "Energy losses in hydrostatic drive", LAP LAMBERT, 2016.
.. [3] A. Mączyszyn, "Energy analysis of rotary positive displacement machines
   used in hydrostatic transmissions", PhD thesis, Gdańsk, 2014.

"""

from __future__ import annotations

from satmotor_ros.model._typing import Real
from satmotor_ros.model.units import CST

REFERENCE_VISCOSITY = 35.0 * CST
"""nu_n of eqs. (29)-(30): the related kinematic viscosity, 35 cSt (the paper's value), [m^2/s]."""


def motor_leakage(dp_i: Real, speed: Real, k_g: float, flow_t: float, p_n: float, n_t: float,
                  a_pv: float, a_nv: float, viscosity_factor: float) -> Real:
    r"""
    Compute the volumetric losses of a constant-displacement motor, eq. (29).

    .. math:: Q_l = k_g\,Q_{Pt}\left(\frac{\Delta p_i}{p_n}\right)^{a_{pv}}
        \left(\frac{n}{n_t}\right)^{a_{nv}}\left(\frac{\nu}{\nu_n}\right)^{a_{vv}}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n of the motor, [rad/s]
    k_g : float
        Loss coefficient k_g: Q_l / Q_Pt at p_n, n_t and nu_n, [-]
    flow_t : float
        Theoretical capacity Q_Pt of the pump feeding the motor, q_t n_t, [m^3/s]
    p_n : float
        Nominal pressure of the circuit, [Pa]
    n_t : float
        Theoretical speed of the motor at Q_Pt, [rad/s]
    a_pv : float
        Exponent of the pressure drop, > 0, [-]
    a_nv : float
        Exponent of the speed, >= 0, [-]
    viscosity_factor : float
        (nu/nu_n)^a_vv from :func:`viscosity_factor`, [-]

    Returns
    -------
    float or ndarray
        Q_l, [m^3/s]

    Examples
    --------
    >>> motor_leakage(25e6, 157.0, 0.02, 1e-3, 25e6, 157.0, 1.0, 0.3, 1.0)
    2e-05

    """
    out: Real = k_g * flow_t * viscosity_factor * (dp_i / p_n) ** a_pv * (speed / n_t) ** a_nv
    return out


def pump_leakage(dp_i: Real, speed: Real, k_1: float, q: float, p_n: float, a_pv: float,
                 viscosity_factor: float) -> Real:
    r"""
    Compute the volumetric losses of a constant-displacement pump, eq. (30).

    .. math:: Q_l = k_1\,q_{Pt}\,n_P\left(\frac{\Delta p_i}{p_n}\right)^{a_{pv}}
        \left(\frac{\nu}{\nu_n}\right)^{a_{vv}}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure rise in the working chambers, [Pa]
    speed : float or ndarray
        Pump speed n_P, [rad/s]
    k_1 : float
        Loss coefficient k_1: Q_l / (q_Pt n_P) at p_n and nu_n, [-]
    q : float
        Theoretical displacement of the pump q_Pt, [m^3/rad]
    p_n : float
        Nominal pressure of the circuit, [Pa]
    a_pv : float
        Exponent of the pressure, > 0, [-]
    viscosity_factor : float
        (nu/nu_n)^a_vv from :func:`viscosity_factor`, [-]

    Returns
    -------
    float or ndarray
        Q_l of the pump, [m^3/s]

    Examples
    --------
    >>> round(pump_leakage(25e6, 150.0, 0.03, 5e-6, 25e6, 1.0, 1.0), 12)
    2.25e-05

    """
    out: Real = k_1 * q * speed * viscosity_factor * (dp_i / p_n) ** a_pv
    return out


def viscosity_factor(nu: float, nu_n: float, a_vv: float) -> float:
    r"""
    Compute the viscosity factor of eqs. (29)-(30).

    .. math:: \left(\frac{\nu}{\nu_n}\right)^{a_{vv}}

    Parameters
    ----------
    nu : float
        Kinematic viscosity of the liquid, [m^2/s]
    nu_n : float
        The related viscosity nu_n (35 cSt in the paper), [m^2/s]
    a_vv : float
        Exponent of the viscosity; < 0 when the losses fall as the viscosity rises, [-]

    Returns
    -------
    float
        The factor, [-]

    Examples
    --------
    >>> viscosity_factor(35e-6, REFERENCE_VISCOSITY, -0.5)
    1.0

    """
    out: float = (nu / nu_n) ** a_vv
    return out
