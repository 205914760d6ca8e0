# SPDX-License-Identifier: Apache-2.0
"""
The prediction: inputs -> model call -> speed, losses, residual and status.

:func:`predict` is the one path that the live node (a :class:`Snapshot` of floats per
message, the model's single-point path ``speed_point``, a few microseconds) and bag replay
(a :class:`SnapshotBatch` of arrays, every driving time at once, the array path ``speed``)
both drive: its body is written once on values that may be floats or arrays
(:func:`pick`). A bag replayed gives the levels, statuses and messages the node published,
and its numbers to 1e-12 (the two model paths agree to that).
"""

from __future__ import annotations

import math
from operator import itemgetter
from typing import Any, NamedTuple, overload

import numpy as np
import numpy.typing as npt

from satmotor_ros.model import (COMPONENTS, describe_status, INVALID, MotorModel, Point,
                                PointStatus)
from satmotor_ros.model.effects import Effect, kind_of
from satmotor_ros.model.revolutions import revolutions
from satmotor_ros.model.units import channel_gauge, LPM, MPA
from satmotor_ros.prediction.rule import (describe_input, FIELDS, input_level, INPUTS,
                                          InputState, Level, Snapshot, SnapshotBatch)

OUTPUTS = ('dp', 'dp_i', 'p_ex', 'speed', *COMPONENTS, 'residual')
"""Computed fields of a prediction (SI: Pa, rad/s, m^3/s), after the inputs."""

_NOTED = int(PointStatus.STALLED | PointStatus.CHANNEL_LIMITED | PointStatus.EXTRAPOLATED)
_INVALID = int(INVALID)
_I_CASE = INPUTS.index('p_case')
_I_SPEED = INPUTS.index('measured_speed')
_GAUGED = ('p_case', 'p_in', 'p_out')
_MEASURED = {'p_case': _I_CASE, 'p_in': INPUTS.index('p_in'),
             'p_out': INPUTS.index('p_out'), 'temperature': INPUTS.index('temperature')}
CHANNELS = ('p_case', 'p_in', 'p_out', 'temperature', 'time', 'revolutions')
"""
Channels a calibrated effect may read (``MotorModel.channels``): case, inlet (port A) and
outlet (port B) pressure made gauge (absolute - ATMOSPHERE, floored at 0) [Pa], temperature
[degC], and the time [s] and shaft revolutions [rev] since the first prediction (see
:class:`Progress`), as ``satmotor calibrate`` counts them from the start of a bag.
"""

# plain ints: an enum member looked up on its class costs a microsecond per message
_FRESH = int(InputState.FRESH)
_OK, _WARN, _ERROR = int(Level.OK), int(Level.WARN), int(Level.ERROR)


def pick(condition: Any, if_true: Any, if_false: Any) -> Any:
    """
    Choose element by element: a conditional expression on scalars, ``np.where`` on arrays.

    What lets one body of code serve one message (floats, the node) and a whole
    recording (arrays, replay).

    Parameters
    ----------
    condition : bool or ndarray of bool
        Where to take `if_true`, [-]
    if_true, if_false : float, int or ndarray
        The choices, [any]

    Returns
    -------
    float, int or ndarray
        The choice; an array when `condition` is one.

    """
    if condition is True:  # the usual scalar case first: the node calls this per message
        return if_true
    if condition is False:
        return if_false
    if isinstance(condition, np.ndarray):
        return np.where(condition, if_true, if_false)
    return if_true if condition else if_false  # numpy's scalar bool


def _is_array(x: Any) -> bool:
    return isinstance(x, np.ndarray)


class Progress:
    """
    Time and revolutions since the first prediction, advanced prediction by prediction.

    Revolutions add the measured speed (when fresh) times the time since the previous
    prediction. :meth:`advance` takes one snapshot (the node) or a whole batch (replay)
    and sums the same terms in the same order.
    """

    def __init__(self) -> None:
        """Start before the first prediction."""
        self.origin_ns: int | None = None
        self.last_ns = 0
        self.revolutions = 0.0

    def advance(self, snap: Snapshot | SnapshotBatch) -> tuple[Any, Any]:
        """
        Count the snapshot(s) in and return the time and revolutions at each.

        Parameters
        ----------
        snap : Snapshot or SnapshotBatch
            The inputs of the prediction(s) about to be made, [-]

        Returns
        -------
        tuple
            Time since the first prediction [s] and revolutions [rev]: floats for a
            Snapshot, arrays for a batch.

        """
        stamps: Any = snap.stamp_ns  # an int, or an array for a batch: one body for both
        batch = _is_array(stamps)
        if batch and not len(stamps):
            return np.zeros(0), np.zeros(0)
        if self.origin_ns is None:
            self.origin_ns = self.last_ns = int(stamps[0] if batch else stamps)
        dt = (np.diff(stamps, prepend=self.last_ns) if batch else stamps - self.last_ns) * 1e-9
        fresh = snap.states[_I_SPEED] == _FRESH
        speed = pick(fresh, snap.values[_I_SPEED], 0.0)  # inf or NaN where not fresh
        turned = revolutions(speed, dt, self.revolutions)
        self.revolutions = float(turned[-1] if batch else turned)
        self.last_ns = int(stamps[-1] if batch else stamps)
        return (stamps - self.origin_ns) * 1e-9, turned

    def peek(self, stamp_ns: int) -> tuple[float, float]:
        """
        Return the time and revolutions at `stamp_ns` without counting a prediction.

        Parameters
        ----------
        stamp_ns : int
            Time, [ns]

        Returns
        -------
        tuple of float
            Time since the first prediction (0 before it) [s] and revolutions so far [rev].

        """
        origin = stamp_ns if self.origin_ns is None else self.origin_ns
        return (stamp_ns - origin) * 1e-9, self.revolutions


def _leakage_effect(model: MotorModel) -> Effect | None:
    """Return the effect whose channel drives the external leakage of eq. (24), or None."""
    return next((e for e in model.effects if kind_of(e).drives_leakage), None)


def _gauge(p: Any) -> Any:
    """Absolute pressure made gauge, floored at 0 (float or array), [Pa]."""
    return channel_gauge(p)


def _channels(needed: tuple[str, ...], snap: Snapshot | SnapshotBatch,
              progress: tuple[Any, Any]) -> tuple[dict[str, Any], Any]:
    """Return the channels the model's effects read and where one of them is missing."""
    channels: dict[str, Any] = {}
    missing: Any = False
    for name in needed:
        if name in ('time', 'revolutions'):
            channels[name] = progress[name == 'revolutions']
            continue
        i = _MEASURED.get(name)
        if i is None:  # a channel motor_model does not measure: never usable
            missing, channels[name] = True, 0.0
            continue
        fresh = snap.states[i] == _FRESH
        missing = pick(fresh, missing, True)
        value = snap.values[i]
        channels[name] = pick(fresh, _gauge(value) if name in _GAUGED else value, 0.0)
    return channels, missing


def _channel_problem(needed: tuple[str, ...], snap: Snapshot) -> str:
    """Say why the channels the model's effects need are not there, or ''."""
    for name in needed:
        i = _MEASURED.get(name)
        if name in ('time', 'revolutions'):
            continue
        if i is None:
            return (f'the calibrated effect needs the channel {name!r}, which motor_model '
                    f'does not measure (it has: {", ".join(CHANNELS)})')
        if snap.states[i] != InputState.FRESH:
            return (f'the calibrated effect needs {FIELDS[INPUTS[i]]}: '
                    f'{InputState(snap.states[i]).name.lower()}')
    return ''


class Prediction(NamedTuple):
    """One prediction: its inputs, the model's outputs and what is wrong, all SI."""

    stamp_ns: int  # driving time [ns]
    inputs: tuple[float, ...]  # values per INPUTS as used (NaN where missing) [SI]
    outputs: tuple[float, ...]  # values per OUTPUTS; NaN where not computed [SI]
    status: int  # PointStatus of the model; 0 when the model was not run
    level: int  # a Level: OK, WARN (published, with a note) or ERROR (not published)
    message: str  # 'OK' or the problems, each naming the field and the value

    @property
    def valid(self) -> bool:
        """Whether the prediction may be published (its outputs are numbers)."""
        return self.level < Level.ERROR

    def output(self, name: str) -> float:
        """Return the output `name` (one of :data:`OUTPUTS`), [SI]."""
        return self.outputs[OUTPUTS.index(name)]


class PredictionBatch(NamedTuple):
    """Many predictions as arrays (see :class:`Prediction`)."""

    snapshots: SnapshotBatch  # the inputs
    outputs: npt.NDArray[np.float64]  # (len(OUTPUTS), n); NaN where level is ERROR [SI]
    status: npt.NDArray[np.uint8]  # PointStatus per prediction (0 where not run)
    level: npt.NDArray[np.uint8]  # Level per prediction
    timeout: float  # the input timeout [s]
    channels: tuple[str, ...] = ()  # channels the model's effects read (MotorModel.channels)

    def __len__(self) -> int:
        """Return the number of predictions."""
        return len(self.level)

    @property
    def valid(self) -> npt.NDArray[np.bool_]:
        """Mask of the predictions that would be published."""
        return self.level < Level.ERROR

    def output(self, name: str) -> npt.NDArray[np.float64]:
        """Return the output `name` (one of :data:`OUTPUTS`) of every prediction, [SI]."""
        row: npt.NDArray[np.float64] = self.outputs[OUTPUTS.index(name)]  # numpy types it as Any
        return row

    def snapshot(self, i: int) -> Snapshot:
        """Return the inputs of prediction `i` as the live node would hold them."""
        s = self.snapshots
        return Snapshot(int(s.stamp_ns[i]), tuple(float(v) for v in s.values[:, i]),
                        tuple(float(a) for a in s.ages[:, i]),
                        tuple(int(x) for x in s.states[:, i]))

    def message(self, i: int) -> str:
        """Spell out prediction `i`'s problems (``'OK'`` if none), as :class:`Prediction` does."""
        return describe(self.snapshot(i), self.timeout, int(self.status[i]), self.channels)[1]


def _fixed(value: float) -> str:
    """Four decimals, and no sign on a value that shows as zero (not '-0.0000')."""
    text = f'{value:.4f}'
    return text[1:] if text.startswith('-') and not float(text) else text


def _model_note(status: int, flow: float, dp: float) -> str:
    # read by people (logs, diagnostics, replay's message column): hydraulic units
    return (f'model status {describe_status(status)} at flow_command {_fixed(flow / LPM)} '
            f'l/min, dp {_fixed(dp / MPA)} MPa')


def _level_table() -> npt.NDArray[np.uint8]:
    table = np.zeros((len(INPUTS), max(InputState) + 1), dtype=np.uint8)
    for i, name in enumerate(INPUTS):
        for state in InputState:
            table[i, state] = input_level(name, state)
    return table


_LEVELS = _level_table()
_LEVEL_ROWS = _LEVELS.tolist()  # Python ints for one snapshot: numpy scalars are slower
_POINT_LOSSES = itemgetter(*(Point._fields.index(c) for c in COMPONENTS))


def _worst(levels: list[Any]) -> Any:
    """Return the worst of some levels, element by element (floats or arrays)."""
    return np.maximum.reduce(levels) if _is_array(levels[-1]) else max(levels)


def _masked(keep: Any, values: list[Any], fill: float) -> list[Any]:
    """Return `values` where `keep`, `fill` elsewhere (one test for floats)."""
    if _is_array(keep):
        return [np.where(keep, value, fill) for value in values]
    return values if keep else [fill] * len(values)


def describe(snap: Snapshot, timeout: float, status: int, channels: tuple[str, ...] = ()
             ) -> tuple[int, str]:
    """
    Rate one prediction and spell out its problems, each naming the field and the value.

    Parameters
    ----------
    snap : Snapshot
        Its inputs, [-]
    timeout : float
        The input timeout, quoted in messages, [s]
    status : int
        The model's :class:`PointStatus`; 0 when the model was not run, [-]
    channels : tuple of str
        Channels the model's effects read (``MotorModel.channels``), [-]

    Returns
    -------
    tuple
        The :class:`Level` and ``'OK'`` or the problems.

    """
    level, notes = Level.OK, []
    for name, value, age, state in zip(INPUTS, snap.values, snap.ages, snap.states):
        rated = input_level(name, state)
        if rated:
            level = max(level, rated)
            notes.append(describe_input(name, state, value, age, timeout))
    why = _channel_problem(channels, snap) if level < Level.ERROR else ''
    if why:
        level = Level.ERROR
        notes.append(why)
    if level < Level.ERROR and status & (_NOTED | _INVALID):
        level = max(level, Level.ERROR if status & _INVALID else Level.WARN)
        notes.append(_model_note(status, snap.values[0], snap.values[1] - snap.values[2]))
    return int(level), '; '.join(notes) if notes else 'OK'


def _model_call(model: MotorModel, flow: Any, dp: Any, p_ex: Any,
                channels: dict[str, Any] | None) -> tuple[Any, Any, Any, list[Any]]:
    """Run the model's point path on floats, its array path on arrays."""
    if _is_array(flow):
        op = model.speed(flow, dp, p_ex=p_ex, errors='mask', channels=channels)
        return op.speed, op.dp_i, op.status, list(op.losses.as_dict().values())
    point = model.speed_point(flow, dp, p_ex=p_ex, channels=channels)
    return point.speed, point.dp_i, point.status, list(_POINT_LOSSES(point))


@overload
def predict(model: MotorModel, snap: Snapshot, timeout: float,
            progress: tuple[Any, Any] = ...) -> Prediction: ...


@overload
def predict(model: MotorModel, snap: SnapshotBatch, timeout: float,
            progress: tuple[Any, Any] = ...) -> PredictionBatch: ...


def predict(model: MotorModel, snap: Snapshot | SnapshotBatch, timeout: float,
            progress: tuple[Any, Any] = (0.0, 0.0)) -> Prediction | PredictionBatch:
    """
    Predict from one snapshot of the inputs (the node) or from many at once (replay).

    Parameters
    ----------
    model : MotorModel
        The motor model, [-]
    snap : Snapshot or SnapshotBatch
        The inputs at the driving time(s), [-]
    timeout : float
        The input timeout, quoted in messages, [s]
    progress : tuple
        Time since the first prediction [s] and revolutions [rev] at the driving time(s)
        (:meth:`Progress.advance`), for effects that read them, [-]

    Returns
    -------
    Prediction or PredictionBatch
        Outputs and status; NaN outputs and level ERROR where no prediction may be made.

    """
    values, states = snap.values, snap.states
    levels = _LEVELS if _is_array(states) else _LEVEL_ROWS
    level = _worst([row[state] for row, state in zip(levels, states)])
    channels = None
    if model.channels:
        channels, missing = _channels(model.channels, snap, progress)
        level = pick(missing, _ERROR, level)
    usable = level < _ERROR
    if not (usable.any() if _is_array(usable) else usable):
        return _result(model, snap, timeout, [math.nan] * len(OUTPUTS), 0, level)
    p_ex = pick(states[_I_CASE] == _FRESH, _gauge(values[_I_CASE]), 0.0)
    flow, dp, p_ex = _masked(usable, [values[0], values[1] - values[2], p_ex], 0.0)
    if channels is not None:
        channels = dict(zip(channels, _masked(usable, list(channels.values()), 0.0)))
    speed, dp_i, status, losses = _model_call(model, flow, dp, p_ex, channels)
    leak = _leakage_effect(model) if channels is not None else None
    if leak is not None and channels is not None:  # the pressure that drove eq. (24)
        kind = kind_of(leak)  # the channel it reads while the flow runs backwards, or forward
        p_ex = pick(flow < 0.0, channels[kind.channel_at(leak, True)],
                    channels[kind.channel_at(leak, False)])
    status = pick(usable, status, 0)
    level = _worst([level, pick(status & _INVALID, _ERROR, pick(status & _NOTED, _WARN, _OK))])
    residual = pick(states[_I_SPEED] == _FRESH, model.true_speed(values[_I_SPEED]) - speed,
                    math.nan)
    outputs = _masked(level < _ERROR, [dp, dp_i, p_ex, speed, *losses, residual], math.nan)
    return _result(model, snap, timeout, outputs, status, level)


def _result(model: MotorModel, snap: Snapshot | SnapshotBatch, timeout: float,
            outputs: list[Any], status: Any, level: Any) -> Prediction | PredictionBatch:
    """Pack the outputs as the node's Prediction or replay's PredictionBatch."""
    if isinstance(snap, SnapshotBatch):
        n = len(snap.stamp_ns)
        table = np.empty((len(OUTPUTS), n))
        for row, column in zip(table, outputs):
            row[:] = column
        return PredictionBatch(snap, table, np.broadcast_to(status, n).astype(np.uint8),
                               np.broadcast_to(level, n).astype(np.uint8), timeout,
                               model.channels)
    if level == _OK and not status & (_NOTED | _INVALID):
        message = 'OK'  # the usual case, without building any text
    else:
        level, message = describe(snap, timeout, int(status), model.channels)
    return Prediction(snap.stamp_ns, snap.values, tuple(outputs), int(status), int(level),
                      message)
