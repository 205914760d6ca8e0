# SPDX-License-Identifier: Apache-2.0
"""
rosbag2 bags in and out, without ROS: topics as numpy time series, fast.

Reading (:func:`read_series`, :func:`list_topics`) takes sqlite3 and MCAP bags of every
metadata version, split or zstd-compressed (FILE or MESSAGE), with or without
metadata.yaml: rosbags reads the storage files (the ``mcap`` library the MCAP files rosbags
cannot open), metadata.yaml is checked against the storage, and Float64, FluidPressure,
Temperature and JointState messages are decoded with a vectorised CDR decoder. Writing
(:func:`write_bag`) uses rosbags' writer, with MCAP chunks written by the ``mcap``
library so that they carry CRCs. Every failure, a damaged or truncated file too, is a
:class:`BagError` with a one-line message naming the file.

Example::

    series = read_series('run1', ['flow_command', 'inlet_pressure', 'joint_states'])
    missing = missing_topics(series, ['flow_command', 'inlet_pressure'])
    p_in = series['inlet_pressure'].fields['fluid_pressure']  # [Pa]
    t = series['inlet_pressure'].t_ns  # log time [ns]
"""

from satmotor_ros.bags.decode import decode, FIELDS, pack_payloads
from satmotor_ros.bags.encode import encode_many, encode_message
from satmotor_ros.bags.errors import BagError
from satmotor_ros.bags.series import (describe_topics, list_topics, match_topics,
                                      missing_topics, parse_topic_map, read_series, Series)
from satmotor_ros.bags.storage import open_bag, TopicInfo
from satmotor_ros.bags.writer import OutTopic, write_bag

__all__ = [
    'BagError', 'FIELDS', 'OutTopic', 'Series', 'TopicInfo', 'decode',
    'describe_topics', 'encode_many', 'encode_message', 'list_topics', 'match_topics',
    'missing_topics', 'open_bag', 'pack_payloads', 'parse_topic_map', 'read_series',
    'write_bag',
]
