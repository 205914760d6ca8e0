# SPDX-License-Identifier: Apache-2.0
"""The 24 foreign bags of test/data/foreign_bags: every one read, or one clear error."""

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores

from satmotor_ros.bags import BagError, list_topics, open_bag, read_series
from vendored_data import data_path, foreign_bag, FOREIGN_BAGS

# Messages in the storage, counted independently of any bag library (the bags' README).
STORAGE_COUNTS = {
    'v1_crystal_cdr_test': 7, 'v4_talker_2020': 20, 'v4_talker_dbschema4_qos_edited': 20,
    'v4_talker_mcap_gocli': 20, 'v4_test_msgs_strings': 10, 'v4_empty': 0,
    'v4_empty_zstd_file': 0, 'v4_wbag_split5': 6074, 'v5_humble_sensor_sqlite3': 34,
    'v5_humble_sensor_mcap': 2, 'v5_humble_geometry_mcap': 3, 'v5_nebula_radar_custom': 4,
    'v5_nebula_vlp32_empty_qos': 5, 'v6_wrong_format_mcap': 7, 'v7_cdr_test_sqlite3': 7,
    'v7_cdr_test_mcap': 7, 'v8_services_sqlite3': 10, 'v8_services_mcap': 10,
    'v9_actions_sqlite3': 187, 'v9_actions_mcap': 218, 'nometa_split3_talker': 52,
    'nometa_msgcompressed_split4': 1127, 'nometa_filecompressed_split4': 775,
}
DISAGREEING = {'v3_cdr_test_type_mismatch': '/test_topic is test_msgs/msg/BasicTypes in '
                                            'metadata.yaml and test_msgs/msg/Primitives in'}


def test_the_table_covers_all_24_bags():
    bags = sorted(p.name for p in data_path('foreign_bags').iterdir() if p.is_dir())
    assert bags == sorted([*STORAGE_COUNTS, *DISAGREEING]) == sorted(FOREIGN_BAGS)
    assert len(bags) == 24


@pytest.mark.parametrize('name', sorted(STORAGE_COUNTS))
def test_foreign_bag_reads_every_message_of_its_storage(name):
    topics = list_topics(foreign_bag(name))
    assert sum(t.count for t in topics.values()) == STORAGE_COUNTS[name]
    infos, raw = open_bag(foreign_bag(name)).read(set(topics))  # every message, walked
    assert {n: len(r.t_ns) for n, r in raw.items()} == {n: t.count for n, t in infos.items()}
    assert {n: t for n, t in infos.items() if t.count} == \
        {n: t for n, t in topics.items() if t.count}  # the summary may list empty channels
    for messages in raw.values():
        assert (np.diff(messages.t_ns) >= 0).all()
        if len(messages.t_ns):
            assert messages.payload(0)[:2] in (b'\x00\x01', b'\x00\x00')  # CDR, unpacked


@pytest.mark.parametrize('name', sorted(DISAGREEING))
def test_foreign_bag_whose_metadata_disagrees_is_one_clear_error(name):
    with pytest.raises(BagError, match=DISAGREEING[name]) as err:
        list_topics(foreign_bag(name))
    assert '\n' not in str(err.value)


def _rosbags_messages(bag):
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    with AnyReader([foreign_bag(bag)], default_typestore=typestore) as reader:
        return [(t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()
                if c.msgtype in ('sensor_msgs/msg/JointState', 'sensor_msgs/msg/Temperature')]


def test_foreign_joint_state_and_temperature_decode_as_rosbags_decodes_them():
    joint = read_series(foreign_bag('v5_humble_sensor_mcap'), ['joint_states'],
                        {'/one_shot/joint_state': 'joint_states'}, joint='joint2')
    ((t, msg),) = _rosbags_messages('v5_humble_sensor_mcap')
    series = joint['joint_states']
    assert series.t_ns.tolist() == [t]
    assert [series.fields[k][0] for k in ('position', 'velocity', 'effort')] == [
        msg.position[1], msg.velocity[1], msg.effort[1]]
    temp = read_series(foreign_bag('v5_humble_sensor_sqlite3'), ['fluid_temperature'],
                       {'/my_temperature': 'fluid_temperature'})['fluid_temperature']
    expected = _rosbags_messages('v5_humble_sensor_sqlite3')
    np.testing.assert_array_equal(temp.fields['temperature'], [m.temperature
                                                               for _, m in expected])
    np.testing.assert_array_equal(temp.t_ns, [t for t, _ in expected])


def test_foreign_wrong_serialization_format_is_named():
    with pytest.raises(BagError, match="serialization format 'wrong_format' is not supported"):
        read_series(foreign_bag('v6_wrong_format_mcap'), ['x'], {'/test_topic': 'x'})
