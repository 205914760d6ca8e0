# SPDX-License-Identifier: Apache-2.0
"""What appears at a target after its check is never replaced (issue 25 item 2)."""

import json

import pytest

from satmotor_ros.cli import calibrate as calibrate_command
from satmotor_ros.cli import main
from satmotor_ros.cli._common import CliError
from satmotor_ros.cli._output import MARKER, output_dir, output_file, written_by
from satmotor_ros.identify import write_csv
from satmotor_ros.identify.synthetic import generate, Injection, Plan, to_columns

MADE = "--out '.*' was made during the run and is not an earlier output of satmotor calibrate"


def _user_dir(target, marker=None):
    target.mkdir()
    (target / 'thesis.tex').write_text('years of work')
    if marker:
        (target / MARKER).write_text(json.dumps({'command': marker}))


def _left(tmp_path):
    return sorted(p.name for p in tmp_path.iterdir())


@pytest.mark.parametrize('marker', [None, 'validate'])
def test_a_directory_made_between_check_and_commit_is_kept(tmp_path, marker):
    target = tmp_path / 'out'
    with pytest.raises(CliError, match=MADE):
        with output_dir('--out', target, 'calibrate') as tmp:
            (tmp / 'report.md').write_text('ours')
            _user_dir(target, marker)  # another process, after the check
    assert (target / 'thesis.tex').read_text() == 'years of work'
    assert not (target / 'report.md').exists()
    assert _left(tmp_path) == ['out']  # no temporary, nothing renamed aside


def test_a_file_made_there_is_kept_too(tmp_path):
    target = tmp_path / 'out'
    with pytest.raises(CliError, match=MADE):
        with output_dir('--out', target, 'calibrate'):
            target.write_text('a user file')
    assert target.read_text() == 'a user file' and _left(tmp_path) == ['out']
    out = tmp_path / 'x.csv'
    with pytest.raises(CliError, match="--out '.*x.csv' was made during the run"):
        with output_file('--out', out, 'calibrate', lambda path: False) as tmp:
            tmp.write_text('ours')
            out.write_text('theirs')
    assert out.read_text() == 'theirs' and _left(tmp_path) == ['out', 'x.csv']


def test_an_earlier_output_of_ours_made_meanwhile_is_replaced(tmp_path):
    target = tmp_path / 'out'
    with output_dir('--out', target, 'calibrate') as tmp:
        (tmp / 'report.md').write_text('new')
        _user_dir(target, 'calibrate')
    assert sorted(p.name for p in target.iterdir()) == [MARKER, 'report.md']
    assert _left(tmp_path) == ['out']


def test_force_replaces_it_and_a_link_is_removed_not_followed(tmp_path):
    target, elsewhere = tmp_path / 'out', tmp_path / 'elsewhere'
    _user_dir(elsewhere, 'calibrate')
    with output_dir('--out', target, 'calibrate'):
        target.symlink_to(elsewhere)
    assert not target.is_symlink() and (target / MARKER).exists()
    assert (elsewhere / 'thesis.tex').exists()
    with output_dir('--out', target, 'calibrate', force=True):
        _user_dir(tmp_path / 'x')
    assert written_by('calibrate')(target)


def test_calibrate_refuses_a_directory_made_while_it_writes(tmp_path, monkeypatch, capsys):
    table = generate(Plan(liquid='oil', n_points=40), Injection(), seed=1)
    data = tmp_path / 'bench.csv'
    write_csv(data, to_columns(table))
    target = tmp_path / 'out'
    report = calibrate_command.write_report

    def slow_report(*args, **kwargs):
        report(*args, **kwargs)
        _user_dir(target, 'validate')  # a finished `validate --out out`, in the last second
    monkeypatch.setattr(calibrate_command, 'write_report', slow_report)
    code = main(['calibrate', str(data), '--liquid', 'oil', '--out', str(target)])
    err = capsys.readouterr().err
    assert code == 1 and err.count('\n') == 1
    assert "satmotor: error: --out '" in err and 'was made during the run' in err
    assert (target / 'thesis.tex').exists() and not (target / 'coefficients.yaml').exists()
    assert json.loads((target / MARKER).read_text()) == {'command': 'validate'}
