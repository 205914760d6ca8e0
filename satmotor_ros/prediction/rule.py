# SPDX-License-Identifier: Apache-2.0
"""
The combination rule: which inputs a prediction may use, and what is wrong with the others.

Each input keeps its latest value and the time it arrived. A prediction is made at a
driving time (every ``flow_command`` by default, or the ticks of a fixed rate) from the
latest value of each input, provided it arrived no longer than the input timeout before
the driving time and its value is valid. The live node (:class:`Combiner`, one message
at a time) and bag replay (:func:`combine_batch`, whole arrays at once) apply the same
rule: both hold the latest value and age of each input and rate them with
:func:`input_states`, one body of code for floats and arrays.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import enum
import math
import sys
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from satmotor_ros.interface import CHANNELS, PREDICTION_INPUTS
from satmotor_ros.limits import RATE_MAX_PREDICTIONS
from satmotor_ros.model.engine.screening import CEILINGS

INPUTS = PREDICTION_INPUTS
"""The inputs of a prediction, in the order of every per-input tuple and array."""

TOPICS = {name: CHANNELS[name].topic for name in INPUTS}
"""The topic (relative name, DESIGN.md) that carries each input."""

UNITS = {name: CHANNELS[name].unit for name in INPUTS}
"""The SI unit of each input, as on its topic."""

FIELDS = {name: f'{CHANNELS[name].topic}.{CHANNELS[name].field}' for name in INPUTS}
"""The message field each input is read from, as named in diagnostics."""

REQUIRED = ('flow', 'p_in', 'p_out')
"""Inputs without which no prediction is made."""

NON_NEGATIVE = ('p_in', 'p_out', 'p_case')
"""Inputs whose negative values are invalid: absolute pressures (flow and speed are signed)."""

MODES = ('on_flow', 'rate')
"""Publish modes: on every flow_command, or at a fixed rate."""


class Level(enum.IntEnum):
    """Severity of a prediction's problems, as ``diagnostic_msgs/DiagnosticStatus`` levels."""

    OK = 0
    WARN = 1
    ERROR = 2


class InputState(enum.IntEnum):
    """Why an input can or cannot be used at a driving time."""

    FRESH = 0  # arrived within the timeout, value valid
    MISSING = 1  # never arrived
    STALE = 2  # older than the timeout
    NOT_FINITE = 3  # NaN or inf
    NEGATIVE = 4  # negative absolute pressure
    BEYOND_LIMIT = 5  # finite but beyond any motor (model.screening.CEILINGS): a broken message


@dataclass(frozen=True)
class Rule:
    """
    When predictions are made and which inputs they may use.

    Parameters
    ----------
    timeout : float
        Oldest age of an input that a prediction may use, [s]
    mode : {'on_flow', 'rate'}
        Predict on every flow_command, or at a fixed rate, [-]
    rate : float
        Prediction rate in ``'rate'`` mode, [Hz]

    """

    timeout: float = 0.5  # [s]
    mode: str = 'on_flow'  # 'on_flow' or 'rate'
    rate: float = 50.0  # [Hz]

    def __post_init__(self) -> None:
        """Reject values the rule cannot run with, naming the field."""
        if not (math.isfinite(self.timeout) and 0.0 < self.timeout <= 86400.0):
            raise ValueError(f'timeout = {self.timeout!r} s: must be in (0, 86400]')
        if self.mode not in MODES:
            raise ValueError(f'mode = {self.mode!r}: use one of {", ".join(MODES)}')
        if not (math.isfinite(self.rate) and 1.0e-3 <= self.rate <= 10000.0):
            raise ValueError(f'rate = {self.rate!r} Hz: must be in [0.001, 10000]')

    @property
    def timeout_ns(self) -> int:
        """Return the timeout in integer nanoseconds, [ns]."""
        return int(round(self.timeout * 1e9))

    @property
    def period_ns(self) -> int:
        """Return the prediction period in ``'rate'`` mode, [ns]."""
        return int(round(1e9 / self.rate))


_FLOAT_MAX = sys.float_info.max
# plain ints: an enum member looked up on its class costs a microsecond per message
_FRESH, _MISSING, _STALE, _NOT_FINITE, _NEGATIVE, _BEYOND = (int(s) for s in InputState)
_CEILINGS = {name: CEILINGS.get(UNITS[name], math.inf) for name in INPUTS}


def input_state(name: str, value: Any, age_ns: Any, timeout_ns: int) -> Any:
    """
    Rate an input at a driving time: one value (float) or many (array) alike.

    Parameters
    ----------
    name : str
        Input name, one of :data:`INPUTS`, [-]
    value : float or ndarray
        Its latest value, [unit of the input]
    age_ns : float or ndarray
        Driving time minus its arrival; NaN when it never arrived, [ns]
    timeout_ns : int
        The rule's timeout, [ns]

    Returns
    -------
    int or ndarray of int
        An :class:`InputState`: FRESH, MISSING, STALE, NOT_FINITE, NEGATIVE or
        BEYOND_LIMIT.

    """
    # Operators only, so that Python's bools and numpy's bool arrays go through alike:
    # state + condition * (new - state) is `new` where the condition holds, later ones win.
    state = ((value < 0.0) & (name in NON_NEGATIVE)) * _NEGATIVE
    # a finite value no motor reaches (6.3e8 rad/s) is a broken message: never used, so that
    # it cannot feed the revolutions counter or any other state that outlives the message
    state += (abs(value) > _CEILINGS[name]) * (_BEYOND - state)
    state += ((value != value) | (abs(value) > _FLOAT_MAX)) * (_NOT_FINITE - state)
    state += (age_ns > timeout_ns) * (_STALE - state)
    state += (age_ns != age_ns) * (_MISSING - state)  # NaN age: never arrived
    return state


def input_states(values: Sequence[float] | npt.NDArray[np.float64],
                 ages_ns: Sequence[float] | npt.NDArray[np.float64],
                 timeout_ns: int) -> list[Any]:
    """
    Rate every input at a driving time (floats) or at many (rows of arrays).

    Parameters
    ----------
    values : sequence
        Per input of :data:`INPUTS`: its latest value(s), [unit of the input]
    ages_ns : sequence
        Per input: driving time(s) minus arrival; NaN where it never arrived, [ns]
    timeout_ns : int
        The rule's timeout, [ns]

    Returns
    -------
    list
        Per input: an :class:`InputState` value (or an array of them). An outlet pressure
        above the inlet pressure is fine: a negative drop (doc/quadrants.md).

    """
    return [input_state(name, value, age, timeout_ns)
            for name, value, age in zip(INPUTS, values, ages_ns)]


class Snapshot(NamedTuple):
    """The inputs of one prediction: the latest value, age and state of each."""

    stamp_ns: int  # driving time [ns]
    values: tuple[float, ...]  # per input of INPUTS; NaN when missing [unit of the input]
    ages: tuple[float, ...]  # per input: driving time minus arrival; NaN when missing [s]
    states: tuple[int, ...]  # per input: an InputState


class Combiner:
    """
    The rule applied live: keep each input's latest value, snapshot at a driving time.

    Parameters
    ----------
    rule : Rule
        Timeout and mode, [-]

    """

    def __init__(self, rule: Rule) -> None:
        """Start with no input received."""
        self.rule = rule
        self._values = [math.nan] * len(INPUTS)
        self._times: list[int | None] = [None] * len(INPUTS)

    def update(self, name: str, value: float, t_ns: int) -> None:
        """
        Record the latest value of an input.

        Parameters
        ----------
        name : str
            Input name, one of :data:`INPUTS`, [-]
        value : float
            The value, [unit of the input]
        t_ns : int
            Arrival time on the node's clock, [ns]

        """
        i = INPUTS.index(name)
        self._values[i] = float(value)
        self._times[i] = int(t_ns)

    def snapshot(self, t_ns: int) -> Snapshot:
        """
        Take the inputs a prediction at time `t_ns` may use.

        Parameters
        ----------
        t_ns : int
            Driving time on the node's clock, [ns]

        Returns
        -------
        Snapshot
            Values, ages and states of every input.

        """
        ages_ns = [math.nan if t is None else float(t_ns - t) for t in self._times]
        states = input_states(self._values, ages_ns, self.rule.timeout_ns)
        return Snapshot(int(t_ns), tuple(self._values), tuple(a * 1e-9 for a in ages_ns),
                        tuple(states))


class SnapshotBatch(NamedTuple):
    """The inputs of many predictions, as arrays (see :class:`Snapshot`)."""

    stamp_ns: npt.NDArray[np.int64]  # driving times [ns]
    values: npt.NDArray[np.float64]  # (len(INPUTS), n) [unit of the input]
    ages: npt.NDArray[np.float64]  # (len(INPUTS), n) [s]
    states: npt.NDArray[np.uint8]  # (len(INPUTS), n) InputState


def driving_times(rule: Rule, flow_t_ns: npt.NDArray[np.int64], first_ns: int,
                  last_ns: int) -> npt.NDArray[np.int64]:
    """
    Return the times at which predictions are made over a recording.

    Parameters
    ----------
    rule : Rule
        The rule, [-]
    flow_t_ns : ndarray of int64
        Arrival times of flow_command, [ns]
    first_ns, last_ns : int
        Times of the first and last message of the recording, [ns]

    Returns
    -------
    ndarray of int64
        Every flow_command's time (``'on_flow'``), or ticks of the rate from the first
        message on (``'rate'``), [ns]

    Raises
    ------
    ValueError
        If the rate asks for more than :data:`~satmotor_ros.limits.RATE_MAX_PREDICTIONS`.

    """
    if rule.mode == 'on_flow':
        return np.array(flow_t_ns, dtype=np.int64)
    if last_ns < first_ns:
        return np.zeros(0, dtype=np.int64)
    count = (last_ns - first_ns) // rule.period_ns + 1
    if count > RATE_MAX_PREDICTIONS:
        raise ValueError(f'rate = {rule.rate:g} Hz over {(last_ns - first_ns) / 1e9:.6g} s asks '
                         f'for {count} predictions, more than {RATE_MAX_PREDICTIONS} '
                         '(SATMOTOR_RATE_MAX_PREDICTIONS)')
    return np.arange(first_ns, last_ns + 1, rule.period_ns, dtype=np.int64)


def combine_batch(rule: Rule, stamps_ns: npt.NDArray[np.int64],
                  inputs: dict[str, tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]],
                  ) -> SnapshotBatch:
    """
    Apply the rule to whole recorded series at once (what the live node does per message).

    An input recorded at the same nanosecond as a driving time counts as received before it.

    Parameters
    ----------
    rule : Rule
        Timeout, [-]
    stamps_ns : ndarray of int64
        Driving times, ascending, [ns]
    inputs : dict
        Input name -> (arrival times ascending [ns], values [unit of the input]); absent
        inputs never arrived, [-]

    Returns
    -------
    SnapshotBatch
        Values, ages and states per input and driving time.

    """
    stamps_ns = np.asarray(stamps_ns, dtype=np.int64)
    values = np.full((len(INPUTS), len(stamps_ns)), np.nan)
    ages_ns = np.full((len(INPUTS), len(stamps_ns)), np.nan)
    for i, name in enumerate(INPUTS):
        if name not in inputs or len(inputs[name][0]) == 0:
            continue
        t, v = inputs[name]
        idx = np.searchsorted(t, stamps_ns, side='right') - 1
        seen = idx >= 0
        at = np.where(seen, idx, 0)
        values[i] = np.where(seen, v[at], np.nan)
        ages_ns[i] = np.where(seen, stamps_ns - t[at], np.nan)
    states = np.array(input_states(values, ages_ns, rule.timeout_ns), dtype=np.uint8)
    return SnapshotBatch(stamps_ns, values, ages_ns * 1e-9, states)


def input_level(name: str, state: int) -> Level:
    """
    Rate the :class:`InputState` of input `name` by what it means for the prediction.

    ERROR when no prediction may be made, WARN when it is made without this input, else OK.
    """
    if state == InputState.FRESH:
        return Level.OK
    if name in REQUIRED:
        return Level.ERROR
    if state == InputState.MISSING:
        return Level.OK  # optional input not published: not a problem
    return Level.ERROR if name == 'p_case' else Level.WARN


def describe_input(name: str, state: int, value: float, age: float, timeout: float) -> str:
    """
    Spell out what is wrong with an input, naming the field and the value.

    Parameters
    ----------
    name : str
        Input name, [-]
    state : int
        Its :class:`InputState`, [-]
    value : float
        Its latest value, [unit of the input]
    age : float
        Its age at the driving time, [s]
    timeout : float
        The input timeout, [s]

    Returns
    -------
    str
        One line, e.g. ``'inlet_pressure.fluid_pressure = nan Pa: not finite'``.

    """
    field, unit = FIELDS[name], UNITS[name]
    if state == InputState.MISSING:
        return f'{TOPICS[name]}: no message received'
    if state == InputState.STALE:
        return f'{TOPICS[name]}: last message {age:.3g} s old (input_timeout {timeout:g} s)'
    if state == InputState.NOT_FINITE:
        return f'{field} = {value!r} {unit}: not finite'
    if state == InputState.NEGATIVE:
        return f'{field} = {value!r} {unit}: negative'
    if state == InputState.BEYOND_LIMIT:
        return (f'{field} = {value!r} {unit}: beyond any motor (limit '
                f'{_CEILINGS[name]:g} {unit}), ignored')
    return f'{field} = {value!r} {unit}: ok'
