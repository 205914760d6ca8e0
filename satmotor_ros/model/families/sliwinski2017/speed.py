# SPDX-License-Identifier: Apache-2.0
"""
Absorbency, effective speed and speed loss: eqs. (36), (40) and (41) of Śliwiński (2017).

Like :mod:`.losses`, each equation is one function of plain arithmetic, correct
on Python floats and on numpy arrays.
"""

from __future__ import annotations

import math

from satmotor_ros.model._numeric import maximum
from satmotor_ros.model._typing import Real
from satmotor_ros.model.coefficients import MotorGeometry
from satmotor_ros.model.results import speed_loss  # noqa: F401 (eq. 41 beside the others)
from satmotor_ros.model.units import CM3_PER_MIN, MPA, RPM


def absorbency(speed: Real, losses: Real, qt: float) -> Real:
    r"""
    Compute the flow a motor absorbs at a given speed, eq. (36).

    .. math:: Q = q_t\,n + Q_{vl},\quad
        Q_{vl} = \Delta q\,n + Q_{Lfg} + Q_C + Q_{ex}

    Parameters
    ----------
    speed : float or ndarray
        Shaft speed n, [rad/s]
    losses : float or ndarray
        Volumetric losses Q_vl of eq. (31), [m^3/s]
    qt : float
        Theoretical displacement q_t, [m^3/rad]

    Returns
    -------
    float or ndarray
        Absorbency Q, [m^3/s]

    """
    return qt * speed + losses


def effective_speed(flow: Real, dp_i: Real, leakage: Real, a0: float,
                    a1: float, scale: float, b: float) -> Real:
    r"""
    Compute the effective shaft speed from flow and pressure, eq. (40).

    .. math::
        n = \left(\frac{\sqrt{b^2 + 4ac} - b}{2a}\right)^2,\quad
        a = q_t + C\,\Delta p_i\,m^2 H,\ b = C_{id}\,m^2 H,\
        c = Q - Q_{Lfg} - Q_C - Q_{ex}

    evaluated in the folded, cancellation-free form
    ``n = (x / (sqrt((a_0 + a_1 dp_i) x + b^2) + b))^2`` with ``x = s c``.

    Parameters
    ----------
    flow : float or ndarray
        Flow into the motor Q, [m^3/s]
    dp_i : float or ndarray
        Pressure drop in the working chambers, [Pa]
    leakage : float or ndarray
        Speed-independent losses Q_Lfg + Q_C + Q_ex, [m^3/s]
    a0 : float
        Folded 2a at dp_i = 0 from :func:`effective_speed_coefficients`, [cm^3/rev (rad/s)^-0.5]
    a1 : float
        Its growth with dp_i, [cm^3/rev (rad/s)^-0.5 / Pa]
    scale : float
        s, from m^3/s to the folded unit of c, [(cm^3/min)/(m^3/s) (rad/s)^0.5]
    b : float
        C_id m^2 H, [cm^3/rev (rev/min)^0.5]

    Returns
    -------
    float or ndarray
        Effective speed n >= 0, [rad/s]; 0 where the leakage takes all the flow.

    """
    two_a = a0 + a1 * dp_i
    x = maximum(flow - leakage, 0.0) * scale
    if b == 0.0:
        return x / two_a
    root: Real = x / ((two_a * x + b * b) ** 0.5 + b)
    return root * root


def effective_speed_coefficients(c: float, c_id: float,
                                 geometry: MotorGeometry) -> tuple[float, float, float, float]:
    r"""
    Compute the constants of eq. (40) in its folded, cancellation-free form.

    .. math::
        n = \left(\frac{x}{\sqrt{(a_0 + a_1 \Delta p_i)\,x + b^2} + b}\right)^2,\quad
        x = s\,(Q - Q_{Lfg} - Q_C - Q_{ex})

    Parameters
    ----------
    c : float
        Lumped coefficient C of eq. (33), [1/(MPa*rev)]
    c_id : float
        Inertia coefficient C_id, [1/(rev*min)^0.5]
    geometry : MotorGeometry
        Motor geometry (q_t, m, H), [-]

    Returns
    -------
    tuple of float
        a_0, a_1, s and b, the arguments of :func:`effective_speed`.

    """
    # n [rad/s] = RPM (2c / (sqrt(b^2 + 4ac) + b))^2 with c in cm^3/min. With x = 2 sqrt(RPM) c
    # that is (x / (sqrt(b^2 + (2a / sqrt(RPM)) x) + b))^2: the constants fold into two scalars.
    m2h = geometry.m2h
    k = 2.0 / math.sqrt(RPM)
    return (k * geometry.displacement_cm3_per_rev, k * c * m2h / MPA,
            4.0 / (k * CM3_PER_MIN), c_id * m2h)
