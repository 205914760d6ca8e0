# SPDX-License-Identifier: Apache-2.0
"""replay's outputs: refused before any is written when they clash, committed all or none."""

from pathlib import Path

import pytest
from satmotor_ros.cli import _output, replay
from satmotor_ros.cli.main import main
from test_replay import _bag


@pytest.fixture
def bag(tmp_path):
    _bag(tmp_path / 'bag')
    return tmp_path / 'bag'


def _names(path):
    return sorted(p.name for p in path.iterdir())


@pytest.mark.parametrize('args, text', [
    (['--out', 'p7.png', '--plot', 'p7.png'], "--out 'p7.png' and --plot 'p7.png' are one path"),
    (['--out-bag', 'ob.csv', '--out', 'ob.csv'], "--out-bag 'ob.csv' and --out 'ob.csv' are"),
    (['--out-bag', 'ob', '--out', 'ob/x.csv'], 'one path or one holds the other'),
    (['--out', 'x.csv', '--out-bag', 'x_speed.png'], "and --plot 'x_speed.png' are one path"),
    (['--out', 'ro.csv', '--plot', '/proc/x.png'], "--plot '/proc/x.png': cannot write there"),
])
def test_clashing_or_unwritable_outputs_are_refused_before_any_is_written(
        bag, tmp_path, capsys, monkeypatch, args, text):
    monkeypatch.chdir(tmp_path)
    assert main(['replay', str(bag), '--liquid', 'oil', *args]) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and text in err, err
    assert _names(tmp_path) == ['bag']


def test_a_failing_plot_leaves_no_new_csv_nor_bag(bag, tmp_path, capsys, monkeypatch):
    def broken(path, *args):
        raise OSError(28, 'No space left on device', str(path))
    monkeypatch.setattr(replay, 'plot_speed', broken)
    assert main(['replay', str(bag), '--liquid', 'oil',
                 '--out', str(tmp_path / 'r.csv'), '--out-bag',
                 str(tmp_path / 'ob')]) == 1
    assert 'No space left on device' in capsys.readouterr().err
    assert _names(tmp_path) == ['bag']


def test_the_csv_written_in_pieces_equals_the_csv_written_at_once(
        bag, tmp_path, capsys, monkeypatch):
    assert main(['replay', str(bag), '--liquid', 'oil',
                 '--out', str(tmp_path / 'whole.csv'), '--no-plot']) == 0
    monkeypatch.setattr(replay, 'CSV_CHUNK_ROWS', 7)
    assert main(['replay', str(bag), '--liquid', 'oil',
                 '--out', str(tmp_path / 'pieces.csv'), '--no-plot']) == 0
    whole = (tmp_path / 'whole.csv').read_bytes()
    assert whole.count(b'\n') == 301 and (tmp_path / 'pieces.csv').read_bytes() == whole


def test_too_many_points_per_curve_are_refused_in_one_line(tmp_path, capsys):
    assert main(['characteristics', '--points', '1000000000', '--out', str(tmp_path / 'c')]) == 1
    assert capsys.readouterr().err == (
        'satmotor: error: --points 1000000000: more than 100000 points per curve (the cap '
        'SATMOTOR_CURVE_MAX_POINTS)\n')
    assert not Path(tmp_path / 'c').exists()


@pytest.mark.parametrize('error, code, line', [
    (MemoryError, 1, 'satmotor: error: out of memory; ask for less'),
    (KeyboardInterrupt, 130, 'satmotor: interrupted; outputs not yet written are left as they '
                             'were'),
])
def test_memory_and_interrupts_anywhere_are_one_line(capsys, monkeypatch, error, code, line):
    def raising(**kwargs):
        raise error
    monkeypatch.setattr(_output, 'COMMITTED', [])  # what earlier tests committed
    monkeypatch.setattr(replay, 'command', raising)
    assert main(['replay', 'any']) == code
    err = capsys.readouterr().err
    assert err.startswith(line) and err.count('\n') == 1, err


def test_the_out_bag_has_ordinary_names_that_its_metadata_names(bag, tmp_path, capsys):
    """Issue 21: the bag's files are not left under the hidden temporary name."""
    out = tmp_path / 'predicted'
    assert main(['replay', str(bag), '--liquid', 'oil', '--out-bag', str(out), '--no-plot']) == 0
    visible = sorted(p.name for p in out.iterdir() if not p.name.startswith('.'))
    assert visible == ['metadata.yaml', 'predicted.mcap'], sorted(out.iterdir())
    assert 'partial' not in ''.join(p.name for p in out.iterdir())
    metadata = (out / 'metadata.yaml').read_text(encoding='utf-8')
    assert '- predicted.mcap' in metadata and 'partial' not in metadata
    from satmotor_ros.bags import list_topics
    assert '/motor1/predicted_joint_state' in list_topics(str(out))  # readable by its name
    assert 'partial' not in ''.join(p.name for p in tmp_path.iterdir())
