# SPDX-License-Identifier: Apache-2.0
"""The inverse map n(Q, dp): eq. (40) in closed form, or eq. (36) solved for n."""

from __future__ import annotations

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.batch import Chunk, mask_invalid, run
from satmotor_ros.model.composition import Equations
from satmotor_ros.model.results import OperatingPoints, PointStatus
from satmotor_ros.model.screening import (At, check_limit, check_solution, Errors,
                                          flag_extrapolated, prepare, Status)
from satmotor_ros.model.solve import solve_increasing
from satmotor_ros.model.speed import absorbency, effective_speed

RTOL = 1e-13
"""Relative tolerance of the iterative maps: Newton polishes well below it, bisection to it."""

ROOT_ATOL = 1e-20
"""Absolute resolution of sqrt(n) in the speed solve, [(rad/s)^0.5]; worth < 1e-23 m^3/s."""


def solve_speed(eqs: Equations, flow: FloatArray, dp_i: FloatArray, leak: FloatArray,
                status: Status) -> tuple[FloatArray, np.ndarray]:
    """
    Solve eq. (36) for n at given flow and dp_i (Newton in sqrt(n), bracketed).

    Where the law has no speed at or above its floor for a flow the leakage
    alone does not take (eq. 39 near stall), the point is flagged NO_ROOT.

    Parameters
    ----------
    eqs : Equations
        The model's equations, [-]
    flow : ndarray
        Flow into the motor, [m^3/s]
    dp_i : ndarray
        Chamber pressure drop, [Pa]
    leak : ndarray
        Q_Lfg + Q_C + Q_ex, [m^3/s]
    status : ndarray of uint8
        Flags, updated in place, [-]

    Returns
    -------
    speed : ndarray
        n; 0 where the shaft does not turn, [rad/s]
    converged : ndarray of bool
        What the solver reported.

    """
    law, geometry = eqs.law, eqs.geometry
    qt = geometry.displacement
    hi = np.maximum(flow - leak, 0.0) / qt  # all of it through the displacement
    lo = law.floor(dp_i)
    moving = (absorbency(lo, law.loss(lo, dp_i) + leak, geometry) < flow) & (hi > lo)
    status |= (~moving & (hi > 0.0) & (lo > 0.0)) * np.uint8(PointStatus.NO_ROOT)

    def residual(root: FloatArray) -> tuple[FloatArray, FloatArray]:
        # in s = sqrt(n): eq. (14)'s n^0.5 and eq. (39)'s sqrt(n) become linear at low
        # speed, where Newton steps in n would only halve
        n = root * root
        loss = law.loss(n, dp_i)
        with np.errstate(invalid='ignore'):  # inf * 0 at n = 0: bisected instead
            slope = (qt + law.slopes(n, dp_i, loss)[0]) * 2.0 * root
        return absorbency(n, loss + leak, geometry) - flow, slope

    lo, hi = np.sqrt(np.where(moving, lo, 0.0)), np.sqrt(np.where(moving, hi, 0.0))
    root, converged = solve_increasing(residual, lo, hi, hi, xtol=ROOT_ATOL, rtol=RTOL)
    return np.where(moving, root * root, 0.0), converged


def speed_map(eqs: Equations, flow: object, dp_name: str, dp_value: object, p_ex: object,
              errors: Errors, closed_form: bool) -> OperatingPoints:
    """
    Compute n(Q, dp) over a batch; see :meth:`MotorModel.speed`.

    Parameters
    ----------
    eqs : Equations
        The model's equations, [-]
    flow : float or array_like
        Flow into the motor, [m^3/s]
    dp_name : {'dp', 'dp_i'}
        Which pressure drop is given, [-]
    dp_value : float or array_like
        The pressure drop, [Pa]
    p_ex : float or array_like
        Pressure driving the external leakage, [Pa]
    errors : {'raise', 'mask'}
        What to do with a bad element, [-]
    closed_form : bool
        Use eq. (40) rather than solve eq. (36), [-]

    Returns
    -------
    OperatingPoints
        The result.

    """
    arrays, status = prepare(
        {'flow': (flow, 'm^3/s'), dp_name: (dp_value, 'Pa'), 'p_ex': (p_ex, 'Pa')}, errors)
    port = dp_name == 'dp'
    given = {'flow': arrays[0], 'dp': arrays[1]} if port else {'flow': arrays[0]}
    d = eqs.derived

    def core(q: FloatArray, dpv: FloatArray, pex: FloatArray, status: Status,
             at: At) -> Chunk:
        chamber = eqs.chamber_drop(dpv, q, status) if port else dpv
        chamber = check_limit(chamber, d.dp_limit, (dp_name, dpv), status, errors, at)
        q_lfg, q_c, q_ex = eqs.leakage(chamber, pex)
        leak = q_lfg + q_c + q_ex
        if closed_form:
            n = effective_speed(q, chamber, leak, d.c_lumped, eqs.coef.c_id, eqs.geometry)
        else:
            n, converged = solve_speed(eqs, q, chamber, leak, status)
        if n.size and n.min() == 0.0:
            status |= (n == 0.0) * np.uint8(PointStatus.STALLED)
        losses = eqs.breakdown(n, chamber, q_lfg, q_c, q_ex, leak)
        if not closed_form:
            absorbed = absorbency(n, losses['total'], eqs.geometry)
            check_solution(absorbed, q, converged, n > 0.0, status, errors,
                           ('flow', 'm^3/s', q, at), f'eq. (36) with eq. ({eqs.law.name[2:]})')
        flag_extrapolated(d, n, chamber, status)
        fields_ = {'speed': n, 'dp_i': chamber, **losses}
        if not port:
            fields_['dp'] = chamber + eqs.channel_drop(q)
        return mask_invalid(fields_, status)

    return run(core, arrays, status, given, not closed_form, eqs.geometry)
