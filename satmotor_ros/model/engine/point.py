# SPDX-License-Identifier: Apache-2.0
"""
One operating point on Python floats: the model at a few microseconds a call.

The array maps of :class:`~satmotor_ros.model.MotorModel` pay numpy's fixed
cost per call (tens of microseconds), which a 1 kHz plant cannot afford. This
module evaluates one point with the very equation functions, composed by
:class:`~.sliwinski2017.composition.Equations`, and the scalar form of the
solver the array maps use; only the screening and the status flags are written
for floats here.
"""

from __future__ import annotations

import math

import numpy as np  # noqa: F401 (maximum's, inlined)

from satmotor_ros.model._inline import inline_on_floats
from satmotor_ros.model._numeric import maximum
from satmotor_ros.model.engine.screening import (below_floor, beyond_limit, CEILINGS,
                                                 channel_limited, CHECK, FLOW_ATOL, FLOW_SOLVE,
                                                 holds, input_flags, outside_range, SPEED_SOLVE,
                                                 stalled)
from satmotor_ros.model.engine.solve import solve_increasing_scalar
from satmotor_ros.model.errors import InvalidInputError
from satmotor_ros.model.families.sliwinski2017.composition import Equations
from satmotor_ros.model.families.sliwinski2017.speed import absorbency
from satmotor_ros.model.results import Point, PointStatus

_BEYOND_LIMIT = int(PointStatus.BEYOND_LIMIT)
_NO_ROOT = int(PointStatus.NO_ROOT)
_INF = math.inf
_FLOW_MAX, _SPEED_MAX, _DP_MAX = CEILINGS['m^3/s'], CEILINGS['rad/s'], CEILINGS['Pa']
_NAN = math.nan
_new_point = tuple.__new__


def invalid_point(status: int) -> Point:
    """Return the all-NaN point of an invalid element, as the array maps mask it."""
    return _new_point(Point, (_NAN,) * 12 + (status,))


def as_float(name: str, value: object) -> float:
    """
    Convert one scalar argument to a Python float, refusing what is not a number.

    Parameters
    ----------
    name : str
        Argument name, for the message, [-]
    value : object
        A real number (int, float, numpy scalar or 0-d array), [SI]

    Returns
    -------
    float
        The value.

    Raises
    ------
    InvalidInputError
        For a string, a bool, a sequence or anything else that is not one real number.

    """
    kind = getattr(getattr(value, 'dtype', None), 'kind', 'f')  # numpy scalars and arrays
    if isinstance(value, (str, bytes, bool)) or kind not in 'iuf':
        msg = f'{name} = {value!r}: expected a number, got {type(value).__name__}'
        raise InvalidInputError(msg)
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        msg = f'{name} = {value!r}: expected one number, got {type(value).__name__}'
        raise InvalidInputError(msg) from None


class PointEvaluator:
    """
    Evaluate single operating points of one model on Python floats.

    Parameters
    ----------
    eqs : Equations
        The model's equations, [-]

    """

    def __init__(self, eqs: Equations) -> None:
        """Keep the equations, and the parts each point reads, in its own attributes."""
        self.eqs = eqs
        self.d = d = eqs.derived
        self._qt, self._dp_limit, self._closed_form = d.qt, d.dp_limit, eqs.closed_form
        self._range = (d.dp_max, d.speed_max, d.dp_min, d.speed_min, d.liquid_extrapolated)
        self._leakage, self._breakdown = eqs.leakage, eqs.breakdown
        self._chamber_drop, self._channel_drop = eqs.chamber_drop, eqs.channel_drop
        self._speed_problem, self._flow_problem = eqs.speed_problem, eqs.flow_problem
        self._closed_form_speed = eqs.closed_form_speed
        law = eqs.law
        self._max_floor, self._floor = law.max_floor, law.floor

    @inline_on_floats
    def _point(self, flow: float | None, speed: float, dp: float | None, dp_i: float,
               q_lfg: float, q_c: float, q_ex: float, status: int) -> Point:
        """
        Compose the loss breakdown of eq. (31) and the status into a :class:`Point`.

        A `flow` of None is the absorbency of eq. (36); a `dp` of None is dp_i
        plus the channel drop of eq. (35) at that flow.
        """
        fc, dch, bl, ine, total = self._breakdown(speed, dp_i, q_lfg + q_c + q_ex)
        dp_max, speed_max, dp_min, speed_min, liquid_extrapolated = self._range
        status |= outside_range(speed, dp_i, dp_max, speed_max, dp_min, speed_min,
                                liquid_extrapolated)
        if flow is None:
            flow = absorbency(speed, total, self._qt)
        if dp is None:
            dp = dp_i + self._channel_drop(flow)
        if not (abs(flow) < _INF and abs(speed) < _INF and abs(total) < _INF and abs(dp) < _INF):
            return invalid_point(_BEYOND_LIMIT)  # an input so large that the result overflows
        return _new_point(Point, (flow, speed, dp, dp_i, q_lfg, q_c, fc, dch, bl, ine, q_ex,
                                  total, status))

    @inline_on_floats
    def speed(self, flow: float, dp: float, port: bool, p_ex: float) -> Point:
        """Compute n(Q, dp) at one point: :meth:`MotorModel.speed_point` without effects."""
        if not (0.0 <= flow <= _FLOW_MAX and 0.0 <= dp <= _DP_MAX and 0.0 <= p_ex <= _DP_MAX):
            return invalid_point(input_flags(flow, _FLOW_MAX) | input_flags(dp, _DP_MAX)
                                 | input_flags(p_ex, _DP_MAX))
        dp_i = self._chamber_drop(dp, flow) if port else dp
        status = channel_limited(dp_i)
        dp_i = maximum(dp_i, 0.0)
        if beyond_limit(dp_i, self._dp_limit):
            return invalid_point(_BEYOND_LIMIT)
        q_lfg, q_c, q_ex = self._leakage(dp_i, p_ex)
        if self._closed_form:
            speed = self._closed_form_speed(flow, dp_i, q_lfg + q_c + q_ex)
        else:
            speed, failed = self._solve_speed(flow, dp_i, q_lfg + q_c + q_ex)
            if failed:
                return invalid_point(failed)
        status |= stalled(speed)
        point = self._point(flow, speed, dp if port else None, dp_i, q_lfg, q_c, q_ex, status)
        if not self._closed_form and speed > 0.0 and not holds(
                absorbency(speed, point.total, self._qt), flow):
            return invalid_point(_NO_ROOT)
        return point

    def _solve_speed(self, flow: float, dp_i: float, leak: float) -> tuple[float, int]:
        """Solve eq. (36) for n at given flow and dp_i; return n and a status flag."""
        lo, hi, residual = self._speed_problem(flow, dp_i, leak)
        if not hi > lo:
            return 0.0, (_NO_ROOT if hi > 0.0 and lo > 0.0 else 0)
        if lo > 0.0 and not residual(lo)[0] < 0.0:
            return 0.0, _NO_ROOT
        return solve_increasing_scalar(residual, lo, hi, hi, SPEED_SOLVE, CHECK * flow + FLOW_ATOL)

    @inline_on_floats
    def absorbency(self, speed: float, dp: float, port: bool, p_ex: float,
                   flow_guess: float | None) -> Point:
        """Compute Q(n, dp) at one point: :meth:`MotorModel.absorbency_point` without effects."""
        if not (0.0 <= speed <= _SPEED_MAX and 0.0 <= dp <= _DP_MAX and 0.0 <= p_ex <= _DP_MAX):
            return invalid_point(input_flags(speed, _SPEED_MAX) | input_flags(dp, _DP_MAX)
                                 | input_flags(p_ex, _DP_MAX))
        root = speed  # not used without `port`
        if port:
            lo, upper, residual = self._flow_problem(speed, dp, p_ex)
            if flow_guess is not None and lo < flow_guess < _INF:
                hi, start = _INF, flow_guess
            else:  # no useful guess: start at the upper bound
                hi = start = upper()
            root, failed = solve_increasing_scalar(residual, lo, hi, start, FLOW_SOLVE, FLOW_ATOL,
                                                   True)
            if failed:
                return invalid_point(failed)
        dp_i = self._chamber_drop(dp, root) if port else dp
        status = channel_limited(dp_i)
        dp_i = maximum(dp_i, 0.0)
        if beyond_limit(dp_i, self._dp_limit):
            return invalid_point(_BEYOND_LIMIT)
        if speed < self._max_floor and below_floor(speed, self._floor(dp_i)):
            return invalid_point(_BEYOND_LIMIT)
        q_lfg, q_c, q_ex = self._leakage(dp_i, p_ex)
        point = self._point(None, speed, dp if port else None, dp_i, q_lfg, q_c, q_ex, status)
        if port and not holds(point.flow, root):
            return invalid_point(_NO_ROOT)
        return point
