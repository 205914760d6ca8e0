# SPDX-License-Identifier: Apache-2.0
"""The ``satmotor`` command: operating points, characteristics and one-line errors."""

import csv
import json
import re

import pytest

from satmotor_ros.cli import main


def _run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_operating_point_json_has_speed_loss_and_breakdown(capsys):
    code, out, _ = _run(capsys, 'operating-point', '--liquid', 'water', '--flow', '5',
                        '--dp-i', '25', '--json')
    assert code == 0
    result = json.loads(out)
    assert result['speed_rpm'] == pytest.approx(74.6, abs=0.05)
    assert result['speed_loss_rpm'] == pytest.approx(5000 / 32.94 - 74.6, abs=0.05)
    losses = result['losses_lpm']
    assert set(losses) == {'flat_clearance', 'commutation', 'compressibility', 'deformation',
                           'backlash', 'inertia', 'external', 'total'}
    assert losses['total'] == pytest.approx(sum(v for k, v in losses.items() if k != 'total'))
    assert result['status'] == 'EXTRAPOLATED'  # 74.6 rpm: below the 100 rpm measured


@pytest.mark.parametrize(('flow', 'dp'), [('5', '25'), ('8.333333333e-5m^3/s', '250bar'),
                                          ('5 l/min', '25000 kPa')])
def test_operating_point_accepts_units(capsys, flow, dp):
    code, out, _ = _run(capsys, 'operating-point', '--flow', flow, '--dp', dp, '--json')
    assert code == 0
    assert json.loads(out)['dp_MPa'] == pytest.approx(25.0)
    assert json.loads(out)['flow_lpm'] == pytest.approx(5.0)


def test_operating_point_table_names_every_component(capsys):
    code, out, _ = _run(capsys, 'operating-point', '--flow', '20', '--dp', '10')
    assert code == 0
    for label in ('speed n', 'speed loss n_i', 'Q_Lfg, eq. (1)', 'Q_C, eq. (5)',
                  'dQ_fc, eq. (11)', 'dQ_dch, eq. (12)', 'dQ_b, eq. (13)', 'dQ_id, eq. (14)',
                  'Q_ex, eq. (24)', 'Q_vl, eq. (31)'):
        assert label in out


def test_operating_point_with_user_liquid(capsys):
    _, ref, _ = _run(capsys, 'operating-point', '--flow', '10', '--dp', '10', '--json')
    code, out, _ = _run(capsys, 'operating-point', '--flow', '10', '--dp', '10', '--json',
                        '--viscosity', '15', '--density', '860', '--bulk-modulus', '1.4GPa')
    assert code == 0
    assert json.loads(out)['speed_rpm'] < json.loads(ref)['speed_rpm']
    assert json.loads(out)['liquid'].startswith('user liquid')


def test_stalled_point_warns(capsys):
    code, out, _ = _run(capsys, 'operating-point', '--flow', '0.01', '--dp', '25')
    assert code == 0
    assert 'STALLED' in out and 'does not turn' in out


@pytest.mark.parametrize(('argv', 'message'), [
    (['--flow', '1e400', '--dp', '2'], "--flow '1e400': must be a finite value"),
    (['--flow', 'nan', '--dp', '2'], "--flow 'nan': 'nan' is not a number"),
    (['--flow', '5', '--dp', '2kg'], "--dp '2kg': unit 'kg' is not a pressure unit"),
    (['--flow', '5', '--dp', '80'], 'dp = 80000000.0 Pa: chamber pressure drop beyond'),
    (['--flow', '5', '--dp', '2', '--liquid', 'glycol'], "--liquid 'glycol': not a coefficient"),
    (['--flow', '5', '--dp', '2', '--viscosity', '0'], "--viscosity '0': must be a finite value"),
    (['--flow', '5', '--dp', '2', '--density', 'heavy'], "--density 'heavy'"),
    (['--flow', '5', '--dp', '2', '--motor', '/nonexistent.yaml'], 'cannot read motor config'),
])
def test_bad_input_exits_1_with_one_line_naming_the_field(capsys, argv, message):
    code, out, err = _run(capsys, 'operating-point', *argv)
    assert code == 1
    assert out == ''
    assert err.count('\n') == 1 and message in err


def test_characteristics_writes_png_and_csv(tmp_path, capsys):
    code, out, _ = _run(capsys, 'characteristics', '--liquid', 'oil', '--out', str(tmp_path),
                        '--points', '12')
    assert code == 0
    names = ('constant_flow', 'constant_speed', 'displacement_change', 'speed_loss',
             'water_oil_ratio')
    for name in names:
        png = tmp_path / f'{name}.png'
        assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
        assert png.stat().st_size > 10_000
        with (tmp_path / f'{name}.csv').open(encoding='utf-8') as stream:
            rows = list(csv.reader(stream))
        assert all('[' in header for header in rows[0])
        assert len(rows) == 1 + 4 * 12
    with (tmp_path / 'water_oil_ratio.csv').open(encoding='utf-8') as stream:
        rows = [r for r in csv.DictReader(stream) if r['Q [l/min]'] == '5']
    assert float(rows[-1]['n_w/n_o [-]']) == pytest.approx(0.560, abs=0.001)


def test_characteristics_refuses_an_unwritable_directory(tmp_path, capsys):
    blocker = tmp_path / 'file'
    blocker.write_text('x')
    code, _, err = _run(capsys, 'characteristics', '--out', str(blocker / 'sub'))
    assert code == 1 and '--out' in err


def test_usage_errors_exit_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(['operating-point', '--flow', '5'])
    assert exc.value.code == 2


def test_every_model_subcommand_takes_the_same_motor_options_as_the_nodes(capsys, tmp_path):
    """--law and a user liquid reach the model, as the node parameters of the same names."""
    from satmotor_ros.options import MotorOptions
    code, out, _ = _run(capsys, 'operating-point', '--flow', '10', '--dp', '10', '--json',
                        '--law', 'eq39', '--viscosity', '15', '--liquid', 'water')
    assert code == 0
    result = json.loads(out)
    model = MotorOptions('water', displacement_law='eq39', viscosity=15e-6).build_model()
    assert result['displacement_law'] == 'eq39' == model.displacement_law
    assert result['liquid'] == model.liquid.name == 'user liquid on the water set'
    assert result['speed_rad_s'] == pytest.approx(float(model.speed(10 / 60000, 10e6).speed),
                                                  rel=1e-12)
    code, _, _ = _run(capsys, 'characteristics', '--out', str(tmp_path), '--points', '3',
                      '--law', 'eq39', '--density', '900')
    assert code == 0


@pytest.mark.parametrize('family', ['sliwinski2017', 'balawender', 'paszota'])
def test_operating_point_of_each_family_labels_its_own_components(capsys, family):
    from satmotor_ros.options import MotorOptions
    from satmotor_ros.model.families import FAMILIES
    code, out, _ = _run(capsys, 'operating-point', '--flow', '10', '--dp', '10', '--family',
                        family, '--json')
    assert code == 0 and json.loads(out)['family'] == family
    model = MotorOptions(family=family).build_model()
    assert json.loads(out)['speed_rad_s'] == pytest.approx(
        model.speed_point(10 / 60000, 10e6).speed, rel=1e-12)
    code, out, _ = _run(capsys, 'operating-point', '--flow', '10', '--dp', '10', '--family',
                        family)
    labels = FAMILIES[family].components
    assert all(label in out for label in labels.values())
    assert ('Q_C, eq. (5)' in out) == (family == 'sliwinski2017')


def test_displacement_builds_a_motor_with_no_yaml(capsys, tmp_path):
    code, out, _ = _run(capsys, 'operating-point', '--flow', '10', '--dp', '10', '--family',
                        'paszota', '--displacement', '0.30in^3/rev', '--json')
    assert code == 0
    result = json.loads(out)
    assert result['motor'].startswith('paszota motor of 4.916 cm^3/rev')
    assert 1900 < result['speed_rpm'] < 10 / 0.0049161
    code, _, _ = _run(capsys, 'characteristics', '--out', str(tmp_path), '--points', '3',
                      '--family', 'balawender', '--displacement', '5')
    assert code == 0 and (tmp_path / 'water_oil_ratio.png').is_file()
    assert not (tmp_path / 'displacement_change.png').exists()  # eqs. (33), (39): not its own


@pytest.mark.parametrize(('argv', 'message'), [
    (['--displacement', '0'], "--displacement '0': must be a finite value > 0"),
    (['--displacement', '5', '--motor', 'x.yaml'], '--displacement 7.9577'),
    (['--family', 'paszota', '--motor', 'config/sm075_25.yaml'],
     "--family 'paszota': config/sm075_25.yaml is a sliwinski2017 motor"),
    (['--family', 'paszota', '--law', 'eq39'], "the paszota family has 'eq33'"),
])
def test_family_options_refuse_with_one_line_naming_the_option(capsys, argv, message):
    code, out, err = _run(capsys, 'operating-point', '--flow', '5', '--dp', '2', *argv)
    assert code == 1 and out == ''
    assert err.count('\n') == 1 and message in err, err


def test_operating_point_takes_signed_flow_and_drop(capsys):
    code, out, _ = _run(capsys, 'operating-point', '--liquid', 'oil', '--flow=-10',
                        '--dp=-100bar')
    assert code == 0
    assert re.search(r'speed n\s+-\d', out) and 'flow Q                  -10.000' in out
