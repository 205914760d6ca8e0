# SPDX-License-Identifier: Apache-2.0
"""Write bags with rosbags' writer: MCAP (default) or sqlite3, messages in log-time order."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from satmotor_ros.bags.errors import BagError


class OutTopic(NamedTuple):
    """The messages of one topic to write."""

    name: str  # topic name, e.g. '/predicted_joint_state'
    msgtype: str  # e.g. 'sensor_msgs/msg/JointState'
    t_ns: npt.NDArray[np.int64]  # log times [ns]
    data: Sequence[bytes]  # serialised CDR messages


def write_bag(path: str | Path, topics: Sequence[OutTopic], storage: str = 'mcap') -> int:
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

    path = Path(path)
    if path.exists():
        raise BagError(f'{path}: already exists (choose a new directory for the bag)')
    plugins = {'mcap': StoragePlugin.MCAP, 'sqlite3': StoragePlugin.SQLITE3}
    if storage not in plugins:
        raise BagError(f'storage {storage!r}: use mcap or sqlite3')
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
        writer = Writer(path, version=9, storage_plugin=plugins[storage])
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
