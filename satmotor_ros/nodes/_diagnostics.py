# SPDX-License-Identifier: Apache-2.0
"""DiagnosticStatus and DiagnosticArray messages from plain Python values."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
import math

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.time import Time
from satmotor_ros.model.units import LPM, MPA, RPM

NOT_AVAILABLE = 'n/a'
"""What a value that is not there (NaN, None) shows: never 'nan'."""

HUMAN_UNITS = {'m^3/s': ('l/min', LPM, 4), 'Pa': ('MPa', MPA, 4), 'rad/s': ('rpm', RPM, 2),
               'degC': ('degC', 1.0, 2), 's': ('s', 1.0, 3)}
"""SI unit -> the unit a person reads (hydraulic units, the human edge), its size in SI and
the decimals shown: a flow of 1.96e-21 m^3/s reads 0.0000 l/min."""


def human(value: float | None, si_unit: str) -> tuple[str, str]:
    """
    Show an SI value in the unit a person reads, with fixed decimals.

    Parameters
    ----------
    value : float or None
        The value; NaN or None when there is none, [si_unit]
    si_unit : str
        Its SI unit, a key of :data:`HUMAN_UNITS` (others are shown as they are), [-]

    Returns
    -------
    tuple of str
        The unit shown and the text (:data:`NOT_AVAILABLE` for no value), e.g.
        ``('l/min', '5.0000')``.

    """
    unit, size, decimals = HUMAN_UNITS.get(si_unit, (si_unit, 1.0, 6))
    if value is None or value != value:
        return unit, NOT_AVAILABLE
    shown = value / size
    if not math.isfinite(shown):
        return unit, repr(shown)
    text = f'{shown:.{decimals}f}'
    return unit, text[1:] if text.startswith('-') and not float(text) else text  # no -0.00


def format_value(value: object) -> str:
    """
    Format a key-value's value: floats with 9 significant digits, NaN and None as 'n/a'.

    Parameters
    ----------
    value : object
        Number, string or flag, [-]

    Returns
    -------
    str
        The text.

    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return NOT_AVAILABLE
    if isinstance(value, float):
        return f'{value:.9g}'
    return str(value)


def status(name: str, hardware_id: str, level: int, message: str,
           values: Mapping[str, object]) -> DiagnosticStatus:
    """
    Build one DiagnosticStatus.

    Parameters
    ----------
    name : str
        Status name, conventionally ``'<node>: <what>'``, [-]
    hardware_id : str
        The device, [-]
    level : int
        OK 0, WARN 1, ERROR 2, STALE 3, [-]
    message : str
        One-line summary, [-]
    values : mapping
        Key -> value; keys carry their unit in brackets, [-]

    Returns
    -------
    DiagnosticStatus
        The status.

    """
    return DiagnosticStatus(level=bytes([int(level)]), name=name, message=message,
                            hardware_id=hardware_id,
                            values=[KeyValue(key=k, value=format_value(v))
                                    for k, v in values.items()])


def array(stamp: Time, statuses: Iterable[DiagnosticStatus]) -> DiagnosticArray:
    """
    Wrap statuses in a stamped DiagnosticArray.

    Parameters
    ----------
    stamp : rclpy.time.Time
        Time of the report, [-]
    statuses : iterable of DiagnosticStatus
        The statuses, [-]

    Returns
    -------
    DiagnosticArray
        The message.

    """
    msg = DiagnosticArray(status=list(statuses))
    msg.header.stamp = stamp.to_msg()
    return msg
