# SPDX-License-Identifier: Apache-2.0
"""Batch evaluation: chunks for the iterative maps, one pass for closed forms, owned results."""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence

import numpy as np

from satmotor_ros.model._numeric import maximum
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.coefficients import MotorGeometry
from satmotor_ros.model.engine.screening import add_flags, channel_limited, Errors, prepare, Status
from satmotor_ros.model.families.sliwinski2017.composition import Equations
from satmotor_ros.model.results import COMPONENTS, INVALID, LossBreakdown, OperatingPoints

CHUNK = 8192
"""
Elements solved at once by the iterative maps.

Temporaries of this size stay in cache, and a chunk stops iterating as soon as
its own elements converge: 3-4x faster than solving a whole batch at once. A
closed-form evaluation is a single pass, where chunking would only add a copy.
"""

Chunk = dict[str, 'np.ndarray | float']
"""Results of one chunk by field name: OperatingPoints fields and COMPONENTS (0.0: none)."""


def _join(parts: Iterator[Chunk], size: int, chunk: int) -> dict[str, np.ndarray]:
    """
    Write the chunks' fields into whole arrays as they come (a scalar is 0: no pages written).

    Each chunk's temporaries are freed before the next is computed, so that the
    chunks reuse the same memory; a single chunk's arrays are kept as they are.
    """
    joined: dict[str, np.ndarray] = {}
    for start, part in zip(range(0, max(size, 1), chunk), parts):
        for key, value in part.items():
            if start == 0 and size <= chunk:  # the only chunk
                joined[key] = np.asarray(value) if np.ndim(value) else np.zeros(size)
                continue
            if key not in joined:  # calloc'd: a component that is 0 throughout writes no page
                joined[key] = np.zeros(size, dtype=np.result_type(value))
            if np.ndim(value) or value:
                joined[key][start:start + chunk] = value
    return joined


def map_inputs(first: tuple[str, object, str], dp_name: str, dp_value: object, p_ex: object,
               errors: Errors) -> tuple[tuple[FloatArray, ...], Status, bool,
                                        dict[str, FloatArray]]:
    """
    Screen and broadcast a map's inputs: the given flow or speed, a pressure drop and p_ex.

    Parameters
    ----------
    first : tuple of (str, array_like, str)
        Name, value and SI unit of the flow or speed, [-]
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
    arrays : tuple of ndarray
        The three inputs, broadcast.
    status : ndarray of uint8
        Their screening flags.
    port : bool
        Whether the drop is between the ports.
    given : dict
        The inputs that come back as fields of the result, by field name.

    """
    name, value, unit = first
    arrays, status = prepare({name: (value, unit), dp_name: (dp_value, 'Pa'),
                              'p_ex': (p_ex, 'Pa')}, errors)
    port = dp_name == 'dp'
    given = {name: arrays[0], 'dp': arrays[1]} if port else {name: arrays[0]}
    return arrays, status, port, given


def components(eqs: Equations, speed: FloatArray, dp_i: FloatArray, q_lfg: FloatArray,
               q_c: FloatArray, q_ex: FloatArray | float,
               leak: FloatArray) -> tuple[Chunk, FloatArray]:
    """Return the components of eq. (31) by name, and Q_vl; `leak` is Q_Lfg + Q_C + Q_ex."""
    fc, dch, bl, ine, total = eqs.breakdown(speed, dp_i, leak)
    return dict(zip(COMPONENTS, (q_lfg, q_c, fc, dch, bl, ine, q_ex, total))), total


def clip_chamber_drop(dp_i: FloatArray, status: Status) -> FloatArray:
    """
    Clip the chamber drop of eq. (34) to 0, flagged CHANNEL_LIMITED where it was below.

    Parameters
    ----------
    dp_i : ndarray
        Chamber pressure drop, [Pa]
    status : ndarray of uint8
        Flags, updated in place, [-]

    Returns
    -------
    ndarray
        dp_i >= 0, [Pa]

    """
    if dp_i.size == 0 or dp_i.min() >= 0.0:
        return dp_i
    add_flags(status, channel_limited(dp_i))
    return maximum(dp_i, 0.0)


def mask_invalid(chunk: Chunk, status: Status) -> Chunk:
    """
    Put NaN in every field of the invalid elements and keep only their INVALID flags.

    Parameters
    ----------
    chunk : dict
        Fields of one chunk, [SI]
    status : ndarray of uint8
        Flags of the chunk, updated in place, [-]

    Returns
    -------
    dict
        The fields, with ``status`` added.

    """
    invalid = (status & int(INVALID)) != 0 if status.any() else None
    if invalid is not None and invalid.any():
        status &= np.where(invalid, np.uint8(INVALID), np.uint8(0xFF))  # no STALLED etc.
        chunk = {k: np.where(invalid, np.nan, v) for k, v in chunk.items()}
    chunk['status'] = status
    return chunk


def run(core: Callable[..., Chunk], arrays: Sequence[FloatArray], status: Status,
        given: dict[str, FloatArray], iterative: bool,
        geometry: MotorGeometry) -> OperatingPoints:
    """
    Evaluate a map's `core` over a batch and assemble the result.

    Parameters
    ----------
    core : callable
        ``core(*arrays, status, at) -> Chunk`` for one chunk of flat arrays, [-]
    arrays : sequence of ndarray
        The screened arguments, broadcast to one shape, [SI]
    status : ndarray of uint8
        Flags from screening, [-]
    given : dict
        Inputs that come back as fields (copies), by field name, [SI]
    iterative : bool
        Evaluate in chunks of :data:`CHUNK` (for the solves), [-]
    geometry : MotorGeometry
        The motor, [-]

    Returns
    -------
    OperatingPoints
        The result; its arrays are its own and read-only.

    """
    shape = status.shape
    bad = status != 0 if status.any() else None
    clean = arrays if bad is None else [np.where(bad, 0.0, a) for a in arrays]
    flat = [a.reshape(-1) for a in clean]  # a view where it can be, e.g. broadcast scalars
    flat_status = status.ravel()
    chunk = CHUNK if iterative else max(flat_status.size, 1)
    parts = (core(*(a[i:i + chunk] for a in flat), flat_status[i:i + chunk], (i, shape))
             for i in range(0, max(flat_status.size, 1), chunk))
    fields_ = {k: v.reshape(shape) for k, v in _join(parts, flat_status.size, chunk).items()}
    invalid = (fields_['status'] & int(INVALID)) != 0
    for name, value in given.items():
        fields_[name] = np.where(invalid, np.nan, value) if invalid.any() else value
    for name, value in fields_.items():  # the results own their data, read-only
        if any(np.may_share_memory(value, a) for a in arrays):
            value = fields_[name] = value.copy()
        value.flags.writeable = False
    losses = LossBreakdown(**{k: fields_.pop(k) for k in COMPONENTS})
    return OperatingPoints(losses=losses, geometry=geometry, **fields_)
