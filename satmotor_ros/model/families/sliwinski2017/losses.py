# SPDX-License-Identifier: Apache-2.0
"""
The components of the volumetric losses, one function per equation of [1]_.

Each equation is one function of its variables and of constants that depend only
on the motor, the coefficient set and the liquid; those constants come from the
``*_coefficients`` functions beside it, computed once per model (see
:mod:`.derived`). Every equation function is plain arithmetic: correct on a
Python float (the few-microsecond single point) and on numpy arrays (the batch
maps), broadcasting like numpy. Inputs are assumed valid (finite, chamber
pressure drop >= 0, speed >= 0): screening belongs to
:class:`satmotor_ros.model.MotorModel`.

References
----------
.. [1] P. Śliwiński, "The influence of water and mineral oil on volumetric
   losses in a hydraulic motor", Polish Maritime Research 24 (2017).

"""

from __future__ import annotations

import math
from typing import Protocol

from satmotor_ros.model._numeric import log, maximum
from satmotor_ros.model._typing import Real
from satmotor_ros.model.coefficients import Liquid, LossCoefficients, MotorGeometry
from satmotor_ros.model.units import CM3_PER_MIN, CM3_PER_REV, LPM, MPA, RPM


class ChannelCoefficients(Protocol):
    """The coefficients of eq. (35), as every family that uses it names them."""

    @property
    def c_t(self) -> float:
        """Turbulent channel coefficient, Q in l/min -> Pa."""

    @property
    def c_l(self) -> float:
        """Laminar channel coefficient, mu in mPa*s, Q in l/min -> Pa."""


EMPIRICAL_DP_FLOOR = 1.0 * MPA
"""Chamber drop below which eq. (39) holds its value at this drop, [Pa] (see eq. 39)."""


def clearance_height(dp_i: Real, h0: float, compliance: float) -> Real:
    r"""
    Compute the equivalent axial clearance under pressure, eq. (2).

    .. math:: h = \frac{h_R + h_S}{2} - (D_C H + D_K)\,\Delta p_i = h_0 - s\,\Delta p_i

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    h0 : float
        Unloaded clearance h_0 from :func:`clearance_coefficients`, [m]
    compliance : float
        Compliance s from :func:`clearance_coefficients`, [m/Pa]

    Returns
    -------
    float or ndarray
        Equivalent clearance h, [m]

    Notes
    -----
    Fitted with H in mm, h in um and dp_i in MPa; h(0) = 5.865 um and
    h(25 MPa) = 5.140 um for the SM-0,75/25.

    Examples
    --------
    >>> from satmotor_ros.model.io.config import load_motor
    >>> spec = load_motor()
    >>> h0, s = clearance_coefficients(spec.geometry, spec.sets['oil'].coefficients)
    >>> round(clearance_height(25e6, h0, s) * 1e6, 3)
    5.14

    """
    return h0 - compliance * dp_i


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


def flat_clearance_leakage(dp_i: Real, h: Real, k_lfg: float,
                           e_lfg: float) -> Real:
    r"""
    Compute the leakage in the flat axial clearances Q_Lfg, eq. (1).

    .. math::
        Q_{Lfg} = A_1 m^{\frac{1-\beta}{2-\beta}} \nu^{-\frac{\beta}{2-\beta}}
        \left(\frac{2 h^3}{K A_2 \rho}\right)^{\frac{1}{2-\beta}}
        \Delta p_i^{\frac{1}{2-\beta}} = k\,(h^3 \Delta p_i)^e

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    h : float or ndarray
        Equivalent axial clearance from eq. (2), [m]
    k_lfg : float
        Prefactor k from :func:`flat_clearance_coefficients`, [m^3/s / (m^3 Pa)^e]
    e_lfg : float
        Exponent e = 1/(2 - beta), [-]

    Returns
    -------
    float or ndarray
        Leakage flow Q_Lfg, [m^3/s]

    Notes
    -----
    Fitted with m in mm, nu in cSt, h in um, rho in kg/m^3, dp_i in MPa and
    Q_Lfg in l/min; beta = 1 is laminar flow, beta -> 0 turbulent.

    """
    out: Real = k_lfg * (h * h * h * dp_i) ** e_lfg
    return out


def flat_clearance_coefficients(liquid: Liquid, geometry: MotorGeometry,
                                coef: LossCoefficients) -> tuple[float, float]:
    r"""
    Compute the constants of eq. (1): Q_Lfg = k * (h^3 dp_i)^e.

    .. math::
        k = A_1 m^{\frac{1-\beta}{2-\beta}} \nu^{-\frac{\beta}{2-\beta}}
        \left(\frac{2}{K A_2 \rho}\right)^{\frac{1}{2-\beta}},\quad
        e = \frac{1}{2-\beta}

    Parameters
    ----------
    liquid : Liquid
        The working liquid (nu, rho), [-]
    geometry : MotorGeometry
        Motor geometry (tooth module m), [-]
    coef : LossCoefficients
        Coefficient set (A_1, A_2, K, beta), [-]

    Returns
    -------
    prefactor : float
        k, for h in m and dp_i in Pa, [m^3/s / (m^3 Pa)^e]
    exponent : float
        e, [-]

    """
    nu, rho = liquid.kinematic_viscosity, liquid.density
    e = 1.0 / (2.0 - coef.beta)
    # h^3 [um^3] * dp_i [MPa] = h^3 [m^3] * dp_i [Pa] * 1e12; the 1e12 goes into the prefactor
    prefactor = (coef.a1 * (geometry.module * 1.0e3) ** ((1.0 - coef.beta) * e)
                 * (nu * 1.0e6) ** (-coef.beta * e)
                 * (2.0e12 / (coef.k * coef.a2 * rho)) ** e * LPM)
    return float(prefactor), e


def commutation_leakage(dp_i: Real, k_c: float, gamma: float) -> Real:
    r"""
    Compute the leakage in the commutation-unit clearances Q_C, eq. (5).

    .. math::
        Q_C = C_1 (D_o h_S)^{C_2}
        \left(\frac{1}{\rho \nu C_3}\right)^{\gamma} \Delta p_i^{\gamma}
        = k\,\Delta p_i^{\gamma}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    k_c : float
        Prefactor k from :func:`commutation_coefficient`, [m^3/s / Pa^gamma]
    gamma : float
        Exponent gamma, [-]

    Returns
    -------
    float or ndarray
        Leakage flow Q_C, [m^3/s]

    Notes
    -----
    Fitted with D_o in mm, h_S in um, nu in cSt, dp_i in MPa; the raw value
    is read as m^3/s. It stays below 0.012 l/min for the SM-0,75/25.

    """
    out: Real = k_c * dp_i ** gamma
    return out


def commutation_coefficient(liquid: Liquid, geometry: MotorGeometry,
                            coef: LossCoefficients) -> float:
    r"""
    Compute the prefactor of eq. (5): Q_C = k * dp_i^gamma.

    .. math:: k = C_1 (D_o h_S)^{C_2} \left(\frac{1}{\rho \nu C_3}\right)^{\gamma}

    Parameters
    ----------
    liquid : Liquid
        The working liquid (rho, nu), [-]
    geometry : MotorGeometry
        Motor geometry (D_o, h_S), [-]
    coef : LossCoefficients
        Coefficient set (C_1, C_2, C_3, gamma), [-]

    Returns
    -------
    float
        k, for dp_i in Pa, [m^3/s / Pa^gamma]

    """
    base = (geometry.commutation_diameter * 1.0e3) * (geometry.clearance_satellites * 1.0e6)
    mu_cst = liquid.density * liquid.kinematic_viscosity * 1.0e6
    return float(coef.c1 * base ** coef.c2 * (1.0 / (mu_cst * coef.c3)) ** coef.gamma
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
    return c * geometry.m2h * CM3_PER_MIN / (MPA * RPM)


def pressure_speed_loss(dp_i: Real, speed: Real, k: float) -> Real:
    r"""
    Compute a loss proportional to pressure and speed, eqs. (11), (12) and (13).

    .. math:: \Delta Q_{fc},\ \Delta Q_{dch},\ \Delta Q_b = c\,m^2 H\,\Delta p_i\,n

    with c = C_fc*beta_l (compressibility, eq. 11), C_dch (deformation of the
    chambers, eq. 12) or C_b (tip clearance and backlash, eq. 13).

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n, [rad/s]
    k : float
        c m^2 H from :func:`pressure_speed_coefficient`, [m^3/(Pa*rad)]

    Returns
    -------
    float or ndarray
        The loss, [m^3/s]

    """
    return k * dp_i * speed


def inertia_loss(speed: Real, k_id: float) -> Real:
    r"""
    Compute the loss from satellite and liquid inertia Delta Q_id, eq. (14).

    .. math:: \Delta Q_{id} = C_{id}\,m^2 H\,n^{0.5}

    Parameters
    ----------
    speed : float or ndarray
        Shaft speed n, [rad/s]
    k_id : float
        C_id m^2 H from :func:`inertia_coefficient`, [m^3/s / (rad/s)^0.5]

    Returns
    -------
    float or ndarray
        Delta Q_id, [m^3/s]

    """
    out: Real = k_id * speed ** 0.5
    return out


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
    return c_id * geometry.m2h * CM3_PER_MIN / math.sqrt(RPM)


def displacement_change(dp_i: Real, speed: Real, k_p: float,
                        k_id: float) -> Real:
    r"""
    Compute the change of displacement per revolution Delta q, eq. (33).

    .. math:: \Delta q = \left(C\,\Delta p_i + \frac{C_{id}}{n^{0.5}}\right) m^2 H

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    speed : float or ndarray
        Shaft speed n > 0, [rad/s]
    k_p : float
        C m^2 H from :func:`pressure_speed_coefficient`, [m^3/(Pa*rad)]
    k_id : float
        C_id m^2 H from :func:`inertia_coefficient`, [m^3/s / (rad/s)^0.5]

    Returns
    -------
    float or ndarray
        Delta q, [m^3/rad]; Delta Q_vl = Delta q * n, eq. (32).

    Examples
    --------
    >>> from satmotor_ros.model.io.config import load_motor
    >>> spec = load_motor()
    >>> coef = spec.sets['oil'].coefficients
    >>> k_p = pressure_speed_coefficient(coef.c, spec.geometry)
    >>> k_id = inertia_coefficient(coef.c_id, spec.geometry)
    >>> dq = displacement_change(2 * MPA, 100 * RPM, k_p, k_id)
    >>> round(dq * 2 * 3.141592653589793 * 1e6, 4)  # cm^3/rev
    2.0143

    """
    out: Real = k_p * dp_i + k_id / speed ** 0.5
    return out


def displacement_loss(dp_i: Real, speed: Real, k_p: float, k_id: float) -> Real:
    r"""
    Compute the speed-dependent losses Delta Q_vl = Delta q * n, eqs. (32)-(33).

    .. math:: \Delta Q_{vl} = \left(C\,\Delta p_i\,n + C_{id}\,n^{0.5}\right) m^2 H

    The sum of eqs. (11)-(14); unlike ``displacement_change * speed`` it is
    finite at n = 0.

    Parameters
    ----------
    dp_i : float or ndarray
        Chamber pressure drop, [Pa]
    speed : float or ndarray
        Shaft speed n, 0 included, [rad/s]
    k_p : float
        C m^2 H, the lumped pressure-speed coefficient, [m^3/(Pa*rad)]
    k_id : float
        C_id m^2 H, the inertia coefficient, [m^3/s / (rad/s)^0.5]

    Returns
    -------
    float or ndarray
        Delta Q_vl, [m^3/s]

    """
    return pressure_speed_loss(dp_i, speed, k_p) + inertia_loss(speed, k_id)


def displacement_change_empirical(dp_i: Real, speed: Real, c1: float,
                                  c2: float) -> Real:
    r"""
    Compute the empirical change of displacement Delta q, eq. (39).

    .. math:: \Delta q = \frac{C_1}{\sqrt{n}}\,\Delta p_i^{C_2/\sqrt{n}}

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, at least :data:`EMPIRICAL_DP_FLOOR`, [Pa]
    speed : float or ndarray
        Shaft speed n > 0, [rad/s]
    c1 : float
        C_1 of eq. (39), [cm^3/rev (rev/min)^0.5]
    c2 : float
        C_2 of eq. (39), [(rev/min)^0.5]

    Returns
    -------
    float or ndarray
        Delta q, [m^3/rad]; Delta Q_vl = Delta q * n, eq. (32).

    Notes
    -----
    Fitted with n in rpm, dp_i in MPa and Delta q in cm^3/rev. The paper
    allows it only for low load: it is nearly independent of dp_i and biased
    at high dp_i. For dp_i > 1 MPa its loss Delta q * n grows without bound
    as n -> 0, so it is used only above ``(C_2 ln dp_i)^2`` rpm
    (:func:`empirical_speed_floor`), where that loss is increasing in n.

    Below :data:`EMPIRICAL_DP_FLOOR` (1 MPa) the model takes dp_i as 1 MPa
    (:class:`~satmotor_ros.model.families.sliwinski2017.laws.EmpiricalLaw`), so that Delta q =
    C_1/sqrt(n) there. As printed, dp_i^(C_2/sqrt(n)) falls to 0^x = 0 at
    dp_i = 0 but only logarithmically slowly (it is still 0.9 at 1 Pa), so the
    law would jump at an unloaded motor and eqs. (34)-(36) would have no root
    near it. The paper fitted eq. (39) on 2-25 MPa; at 0 MPa the eq. (33)
    counterpart, C_id/sqrt(n), is pressure-independent as well.

    Examples
    --------
    >>> from satmotor_ros.model.io.config import load_motor
    >>> coef = load_motor().sets['oil'].coefficients
    >>> dq = displacement_change_empirical(10 * MPA, 1000 * RPM, coef.c1_39, coef.c2_39)
    >>> round(dq * 2 * 3.141592653589793 * 1e6, 4)  # cm^3/rev
    0.3727

    """
    out: Real = displacement_change_at_root(dp_i, 1.0 / (speed / RPM) ** 0.5, c1, c2)
    return out


def displacement_change_at_root(dp_i: Real, inv_sqrt_n: Real, c1: float, c2: float) -> Real:
    """
    Compute Delta q of eq. (39) from 1/sqrt(n), n in rpm: :func:`displacement_change_empirical`.

    A solve at fixed n computes the root once and calls this (see that function's notes).

    Parameters
    ----------
    dp_i : float or ndarray
        Chamber pressure drop, not below the 1 MPa floor, [Pa]
    inv_sqrt_n : float or ndarray
        1/sqrt(n) with n in rev/min, [(rev/min)^-0.5]
    c1 : float
        Eq. (39)'s factor C_1, [cm^3/rev (rev/min)^0.5]
    c2 : float
        Eq. (39)'s exponent factor C_2, [(rev/min)^0.5]

    Returns
    -------
    float or ndarray
        Delta q, [m^3/rad]

    """
    out: Real = c1 * inv_sqrt_n * (dp_i / MPA) ** (c2 * inv_sqrt_n) * CM3_PER_REV
    return out


def empirical_drop(dp_i: Real) -> Real:
    """
    Return the chamber drop eq. (39) is evaluated at: dp_i, not below :data:`EMPIRICAL_DP_FLOOR`.

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]

    Returns
    -------
    float or ndarray
        max(dp_i, 1 MPa), [Pa]

    """
    return maximum(dp_i, EMPIRICAL_DP_FLOOR)


def empirical_speed_floor(dp_i: Real, c2: float) -> Real:
    r"""
    Compute the lowest speed at which eq. (39) is used.

    .. math:: n_{min} = (C_2 \ln \Delta p_i)^2 \quad (\Delta p_i > 1\,\mathrm{MPa})

    Below it the loss of eq. (39) falls with speed and diverges as n -> 0.

    Parameters
    ----------
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    c2 : float
        C_2 of eq. (39), [(rev/min)^0.5]

    Returns
    -------
    float or ndarray
        n_min, [rad/s]; 0 for dp_i <= 1 MPa.

    """
    root = c2 * log(empirical_drop(dp_i) / MPA)
    return root * root * RPM


def external_leakage(p_ex: Real, k_ex: float) -> Real:
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
    k_ex : float
        Lumped coefficient k_ex (``coefficients.external_leakage``), [m^3/(s*Pa)]

    Returns
    -------
    float or ndarray
        External leakage Q_ex, [m^3/s]

    """
    return k_ex * p_ex


def channel_pressure_drop(flow: Real, turbulent: float, laminar: float) -> Real:
    r"""
    Compute the pressure drop in the internal channels Delta p_ich, eq. (35).

    .. math:: \Delta p_{ich} = C_t\,\rho\,Q^2 + C_l\,\mu\,Q = (a\,Q + b)\,Q

    Parameters
    ----------
    flow : float or ndarray
        Flow through the motor (absorbency) Q, [m^3/s]
    turbulent : float
        a = C_t rho from :func:`channel_coefficients`, [Pa/(m^3/s)^2]
    laminar : float
        b = C_l mu from :func:`channel_coefficients`, [Pa/(m^3/s)]

    Returns
    -------
    float or ndarray
        Delta p_ich, [Pa]

    Notes
    -----
    Fitted with Q in l/min and mu in mPa*s; oil gives 0.03, 0.44 and
    1.76 MPa at 5, 20 and 40 l/min.

    Examples
    --------
    >>> from satmotor_ros.model.io.config import load_motor
    >>> oil = load_motor().sets['oil']
    >>> a, b = channel_coefficients(oil.liquid, oil.coefficients)
    >>> round(channel_pressure_drop(40 * LPM, a, b) / 1e6, 2)
    1.76

    """
    return (turbulent * flow + laminar) * flow


def channel_coefficients(liquid: Liquid, coef: ChannelCoefficients) -> tuple[float, float]:
    r"""
    Compute the constants of eq. (35): Delta p_ich = (a Q + b) Q.

    .. math:: a = C_t\,\rho,\quad b = C_l\,\mu

    Parameters
    ----------
    liquid : Liquid
        The liquid through the channels (rho, mu = rho nu), [-]
    coef : LossCoefficients or another family's coefficients
        Coefficient set (C_t, C_l), [-]

    Returns
    -------
    turbulent : float
        a, for Q in m^3/s, [Pa/(m^3/s)^2]
    laminar : float
        b, for Q in m^3/s, [Pa/(m^3/s)]

    """
    rho = liquid.density
    mu_mpas = rho * liquid.kinematic_viscosity * 1.0e3
    return float((coef.c_t / (LPM * LPM)) * rho), float((coef.c_l / LPM) * mu_mpas)


def chamber_pressure_drop(dp: Real, dp_ich: Real) -> Real:
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
    float or ndarray
        Delta p_i, [Pa]

    """
    return dp - dp_ich
