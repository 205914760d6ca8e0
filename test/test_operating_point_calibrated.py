# SPDX-License-Identifier: Apache-2.0
"""``operating-point`` on calibrated motor files: the effects' values, their channels."""

import json

import numpy as np
import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import calibrate, read_csv, write_csv
from satmotor_ros.identify.output import write_yaml
from satmotor_ros.identify.synthetic import generate, Injection, Plan, to_columns
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA, RPM
import yaml


def _calibrated(tmp, effect, seed=3):
    """Calibrate on synthetic data with `effect` injected; return the coefficients file."""
    table = generate(Plan(liquid='oil'), Injection.realistic(effect, 2.0, 'oil'), seed=seed)
    data = tmp / f'{effect}.csv'
    write_csv(data, to_columns(table))
    # what `satmotor calibrate` does, but its report (plots): calibrate, then its writer
    path = tmp / f'cal_{effect}.yaml'
    write_yaml(calibrate(read_csv(data), 'oil'), path)
    return path


@pytest.fixture(scope='module')
def files(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('cal')
    return {effect: _calibrated(tmp, effect)
            for effect in ('term:dp^2*n', 'flow_sensor_offset', 'external_leakage')}


def _point(capsys, motor, *extra):
    code = main(['operating-point', '--motor', str(motor), '--flow', '20', '--dp', '10',
                 '--json', *extra])
    out, err = capsys.readouterr()
    return code, (json.loads(out) if code == 0 else None), err


def _effects(motor):
    doc = yaml.safe_load(motor.read_text())
    return doc['coefficient_sets']['oil']['effects']


def test_a_channel_free_term_is_evaluated_and_its_loss_shown(files, capsys):
    motor = files['term:dp^2*n']
    (name, effect), = _effects(motor).items()
    assert name.startswith('term:')
    code, result, err = _point(capsys, motor)
    assert code == 0, err
    model = MotorModel.from_spec(load_motor(motor), 'oil')
    point = model.speed_point(20 * LPM, 10 * MPA)
    assert result['speed_rpm'] == pytest.approx(point.speed / RPM, rel=1e-9)
    extra = effect['coefficient'] * (result['dp_i_MPa'] * MPA) ** effect['exponents']['dp'] \
        * result['speed_rad_s'] ** effect['exponents']['n']
    assert result['effects'] == [name]
    assert result['effects_lpm'] == pytest.approx(extra / LPM, rel=1e-6)
    assert result['effects_lpm'] > 0.0
    assert main(['operating-point', '--motor', str(motor), '--flow', '20', '--dp', '10']) == 0
    assert f'  of it from {name}' in capsys.readouterr().out


def test_a_sensor_effect_file_gives_a_point(files, capsys):
    code, result, err = _point(capsys, files['flow_sensor_offset'])
    assert code == 0, err
    assert result['status'] == 'OK' and result['speed_rpm'] > 0.0


def test_the_model_scalar_path_returns_scalars_with_effects(files):
    model = MotorModel.from_spec(load_motor(files['term:dp^2*n']), 'oil')
    op = model.speed(20 * LPM, 10 * MPA)
    assert np.shape(op.speed) == () and np.shape(op.losses.total) == ()
    assert np.shape(op.status) == ()
    assert np.shape(model.absorbency(np.full(3, 50.0), 10 * MPA).flow) == (3,)


def test_external_leakage_reads_the_case_pressure_given(files, capsys):
    motor = files['external_leakage']
    k = _effects(motor)['external_leakage']['coefficient']
    code, _, err = _point(capsys, motor)
    assert code == 1
    assert err.strip() == ("satmotor: error: --channel: the motor file's effects read p_case; "
                           'give --channel p_case=VALUE')
    code, result, err = _point(capsys, motor, '--channel', 'p_case=0.3MPa')
    assert code == 0, err
    assert result['losses_lpm']['external'] == pytest.approx(k * 0.3 * MPA / LPM, rel=1e-9)
    assert result['channels'] == {'p_case': pytest.approx(0.3 * MPA)}
    code, absolute, _ = _point(capsys, motor, '--channel', 'p_case=4bara')
    assert absolute['channels']['p_case'] == pytest.approx(4e5 - ATMOSPHERE)


@pytest.mark.parametrize('channel, message', [
    ('p_case', "--channel 'p_case': use NAME=VALUE"),
    ('temperature=40', "--channel 'temperature=40': the motor file's effects read p_case, "
                       "not 'temperature'"),
    ('p_case=3degC', "--channel 'p_case=3degC': unit 'degC' is not a pressure unit"),
    ('p_case=-1', "--channel 'p_case=-1': a pressure must be >= 0"),
    ('p_case=1e400', "--channel 'p_case=1e400': must be a finite value"),
])
def test_a_bad_channel_is_one_line_naming_it(files, capsys, channel, message):
    code, _, err = _point(capsys, files['external_leakage'], '--channel', channel)
    assert code == 1
    assert err.count('\n') == 1 and message in err


def test_a_channel_twice_is_refused(files, capsys):
    code, _, err = _point(capsys, files['external_leakage'], '--channel', 'p_case=1',
                          '--channel', 'p_case=2')
    assert code == 1 and 'p_case is given twice' in err


def test_a_reverse_loss_file_gives_a_point_both_ways(files, tmp_path, capsys):
    doc = yaml.safe_load(files['flow_sensor_offset'].read_text())
    doc['coefficient_sets']['oil']['effects']['reverse_loss'] = {'coefficient': 1e-13}
    motor = tmp_path / 'reverse.yaml'
    motor.write_text(yaml.safe_dump(doc))
    for flow in ('20', '-20'):
        assert main(['operating-point', '--motor', str(motor), '--flow', flow, '--dp', '10',
                     '--json']) == 0
        assert json.loads(capsys.readouterr().out)['speed_rad_s'] != 0.0


@pytest.mark.parametrize('suffix', ['dp^.', 'dp^1.2.3', 'n^11'])
def test_a_malformed_term_exponent_is_one_line(files, tmp_path, capsys, suffix):
    text = files['term:dp^2*n'].read_text()
    name, = _effects(files['term:dp^2*n'])
    motor = tmp_path / 'bad.yaml'
    motor.write_text(text.replace(f'{name}:', f'term:{suffix}:'))
    code, _, err = _point(capsys, motor)
    assert code == 1 and err.count('\n') == 1
    assert f'term {suffix!r} is not a product of powers of dp and n' in err
