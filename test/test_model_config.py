# SPDX-License-Identifier: Apache-2.0
"""Motor specifications load from YAML and every bad value is named by its key."""

import copy

import pytest
from satmotor_ros.model import ConfigError, Liquid, load_motor, MotorModel
from satmotor_ros.model.io.config import default_config_path, motor_from_mapping
from satmotor_ros.model.units import LPM, MPA
import yaml


@pytest.fixture(scope='module')
def document():
    return yaml.safe_load(default_config_path().read_text(encoding='utf-8'))


def test_default_spec_is_the_sm075_25_for_oil_and_water():
    spec = load_motor()
    assert spec.name == 'SM-0,75/25'
    assert set(spec.sets) == {'oil', 'water'}
    assert spec.geometry.displacement_cm3_per_rev == pytest.approx(32.94)
    assert spec.geometry.m2h == pytest.approx(14.0625)
    assert spec.sets['water'].liquid.kinematic_viscosity == pytest.approx(0.853e-6)
    assert spec.valid_range.dp_max == 25 * MPA
    assert spec.valid_range.dp_min == 2 * MPA
    assert spec.valid_range.speed_min == pytest.approx(100 * 2 * 3.141592653589793 / 60)
    assert spec.sets['oil'].fitted_viscosity == pytest.approx((40e-6, 40e-6))


@pytest.mark.parametrize(('path', 'value', 'match'), [
    (('coefficient_sets', 'oil', 'coefficients', 'beta'), 2.5,
     r'coefficient_sets\.oil\.coefficients\.beta = 2\.5 is outside'),
    (('coefficient_sets', 'water', 'coefficients', 'c'), 'abc',
     r"coefficient_sets\.water\.coefficients\.c = 'abc': expected a number"),
    (('geometry', 'module'), '0.75 l/min',
     r"geometry\.module = '0\.75 l/min': unit 'l/min' is not a length unit"),
    (('geometry', 'height'), -1.0, r'geometry\.height = -1\.0 is outside'),
    (('coefficient_sets', 'oil', 'liquid', 'density'), 0, r'liquid\.density = 0\.0 is outside'),
    (('valid_range', 'dp_max'), float('nan'), r'valid_range\.dp_max = nan'),
    (('coefficient_sets', 'oil', 'coefficients', 'compressed_volume_fraction'), 50.0,
     r'compressed_volume_fraction = 50\.0 gives C_fc\*beta_l'),
    (('coefficient_sets', 'oil', 'coefficients', 'gamma'), True,
     r'coefficients\.gamma = True: expected a number'),
    (('coefficient_sets', 'oil', 'viscosity_range'), ['50 cSt', '10 cSt'],
     r'coefficient_sets\.oil\.viscosity_range\[1\] = 9\.99+e-06 is outside \[4\.9+6e-05'),
    (('coefficient_sets', 'oil', 'viscosity_range'), '40 cSt',
     r"coefficient_sets\.oil\.viscosity_range = '40 cSt': expected \[low, high\]"),
    (('coefficient_sets', 'oil', 'viscosity'), 1.0,
     r'coefficient_sets\.oil has unknown key\(s\): viscosity'),
    (('valid_range', 'dp_min'), '30 MPa', r'valid_range\.dp_min = 30000000\.0 is outside'),
])
def test_bad_values_are_named_by_key_and_value(document, path, value, match):
    doc = copy.deepcopy(document)
    node = doc
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(ConfigError, match=match):
        motor_from_mapping(doc)


def test_missing_and_unknown_keys_are_named(document):
    doc = copy.deepcopy(document)
    del doc['coefficient_sets']['oil']['coefficients']['c_id']
    with pytest.raises(ConfigError, match=r'coefficient_sets\.oil\.coefficients is missing '
                                          r'key\(s\): c_id'):
        motor_from_mapping(doc)
    doc = copy.deepcopy(document)
    doc['geometry']['teeth'] = 12
    with pytest.raises(ConfigError, match=r'geometry has unknown key\(s\): teeth'):
        motor_from_mapping(doc)
    with pytest.raises(ConfigError, match='is missing key'):
        motor_from_mapping({'motor': 'x'})
    with pytest.raises(ConfigError, match='must be a mapping'):
        motor_from_mapping(['a list'])


def test_unreadable_and_malformed_files_are_config_errors(tmp_path):
    with pytest.raises(ConfigError, match=r"^cannot read motor config '.*absent\.yaml': "):
        load_motor(tmp_path / 'absent.yaml')
    bad = tmp_path / 'bad.yaml'
    bad.write_text('geometry: [unclosed\n', encoding='utf-8')
    with pytest.raises(ConfigError, match=r"^motor config '.*bad\.yaml': not valid YAML \(line 2"):
        load_motor(bad)


def test_a_spec_knows_its_source_and_the_default_model_is_oil():
    path = default_config_path()
    assert load_motor(path).source == str(path)
    assert load_motor().source == str(path)
    assert MotorModel.default().coefficient_set.name == 'oil'
    assert MotorModel.default().displacement_law == 'eq33'


def test_user_file_with_si_numbers_loads_like_the_default(tmp_path, document):
    doc = copy.deepcopy(document)
    doc['geometry']['displacement'] = 32.94e-6 / (2 * 3.141592653589793)
    doc['coefficient_sets']['oil']['liquid']['kinematic_viscosity'] = 40e-6
    path = tmp_path / 'motor.yaml'
    path.write_text(yaml.safe_dump(doc), encoding='utf-8')
    mine = MotorModel.from_spec(load_motor(path), 'oil')
    ref = MotorModel.default('oil')
    assert float(mine.speed(5 * LPM, 10 * MPA).speed) == pytest.approx(
        float(ref.speed(5 * LPM, 10 * MPA).speed), rel=1e-12)


def test_user_liquid_changes_viscosity_density_and_compressibility_share():
    spec = load_motor()
    hot_oil = Liquid('hot oil', 15e-6, 860.0, 1.4e9)
    hot = MotorModel.from_spec(spec, 'oil', hot_oil)
    ref = MotorModel.from_spec(spec, 'oil')
    assert hot.c_dch == ref.c_dch and hot.c_b == ref.c_b
    assert hot.c_fc_beta == pytest.approx(ref.c_fc_beta * 1.6 / 1.4)
    hot_loss = float(hot.absorbency(500 * 0.10471975511965977, dp_i=10 * MPA).losses.total)
    ref_loss = float(ref.absorbency(500 * 0.10471975511965977, dp_i=10 * MPA).losses.total)
    assert hot_loss > ref_loss  # thinner oil leaks more
    with pytest.raises(ConfigError, match=r'water\.kinematic_viscosity = -1\.0'):
        Liquid('water', -1.0, 1000.0, 2e9)


def test_unknown_coefficient_set_is_named():
    with pytest.raises(Exception, match="coefficient set 'glycol' is not in"):
        MotorModel.from_spec(load_motor(), 'glycol')
