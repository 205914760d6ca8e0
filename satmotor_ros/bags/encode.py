# SPDX-License-Identifier: Apache-2.0
"""CDR encoding of the fixed message layouts, one message or whole arrays at once."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import struct

import numpy as np
import numpy.typing as npt

from satmotor_ros.bags.decode import FIELDS, parse_layout
from satmotor_ros.bags.errors import BagError
from satmotor_ros.interface import FLOAT64, FLUID_PRESSURE, JOINT_STATE, TEMPERATURE


class _Writer:
    """Append little-endian CDR primitives, aligned relative to the payload."""

    def __init__(self) -> None:
        self.buf = bytearray(b'\x00\x01\x00\x00')

    def align(self, size: int) -> None:
        self.buf += b'\0' * ((-(len(self.buf) - 4)) % size)

    def pack(self, code: str, size: int, value: float) -> None:
        self.align(size)
        self.buf += struct.pack('<' + code, value)

    def string(self, text: str) -> None:
        raw = text.encode('utf-8') + b'\0'
        self.pack('I', 4, len(raw))
        self.buf += raw

    def doubles(self, values: Sequence[float]) -> None:
        self.pack('I', 4, len(values))
        if len(values):
            self.align(8)
            self.buf += struct.pack(f'<{len(values)}d', *values)


def encode_message(msgtype: str, values: Mapping[str, float], stamp_ns: int = 0,
                   frame_id: str = '', joints: Sequence[str] = ()) -> bytes:
    """
    Serialise one message.

    Parameters
    ----------
    msgtype : str
        One of the types of :data:`~satmotor_ros.bags.decode.FIELDS`, [-]
    values : mapping
        Field name -> value; a JointState field missing here is an empty sequence, and a
        present one holds one value per joint (a float for a single joint), [SI]
    stamp_ns : int
        Header stamp, [ns]
    frame_id : str
        Header frame, [-]
    joints : sequence of str
        JointState only: the joint names, [-]

    Returns
    -------
    bytes
        The CDR message with its encapsulation header.

    """
    out = _Writer()
    if msgtype == FLOAT64:
        out.pack('d', 8, float(values['data']))
        return bytes(out.buf)
    sec, nsec = divmod(int(stamp_ns), 1_000_000_000)
    out.pack('i', 4, sec)
    out.pack('I', 4, nsec)
    out.string(frame_id)
    if msgtype in (FLUID_PRESSURE, TEMPERATURE):
        for name in FIELDS[msgtype]:
            out.pack('d', 8, float(values.get(name, 0.0)))
    elif msgtype == JOINT_STATE:
        out.pack('I', 4, len(joints))
        for joint in joints:
            out.string(joint)
        for name in FIELDS[JOINT_STATE]:
            out.doubles([float(v) for v in np.atleast_1d(values.get(name, np.empty(0)))])
    else:
        raise BagError(f'{msgtype} has no encoder (supported: {", ".join(FIELDS)})')
    return bytes(out.buf)


def encode_many(msgtype: str, fields: Mapping[str, npt.ArrayLike],
                stamp_ns: npt.ArrayLike | None = None, frame_id: str = '',
                joint: str | None = None) -> list[bytes]:
    """
    Serialise many messages of one layout at once.

    Parameters
    ----------
    msgtype : str
        One of the types of :data:`~satmotor_ros.bags.decode.FIELDS`, [-]
    fields : mapping
        Field name -> one value per message; JointState fields missing here are empty
        sequences, [SI]
    stamp_ns : array_like of int, optional
        Header stamps, [ns]
    frame_id : str
        Header frame of every message, [-]
    joint : str or None
        JointState only: the single joint's name, [-]

    Returns
    -------
    list of bytes
        One CDR message per element.

    """
    columns = {name: np.asarray(v, dtype=np.float64) for name, v in fields.items()}
    n = len(next(iter(columns.values())))
    stamps = (np.zeros(n, dtype=np.int64) if stamp_ns is None
              else np.asarray(stamp_ns, dtype=np.int64))
    if n == 0:
        return []
    joints = (joint,) if joint is not None else ()
    template = encode_message(msgtype, dict.fromkeys(columns, 0.0), 0, frame_id, joints)
    layout = parse_layout(msgtype, template, joint)
    size = len(template)
    grid = np.tile(np.frombuffer(template, dtype=np.uint8), (n, 1))
    flat = grid.reshape(-1)
    for name, offset in zip(FIELDS[msgtype], layout.fields):
        if name in columns and offset is not None:
            _column(flat, '<f8', offset, size, n)[:] = columns[name]
    if layout.stamp is not None:
        sec, nsec = np.divmod(stamps, 1_000_000_000)
        _column(flat, '<i4', layout.stamp, size, n)[:] = sec
        _column(flat, '<u4', layout.stamp + 4, size, n)[:] = nsec
    raw = grid.tobytes()
    return [raw[i:i + size] for i in range(0, n * size, size)]


def _column(flat: np.ndarray, dtype: str, offset: int, stride: int, n: int) -> np.ndarray:
    view: np.ndarray = np.ndarray((n,), dtype=dtype, buffer=flat, offset=offset,
                                  strides=(stride,))  # numpy types this constructor as Any
    return view
