# SPDX-License-Identifier: Apache-2.0
"""zstd bombs in a bag end in one line, within the decompression budget (issue 14)."""

import pytest

from satmotor_ros.bags import BagError, open_bag
from satmotor_ros.bags import storage
from satmotor_ros.limits import bag_budget, BAG_FLOOR_BYTES, BAG_MAX_RATIO

if storage.sys.version_info >= (3, 14):
    from compression import zstd
else:
    from backports import zstd

BUDGET = 1 << 20  # [byte]; the tests shrink the budget so that a 4 MiB bomb exceeds it
ZEROS = b'\0' * (4 << 20)


@pytest.fixture(autouse=True)
def small_budget(monkeypatch):
    monkeypatch.setattr(storage, 'bag_budget', lambda stored: BUDGET)


def _mcap(path, payload, compression):
    from mcap.writer import CompressionType, Writer
    with path.open('wb') as stream:
        writer = Writer(stream, compression=getattr(CompressionType, compression))
        writer.start(profile='ros2', library='test')
        schema = writer.register_schema('std_msgs/msg/Float64', 'ros2msg', b'float64 data')
        channel = writer.register_channel('/x', 'cdr', schema)
        writer.add_message(channel, log_time=1, data=payload, publish_time=1)
        writer.finish()
    return path


def test_budget_grows_with_the_stored_size_between_floor_and_cap():
    assert bag_budget(0) == BAG_FLOOR_BYTES
    assert bag_budget(10 << 20) == BAG_MAX_RATIO * (10 << 20)


def test_file_compressed_bomb_is_refused(tmp_path):
    path = tmp_path / 'bomb.mcap.zstd'
    path.write_bytes(zstd.compress(bytes(_mcap(tmp_path / 'plain.mcap', ZEROS,
                                               'NONE').read_bytes())))
    assert path.stat().st_size < 64 << 10
    with pytest.raises(BagError, match=r'bomb.mcap.zstd: decompresses to more than 1048576 '):
        open_bag(path).topics()


def test_chunk_compressed_bomb_is_refused_before_it_is_decompressed(tmp_path):
    path = _mcap(tmp_path / 'bomb.mcap', ZEROS, 'ZSTD')
    assert path.stat().st_size < 64 << 10
    with pytest.raises(BagError, match='bomb.mcap: decompresses to more than'):
        open_bag(path).topics()


def test_message_compressed_bomb_is_refused(tmp_path):
    path = _mcap(tmp_path / 'bomb.mcap', zstd.compress(ZEROS), 'NONE')
    with pytest.raises(BagError, match='/x: decompresses to more than'):
        open_bag(path).read(['/x'])


def test_a_bag_within_its_budget_is_read(tmp_path):
    small = b'\0\1' * 1000
    path = _mcap(tmp_path / 'fine.mcap', zstd.compress(small), 'ZSTD')
    _, raw = open_bag(path).read(['/x'])
    assert raw['/x'].payload(0) == small
