# SPDX-License-Identifier: Apache-2.0
"""The forward map Q(n, dp): eq. (36), with eqs. (34)-(35) solved together for a port drop."""

from __future__ import annotations

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.coefficients import MotorGeometry
from satmotor_ros.model.engine.batch import (Chunk, clip_chamber_drop, components, map_inputs,
                                             mask_invalid, run)
from satmotor_ros.model.engine.screening import (At, check_floor, check_limit, check_solution,
                                                 Errors, flag_extrapolated, FLOW_ATOL, FLOW_SOLVE,
                                                 Status)
from satmotor_ros.model.engine.solve import solve_increasing
from satmotor_ros.model.families.sliwinski2017.composition import Equations
from satmotor_ros.model.families.sliwinski2017.speed import absorbency
from satmotor_ros.model.results import OperatingPoints


def solve_flow(eqs: Equations, speed: FloatArray, dp: FloatArray,
               p_ex: FloatArray) -> tuple[FloatArray, Status]:
    """
    Solve eqs. (34)-(36) together for Q at given n and port dp (the solver of :mod:`.solve`).

    Parameters
    ----------
    eqs : Equations
        The model's equations, [-]
    speed : ndarray
        Shaft speed, [rad/s]
    dp : ndarray
        Port pressure drop, [Pa]
    p_ex : ndarray
        Pressure driving the external leakage, [Pa]

    Returns
    -------
    flow : ndarray
        The root Q, [m^3/s]
    solved : ndarray of uint8
        The solver's status per point.

    """
    lo, upper, residual = eqs.flow_problem(speed, dp, p_ex)
    hi = upper()
    return solve_increasing(residual, lo, hi, hi, FLOW_SOLVE, FLOW_ATOL, mirror=True)


def absorbency_map(eqs: Equations, geometry: MotorGeometry, speed: object, dp_name: str,
                   dp_value: object, p_ex: object, errors: Errors) -> OperatingPoints:
    """Compute Q(n, dp) over a batch: :meth:`MotorModel.absorbency` without effects."""
    arrays, status, port, given = map_inputs(('speed', speed, 'rad/s'), dp_name, dp_value,
                                             p_ex, errors)
    d = eqs.derived

    def core(n: FloatArray, dpv: FloatArray, pex: FloatArray, status: Status,
             at: At) -> Chunk:
        if port:
            root, solved = solve_flow(eqs, n, dpv, pex)
            chamber = clip_chamber_drop(eqs.chamber_drop(dpv, root), status)
        else:
            chamber = dpv
        chamber = check_limit(chamber, d.dp_limit, (dp_name, dpv), status, errors, at)
        check_floor(n, eqs.law, chamber, status, errors, at)
        q_lfg, q_c, q_ex = eqs.leakage(chamber, pex)
        losses, total = components(eqs, n, chamber, q_lfg, q_c, q_ex, q_lfg + q_c + q_ex)
        flow = absorbency(n, total, d.qt)
        if port:
            check_solution(flow, root, solved, ~np.isnan(flow), status, errors,
                           ('speed', 'rad/s', n, at), 'eqs. (34)-(36) for the flow')
        flag_extrapolated(d, n, chamber, status)
        fields_ = {'flow': flow, 'dp_i': chamber, **losses}
        if not port:
            fields_['dp'] = chamber + eqs.channel_drop(flow)
        return mask_invalid(fields_, status)

    return run(core, arrays, status, given, port, geometry)
