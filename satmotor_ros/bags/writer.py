# SPDX-License-Identifier: Apache-2.0
"""
Write bags with rosbags' writer: MCAP (default) or sqlite3, messages in log-time order.

rosbags writes metadata.yaml and the sqlite3 storage; the MCAP storage is written by the
``mcap`` library instead, because rosbags leaves the chunk CRCs zero: with them a reader
refuses a damaged chunk rather than return altered numbers.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import cast, NamedTuple, TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from satmotor_ros.bags.errors import BagError

if TYPE_CHECKING:
    from rosbags.interfaces import Connection, ConnectionExtRosbag2
    from rosbags.rosbag2 import CompressionMode


class OutTopic(NamedTuple):
    """The messages of one topic to write."""

    name: str  # topic name, e.g. '/predicted_joint_state'
    msgtype: str  # e.g. 'sensor_msgs/msg/JointState'
    t_ns: npt.NDArray[np.int64]  # log times [ns]
    data: Sequence[bytes]  # serialised CDR messages


class _McapStorage:
    """rosbags' storage-writer interface over the ``mcap`` writer (zstd chunks with CRCs)."""

    stem = ''  # name of the storage file without .mcap; '' for the directory's name

    def __init__(self, path: Path, compression: CompressionMode) -> None:  # noqa: ARG002
        from mcap.writer import CompressionType, Writer

        self.path = path / f'{self.stem or path.name}.mcap'
        self.stream = self.path.open('xb')
        self.mcap = Writer(self.stream, compression=CompressionType.ZSTD, enable_crcs=True)
        self.mcap.start(profile='ros2', library='satmotor_ros')
        self.schemas: dict[str, int] = {}
        self.channels: dict[int, int] = {}

    def add_msgtype(self, connection: Connection) -> None:
        encoding = 'ros2msg' if connection.msgdef.format.name == 'MSG' else 'ros2idl'
        self.schemas[connection.msgtype] = self.mcap.register_schema(
            connection.msgtype, encoding, connection.msgdef.data.encode())

    def add_connection(self, connection: Connection, offered_qos_profiles: str) -> None:
        ext = cast('ConnectionExtRosbag2', connection.ext)
        self.channels[connection.id] = self.mcap.register_channel(
            connection.topic, ext.serialization_format,
            self.schemas[connection.msgtype], {'offered_qos_profiles': offered_qos_profiles})

    def write(self, connection: Connection, timestamp: int, data: bytes | memoryview) -> None:
        self.mcap.add_message(self.channels[connection.id], timestamp, bytes(data), timestamp)

    def close(self, version: int, metadata: str) -> None:  # noqa: ARG002 (rosbags' signature)
        self.mcap.add_metadata('rosbag2', {'serialized_metadata': metadata})
        self.mcap.finish()  # type: ignore[no-untyped-call]  # mcap 1.6 leaves it unannotated
        self.stream.close()

    def abort(self) -> None:
        self.stream.close()


def write_bag(path: str | Path, topics: Sequence[OutTopic], storage: str = 'mcap',
              name: str = '', custom_data: Mapping[str, str] | None = None) -> int:
    """
    Write topics into a new bag, every message in log-time order.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory to create; it must not exist, [-]
    topics : sequence of OutTopic
        What to write; types must be known to the ROS 2 Kilted typestore, [-]
    storage : {'mcap', 'sqlite3'}
        Storage plugin, [-]
    name : str
        The bag's final directory name, which names its storage file (``NAME.mcap``) when
        `path` is a temporary name that is renamed to it once written; '' for `path`'s own
        name (the only choice for sqlite3), [-]
    custom_data : mapping of str to str, optional
        Recorded in metadata.yaml's ``custom_data`` (:mod:`satmotor_ros.bags.custom`), [-]

    Returns
    -------
    int
        Messages written.

    Raises
    ------
    BagError
        If the directory exists, a type is unknown or the storage cannot be written.

    """
    from rosbags.rosbag2 import StoragePlugin, Writer, WriterError
    from rosbags.typesys import get_typestore, Stores

    class Storage(_McapStorage):
        stem = name

    class McapWriter(Writer):
        STORAGE_PLUGINS = {**Writer.STORAGE_PLUGINS, StoragePlugin.MCAP: Storage}

    path = Path(path)
    if path.exists():
        raise BagError(f'{path}: already exists (choose a new directory for the bag)')
    plugins = {'mcap': StoragePlugin.MCAP, 'sqlite3': StoragePlugin.SQLITE3}
    if storage not in plugins:
        raise BagError(f'storage {storage!r}: use mcap or sqlite3')
    if name and storage != 'mcap':
        raise BagError(f'name {name!r}: only an MCAP bag takes a storage file name')
    typestore = get_typestore(Stores.ROS2_KILTED)
    for topic in topics:
        if topic.msgtype not in typestore.fielddefs:
            raise BagError(f'{topic.name}: type {topic.msgtype} is not known to the typestore')
    times = [np.asarray(t.t_ns, dtype=np.int64) for t in topics]
    which = np.concatenate([np.full(len(t), k, dtype=np.int64) for k, t in enumerate(times)]) \
        if times else np.zeros(0, dtype=np.int64)
    index = np.concatenate([np.arange(len(t)) for t in times]) if times else which
    stamps = np.concatenate(times) if times else which
    order = np.argsort(stamps, kind='stable')
    try:
        writer = McapWriter(path, version=9, storage_plugin=plugins[storage])
        for key, value in (custom_data or {}).items():
            writer.set_custom_data(key, value)
        writer.open()
        try:
            connections = [writer.add_connection(t.name, t.msgtype, typestore=typestore)
                           for t in topics]
            write = writer.write
            for k, i, t in zip(which[order].tolist(), index[order].tolist(),
                               stamps[order].tolist()):
                write(connections[k], t, topics[k].data[i])
        finally:
            writer.close()
    except (WriterError, OSError) as err:
        raise BagError(f'{path}: cannot write the bag ({err})') from None
    return len(order)
