# SPDX-License-Identifier: Apache-2.0
"""
The earlier literature's volumetric losses, eqs. (15)-(28) of [1]_: one function per equation.

Balawender [2]_ and Śliwiński [3]_ write the losses of a motor supplied with
oil (index O) as a pressure-and-speed term, a laminar and a turbulent
leakage and an external leakage (eq. 15), and those of a motor supplied with
a low-viscosity liquid (index E: water, HFA-E emulsion) as the oil's terms
scaled by ratios of the two liquids' properties (eq. 16). ``q`` is the
displacement per radian, q_t/(2 pi). Every function is plain arithmetic,
correct on a Python float and on an array alike; inputs are assumed valid
(screening belongs to the model).

The printed eqs. (16), (18) and (26) are garbled the way eq. (36) is: an
underbrace label printed as a denominator. ``k_c ΔQ_vl,O / ΔQ_vl,E`` reads
"ΔQ_vl,E = k_c ΔQ_vl,O", and so on (doc/families.md).

References
----------
.. [1] P. Śliwiński, "The influence of water and mineral oil on volumetric
   losses in a hydraulic motor", Polish Maritime Research 24 (2017).
.. [2] A. Balawender, "Physical and mathematical model of losses in hydraulic
   motors", Gdańsk University of Technology, 2005.
.. [3] P. Śliwiński, "Comparison of phenomena in hydraulic satellite motors
   supplied with oil-in-water emulsion and oil", PhD thesis, Gdańsk, 2006.

"""

from __future__ import annotations

from satmotor_ros.model._numeric import maximum
from satmotor_ros.model._typing import Real
from satmotor_ros.model.units import MPA

TURBULENT_FACTOR = 0.9
"""The factor of eq. (22), [-]."""

TURBULENT_EXPONENT = -3.0 / 7.0
"""The exponent of Delta p_i,O in eq. (22) (Blasius-type friction), [-]; Delta p_i in MPa."""

LAMINAR_TRANSITION = TURBULENT_FACTOR ** (-1.0 / TURBULENT_EXPONENT) * MPA
"""
Chamber drop where eqs. (22) and (23) give the same k_s: 0.9^(7/3) MPa = 0.782 MPa, [Pa].

Below it eq. (22) would make the leakage of the low-viscosity liquid larger than
laminar flow allows, so the family takes eq. (23) there (laminar) and eq. (22)
above it (not fully developed turbulent): k_s is continuous at this drop.
"""


def pressure_speed_loss_low_viscosity(dp_i: Real, omega: Real, q: float, c_vl: float,
                                      k_c: float) -> Real:
    r"""
    Compute the loss proportional to pressure and speed with a low-viscosity liquid, eq. (18).

    .. math:: \Delta Q_{vl,E} = \underbrace{k_c\,C_{vl,O}}_{C_{vl,E}}\,\frac{q_t}{2\pi}
        \,\Delta p_{i,E}\,\omega

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers Delta p_i,E, [Pa]
    omega : float or ndarray
        Shaft speed, [rad/s]
    q : float
        Displacement q_t/(2 pi), [m^3/rad]
    c_vl : float
        C_vl,O of the oil, [1/Pa]
    k_c : float
        Compressibility ratio of eq. (19), [-]

    Returns
    -------
    float or ndarray
        Delta Q_vl,E, [m^3/s]

    """
    return k_c * c_vl * q * dp_i * omega


def compressibility_ratio(bulk_modulus_oil: float, bulk_modulus_liquid: float) -> float:
    r"""
    Compute k_c, the ratio of the liquids' bulk moduli, eq. (19).

    .. math:: k_c = \frac{K_O}{K_E}

    Parameters
    ----------
    bulk_modulus_oil : float
        K_O of the oil, [Pa]
    bulk_modulus_liquid : float
        K_E of the low-viscosity liquid, [Pa]

    Returns
    -------
    float
        k_c, [-]

    Examples
    --------
    >>> compressibility_ratio(1.6e9, 2.2e9)
    0.7272727272727273

    """
    return bulk_modulus_oil / bulk_modulus_liquid


def laminar_leakage(dp_i: Real, mu: float, q: float, c_ol: float, b_h: float) -> Real:
    r"""
    Compute the laminar leakage with oil, eq. (20).

    .. math:: Q_{l,O} = \frac{C_{ol,O}}{\mu_o}\,\frac{q_t}{2\pi}\,\Delta p_{i,O}
        \,(1 + B_h\,\Delta p_{i,O})^3

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    mu : float
        Dynamic viscosity of the oil mu_o, [Pa*s]
    q : float
        Displacement q_t/(2 pi), [m^3/rad]
    c_ol : float
        C_ol,O, [-]
    b_h : float
        B_h, relative change of the clearance with pressure, [1/Pa]

    Returns
    -------
    float or ndarray
        Q_l,O, [m^3/s]

    """
    return c_ol / mu * q * dp_i * (1.0 + b_h * dp_i) ** 3


def turbulent_leakage(dp_i: Real, rho: float, q: float, c_ot: float) -> Real:
    r"""
    Compute the turbulent leakage with oil, eq. (21).

    .. math:: Q_{t,O} = C_{ot,O}\,\sqrt{\frac{2\,\Delta p_{i,O}}{\rho_o}}
        \,\sqrt[3]{\left(\frac{q_t}{2\pi}\right)^2}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    rho : float
        Density of the oil rho_o, [kg/m^3]
    q : float
        Displacement q_t/(2 pi), [m^3/rad]
    c_ot : float
        C_ot,O, [-]

    Returns
    -------
    float or ndarray
        Q_t,O, [m^3/s]

    """
    out: Real = c_ot * (2.0 * dp_i / rho) ** 0.5 * q ** (2.0 / 3.0)
    return out


def leakage_ratio_turbulent(dp_i: Real, mu_oil: float, mu_liquid: float) -> Real:
    r"""
    Compute k_s for not fully developed turbulent flow of the low-viscosity liquid, eq. (22).

    .. math:: k_s = 0.9\,\frac{\mu_o}{\mu_E}\,\Delta p_{i,O}^{-3/7}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, > 0, [Pa]
    mu_oil, mu_liquid : float
        Dynamic viscosities of the oil mu_o and of the low-viscosity liquid mu_E, [Pa*s]

    Returns
    -------
    float or ndarray
        k_s, [-]

    Notes
    -----
    The paper gives no unit for Delta p_i here; MPa, the unit of every other
    empirical fit of the paper, makes eqs. (22) and (23) meet at 0.78 MPa
    (:data:`LAMINAR_TRANSITION`), where the flow in the clearances of a
    water motor turns from laminar to turbulent. In Pa water would leak less
    than laminar flow at any drop above 0.8 Pa.

    Examples
    --------
    >>> round(leakage_ratio_turbulent(10e6, 35e-3, 0.85e-3), 2)
    13.81

    """
    out: Real = TURBULENT_FACTOR * mu_oil / mu_liquid * (dp_i / MPA) ** TURBULENT_EXPONENT
    return out


def leakage_ratio_laminar(mu_oil: float, mu_liquid: float) -> float:
    r"""
    Compute k_s for laminar flow of the low-viscosity liquid, eq. (23).

    .. math:: k_s = \frac{\mu_o}{\mu_E}

    Parameters
    ----------
    mu_oil, mu_liquid : float
        Dynamic viscosities of the oil mu_o and of the low-viscosity liquid mu_E, [Pa*s]

    Returns
    -------
    float
        k_s, [-]

    """
    return mu_oil / mu_liquid


def leakage_ratio(dp_i: Real, mu_oil: float, mu_liquid: float) -> Real:
    r"""
    Compute k_s, laminar (eq. 23) below the transition drop and turbulent (eq. 22) above.

    .. math:: k_s = \min\left(0.9\,\frac{\mu_o}{\mu_E}\,\Delta p_{i,O}^{-3/7},
        \ \frac{\mu_o}{\mu_E}\right)

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, >= 0, [Pa]
    mu_oil, mu_liquid : float
        Dynamic viscosities of the oil mu_o and of the low-viscosity liquid mu_E, [Pa*s]

    Returns
    -------
    float or ndarray
        k_s, eqs. (22)-(23), continuous at :data:`LAMINAR_TRANSITION`, [-]

    """
    return leakage_ratio_turbulent(maximum(dp_i, LAMINAR_TRANSITION), mu_oil, mu_liquid)


def external_leakage_oil(p_2: Real, mu: float, q: float, c_ex: float) -> Real:
    r"""
    Compute the external leakage with oil, eq. (24).

    .. math:: Q_{ex,O} = \frac{C_{ex,O}}{\mu_o}\,\frac{q_t}{2\pi}\,p_{2,O}

    Parameters
    ----------
    p_2 : float or ndarray
        Pressure driving the leak (outflow port or case, gauge), [Pa]
    mu : float
        Dynamic viscosity of the oil mu_o, [Pa*s]
    q : float
        Displacement q_t/(2 pi), [m^3/rad]
    c_ex : float
        C_ex,O, [-]

    Returns
    -------
    float or ndarray
        Q_ex,O, [m^3/s]

    """
    return c_ex / mu * q * p_2


def chamber_pressure_drop_low_viscosity(dp: Real, dp_ich_oil: Real, k_h: Real) -> Real:
    r"""
    Compute the pressure drop in the working chambers with a low-viscosity liquid, eq. (26).

    .. math:: \Delta p_{i,E} = \Delta p - \underbrace{k_H\,\Delta p_{ich,O}}_{\Delta p_{ich,E}}

    Parameters
    ----------
    dp : float or ndarray
        Pressure drop between the ports, [Pa]
    dp_ich_oil : float or ndarray
        Delta p_ich,O of eq. (27), [Pa]
    k_h : float or ndarray
        k_H of eq. (28), [-]

    Returns
    -------
    float or ndarray
        Delta p_i,E, [Pa]

    """
    return dp - k_h * dp_ich_oil


def channel_pressure_drop_oil(omega: Real, rho: float, q: float, c_ich: float) -> Real:
    r"""
    Compute the pressure drop in the internal channels with oil, eq. (27).

    .. math:: \Delta p_{ich,O} = C_{ich,O}\,\rho_o\,\omega^2
        \,\sqrt[3]{\left(\frac{q_t}{2\pi}\right)^2}

    Parameters
    ----------
    omega : float or ndarray
        Speed of the flow through the channels, [rad/s]
    rho : float
        Density of the liquid, [kg/m^3]
    q : float
        Displacement q_t/(2 pi), [m^3/rad]
    c_ich : float
        C_ich,O, [-]

    Returns
    -------
    float or ndarray
        Delta p_ich,O with oil, [Pa]

    Notes
    -----
    The family evaluates it at omega = Q/q, the speed of the flow Q that
    passes the channels: that is how eq. (28) scales it to another liquid
    (by the ratio of the flows), and it keeps the channel drop a function of
    the flow, as in eqs. (34)-(35) of the paper's own model.

    """
    out: Real = c_ich * rho * omega * omega * q ** (2.0 / 3.0)
    return out


def channel_ratio(rho_liquid: float, rho_oil: float, flow_liquid: Real, flow_oil: Real) -> Real:
    r"""
    Compute k_H, the channel drop of the low-viscosity liquid against the oil's, eq. (28).

    .. math:: k_H = \frac{\rho_E}{\rho_o}\left(\frac{Q_E}{Q_O}\right)^2

    Parameters
    ----------
    rho_liquid : float
        Density of the low-viscosity liquid rho_E, [kg/m^3]
    rho_oil : float
        Density of the oil rho_o, [kg/m^3]
    flow_liquid : float or ndarray
        Flow of the low-viscosity liquid Q_E, [m^3/s]
    flow_oil : float or ndarray
        Flow of the oil Q_O, [m^3/s]

    Returns
    -------
    float or ndarray
        k_H, [-]

    """
    return rho_liquid / rho_oil * (flow_liquid / flow_oil) ** 2
