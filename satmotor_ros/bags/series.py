# SPDX-License-Identifier: Apache-2.0
"""
Bag topics as time series: what calibration and replay read.

``read_series(bag, ['flow_command', 'inlet_pressure'])`` returns one :class:`Series` per
topic found: log times, header stamps and the message's numbers as float arrays (SI, as
on the topics). Names match with or without a namespace (``flow_command`` finds
``/flow_command`` and ``/motor1/flow_command``); ``topic_map`` renames bag topics first.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from satmotor_ros.bags.decode import decode, FIELDS
from satmotor_ros.bags.errors import BagError
from satmotor_ros.bags.storage import open_bag, TopicInfo
from satmotor_ros.interface import JOINT_NAME, TOPIC_TYPES


@dataclass(frozen=True)
class Series:
    """
    The messages of one topic as arrays, in log-time order.

    ``fields`` holds per message type: Float64 ``data``; FluidPressure ``fluid_pressure``
    and ``variance``; Temperature ``temperature`` and ``variance``; JointState
    ``position``, ``velocity`` and ``effort`` of one joint (NaN where the message has no
    such value; messages without the joint are left out and counted in ``skipped``).
    """

    topic: str  # the topic's name in the bag
    msgtype: str  # e.g. 'sensor_msgs/msg/FluidPressure'
    t_ns: npt.NDArray[np.int64]  # log (receive) time [ns]
    stamp_ns: npt.NDArray[np.int64] | None  # header.stamp; None for messages without one [ns]
    fields: Mapping[str, npt.NDArray[np.float64]]  # by field name [SI, as on the topic]
    raw: tuple[bytes, ...] | None = None  # the serialised messages, when asked for
    skipped: int = 0  # JointState messages without the joint

    def __len__(self) -> int:
        """Return the number of messages."""
        return len(self.t_ns)


def _absolute(name: str) -> str:
    return name if name.startswith('/') else '/' + name


def parse_topic_map(pairs: Iterable[str]) -> dict[str, str]:
    """
    Parse ``old:=new`` renames, as given on a command line.

    Parameters
    ----------
    pairs : iterable of str
        Each ``old:=new``, [-]

    Returns
    -------
    dict
        Old name -> new name.

    Raises
    ------
    BagError
        If a pair is not of the form ``old:=new``.

    """
    mapping = {}
    for pair in pairs:
        old, sep, new = pair.partition(':=')
        if not sep or not old.strip() or not new.strip():
            raise BagError(f'--topic-map {pair!r}: use OLD:=NEW')
        mapping[old.strip()] = new.strip()
    return mapping


def match_topics(available: Iterable[str], requested: Iterable[str],
                 topic_map: Mapping[str, str] | None = None) -> dict[str, str]:
    """
    Find the bag topic behind each requested name.

    A relative name (``flow_command``) matches the bag topic of that name in any
    namespace; if several match, the one in the root namespace wins, else it is an error.
    An absolute name (``/motor1/flow_command``) matches only itself.

    Parameters
    ----------
    available : iterable of str
        Topic names in the bag, [-]
    requested : iterable of str
        Names asked for, [-]
    topic_map : mapping, optional
        Bag topic -> the name it is to be matched as, [-]

    Returns
    -------
    dict
        Requested name -> bag topic name, for the requested names found.

    Raises
    ------
    BagError
        If a topic_map source is not in the bag or a name is ambiguous.

    """
    names = {_absolute(n): n for n in available}
    renamed = dict(names)
    for old, new in (topic_map or {}).items():
        if _absolute(old) not in names:
            raise BagError(f'--topic-map {old}:={new}: {old} is not in the bag')
        del renamed[_absolute(old)]
        renamed[_absolute(new)] = names[_absolute(old)]
    found = {}
    for want in requested:
        if want.startswith('/'):
            hits = [want] if want in renamed else []
        else:
            hits = [n for n in renamed if n == '/' + want or n.endswith('/' + want)]
            if len(hits) > 1 and '/' + want in hits:
                hits = ['/' + want]
        if len(hits) > 1:
            raise BagError(f'{want} matches several topics ({", ".join(sorted(hits))}): '
                           f'choose one with --topic-map {sorted(hits)[0]}:={want}')
        if hits:
            found[want] = renamed[hits[0]]
    return found


def list_topics(path: str | Path) -> dict[str, TopicInfo]:
    """
    List a bag's topics with their types and message counts (from the storage).

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory or storage file, [-]

    Returns
    -------
    dict
        Topic name -> :class:`~satmotor_ros.bags.storage.TopicInfo`.

    Raises
    ------
    BagError
        If the bag cannot be read or its metadata disagrees with its storage.

    """
    return open_bag(path).topics()


def read_series(path: str | Path, topics: Iterable[str],
                topic_map: Mapping[str, str] | None = None, joint: str | None = JOINT_NAME,
                keep_raw: bool = False) -> dict[str, Series]:
    """
    Read topics of a bag into time series.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory (sqlite3 or MCAP, any metadata version, split, compressed, with or
        without metadata.yaml) or a single storage file, [-]
    topics : iterable of str
        Names to read, matched as :func:`match_topics` says; DESIGN.md names must have
        their DESIGN.md type, [-]
    topic_map : mapping, optional
        Bag topic -> name to match it as, [-]
    joint : str or None
        The joint whose values JointState series hold (None: each message's first), [-]
    keep_raw : bool
        Also keep the serialised messages (to copy them into another bag), [-]

    Returns
    -------
    dict
        Requested name -> :class:`Series`, for the names found (see
        :func:`missing_topics`).

    Raises
    ------
    BagError
        If the bag cannot be read, disagrees with its metadata, or a topic has a type or
        serialisation format that cannot be decoded; the message is one line.

    """
    bag = open_bag(path)
    requested = list(dict.fromkeys(topics))
    available = bag.topics()
    found = match_topics(available, requested, topic_map)
    for want, name in found.items():
        info = available[name]
        base = want.rsplit('/', 1)[-1] if want.startswith('/') else want
        expected = TOPIC_TYPES.get(base) or TOPIC_TYPES.get(want.lstrip('/'))
        if expected is not None and info.msgtype != expected:
            raise BagError(f'{want} ({name} in the bag) is {info.msgtype}; '
                           f'expected {expected}')
        if info.serialization != 'cdr':
            raise BagError(f'{want} ({name} in the bag): serialization format '
                           f'{info.serialization!r} is not supported (only cdr)')
        if info.msgtype not in FIELDS:
            raise BagError(f'{want} ({name} in the bag) is {info.msgtype}, which cannot be '
                           f'read as a series (supported: {", ".join(FIELDS)})')
    available, raw = bag.read(set(found.values()))
    result = {}
    for want, name in found.items():
        info = available[name]
        messages = raw[name]
        try:
            decoded = decode(info.msgtype, messages.buf, messages.offsets, messages.lengths,
                             joint)
        except BagError as err:
            raise BagError(f'{name}: {err}') from None
        keep = decoded.keep
        result[want] = Series(
            name, info.msgtype, messages.t_ns[keep], decoded.stamp_ns, decoded.fields,
            tuple(messages.payload(i) for i in np.flatnonzero(keep).tolist())
            if keep_raw else None, int(len(keep) - keep.sum()))
    return result


def missing_topics(series: Mapping[str, Series], required: Iterable[str]) -> list[str]:
    """
    Name the required topics that a :func:`read_series` result lacks or holds empty.

    Parameters
    ----------
    series : mapping
        What :func:`read_series` returned, [-]
    required : iterable of str
        Names that must be there with at least one message, [-]

    Returns
    -------
    list of str
        The missing names, in the order given.

    """
    return [name for name in required if name not in series or not len(series[name])]


def describe_topics(infos: Mapping[str, TopicInfo], limit: int = 8) -> str:
    """
    Summarise a bag's topics on one line, for error messages.

    Parameters
    ----------
    infos : mapping
        Topic name -> TopicInfo, [-]
    limit : int
        Most topics to name, [-]

    Returns
    -------
    str
        E.g. ``'/topic std_msgs/msg/String (10), /rosout rcl_interfaces/msg/Log (10)'``.

    """
    if not infos:
        return 'no topics'
    items = [f'{i.name} {i.msgtype} ({i.count})' for i in infos.values()]
    more = f', ... {len(items) - limit} more' if len(items) > limit else ''
    return ', '.join(items[:limit]) + more
