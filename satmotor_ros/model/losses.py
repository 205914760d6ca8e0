# SPDX-License-Identifier: Apache-2.0
"""
The components of the volumetric losses, one function per equation of [1]_.

Every function takes and returns SI arrays (broadcasting like numpy) and
converts to the unit system the paper's coefficients were fitted in
internally. Inputs are assumed valid (finite, chamber pressure drop >= 0,
speed >= 0): screening belongs to :class:`satmotor_ros.model.MotorModel`.

References
----------
.. [1] P. Śliwiński, "The influence of water and mineral oil on volumetric
   losses in a hydraulic motor", Polish Maritime Research 24 (2017).

"""

from __future__ import annotations

import math

import numpy as np

from satmotor_ros.model._typing import ArrayLike, FloatArray
from satmotor_ros.model.coefficients import LossCoefficients, MotorGeometry
from satmotor_ros.model.units import LPM, MPA, RPM

_CM3_PER_MIN = 1.0e-6 / 60.0  # one cm^3/min in m^3/s
_CM3_PER_REV = 1.0e-6 / (2.0 * np.pi)  # one cm^3/rev in m^3/rad

EMPIRICAL_DP_FLOOR = 1.0 * MPA
"""Chamber drop below which eq. (39) holds its value at this drop, [Pa] (see eq. 39)."""


def clearance_height(dp_i: ArrayLike, geometry: MotorGeometry,
                     coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the equivalent axial clearance under pressure, eq. (2).

    .. math:: h = \frac{h_R + h_S}{2} - (D_C H + D_K)\,\Delta p_i

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    geometry : MotorGeometry
        Motor geometry (h_R, h_S, H), [-]
    coef : LossCoefficients
        Coefficient set (D_C, D_K), [-]

    Returns
    -------
    ndarray
        Equivalent clearance h, [m]

    Notes
    -----
    Fitted with H in mm, h in um and dp_i in MPa; h(0) = 5.865 um and
    h(25 MPa) = 5.140 um for the SM-0,75/25.

    Examples
    --------
    >>> from satmotor_ros.model.config import load_motor
    >>> spec = load_motor()
    >>> h = clearance_height(25e6, spec.geometry, spec.sets['oil'].coefficients)
    >>> round(float(h) * 1e6, 3)
    5.14

    """
    h0, slope = clearance_coefficients(geometry, coef)
    return h0 - slope * np.asarray(dp_i, dtype=float)


def clearance_coefficients(geometry: MotorGeometry,
                           coef: LossCoefficients) -> tuple[float, float]:
    r"""
    Compute the constants of eq. (2): h = h_0 - s * dp_i.

    .. math:: h_0 = \frac{h_R + h_S}{2},\quad s = D_C H + D_K

    Parameters
    ----------
    geometry : MotorGeometry
        Motor geometry (h_R, h_S, H), [-]
    coef : LossCoefficients
        Coefficient set (D_C, D_K), [-]

    Returns
    -------
    h0 : float
        Unloaded clearance h_0, [m]
    slope : float
        Compliance s, [m/Pa]

    """
    h0 = 0.5 * (geometry.clearance_rotor + geometry.clearance_satellites)
    slope = (coef.d_c * geometry.height * 1.0e3 + coef.d_k) * 1.0e-6 / MPA  # [m/Pa]
    return h0, slope


def flat_clearance_leakage(dp_i: ArrayLike, h: ArrayLike, nu: ArrayLike, rho: ArrayLike,
                           geometry: MotorGeometry, coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the leakage in the flat axial clearances Q_Lfg, eq. (1).

    .. math::
        Q_{Lfg} = A_1 m^{\frac{1-\beta}{2-\beta}} \nu^{-\frac{\beta}{2-\beta}}
        \left(\frac{2 h^3}{K A_2 \rho}\right)^{\frac{1}{2-\beta}}
        \Delta p_i^{\frac{1}{2-\beta}}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    h : float or ndarray
        Equivalent axial clearance from eq. (2), [m]
    nu : float or ndarray
        Kinematic viscosity of the liquid, [m^2/s]
    rho : float or ndarray
        Density of the liquid, [kg/m^3]
    geometry : MotorGeometry
        Motor geometry (tooth module m), [-]
    coef : LossCoefficients
        Coefficient set (A_1, A_2, K, beta), [-]

    Returns
    -------
    ndarray
        Leakage flow Q_Lfg, [m^3/s]

    Notes
    -----
    Fitted with m in mm, nu in cSt, h in um, rho in kg/m^3, dp_i in MPa and
    Q_Lfg in l/min; beta = 1 is laminar flow, beta -> 0 turbulent.

    """
    prefactor, e = flat_clearance_coefficients(nu, rho, geometry, coef)
    h = np.asarray(h, dtype=float)
    return prefactor * (h * h * h * np.asarray(dp_i, dtype=float)) ** e


def flat_clearance_coefficients(nu: ArrayLike, rho: ArrayLike, geometry: MotorGeometry,
                                coef: LossCoefficients) -> tuple[FloatArray, float]:
    r"""
    Compute the constants of eq. (1): Q_Lfg = k * (h^3 dp_i)^e.

    .. math::
        k = A_1 m^{\frac{1-\beta}{2-\beta}} \nu^{-\frac{\beta}{2-\beta}}
        \left(\frac{2}{K A_2 \rho}\right)^{\frac{1}{2-\beta}},\quad
        e = \frac{1}{2-\beta}

    Parameters
    ----------
    nu : float or ndarray
        Kinematic viscosity of the liquid, [m^2/s]
    rho : float or ndarray
        Density of the liquid, [kg/m^3]
    geometry : MotorGeometry
        Motor geometry (tooth module m), [-]
    coef : LossCoefficients
        Coefficient set (A_1, A_2, K, beta), [-]

    Returns
    -------
    prefactor : ndarray
        k, for h in m and dp_i in Pa, [m^3/s / (m^3 Pa)^e]
    exponent : float
        e, [-]

    """
    e = 1.0 / (2.0 - coef.beta)
    nu_cst = np.asarray(nu, dtype=float) * 1.0e6
    # h^3 [um^3] * dp_i [MPa] = h^3 [m^3] * dp_i [Pa] * 1e12; the 1e12 goes into the prefactor
    prefactor = (coef.a1 * (geometry.module * 1.0e3) ** ((1.0 - coef.beta) * e)
                 * nu_cst ** (-coef.beta * e)
                 * (2.0e12 / (coef.k * coef.a2 * np.asarray(rho, dtype=float))) ** e * LPM)
    return prefactor, e


def commutation_leakage(dp_i: ArrayLike, nu: ArrayLike, rho: ArrayLike,
                        geometry: MotorGeometry, coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the leakage in the commutation-unit clearances Q_C, eq. (5).

    .. math::
        Q_C = C_1 (D_o h_S)^{C_2}
        \left(\frac{1}{\rho \nu C_3}\right)^{\gamma} \Delta p_i^{\gamma}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    nu : float or ndarray
        Kinematic viscosity of the liquid, [m^2/s]
    rho : float or ndarray
        Density of the liquid, [kg/m^3]
    geometry : MotorGeometry
        Motor geometry (D_o, h_S), [-]
    coef : LossCoefficients
        Coefficient set (C_1, C_2, C_3, gamma), [-]

    Returns
    -------
    ndarray
        Leakage flow Q_C, [m^3/s]

    Notes
    -----
    Fitted with D_o in mm, h_S in um, nu in cSt, dp_i in MPa; the raw value
    is read as m^3/s. It stays below 0.012 l/min for the SM-0,75/25.

    """
    return (commutation_coefficient(nu, rho, geometry, coef)
            * np.asarray(dp_i, dtype=float) ** coef.gamma)


def commutation_coefficient(nu: ArrayLike, rho: ArrayLike, geometry: MotorGeometry,
                            coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the prefactor of eq. (5): Q_C = k * dp_i^gamma.

    .. math:: k = C_1 (D_o h_S)^{C_2} \left(\frac{1}{\rho \nu C_3}\right)^{\gamma}

    Parameters
    ----------
    nu : float or ndarray
        Kinematic viscosity of the liquid, [m^2/s]
    rho : float or ndarray
        Density of the liquid, [kg/m^3]
    geometry : MotorGeometry
        Motor geometry (D_o, h_S), [-]
    coef : LossCoefficients
        Coefficient set (C_1, C_2, C_3, gamma), [-]

    Returns
    -------
    ndarray
        k, for dp_i in Pa, [m^3/s / Pa^gamma]

    """
    nu_cst = np.asarray(nu, dtype=float) * 1.0e6
    base = (geometry.commutation_diameter * 1.0e3) * (geometry.clearance_satellites * 1.0e6)
    return (coef.c1 * base ** coef.c2
            * (1.0 / (np.asarray(rho, dtype=float) * nu_cst * coef.c3)) ** coef.gamma
            * MPA ** -coef.gamma)


def compressibility_coefficient(bulk_modulus: float, geometry: MotorGeometry,
                                coef: LossCoefficients) -> float:
    r"""
    Compute the compressibility share C_fc*beta_l of the lumped C, eqs. (9)-(11).

    .. math:: C_{fc}\beta_l = C'_{fc}\,\frac{q_t}{K\,m^2 H}

    Eq. (9) gives Delta Q_fc = C'_fc beta_l q_t n dp_i with beta_l = 1/K; this
    restates it in the form of eq. (11) so that it adds to C of eq. (33).

    Parameters
    ----------
    bulk_modulus : float
        Bulk modulus K of the liquid, [Pa]
    geometry : MotorGeometry
        Motor geometry (q_t, m, H), [-]
    coef : LossCoefficients
        Coefficient set (C'_fc, the compressed share of q_t), [-]

    Returns
    -------
    float
        C_fc*beta_l, [1/(MPa*rev)]

    """
    return (coef.compressed_volume_fraction * geometry.displacement_cm3_per_rev
            / (bulk_modulus / MPA * geometry.m2h))


def pressure_speed_coefficient(c: float, geometry: MotorGeometry) -> float:
    r"""
    Compute k of the common form k * dp_i * n of eqs. (11)-(13).

    .. math:: k = c\,m^2 H

    Parameters
    ----------
    c : float
        One of C_fc*beta_l, C_dch, C_b or their sum C, [1/(MPa*rev)]
    geometry : MotorGeometry
        Motor geometry (m, H), [-]

    Returns
    -------
    float
        k, for dp_i in Pa and n in rad/s, [m^3/(Pa*rad)]

    """
    return c * geometry.m2h * _CM3_PER_MIN / (MPA * RPM)


def _pressure_speed_loss(c: float, dp_i: ArrayLike, speed: ArrayLike,
                         geometry: MotorGeometry) -> FloatArray:
    """Evaluate c * m^2 H * dp_i * n, the common form of eqs. (11)-(13), in m^3/s."""
    scale = pressure_speed_coefficient(c, geometry)
    return scale * np.asarray(dp_i, dtype=float) * np.asarray(speed, dtype=float)


def compressibility_loss(dp_i: ArrayLike, speed: ArrayLike, c_fc_beta: float,
                         geometry: MotorGeometry) -> FloatArray:
    r"""
    Compute the loss from liquid compressibility Delta Q_fc, eq. (11).

    .. math:: \Delta Q_{fc} = C_{fc}\,\beta_l\,m^2 H\,\Delta p_i\,n

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n, [rad/s]
    c_fc_beta : float
        C_fc*beta_l from :func:`compressibility_coefficient`, [1/(MPa*rev)]
    geometry : MotorGeometry
        Motor geometry (m, H), [-]

    Returns
    -------
    ndarray
        Delta Q_fc, [m^3/s]

    """
    return _pressure_speed_loss(c_fc_beta, dp_i, speed, geometry)


def deformation_loss(dp_i: ArrayLike, speed: ArrayLike, c_dch: float,
                     geometry: MotorGeometry) -> FloatArray:
    r"""
    Compute the loss from elastic deformation of the chambers Delta Q_dch, eq. (12).

    .. math:: \Delta Q_{dch} = C_{dch}\,m^2 H\,\Delta p_i\,n

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n, [rad/s]
    c_dch : float
        Deformation coefficient C_dch, [1/(MPa*rev)]
    geometry : MotorGeometry
        Motor geometry (m, H), [-]

    Returns
    -------
    ndarray
        Delta Q_dch, [m^3/s]

    """
    return _pressure_speed_loss(c_dch, dp_i, speed, geometry)


def backlash_loss(dp_i: ArrayLike, speed: ArrayLike, c_b: float,
                  geometry: MotorGeometry) -> FloatArray:
    r"""
    Compute the loss from tip clearance and backlash Delta Q_b, eq. (13).

    .. math:: \Delta Q_b = C_b\,m^2 H\,\Delta p_i\,n

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n, [rad/s]
    c_b : float
        Backlash coefficient C_b, [1/(MPa*rev)]
    geometry : MotorGeometry
        Motor geometry (m, H), [-]

    Returns
    -------
    ndarray
        Delta Q_b, [m^3/s]

    """
    return _pressure_speed_loss(c_b, dp_i, speed, geometry)


def inertia_loss(speed: ArrayLike, c_id: float, geometry: MotorGeometry) -> FloatArray:
    r"""
    Compute the loss from satellite and liquid inertia Delta Q_id, eq. (14).

    .. math:: \Delta Q_{id} = C_{id}\,m^2 H\,n^{0.5}

    Parameters
    ----------
    speed : float or ndarray
        Shaft speed n, [rad/s]
    c_id : float
        Inertia coefficient C_id, [1/(rev*min)^0.5]
    geometry : MotorGeometry
        Motor geometry (m, H), [-]

    Returns
    -------
    ndarray
        Delta Q_id, [m^3/s]

    """
    return inertia_coefficient(c_id, geometry) * np.sqrt(np.asarray(speed, dtype=float))


def inertia_coefficient(c_id: float, geometry: MotorGeometry) -> float:
    r"""
    Compute k of eq. (14) written as Delta Q_id = k * n^0.5.

    .. math:: k = C_{id}\,m^2 H

    Parameters
    ----------
    c_id : float
        Inertia coefficient C_id, [1/(rev*min)^0.5]
    geometry : MotorGeometry
        Motor geometry (m, H), [-]

    Returns
    -------
    float
        k, for n in rad/s, [m^3/s / (rad/s)^0.5]

    """
    return c_id * geometry.m2h * _CM3_PER_MIN / math.sqrt(RPM)


def displacement_change(dp_i: ArrayLike, speed: ArrayLike, c: float, c_id: float,
                        geometry: MotorGeometry) -> FloatArray:
    r"""
    Compute the change of displacement per revolution Delta q, eq. (33).

    .. math:: \Delta q = \left(C\,\Delta p_i + \frac{C_{id}}{n^{0.5}}\right) m^2 H

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n > 0, [rad/s]
    c : float
        Lumped coefficient C = C_fc*beta_l + C_dch + C_b, [1/(MPa*rev)]
    c_id : float
        Inertia coefficient C_id, [1/(rev*min)^0.5]
    geometry : MotorGeometry
        Motor geometry (m, H), [-]

    Returns
    -------
    ndarray
        Delta q, [m^3/rad]; Delta Q_vl = Delta q * n, eq. (32).

    Examples
    --------
    >>> from satmotor_ros.model.config import load_motor
    >>> from satmotor_ros.model.units import MPA, RPM
    >>> spec = load_motor()
    >>> coef = spec.sets['oil'].coefficients
    >>> dq = displacement_change(2 * MPA, 100 * RPM, coef.c, coef.c_id, spec.geometry)
    >>> round(float(dq) * 2 * 3.141592653589793 * 1e6, 4)  # cm^3/rev
    2.0143

    """
    n_rpm = np.asarray(speed, dtype=float) / RPM
    dq_cm3 = (c * np.asarray(dp_i, dtype=float) / MPA + c_id / np.sqrt(n_rpm)) * geometry.m2h
    return dq_cm3 * _CM3_PER_REV


def displacement_loss(dp_i: ArrayLike, speed: ArrayLike, c: float, c_id: float,
                      geometry: MotorGeometry) -> FloatArray:
    r"""
    Compute the speed-dependent losses Delta Q_vl = Delta q * n, eqs. (32)-(33).

    .. math:: \Delta Q_{vl} = \left(C\,\Delta p_i\,n + C_{id}\,n^{0.5}\right) m^2 H

    The sum of eqs. (11)-(14); unlike ``displacement_change * speed`` it is
    finite at n = 0.

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n, [rad/s]
    c : float
        Lumped coefficient C = C_fc*beta_l + C_dch + C_b, [1/(MPa*rev)]
    c_id : float
        Inertia coefficient C_id, [1/(rev*min)^0.5]
    geometry : MotorGeometry
        Motor geometry (m, H), [-]

    Returns
    -------
    ndarray
        Delta Q_vl, [m^3/s]

    """
    return _pressure_speed_loss(c, dp_i, speed, geometry) + inertia_loss(speed, c_id, geometry)


def displacement_change_empirical(dp_i: ArrayLike, speed: ArrayLike,
                                  coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the empirical change of displacement Delta q, eq. (39).

    .. math:: \Delta q = \frac{C_1}{\sqrt{n}}\,\Delta p_i^{C_2/\sqrt{n}}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n > 0, [rad/s]
    coef : LossCoefficients
        Coefficient set (C_1, C_2 of eq. 39), [-]

    Returns
    -------
    ndarray
        Delta q, [m^3/rad]

    Notes
    -----
    Fitted with n in rpm, dp_i in MPa and Delta q in cm^3/rev. The paper
    allows it only for low load: it is nearly independent of dp_i and biased
    at high dp_i. For dp_i > 1 MPa its loss Delta q * n grows without bound
    as n -> 0, so it is used only above ``(C_2 ln dp_i)^2`` rpm, where that
    loss is increasing in n.

    Below :data:`EMPIRICAL_DP_FLOOR` (1 MPa) dp_i is taken as 1 MPa, so that
    Delta q = C_1/sqrt(n) there. As printed, dp_i^(C_2/sqrt(n)) falls to 0^x = 0
    at dp_i = 0 but only logarithmically slowly (it is still 0.9 at 1 Pa), so
    the law would jump at an unloaded motor and eqs. (34)-(36) would have no
    root near it. The paper fitted eq. (39) on 2-25 MPa; at 0 MPa the eq. (33)
    counterpart, C_id/sqrt(n), is pressure-independent as well.

    """
    inv_sqrt_n = 1.0 / np.sqrt(np.asarray(speed, dtype=float) / RPM)
    dp_mpa = np.maximum(np.asarray(dp_i, dtype=float) / MPA, EMPIRICAL_DP_FLOOR / MPA)
    return coef.c1_39 * inv_sqrt_n * dp_mpa ** (coef.c2_39 * inv_sqrt_n) * _CM3_PER_REV


def displacement_loss_empirical(dp_i: ArrayLike, speed: ArrayLike,
                                coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the speed-dependent losses with the empirical Delta q, eqs. (32), (39).

    .. math:: \Delta Q_{vl} = C_1\,\sqrt{n}\,\Delta p_i^{C_2/\sqrt{n}}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n; 0 gives 0 (no revolution, no displacement loss), [rad/s]
    coef : LossCoefficients
        Coefficient set (C_1, C_2 of eq. 39), [-]

    Returns
    -------
    ndarray
        Delta Q_vl, [m^3/s]

    """
    speed = np.asarray(speed, dtype=float)
    moving = speed > 0.0
    safe = np.where(moving, speed, 1.0)
    return np.where(moving, displacement_change_empirical(dp_i, safe, coef) * safe, 0.0)


def empirical_speed_floor(dp_i: ArrayLike, coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the lowest speed at which eq. (39) is used.

    .. math:: n_{min} = (C_2 \ln \Delta p_i)^2 \quad (\Delta p_i > 1\,\mathrm{MPa})

    Below it the loss of eq. (39) falls with speed and diverges as n -> 0.

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    coef : LossCoefficients
        Coefficient set (C_2 of eq. 39), [-]

    Returns
    -------
    ndarray
        n_min, [rad/s]; 0 for dp_i <= 1 MPa.

    """
    dp_mpa = np.maximum(np.asarray(dp_i, dtype=float) / MPA, 1.0)
    return (coef.c2_39 * np.log(dp_mpa)) ** 2 * RPM


def external_leakage(p_ex: ArrayLike, coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the external leakage Q_ex, eq. (24) in lumped form.

    .. math:: Q_{ex} = k_{ex}\,p_{ex}

    Eq. (24) writes the coefficient as C_ex/mu * q_t/(2 pi) and the pressure
    as the outlet port's; here both are lumped so that a calibration can fit
    k_ex against whichever pressure drives the leak (outlet or case). The
    paper's motor has none (k_ex = 0).

    Parameters
    ----------
    p_ex : float or ndarray
        Pressure difference driving the external leak, [Pa]
    coef : LossCoefficients
        Coefficient set (external_leakage = k_ex), [-]

    Returns
    -------
    ndarray
        External leakage Q_ex, [m^3/s]

    """
    return coef.external_leakage * np.asarray(p_ex, dtype=float)


def channel_pressure_drop(flow: ArrayLike, nu: ArrayLike, rho: ArrayLike,
                          coef: LossCoefficients) -> FloatArray:
    r"""
    Compute the pressure drop in the internal channels Delta p_ich, eq. (35).

    .. math:: \Delta p_{ich} = C_t\,\rho\,Q^2 + C_l\,\mu\,Q

    Parameters
    ----------
    flow : float or ndarray
        Flow through the motor (absorbency) Q, [m^3/s]
    nu : float or ndarray
        Kinematic viscosity of the liquid, [m^2/s]
    rho : float or ndarray
        Density of the liquid, [kg/m^3]
    coef : LossCoefficients
        Coefficient set (C_t, C_l), [-]

    Returns
    -------
    ndarray
        Delta p_ich, [Pa]

    Notes
    -----
    Fitted with Q in l/min and mu in mPa*s; oil gives 0.03, 0.44 and
    1.76 MPa at 5, 20 and 40 l/min.

    Examples
    --------
    >>> from satmotor_ros.model.config import load_motor
    >>> spec = load_motor()
    >>> oil = spec.sets['oil']
    >>> dp = channel_pressure_drop(40 * LPM, oil.liquid.kinematic_viscosity,
    ...                            oil.liquid.density, oil.coefficients)
    >>> round(float(dp) / 1e6, 2)
    1.76

    """
    turbulent, laminar = channel_coefficients(nu, rho, coef)
    flow = np.asarray(flow, dtype=float)
    return (turbulent * flow + laminar) * flow


def channel_coefficients(nu: ArrayLike, rho: ArrayLike,
                         coef: LossCoefficients) -> tuple[FloatArray, FloatArray]:
    r"""
    Compute the constants of eq. (35): Delta p_ich = (a Q + b) Q.

    .. math:: a = C_t\,\rho,\quad b = C_l\,\mu

    Parameters
    ----------
    nu : float or ndarray
        Kinematic viscosity of the liquid, [m^2/s]
    rho : float or ndarray
        Density of the liquid, [kg/m^3]
    coef : LossCoefficients
        Coefficient set (C_t, C_l), [-]

    Returns
    -------
    turbulent : ndarray
        a, for Q in m^3/s, [Pa/(m^3/s)^2]
    laminar : ndarray
        b, for Q in m^3/s, [Pa/(m^3/s)]

    """
    rho = np.asarray(rho, dtype=float)
    mu_mpas = rho * np.asarray(nu, dtype=float) * 1.0e3
    return (coef.c_t / (LPM * LPM)) * rho, (coef.c_l / LPM) * mu_mpas


def chamber_pressure_drop(dp: ArrayLike, dp_ich: ArrayLike) -> FloatArray:
    r"""
    Compute the pressure drop in the working chambers Delta p_i, eq. (34).

    .. math:: \Delta p_i = \Delta p - \Delta p_{ich}

    Parameters
    ----------
    dp : float or ndarray
        Pressure drop between the motor ports, [Pa]
    dp_ich : float or ndarray
        Pressure drop in the internal channels, eq. (35), [Pa]

    Returns
    -------
    ndarray
        Delta p_i, [Pa]

    """
    return np.asarray(dp, dtype=float) - np.asarray(dp_ich, dtype=float)
