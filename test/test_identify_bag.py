# SPDX-License-Identifier: Apache-2.0
"""Calibration from rosbag2 recordings (MCAP and sqlite3) and one clear line for foreign bags."""

import json

import numpy as np
import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import calibrate, DataError
from satmotor_ros.identify.bag import read_bag
from satmotor_ros.identify.synthetic import generate_series, Injection, Plan, write_bag_of
from vendored_data import foreign_bag, FOREIGN_BAGS


@pytest.fixture(scope='module')
def water_wear_series():
    return generate_series(Plan(liquid='water'), Injection.realistic('clearance_wear', 1.0,
                                                                     'water'),
                           seed=8, samples=12000)


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_bag_reads_as_the_time_series_it_recorded(tmp_path, water_wear_series, storage):
    series = water_wear_series
    write_bag_of(tmp_path / 'bag', series, storage)
    table = read_bag(tmp_path / 'bag')
    assert table.time_series and len(table) == len(series)
    np.testing.assert_allclose(table.speed, series.speed)
    # the other topics are logged 1-4 us after joint_states and interpolated onto its times
    close = {'rtol': 1e-3, 'atol': 1e-6}
    np.testing.assert_allclose(table.flow, series.flow, **close)
    np.testing.assert_allclose(table.p_out, series.p_out, **close)  # made gauge again
    np.testing.assert_allclose(table.channels['p_case'], series.channels['p_case'], **close)
    np.testing.assert_allclose(table.channels['temperature'], series.channels['temperature'],
                               **close)
    # aux steps between set-points: only the step samples are interpolated across the step
    assert np.mean(np.isclose(table.channels['aux'], series.channels['aux'], **close)) > 0.99
    assert 'gauge' in table.notes[0]


@pytest.mark.slow
def test_calibrate_command_on_a_bag_names_the_wear(tmp_path, water_wear_series, capsys):
    write_bag_of(tmp_path / 'bag', water_wear_series, 'mcap')
    code = main(['calibrate', str(tmp_path / 'bag'), '--liquid', 'water', '--out',
                 str(tmp_path / 'out')])
    assert code == 0, capsys.readouterr().err
    result = json.loads((tmp_path / 'out' / 'calibration.json').read_text())
    assert result['effect'] == 'clearance_wear'
    bins = result['error_over_bins']  # over the rows the fit reads; over every sample the
    # noise that a row averages out stays in both figures
    assert bins['error_before']['rmse_lpm'] > 3 * bins['error_after']['rmse_lpm']
    assert result['error_before']['rmse_lpm'] > 1.5 * result['error_after']['rmse_lpm']


def test_bag_with_flow_command_only_is_used(tmp_path):
    series = generate_series(Plan(liquid='oil'), Injection(), seed=2, samples=6000)
    write_bag_of(tmp_path / 'bag', series, 'mcap')
    table = read_bag(tmp_path / 'bag', topic_map={'/flow_measured': 'flow_command'})
    assert 'flow from flow_command' in table.notes[0]
    assert calibrate(table, 'oil').chosen is None


@pytest.mark.parametrize('bag', FOREIGN_BAGS)
def test_foreign_bag_gives_one_clear_line(tmp_path, bag, capsys):
    with pytest.raises(DataError) as info:
        read_bag(foreign_bag(bag))
    text = str(info.value)
    assert '\n' not in text and bag in text
    assert 'lacks the calibration topic' in text or 'metadata' in text
    code = main(['calibrate', str(foreign_bag(bag)), '--liquid', 'oil', '--out',
                 str(tmp_path / 'o')])
    err = capsys.readouterr().err
    assert code == 1 and err.count('\n') == 1


def _residual_rms(path):
    import csv
    with open(path, newline='') as f:
        rows = list(csv.DictReader(f))
    r = np.array([float(row['residual [rpm]']) for row in rows if row['residual [rpm]']])
    return float(np.sqrt(np.mean(r ** 2)))


@pytest.mark.slow
def test_end_to_end_bag_calibrate_then_replay_with_the_new_yaml_shrinks_speed_residual(
        tmp_path, capsys):
    """A leaking motor's bag -> calibrate -> coefficients.yaml into the node's prediction."""
    series = generate_series(Plan(liquid='water'),
                             Injection.realistic('external_leakage', 1.0, 'water'), seed=3,
                             samples=8000, rate=50.0)
    bag = tmp_path / 'bag'
    write_bag_of(bag, series, 'mcap', flow_topic='flow_command')
    assert main(['calibrate', str(bag), '--liquid', 'water', '--out', str(tmp_path / 'cal')]) == 0
    common = ['replay', str(bag), '--liquid', 'water', '--no-plot']
    assert main([*common, '--out', str(tmp_path / 'before.csv')]) == 0
    assert main([*common, '--motor', str(tmp_path / 'cal' / 'coefficients.yaml'),
                 '--out', str(tmp_path / 'after.csv')]) == 0
    capsys.readouterr()
    before, after = _residual_rms(tmp_path / 'before.csv'), _residual_rms(tmp_path / 'after.csv')
    assert after < 0.6 * before
