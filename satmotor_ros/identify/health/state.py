# SPDX-License-Identifier: Apache-2.0
"""
A saved health state read back: checked field by field before anything is built from it.

A state file is a user's file too: edited by hand, cut short by a full disk, copied from
another version. :func:`check_state` compares what was read with the layout a fresh monitor
saves (:func:`template` gives it) and refuses the first field that is missing, unknown or of
another kind, naming it (``cusum.up``, ``alarms[2].kind``), so that
:meth:`~satmotor_ros.identify.health.HealthMonitor.resume` raises one
:class:`~satmotor_ros.identify.errors.DataError` line and never a TypeError or KeyError from
deep inside.
"""

from __future__ import annotations

from dataclasses import asdict, fields
from typing import Any

import numpy as np

from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.health.records import Alarm, HealthSettings, SKIP_REASONS

SAMPLE_COLUMNS = ('time', 'speed', 'flow', 'p_in', 'p_out')
"""Columns every saved block of samples has (arrays of one length)."""

OPTIONAL_COLUMNS = ('p_case', 'temperature', 'stale')
"""Columns a saved block may hold as None."""

ROWS = {'window': 3, 'learn_bins': 6, 'trend_bins': 5}
"""Lists of rows of numbers, and the numbers in a row."""


def compatible(state: dict[str, Any]) -> dict[str, Any]:
    """
    Fill in what a state of the same version saved before a field existed lacks.

    Parameters
    ----------
    state : dict
        The state as read, [-]

    Returns
    -------
    dict
        The state with ``step_s``, ``carry`` and every skip reason present.

    """
    state.setdefault('step_s', 0.0)  # saved before the bins followed the step
    state.setdefault('trend_bins', [])  # before a change restarted the trend where it began
    if 'carry' not in state and isinstance(state.get('open_bin'), np.ndarray):
        state['carry'] = np.zeros_like(state['open_bin'])  # before a thin bin joined the next
    if isinstance(state.get('skipped'), dict):  # before a reason was counted
        state['skipped'] = {**dict.fromkeys(SKIP_REASONS, 0), **state['skipped']}
    return state


def check_settings(saved: Any, path: str) -> HealthSettings:
    """
    Return the settings a state was saved with, or refuse them naming the field.

    Parameters
    ----------
    saved : Any
        The state's ``settings``, [-]
    path : str
        The file, for the message, [-]

    Returns
    -------
    HealthSettings
        The settings.

    Raises
    ------
    DataError
        A field missing, unknown or of another kind, or a value the settings refuse.

    """
    if not isinstance(saved, dict):
        raise DataError(f'{path}: settings = {_short(saved)}: need a mapping')
    defaults = asdict(HealthSettings())
    for name, value in saved.items():
        if name not in defaults:
            raise DataError(f'{path}: settings.{name}: not a field of the health settings')
        default = defaults[name]
        if isinstance(default, bool):
            ok = isinstance(value, bool)
        else:
            ok = _number(value) or (value is None and _optional(name))
        if not ok:
            raise DataError(f'{path}: settings.{name} = {_short(value)}: need '
                            f'{"true or false" if isinstance(default, bool) else "a number"}')
    try:
        return HealthSettings(**saved)
    except DataError as err:
        raise DataError(f'{path}: settings.{err}') from None


def check_state(state: dict[str, Any], like: dict[str, Any], path: str) -> None:
    """
    Refuse a state that is not laid out as `like`, naming the first field that is not.

    Parameters
    ----------
    state : dict
        The state as read (:func:`compatible` applied, ``version``, ``baseline`` and
        ``settings`` already checked), [-]
    like : dict
        A fresh monitor's state as it reads back (:func:`template`), [-]
    path : str
        The file, for the message, [-]

    Raises
    ------
    DataError
        One line: the file, the field, what it holds and what it needs.

    """
    _check(state, like, '', path)
    alarms = len(state['alarms'])
    if not -1 <= state['pending'] < alarms:
        raise DataError(f'{path}: pending = {state["pending"]}: need -1 or an alarm\'s index '
                        f'(0 to {alarms - 1})')
    if not 0 <= state['acknowledged'] <= alarms:
        raise DataError(f'{path}: acknowledged = {state["acknowledged"]}: need 0 to {alarms} '
                        'alarms')
    if len(state['noise_rate']) != len(state['noise_residual']):
        raise DataError(f'{path}: noise_rate, noise_residual: need as many blocks of each')


def _check(value: Any, like: Any, where: str, path: str) -> None:
    """Compare `value` with `like` recursively; raise at the first difference."""
    def refuse(need: str) -> None:
        raise DataError(f'{path}: {where or "the state"} = {_short(value)}: need {need}')

    if isinstance(like, dict):
        if not isinstance(value, dict):
            refuse('a mapping')
        for key in like:
            if key not in value:
                raise DataError(f'{path}: {_at(where, key)}: missing (a truncated or edited '
                                'state?)')
        for key in value:
            if key not in like:
                raise DataError(f'{path}: {_at(where, key)}: not a field of the health state')
            _check(value[key], like[key], _at(where, key), path)
    elif isinstance(like, np.ndarray):
        if not isinstance(value, np.ndarray) or value.dtype != like.dtype \
                or value.shape != like.shape:
            refuse(f'{like.size} numbers')
    elif isinstance(like, list):
        if not isinstance(value, list):
            refuse('a list')
        if like:
            if len(value) != len(like):
                refuse(f'{len(like)} entries')
            for k, (item, model) in enumerate(zip(value, like)):
                _check(item, model, f'{where}[{k}]', path)
        else:
            for k, item in enumerate(value):
                _element(item, where, f'{where}[{k}]', path)
    elif isinstance(like, bool):
        if not isinstance(value, bool):
            refuse('true or false')
    elif isinstance(like, int):
        if not isinstance(value, int) or isinstance(value, bool):
            refuse('a whole number')
    elif isinstance(like, float):
        if not _number(value):
            refuse('a number')
    elif isinstance(like, str):
        if not isinstance(value, str):
            refuse('a string')


def _element(item: Any, name: str, where: str, path: str) -> None:
    """Check one entry of a list a fresh state holds empty."""
    def refuse(need: str) -> None:
        raise DataError(f'{path}: {where} = {_short(item)}: need {need}')

    if name in ROWS:
        if not (isinstance(item, list) and len(item) == ROWS[name]
                and all(_number(x) for x in item)):
            refuse(f'{ROWS[name]} numbers')
    elif name == 'alarms':
        _check(item, asdict(Alarm(0.0, 'change', '', 0.0)), where, path)
        if item['kind'] not in ('change', 'limit'):
            raise DataError(f"{path}: {where}.kind = {_short(item['kind'])}: need 'change' or "
                            "'limit'")
    elif name in ('recent', 'held'):
        _samples(item, where, path)
    elif name in ('noise_rate', 'noise_residual'):
        if not (isinstance(item, np.ndarray) and item.ndim == 1 and item.dtype == float):
            refuse('a list of numbers')
    else:
        refuse('nothing (a fresh state holds none)')


def _samples(item: Any, where: str, path: str) -> None:
    """Check a saved block of samples: five arrays of one length, three optional ones."""
    if not isinstance(item, dict):
        raise DataError(f'{path}: {where} = {_short(item)}: need a block of samples')
    known = (*SAMPLE_COLUMNS, *OPTIONAL_COLUMNS)
    for key in item:
        if key not in known:
            raise DataError(f'{path}: {_at(where, key)}: not a column of the samples')
    length = None
    for key in known:
        value = item.get(key)
        if value is None and key in OPTIONAL_COLUMNS:
            continue
        kind = bool if key == 'stale' else float
        if not (isinstance(value, np.ndarray) and value.ndim == 1 and value.dtype == kind):
            raise DataError(f'{path}: {_at(where, key)} = {_short(value)}: need a list of '
                            f'{"booleans" if kind is bool else "numbers"}')
        if length is not None and value.size != length:
            raise DataError(f'{path}: {_at(where, key)}: {value.size} values for {length} '
                            'times')
        length = value.size


def template(state: dict[str, Any]) -> dict[str, Any]:
    """
    Return a fresh monitor's state as it reads back from a file: the layout to compare with.

    Parameters
    ----------
    state : dict
        A fresh monitor's ``_state()``, [-]

    Returns
    -------
    dict
        Tuples as lists, arrays as float or bool arrays, NaN as float (as JSON gives them).

    """
    def back(x: Any) -> Any:
        if isinstance(x, dict):
            return {k: back(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [back(v) for v in x]
        if isinstance(x, np.ndarray):
            return x.astype(bool if x.dtype == bool else float)
        if isinstance(x, np.floating):
            return float(x)
        if isinstance(x, np.integer):
            return int(x)
        return x
    return {k: back(v) for k, v in state.items()}


def _number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _optional(name: str) -> bool:
    """Return whether a settings field may be None (its annotation says so)."""
    return any(f.name == name and 'None' in str(f.type) for f in fields(HealthSettings))


def _at(where: str, key: str) -> str:
    return f'{where}.{key}' if where else key


def _short(x: Any) -> str:
    """Return a value for a message: its repr, cut at 40 characters."""
    if isinstance(x, np.ndarray):
        return f'{x.size} values'
    text = repr(x)
    return text if len(text) <= 40 else text[:37] + '...'


__all__ = ['check_settings', 'check_state', 'compatible', 'template']
