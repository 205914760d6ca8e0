# SPDX-License-Identifier: Apache-2.0
"""SIGINT and SIGTERM mid-write: one line, exit 130, no temporary left, the old output kept."""

import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _env():
    return {**os.environ, 'PYTHONPATH': str(ROOT)}


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    path = tmp_path_factory.mktemp('signals') / 'bag'
    subprocess.run([sys.executable, '-m', 'satmotor_ros.cli', 'synthetic', '--liquid',
                    'water', '--series', '30000', '--bag', 'mcap', '--seed', '3', '--out',
                    str(path)], env=_env(), check=True, capture_output=True, timeout=120)
    return path


@pytest.mark.slow
@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_bag_is_written_leaves_the_earlier_output(bag, signum):
    work = bag.parent / signum.name
    work.mkdir()
    earlier = work / 'out'
    earlier.mkdir()  # an earlier output of replay: its marker, and a file that must stay
    (earlier / '.satmotor-output.json').write_text(json.dumps({'command': 'replay'}))
    (earlier / 'keep').write_text('earlier')
    proc = subprocess.Popen(
        [sys.executable, '-m', 'satmotor_ros.cli', 'replay', str(bag), '--liquid', 'oil',
         '--topic-map',
         '/flow_measured:=flow_command', '--no-plot', '--out-bag', str(earlier)],
        env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not list(work.glob('.out.partial-*')) and proc.poll() is None \
                and time.monotonic() < deadline:
            time.sleep(0.002)
        assert proc.poll() is None, 'replay finished before its temporary bag appeared'
        proc.send_signal(signum)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    how = 'interrupted' if signum == signal.SIGINT else 'terminated (SIGTERM)'
    assert proc.returncode == 130
    assert err == f'satmotor: {how}; outputs not yet written are left as they were\n'
    assert 'wrote' not in out
    assert sorted(p.name for p in work.iterdir()) == ['out']
    assert (earlier / 'keep').read_text() == 'earlier'


def _dead_pid():
    proc = subprocess.Popen([sys.executable, '-c', 'pass'])
    proc.wait()
    return proc.pid


def test_what_a_killed_run_left_is_cleaned_at_the_next_run_and_nothing_else(tmp_path):
    """Issue 25: only our own names, only of a process that is gone; an aside is put back."""
    from satmotor_ros.cli import _output
    dead, alive = _dead_pid(), os.getpid()
    (tmp_path / f'.a.csv.partial-{dead}').write_text('half')
    (tmp_path / f'.bag.partial-{dead}').mkdir()
    (tmp_path / f'.bag.partial-{dead}' / 'x.mcap').write_text('half')
    (tmp_path / f'.b.csv.partial-{alive}').write_text('being written')
    (tmp_path / '.c.partial-notapid').write_text('the user')
    (tmp_path / f'.mine.old-{dead}-0123abcd').write_text('the user, renamed aside')
    (tmp_path / f'.taken.old-{dead}-0123abcd').write_text('aside')
    (tmp_path / 'taken').write_text('new')
    restored = _output.clean_stale(tmp_path)
    assert restored == [tmp_path / 'mine']
    assert (tmp_path / 'mine').read_text() == 'the user, renamed aside'
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([
        f'.b.csv.partial-{alive}', '.c.partial-notapid', f'.taken.old-{dead}-0123abcd', 'mine',
        'taken'])


@pytest.mark.slow
def test_kill_9_mid_write_leaves_a_partial_that_the_next_run_removes(bag):
    work = bag.parent / 'killed'
    work.mkdir()
    argv = [sys.executable, '-m', 'satmotor_ros.cli', 'replay', str(bag), '--liquid', 'oil',
            '--topic-map', '/flow_measured:=flow_command', '--no-plot', '--out-bag',
            str(work / 'out')]
    proc = subprocess.Popen(argv, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        # the temporary bag is a directory; a file of that name is the writability probe,
        # made and removed at once
        while not any(p.is_dir() for p in work.glob('.out.partial-*')) \
                and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.002)
        assert proc.poll() is None, 'replay finished before its temporary bag appeared'
        proc.kill()
    finally:
        proc.communicate()
    assert [p.name for p in work.iterdir()] == [f'.out.partial-{proc.pid}']
    done = subprocess.run(argv, env=_env(), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in work.iterdir()) == ['out']
