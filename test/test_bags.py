# SPDX-License-Identifier: Apache-2.0
"""Bags written and read back: the fast decoder against rosbags, matching, errors."""

import gc
from pathlib import Path
import shutil
import struct

from backports import zstd
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
from rosbags.typesys import get_typestore, Stores
from satmotor_ros.bags import (BagError, decode, encode_many, encode_message, list_topics,
                               match_topics, missing_topics, OutTopic, pack_payloads,
                               parse_topic_map, read_series, write_bag)
from satmotor_ros.interface import FLOAT64, FLUID_PRESSURE, JOINT_STATE, TEMPERATURE
import yaml


TYPESTORE = get_typestore(Stores.ROS2_KILTED)
N = 200


def _inputs(rng, prefix='/'):
    """Return OutTopics of the four input topics with random values and frame ids."""
    t0 = 1_700_000_000_000_000_000
    t = t0 + np.cumsum(rng.integers(1, 20_000_000, size=(4, N)), axis=1)
    flow = rng.uniform(0, 6e-4, N)
    p_in = rng.uniform(1e6, 3e7, N)
    p_out = rng.uniform(1e5, 1e6, N)
    speed = rng.uniform(0, 150, N)
    return {
        'flow': flow, 'p_in': p_in, 'p_out': p_out, 'speed': speed, 't': t,
        'topics': [
            OutTopic(prefix + 'flow_command', FLOAT64, t[0],
                     encode_many(FLOAT64, {'data': flow})),
            OutTopic(prefix + 'inlet_pressure', FLUID_PRESSURE, t[1], encode_many(
                FLUID_PRESSURE, {'fluid_pressure': p_in, 'variance': np.full(N, 4.0)},
                t[1] - 5, frame_id='inlet')),
            OutTopic(prefix + 'outlet_pressure', FLUID_PRESSURE, t[2], encode_many(
                FLUID_PRESSURE, {'fluid_pressure': p_out}, t[2] - 5)),
            OutTopic(prefix + 'joint_states', JOINT_STATE, t[3], encode_many(
                JOINT_STATE, {'position': speed * 2, 'velocity': speed}, t[3],
                joint='motor_shaft')),
        ]}


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_written_bag_reads_back_exactly_and_as_rosbags_reads_it(tmp_path, storage):
    """Test values, log times and stamps survive a round trip, and rosbags agrees."""
    data = _inputs(np.random.default_rng(1))
    bag = tmp_path / 'bag'
    assert write_bag(bag, data['topics'], storage=storage) == 4 * N
    series = read_series(bag, ['flow_command', 'inlet_pressure', 'outlet_pressure',
                               'joint_states'])
    assert gc.isenabled()  # paused only while the messages were collected
    np.testing.assert_array_equal(series['flow_command'].fields['data'], data['flow'])
    np.testing.assert_array_equal(series['flow_command'].t_ns, data['t'][0])
    assert series['flow_command'].stamp_ns is None
    np.testing.assert_array_equal(series['inlet_pressure'].fields['fluid_pressure'],
                                  data['p_in'])
    np.testing.assert_array_equal(series['inlet_pressure'].fields['variance'], 4.0)
    np.testing.assert_array_equal(series['inlet_pressure'].stamp_ns, data['t'][1] - 5)
    np.testing.assert_array_equal(series['outlet_pressure'].fields['fluid_pressure'],
                                  data['p_out'])
    np.testing.assert_array_equal(series['joint_states'].fields['velocity'], data['speed'])
    np.testing.assert_array_equal(series['joint_states'].fields['position'], 2 * data['speed'])
    assert np.isnan(series['joint_states'].fields['effort']).all()
    with AnyReader([bag], default_typestore=TYPESTORE) as reader:
        seen = {}
        for conn, t, raw in reader.messages():
            seen.setdefault(conn.topic, []).append((t, reader.deserialize(raw, conn.msgtype)))
    assert [m.fluid_pressure for _, m in seen['/inlet_pressure']] == data['p_in'].tolist()
    assert [m.header.frame_id for _, m in seen['/inlet_pressure']] == ['inlet'] * N
    assert [m.velocity[0] for _, m in seen['/joint_states']] == data['speed'].tolist()
    assert [t for t, _ in seen['/flow_command']] == data['t'][0].tolist()


def test_decoder_equals_rosbags_on_mixed_layouts_and_endianness():
    """Test frame ids, joint orders and big-endian messages mixed in one topic."""
    js, hdr, tm = (TYPESTORE.types[n] for n in (
        JOINT_STATE, 'std_msgs/msg/Header', 'builtin_interfaces/msg/Time'))
    rng = np.random.default_rng(2)
    msgs = []
    for i in range(60):
        names = [['motor_shaft'], ['a', 'motor_shaft'], ['motor_shaft', 'b'], ['zz']][i % 4]
        k = len(names)
        msg = js(header=hdr(stamp=tm(sec=i, nanosec=7 * i), frame_id=['', 'x', 'y'][i % 3]),
                 name=names, position=rng.normal(size=k), velocity=rng.normal(size=k),
                 effort=rng.normal(size=k) if i % 5 else np.zeros(0))
        msgs.append((msg, bytes(TYPESTORE.serialize_cdr(msg, JOINT_STATE,
                                                        little_endian=bool(i % 7)))))
    decoded = decode(JOINT_STATE, *pack_payloads([raw for _, raw in msgs]), 'motor_shaft')
    expected = [m for m, _ in msgs if 'motor_shaft' in m.name]
    assert decoded.keep.sum() == len(expected) == 45
    for name in ('position', 'velocity', 'effort'):
        want = [getattr(m, name)[m.name.index('motor_shaft')]
                if len(getattr(m, name)) else np.nan for m in expected]
        np.testing.assert_array_equal(decoded.fields[name], want)
    np.testing.assert_array_equal(decoded.stamp_ns, [m.header.stamp.sec * 10**9
                                                     + m.header.stamp.nanosec
                                                     for m in expected])


def test_encoder_is_byte_identical_to_rosbags():
    fp = TYPESTORE.types[FLUID_PRESSURE]
    hdr = TYPESTORE.types['std_msgs/msg/Header']
    tm = TYPESTORE.types['builtin_interfaces/msg/Time']
    msg = fp(header=hdr(stamp=tm(sec=3, nanosec=9), frame_id='abc'), fluid_pressure=2.5e7,
             variance=0.5)
    assert encode_message(FLUID_PRESSURE, {'fluid_pressure': 2.5e7, 'variance': 0.5},
                          3_000_000_009, 'abc') == bytes(TYPESTORE.serialize_cdr(msg,
                                                                                 FLUID_PRESSURE))
    temp = TYPESTORE.types[TEMPERATURE](
        header=hdr(stamp=tm(sec=1, nanosec=0), frame_id=''), temperature=-4.0, variance=0.0)
    assert encode_many(TEMPERATURE, {'temperature': [-4.0]}, [10**9])[0] == \
        bytes(TYPESTORE.serialize_cdr(temp, TEMPERATURE))


def test_decoder_rejects_garbage_with_one_line():
    with pytest.raises(BagError, match='truncated'):
        decode(FLUID_PRESSURE, *pack_payloads([b'\x00\x01\x00\x00\x01\x00']))
    with pytest.raises(BagError, match='not a CDR message'):
        decode(FLOAT64, *pack_payloads([b'\xff\xff\x00\x00' + bytes(8)]))
    with pytest.raises(BagError, match='no fast decoder'):
        decode('std_msgs/msg/String', *pack_payloads([b'']))


def test_names_match_with_or_without_namespace_and_can_be_renamed():
    bag = ['/flow_command', '/m1/inlet_pressure', '/m2/inlet_pressure', 'outlet_pressure']
    assert match_topics(bag, ['flow_command', 'outlet_pressure']) == {
        'flow_command': '/flow_command', 'outlet_pressure': 'outlet_pressure'}
    with pytest.raises(BagError, match='inlet_pressure matches several topics '
                                       r'\(/m1/inlet_pressure, /m2/inlet_pressure\)'):
        match_topics(bag, ['inlet_pressure'])
    assert match_topics(bag, ['/m2/inlet_pressure']) == {
        '/m2/inlet_pressure': '/m2/inlet_pressure'}
    renamed = parse_topic_map(['/m1/inlet_pressure:=inlet_pressure'])
    assert match_topics(bag, ['inlet_pressure'], renamed) == {
        'inlet_pressure': '/m1/inlet_pressure'}
    with pytest.raises(BagError, match='/nope is not in the bag'):
        match_topics(bag, ['x'], {'/nope': 'x'})
    with pytest.raises(BagError, match="--topic-map 'a=b': use OLD:=NEW"):
        parse_topic_map(['a=b'])


def test_namespaced_bag_reads_and_reports_missing_topics(tmp_path):
    data = _inputs(np.random.default_rng(3), prefix='/motor1/')
    write_bag(tmp_path / 'bag', data['topics'][:2])
    series = read_series(tmp_path / 'bag', ['flow_command', 'inlet_pressure',
                                            'outlet_pressure'])
    assert series['inlet_pressure'].topic == '/motor1/inlet_pressure'
    assert missing_topics(series, ['flow_command', 'outlet_pressure', 'case_pressure']) == [
        'outlet_pressure', 'case_pressure']


def test_wrong_type_on_a_design_topic_is_named(tmp_path):
    write_bag(tmp_path / 'bag', [OutTopic('/inlet_pressure', FLOAT64, np.array([1]),
                                          encode_many(FLOAT64, {'data': [1.0]}))])
    with pytest.raises(BagError, match='inlet_pressure .* is std_msgs/msg/Float64; expected '
                                       'sensor_msgs/msg/FluidPressure'):
        read_series(tmp_path / 'bag', ['inlet_pressure'])


def _rosbags_bag(path, mode=None, storage=StoragePlugin.SQLITE3):
    """Write a small bag with rosbags' own writer, optionally zstd-compressed."""
    writer = Writer(path, version=8, storage_plugin=storage)
    if mode is not None:
        writer.set_compression(mode, CompressionFormat.ZSTD)
    with writer:
        conn = writer.add_connection('/flow_command', FLOAT64, typestore=TYPESTORE)
        for i in range(10):
            writer.write(conn, 100 + i, encode_message(FLOAT64, {'data': float(i)}))


@pytest.mark.parametrize('storage', [StoragePlugin.SQLITE3, StoragePlugin.MCAP])
@pytest.mark.parametrize('mode', [None, CompressionMode.FILE, CompressionMode.MESSAGE])
def test_compressed_bags_read(tmp_path, mode, storage):
    _rosbags_bag(tmp_path / 'bag', mode, storage)
    series = read_series(tmp_path / 'bag', ['flow_command'])
    assert series['flow_command'].fields['data'].tolist() == list(map(float, range(10)))


def test_bag_without_metadata_reads_from_its_storage_files(tmp_path):
    _rosbags_bag(tmp_path / 'bag')
    (tmp_path / 'bag' / 'metadata.yaml').unlink()
    assert len(read_series(tmp_path / 'bag', ['flow_command'])['flow_command']) == 10
    db3 = next((tmp_path / 'bag').glob('*.db3'))
    assert len(read_series(db3, ['flow_command'])['flow_command']) == 10


def _edit_metadata(bag: Path, edit):
    meta = bag / 'metadata.yaml'
    doc = yaml.safe_load(meta.read_text())
    edit(doc['rosbag2_bagfile_information'])
    meta.write_text(yaml.safe_dump(doc))


@pytest.mark.parametrize(('edit', 'text'), [
    (lambda d: d['topics_with_message_count'][0].update(message_count=11),
     'metadata.yaml and storage disagree: /flow_command has 11 messages in metadata.yaml '
     'and 10 in'),
    (lambda d: d['topics_with_message_count'][0]['topic_metadata'].update(
        type='std_msgs/msg/Float32'),
     '/flow_command is std_msgs/msg/Float32 in metadata.yaml and std_msgs/msg/Float64 in'),
    (lambda d: d.update(relative_file_paths=['gone.db3']), "lists 'gone.db3', which is not"),
    (lambda d: d.update(storage_identifier='mcap'),
     "storage_identifier is 'mcap' but .* is sqlite3"),
    (lambda d: d.update(storage_identifier='rosbag_v1'), "'rosbag_v1' is not supported"),
    (lambda d: d.pop('relative_file_paths'), "missing or malformed 'relative_file_paths'"),
])
def test_metadata_that_disagrees_with_storage_is_one_clear_error(tmp_path, edit, text):
    _rosbags_bag(tmp_path / 'bag')
    _edit_metadata(tmp_path / 'bag', edit)
    with pytest.raises(BagError, match=text) as err:
        read_series(tmp_path / 'bag', ['flow_command'])
    assert '\n' not in str(err.value)


def test_truncated_mcap_and_missing_bag_are_errors(tmp_path):
    write_bag(tmp_path / 'bag', _inputs(np.random.default_rng(4))['topics'])
    mcap = next((tmp_path / 'bag').glob('*.mcap'))
    cut = tmp_path / 'cut'
    cut.mkdir()
    (cut / 'x.mcap').write_bytes(mcap.read_bytes()[:3000])
    with pytest.raises(BagError, match=r'x.mcap: damaged or truncated \(.+\)$'):
        list_topics(cut)
    with pytest.raises(BagError, match='no such bag'):
        list_topics(tmp_path / 'nothing')
    with pytest.raises(BagError, match='already exists'):
        write_bag(tmp_path / 'bag', [])
    shutil.rmtree(tmp_path / 'bag')


@pytest.mark.parametrize('storage', [StoragePlugin.SQLITE3, StoragePlugin.MCAP])
def test_messages_stored_out_of_order_come_back_in_log_time_order(tmp_path, storage):
    with Writer(tmp_path / 'bag', version=9, storage_plugin=storage) as writer:
        conn = writer.add_connection('/inlet_pressure', FLUID_PRESSURE, typestore=TYPESTORE)
        for t in (30, 10, 20, 10):
            writer.write(conn, t, encode_message(FLUID_PRESSURE, {'fluid_pressure': t * 1.0},
                                                 frame_id='a' * (t // 10)))
    series = read_series(tmp_path / 'bag', ['inlet_pressure'])['inlet_pressure']
    assert series.t_ns.tolist() == [10, 10, 20, 30]
    assert series.fields['fluid_pressure'].tolist() == [10.0, 10.0, 20.0, 30.0]


def _zstd_file_compressed(bag):
    """Compress a bag's storage files with zstd and edit metadata.yaml as rosbag2 does."""
    for file in [*bag.glob('*.mcap'), *bag.glob('*.db3')]:
        file.with_name(file.name + '.zstd').write_bytes(zstd.compress(file.read_bytes()))
        file.unlink()

    def edit(doc):
        doc.update(compression_format='zstd', compression_mode='FILE',
                   relative_file_paths=[f + '.zstd' for f in doc['relative_file_paths']])
        for entry in doc.get('files') or ():
            entry['path'] += '.zstd'
    _edit_metadata(bag, edit)


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_zstd_file_compressed_bag_of_our_writer_reads_as_the_plain_one(tmp_path, storage):
    data = _inputs(np.random.default_rng(5))
    write_bag(tmp_path / 'bag', data['topics'], storage=storage)
    names = ['flow_command', 'inlet_pressure', 'joint_states']
    plain = read_series(tmp_path / 'bag', names)
    _zstd_file_compressed(tmp_path / 'bag')
    assert [p.suffixes[-2:] for p in (tmp_path / 'bag').glob('*.zstd')] == [
        ['.mcap' if storage == 'mcap' else '.db3', '.zstd']]
    packed = read_series(tmp_path / 'bag', names)
    for name in names:
        np.testing.assert_array_equal(packed[name].t_ns, plain[name].t_ns)
        for field, values in plain[name].fields.items():
            np.testing.assert_array_equal(packed[name].fields[field], values)
    np.testing.assert_array_equal(packed['flow_command'].fields['data'], data['flow'])
    zst = next((tmp_path / 'bag').glob('*.zstd'))
    assert len(read_series(zst, ['flow_command'])['flow_command']) == N  # the file alone
    zst.write_bytes(zst.read_bytes()[:-100])
    with pytest.raises(BagError, match=f'{zst.name}: not a complete zstd file'):
        read_series(tmp_path / 'bag', names)


def _chunks(mcap):
    """Return the chunk records of an MCAP file."""
    from mcap.records import Chunk
    from mcap.stream_reader import StreamReader
    with mcap.open('rb') as stream:
        return [r for r in StreamReader(stream, emit_chunks=True).records
                if isinstance(r, Chunk)]


def _flip(path, at, count=16):
    data = bytearray(path.read_bytes())
    data[at:at + count] = bytes(b ^ 0xFF for b in data[at:at + count])
    path.write_bytes(bytes(data))


@pytest.mark.parametrize('where', [0.1, 0.5, 0.9])
def test_mcap_bag_with_16_flipped_bytes_in_a_chunk_is_refused_with_one_line(tmp_path, where):
    """Our writer puts CRCs on its chunks; a damaged chunk never gives altered numbers."""
    write_bag(tmp_path / 'bag', _inputs(np.random.default_rng(6))['topics'])
    mcap = next((tmp_path / 'bag').glob('*.mcap'))
    chunks = _chunks(mcap)
    assert chunks and all(c.uncompressed_crc for c in chunks) and \
        {c.compression for c in chunks} == {'zstd'}
    start = mcap.read_bytes().index(chunks[0].data)
    _flip(mcap, start + int(where * len(chunks[0].data)))
    with pytest.raises(BagError, match=rf'^{mcap.name}: damaged or truncated \(.+\)$') as err:
        read_series(tmp_path / 'bag', ['flow_command', 'inlet_pressure', 'joint_states'])
    assert '\n' not in str(err.value)


def test_uncompressed_mcap_chunk_with_flipped_bytes_is_a_crc_mismatch(tmp_path):
    """In a chunk that is not compressed, only the CRC can tell: it must."""
    bag = _mcap_by_the_mcap_library(tmp_path / 'bag', schema_encoding='ros2msg')
    assert list_topics(bag)['/flow_command'].count == 10
    mcap = next(bag.glob('*.mcap'))
    (chunk,) = _chunks(mcap)
    payload = encode_message(FLOAT64, {'data': 5.0})
    _flip(mcap, mcap.read_bytes().index(payload) + 4, count=8)  # the number itself
    with pytest.raises(BagError, match=f'{mcap.name}: damaged or truncated .*checksum'):
        read_series(bag, ['flow_command'])


def _mcap_by_the_mcap_library(bag, schema_encoding):
    """Write a 10-message MCAP bag (no metadata.yaml) with the mcap library, chunks plain."""
    from mcap.writer import CompressionType, Writer as McapWriter
    bag.mkdir()
    with (bag / 'x_0.mcap').open('wb') as stream:
        writer = McapWriter(stream, compression=CompressionType.NONE)
        writer.start(profile='ros2')
        schema = writer.register_schema(FLOAT64, schema_encoding, b'')
        channel = writer.register_channel('/flow_command', 'cdr', schema)
        for i in range(10):
            writer.add_message(channel, 100 + i, encode_message(FLOAT64, {'data': float(i)}),
                               100 + i)
        writer.finish()
    return bag


def test_mcap_with_a_schema_encoding_rosbags_does_not_know_reads(tmp_path):
    """rosbag2 writes schema encoding 'unknown' for types it has no definition of."""
    bag = _mcap_by_the_mcap_library(tmp_path / 'bag', schema_encoding='unknown')
    series = read_series(bag, ['flow_command'])['flow_command']
    assert series.fields['data'].tolist() == list(map(float, range(10)))
    assert series.t_ns.tolist() == list(range(100, 110))
    mcap = next(bag.glob('*.mcap'))
    _flip(mcap, mcap.read_bytes().index(encode_message(FLOAT64, {'data': 5.0})) + 4, 8)
    with pytest.raises(BagError,
                       match=f'{mcap.name}: damaged or truncated .*crc validation failed'):
        read_series(bag, ['flow_command'])


def test_mcap_whose_statistics_count_other_messages_than_it_holds_is_refused(tmp_path):
    bag = _mcap_by_the_mcap_library(tmp_path / 'bag', schema_encoding='ros2msg')
    mcap = next(bag.glob('*.mcap'))
    counts = struct.pack('<IHQ', 10, 1, 10)  # statistics: one channel, id 1, 10 messages
    data = mcap.read_bytes()
    assert data.count(counts) == 1
    mcap.write_bytes(data.replace(counts, struct.pack('<IHQ', 10, 1, 11)))
    assert list_topics(bag)['/flow_command'].count == 11  # the summary, as rosbags reads it
    with pytest.raises(BagError, match=r'x_0.mcap: damaged or truncated \(/flow_command: its '
                                       r'index counts 11 messages, 10 were found\)'):
        read_series(bag, ['flow_command'])
