# SPDX-License-Identifier: Apache-2.0
"""Calibration with bad cells: named, handled, the other channels' verdict kept (issue 14)."""

import json

import numpy as np
import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import DataError, read_csv
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from test_calibrate_cli import _csv


@pytest.fixture(scope='module')
def leak_csv(tmp_path_factory):
    """Return the lines of a bench CSV with a clear external leakage through p_case."""
    table = generate(Plan(liquid='water'), Injection.realistic('external_leakage', 1, 'water'),
                     seed=7)
    return _csv(tmp_path_factory.mktemp('leak') / 'bench.csv', table).read_text().splitlines()


def _with_cell(tmp_path, lines, column, row, text):
    """Write the CSV with data row `row` of `column` replaced by `text`."""
    cells = [line.split(',') for line in lines]
    index = [c.split(' [')[0] for c in cells[0]].index(column)
    cells[row][index] = text
    path = tmp_path / 'bad.csv'
    path.write_text('\n'.join(','.join(c) for c in cells) + '\n')
    return path


def _calibrate(capsys, data, *options):
    code = main(['calibrate', str(data), '--liquid', 'water', '--out',
                 str(data.parent / 'out'), *options])
    out, err = capsys.readouterr()
    return code, out, err, (data.parent / 'out' / 'report.md').read_text()


@pytest.mark.parametrize(('column', 'text', 'note'), [
    ('p_case', '1e300', "column 'p_case': dropped 1 rows where it is missing or absurd (up to "
                        '1e+303 in SI) (data rows 5)'),
    ('p_case', 'nan', "column 'p_case': dropped 1 rows where it is missing (data rows 5)"),
    ('speed', '1e308', "column 'speed': dropped the rows of 1 absurd values (up to 1.05e+307 "
                       'in SI) at data rows 5'),
    ('temperature', '-1e300', "column 'temperature': dropped 1 rows where it is missing or "
                              'absurd'),
])
def test_one_bad_cell_is_named_and_the_leak_still_found(tmp_path, capsys, leak_csv, column,
                                                        text, note):
    code, out, err, report = _calibrate(capsys, _with_cell(tmp_path, leak_csv, column, 5, text))
    assert code == 0
    assert out.startswith('effect: external_leakage (p_case')
    assert 'over 99 points' in out
    assert f'warning: {tmp_path / "bad.csv"}: bad cells: {note}' in err
    assert f'- bad cells: {note}' in report


def test_a_pressure_beyond_any_hydraulics_is_dropped_and_a_high_one_is_kept(
        tmp_path, leak_csv):
    absurd = read_csv(_with_cell(tmp_path, leak_csv, 'p_in', 5, '2000'))  # MPa: 2 GPa
    assert len(absurd) == 99
    assert [n for n in absurd.notes if "'p_in'" in n] == [
        "bad cells: column 'p_in': dropped the rows of 1 absurd values (up to 2e+09 in SI) at "
        'data rows 5']
    high = read_csv(_with_cell(tmp_path, leak_csv, 'p_in', 5, '600'))  # an intensifier's
    assert len(high) == 100 and high.p_in.max() == pytest.approx(600e6)


def test_a_mostly_missing_channel_drops_no_row(tmp_path, leak_csv):
    lines = [line + (',aux2 [V]' if i == 0 else f',{i if i % 2 else ""}')
             for i, line in enumerate(leak_csv)]
    path = tmp_path / 'sparse.csv'
    path.write_text('\n'.join(lines) + '\n')
    table = read_csv(path)
    assert len(table) == 100 and np.isnan(table.channels['aux2']).sum() == 50
    [note] = [n for n in table.notes if 'aux2' in n]  # said, since its effects go untested
    assert "column 'aux2': missing in 50 of 100 rows (data rows 2, 4, 6, 8, 10 and 45 more)" \
        in note and 'its effects are not tested' in note


def test_a_leak_channel_missing_in_many_rows_is_said_on_stderr(tmp_path, capsys, leak_csv):
    """20 of 100 p_case cells empty: the verdict may change, but not in silence."""
    cells = [line.split(',') for line in leak_csv]
    index = [c.split(' [')[0] for c in cells[0]].index('p_case')
    for row in range(1, 21):
        cells[row][index] = 'nan'
    path = tmp_path / 'bad.csv'
    path.write_text('\n'.join(','.join(c) for c in cells) + '\n')
    code, _, err, report = _calibrate(capsys, path)
    assert code == 0
    assert "column 'p_case': missing in 20 of 100 rows" in err
    assert 'its effects are not tested' in report


def test_absurd_values_in_every_row_of_a_required_column_are_refused(tmp_path):
    path = tmp_path / 'x.csv'
    path.write_text('speed [rpm],flow [l/min],p_in [MPa],p_out [MPa]\n'
                    + ''.join(f'{600 + i},1e12,10,1\n' for i in range(20)))
    with pytest.raises(DataError, match='no row has finite values'):
        read_csv(path)


def test_report_states_the_folds_asked_for(tmp_path, capsys, leak_csv):
    path = tmp_path / 'bench.csv'
    path.write_text('\n'.join(leak_csv) + '\n')
    *_, report = _calibrate(capsys, path, '--folds', '3')
    assert '(3-fold cross-validation)' in report and '5-fold' not in report


def test_speed_in_rpm_labelled_rad_per_s_is_warned_about(tmp_path, capsys, leak_csv):
    path = tmp_path / 'bench.csv'
    path.write_text('\n'.join([leak_csv[0].replace('speed [rpm]', 'speed [rad/s]'),
                               *leak_csv[1:]]) + '\n')
    code, out, err, report = _calibrate(capsys, path)
    assert code == 0
    warning = ('implausible data: the volumetric losses Q - q_t n are larger than the flow '
               'itself at 100 of 100 points')
    assert warning in err and 'a speed in rpm labelled [rad/s]?' in err
    assert f'- {warning}' in report
    summary = json.loads((path.parent / 'out' / 'calibration.json').read_text())
    assert summary['warnings'][0].startswith(warning)  # the file says so too, not only stderr
    assert out.startswith('WARNING implausible data')


def test_plausible_data_give_no_warning(tmp_path, capsys, leak_csv):
    path = tmp_path / 'bench.csv'
    path.write_text('\n'.join(leak_csv) + '\n')
    _, _, err, report = _calibrate(capsys, path)
    assert 'warning' not in err and 'implausible' not in report
    assert 'warnings' not in json.loads((path.parent / 'out' / 'calibration.json').read_text())
