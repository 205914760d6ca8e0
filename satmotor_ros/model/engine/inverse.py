# SPDX-License-Identifier: Apache-2.0
"""The inverse map n(Q, dp): eq. (40) in closed form, or eq. (36) solved for n."""

from __future__ import annotations

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.coefficients import MotorGeometry
from satmotor_ros.model.engine.batch import (Chunk, clip_chamber_drop, components, map_inputs,
                                             mask_invalid, run)
from satmotor_ros.model.engine.screening import (add_flags, At, CHECK, check_limit, check_solution,
                                                 Errors, flag_extrapolated, FLOW_ATOL, SPEED_SOLVE,
                                                 stalled, Status)
from satmotor_ros.model.engine.solve import solve_increasing
from satmotor_ros.model.families.sliwinski2017.composition import Equations
from satmotor_ros.model.families.sliwinski2017.speed import absorbency
from satmotor_ros.model.results import OperatingPoints, PointStatus


def solve_speed(eqs: Equations, flow: FloatArray, dp_i: FloatArray, leak: FloatArray,
                status: Status) -> tuple[FloatArray, Status]:
    """
    Solve eq. (36) for n at given flow and dp_i (the solver of :mod:`.solve`).

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
    solved : ndarray of uint8
        The solver's status per point.

    """
    lo, hi, residual = eqs.speed_problem(flow, dp_i, leak)
    with np.errstate(divide='ignore', invalid='ignore'):  # the stalled elements sit at n = 0
        moving = hi > lo
        if eqs.law.has_floor:  # the flow must exceed what eq. (36) takes at the floor
            moving &= (lo <= 0.0) | (residual(np.where(lo > 0.0, lo, hi))[0] < 0.0)
        status |= (~moving & (hi > 0.0) & (lo > 0.0)) * np.uint8(PointStatus.NO_ROOT)
        lo, hi = np.where(moving, lo, 0.0), np.where(moving, hi, 0.0)
        n, solved = solve_increasing(residual, lo, hi, hi, SPEED_SOLVE, CHECK * flow + FLOW_ATOL)
    return np.where(moving, n, 0.0), solved


def speed_map(eqs: Equations, geometry: MotorGeometry, flow: object, dp_name: str,
              dp_value: object, p_ex: object, errors: Errors,
              closed_form: bool) -> OperatingPoints:
    """Compute n(Q, dp) over a batch: :meth:`MotorModel.speed` without effects."""
    arrays, status, port, given = map_inputs(('flow', flow, 'm^3/s'), dp_name, dp_value,
                                             p_ex, errors)
    d = eqs.derived

    def core(q: FloatArray, dpv: FloatArray, pex: FloatArray, status: Status,
             at: At) -> Chunk:
        chamber = clip_chamber_drop(eqs.chamber_drop(dpv, q), status) if port else dpv
        chamber = check_limit(chamber, d.dp_limit, (dp_name, dpv), status, errors, at)
        q_lfg, q_c, q_ex = eqs.leakage(chamber, pex)
        leak = q_lfg + q_c + q_ex
        if closed_form:
            n = eqs.closed_form_speed(q, chamber, leak)
        else:
            n, solved = solve_speed(eqs, q, chamber, leak, status)
        add_flags(status, stalled(n))  # not a min() == 0 guard: a NaN elsewhere would hide it
        losses, total = components(eqs, n, chamber, q_lfg, q_c, q_ex, leak)
        if not closed_form:
            absorbed = absorbency(n, total, d.qt)
            check_solution(absorbed, q, solved, n > 0.0, status, errors,
                           ('flow', 'm^3/s', q, at), f'eq. (36) with eq. ({eqs.law.name[2:]})')
        flag_extrapolated(d, n, chamber, status)
        fields_ = {'speed': n, 'dp_i': chamber, **losses}
        if not port:
            fields_['dp'] = chamber + eqs.channel_drop(q)
        return mask_invalid(fields_, status)

    return run(core, arrays, status, given, not closed_form, geometry)
