# SPDX-License-Identifier: Apache-2.0
"""Outputs replace only their own earlier results and appear whole or not at all (issue 14)."""

import json

import pytest

from satmotor_ros.cli._common import CliError
from satmotor_ros.cli._output import MARKER, output_dir, output_file, png_by, png_metadata


def _write(directory, text):
    (directory / 'report.md').write_text(text)


def test_directory_appears_whole_with_its_marker_and_parents(tmp_path):
    target = tmp_path / 'a' / 'b'
    with output_dir('--out', target, 'calibrate') as tmp:
        _write(tmp, 'first')
        assert not target.exists()  # nothing at the target until the block ends
    assert (target / 'report.md').read_text() == 'first'
    assert json.loads((target / MARKER).read_text()) == {'command': 'calibrate',
                                                         'files': ['report.md']}
    assert [p.name for p in target.parent.iterdir()] == ['b']  # no temporary left


def test_earlier_output_of_the_same_command_is_replaced_whole(tmp_path):
    target = tmp_path / 'cal'
    with output_dir('--out', target, 'calibrate') as tmp:
        _write(tmp, 'first')
        (tmp / 'old.png').write_bytes(b'x')
    with output_dir('--out', target, 'calibrate') as tmp:
        _write(tmp, 'second')
    assert sorted(p.name for p in target.iterdir()) == [MARKER, 'report.md']
    assert (target / 'report.md').read_text() == 'second'


def test_failure_or_interrupt_leaves_the_previous_result_intact(tmp_path):
    target = tmp_path / 'cal'
    with output_dir('--out', target, 'calibrate') as tmp:
        _write(tmp, 'first')
    for error in (KeyboardInterrupt, OSError):
        with pytest.raises(error), output_dir('--out', target, 'calibrate') as tmp:
            _write(tmp, 'half')
            raise error()
    assert (target / 'report.md').read_text() == 'first'
    assert [p.name for p in tmp_path.iterdir()] == ['cal']


def test_a_file_the_user_put_in_an_earlier_output_makes_it_theirs(tmp_path):
    target = tmp_path / 'cal'
    with output_dir('--out', target, 'calibrate') as tmp:
        _write(tmp, 'first')
        (tmp / 'plots').mkdir()
        (tmp / 'plots' / 'a.png').write_bytes(b'x')
    (target / 'plots' / 'a.png').unlink()  # a file of ours gone: still ours
    with output_dir('--out', target, 'calibrate') as tmp:
        _write(tmp, 'second')
    (target / 'my_notes.txt').write_text('mine')
    with pytest.raises(CliError, match='not an earlier output of satmotor calibrate'):
        with output_dir('--out', target, 'calibrate'):
            pytest.fail('must not get here')
    assert (target / 'my_notes.txt').read_text() == 'mine'
    assert (target / 'report.md').read_text() == 'second'
    (target / MARKER).write_text(json.dumps({'command': 'calibrate'}))  # an older marker
    with output_dir('--out', target, 'calibrate') as tmp:
        _write(tmp, 'third')
    assert (target / 'report.md').read_text() == 'third'


@pytest.mark.parametrize('other', ['user', 'validate'])
def test_a_directory_we_did_not_write_is_refused_unless_forced(tmp_path, other):
    target = tmp_path / 'mine'
    target.mkdir()
    _write(target, 'the user report')
    if other == 'validate':
        (target / MARKER).write_text(json.dumps({'command': 'validate'}))
    with pytest.raises(CliError, match=r"--out '.*mine' exists and is not an earlier output "
                                       r'of satmotor calibrate; .* --force'):
        with output_dir('--out', target, 'calibrate'):
            pytest.fail('must not get here')
    assert (target / 'report.md').read_text() == 'the user report'
    with output_dir('--out', target, 'calibrate', force=True) as tmp:
        _write(tmp, 'forced')
    assert (target / 'report.md').read_text() == 'forced'


@pytest.mark.parametrize('relation', ['same', 'inside', 'contains'])
def test_an_output_is_never_an_input(tmp_path, relation):
    data = tmp_path / 'bag'
    data.mkdir()
    (data / 'x.mcap').write_bytes(b'bag')
    out = {'same': data, 'inside': data / 'cal', 'contains': tmp_path}[relation]
    with pytest.raises(CliError, match='is or contains the input'):
        with output_dir('--out', out, 'calibrate', inputs=[data], force=True):
            pass
    assert (data / 'x.mcap').read_bytes() == b'bag'


def test_file_output_is_renamed_into_place_and_checked(tmp_path):
    target = tmp_path / 'speed.png'
    target.write_bytes(b'a user picture')
    ours = png_by('replay')
    with pytest.raises(CliError, match='not an earlier output of satmotor replay'):
        with output_file('--plot', target, 'replay', ours):
            pass
    target.unlink()
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot as plt
    fig = plt.figure(figsize=(1, 1))
    with output_file('--plot', target, 'replay', ours) as tmp:
        fig.savefig(tmp, format='png', metadata=png_metadata('replay'))
    plt.close(fig)
    assert ours(target) and not png_by('calibrate')(target)
    with pytest.raises(RuntimeError), output_file('--plot', target, 'replay', ours) as tmp:
        tmp.write_bytes(b'half')
        raise RuntimeError
    assert ours(target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ['speed.png']


def test_an_empty_directory_is_used(tmp_path):
    with output_dir('--out', tmp_path, 'characteristics') as tmp:
        _write(tmp, 'x')
    assert (tmp_path / 'report.md').read_text() == 'x'
