# SPDX-License-Identifier: Apache-2.0
"""
The prediction: inputs -> model call -> speed, losses, residual and status.

:func:`predict_point` serves the live node (one snapshot per message, the model's
single-point path ``speed_point``, a few microseconds) and :func:`predict_batch` serves bag
replay (every driving time at once, the array path ``speed``). Both apply the same checks
and levels to the same model, so a bag replayed gives the levels, statuses and messages
the node published, and its numbers to 1e-12 (the two model paths agree to that).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from satmotor_ros.model import COMPONENTS, describe_status, INVALID, MotorModel, PointStatus
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import ATMOSPHERE
from satmotor_ros.prediction.rule import (describe_input, FIELDS, input_level, INPUTS,
                                          InputState, Level, Snapshot, SnapshotBatch)

OUTPUTS = ('dp', 'dp_i', 'p_ex', 'speed', *COMPONENTS, 'residual')
"""Computed fields of a prediction (SI: Pa, rad/s, m^3/s), after the inputs."""

_NOTED = PointStatus.STALLED | PointStatus.CHANNEL_LIMITED | PointStatus.EXTRAPOLATED
_I_OUT = INPUTS.index('p_out')
_I_CASE = INPUTS.index('p_case')
_I_SPEED = INPUTS.index('measured_speed')
_GAUGED = {'p_case': _I_CASE, 'p_out': _I_OUT}
_MEASURED = {**_GAUGED, 'temperature': INPUTS.index('temperature')}
CHANNELS = ('p_case', 'p_out', 'temperature', 'time', 'revolutions')
"""
Channels a calibrated effect may read (``MotorModel.channels``): case and outlet pressure
made gauge (absolute - ATMOSPHERE, floored at 0) [Pa], temperature [degC], and the time [s]
and shaft revolutions [rev] since the first prediction (see :class:`Progress`), as
``satmotor calibrate`` counts them from the start of a bag.
"""

_TWO_PI = 2.0 * math.pi


class Progress:
    """
    Time and revolutions since the first prediction, advanced one prediction at a time.

    Revolutions add the measured speed (when fresh) times the time since the previous
    prediction; :func:`predict_batch` sums the same terms in the same order.
    """

    def __init__(self) -> None:
        """Start before the first prediction."""
        self.origin_ns: int | None = None
        self.last_ns = 0
        self.revolutions = 0.0

    def advance(self, snap: Snapshot) -> tuple[float, float]:
        """
        Count the snapshot in and return the time and revolutions at it.

        Parameters
        ----------
        snap : Snapshot
            The inputs of the prediction about to be made, [-]

        Returns
        -------
        tuple of float
            Time since the first prediction [s] and revolutions [rev].

        """
        if self.origin_ns is None:
            self.origin_ns = self.last_ns = snap.stamp_ns
        if snap.states[_I_SPEED] == InputState.FRESH:
            dt = (snap.stamp_ns - self.last_ns) * 1e-9
            self.revolutions += snap.values[_I_SPEED] * dt / _TWO_PI
        self.last_ns = snap.stamp_ns
        return (snap.stamp_ns - self.origin_ns) * 1e-9, self.revolutions

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


def _leakage_channel(model: MotorModel) -> str | None:
    """Return the channel an external-leakage effect reads p_ex from, or None."""
    return next((e.regressor for e in model.effects if e.kind == 'external_leakage'), None)


def _gauge(p: float) -> float:
    return p - ATMOSPHERE if p > ATMOSPHERE else 0.0


def _channels(needed: tuple[str, ...], snap: Snapshot,
              progress: tuple[float, float]) -> tuple[dict[str, float] | None, str]:
    """Return the channels the model's effects need, or None and why they are missing."""
    channels: dict[str, float] = {}
    for name in needed:
        if name in ('time', 'revolutions'):
            channels[name] = progress[name == 'revolutions']
            continue
        i = _MEASURED.get(name)
        if i is None:
            return None, (f'the calibrated effect needs the channel {name!r}, which '
                          f'motor_model does not measure (it has: {", ".join(CHANNELS)})')
        if snap.states[i] != InputState.FRESH:
            return None, (f'the calibrated effect needs {FIELDS[INPUTS[i]]}: '
                          f'{InputState(snap.states[i]).name.lower()}')
        value = snap.values[i]
        channels[name] = _gauge(value) if name in _GAUGED else value
    return channels, ''


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
        """
        Return one output by name.

        Parameters
        ----------
        name : str
            One of :data:`OUTPUTS`, [-]

        Returns
        -------
        float
            Its value, [SI]

        """
        return self.outputs[OUTPUTS.index(name)]


def _model_note(status: int, flow: float, dp: float) -> str:
    return (f'model status {describe_status(status)} at flow_command.data = {flow!r} m^3/s, '
            f'dp = {dp!r} Pa')


def _messages(snap: Snapshot, timeout: float, status: int, dp: float) -> tuple[int, str]:
    """Return the level and the message of a snapshot and its model status."""
    level, notes = Level.OK, []
    p_in = snap.values[INPUTS.index('p_in')]
    for name, value, age, state in zip(INPUTS, snap.values, snap.ages, snap.states):
        rated = input_level(name, state)
        if rated:
            level = max(level, rated)
            notes.append(describe_input(name, state, value, age, timeout, p_in))
    if level < Level.ERROR and status & int(_NOTED | INVALID):
        level = max(level, Level.ERROR if status & INVALID else Level.WARN)
        notes.append(_model_note(status, snap.values[0], dp))
    return int(level), '; '.join(notes) if notes else 'OK'


def _level_table() -> npt.NDArray[np.uint8]:
    table = np.zeros((len(INPUTS), max(InputState) + 1), dtype=np.uint8)
    for i, name in enumerate(INPUTS):
        for state in InputState:
            table[i, state] = input_level(name, state)
    return table


_LEVELS = _level_table()
_LEVEL_ROWS = [tuple(int(x) for x in row) for row in _LEVELS]
_NOTED_OR_INVALID = int(_NOTED | INVALID)


def _input_level(states: tuple[int, ...]) -> int:
    """Return the worst level of the inputs' states (a table look-up per input)."""
    return max(row[state] for row, state in zip(_LEVEL_ROWS, states))


def predict_point(model: MotorModel, snap: Snapshot, timeout: float,
                  progress: tuple[float, float] = (0.0, 0.0)) -> Prediction:
    """
    Predict from one snapshot of the inputs (the live node's path).

    Parameters
    ----------
    model : MotorModel
        The motor model, [-]
    snap : Snapshot
        The inputs at the driving time, [-]
    timeout : float
        The input timeout, quoted in messages, [s]
    progress : tuple of float
        Time since the first prediction [s] and revolutions [rev] (:class:`Progress`),
        for effects that read them, [-]

    Returns
    -------
    Prediction
        Outputs and status; NaN outputs and level ERROR when no prediction may be made.

    """
    inputs_level = _input_level(snap.states)
    channels, why = None, ''
    if inputs_level < Level.ERROR and model.channels:
        channels, why = _channels(model.channels, snap, progress)
    if inputs_level >= Level.ERROR or why:
        level, message = _messages(snap, timeout, 0, math.nan)
        if why:
            level, message = Level.ERROR, why if message == 'OK' else f'{message}; {why}'
        return Prediction(snap.stamp_ns, snap.values, (math.nan,) * len(OUTPUTS), 0, level,
                          message)
    flow, p_in, p_out = snap.values[0], snap.values[1], snap.values[2]
    p_ex = _gauge(snap.values[_I_CASE]) if snap.states[_I_CASE] == InputState.FRESH else 0.0
    dp = p_in - p_out
    point = model.speed_point(flow, dp, p_ex=p_ex, channels=channels)
    leak = _leakage_channel(model)
    if leak is not None and channels is not None:
        p_ex = channels[leak]  # the pressure the effect drove eq. (24) with
    status = point.status
    speed = point.speed
    residual = (model.true_speed(snap.values[_I_SPEED]) - speed
                if snap.states[_I_SPEED] == InputState.FRESH else math.nan)
    if inputs_level == Level.OK and not status & _NOTED_OR_INVALID:
        level, message = Level.OK, 'OK'  # the usual case, without building any text
    else:
        level, message = _messages(snap, timeout, status, dp)
    if level >= Level.ERROR:
        return Prediction(snap.stamp_ns, snap.values, (math.nan,) * len(OUTPUTS), status,
                          level, message)
    outputs = (dp, point.dp_i, p_ex, speed, *(getattr(point, c) for c in COMPONENTS),
               residual)
    return Prediction(snap.stamp_ns, snap.values, outputs, status, level, message)


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
        """
        Return one output by name.

        Parameters
        ----------
        name : str
            One of :data:`OUTPUTS`, [-]

        Returns
        -------
        ndarray
            Its values, [SI]

        """
        return self.outputs[OUTPUTS.index(name)]

    def snapshot(self, i: int) -> Snapshot:
        """
        Return the inputs of prediction `i` as the live node would hold them.

        Parameters
        ----------
        i : int
            Index of the prediction, [-]

        Returns
        -------
        Snapshot
            Its inputs.

        """
        s = self.snapshots
        return Snapshot(int(s.stamp_ns[i]), tuple(float(v) for v in s.values[:, i]),
                        tuple(float(a) for a in s.ages[:, i]),
                        tuple(int(x) for x in s.states[:, i]))

    def message(self, i: int) -> str:
        """
        Spell out prediction `i`'s problems, as :func:`predict_point` does.

        Parameters
        ----------
        i : int
            Index of the prediction, [-]

        Returns
        -------
        str
            ``'OK'`` or the problems.

        """
        snap = self.snapshot(i)
        dp = float(snap.values[1] - snap.values[2])
        message = _messages(snap, self.timeout, int(self.status[i]), dp)[1]
        if self.channels and _input_level(snap.states) < Level.ERROR:
            why = _channels(self.channels, snap, (0.0, 0.0))[1]
            if why:
                message = why if message == 'OK' else f'{message}; {why}'
        return message


def predict_batch(model: MotorModel, snaps: SnapshotBatch, timeout: float) -> PredictionBatch:
    """
    Predict from many snapshots at once (bag replay's path), as :func:`predict_point` would.

    Parameters
    ----------
    model : MotorModel
        The motor model, [-]
    snaps : SnapshotBatch
        The inputs at every driving time, [-]
    timeout : float
        The input timeout, quoted in messages, [s]

    Returns
    -------
    PredictionBatch
        Outputs, status and level per driving time.

    """
    values, states = snaps.values, snaps.states
    n = values.shape[1]
    level = np.zeros(n, dtype=np.uint8)
    for i in range(len(INPUTS)):
        np.maximum(level, _LEVELS[i][states[i]], out=level)
    channels = None
    if model.channels:
        level, channels = _batch_channels(model, snaps, level)
    usable = level < Level.ERROR
    flow = np.where(usable, values[0], 0.0)
    dp = np.where(usable, values[1] - values[2], 0.0)
    p_ex = np.where(usable & (states[_I_CASE] == InputState.FRESH),
                    np.maximum(values[_I_CASE] - ATMOSPHERE, 0.0), 0.0)
    op = model.speed(flow, dp, p_ex=p_ex, errors='mask', channels=channels)
    leak = _leakage_channel(model)
    if leak is not None and channels is not None:
        p_ex = channels[leak]  # the pressure the effect drove eq. (24) with
    status = np.where(usable, op.status, 0).astype(np.uint8)
    model_level = np.where(status & int(INVALID), np.uint8(Level.ERROR),
                           np.where(status & int(_NOTED), np.uint8(Level.WARN), np.uint8(0)))
    np.maximum(level, model_level, out=level)
    speed = op.speed
    residual = np.where(states[_I_SPEED] == InputState.FRESH,
                        model.true_speed(values[_I_SPEED]) - speed, np.nan)
    columns = [dp, op.dp_i, p_ex, speed, *op.losses.as_dict().values(), residual]
    outputs = np.empty((len(OUTPUTS), n))
    for row, column in zip(outputs, columns):
        row[:] = column
    outputs[:, level >= Level.ERROR] = np.nan
    return PredictionBatch(snaps, outputs, status, level, timeout, model.channels)


def _batch_progress(snaps: SnapshotBatch) -> tuple[FloatArray, FloatArray]:
    """Return time [s] and revolutions [rev] at each prediction, as :class:`Progress`."""
    stamps = snaps.stamp_ns
    if not len(stamps):
        return np.zeros(0), np.zeros(0)
    dt = np.diff(stamps, prepend=stamps[0]) * 1e-9
    fresh = snaps.states[_I_SPEED] == InputState.FRESH
    with np.errstate(invalid='ignore', over='ignore'):  # inf or NaN where not fresh
        turns = np.where(fresh, snaps.values[_I_SPEED] * dt / _TWO_PI, 0.0)
    return (stamps - stamps[0]) * 1e-9, np.cumsum(turns)


def _batch_channels(model: MotorModel, snaps: SnapshotBatch, level: npt.NDArray[np.uint8]
                    ) -> tuple[npt.NDArray[np.uint8], dict[str, FloatArray]]:
    """Return the levels with missing channels made ERROR, and the channels (0 there)."""
    channels: dict[str, FloatArray] = {}
    level = level.copy()
    progress = _batch_progress(snaps)
    for name in model.channels:
        if name in ('time', 'revolutions'):
            channels[name] = progress[name == 'revolutions']
            continue
        i = _MEASURED.get(name)
        if i is None:
            level[:] = Level.ERROR
            channels[name] = np.zeros(len(level))
            continue
        fresh = snaps.states[i] == InputState.FRESH
        level[~fresh] = Level.ERROR
        value = snaps.values[i]
        if name in _GAUGED:
            value = np.maximum(value - ATMOSPHERE, 0.0)
        channels[name] = np.where(fresh & (level < Level.ERROR), value, 0.0)
    return level, channels
