# SPDX-License-Identifier: Apache-2.0
"""
``satmotor fleet`` on real Dask clusters.

A local one of two worker processes, and one started apart (``dask scheduler``, ``dask
worker``) reached through ``--scheduler``.
"""

import json
import os
from pathlib import Path
import re
import subprocess
import sys
import time

import pytest

from satmotor_ros.fleet import run_fleet
from satmotor_ros.fleet.synthetic import LEAK_DAY, make_fleet
from satmotor_ros.fleet.tasks import ZERO_PRESSURE

pytestmark = pytest.mark.slow  # real Dask clusters

REPOSITORY = Path(__file__).resolve().parents[1]
DAYS = 6


@pytest.fixture(scope='module')
def fleet(tmp_path_factory):
    """Run the synthetic fleet once on two local workers: (root, out, outcome, lines)."""
    base = tmp_path_factory.mktemp('fleet')
    root = make_fleet(base / 'root', days=DAYS)  # README's fleet (its first days, its seeds)
    lines = []
    outcome = run_fleet(str(root), str(base / 'out'), workers=2, liquid='water',
                        show_progress=False, say=lines.append)
    return root, base / 'out', outcome, lines


def test_fleet_ranks_the_wearing_motor_first_and_names_the_leak_and_the_bad_recordings(fleet):
    root, out, outcome, lines = fleet
    report = json.loads((out / 'fleet.json').read_text())
    motors = {m['motor']: m for m in report['motors']}
    assert [m['motor'] for m in report['motors']][0] == 'wearing'
    assert outcome.motors[0] == 'wearing'
    wearing, leak, healthy, patchy = (motors[k] for k in ('wearing', 'leak', 'healthy', 'tug_d'))
    assert wearing['trend_per_day'] == pytest.approx(0.06, rel=0.15)
    assert 0 < wearing['days_to_limit'] < 20 and not wearing['alarms']
    assert [a['kind'] for a in leak['alarms']] == ['change']
    assert leak['alarms'][0]['date'].startswith(f'2026-03-{1 + LEAK_DAY:02d}')
    assert 'what changed: ' in leak['alarms'][0]['what']  # the monitor's explainer (a recording
    # may be too short for it to name the change, doc/fleet.md)
    assert leak['leakage_factor'][-1]['value'] == pytest.approx(1.6, rel=0.03)
    said = re.search(r'leakage factor ([\d.]+) -> ([\d.]+) \(\+(\d+) %\) since (\S+),',
                     leak['alarms'][0]['what'])
    assert said and float(said[1]) == pytest.approx(1.0, abs=0.02)
    assert float(said[2]) == pytest.approx(1.6, abs=0.04) and 55 <= int(said[3]) <= 65
    assert said[4] == f'2026-03-{LEAK_DAY:02d}'
    readme = ' '.join((REPOSITORY / 'README.md').read_text().split())  # they quote this run
    assert f"the leak's change alarm (leakage factor {said[1]} -> {said[2]}), 3 refused" in readme
    doc = ' '.join((REPOSITORY / 'doc' / 'fleet.md').read_text().split())
    assert f'`{said[0][:-1]}`' in doc
    assert not healthy['alarms'] and healthy['days_to_limit'] is None
    for point in healthy['leakage_factor']:
        assert point['ci95'][0] <= point['value'] <= point['ci95'][1]
        assert point['value'] == pytest.approx(1.0, abs=0.02)
    reasons = {r['path']: r['reason'] for r in patchy['refused']}
    assert set(reasons) == {'tug_d/d02.csv', 'tug_d/d04.csv', 'tug_d/d99_garbage.csv'}
    assert reasons['tug_d/d02.csv'].startswith('truncated mid-row')
    assert reasons['tug_d/d04.csv'] == ZERO_PRESSURE
    assert 'UTF-8' in reasons['tug_d/d99_garbage.csv']
    assert len(patchy['leakage_factor']) == DAYS - 2  # the others went on
    assert 'memory per task' in lines[0] and '2 worker(s)' in lines[0]
    md = (out / 'fleet.md').read_text()
    assert md.index('## wearing') < md.index('## leak') and 'truncated' in md


def test_fleet_outputs_are_the_single_commands_and_ran_on_the_cluster_s_workers(fleet):
    root, out, outcome, _ = fleet
    baseline = json.loads((out / 'healthy' / 'baseline.json').read_text())
    assert baseline['recording'] == 'vessel_a/day00.csv'
    calibrated = out / 'healthy' / 'day00.csv' / 'calibrate'
    assert {'calibration.json', 'coefficients.yaml', 'report.md'} <= \
        {p.name for p in calibrated.iterdir()}
    assert json.loads((calibrated / '.satmotor-output.json').read_text())['command'] == \
        'calibrate'
    steps = [json.loads(p.read_text()) for p in out.glob('*/*/.fleet-monitor.json')]
    assert len(steps) == outcome.recordings  # one monitor per motor, a step per recording
    assert (out / 'healthy' / 'day03.csv' / 'monitor' / 'monitor.json').is_file()
    markers = [json.loads(p.read_text()) for p in out.glob('*/*/.fleet-done.json')]
    assert len(markers) == outcome.recordings == 4 * DAYS + 1
    # every task in a worker process of the two-worker cluster, none in the client's; which
    # worker takes which is the scheduler's (after the baselines, data locality may keep the
    # short tasks on one: a CI run saw all 25 there), so both are not required
    workers = {m['worker'] for m in markers}
    assert 1 <= len(workers) <= 2 and not any(w.endswith(f':{os.getpid()}') for w in workers)
    plots = out / 'plots'
    for png in [plots / 'fleet.png', *(plots / f'{m}.png' for m in outcome.motors)]:
        assert png.read_bytes().startswith(b'\x89PNG')


def test_fleet_rerun_does_nothing_done_and_starts_no_cluster(fleet):
    root, out, first, _ = fleet
    lines = []
    again = run_fleet(str(root), str(out), workers=2, liquid='water', show_progress=False,
                      say=lines.append)
    assert (again.ran, again.reused, again.cluster) == (0, first.recordings, '')
    assert 'no cluster started' in lines[0]
    assert again.seconds < 0.5 * first.seconds
    touched = root / 'vessel_a' / 'day03.csv'
    os.utime(touched, (time.time(), time.time()))  # same content: still done
    assert run_fleet(str(root), str(out), liquid='water', show_progress=False,
                     say=lines.append).ran == 0
    with touched.open('a') as file:  # new content: only it is redone
        file.write(touched.read_text().splitlines()[-1] + '\n')
    redo = run_fleet(str(root), str(out), workers=1, liquid='water', show_progress=False,
                     say=lines.append)
    assert (redo.ran, redo.reused) == (1, first.recordings - 1)


def _start(argv, log):
    """Start ``dask ARGV`` (the venv's own) with this checkout importable on the worker."""
    env = {**os.environ, 'PYTHONPATH': str(REPOSITORY)}
    return subprocess.Popen([str(Path(sys.executable).parent / 'dask'), *argv], stdout=log,
                            stderr=subprocess.STDOUT, env=env, start_new_session=True)


def test_fleet_runs_on_a_scheduler_and_worker_started_apart(tmp_path):
    root = make_fleet(tmp_path / 'root', days=3, points=30, motors=('healthy',))
    address_file = tmp_path / 'scheduler.json'
    log = (tmp_path / 'dask.log').open('w')
    scheduler = _start(['scheduler', '--scheduler-file', str(address_file), '--port', '0',
                        '--no-dashboard'], log)
    worker = None
    try:
        deadline = time.monotonic() + 60
        while not address_file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        address = json.loads(address_file.read_text())['address']
        worker = _start(['worker', address, '--nthreads', '1', '--memory-limit', '1GiB',
                         '--no-dashboard'], log)
        lines = []
        outcome = run_fleet(str(root), str(tmp_path / 'out'), scheduler=address,
                            liquid='water', show_progress=False, say=lines.append)
    finally:
        for process in (worker, scheduler):
            if process is not None:
                process.terminate()
                process.wait(timeout=30)
        log.close()
    assert outcome.cluster == address and outcome.ran == 3
    assert '1 worker(s)' in lines[0] and 'memory per task 1.00 GiB' in lines[0]
    report = json.loads((tmp_path / 'out' / 'fleet.json').read_text())
    assert [len(m['leakage_factor']) for m in report['motors']] == [3]


def test_a_scheduler_lost_mid_run_is_one_line_and_exit_1(tmp_path):
    """Cold review F6 of issue 24: a scheduler gone mid-run exited 0 after a traceback."""
    root = make_fleet(tmp_path / 'root', days=2, points=30, motors=('healthy',))
    address_file = tmp_path / 'scheduler.json'
    log = (tmp_path / 'dask.log').open('w')
    scheduler = _start(['scheduler', '--scheduler-file', str(address_file), '--port', '0',
                        '--no-dashboard'], log)
    worker = run = None
    try:
        deadline = time.monotonic() + 60
        while not address_file.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        address = json.loads(address_file.read_text())['address']
        worker = _start(['worker', address, '--nthreads', '1', '--no-dashboard'], log)
        run = subprocess.Popen(
            [sys.executable, '-c', 'import sys; from satmotor_ros.cli.main import main; '
             'sys.exit(main(sys.argv[1:]))', 'fleet', str(root), '--out', str(tmp_path / 'out'),
             '--scheduler', address, '--liquid', 'water', '--no-progress'],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
            env={**os.environ, 'PYTHONPATH': str(REPOSITORY)})
        baseline = tmp_path / 'out' / 'healthy' / 'baseline.json'
        deadline = time.monotonic() + 120
        while not baseline.exists() and time.monotonic() < deadline:  # work under way
            time.sleep(0.1)
        scheduler.terminate()
        scheduler.wait(timeout=30)
        out, err = run.communicate(timeout=120)
    finally:
        for process in (run, worker, scheduler):
            if process is not None and process.poll() is None:
                process.terminate()
                process.wait(timeout=30)
        log.close()
    assert run.returncode == 1, (out, err)
    assert err.count('\n') == 1 and 'lost mid-run' in err and 'run again to resume' in err
