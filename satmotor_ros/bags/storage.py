# SPDX-License-Identifier: Apache-2.0
"""
rosbag2 storage: metadata, storage files and raw messages by topic, read with rosbags.

Every storage file (``.db3`` or ``.mcap``, or either zstd FILE-compressed as ``.zstd``) is
read on its own with rosbags' Reader, which checks MCAP chunk CRCs; the few MCAP files it
cannot open (schema encodings it does not know) are read with the ``mcap`` library, which
checks them too. metadata.yaml is read here and checked against the storage rather than
used to select from it: rosbags' directory reader silently returns no messages for a topic
whose type or QoS differ between the two. Here the storage is the truth, and a topic whose
type or message count differs is an error naming both. Bags of any metadata version (1-9),
split into several files, with zstd FILE or MESSAGE compression, or without metadata.yaml
(storage files found in the directory) are read. A damaged or truncated file is a
:class:`BagError` naming the file, never altered numbers.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import closing, contextmanager
from dataclasses import dataclass, field
import gc
from pathlib import Path
import re
import sqlite3
import struct
import sys
import tempfile
from typing import cast, NamedTuple, TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from satmotor_ros.bags.decode import pack_payloads
from satmotor_ros.bags.errors import BagError
from satmotor_ros.bounded_yaml import read_yaml, YamlLimitError
from satmotor_ros.limits import bag_budget

if TYPE_CHECKING:
    from rosbags.interfaces import ConnectionExtRosbag2

if sys.version_info >= (3, 14):  # PEP 784; setup.py installs the backport only below 3.14
    from compression import zstd
else:
    from backports import zstd


STORAGES = ('sqlite3', 'mcap')
"""Storage plugins that can be read."""

_ZSTD_MAGIC = b'\x28\xb5\x2f\xfd'
_SPLIT_INDEX = re.compile(r'_(\d+)\.(?:db3|mcap)(?:\.zstd)?$')
_SUFFIXES = ('.db3', '.db3.zstd', '.mcap', '.mcap.zstd')


class TopicInfo(NamedTuple):
    """A topic as the storage holds it."""

    name: str
    msgtype: str  # normalised: 'pkg/msg/Type'
    serialization: str  # 'cdr' for ROS 2
    count: int  # type: ignore[assignment]  # messages in the storage (not tuple.count)


class RawTopic(NamedTuple):
    """The messages of one topic in log-time order, their payloads packed in one buffer."""

    t_ns: npt.NDArray[np.int64]  # log (receive) times [ns]
    buf: npt.NDArray[np.uint8]  # serialised payloads, back to back
    offsets: npt.NDArray[np.int64]  # start of each payload in buf [bytes]
    lengths: npt.NDArray[np.int64]  # length of each payload [bytes]

    def payload(self, i: int) -> bytes:
        """Return message `i` as stored: its CDR bytes."""
        start = int(self.offsets[i])
        return self.buf[start:start + int(self.lengths[i])].tobytes()


def _packed(name: str, t_ns: list[int], payloads: list[bytes]) -> RawTopic:
    """Pack one topic's messages into a RawTopic, in log-time order."""
    try:
        times = np.array(t_ns, dtype=np.int64)
    except OverflowError:  # an MCAP log time >= 2**63: rosbag2's times are int64
        times = np.array([-1])
    if len(times) and times.min() < 0:
        raise BagError(f'{name}: a log time is outside [0, 2**63) ns (1970 to 2262), as no '
                       'rosbag2 recorder writes it')
    raw = RawTopic(times, *pack_payloads(payloads))
    if len(t_ns) > 1 and np.any(np.diff(raw.t_ns) < 0):
        order = np.argsort(raw.t_ns, kind='stable')
        return raw._replace(t_ns=raw.t_ns[order], offsets=raw.offsets[order],
                            lengths=raw.lengths[order])
    return raw


def _normalized_type(msgtype: str) -> str:
    """Give a type name its ``pkg/msg/Type`` form (Crystal-era bags wrote ``pkg/Type``)."""
    parts = msgtype.strip().split('/')
    return f'{parts[0]}/msg/{parts[1]}' if len(parts) == 2 else msgtype.strip()


class FileTopic(NamedTuple):
    """One topic of one storage file: what it is, and its messages when they were asked for."""

    info: TopicInfo
    t_ns: list[int]  # log times [ns]
    payloads: list[bytes]  # serialised messages, as stored


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
    _tmp: tempfile.TemporaryDirectory[str] | None = field(default=None, repr=False)
    _budget: _Budget | None = field(default=None, repr=False)

    def topics(self) -> dict[str, TopicInfo]:
        """
        List the topics of the storage, checked against metadata.yaml.

        Returns
        -------
        dict
            Topic name -> :class:`TopicInfo`, with the message count of the storage.

        Raises
        ------
        BagError
            If a storage file cannot be read or metadata.yaml disagrees with the storage.

        """
        return self.read(())[0]

    def read(self, names: tuple[str, ...] | list[str] | set[str],
             ) -> tuple[dict[str, TopicInfo], dict[str, RawTopic]]:
        """
        Read the raw messages of some topics.

        Parameters
        ----------
        names : collection of str
            Full topic names as in the bag, [-]

        Returns
        -------
        tuple
            The storage's topics (name -> :class:`TopicInfo`) and the messages of the
            requested ones (name -> :class:`RawTopic`, log-time order, MESSAGE
            compression undone).

        Raises
        ------
        BagError
            If a storage file cannot be read or metadata.yaml disagrees with the storage.

        """
        wanted = set(names)
        infos: dict[str, TopicInfo] = {}
        messages: dict[str, tuple[list[int], list[bytes]]] = {}
        budget = self._budget = _Budget(self.files)
        for path in self.files:
            plain = self._uncompressed(path, budget)
            if plain.name.endswith('.mcap'):
                budget.check_chunks(plain, path.name)
            for topic in _read_file(plain, wanted, path.name):
                info, seen = topic.info, infos.get(topic.info.name)
                if seen is not None and seen.msgtype != info.msgtype:
                    raise BagError(f'{info.name} is {seen.msgtype} in one storage file and '
                                   f'{info.msgtype} in {path.name}')
                infos[info.name] = info._replace(count=info.count + (seen.count if seen else 0))
                if info.name in wanted:
                    t_ns, payloads = messages.setdefault(info.name, ([], []))
                    t_ns.extend(topic.t_ns)
                    payloads.extend(topic.payloads)
        self._check_metadata(infos)
        return infos, {name: _packed(name, t_ns, _decompressed(payloads, name, budget))
                       for name, (t_ns, payloads) in messages.items()}

    def _uncompressed(self, path: Path, budget: _Budget) -> Path:
        """Undo zstd FILE compression into a temporary file that lives as long as the bag."""
        if path.suffix != '.zstd':
            return path
        if self._tmp is None:
            self._tmp = tempfile.TemporaryDirectory(prefix='satmotor_bag_')
        target = Path(self._tmp.name) / path.name.removesuffix('.zstd')
        if target.exists():
            budget.spend(target.stat().st_size, path.name)
            return target
        try:
            with zstd.open(path, 'rb') as source, target.open('wb') as sink:
                while block := source.read(1 << 20):
                    budget.spend(len(block), path.name)
                    sink.write(block)
        except (zstd.ZstdError, EOFError) as err:
            target.unlink(missing_ok=True)
            raise BagError(f'{path.name}: not a complete zstd file ({err})') from None
        except BagError:
            target.unlink(missing_ok=True)
            raise
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
            if found.count != meta.count:
                raise BagError(f'metadata.yaml and storage disagree: {name} has {meta.count} '
                               f'messages in metadata.yaml and {found.count} in {where}')


def _read_file(path: Path, wanted: set[str], name: str) -> list[FileTopic]:
    """
    Read one (uncompressed) storage file: all its topics, the messages of the wanted ones.

    Parameters
    ----------
    path : pathlib.Path
        The ``.db3`` or ``.mcap`` file, [-]
    wanted : set of str
        Topics whose messages to read, [-]
    name : str
        The file's name in the bag, for messages, [-]

    Returns
    -------
    list of FileTopic
        One per topic of the file (its channels or connections joined).

    Raises
    ------
    BagError
        If the file is damaged, truncated or not a storage file.

    """
    from apsw import Error as ApswError  # rosbags reads .db3 files through apsw
    from mcap.exceptions import McapError
    from rosbags.rosbag2 import ReaderError

    try:
        if path.suffix == '.db3':
            _check_sqlite(path, name)
        channels = _read_with_rosbags(path, wanted)
        if channels is None:
            channels = _read_with_mcap(path, wanted)
    except BagError:
        raise
    except (ReaderError, McapError, sqlite3.Error, ApswError, zstd.ZstdError, struct.error,
            EOFError, ValueError, TypeError, LookupError, RuntimeError, OverflowError,
            MemoryError) as err:  # the last two: a damaged length asks for 2**60 bytes
        detail = (str(err).splitlines() or [type(err).__name__])[0]
        raise BagError(f'{name}: damaged or truncated ({detail})') from None
    topics: dict[str, FileTopic] = {}
    for channel in channels:
        info = channel.info
        if info.name in wanted and len(channel.t_ns) != info.count:
            raise BagError(f'{name}: damaged or truncated ({info.name}: its index counts '
                           f'{info.count} messages, {len(channel.t_ns)} were found)')
        seen = topics.get(info.name)
        if seen is None:
            topics[info.name] = channel
            continue
        if seen.info.msgtype != info.msgtype:
            raise BagError(f'{name}: {info.name} is both {seen.info.msgtype} and '
                           f'{info.msgtype}')
        topics[info.name] = FileTopic(seen.info._replace(count=seen.info.count + info.count),
                                      seen.t_ns + channel.t_ns,
                                      seen.payloads + channel.payloads)
    return list(topics.values())


def _check_sqlite(path: Path, name: str) -> None:
    """
    Refuse a ``.db3`` file whose rows rosbag2 cannot have written, before they are read.

    rosbags reads any SQLite value: a text log time, a text or integer payload or a
    message whose topic id names no topic would pass through it, to end in a numpy
    error or be dropped without a word.

    Raises
    ------
    BagError
        Naming the first offending message id and how many there are.

    """
    checks = (
        ("typeof(timestamp) != 'integer'", 'a log time that is not an integer'),
        ("typeof(data) != 'blob'", 'a payload that is not a blob'),
        ('topic_id NOT IN (SELECT id FROM topics)', 'a topic id with no topic'),
    )
    with closing(sqlite3.connect(f'{path.resolve().as_uri()}?mode=ro&immutable=1',
                                 uri=True)) as db:
        bad = db.execute("SELECT count(*) FROM topics WHERE typeof(name) != 'text' "
                         "OR typeof(type) != 'text'").fetchone()[0]
        if bad:
            raise BagError(f'{name}: {bad} topics have a name or type that is not text')
        for where, what in checks:
            count, first = db.execute(
                f'SELECT count(*), min(id) FROM messages WHERE {where}').fetchone()
            if count:
                raise BagError(f'{name}: {count} messages have {what} (the first: id '
                               f'{first}); not written by rosbag2')


def _read_with_rosbags(path: Path, wanted: set[str]) -> list[FileTopic] | None:
    """Read a file's channels with rosbags' Reader; None for an MCAP file it cannot open."""
    from rosbags.rosbag2 import Reader

    reader = Reader(path)
    try:
        reader.open()
    except KeyError:  # rosbags 0.11.9 knows no MCAP schema encoding 'unknown' (rosbag2's)
        return None
    try:
        channels = {conn.id: FileTopic(TopicInfo(
            conn.topic, _normalized_type(conn.msgtype),
            cast('ConnectionExtRosbag2', conn.ext).serialization_format, conn.msgcount), [], [])
            for conn in reader.connections}
        picked = [conn for conn in reader.connections if conn.topic in wanted]
        with _gc_paused():
            for conn, t_ns, data in reader.messages(picked) if picked else ():
                channel = channels[conn.id]
                channel.t_ns.append(t_ns)
                channel.payloads.append(data)
    finally:
        reader.close()
    return list(channels.values())


@contextmanager
def _gc_paused() -> Iterator[None]:
    """
    Pause the cyclic garbage collector while a file's messages are read.

    Reading allocates a few tuples per message, none of them in a cycle; the collector's
    passes over them cost a quarter of the read (1.4e6 messages: 3.4 s -> 2.6 s).

    Yields
    ------
    None
        Nothing; the collector runs again (if it did before) on leaving.

    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _read_with_mcap(path: Path, wanted: set[str]) -> list[FileTopic]:
    """Read an MCAP file's channels with the ``mcap`` library, checking its CRCs."""
    from mcap.records import Channel, Message, Schema
    from mcap.stream_reader import StreamReader

    schemas: dict[int, str] = {}
    channels: dict[int, FileTopic] = {}
    counts: dict[int, int] = {}
    with path.open('rb') as stream:
        for record in StreamReader(stream, validate_crcs=True).records:
            if isinstance(record, Message):
                counts[record.channel_id] = counts.get(record.channel_id, 0) + 1
                channel = channels[record.channel_id]
                if channel.info.name in wanted:
                    channel.t_ns.append(record.log_time)
                    channel.payloads.append(record.data)
            elif isinstance(record, Schema):
                schemas[record.id] = record.name
            elif isinstance(record, Channel) and record.id not in channels:
                channels[record.id] = FileTopic(TopicInfo(
                    record.topic, _normalized_type(schemas.get(record.schema_id, '')),
                    record.message_encoding, 0), [], [])
    return [c._replace(info=c.info._replace(count=counts.get(k, 0)))
            for k, c in channels.items()]


class _Budget:
    """
    What a bag may still decompress to (:func:`satmotor_ros.limits.bag_budget`), [byte].

    Parameters
    ----------
    files : list of pathlib.Path
        The bag's storage files as stored, [-]

    """

    def __init__(self, files: list[Path]) -> None:
        """Start from the budget of the stored size."""
        self.total = self.left = bag_budget(sum(f.stat().st_size for f in files))

    def spend(self, size: int, name: str) -> None:
        """Take `size` bytes, or raise :class:`BagError` naming `name` and the cap."""
        self.left -= size
        if self.left < 0:
            raise BagError(f'{name}: decompresses to more than {self.total} bytes (the cap for '
                           'a bag of this size; SATMOTOR_BAG_MAX_BYTES, SATMOTOR_BAG_MAX_RATIO)')

    def check_chunks(self, path: Path, name: str) -> None:
        """Refuse an MCAP file whose chunks say they decompress beyond the budget."""
        from mcap.exceptions import McapError, RecordLengthLimitExceeded
        from mcap.records import Chunk
        from mcap.stream_reader import StreamReader

        size, stored = 0, path.stat().st_size
        try:
            with path.open('rb') as stream:
                for record in StreamReader(stream, emit_chunks=True,
                                           record_size_limit=stored).records:
                    if isinstance(record, Chunk) and record.compression:
                        size += record.uncompressed_size
                        if size > self.left:
                            self.spend(size, name)
        except BagError:
            raise
        except RecordLengthLimitExceeded as err:  # a record longer than its file
            raise BagError(f'{name}: damaged or truncated ({err} bytes, the size of the '
                           'file)') from None
        except (McapError, ValueError, struct.error, EOFError, OverflowError, MemoryError):
            return  # damaged: the reader says how
        if size > self.left:
            self.spend(size, name)


def _decompressed(payloads: list[bytes], name: str, budget: _Budget) -> list[bytes]:
    """Undo zstd MESSAGE compression, recognised by the zstd magic of each payload."""
    if not payloads or not payloads[0].startswith(_ZSTD_MAGIC):
        return payloads
    out = []
    try:
        for p in payloads:
            if p.startswith(_ZSTD_MAGIC):
                decompressor = zstd.ZstdDecompressor()
                p = decompressor.decompress(p, max_length=max(budget.left, 0) + 1)
                budget.spend(len(p), name)
                if not decompressor.eof:
                    raise BagError(f'{name}: a zstd-compressed message is incomplete')
            out.append(p)
    except zstd.ZstdError as err:
        raise BagError(f'{name}: a zstd-compressed message cannot be decompressed '
                       f'({err})') from None
    return out


def _split_key(path: Path) -> tuple[int, str]:
    match = _SPLIT_INDEX.search(path.name)
    return (int(match.group(1)) if match else -1, path.name)


def _storage_of(path: Path) -> str:
    name = path.name.removesuffix('.zstd')
    if name.endswith('.mcap'):
        return 'mcap'
    if name.endswith('.db3'):
        return 'sqlite3'
    raise BagError(f'{path}: not a rosbag2 storage file ({", ".join(_SUFFIXES)})')


def _parse_metadata(path: Path) -> tuple[str, list[str], dict[str, TopicInfo], str]:
    try:
        doc = read_yaml(path)
        info = doc['rosbag2_bagfile_information']
        storage = str(info['storage_identifier'])
        files = [str(f).strip() for f in info['relative_file_paths']]
        topics = {}
        for entry in info.get('topics_with_message_count') or ():
            meta = entry['topic_metadata']
            topics[meta['name']] = TopicInfo(meta['name'], _normalized_type(meta['type']),
                                             meta.get('serialization_format', 'cdr'),
                                             int(entry.get('message_count', 0)))
        mode = str(info.get('compression_mode') or '')
        fmt = str(info.get('compression_format') or '')
    except YamlLimitError as err:
        raise BagError(f'{path}: {err}') from None
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
        Bag directory, or a single ``.db3`` or ``.mcap`` file, either possibly ``.zstd``, [-]

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
                        if p.name.endswith(_SUFFIXES)), key=_split_key)
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
        if Path(name).is_absolute() or not file.resolve().is_relative_to(path.resolve()):
            raise BagError(f'{meta_path} lists {name!r}, which is outside the bag directory')
        if not file.is_file():
            raise BagError(f'{meta_path} lists {name!r}, which is not in {path}')
        if _storage_of(file) != storage:
            raise BagError(f'metadata.yaml and storage disagree: storage_identifier is '
                           f'{storage!r} but {name} is {_storage_of(file)}')
        files.append(file)
    return Bag(path, storage, files, topics)
