# SPDX-License-Identifier: Apache-2.0
"""The forward map Q(n, dp): eq. (36), with eqs. (34)-(35) solved together for a port drop."""

from __future__ import annotations

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.batch import Chunk, mask_invalid, run
from satmotor_ros.model.composition import Equations
from satmotor_ros.model.inverse import RTOL
from satmotor_ros.model.results import OperatingPoints
from satmotor_ros.model.screening import (At, check_floor, check_limit, check_solution,
                                          Errors, flag_extrapolated, FLOW_ATOL, prepare,
                                          Status)
from satmotor_ros.model.solve import solve_increasing
from satmotor_ros.model.speed import absorbency


def solve_flow(eqs: Equations, speed: FloatArray, dp: FloatArray,
               p_ex: FloatArray) -> tuple[FloatArray, np.ndarray]:
    """
    Solve eqs. (34)-(36) together for Q at given n and port dp (Newton, bracketed).

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
    converged : ndarray of bool
        What the solver reported.

    """
    law, geometry, d = eqs.law, eqs.geometry, eqs.derived
    dp_cap = np.minimum(dp, d.dp_limit)

    def residual(flow: FloatArray) -> tuple[FloatArray, FloatArray]:
        dp_i = np.maximum(dp_cap - eqs.channel_drop(flow), 0.0)
        q_lfg, q_c, q_ex = eqs.leakage(dp_i, p_ex)
        loss = law.loss(speed, dp_i)
        absorbed = absorbency(speed, loss + q_lfg + q_c + q_ex, geometry)
        d_loss = law.slopes(speed, dp_i, loss)[1]
        d_absorbed = np.where(dp_i > 0.0, (eqs.leakage_slope(dp_i, q_lfg, q_c) + d_loss)
                              * (2.0 * d.ch_a * flow + d.ch_b), 0.0)
        return flow - absorbed, 1.0 + d_absorbed

    # The flow absorbed falls as the flow rises (more channel drop, less chamber drop): the
    # flow without any channel drop is an upper bound, q_t n a lower one.
    q_lfg, q_c, q_ex = eqs.leakage(dp_cap, p_ex)
    upper = absorbency(speed, law.loss(speed, dp_cap) + q_lfg + q_c + q_ex, geometry)
    return solve_increasing(residual, d.qt * speed, upper, upper, xtol=0.01 * FLOW_ATOL,
                            rtol=RTOL)


def absorbency_map(eqs: Equations, speed: object, dp_name: str, dp_value: object,
                   p_ex: object, errors: Errors) -> OperatingPoints:
    """
    Compute Q(n, dp) over a batch; see :meth:`MotorModel.absorbency`.

    Parameters
    ----------
    eqs : Equations
        The model's equations, [-]
    speed : float or array_like
        Shaft speed, [rad/s]
    dp_name : {'dp', 'dp_i'}
        Which pressure drop is given, [-]
    dp_value : float or array_like
        The pressure drop, [Pa]
    p_ex : float or array_like
        Pressure driving the external leakage, [Pa]
    errors : {'raise', 'mask'}
        What to do with a bad element, [-]

    Returns
    -------
    OperatingPoints
        The result.

    """
    arrays, status = prepare(
        {'speed': (speed, 'rad/s'), dp_name: (dp_value, 'Pa'), 'p_ex': (p_ex, 'Pa')}, errors)
    port = dp_name == 'dp'
    given = {'speed': arrays[0], 'dp': arrays[1]} if port else {'speed': arrays[0]}
    d = eqs.derived

    def core(n: FloatArray, dpv: FloatArray, pex: FloatArray, status: Status,
             at: At) -> Chunk:
        if port:
            root, converged = solve_flow(eqs, n, dpv, pex)
            chamber = eqs.chamber_drop(dpv, root, status)
        else:
            chamber = dpv
        chamber = check_limit(chamber, d.dp_limit, (dp_name, dpv), status, errors, at)
        check_floor(n, eqs.law, chamber, status, errors, at)
        q_lfg, q_c, q_ex = eqs.leakage(chamber, pex)
        losses = eqs.breakdown(n, chamber, q_lfg, q_c, q_ex, q_lfg + q_c + q_ex)
        flow = absorbency(n, losses['total'], eqs.geometry)
        if port:
            check_solution(flow, root, converged, flow == flow, status, errors,
                           ('speed', 'rad/s', n, at), 'eqs. (34)-(36) for the flow')
        flag_extrapolated(d, n, chamber, status)
        fields_ = {'flow': flow, 'dp_i': chamber, **losses}
        if not port:
            fields_['dp'] = chamber + eqs.channel_drop(flow)
        return mask_invalid(fields_, status)

    return run(core, arrays, status, given, port, eqs.geometry)
