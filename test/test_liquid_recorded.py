# SPDX-License-Identifier: Apache-2.0
"""No silent guess about the liquid: the bag records it, the commands take it or refuse."""

import numpy as np
import pytest

from satmotor_ros.bags import encode_many, OutTopic, write_bag
from satmotor_ros.bags.custom import custom_data, LIQUID_KEY, MOTOR_KEY
from satmotor_ros.cli import main
from satmotor_ros.identify.synthetic import (generate_series, generate_transient, Injection, Plan,
                                             to_columns, write_bag_of)
from satmotor_ros.identify.table import write_csv
from satmotor_ros.interface import FLOAT64, FLUID_PRESSURE, JOINT_STATE
from satmotor_ros.model.units import LPM, MPA

WATER = {LIQUID_KEY: 'water', MOTOR_KEY: 'SM-0,75/25'}


def _bag(path, custom=None, storage='mcap'):
    n = 200
    rng = np.random.default_rng(3)
    t = 2_000_000_000 + np.arange(n, dtype=np.int64) * 10_000_000
    topics = [
        OutTopic('/flow_command', FLOAT64, t + 3_000_000,
                 encode_many(FLOAT64, {'data': rng.uniform(5, 40, n) * LPM})),
        OutTopic('/inlet_pressure', FLUID_PRESSURE, t + 1_000_000,
                 encode_many(FLUID_PRESSURE, {'fluid_pressure': rng.uniform(5, 20, n) * MPA}, t)),
        OutTopic('/outlet_pressure', FLUID_PRESSURE, t + 1_000_000,
                 encode_many(FLUID_PRESSURE, {'fluid_pressure': np.full(n, 0.5 * MPA)}, t)),
        OutTopic('/joint_states', JOINT_STATE, t + 2_000_000,
                 encode_many(JOINT_STATE, {'velocity': rng.uniform(50, 150, n)}, t,
                             joint='motor_shaft'))]
    write_bag(path, topics, storage, custom_data=custom)
    return path


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_a_bag_records_its_liquid_and_motor(tmp_path, storage):
    bag = _bag(tmp_path / 'bag', WATER, storage)
    assert custom_data(bag) == WATER
    assert custom_data(_bag(tmp_path / 'plain', storage=storage)) == {}
    if storage == 'mcap':  # the storage file alone carries it too
        assert custom_data(next(bag.glob('*.mcap'))) == WATER


def test_replay_takes_the_recorded_liquid_as_if_told(tmp_path, capsys):
    bag = _bag(tmp_path / 'bag', WATER)
    assert main(['replay', str(bag), '--no-plot', '--out', str(tmp_path / 'a.csv')]) == 0
    out = capsys.readouterr()
    assert 'liquid water (recorded in the bag, motor SM-0,75/25)' in out.out
    assert 'WARNING' not in out.out + out.err
    assert main(['replay', str(bag), '--no-plot', '--liquid', 'water',
                 '--out', str(tmp_path / 'b.csv')]) == 0
    assert (tmp_path / 'a.csv').read_bytes() == (tmp_path / 'b.csv').read_bytes()
    assert main(['replay', str(bag), '--no-plot', '--liquid', 'oil',
                 '--out', str(tmp_path / 'c.csv')]) == 0
    assert (tmp_path / 'a.csv').read_bytes() != (tmp_path / 'c.csv').read_bytes()


def test_a_contradicting_liquid_is_followed_but_said_loudly(tmp_path, capsys):
    bag = _bag(tmp_path / 'bag', WATER)
    assert main(['replay', str(bag), '--no-plot', '--liquid', 'oil']) == 0
    out = capsys.readouterr()
    assert out.err.count('\n') == 1 and 'WARNING: --liquid oil differs from the liquid ' \
        'recorded in' in out.err and '(water)' in out.err
    assert 'liquid oil (--liquid; the bag records water); WARNING' in out.out


def test_a_recorded_motor_other_than_the_packaged_one_is_said_loudly(tmp_path, capsys):
    bag = _bag(tmp_path / 'bag', {LIQUID_KEY: 'water', MOTOR_KEY: 'rig 7 motor'})
    assert main(['replay', str(bag), '--no-plot', '--out', str(tmp_path / 'a.csv')]) == 0
    out = capsys.readouterr()
    assert out.err.count('\n') == 1
    assert "records the motor 'rig 7 motor'; replay uses the packaged SM-0,75/25" in out.err
    assert 'WARNING' in out.out
    assert main(['replay', str(_bag(tmp_path / 'same', WATER)), '--no-plot']) == 0
    assert 'WARNING' not in ''.join(capsys.readouterr())
    assert main(['replay', str(bag), '--no-plot', '--displacement', '30cm^3/rev']) == 0
    assert 'records the motor' not in capsys.readouterr().err  # a motor was given


def test_a_bag_without_liquid_is_refused_in_one_line_naming_the_option(tmp_path, capsys):
    bag = _bag(tmp_path / 'bag')
    assert main(['replay', str(bag), '--no-plot', '--out', str(tmp_path / 'x.csv')]) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'do not record their liquid' in err and '--liquid' in err
    assert not (tmp_path / 'x.csv').exists()


@pytest.mark.parametrize('command', ['calibrate', 'validate'])
def test_a_csv_without_liquid_is_refused_in_one_line(tmp_path, capsys, command):
    table = generate_series(Plan(liquid='oil'), Injection(), seed=1, samples=2000)
    write_csv(tmp_path / 'bench.csv', to_columns(table))
    assert main([command, str(tmp_path / 'bench.csv'), '--out', str(tmp_path / 'o')]) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'do not record their liquid: name it with --liquid' in err
    assert not (tmp_path / 'o').exists()


def test_replay_out_bag_records_the_liquid_it_used(tmp_path, capsys):
    bag = _bag(tmp_path / 'bag', WATER)
    assert main(['replay', str(bag), '--no-plot', '--out-bag', str(tmp_path / 'ob')]) == 0
    assert custom_data(tmp_path / 'ob') == WATER
    assert main(['replay', str(tmp_path / 'ob'), '--no-plot']) == 0  # and reads it back
    assert 'liquid water (recorded' in capsys.readouterr().out


@pytest.mark.slow
def test_calibrate_takes_the_recorded_liquid_and_says_a_contradiction_in_the_report(
        tmp_path, capsys):
    table = generate_transient(Plan(liquid='water'), Injection(), seed=4, duration_s=40.0)
    write_bag_of(tmp_path / 'bag', table, custom_data=WATER)
    assert main(['calibrate', str(tmp_path / 'bag'), '--out', str(tmp_path / 'a')]) == 0
    assert 'liquid water (recorded in the bag' in capsys.readouterr().out
    assert '"liquid": "water"' in (tmp_path / 'a' / 'calibration.json').read_text()
    assert main(['calibrate', str(tmp_path / 'bag'), '--liquid', 'oil',
                 '--out', str(tmp_path / 'b')]) == 0
    out = capsys.readouterr()
    assert 'WARNING: --liquid oil differs' in out.err and 'WARNING: --liquid oil' in out.out
    report = (tmp_path / 'b' / 'report.md').read_text()
    assert '- WARNING: --liquid oil differs from the liquid recorded in' in report
