# SPDX-License-Identifier: Apache-2.0
"""Hostile YAML files end in one line within bounded time and memory (issue 14)."""

import resource
import time

import pytest

from satmotor_ros.bags import BagError, open_bag
from satmotor_ros.bounded_yaml import parse_yaml, read_yaml, YamlLimitError
from satmotor_ros.interface import MotorOptions
from satmotor_ros.limits import YAML_MAX_BYTES
from satmotor_ros.model import ConfigError, load_motor
from satmotor_ros.model.config import default_config_path
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


def test_endless_file_is_cut_at_the_cap():
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(YamlLimitError, match=f'larger than {YAML_MAX_BYTES} bytes'):
        read_yaml('/dev/zero')
    grown_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown_kib < 64 * 1024


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
