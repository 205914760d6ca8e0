# SPDX-License-Identifier: Apache-2.0
"""Text DATA and column mappings that once crashed, hung or misled (issue 25 items 3, 6-10)."""

import os
from pathlib import Path
import subprocess
import sys
import time

import numpy as np
import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import read_csv, write_csv
from satmotor_ros.identify import textfile
from satmotor_ros.identify.columns import mapping_from_dict, read_log
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.steady import extract_steady
from satmotor_ros.identify.synthetic import generate, generate_series, Injection, Plan, to_columns
from satmotor_ros.identify.table import table_from_columns
from satmotor_ros.model.units import PSI

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope='module')
def bench(tmp_path_factory):
    path = tmp_path_factory.mktemp('bench') / 'bench.csv'
    write_csv(path, to_columns(generate(Plan(n_points=40), Injection(), seed=2)))
    return path


def _run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _one_line(code, err, *needles):
    assert code == 1
    assert err.count('\n') == 1 and err.startswith('satmotor: error: '), err
    for needle in needles:
        assert needle in err, err


def _cli(*argv, env=None, timeout=60):
    """Run satmotor in a child process (a hang ends the test, not the suite)."""
    environ = {**os.environ, 'PYTHONPATH': str(ROOT), **(env or {})}
    done = subprocess.run([sys.executable, '-m', 'satmotor_ros.cli', *map(str, argv)],
                          capture_output=True, text=True, env=environ, timeout=timeout)
    return done.returncode, done.stderr


# -- item 3: no cap on text DATA ------------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize('command', ['calibrate', 'validate'])
def test_a_device_or_a_fifo_as_data_is_one_line_at_once(tmp_path, command):
    fifo = tmp_path / 'fifo'
    os.mkfifo(fifo)
    for data in ('/dev/zero', fifo):
        started = time.monotonic()
        code, err = _cli(command, data, '--liquid', 'oil', '--out', tmp_path / 'out')
        assert code == 1 and err.count('\n') == 1, err
        assert 'not a regular file (a FIFO, device or directory)' in err
        assert time.monotonic() - started < 30
    assert not (tmp_path / 'out').exists()


def test_the_byte_cap_is_read_no_further(tmp_path, monkeypatch, capsys, bench):
    monkeypatch.setattr(textfile, 'TEXT_MAX_BYTES', 1000)
    code, _, err = _run(capsys, 'calibrate', bench, '--liquid', 'oil', '--out', tmp_path / 'o')
    _one_line(code, err, 'larger than 1000 bytes (the cap SATMOTOR_TEXT_MAX_BYTES)')


@pytest.mark.slow
def test_the_row_cap_is_overridden_through_the_environment(tmp_path, bench):
    code, err = _cli('validate', bench, '--liquid', 'oil', '--out', tmp_path / 'o',
                     env={'SATMOTOR_TEXT_MAX_ROWS': '39'})
    assert code == 1 and err.count('\n') == 1
    assert 'more than 39 data rows (the cap SATMOTOR_TEXT_MAX_ROWS' in err
    code, err = _cli('validate', bench, '--liquid', 'oil', '--out', tmp_path / 'o',
                     env={'SATMOTOR_TEXT_MAX_ROWS': '40'})
    assert code == 0, err


# -- item 6: symbolic link loops --------------------------------------------------------------

@pytest.mark.parametrize('argv, option', [
    (['calibrate', '{loop}', '--liquid', 'oil', '--out', '{out}'], "DATA '"),
    (['validate', '{loop}', '--liquid', 'oil', '--out', '{out}'], "DATA '"),
    (['calibrate', '{bench}', '--liquid', 'oil', '--out', '{loop}'], "--out '"),
    (['validate', '{bench}', '--liquid', 'oil', '--out', '{loop}'], "--out '"),
    (['calibrate', '{bench}', '--liquid', 'oil', '--columns', '{loop}', '--out', '{out}'],
     "--columns '"),
    (['characteristics', '--out', '{loop}'], "--out '"),
    (['demo', '--out', '{loop}'], "--out '"),
    (['replay', '{loop}', '--liquid', 'oil'], "BAG '"),
    (['replay', '{bench}', '--liquid', 'oil', '--out', '{loop}'], "--out '"),
])
def test_a_symlink_loop_is_one_line_naming_the_option(tmp_path, capsys, bench, argv, option):
    (tmp_path / 'a').symlink_to(tmp_path / 'b')
    (tmp_path / 'b').symlink_to(tmp_path / 'a')
    names = {'loop': tmp_path / 'a', 'out': tmp_path / 'out', 'bench': bench}
    code, _, err = _run(capsys, *(arg.format(**names) for arg in argv))
    _one_line(code, err, option)
    assert 'symbolic links' in err
    assert not (tmp_path / 'out').exists()


# -- items 7-9: mappings -----------------------------------------------------------------------

NUMBERED = {'speed': {'column': 1, 'unit': 'rpm'}, 'flow': {'column': 2, 'unit': 'l/min'},
            'p_in': {'column': 3, 'unit': 'MPa'}, 'p_out': {'column': 4, 'unit': 'MPa'}}


def _log(tmp_path, text):
    path = tmp_path / 'log.txt'
    path.write_text(text)
    return path


def test_a_headerless_log_with_a_column_past_the_last(tmp_path):
    log = _log(tmp_path, '600 20 10 1\n700 22 11 1\n')
    doc = {'file': {'header': 'none'}, 'columns': NUMBERED, 'channels': {'aux': 9}}
    with pytest.raises(DataError, match=r'channels.aux: column 9: the log has 4 columns$'):
        read_log(log, mapping_from_dict(doc))
    with pytest.raises(DataError, match=r'columns.p_out: column 9: the log has 4 columns$'):
        read_log(log, mapping_from_dict({'file': {'header': 'none'}, 'columns': {
            **NUMBERED, 'p_out': {'column': 9, 'unit': 'MPa'}}}))
    doc['channels'] = {'aux': {'column': 9, 'optional': True}}
    table = read_log(log, mapping_from_dict(doc))
    assert 'aux' not in table.channels and len(table) == 2
    assert any(note.startswith('sanity check: channels.aux (optional) is absent')
               and 'column 9: the log has 4 columns' in note for note in table.notes)


def test_channels_are_capped_beside_the_columns_at_once(tmp_path):
    doc = {'columns': NUMBERED, 'channels': {f'c{i}': 1 for i in range(30_000)}}
    started = time.monotonic()
    with pytest.raises(DataError, match=r'channels: 30000 channels, more than the 256 columns '
                                        r'a log may have \(the cap SATMOTOR_CSV_MAX_COLUMNS'):
        mapping_from_dict(doc)
    assert time.monotonic() - started < 2.0


PSIG = '#RPM,Flow(l/min),Up(psig),Low(psig)\n600 20 1500 100\n700 22 1600 100\n'
COLUMNS = {'speed': {'column': 'RPM', 'unit': 'rpm'}, 'flow': 'Flow', 'p_in': 'Up',
           'p_out': 'Low'}


def test_absolute_against_a_gauge_header_is_refused_naming_both(tmp_path):
    log = _log(tmp_path, PSIG)
    doc = {'columns': {**COLUMNS, 'p_in': {'column': 'Up', 'reference': 'absolute'}}}
    with pytest.raises(DataError, match=r'columns.p_in.reference: absolute contradicts the unit '
                                        r"'psig' of the log's column 'Up'$"):
        read_log(log, mapping_from_dict(doc))
    doc['columns']['p_in']['unit'] = 'psig'
    with pytest.raises(DataError, match='columns.p_in.reference: absolute contradicts the '
                                        "unit 'psig'"):
        mapping_from_dict(doc)
    gauge = read_log(log, mapping_from_dict({'columns': COLUMNS}))
    assert gauge.p_in[0] == pytest.approx(1500 * PSI)


# -- item 10: quietly wrong setups -------------------------------------------------------------

def test_one_column_as_two_quantities_is_refused(tmp_path):
    log = _log(tmp_path, PSIG)
    doc = {'columns': {**COLUMNS, 'flow': {'column': 'RPM', 'unit': 'l/min'}}}
    with pytest.raises(DataError, match=r"columns.flow: column 'RPM' is already columns.speed: "
                                        'one column is one quantity'):
        read_log(log, mapping_from_dict(doc))


@pytest.mark.parametrize('unit', ['bar', 'MPa', 'psia'])
def test_a_unit_the_header_contradicts_is_refused(tmp_path, unit):
    log = _log(tmp_path, PSIG)
    doc = {'columns': {**COLUMNS, 'p_in': {'column': 'Up', 'unit': unit}}}
    with pytest.raises(DataError, match=rf"columns.p_in.unit: '{unit}' contradicts the unit of "
                                        r"the log's column 'Up' \(psig\)"):
        read_log(log, mapping_from_dict(doc))


@pytest.mark.parametrize('unit', ['psi', 'PSIG'])
def test_a_unit_the_header_agrees_with_is_taken(tmp_path, unit):
    table = read_log(_log(tmp_path, PSIG), mapping_from_dict(
        {'columns': {**COLUMNS, 'p_in': {'column': 'Up', 'unit': unit}}}))
    assert table.p_in[1] == pytest.approx(1600 * PSI)


def test_a_comment_rule_that_takes_data_rows_says_how_many(tmp_path):
    speeds = (600, 700, 1100)  # file.comment: 1 takes every row of 1100 rpm
    log = _log(tmp_path, ''.join(f'{speeds[i % 3]} 20 10 1\n' for i in range(60)))
    doc = {'file': {'header': 'none', 'comment': 1}, 'columns': NUMBERED}
    table = read_log(log, mapping_from_dict(doc))
    assert len(table) == 40
    note, = (n for n in table.notes if n.startswith('sanity check: the comment rule'))
    assert "the comment rule '1' left out 20 lines among the 40 data rows read (lines 3, 6, " \
        in note
    doc['file']['comment'] = '#'
    assert not any('comment rule' in n for n in read_log(log, mapping_from_dict(doc)).notes)


def test_time_that_restarts_is_named_and_kept_apart(tmp_path):
    plan = Plan(n_points=12)
    first = generate_series(plan, Injection(), seed=1, samples=3000)
    second = generate_series(plan, Injection(), seed=2, samples=3000)
    apart = [len(extract_steady(part)) for part in (first, second)]
    columns = {name: (unit, np.concatenate([a, to_columns(second)[name][1]]))
               for name, (unit, a) in to_columns(first).items()}
    path = tmp_path / 'two.csv'
    write_csv(path, columns)
    table = read_csv(path)
    note, = (n for n in table.notes if n.startswith('sanity check: the time restarts'))
    assert 'restarts 1 time(s) (data row 3001:' in note and 'two logs in one file?' in note
    assert np.all(np.diff(table.channels['time']) > 0.0)  # file order kept, pieces apart
    assert len(extract_steady(table)) == sum(apart)


@pytest.mark.slow
def test_a_displacement_that_makes_most_losses_negative_is_named(tmp_path, capsys, bench):
    code, _, err = _run(capsys, 'calibrate', bench, '--liquid', 'oil', '--displacement',
                        '45cm^3/rev', '--out', tmp_path / 'cal')
    assert code == 0
    assert 'sanity check: the displacement 45 cm^3/rev makes the volumetric loss' in err
    assert 'negative in 40 of 40 rows' in err
    assert 'sanity check: the displacement 45' in (tmp_path / 'cal' / 'report.md').read_text()
    code, _, err = _run(capsys, 'calibrate', bench, '--liquid', 'oil', '--out',
                        tmp_path / 'fine')
    assert code == 0 and 'sanity check' not in err


def test_a_late_timestamp_is_jitter_not_a_restart():
    time = np.arange(0.0, 10.0, 0.1)
    time[50] = time[49] - 0.05  # one sample half a step late
    ones = np.ones_like(time)
    table = table_from_columns({'time': ('s', time), 'speed': ('rpm', 600 * ones),
                                'flow': ('l/min', 20 * ones), 'p_in': ('MPa', 10 * ones),
                                'p_out': ('MPa', ones)}, 'late.csv')
    assert not any(note.startswith('sanity check') for note in table.notes)
    assert np.array_equal(table.channels['time'], time)
