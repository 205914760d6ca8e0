# SPDX-License-Identifier: Apache-2.0
"""
A minimal MCAP reader: channels and raw messages, walked record by record.

Reads every file MCAP's specification allows for ROS 2 (chunked or not; chunks
uncompressed, zstd or lz4), whatever library wrote it, without parsing schemas: the
message layouts are known to :mod:`.decode`. Python only steps from record to record;
the message headers (channel, log time) and payload positions are then read for all
messages of a chunk at once with numpy. Message times are MCAP log times [ns].
"""

from __future__ import annotations

from pathlib import Path
import struct
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from satmotor_ros.bags.errors import BagError

MAGIC = b'\x89MCAP0\r\n'
_OP_FOOTER, _OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK = 0x02, 0x03, 0x04, 0x05, 0x06
_OP_DATA_END = 0x0F
_U16, _U32, _U64 = struct.Struct('<H'), struct.Struct('<I'), struct.Struct('<Q')
_RECORD = struct.Struct('<BQ')
_MESSAGE_HEADER = 22  # channel id u16, sequence u32, log time u64, publish time u64 [bytes]


class Channel(NamedTuple):
    """One MCAP channel: a topic with its type and encoding."""

    topic: str
    msgtype: str  # schema name, e.g. 'std_msgs/msg/Float64'
    encoding: str  # message encoding, e.g. 'cdr'


class Messages(NamedTuple):
    """Messages of one channel inside one buffer."""

    t_ns: npt.NDArray[np.int64]  # log times [ns]
    buf: npt.NDArray[np.uint8]  # the buffer holding the payloads
    offsets: npt.NDArray[np.int64]  # payload start in buf [bytes]
    lengths: npt.NDArray[np.int64]  # payload length [bytes]


class McapContent(NamedTuple):
    """What a walk over an MCAP file found."""

    channels: dict[int, Channel]  # by channel id
    counts: dict[int, int]  # messages per channel id
    parts: dict[int, list[Messages]]  # wanted channels: their messages, per chunk


def _string(buf: bytes, pos: int) -> tuple[str, int]:
    (n,) = _U32.unpack_from(buf, pos)
    return buf[pos + 4:pos + 4 + n].decode('utf-8', 'replace'), pos + 4 + n


def _decompress(kind: str, payload: bytes, name: str) -> bytes:
    if kind == '':
        return payload
    if kind == 'zstd':
        from backports import zstd
        return zstd.decompress(payload)
    if kind == 'lz4':
        import lz4.frame
        return lz4.frame.decompress(payload)
    msg = f'{name}: MCAP chunk compression {kind!r} is not supported (use zstd, lz4 or none)'
    raise BagError(msg)


def read_mcap(path: Path, wanted: set[str] | None) -> McapContent:
    """
    Walk an MCAP file and collect the messages of the wanted topics.

    Parameters
    ----------
    path : pathlib.Path
        The ``.mcap`` file, [-]
    wanted : set of str or None
        Topics whose messages to keep (None or empty: count only), [-]

    Returns
    -------
    McapContent
        Channels, message counts, and the messages of the wanted topics.

    Raises
    ------
    BagError
        If the file is not MCAP or is truncated.

    """
    buf = path.read_bytes()
    if buf[:8] != MAGIC:
        raise BagError(f'{path.name}: not an MCAP file (bad magic)')
    content = McapContent({}, {}, {})
    try:
        _walk(buf, 8, len(buf), content, {}, wanted or set(), path.name)
    except (struct.error, IndexError, ValueError):
        raise BagError(f'{path.name}: truncated or corrupt MCAP record') from None
    return content


def _walk(buf: bytes, pos: int, end: int, content: McapContent, schemas: dict[int, str],
          wanted: set[str], name: str) -> None:
    """Step through the records of `buf`; message records are handled in one batch."""
    unpack_record = _RECORD.unpack_from
    messages: list[int] = []
    add = messages.append
    while pos + 9 <= end:
        op, length = unpack_record(buf, pos)
        start = pos + 9
        pos = start + length
        if op == _OP_MESSAGE:
            add(start)
            continue
        if pos > end:
            break
        if op == _OP_CHUNK:
            kind, at = _string(buf, start + 28)
            (n,) = _U64.unpack_from(buf, at)
            inner = _decompress(kind, buf[at + 8:at + 8 + n], name)
            _walk(inner, 0, len(inner), content, schemas, wanted, name)
        elif op == _OP_SCHEMA:
            (schema_id,) = _U16.unpack_from(buf, start)
            schemas[schema_id], _ = _string(buf, start + 2)
        elif op == _OP_CHANNEL:
            channel_id, schema_id = struct.unpack_from('<HH', buf, start)
            topic, at = _string(buf, start + 4)
            encoding, _ = _string(buf, at)
            content.channels[channel_id] = Channel(topic, schemas.get(schema_id, ''), encoding)
        elif op in (_OP_DATA_END, _OP_FOOTER):
            end = pos = start
            break
    if pos > end:
        raise BagError(f'{name}: truncated MCAP record at byte {start - 9}')
    if messages:
        _collect(buf, np.array(messages, dtype=np.int64), end, content, wanted)


def _gather(raw: npt.NDArray[np.uint8], at: npt.NDArray[np.int64], dtype: str) -> np.ndarray:
    size = np.dtype(dtype).itemsize
    return np.lib.stride_tricks.sliding_window_view(raw, size)[at].view(dtype).reshape(-1)


def _collect(buf: bytes, starts: npt.NDArray[np.int64], end: int, content: McapContent,
             wanted: set[str]) -> None:
    """Read channel ids, log times and payload spans of the message records at `starts`."""
    raw = np.frombuffer(buf, dtype=np.uint8)
    lengths = _gather(raw, starts - 8, '<u8').astype(np.int64) - _MESSAGE_HEADER
    channel = _gather(raw, starts, '<u2')
    if len(lengths) and (lengths.min() < 0 or starts[-1] + _MESSAGE_HEADER + lengths[-1] > end):
        raise ValueError('message record beyond its buffer')
    ids, counts = np.unique(channel, return_counts=True)
    for channel_id, count in zip(ids.tolist(), counts.tolist()):
        content.counts[channel_id] = content.counts.get(channel_id, 0) + count
        known = content.channels.get(channel_id)
        if known is None or known.topic not in wanted:
            continue
        mine = starts[channel == channel_id]
        t_ns = _gather(raw, mine + 6, '<u8').astype(np.int64)
        content.parts.setdefault(channel_id, []).append(
            Messages(t_ns, raw, mine + _MESSAGE_HEADER, lengths[channel == channel_id]))


_OP_STATISTICS = 0x0B
_FOOTER = struct.Struct('<BQQQI')  # opcode, length, summary start, summary offset start, crc


def read_summary(path: Path) -> McapContent | None:
    """
    Read channels and message counts from the summary section, without a walk.

    Parameters
    ----------
    path : pathlib.Path
        The ``.mcap`` file, [-]

    Returns
    -------
    McapContent or None
        Channels and counts (no messages); None when the file has no summary with
        statistics, so that only a walk can count its messages.

    """
    with path.open('rb') as stream:
        size = stream.seek(0, 2)
        if size < 8 + _FOOTER.size + 8:
            return None
        stream.seek(size - 8 - _FOOTER.size)
        tail = stream.read(_FOOTER.size + 8)
        if tail[-8:] != MAGIC:
            return None
        op, _, start, _, _ = _FOOTER.unpack_from(tail)
        footer = size - 8 - _FOOTER.size
        if op != _OP_FOOTER or not 8 <= start < footer:
            return None
        stream.seek(start)
        summary = stream.read(footer - start)
    content = McapContent({}, {}, {})
    schemas: dict[int, str] = {}
    found_statistics = False
    pos = 0
    try:
        while pos + 9 <= len(summary):
            op, length = _RECORD.unpack_from(summary, pos)
            at, pos = pos + 9, pos + 9 + length
            if op == _OP_SCHEMA:
                (schema_id,) = _U16.unpack_from(summary, at)
                schemas[schema_id], _ = _string(summary, at + 2)
            elif op == _OP_CHANNEL:
                channel_id, schema_id = struct.unpack_from('<HH', summary, at)
                topic, after = _string(summary, at + 4)
                encoding, _ = _string(summary, after)
                content.channels[channel_id] = Channel(topic, schemas.get(schema_id, ''),
                                                       encoding)
            elif op == _OP_STATISTICS:
                (n,) = _U32.unpack_from(summary, at + 42)
                for k in range(at + 46, at + 46 + n, 10):
                    channel_id, count = struct.unpack_from('<HQ', summary, k)
                    content.counts[channel_id] = count
                found_statistics = True
    except struct.error:
        return None
    return content if found_statistics else None
