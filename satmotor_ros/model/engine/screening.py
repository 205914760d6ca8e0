# SPDX-License-Identifier: Apache-2.0
"""
Screening of operating points: what is refused, what is flagged, and the messages.

With ``errors='raise'`` the first bad element raises :class:`InvalidInputError`
naming the argument, its index in the batch and its value; with
``errors='mask'`` it is flagged in the element's :class:`PointStatus` and the
rest of the batch is computed.
"""

from __future__ import annotations

import math
from typing import cast, Literal, overload

import numpy as np
import numpy.typing as npt

from satmotor_ros.model._typing import FloatArray, Real
from satmotor_ros.model.engine.solve import Tolerance
from satmotor_ros.model.errors import InvalidInputError, ModelError
from satmotor_ros.model.families.sliwinski2017.derived import DerivedCoefficients
from satmotor_ros.model.families.sliwinski2017.laws import DisplacementLaw
from satmotor_ros.model.results import describe_status, INVALID, PointStatus
from satmotor_ros.model.units import MPA

Errors = Literal['raise', 'mask']
"""Raise on the first invalid element, or return it as NaN."""

At = tuple[int, tuple[int, ...]]
"""Where a chunk sits in the batch: flat offset and the batch's shape (for error messages)."""

Status = npt.NDArray[np.uint8]
"""PointStatus flags per element."""

IntArray = npt.NDArray[np.int_]
"""Flags a rule returns for an array (:func:`add_flags` sets them in a status)."""

BoolArray = npt.NDArray[np.bool_]

CHECK = 1e-10
"""Largest relative residual an iterative solve may leave before its point is flagged."""

FLOW_ATOL = 1e-20
"""Absolute resolution of flows in the solves and their check, [m^3/s] (6e-16 l/min)."""

FLOW_XTOL = 0.01 * FLOW_ATOL
"""Absolute resolution of the flow solve, [m^3/s]."""

RTOL = 1e-11
"""
Relative tolerance of the iterative maps.

A solve ends on a Newton step smaller than this and takes the step, which
leaves an error of the order of its square; only a bisection ends at it.
"""

SPEED_ATOL = 1e-40
"""Absolute resolution of n in the speed solve, [rad/s]; its loss is below 1e-24 m^3/s."""

SPEED_SOLVE = Tolerance(SPEED_ATOL, RTOL)
"""Tolerances of eq. (36) solved for n (its check is relative to the flow)."""

FLOW_SOLVE = Tolerance(FLOW_XTOL, RTOL, CHECK)
"""Tolerances of eqs. (34)-(36) solved for Q."""


def numbers(name: str, value: object) -> FloatArray:
    """
    Return one argument as a float array, refusing what is not real numbers.

    Parameters
    ----------
    name : str
        Argument name, for the message, [-]
    value : float or array_like
        The argument, [SI]

    Returns
    -------
    ndarray
        The values as float64 (the caller's array itself when it already is one).

    Raises
    ------
    InvalidInputError
        For strings, booleans, None, complex numbers and other non-numbers.

    """
    raw = np.asarray(value)
    if raw.dtype.kind not in 'iuf':
        got = type(value).__name__ if raw.ndim == 0 else f'an array of {raw.dtype}'
        text = repr(value)
        text = text if len(text) <= 60 else text[:57] + '...'
        msg = f'{name} = {text}: expected numbers, got {got}'
        raise InvalidInputError(msg)
    return raw.astype(float, copy=False)


def raise_first(name: str, unit: str, value: FloatArray, bad: npt.NDArray[np.bool_], why: str,
                at: At) -> None:
    """
    Raise :class:`InvalidInputError` for the first element flagged in `bad`.

    Parameters
    ----------
    name : str
        Argument name, [-]
    unit : str
        Its SI unit, [-]
    value : ndarray
        The argument's values in this chunk, [SI]
    bad : ndarray of bool
        The elements to report, [-]
    why : str
        What is wrong with them, [-]
    at : tuple
        The chunk's flat offset and the batch's shape, [-]

    """
    first = int(np.flatnonzero(bad)[0])
    offset, shape = at
    index = ', '.join(str(i) for i in np.unravel_index(offset + first, shape)) if shape else ''
    where = f'{name}[{index}]' if shape else name
    count = int(bad.sum())
    tail = f' ({count} element{"s" if count > 1 else ""} of this kind)' if len(shape) else ''
    msg = f'{where} = {float(value.flat[first])!r} {unit}: {why}{tail}'
    raise InvalidInputError(msg)


def check_errors(errors: str) -> None:
    """Refuse an `errors` mode other than ``'raise'`` and ``'mask'`` (ModelError)."""
    if errors not in ('raise', 'mask'):
        msg = f"errors = {errors!r}: use 'raise' or 'mask'"
        raise ModelError(msg)


def raise_invalid(status: npt.NDArray[np.uint8], names: tuple[str, ...],
                  inputs: tuple[FloatArray, ...]) -> None:
    """
    Raise :class:`InvalidInputError` for the first invalid element of a map's result, if any.

    Parameters
    ----------
    status : ndarray of uint8
        The result's flags, one per element, [-]
    names : tuple of str
        The inputs' names, [-]
    inputs : tuple of ndarray
        Their values, as many as `status` has elements, quoted in the message, [SI]

    """
    invalid = np.flatnonzero(status.reshape(-1) & int(INVALID))
    if invalid.size:
        i = int(invalid[0])
        values = ', '.join(f'{n} = {float(x.reshape(-1)[i])!r}' for n, x in zip(names, inputs))
        msg = (f'element {i} ({values}) is invalid: '
               f'{describe_status(int(status.reshape(-1)[i]))}')
        raise InvalidInputError(msg)


CEILINGS = {'m^3/s': 10.0, 'rad/s': 1.0e5, 'Pa': 1.0e10}
"""
Magnitudes beyond any displacement motor, by SI unit: BEYOND_LIMIT, never computed.

600 000 l/min, about 950 000 rpm, 100 000 bar. Far above them the arithmetic overflows
and returns NaN or a wrong 0 that would otherwise carry an ordinary status.
"""

# The rules of the statuses, each written once for a Python float and an array alike: the
# single-point path inlines them (:mod:`.point`), the array maps call them. Each returns the
# flags it raises (an int, or an int array), or the test its caller negates. The flags are
# numpy uint8, so that an array's flags take a byte each (the inlined rules read them as ints).
_INF = math.inf


def _flag(flag: PointStatus) -> int:
    """Return a flag as a numpy uint8 (an int to the type checker: what the point path reads)."""
    return cast(int, np.uint8(flag))


_NOT_FINITE = _flag(PointStatus.NOT_FINITE)
_NEGATIVE = _flag(PointStatus.NEGATIVE)
_BEYOND_LIMIT = _flag(PointStatus.BEYOND_LIMIT)
_STALLED = _flag(PointStatus.STALLED)
_CHANNEL_LIMITED = _flag(PointStatus.CHANNEL_LIMITED)
_EXTRAPOLATED = _flag(PointStatus.EXTRAPOLATED)


@overload
def input_flags(value: float, ceiling: float) -> int: ...


@overload
def input_flags(value: FloatArray, ceiling: float) -> IntArray: ...


def input_flags(value: Real, ceiling: float) -> int | IntArray:
    """Return NOT_FINITE for NaN or inf, else NEGATIVE below 0 and BEYOND_LIMIT past `ceiling`."""
    finite = abs(value) < _INF
    return ((finite < 1) * _NOT_FINITE
            + finite * ((value < 0.0) * _NEGATIVE + (abs(value) > ceiling) * _BEYOND_LIMIT))


@overload
def channel_limited(dp_i: float) -> int: ...


@overload
def channel_limited(dp_i: FloatArray) -> IntArray: ...


def channel_limited(dp_i: Real) -> int | IntArray:
    """Return CHANNEL_LIMITED where the channels take the whole drop: dp_i < 0, clipped to 0."""
    return (dp_i < 0.0) * _CHANNEL_LIMITED


@overload
def beyond_limit(dp_i: float, dp_limit: float) -> int: ...


@overload
def beyond_limit(dp_i: FloatArray, dp_limit: float) -> IntArray: ...


def beyond_limit(dp_i: Real, dp_limit: float) -> int | IntArray:
    """Return BEYOND_LIMIT where the chamber drop passes the model's limit."""
    return (dp_i > dp_limit) * _BEYOND_LIMIT


@overload
def below_floor(speed: float, floor: float) -> int: ...


@overload
def below_floor(speed: FloatArray, floor: FloatArray) -> IntArray: ...


def below_floor(speed: Real, floor: Real) -> int | IntArray:
    """Return BEYOND_LIMIT where a turning shaft is below the law's floor speed."""
    return ((speed > 0.0) & (speed < floor)) * _BEYOND_LIMIT


@overload
def stalled(speed: float) -> int: ...


@overload
def stalled(speed: FloatArray) -> IntArray: ...


def stalled(speed: Real) -> int | IntArray:
    """Return STALLED where the shaft does not turn."""
    flag: int | IntArray = (speed == 0.0) * _STALLED
    return flag


@overload
def outside_range(speed: float, dp_i: float, dp_max: float, speed_max: float, dp_min: float,
                  speed_min: float, liquid_extrapolated: bool) -> int: ...


@overload
def outside_range(speed: FloatArray, dp_i: FloatArray, dp_max: float, speed_max: float,
                  dp_min: float, speed_min: float, liquid_extrapolated: bool) -> IntArray: ...


def outside_range(speed: Real, dp_i: Real, dp_max: float, speed_max: float, dp_min: float,
                  speed_min: float, liquid_extrapolated: bool) -> int | IntArray:
    """Return EXTRAPOLATED outside the validated range, or everywhere off the fitted liquid."""
    return ((dp_i > dp_max) | (speed > speed_max) | (dp_i < dp_min) | (speed < speed_min)
            | liquid_extrapolated) * _EXTRAPOLATED


def add_flags(status: Status, flags: IntArray) -> None:
    """Set the flags a rule returned for an array in `status`, in place."""
    np.bitwise_or(status, flags, out=status, casting='unsafe')


@overload
def holds(value: float, target: float) -> bool: ...


@overload
def holds(value: FloatArray, target: FloatArray) -> BoolArray: ...


def holds(value: Real, target: Real) -> bool | BoolArray:
    """Return whether a solved flow matches its target within :data:`CHECK` (False for NaN)."""
    return abs(value - target) <= CHECK * abs(target) + FLOW_ATOL


def _screen(name: str, unit: str, value: FloatArray, errors: Errors) -> Status | None:
    """Flag non-finite, negative and absurd elements; None when there are none (the usual case)."""
    ceiling = CEILINGS.get(unit, np.inf)
    if value.size == 0 or (value.min() >= 0.0 and value.max() <= ceiling):
        return None
    flags = input_flags(value, ceiling).astype(np.uint8)
    if errors == 'raise':
        at = (0, value.shape)
        for flag, why in ((_NOT_FINITE, 'not finite'),
                          (_BEYOND_LIMIT, f'beyond any motor (|{name}| > {ceiling:g})'),
                          (_NEGATIVE, 'negative')):
            if (flags & flag).any():
                raise_first(name, unit, value, (flags & flag) != 0, why, at)
    return flags


def prepare(named: dict[str, tuple[object, str]],
            errors: Errors) -> tuple[tuple[FloatArray, ...], Status]:
    """
    Convert, screen and broadcast the arguments of a map.

    Parameters
    ----------
    named : dict
        Argument name -> (value, SI unit), [-]
    errors : {'raise', 'mask'}
        What to do with a bad element, [-]

    Returns
    -------
    arrays : tuple of ndarray
        The arguments, broadcast to one shape (views, possibly of the caller's arrays).
    status : ndarray of uint8
        NOT_FINITE / NEGATIVE flags per element.

    """
    check_errors(errors)
    values = [numbers(name, v) for name, (v, _) in named.items()]
    flags = [_screen(name, unit, value, errors)
             for (name, (_, unit)), value in zip(named.items(), values)]
    try:
        arrays = np.broadcast_arrays(*values)
    except ValueError:
        shapes = ', '.join(f'{name} {value.shape}' for name, value in zip(named, values))
        msg = f'the shapes of the arguments do not broadcast together: {shapes}'
        raise InvalidInputError(msg) from None
    status: Status = np.zeros(arrays[0].shape, dtype=np.uint8)
    for flag in flags:
        if flag is not None:
            status |= flag
    return arrays, status


def check_limit(dp_i: FloatArray, dp_limit: float, name: tuple[str, FloatArray],
                status: Status, errors: Errors, at: At) -> FloatArray:
    """
    Flag BEYOND_LIMIT where the chamber drop passes the model's limit.

    Parameters
    ----------
    dp_i : ndarray
        Chamber pressure drop, [Pa]
    dp_limit : float
        The limit, [Pa]
    name : tuple
        The pressure argument's name and values, for the message, [-]
    status : ndarray of uint8
        Flags, updated in place, [-]
    errors : {'raise', 'mask'}
        What to do with a bad element, [-]
    at : tuple
        The chunk's place in the batch, [-]

    Returns
    -------
    ndarray
        `dp_i`, with 0 where it is beyond the limit.

    """
    if dp_i.size == 0 or dp_i.max() <= dp_limit:
        return dp_i
    flags = beyond_limit(dp_i, dp_limit)
    if errors == 'raise':
        raise_first(name[0], 'Pa', name[1], flags != 0,
                    f'chamber pressure drop beyond the model limit {dp_limit / MPA:.1f} MPa, '
                    'where eq. (2) closes the clearance so fast that eq. (1) would fall with '
                    'pressure', at)
    add_flags(status, flags)
    return np.where(flags != 0, 0.0, dp_i)


def check_floor(speed: FloatArray, law: DisplacementLaw, dp_i: FloatArray, status: Status,
                errors: Errors, at: At) -> None:
    """
    Flag BEYOND_LIMIT where a turning shaft is below the law's floor speed.

    Parameters
    ----------
    speed : ndarray
        Shaft speed, [rad/s]
    law : DisplacementLaw
        The displacement law, [-]
    dp_i : ndarray
        Chamber pressure drop, [Pa]
    status : ndarray of uint8
        Flags, updated in place, [-]
    errors : {'raise', 'mask'}
        What to do with a point below the floor, [-]
    at : tuple
        The chunk's place in the batch, [-]

    """
    if not law.has_floor:
        return
    flags = below_floor(speed, law.floor(dp_i))
    if flags.any():
        if errors == 'raise':
            raise_first('speed', 'rad/s', speed, flags != 0,
                        f'below the floor of eq. ({law.name[2:]}), where its loss diverges', at)
        add_flags(status, flags)


def check_solution(value: FloatArray, target: FloatArray, solved: Status,
                   checked: npt.NDArray[np.bool_], status: Status, errors: Errors,
                   name: tuple[str, str, FloatArray, At], what: str) -> None:
    """
    Flag the points where an iterative solve failed, or its point does not hold eq. (36).

    The solver's own flags (NOT_CONVERGED, NO_ROOT) come first; a point it
    accepted whose composed flow still misses the target is NO_ROOT too.
    Invalid points keep their flags; with ``errors='raise'`` the first flagged
    point raises, NO_ROOT (also flagged before the solve) first.

    Parameters
    ----------
    value : ndarray
        The flow eq. (36) gives at the solution, [m^3/s]
    target : ndarray
        The flow it had to match, [m^3/s]
    solved : ndarray of uint8
        The solver's status per point, [-]
    checked : ndarray of bool
        The points to check, [-]
    status : ndarray of uint8
        Flags, updated in place, [-]
    errors : {'raise', 'mask'}
        What to do with a bad element, [-]
    name : tuple
        Argument name, unit, values and the chunk's place, for the message, [-]
    what : str
        The equations solved, for the message, [-]

    """
    with np.errstate(invalid='ignore'):
        off = ~holds(value, target)
    no_root = np.uint8(PointStatus.NO_ROOT)
    if not (off & checked).any() and not solved.any() and not (status & no_root).any():
        return  # the usual case: every solution checks out
    open_ = (status & int(INVALID)) == 0
    status |= np.where(open_, solved, 0).astype(np.uint8)
    status |= (off & checked & open_ & (solved == 0)) * no_root
    if errors == 'raise':
        arg, unit, values, at = name
        flagged = (status & no_root) != 0
        if flagged.any():
            raise_first(arg, unit, values, flagged, f'{what} has no root here', at)
        not_converged = (status & np.uint8(PointStatus.NOT_CONVERGED)) != 0
        if not_converged.any():
            raise_first(arg, unit, values, not_converged, f'{what} did not converge', at)


def flag_extrapolated(derived: DerivedCoefficients, speed: FloatArray, dp_i: FloatArray,
                      status: Status) -> None:
    """
    Flag EXTRAPOLATED outside the validated range or the fitted viscosity.

    Parameters
    ----------
    derived : DerivedCoefficients
        The model's range and liquid, [-]
    speed : ndarray
        Shaft speed, [rad/s]
    dp_i : ndarray
        Chamber pressure drop, [Pa]
    status : ndarray of uint8
        Flags, updated in place, [-]

    """
    d = derived
    with np.errstate(invalid='ignore'):  # each element on its own, NaN never outside
        add_flags(status, outside_range(speed, dp_i, d.dp_max, d.speed_max, d.dp_min,
                                        d.speed_min, d.liquid_extrapolated))


FITTED_TOLERANCE = 0.05
"""
Share of a fitted range's span a calibrated effect may be evaluated beyond before its point is
EXTRAPOLATED, [-] (of the value itself where the data held one value only).
"""

Bounds = tuple[tuple[str, float, float], ...]
"""(quantity, lowest, highest) a calibrated effect may be evaluated at, SI."""


def fitted_bounds(fitted_range: Bounds) -> Bounds:
    """
    Widen an effect's fitted range by :data:`FITTED_TOLERANCE` on each side.

    Parameters
    ----------
    fitted_range : tuple of (str, float, float)
        (quantity, min, max) of the data the effect was fitted on, SI, [-]

    Returns
    -------
    tuple of (str, float, float)
        The bounds :func:`outside_fitted` holds a point against.

    """
    out = []
    for quantity, low, high in fitted_range:
        slack = FITTED_TOLERANCE * ((high - low) or max(abs(low), abs(high)))
        out.append((quantity, low - slack, high + slack))
    return tuple(out)


def outside_fitted(bounds: Bounds, values: dict[str, float]) -> bool:
    """
    Say whether a point evaluates a calibrated effect outside the data it was fitted on.

    The one check of fitted ranges: the scalar point path and the array maps (which run
    the point path element by element when the set has effects) both call it.

    Parameters
    ----------
    bounds : tuple of (str, float, float)
        From :func:`fitted_bounds`, [-]
    values : dict of str to float
        The point's ``dp_i``, ``speed``, ``flow`` (magnitudes) and channels, SI, [-]

    Returns
    -------
    bool
        True where any quantity lies outside its bounds (or is NaN).

    """
    return not all(low <= values[quantity] <= high for quantity, low, high in bounds)
