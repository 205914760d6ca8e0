# SPDX-License-Identifier: Apache-2.0
"""
rosbag2 storage: metadata, sqlite3 and MCAP files, raw messages by topic.

The storage files are read directly (sqlite3 queries, an MCAP record walk), for speed and
so that nothing is dropped silently: rosbags' reader matches metadata.yaml to storage on
type and QoS and returns no messages where they differ. Here the storage is the truth and
metadata.yaml is checked against it: a topic whose type or message count differs is an
error naming both. Bags of any metadata version (1-9), split into several files, with
zstd FILE or MESSAGE compression, or without metadata.yaml (storage files found in the
directory) are read.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
import re
import sqlite3
import tempfile
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from satmotor_ros.bags.decode import gather_rows
from satmotor_ros.bags.errors import BagError
from satmotor_ros.bags.mcap import McapContent, read_mcap, read_summary
import yaml

STORAGES = ('sqlite3', 'mcap')
"""Storage plugins that can be read."""

_ZSTD_MAGIC = b'\x28\xb5\x2f\xfd'
_SPLIT_INDEX = re.compile(r'_(\d+)\.(?:db3|mcap)(?:\.zstd)?$')


class TopicInfo(NamedTuple):
    """A topic as the storage holds it."""

    name: str
    msgtype: str  # normalised: 'pkg/msg/Type'
    serialization: str  # 'cdr' for ROS 2
    count: int  # type: ignore[assignment]  # messages in the storage (not tuple.count)


Found = Iterator[tuple[TopicInfo, list[tuple[np.ndarray, ...]]]]
"""What a storage file holds: each topic with its message parts (times, buffer, ...)."""


class RawTopic(NamedTuple):
    """The messages of one topic in log-time order, their payloads packed in one buffer."""

    t_ns: npt.NDArray[np.int64]  # log (receive) times [ns]
    buf: npt.NDArray[np.uint8]  # serialised payloads, back to back
    offsets: npt.NDArray[np.int64]  # start of each payload in buf [bytes]
    lengths: npt.NDArray[np.int64]  # length of each payload [bytes]

    def payload(self, i: int) -> bytes:
        """
        Return one serialised message.

        Parameters
        ----------
        i : int
            Index of the message, [-]

        Returns
        -------
        bytes
            The CDR payload.

        """
        start = int(self.offsets[i])
        return self.buf[start:start + int(self.lengths[i])].tobytes()


def pack_payloads(payloads: list[bytes]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Pack payloads back to back into one buffer.

    Parameters
    ----------
    payloads : list of bytes
        The serialised messages, [-]

    Returns
    -------
    tuple of ndarray
        The buffer (uint8), the offsets and the lengths (int64), [bytes]

    """
    lengths = np.fromiter(map(len, payloads), dtype=np.int64, count=len(payloads))
    offsets = np.zeros(len(payloads), dtype=np.int64)
    np.cumsum(lengths[:-1], out=offsets[1:])
    return np.frombuffer(b''.join(payloads), dtype=np.uint8), offsets, lengths


def _compact(parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]) -> RawTopic:
    """Join message parts (times, buffer, offsets, lengths) into one packed RawTopic."""
    if not parts:
        empty = np.zeros(0, dtype=np.int64)
        return RawTopic(empty, np.zeros(0, dtype=np.uint8), empty, empty)
    if len(parts) == 1 and parts[0][1].size == parts[0][3].sum():
        packed = RawTopic(*parts[0])  # already back to back (sqlite3)
        return _in_time_order(packed)
    t_ns = np.concatenate([p[0] for p in parts])
    lengths = np.concatenate([p[3] for p in parts])
    offsets = np.zeros(len(lengths), dtype=np.int64)
    np.cumsum(lengths[:-1], out=offsets[1:])
    chunks = []
    for _, buf, starts, sizes in parts:
        if len(sizes) and (sizes == sizes[0]).all():
            chunks.append(gather_rows(buf, starts, int(sizes[0])).reshape(-1))
        else:
            chunks.extend(buf[a:a + n] for a, n in zip(starts.tolist(), sizes.tolist()))
    return _in_time_order(RawTopic(t_ns, np.concatenate(chunks), offsets, lengths))


def _in_time_order(raw: RawTopic) -> RawTopic:
    t_ns = raw.t_ns
    if len(t_ns) > 1 and np.any(np.diff(t_ns) < 0):
        order = np.argsort(t_ns, kind='stable')
        return raw._replace(t_ns=t_ns[order], offsets=raw.offsets[order],
                            lengths=raw.lengths[order])
    return raw


def normalize_type(msgtype: str) -> str:
    """
    Give a message type its ``pkg/msg/Type`` form (Crystal-era bags wrote ``pkg/Type``).

    Parameters
    ----------
    msgtype : str
        Type name as stored, [-]

    Returns
    -------
    str
        The normalised name.

    """
    parts = msgtype.strip().split('/')
    return f'{parts[0]}/msg/{parts[1]}' if len(parts) == 2 else msgtype.strip()


@dataclass
class Bag:
    """
    An opened bag: where its files are and what its metadata says.

    Use :func:`open_bag`; then :meth:`read` for raw messages or :meth:`topics` for a list.
    """

    path: Path
    storage: str  # 'sqlite3' or 'mcap'
    files: list[Path]
    metadata: dict[str, TopicInfo] | None  # from metadata.yaml; None when absent
    _tmp: Any = field(default=None, repr=False)

    def topics(self, count: bool = True) -> dict[str, TopicInfo]:
        """
        List the topics of the storage, checked against metadata.yaml.

        Parameters
        ----------
        count : bool
            Count the messages of every topic; without, sqlite3 counts are -1 (not
            counted), which saves a pass over the messages table, [-]

        Returns
        -------
        dict
            Topic name -> :class:`TopicInfo`.

        Raises
        ------
        BagError
            If a storage file cannot be read or metadata.yaml disagrees with the storage.

        """
        if self.storage == 'mcap':
            summaries = [s for s in map(read_summary, self.files) if s is not None]
            if len(summaries) == len(self.files):
                infos: dict[str, TopicInfo] = {}
                for summary in summaries:
                    for info, _ in _mcap_topics(summary):
                        seen = infos.get(info.name)
                        infos[info.name] = info._replace(
                            count=info.count + (seen.count if seen else 0))
                self._check_metadata(infos)
                return infos
        return self.read((), count)[0]

    def read(self, names: tuple[str, ...] | list[str] | set[str], count: bool = False,
             ) -> tuple[dict[str, TopicInfo], dict[str, RawTopic]]:
        """
        Read the raw messages of some topics.

        Parameters
        ----------
        names : collection of str
            Full topic names as in the bag, [-]
        count : bool
            Also count the messages of the other topics (sqlite3: one more pass), [-]

        Returns
        -------
        tuple
            The storage's topics (name -> :class:`TopicInfo`) and the messages of the
            requested ones (name -> :class:`RawTopic`, log-time order).

        Raises
        ------
        BagError
            If a storage file cannot be read or metadata.yaml disagrees with the storage.

        """
        wanted = set(names)
        infos: dict[str, TopicInfo] = {}
        parts: dict[str, list[Any]] = {n: [] for n in wanted}
        for path in self.files:
            reader = _read_mcap_file if self.storage == 'mcap' else self._read_sqlite_file
            for info, pieces in reader(path, wanted, count):
                seen = infos.get(info.name)
                if seen is not None and seen.msgtype != info.msgtype:
                    raise BagError(f'{info.name} is {seen.msgtype} in one storage file and '
                                   f'{info.msgtype} in {path.name}')
                if seen is not None and min(seen.count, info.count) >= 0:
                    info = info._replace(count=info.count + seen.count)
                infos[info.name] = info
                if info.name in wanted:
                    parts[info.name].extend(pieces)
        self._check_metadata(infos)
        return infos, {name: _compact(parts[name]) for name in wanted & set(infos)}

    def _read_sqlite_file(self, path: Path, wanted: set[str],
                          count: bool) -> Found:
        if path.suffix == '.zstd':
            path = self._decompress_file(path)
        uri = f'{path.resolve().as_uri()}?mode=ro&immutable=1'
        try:
            db = sqlite3.connect(uri, uri=True)
        except sqlite3.Error as err:
            raise BagError(f'{path.name}: cannot open as sqlite3 ({err})') from None
        try:
            topics = db.execute('SELECT id, name, type, serialization_format FROM topics')\
                .fetchall()
            counts = dict(db.execute('SELECT topic_id, COUNT(*) FROM messages '
                                     'GROUP BY topic_id').fetchall()) if count else {}
            ids = {topic_id: name for topic_id, name, _, _ in topics if name in wanted}
            rows = db.execute(f'SELECT topic_id, timestamp, data FROM messages WHERE topic_id '
                              f'IN ({",".join(map(str, ids))})').fetchall() if ids else []
            which = np.fromiter((r[0] for r in rows), dtype=np.int64, count=len(rows))
            for topic_id, name, msgtype, fmt in topics:
                info = TopicInfo(name, normalize_type(msgtype), fmt,
                                 counts.get(topic_id, 0 if count else -1))
                if topic_id not in ids:
                    yield (info if count else info._replace(count=-1)), []
                    continue
                mine = np.flatnonzero(which == topic_id).tolist() if len(ids) > 1 \
                    else range(len(rows))
                t = np.fromiter((rows[i][1] for i in mine), dtype=np.int64, count=len(mine))
                payloads = _decompressed([rows[i][2] for i in mine], name)
                yield info._replace(count=len(mine)), ([(t, *pack_payloads(payloads))]
                                                       if len(mine) else [])
        except sqlite3.DatabaseError as err:
            raise BagError(f'{path.name}: not a rosbag2 sqlite3 file ({err})') from None
        finally:
            db.close()

    def _decompress_file(self, path: Path) -> Path:
        from backports import zstd
        if self._tmp is None:
            self._tmp = tempfile.TemporaryDirectory(prefix='satmotor_bag_')
        target = Path(self._tmp.name) / path.name.removesuffix('.zstd')
        if not target.exists():
            try:
                target.write_bytes(zstd.decompress(path.read_bytes()))
            except zstd.ZstdError as err:
                raise BagError(f'{path.name}: not a zstd file ({err})') from None
        return target

    def _check_metadata(self, infos: dict[str, TopicInfo]) -> None:
        if self.metadata is None:
            return
        where = self.files[0].name if len(self.files) == 1 else 'the storage files'
        for name, meta in self.metadata.items():
            found = infos.get(name)
            if found is None:
                if meta.count:
                    raise BagError(f'metadata.yaml and storage disagree: {name} has '
                                   f'{meta.count} messages in metadata.yaml and is not in '
                                   f'{where}')
                continue
            if found.msgtype != meta.msgtype:
                raise BagError(f'metadata.yaml and storage disagree: {name} is {meta.msgtype} '
                               f'in metadata.yaml and {found.msgtype} in {where}')
            if found.count >= 0 and found.count != meta.count:
                raise BagError(f'metadata.yaml and storage disagree: {name} has {meta.count} '
                               f'messages in metadata.yaml and {found.count} in {where}')


def _read_mcap_file(path: Path, wanted: set[str], count: bool) -> Found:  # noqa: ARG001
    return _mcap_topics(read_mcap(path, wanted))


def _mcap_topics(content: McapContent) -> Found:
    for channel_id, channel in content.channels.items():
        info = TopicInfo(channel.topic, normalize_type(channel.msgtype), channel.encoding,
                         content.counts.get(channel_id, 0))
        yield info, [_uncompressed_part(p, channel.topic)
                     for p in content.parts.get(channel_id, ())]


def _uncompressed_part(part: Any, name: str) -> tuple[np.ndarray, ...]:
    """Return an MCAP part as (times, buffer, offsets, lengths), undoing MESSAGE zstd."""
    t_ns, buf, offsets, lengths = part
    if len(offsets) and buf[offsets[0]:offsets[0] + 4].tobytes() == _ZSTD_MAGIC:
        payloads = [buf[a:a + n].tobytes() for a, n in zip(offsets.tolist(), lengths.tolist())]
        return (t_ns, *pack_payloads(_decompressed(payloads, name)))
    return t_ns, buf, offsets, lengths


def _decompressed(payloads: list[bytes], name: str) -> list[bytes]:
    """Undo zstd MESSAGE compression, recognised by the zstd magic of each payload."""
    if not payloads or not payloads[0].startswith(_ZSTD_MAGIC):
        return payloads
    from backports import zstd
    try:
        return [zstd.decompress(p) if p.startswith(_ZSTD_MAGIC) else p for p in payloads]
    except zstd.ZstdError as err:
        raise BagError(f'{name}: a zstd-compressed message cannot be decompressed '
                       f'({err})') from None


def _split_key(path: Path) -> tuple[int, str]:
    match = _SPLIT_INDEX.search(path.name)
    return (int(match.group(1)) if match else -1, path.name)


def _storage_of(path: Path) -> str:
    name = path.name.removesuffix('.zstd')
    if name.endswith('.mcap'):
        return 'mcap'
    if name.endswith('.db3'):
        return 'sqlite3'
    raise BagError(f'{path}: not a rosbag2 storage file (.db3, .db3.zstd or .mcap)')


def _parse_metadata(path: Path) -> tuple[str, list[str], dict[str, TopicInfo], str]:
    try:
        doc = yaml.safe_load(path.read_text(encoding='utf-8'))
        info = doc['rosbag2_bagfile_information']
        storage = str(info['storage_identifier'])
        files = [str(f).strip() for f in info['relative_file_paths']]
        topics = {}
        for entry in info.get('topics_with_message_count') or ():
            meta = entry['topic_metadata']
            topics[meta['name']] = TopicInfo(meta['name'], normalize_type(meta['type']),
                                             meta.get('serialization_format', 'cdr'),
                                             int(entry.get('message_count', 0)))
        mode = str(info.get('compression_mode') or '')
        fmt = str(info.get('compression_format') or '')
    except yaml.YAMLError as err:
        raise BagError(f'{path}: not valid YAML ({str(err).splitlines()[0]})') from None
    except (KeyError, TypeError, ValueError, AttributeError) as err:
        raise BagError(f'{path}: not rosbag2 metadata (missing or malformed {err})') from None
    if mode and mode.upper() != 'NONE' and fmt != 'zstd':
        raise BagError(f'{path}: compression_format {fmt!r} is not supported (only zstd)')
    return storage, files, topics, mode


def open_bag(path: str | Path) -> Bag:
    """
    Open a rosbag2 bag: a directory with or without metadata.yaml, or one storage file.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory, or a single ``.db3``, ``.db3.zstd`` or ``.mcap`` file, [-]

    Returns
    -------
    Bag
        The opened bag; nothing is read yet.

    Raises
    ------
    BagError
        If the path holds no bag, metadata.yaml is malformed or names missing files, or
        the storage is not sqlite3 or MCAP.

    """
    path = Path(path)
    if path.is_file():
        return Bag(path, _storage_of(path), [path], None)
    if not path.is_dir():
        raise BagError(f'{path}: no such bag directory or file')
    meta_path = path / 'metadata.yaml'
    if not meta_path.is_file():
        files = sorted((p for p in path.iterdir()
                        if p.name.endswith(('.db3', '.db3.zstd', '.mcap'))), key=_split_key)
        if not files:
            raise BagError(f'{path}: no metadata.yaml and no .db3/.mcap storage files')
        kinds = {_storage_of(p) for p in files}
        if len(kinds) > 1:
            raise BagError(f'{path}: no metadata.yaml and both .db3 and .mcap files')
        return Bag(path, kinds.pop(), files, None)
    storage, names, topics, _ = _parse_metadata(meta_path)
    if storage not in STORAGES:
        raise BagError(f'{meta_path}: storage_identifier {storage!r} is not supported '
                       f'(use {" or ".join(STORAGES)})')
    files = []
    for name in names:
        file = path / name
        if not file.is_file():
            raise BagError(f'{meta_path} lists {name!r}, which is not in {path}')
        if _storage_of(file) != storage:
            raise BagError(f'metadata.yaml and storage disagree: storage_identifier is '
                           f'{storage!r} but {name} is {_storage_of(file)}')
        files.append(file)
    return Bag(path, storage, files, topics)
