# SPDX-License-Identifier: Apache-2.0
"""``satmotor monitor``: the outputs per the contract, recordings in time order, bad input."""

from __future__ import annotations

import json
from pathlib import Path

from health_data import DISPLACEMENT, recording
import numpy as np
import pytest

from satmotor_ros.cli.main import main
from satmotor_ros.identify.health import HealthSamples
from satmotor_ros.identify.table import write_csv

MOTOR = ['--liquid', 'oil', '--family', 'paszota', '--displacement',
         f'{DISPLACEMENT * 2 * np.pi * 1e6:.9g}', '--no-explain']


def _csv(path: Path, samples: HealthSamples, time_offset: float = 0.0) -> Path:
    write_csv(path, {'time': ('s', samples.time - time_offset),
                     'speed': ('rad/s', samples.speed), 'flow': ('m^3/s', samples.flow),
                     'p_in': ('Pa', samples.p_in), 'p_out': ('Pa', samples.p_out)})
    return path


def _step(hours: float = 1.5, at: float = 3000.0) -> HealthSamples:
    return recording(hours, seed=2, rate_hz=2.0, scale=lambda t: np.where(t >= at, 1.3, 1.0))


def test_monitor_writes_the_contract_outputs(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """monitor.json has the contract's keys, health.csv units in brackets, the plots exist."""
    data = _csv(tmp_path / 'run.csv', _step())
    assert main(['monitor', str(data), '--out', str(tmp_path / 'out'), *MOTOR]) == 0
    out = tmp_path / 'out'
    doc = json.loads((out / 'monitor.json').read_text())
    assert {'alarms', 'leakage_factor', 'trend_per_hour', 'hours_to_limit', 'n_samples',
            'n_skipped'} <= set(doc)
    (alarm,) = doc['alarms']
    assert alarm['kind'] == 'change' and {'time_s', 'what', 'statistic'} <= set(alarm)
    assert 3000.0 <= alarm['time_s'] <= 3300.0
    point = doc['leakage_factor'][-1]
    assert point['ci95'][0] <= point['value'] <= point['ci95'][1]
    assert point['value'] == pytest.approx(1.3, abs=0.08)
    assert doc['n_samples'] == 10800
    header = (out / 'health.csv').read_text().splitlines()[0].split(',')
    assert header[0] == 'time [s]' and all('[' in h and h.endswith(']') for h in header)
    for name in ('report.md', 'leakage_factor.png', 'detector.png'):
        assert (out / name).stat().st_size > 0
    assert 'change at' in capsys.readouterr().out


def test_times_are_from_the_first_sample_and_t0_maps_them_back(tmp_path: Path) -> None:
    """A log whose clock starts at 5000 s: time_s from 0 (DESIGN.md), t0_s says 5000."""
    data = _csv(tmp_path / 'run.csv', _step(), -5000.0)
    assert main(['monitor', str(data), '--out', str(tmp_path / 'out'), *MOTOR]) == 0
    doc = json.loads((tmp_path / 'out' / 'monitor.json').read_text())
    assert doc['t0_s'] == 5000.0 and 't0_epoch' not in doc
    (alarm,) = doc['alarms']
    assert 3000.0 <= alarm['time_s'] <= 3300.0  # the step at 8000 s on the log's clock


def test_recordings_whose_clock_restarts_are_placed_in_order(tmp_path: Path) -> None:
    """Two CSVs each from 0 s: the second after the first, the change found in it."""
    samples = _step(2.0, at=5000.0)
    first = _csv(tmp_path / 'a.csv', samples.take(samples.time < 3600.0))
    second = _csv(tmp_path / 'b.csv', samples.take(samples.time >= 3600.0), 3600.0)
    assert main(['monitor', str(first), str(second), '--out', str(tmp_path / 'o'),
                 *MOTOR]) == 0
    doc = json.loads((tmp_path / 'o' / 'monitor.json').read_text())
    a, b = doc['recordings']
    assert b['start_s'] > a['end_s'] and b['shifted_s'] > 0
    (alarm,) = doc['alarms']
    assert alarm['time_s'] > b['start_s']


def test_state_file_carries_the_history_to_the_next_run(tmp_path: Path) -> None:
    """Day 1 then day 2 through --state: the level learned on day 1 judges day 2."""
    samples = _step(2.0, at=5000.0)
    first = _csv(tmp_path / 'a.csv', samples.take(samples.time < 3600.0))
    second = _csv(tmp_path / 'b.csv', samples.take(samples.time >= 3600.0), 3600.0)
    state = tmp_path / 'state.json'
    for data, out in ((first, 'o1'), (second, 'o2')):
        assert main(['monitor', str(data), '--out', str(tmp_path / out), '--state', str(state),
                     *MOTOR]) == 0
    doc = json.loads((tmp_path / 'o2' / 'monitor.json').read_text())
    assert doc['n_samples'] == len(samples)
    assert [a['kind'] for a in doc['alarms']] == ['change']
    assert doc['detector']['learning'] is False


def test_an_epoch_recording_sent_again_to_a_state_is_not_counted_twice(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A daily job that sends day 2 twice: its samples are counted once, the clock not moved."""
    samples = _step(2.0, at=5000.0)
    epoch = 1.6e9
    first = _csv(tmp_path / 'a.csv', samples.take(samples.time < 3600.0), -epoch)
    second = _csv(tmp_path / 'b.csv', samples.take(samples.time >= 3600.0), -epoch)
    state = tmp_path / 'state.json'
    for data, out in ((first, 'o1'), (second, 'o2'), (second, 'o3')):
        assert main(['monitor', str(data), '--out', str(tmp_path / out), '--state', str(state),
                     *MOTOR]) == 0
    once, twice = (json.loads((tmp_path / o / 'monitor.json').read_text())
                   for o in ('o2', 'o3'))
    assert twice['n_samples'] == once['n_samples'] == len(samples)
    assert twice['operating_hours'] == pytest.approx(once['operating_hours'])
    assert twice['recordings'] == []  # nothing new: not placed after the history
    assert 'already counted' in capsys.readouterr().out


def test_a_state_in_a_missing_directory_is_refused_before_anything_is_written(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--state nodir/st.json: one line naming --state, no --out written."""
    data = _csv(tmp_path / 'run.csv', recording(0.05, seed=1))
    state = tmp_path / 'nodir' / 'state.json'
    assert main(['monitor', str(data), '--out', str(tmp_path / 'out'), '--state', str(state),
                 *MOTOR]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and '--state' in err[0]
    assert not (tmp_path / 'out').exists()


@pytest.mark.parametrize(('flag', 'value'), [('--false-alarm-hours', '-1'),
                                             ('--limit-volumetric-efficiency', '1.5'),
                                             ('--change-fraction', 'nan')])
def test_a_meaningless_setting_is_one_line_naming_the_flag(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], flag: str, value: str) -> None:
    """Exit 1, one line on stderr naming the flag and the value, nothing written."""
    data = _csv(tmp_path / 'run.csv', recording(0.05, seed=1))
    assert main(['monitor', str(data), '--out', str(tmp_path / 'out'), flag, value,
                 *MOTOR]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and flag in err[0] and value in err[0]
    assert not (tmp_path / 'out').exists()


def test_data_without_time_is_refused_naming_the_column(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A table of steady points (no time column) is no recording: one line names time."""
    s = recording(0.05, seed=1)
    path = tmp_path / 'points.csv'
    write_csv(path, {'speed': ('rad/s', s.speed), 'flow': ('m^3/s', s.flow),
                     'p_in': ('Pa', s.p_in), 'p_out': ('Pa', s.p_out)})
    assert main(['monitor', str(path), '--out', str(tmp_path / 'out'), *MOTOR]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'time' in err[0]


def test_a_state_is_not_resumed_with_other_settings(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--state made with a limit of 2: a run asking for 1.3 is refused naming the flag."""
    data = _csv(tmp_path / 'run.csv', recording(0.3, seed=1))
    state = tmp_path / 'state.json'
    assert main(['monitor', str(data), '--out', str(tmp_path / 'o1'), '--state', str(state),
                 *MOTOR]) == 0
    capsys.readouterr()
    assert main(['monitor', str(data), '--out', str(tmp_path / 'o2'), '--state', str(state),
                 '--limit-leakage-factor', '1.3', *MOTOR]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and '--limit-leakage-factor 1.3' in err[0]


def test_no_usable_sample_is_an_error_not_nan_figures(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Every sample stalled: exit 1 with one line saying why, no output."""
    s = recording(0.1, seed=1)
    stalled = HealthSamples(s.time, 0.0 * s.speed, s.flow, s.p_in, s.p_out)
    data = _csv(tmp_path / 'stalled.csv', stalled)
    assert main(['monitor', str(data), '--out', str(tmp_path / 'out'), *MOTOR]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'stalled' in err[0]
    assert not (tmp_path / 'out').exists()


def test_a_time_column_that_does_not_advance_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A 'time' that mostly runs backwards or stands still is named, not skipped silently."""
    s = recording(0.3, seed=1)
    wrong = HealthSamples(np.round(np.sin(s.time / 50.0), 1), s.speed, s.flow, s.p_in,
                          s.p_out)
    data = _csv(tmp_path / 'wrong.csv', wrong)
    assert main(['monitor', str(data), '--out', str(tmp_path / 'out'), *MOTOR]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'time' in err[0]


def test_epoch_recordings_given_out_of_order_are_taken_in_time_order(tmp_path: Path) -> None:
    """Two epoch-clocked CSVs given later-first: taken by their clocks, t0_epoch the first's."""
    samples = _step(2.0, at=5000.0)
    epoch = 1.7e9
    early = _csv(tmp_path / 'a.csv', samples.take(samples.time < 3600.0), -epoch)
    late = _csv(tmp_path / 'b.csv', samples.take(samples.time >= 3600.0), -epoch)
    assert main(['monitor', str(late), str(early), '--out', str(tmp_path / 'o'),
                 *MOTOR]) == 0
    doc = json.loads((tmp_path / 'o' / 'monitor.json').read_text())
    assert doc['t0_epoch'] == pytest.approx(epoch)
    assert [Path(r['data']).name for r in doc['recordings']] == ['a.csv', 'b.csv']
    assert doc['recordings'][1]['shifted_s'] == 0.0
    (alarm,) = doc['alarms']
    assert 5000.0 <= alarm['time_s'] <= 5300.0
