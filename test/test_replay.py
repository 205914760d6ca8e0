# SPDX-License-Identifier: Apache-2.0
"""``satmotor replay``: bags through the node's prediction, CSV, bag and plot out."""

import csv

import numpy as np
import pytest
from satmotor_ros.bags import encode_many, OutTopic, read_series, write_bag
from satmotor_ros.cli.main import main
from satmotor_ros.interface import FLOAT64, FLUID_PRESSURE, JOINT_STATE
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM
from vendored_data import foreign_bag, FOREIGN_BAGS

OIL = MotorModel.default('oil')


def _bag(path, n=300, prefix='/motor1/', bad_from=None, joint=True, names=None):
    """Write an input bag at 100 Hz: pressures 1 ms, joint 2 ms before each flow_command."""
    rng = np.random.default_rng(7)
    t = 2_000_000_000 + np.arange(n, dtype=np.int64) * 10_000_000
    flow = rng.uniform(5, 40, n) * LPM
    p_in = rng.uniform(5, 25, n) * MPA
    p_out = rng.uniform(0.1, 1.0, n) * MPA
    if bad_from is not None:  # an absolute pressure below 0 (p_out > p_in is a pump's drop)
        p_out[bad_from:] = -MPA
    speed = rng.uniform(50, 150, n)
    names = names or {}
    topics = [
        OutTopic(names.get('flow', prefix + 'flow_command'), FLOAT64, t + 3_000_000,
                 encode_many(FLOAT64, {'data': flow})),
        OutTopic(names.get('p_in', prefix + 'inlet_pressure'), FLUID_PRESSURE, t + 1_000_000,
                 encode_many(FLUID_PRESSURE, {'fluid_pressure': p_in}, t)),
        OutTopic(names.get('p_out', prefix + 'outlet_pressure'), FLUID_PRESSURE,
                 t + 1_000_000, encode_many(FLUID_PRESSURE, {'fluid_pressure': p_out}, t)),
    ]
    if joint:
        topics.append(OutTopic(prefix + 'joint_states', JOINT_STATE, t + 2_000_000,
                               encode_many(JOINT_STATE, {'velocity': speed}, t,
                                           joint='motor_shaft')))
    write_bag(path, topics)
    return {'flow': flow, 'p_in': p_in, 'p_out': p_out, 'speed': speed, 't': t + 3_000_000}


def _rows(path):
    with open(path, newline='') as stream:
        return list(csv.DictReader(stream))


def test_replay_writes_csv_bag_and_plot_equal_to_the_model(tmp_path, capsys):
    data = _bag(tmp_path / 'bag')
    out, out_bag, png = tmp_path / 'p.csv', tmp_path / 'out_bag', tmp_path / 'speed.png'
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil',
                 '--out', str(out), '--out-bag',
                 str(out_bag), '--plot', str(png)]) == 0
    printed = capsys.readouterr().out
    assert '300 driving messages, 300 predictions (0 with a warning), 0 rejected' in printed
    assert 'residual measured - predicted speed over 300 points' in printed
    rows = _rows(out)
    assert len(rows) == 300
    assert {'flow [l/min]', 'p_in [MPa]', 'speed [rpm]', 'speed [rad/s]', 'total [l/min]',
            'residual [rpm]', 'log_time [ns]', 'level'} <= set(rows[0])
    assert 'p_case [MPa]' not in rows[0]  # not in the bag: no column
    expected = OIL.speed(data['flow'], data['p_in'] - data['p_out'])
    speed = np.array([float(r['speed [rad/s]']) for r in rows])
    np.testing.assert_allclose(speed, expected.speed, rtol=1e-13)  # 12 decimals in the CSV
    np.testing.assert_allclose([float(r['total [l/min]']) for r in rows],
                               expected.losses.total / LPM, rtol=1e-12)
    np.testing.assert_allclose([float(r['residual [rpm]']) for r in rows],
                               (data['speed'] - expected.speed) / RPM, rtol=0, atol=1e-9)
    assert [int(r['log_time [ns]']) for r in rows] == data['t'].tolist()
    replayed = read_series(out_bag, ['predicted_joint_state', 'losses/total', 'speed_residual',
                                     'flow_command', 'joint_states'])
    assert replayed['predicted_joint_state'].topic == '/motor1/predicted_joint_state'
    np.testing.assert_array_equal(replayed['predicted_joint_state'].fields['velocity'],
                                  expected.speed)  # the bag holds the doubles, exactly
    np.testing.assert_array_equal(replayed['predicted_joint_state'].stamp_ns, data['t'])
    np.testing.assert_array_equal(replayed['losses/total'].fields['data'],
                                  expected.losses.total)
    np.testing.assert_array_equal(replayed['flow_command'].fields['data'], data['flow'])
    assert len(replayed['speed_residual']) == len(replayed['joint_states']) == 300
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n' and png.stat().st_size > 20000


def test_replay_without_measured_speed_reports_no_residual_and_no_plot(tmp_path, capsys):
    _bag(tmp_path / 'bag', joint=False)
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil',
                 '--out', str(tmp_path / 'p.csv')]) == 0
    assert 'no measured speed (joint_states): no residual' in capsys.readouterr().out
    assert 'residual [rpm]' not in _rows(tmp_path / 'p.csv')[0]
    assert not list(tmp_path.glob('*.png'))


def test_replay_marks_rejected_rows_and_counts_them(tmp_path, capsys):
    _bag(tmp_path / 'bag', bad_from=200)
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil',
                 '--out', str(tmp_path / 'p.csv'),
                 '--no-plot']) == 0
    printed = capsys.readouterr().out
    assert '200 predictions (0 with a warning), 100 rejected' in printed
    assert 'first ERROR at 2.000 s: outlet_pressure.fluid_pressure = ' in printed
    rows = _rows(tmp_path / 'p.csv')
    assert rows[250]['level'] == 'ERROR' and rows[250]['speed [rpm]'] == ''
    assert rows[250]['inputs'] == 'outlet_pressure:NEGATIVE'
    assert rows[10]['level'] == 'OK' and rows[10]['inputs'] == ''


def test_replay_with_no_usable_prediction_fails_with_one_line(tmp_path, capsys):
    _bag(tmp_path / 'bag', bad_from=0)
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil']) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'none of 300 predictions could be made' in err


def test_replay_topic_map_renames_bag_topics(tmp_path, capsys):
    _bag(tmp_path / 'bag', prefix='/', joint=False,
         names={'p_in': '/rig/p1', 'p_out': '/rig/p2'})
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil']) == 1
    err = capsys.readouterr().err
    assert 'no messages on inlet_pressure, outlet_pressure (the bag has: ' in err
    assert '/rig/p1 sensor_msgs/msg/FluidPressure (300)' in err
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil',
                 '--topic-map', '/rig/p1:=inlet_pressure',
                 '--topic-map', '/rig/p2:=outlet_pressure']) == 0


@pytest.mark.parametrize(('args', 'text'), [
    (['--timeout', '-1'], 'timeout = -1.0 s'),
    (['--mode', 'rate', '--rate', '0'], 'rate = 0.0 Hz'),
    (['--mode', 'rate', '--rate', '1e-300'], 'rate = 1e-300 Hz: must be in [0.001, 10000]'),
    (['--timeout', '1e308'], 'timeout = 1e+308 s: must be in (0, 86400]'),
    (['--liquid', 'mercury'], "--liquid 'mercury'"),
    (['--topic-map', 'a:b'], "--topic-map 'a:b': use OLD:=NEW"),
    (['--out-bag', '{tmp}'], 'is or contains the input'),
    (['--out', '{tmp}/bag/metadata.yaml'], 'is or contains the input'),
])
def test_replay_bad_options_exit_1_with_one_line(tmp_path, capsys, args, text):
    _bag(tmp_path / 'bag')
    args = [a.replace('{tmp}', str(tmp_path)) for a in args]
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil', '--no-plot', *args]) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and text in err, err


def test_replay_rate_mode_predicts_on_ticks(tmp_path, capsys):
    _bag(tmp_path / 'bag', joint=False)
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil',
                 '--mode', 'rate', '--rate', '20',
                 '--out', str(tmp_path / 'p.csv')]) == 0
    rows = _rows(tmp_path / 'p.csv')
    times = np.array([float(r['time [s]']) for r in rows])
    np.testing.assert_allclose(np.diff(times), 0.05)
    assert rows[0]['level'] == 'ERROR'  # first tick: nothing received yet
    assert all(r['level'] == 'OK' for r in rows[1:])


@pytest.mark.parametrize('name', FOREIGN_BAGS)
def test_replay_of_every_foreign_bag_fails_cleanly_with_one_line(name, capsys):
    """None of them holds the motor's topics: exit 1, one line naming what is missing."""
    assert main(['replay', str(foreign_bag(name)), '--liquid', 'oil', '--no-plot']) == 1
    captured = capsys.readouterr()
    assert captured.out == '' and captured.err.count('\n') == 1
    assert 'Traceback' not in captured.err
    assert ('no messages on flow_command, inlet_pressure, outlet_pressure' in captured.err
            or 'metadata.yaml and storage disagree' in captured.err)


def test_replay_replaces_only_its_own_outputs(tmp_path, capsys):
    _bag(tmp_path / 'bag')
    csv, png, bag_out = tmp_path / 'run.csv', tmp_path / 'run_speed.png', tmp_path / 'out_bag'
    argv = ['replay', str(tmp_path / 'bag'), '--liquid', 'oil',
            '--out', str(csv), '--out-bag', str(bag_out)]
    assert main(argv) == 0
    first = csv.read_bytes(), png.read_bytes()
    assert main(argv) == 0  # its own earlier outputs are replaced
    assert csv.read_bytes() == first[0] and png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    capsys.readouterr()
    csv.write_text('my own table\n')
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and "--out '" in err and '--force' in err
    assert csv.read_text() == 'my own table\n'
    assert main([*argv, '--force']) == 0
    assert csv.read_bytes() == first[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ['bag', 'out_bag', 'run.csv',
                                                          'run_speed.png']


def test_rate_mode_over_a_long_gap_is_refused_at_the_cap(tmp_path, capsys, monkeypatch):
    from satmotor_ros.prediction import rule
    _bag(tmp_path / 'bag')
    monkeypatch.setattr(rule, 'RATE_MAX_PREDICTIONS', 100)
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil',
                 '--no-plot', '--mode', 'rate']) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'predictions, more than 100' in err, err


def test_plot_must_be_a_png(tmp_path, capsys):
    _bag(tmp_path / 'bag')
    assert main(['replay', str(tmp_path / 'bag'), '--liquid', 'oil',
                 '--plot', str(tmp_path / 'x.yaml')]) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and "x.yaml': a plot is written as PNG" in err, err
    assert not (tmp_path / 'x.yaml').exists()
