# SPDX-License-Identifier: Apache-2.0
"""Hostile YAML files end in one line within bounded time and memory (issue 14)."""

import os
import resource
import subprocess
import sys
import time

import pytest

from satmotor_ros.bags import BagError, open_bag
from satmotor_ros.bounded_yaml import parse_yaml, read_yaml, YamlLimitError
from satmotor_ros.identify.columns import load_mapping
from satmotor_ros.identify.errors import DataError
from satmotor_ros.limits import YAML_MAX_BYTES
from satmotor_ros.model import ConfigError, load_motor
from satmotor_ros.model.io.config import default_config_path
from satmotor_ros.options import MotorOptions
from satmotor_ros.plant.errors import PlantError
from satmotor_ros.plant.params import PlantParams


def _alias_bomb(levels: int = 9) -> str:
    """Return a 'billion laughs' document: 9 ** levels strings from under 1 KB of text."""
    lines = ['a0: &a0 [' + ', '.join(['"lol"'] * 9) + ']']
    for i in range(1, levels):
        lines.append(f'a{i}: &a{i} [' + ', '.join([f'*a{i - 1}'] * 9) + ']')
    return '\n'.join(lines) + '\n'


HOSTILE = {
    'alias bomb': (_alias_bomb(), 'aliases expand to more than'),
    'deep nesting': ('[' * 20000, 'nesting deeper than'),
    'huge integer': ('geometry:\n  module: ' + '9' * 400 + '\n', 'an integer of 400 digits'),
    'huge hex integer': ('a1: 0x' + 'f' * 400 + '\n', 'an integer of 402 digits'),
    'hex beyond int()': ('a1: 0x' + 'f' * 5000 + '\n', 'an integer of 5002 digits'),
    'huge octal integer': ('a1: 0' + '7' * 400 + '\n', 'an integer of 401 digits'),
    'huge binary integer': ('a1: -0b' + '1' * 400 + '\n', 'an integer of 402 digits'),
    'underscored integer': ('a1: 1' + '_9' * 400 + '\n', 'an integer of 401 digits'),
    'sexagesimal integer': ('a1: 1' + ':59' * 200 + '\n', 'an integer of 401 digits'),
    'duplicate key': ('motor: a\nmotor: b\n', "line 2: key 'motor' is given twice"),
    'not yaml': ('a: [1, 2\n', 'not valid YAML'),
}


@pytest.mark.parametrize('name', list(HOSTILE))
def test_hostile_document_gives_one_line_quickly(name):
    text, expected = HOSTILE[name]
    start = time.perf_counter()
    with pytest.raises(YamlLimitError, match=expected) as info:
        parse_yaml(text)
    assert time.perf_counter() - start < 2.0
    message = str(info.value)
    assert '\n' not in message and len(message) < 200  # never the document itself


def test_aliases_that_stay_small_are_read():
    doc = parse_yaml('base: &b {x: 1}\nuse: [*b, *b]\n')
    assert doc['use'] == [{'x': 1}, {'x': 1}]


@pytest.mark.parametrize('text', ['0x' + 'f' * 38, '9' * 40, '-0b' + '1' * 38, '1:30:00'])
def test_integers_within_the_cap_are_read(text):
    assert isinstance(parse_yaml(f'a1: {text}\n')['a1'], int)


def test_file_larger_than_the_cap_is_refused(tmp_path):
    path = tmp_path / 'large.yaml'
    path.write_text('# ' + 'x' * YAML_MAX_BYTES + '\n')
    with pytest.raises(YamlLimitError, match=f'larger than {YAML_MAX_BYTES} bytes'):
        read_yaml(path)


def test_endless_device_is_refused_unread():
    # a device is not a regular file: refused before reading (formerly cut at the size cap)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(YamlLimitError, match='not a regular file'):
        read_yaml('/dev/zero')
    grown_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown_kib < 64 * 1024


def test_fifo_is_refused_at_once_and_never_blocks(tmp_path):
    fifo = tmp_path / 'fifo.yaml'
    os.mkfifo(fifo)
    start = time.perf_counter()
    with pytest.raises(YamlLimitError, match=r'^not a regular file'):
        read_yaml(fifo)
    with pytest.raises(ConfigError, match=r"^motor config '.*fifo.yaml': not a regular file"):
        MotorOptions(motor_file=str(fifo)).build_model()
    with pytest.raises(DataError, match=r'fifo.yaml: not a regular file'):
        load_mapping(str(fifo))
    assert time.perf_counter() - start < 2.0


def test_cli_refuses_a_fifo_and_a_hex_bomb_with_one_line(tmp_path):
    fifo, bomb = tmp_path / 'fifo.yaml', tmp_path / 'bomb.yaml'
    os.mkfifo(fifo)
    hex_a1 = 'a1: 0x' + 'f' * 400 + ' #'
    bomb.write_text(default_config_path().read_text().replace('a1:', hex_a1, 1))
    for path, reason in ((fifo, 'not a regular file'), (bomb, 'an integer of 402 digits')):
        proc = subprocess.run([sys.executable, '-m', 'satmotor_ros.cli', 'operating-point',
                               '--flow', '30', '--dp-i', '10', '--motor', str(path)],
                              capture_output=True, text=True, timeout=60)
        assert proc.returncode == 1 and proc.stderr.count('\n') == 1, proc.stderr
        assert reason in proc.stderr and 'Traceback' not in proc.stderr, proc.stderr


def test_a_long_value_in_a_column_mapping_is_cut_in_the_error(tmp_path):
    path = tmp_path / 'long.columns.yaml'
    path.write_text(f'columns:\n  flow: {{column: q, unit: l/min, sign: "{"1" * 480}"}}\n')
    with pytest.raises(DataError, match=r"sign: '1111.*\.\.\. \(482 characters\): use 1") \
            as info:
        load_mapping(str(path))
    assert len(str(info.value)) < 200
    path.write_text('columns:\n  flow: {column: q, unit: l/min, sign: 0x' + 'f' * 5000 + '}\n')
    with pytest.raises(DataError, match='an integer of 5002 digits'):
        load_mapping(str(path))


def test_motor_file_bomb_is_a_config_error_naming_the_file(tmp_path):
    path = tmp_path / 'bomb.yaml'
    path.write_text(_alias_bomb())
    with pytest.raises(ConfigError, match=r"motor config '.*bomb.yaml': aliases expand"):
        load_motor(path)
    with pytest.raises(ConfigError, match='aliases expand'):
        MotorOptions(motor_file=str(path)).build_model()


def test_packaged_motor_still_loads():
    assert read_yaml(default_config_path())['motor']
    assert set(load_motor().sets) == {'oil', 'water'}


def test_bag_metadata_bomb_is_a_bag_error(tmp_path):
    (tmp_path / 'metadata.yaml').write_text(_alias_bomb())
    with pytest.raises(BagError, match='aliases expand'):
        open_bag(tmp_path)


@pytest.mark.parametrize('name', ['../outside.mcap', '/tmp/outside.mcap', 'sub/../../x.mcap'])
def test_bag_files_stay_inside_the_bag_directory(tmp_path, name):
    bag = tmp_path / 'bag'
    bag.mkdir()
    (tmp_path / 'outside.mcap').write_bytes(b'')
    (bag / 'metadata.yaml').write_text(
        'rosbag2_bagfile_information:\n  storage_identifier: mcap\n'
        f'  relative_file_paths: [{name!r}]\n  topics_with_message_count: []\n')
    with pytest.raises(BagError, match='outside the bag directory'):
        open_bag(bag)


@pytest.mark.parametrize(('field', 'value'), [('bulk_modulus', 5e-324), ('density', 1e-300),
                                              ('viscosity', 1e-300), ('bulk_modulus', 1e13)])
def test_user_liquid_that_would_make_inf_is_refused(field, value):
    with pytest.raises(ConfigError, match=field.replace('viscosity', 'kinematic_viscosity')):
        MotorOptions(**{field: value}).build_model()


@pytest.mark.parametrize('seed', [-1, 2 ** 63])
def test_plant_seed_outside_numpy_range_is_refused(seed):
    with pytest.raises(PlantError, match=f'seed = {seed}'):
        PlantParams(seed=seed)
