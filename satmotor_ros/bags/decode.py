# SPDX-License-Identifier: Apache-2.0
"""
Fast CDR decoding of the fixed message layouts: Float64, FluidPressure, Temperature, JointState.

A generic deserialiser walks every message field by field (rosbags' deserialize_cdr: 2.5 us
a FluidPressure, 6 us a JointState; here 0.08 and 0.22 us, measured on 3.6e5 of each).
These layouts are fixed up to their strings and sequence lengths, so messages are grouped
by length; one message per group is parsed in Python to find where each number sits and
which bytes carry the structure (lengths, joint names); every message of the group whose
structure bytes match is then read with strided numpy views. Messages that do not match
(another frame_id, other joints) are parsed one by one, so the result never depends on
the shortcut.
"""

from __future__ import annotations

from collections.abc import Sequence
import struct
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from satmotor_ros.bags.errors import BagError
from satmotor_ros.interface import FLOAT64, FLUID_PRESSURE, JOINT_STATE, TEMPERATURE

FIELDS = {
    FLOAT64: ('data',),
    FLUID_PRESSURE: ('fluid_pressure', 'variance'),
    TEMPERATURE: ('temperature', 'variance'),
    JOINT_STATE: ('position', 'velocity', 'effort'),
}
"""The float fields decoded per message type (JointState: of the chosen joint), SI."""


class Layout(NamedTuple):
    """Where the numbers of one message sit, and which bytes carry its structure."""

    stamp: int | None  # byte offset of header.stamp.sec (nanosec follows); None: no header
    fields: tuple[int | None, ...]  # byte offset of each FIELDS value; None: absent (NaN)
    structure: tuple[tuple[int, int], ...]  # (start, stop) byte ranges that must match
    little: bool  # little-endian CDR


class _Cursor:
    """Read CDR primitives with alignment relative to the payload after the 4-byte header."""

    def __init__(self, data: bytes) -> None:
        if len(data) < 4 or data[0] != 0 or data[1] not in (0, 1):
            raise BagError(f'not a CDR message (encapsulation {bytes(data[:4])!r})')
        self.data, self.pos = data, 4
        self.little = data[1] == 1
        self.order = '<' if self.little else '>'
        self.structure: list[tuple[int, int]] = [(0, 2)]

    def align(self, size: int) -> None:
        self.pos += (-(self.pos - 4)) % size

    def number(self, code: str, size: int, structural: bool = False) -> tuple[int, float]:
        self.align(size)
        at = self.pos
        (value,) = struct.unpack_from(self.order + code, self.data, at)
        self.pos += size
        if structural:
            self.structure.append((at, at + size))
        return at, value

    def string(self, structural: bool = False) -> str:
        n = int(self.number('I', 4, structural=True)[1])
        at = self.pos
        self.pos += n
        if self.pos > len(self.data):
            raise struct.error('string beyond the end of the message')
        if structural:
            self.structure.append((at, at + n))
        return bytes(self.data[at:at + n]).rstrip(b'\0').decode('utf-8', 'replace')

    def doubles(self) -> list[int]:
        n = int(self.number('I', 4, structural=True)[1])
        if n:
            self.align(8)
        at = self.pos
        self.pos += 8 * n
        if self.pos > len(self.data):
            raise struct.error('sequence beyond the end of the message')
        return [at + 8 * i for i in range(n)]


def parse_layout(msgtype: str, data: bytes, joint: str | None = None) -> Layout:
    """
    Parse one message far enough to know where its numbers are.

    Parameters
    ----------
    msgtype : str
        One of the types of :data:`FIELDS`, [-]
    data : bytes
        The serialised message, with its 4-byte CDR encapsulation header, [-]
    joint : str or None
        JointState only: the joint whose values to take (None: the first), [-]

    Returns
    -------
    Layout
        Offsets of the stamp and the fields, and the structure byte ranges.

    Raises
    ------
    BagError
        If the bytes are not a CDR message of that type.

    """
    cur = _Cursor(data)
    try:
        if msgtype == FLOAT64:
            at, _ = cur.number('d', 8)
            layout = Layout(None, (at,), (), cur.little)
        else:
            stamp, _ = cur.number('i', 4)
            cur.number('I', 4)
            cur.string()  # frame_id: its length is structure, its text is not
            if msgtype in (FLUID_PRESSURE, TEMPERATURE):
                value, _ = cur.number('d', 8)
                variance, _ = cur.number('d', 8)
                layout = Layout(stamp, (value, variance), (), cur.little)
            elif msgtype == JOINT_STATE:
                layout = _joint_layout(cur, stamp, joint)
            else:
                raise BagError(f'{msgtype} has no fast decoder')
    except struct.error:
        raise BagError(f'a {msgtype} message of {len(data)} bytes is truncated') from None
    if cur.pos > len(data):
        raise BagError(f'a {msgtype} message of {len(data)} bytes is truncated')
    return layout._replace(structure=tuple(cur.structure))


def _joint_layout(cur: _Cursor, stamp: int, joint: str | None) -> Layout:
    count = int(cur.number('I', 4, structural=True)[1])
    names = [cur.string(structural=True) for _ in range(count)]
    sequences = [cur.doubles() for _ in range(3)]
    if joint is None:
        index = 0 if names else None
    else:
        index = names.index(joint) if joint in names else None
    if index is None:
        return Layout(stamp, (), (), cur.little)  # no such joint: no fields at all
    return Layout(stamp, tuple(s[index] if index < len(s) else None for s in sequences), (),
                  cur.little)


class Decoded(NamedTuple):
    """Decoded messages of one topic."""

    keep: npt.NDArray[np.bool_]  # per message: it holds the values (JointState: the joint)
    stamp_ns: npt.NDArray[np.int64] | None  # header stamps of the kept messages [ns]
    fields: dict[str, npt.NDArray[np.float64]]  # per FIELDS name, kept messages [SI]


def pack_payloads(payloads: Sequence[bytes]) -> tuple[npt.NDArray[np.uint8],
                                                      npt.NDArray[np.int64],
                                                      npt.NDArray[np.int64]]:
    """
    Pack serialised messages back to back into one buffer.

    Parameters
    ----------
    payloads : sequence of bytes
        The serialised messages, [-]

    Returns
    -------
    tuple of ndarray
        The buffer (uint8), the offset and the length of each message (int64), [bytes]

    """
    lengths = np.fromiter(map(len, payloads), dtype=np.int64, count=len(payloads))
    offsets = np.zeros(len(payloads), dtype=np.int64)
    np.cumsum(lengths[:-1], out=offsets[1:])
    return np.frombuffer(b''.join(payloads), dtype=np.uint8), offsets, lengths


def decode(msgtype: str, buf: npt.NDArray[np.uint8], offsets: npt.NDArray[np.int64],
           lengths: npt.NDArray[np.int64], joint: str | None = None) -> Decoded:
    """
    Decode the messages of one topic, packed in one buffer, into arrays.

    Parameters
    ----------
    msgtype : str
        One of the types of :data:`FIELDS`, [-]
    buf : ndarray of uint8
        The serialised messages, back to back or not (:func:`pack_payloads` packs a list), [-]
    offsets, lengths : ndarray of int64
        Where each message starts in `buf`, and its length, [bytes]
    joint : str or None
        JointState only: the joint to take (None: the first of each message), [-]

    Returns
    -------
    Decoded
        Which messages hold values, their header stamps and their fields.

    Raises
    ------
    BagError
        If the type has no fast decoder or a message is not of that type.

    """
    if msgtype not in FIELDS:
        raise BagError(f'{msgtype} has no fast decoder (supported: {", ".join(FIELDS)})')
    n = len(offsets)
    fields = {name: np.full(n, np.nan) for name in FIELDS[msgtype]}
    stamps = np.zeros(n, dtype=np.int64)
    keep = np.zeros(n, dtype=bool)
    sizes = np.unique(lengths)
    for length in sizes.tolist():
        rows = np.flatnonzero(lengths == length) if len(sizes) > 1 else np.arange(n)
        grid = gather_rows(buf, offsets[rows], length)
        _decode_group(msgtype, grid, rows, joint, fields, stamps, keep)
    has_header = msgtype != FLOAT64
    return Decoded(keep, stamps[keep] if has_header else None,
                   {name: values[keep] for name, values in fields.items()})


def gather_rows(buf: npt.NDArray[np.uint8], starts: npt.NDArray[np.int64],
                length: int) -> npt.NDArray[np.uint8]:
    """
    Copy `length` bytes from each start into the rows of a 2-D array.

    Parameters
    ----------
    buf : ndarray of uint8
        The bytes, [-]
    starts : ndarray of int64
        Where each row starts in `buf`, [bytes]
    length : int
        Bytes per row, [bytes]

    Returns
    -------
    ndarray of uint8
        Shape (len(starts), length); a view of `buf` when the rows lie back to back.

    """
    if length == 0 or not len(starts):
        return np.zeros((len(starts), length), dtype=np.uint8)
    if starts[0] + length * (len(starts) - 1) == starts[-1] \
            and (np.diff(starts) == length).all():
        return buf[starts[0]:starts[0] + length * len(starts)].reshape(-1, length)
    return np.lib.stride_tricks.sliding_window_view(buf, length)[starts]


def _column(grid: npt.NDArray[np.uint8], dtype: str, offset: int) -> np.ndarray:
    size = np.dtype(dtype).itemsize
    return np.ascontiguousarray(grid[:, offset:offset + size]).view(dtype).reshape(-1)


def _decode_group(msgtype: str, grid: npt.NDArray[np.uint8], rows: npt.NDArray[np.intp],
                  joint: str | None, fields: dict[str, np.ndarray], stamps: np.ndarray,
                  keep: np.ndarray) -> None:
    """Decode the messages `rows`, the rows of `grid` (all of one length), in place."""
    if grid.shape[1] == 0:
        raise BagError(f'a {msgtype} message is empty')
    layout = parse_layout(msgtype, grid[0].tobytes(), joint)
    same = np.ones(len(rows), dtype=bool)
    for start, stop in layout.structure:
        same &= (grid[:, start:stop] == grid[0, start:stop]).all(axis=1)
    if not same.all():  # another layout hides among messages of this length
        for k in np.flatnonzero(~same).tolist():
            _decode_one(msgtype, grid[k].tobytes(), int(rows[k]), joint, fields, stamps, keep)
        grid, rows = grid[same], rows[same]
    if not len(rows) or (msgtype == JOINT_STATE and not layout.fields):
        return
    order = '<' if layout.little else '>'
    for name, offset in zip(FIELDS[msgtype], layout.fields):
        if offset is not None:
            fields[name][rows] = _column(grid, order + 'f8', offset)
    if layout.stamp is not None:
        sec = _column(grid, order + 'i4', layout.stamp).astype(np.int64)
        nsec = _column(grid, order + 'u4', layout.stamp + 4)
        stamps[rows] = sec * 1_000_000_000 + nsec
    keep[rows] = True


def _decode_one(msgtype: str, data: bytes, i: int, joint: str | None,
                fields: dict[str, np.ndarray], stamps: np.ndarray, keep: np.ndarray) -> None:
    layout = parse_layout(msgtype, data, joint)
    if msgtype == JOINT_STATE and not layout.fields:
        return
    order = '<' if layout.little else '>'
    for name, offset in zip(FIELDS[msgtype], layout.fields):
        if offset is not None:
            fields[name][i] = struct.unpack_from(order + 'd', data, offset)[0]
    if layout.stamp is not None:
        sec, nsec = struct.unpack_from(order + 'iI', data, layout.stamp)
        stamps[i] = sec * 1_000_000_000 + nsec
    keep[i] = True
