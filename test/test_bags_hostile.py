# SPDX-License-Identifier: Apache-2.0
"""Bags rosbag2 cannot have written end in one line, never a traceback (issue 14)."""

import sqlite3
import struct

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import get_typestore, Stores
from satmotor_ros.bags import BagError, encode_message, read_series
from satmotor_ros.interface import FLOAT64

TYPESTORE = get_typestore(Stores.ROS2_KILTED)
MCAP_MAGIC = b'\x89MCAP0\r\n'


def _db3(path, sql):
    """Write a ten-message sqlite3 bag, then damage its storage file with `sql`."""
    with Writer(path, version=8, storage_plugin=StoragePlugin.SQLITE3) as writer:
        conn = writer.add_connection('/flow_command', FLOAT64, typestore=TYPESTORE)
        for i in range(10):
            writer.write(conn, 100 + i, encode_message(FLOAT64, {'data': float(i)}))
    with sqlite3.connect(next(path.glob('*.db3'))) as db:
        db.execute(sql)
    db.close()
    (path / 'metadata.yaml').unlink()  # the storage alone; metadata.yaml would disagree
    return path


@pytest.mark.parametrize(('sql', 'text'), [
    ("UPDATE messages SET timestamp = 'abc' WHERE id = 3", 'a log time that is not an integer'),
    ('UPDATE messages SET timestamp = 101.5 WHERE id = 3', 'a log time that is not an integer'),
    ("UPDATE messages SET data = 'text' WHERE id >= 3", '8 messages have a payload that is not'),
    ('UPDATE messages SET data = 5 WHERE id = 3', 'a payload that is not a blob'),
    ('UPDATE messages SET topic_id = 99 WHERE id = 3', 'a topic id with no topic'),
])
def test_db3_rows_rosbag2_cannot_write_are_one_line(tmp_path, sql, text):
    bag = _db3(tmp_path / 'bag', sql)
    with pytest.raises(BagError, match=text) as err:
        read_series(bag, ['flow_command'])
    assert '\n' not in str(err.value) and 'the first: id 3' in str(err.value)


def test_negative_db3_log_time_is_refused(tmp_path):
    bag = _db3(tmp_path / 'bag', 'UPDATE messages SET timestamp = -5 WHERE id = 3')
    with pytest.raises(BagError, match=r'/flow_command: a log time is outside \[0, 2\*\*63\)'):
        read_series(bag, ['flow_command'])


def _record(opcode, body):
    return bytes([opcode]) + struct.pack('<Q', len(body)) + body


def _text(text):
    return struct.pack('<I', len(text)) + text.encode()


def _mcap(path, log_times, nesting=0):
    """Write an MCAP file by hand: /flow_command messages, optionally in nested chunks."""
    records = (
        _record(3, struct.pack('<H', 1) + _text('std_msgs/msg/Float64') + _text('ros2msg')
                + struct.pack('<I', 12) + b'float64 data')
        + _record(4, struct.pack('<HH', 1, 1) + _text('/flow_command') + _text('cdr')
                  + struct.pack('<I', 0))
        + b''.join(_record(5, struct.pack('<HIQQ', 1, i, t, t)
                           + encode_message(FLOAT64, {'data': float(i)}))
                   for i, t in enumerate(log_times)))
    for _ in range(nesting):
        records = _record(6, struct.pack('<QQQI', 0, 2**62, len(records), 0) + _text('')
                          + struct.pack('<Q', len(records)) + records)
    path.write_bytes(MCAP_MAGIC + _record(1, _text('ros2') + _text('test')) + records
                     + _record(15, struct.pack('<QI', 0, 0))
                     + _record(2, struct.pack('<QQI', 0, 0, 0)) + MCAP_MAGIC)
    return path


@pytest.mark.parametrize('nesting', [0, 1])
def test_hand_written_mcap_reads_in_and_out_of_a_chunk(tmp_path, nesting):
    series = read_series(_mcap(tmp_path / 'x.mcap', [5, 6], nesting), ['flow_command'])
    np.testing.assert_array_equal(series['flow_command'].t_ns, [5, 6])


@pytest.mark.parametrize('nesting', [0, 1])
def test_mcap_log_times_beyond_int64_are_refused_not_negative(tmp_path, nesting):
    """Test MCAP's unsigned log times >= 2**63 are refused, with an index or without one."""
    from mcap.writer import Writer as McapWriter
    path = _mcap(tmp_path / 'x.mcap', [5, 2**63 + 5, 2**64 - 1], nesting)
    # rosbags' scan reads them as negative and skips them: the count tells
    with pytest.raises(BagError, match=r'/flow_command: its index counts 3 messages, 1 were'):
        read_series(path, ['flow_command'])
    with (tmp_path / 'indexed.mcap').open('wb') as stream:
        writer = McapWriter(stream)
        writer.start(profile='ros2', library='test')
        schema = writer.register_schema('std_msgs/msg/Float64', 'ros2msg', b'float64 data')
        channel = writer.register_channel('/flow_command', 'cdr', schema)
        for t in (5, 2**63 + 5):
            writer.add_message(channel, log_time=t, publish_time=t,
                               data=encode_message(FLOAT64, {'data': 1.0}))
        writer.finish()
    with pytest.raises(BagError, match=r'/flow_command: a log time is outside \[0, 2\*\*63\)'):
        read_series(tmp_path / 'indexed.mcap', ['flow_command'])


def test_mcap_with_3000_nested_chunks_is_one_line(tmp_path):
    path = _mcap(tmp_path / 'x.mcap', [5], nesting=3000)
    with pytest.raises(BagError, match=r'x.mcap: damaged or truncated \(.*[Nn]ested'):
        read_series(path, ['flow_command'])


def test_metadata_with_a_control_character_is_one_line(tmp_path):
    bag = _db3(tmp_path / 'bag', 'SELECT 1')
    (bag / 'metadata.yaml').write_bytes(b'rosbag2_bagfile_information:\n  version: \x12\n')
    with pytest.raises(BagError, match=r'metadata.yaml: not valid YAML \(.*special characters'):
        read_series(bag, ['flow_command'])


@pytest.mark.parametrize('at', [9, -28])  # the header's length; the footer's summary offset
def test_mcap_lengths_and_offsets_of_2_64_are_one_line(tmp_path, at):
    """Test a length or offset that asks for 2**64 bytes is damage, not a MemoryError."""
    from mcap.writer import Writer as McapWriter
    path = tmp_path / 'x.mcap'
    with path.open('wb') as stream:
        writer = McapWriter(stream)
        writer.start(profile='ros2', library='test')
        schema = writer.register_schema('std_msgs/msg/Float64', 'ros2msg', b'float64 data')
        channel = writer.register_channel('/flow_command', 'cdr', schema)
        writer.add_message(channel, log_time=5, publish_time=5,
                           data=encode_message(FLOAT64, {'data': 1.0}))
        writer.finish()
    data = bytearray(path.read_bytes())
    data[at:at + 8 if at + 8 else None] = b'\xff' * 8
    path.write_bytes(bytes(data))
    with pytest.raises(BagError, match=r'x.mcap: damaged or truncated'):
        read_series(path, ['flow_command'])
