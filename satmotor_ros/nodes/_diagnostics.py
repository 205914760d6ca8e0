# SPDX-License-Identifier: Apache-2.0
"""DiagnosticStatus and DiagnosticArray messages from plain Python values."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
import math

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.time import Time


def format_value(value: object) -> str:
    """
    Format a key-value's value: floats with 9 significant digits, NaN as 'nan'.

    Parameters
    ----------
    value : object
        Number, string or flag, [-]

    Returns
    -------
    str
        The text.

    """
    if isinstance(value, float):
        return 'nan' if math.isnan(value) else f'{value:.9g}'
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
