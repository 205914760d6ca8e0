# SPDX-License-Identifier: Apache-2.0
"""The fleet on what its main tests do not use: correlated points, calendar time, edge fleets."""

from datetime import datetime, timezone
import json
from pathlib import Path

from health_data import series_csv
import numpy as np
import pytest

from satmotor_ros.fleet.discover import PATH_DATE
from satmotor_ros.fleet.health import ratio_health
from satmotor_ros.fleet.summary import DAY, motor_view, RECORDING_TIMES

EPOCH = datetime(2026, 3, 1, tzinfo=timezone.utc).timestamp()


def _coverage(rho, trials=300, n=120, seed=7):
    """Share of trials whose interval holds the true ratio, residuals AR(1) with `rho`."""
    rng = np.random.default_rng(seed)
    predicted = np.linspace(1.0, 3.0, n)  # a sweep: losses grow along the table
    held, widths = 0, []
    for _ in range(trials):
        noise = np.empty(n)
        noise[0] = rng.normal()
        for i in range(1, n):
            noise[i] = rho * noise[i - 1] + (1 - rho ** 2) ** 0.5 * rng.normal()
        health = ratio_health(1.3 * predicted + 0.05 * noise, predicted)
        held += health.ci95[0] <= 1.3 <= health.ci95[1]
        widths.append(health.ci95[1] - health.ci95[0])
    return held / trials, float(np.median(widths)), health


def test_the_ratios_interval_holds_its_95_percent_on_correlated_points():
    """Independent points the old interval held 95 %; AR(1) 0.8 points it held 52 %."""
    independent, narrow, health = _coverage(0.0)
    assert independent >= 0.9 and health.inflation < 1.6
    correlated, wide, health = _coverage(0.8)
    assert correlated >= 0.85  # the old interval: 0.52 here
    assert wide > 2.0 * narrow and health.n_effective < health.n_samples / 3
    assert health.as_dict()['estimator'].startswith('ratio-v2')


def test_a_monitor_on_a_restarting_clock_is_trended_on_the_recordings_calendar_times(tmp_path):
    """
    Ten-minute series, one every 2 days, each clock from 0: the monitor's clock spans 1 h.

    Its own trend (0.1 per recorded hour) would be 2.4 a day; the calendar's is 0.05. The
    first recording leaves the monitor learning, its figure without an interval: it gets its
    ratio (the monitor's stopped the report's plot).
    """
    from satmotor_ros.fleet.report import write_report
    steps, markers = [], []
    for i in range(-1, 5):
        value = 1.0 + 0.1 * i
        start = (i + 1) * 610.0  # laid end to end, 10 s apart, on the monitor's clock
        bounds = [value - 0.01, value + 0.01] if i >= 0 else [None, None]
        steps.append({'recording': f'm/run_2026-03-{3 + 2 * i:02d}.csv', 'status': 'done',
                      'result': {'leakage_factor': {'value': value, 'ci95': bounds},
                                 'trend_per_hour': 0.1 * 3600 / 610, 'hours_to_limit': 0.5,
                                 'span_s': [start, start + 600.0], 'alarms': [],
                                 'recording_samples': 3001, 'recording_skipped': 0}})
        markers.append({'status': 'done', 'recording': steps[-1]['recording'],
                        'date': f'2026-03-{3 + 2 * i:02d}T00:00:00+00:00',
                        'time': EPOCH + (2 + 2 * i) * DAY, 'time_source': PATH_DATE,
                        'result': {'leakage_factor': value, 'ci95': [value, value]}})
    view = motor_view('m', 'water', markers, None, steps=steps)
    assert view['estimator'] == 'monitor+ratio' and view['trend_clock'] == RECORDING_TIMES
    assert view['trend_per_day'] == pytest.approx(0.05)
    assert view['days_to_limit'] == pytest.approx((2.0 - 1.4) / 0.05)
    assert {p['time_source'] for p in view['leakage_factor']} == {PATH_DATE}
    assert [p['estimator'] for p in view['leakage_factor']] == ['ratio'] + ['monitor'] * 5
    assert 'learning' in view['leakage_factor'][0]['monitor_unused']
    write_report(tmp_path, [view], {'root': 'r', 'recordings': 6, 'refused': 0, 'ran': 6,
                                    'reused': 0, 'written': 'now', 'estimator': 'e',
                                    'limit': 2.0})
    assert '| 2026-03-03T00:00:00+00:00 | date in the path |' in \
        (tmp_path / 'fleet.md').read_text()


def _csv(path, first_time=0.0):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text('time [s],speed [rpm],flow [l/min],p_in [MPa],p_out [MPa]\n'
                    f'{first_time},1000,20,10,1\n{first_time + 1},1000,20,10,1\n')
    return path


@pytest.mark.parametrize('address', ['nonsense', 'tcp://[::1', 'tcp://host:port'])
def test_a_malformed_scheduler_is_one_line_and_exit_1_before_any_work(tmp_path, capsys,
                                                                      address):
    from satmotor_ros.cli.main import main
    _csv(tmp_path / 'root' / 'm1' / 'a.csv')
    assert main(['fleet', str(tmp_path / 'root'), '--out', str(tmp_path / 'o'),
                 '--scheduler', address, '--no-progress']) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and f'--scheduler {address!r}' in err
    assert 'Traceback' not in err and not (tmp_path / 'o').exists()


def test_an_out_another_command_wrote_is_refused_and_left_as_it_was(tmp_path, capsys):
    import json
    from satmotor_ros.cli.main import main
    _csv(tmp_path / 'root' / 'm1' / 'a.csv')
    theirs = tmp_path / 'cal'
    theirs.mkdir()
    marker = theirs / '.satmotor-output.json'
    marker.write_text(json.dumps({'command': 'calibrate'}) + '\n')
    (theirs / 'coefficients.yaml').write_text('kept: 1\n')
    assert main(['fleet', str(tmp_path / 'root'), '--out', str(theirs)]) == 1
    assert capsys.readouterr().err.count('\n') == 1
    assert sorted(p.name for p in theirs.iterdir()) == ['.satmotor-output.json',
                                                        'coefficients.yaml']
    assert json.loads(marker.read_text()) == {'command': 'calibrate'}


@pytest.fixture(scope='module')
def edge_fleet(tmp_path_factory):
    """Run a fleet of edge cases through the tasks a worker runs (no cluster): the views."""
    from satmotor_ros.fleet.config import FleetConfig
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.synthetic import write_recording
    from satmotor_ros.fleet.tasks import calibrate_baseline, process_recording, RunOptions
    base = tmp_path_factory.mktemp('edges')
    root = base / 'root'
    write_recording(root / 'solo' / 'only_2026-03-01.csv', 1.0, 1, 24)
    (root / 'badfirst').mkdir(parents=True)
    (root / 'badfirst' / 'run_2026-03-01.csv').write_bytes(b'\xff\xfe\x00garbage\n' * 20)
    for i in range(3):
        write_recording(root / 'badfirst' / f'run_2026-03-{2 + i:02d}.csv', 1.0, 10 + i, 24)
    for i, name in enumerate('abc'):  # one time for all three, from their names
        write_recording(root / 'twins' / f'{name}_2026-03-01.csv', 1.0, 20 + i, 24)
    for i in range(4):  # every 3 days by the name, 0.03 a day: 0.09 a recording
        write_recording(root / 'sparse' / f'run_2026-03-{1 + 3 * i:02d}_0800.csv',
                        1.0 + 0.09 * i, 30 + i, 24)
    run = RunOptions(str(base / 'out'), liquid='water')
    views = {}
    for motor in discover(root, FleetConfig()):
        baseline = calibrate_baseline(motor, run)
        markers = [process_recording(r, motor.rule, baseline, run) for r in motor.recordings]
        views[motor.motor] = (motor_view(motor.motor, 'water', markers, baseline), baseline,
                              motor)
    return views


@pytest.mark.slow
def test_a_motor_with_one_recording_is_its_own_baseline_with_no_trend(edge_fleet):
    view, baseline, _ = edge_fleet['solo']
    assert baseline['recording'] == 'solo/only_2026-03-01.csv'
    assert [p['value'] for p in view['leakage_factor']] == [pytest.approx(1.0, abs=0.02)]
    assert view['trend_per_day'] is None and view['days_to_limit'] is None
    assert not view['alarms'] and not view['refused']


@pytest.mark.slow
def test_a_refused_first_recording_leaves_the_baseline_to_the_next_usable_one(edge_fleet):
    view, baseline, _ = edge_fleet['badfirst']
    assert baseline['recording'] == 'badfirst/run_2026-03-02.csv'
    assert [r['path'] for r in view['refused']] == ['badfirst/run_2026-03-01.csv']
    assert 'UTF-8' in view['refused'][0]['reason']
    assert len(view['leakage_factor']) == 3


@pytest.mark.slow
def test_recordings_at_one_time_are_kept_apart_in_name_order_with_no_trend(edge_fleet):
    view, _, motor = edge_fleet['twins']
    assert [r.name for r in motor.recordings] == ['a_2026-03-01.csv', 'b_2026-03-01.csv',
                                                  'c_2026-03-01.csv']
    assert len({r.time for r in motor.recordings}) == 1
    assert len(view['leakage_factor']) == 3 and not view['alarms']
    assert view['trend_per_day'] is None and view['days_to_limit'] is None


@pytest.mark.slow
def test_times_from_file_names_give_the_trend_per_calendar_day(edge_fleet):
    view, _, motor = edge_fleet['sparse']
    assert {r.time_source for r in motor.recordings} == {PATH_DATE}
    assert motor.recordings[1].date == '2026-03-04T08:00:00+00:00'
    assert view['trend_clock'] == RECORDING_TIMES
    assert view['trend_per_day'] == pytest.approx(0.03, rel=0.1)  # not 0.09 a recording
    last = view['leakage_factor'][-1]['value']
    assert view['days_to_limit'] == pytest.approx((2.0 - last) / 0.03, rel=0.15)


def test_an_unreachable_scheduler_is_one_line_and_exit_1(tmp_path, capsys, monkeypatch):
    import socket
    from satmotor_ros.cli.main import main
    from satmotor_ros.fleet import engine
    monkeypatch.setattr(engine, 'CONNECT_WAIT', 2.0)  # the client retries until then (20 s)
    _csv(tmp_path / 'root' / 'm1' / 'a.csv')
    with socket.socket() as free:  # a port nothing listens on once closed
        free.bind(('127.0.0.1', 0))
        port = free.getsockname()[1]
    address = f'tcp://127.0.0.1:{port}'
    assert main(['fleet', str(tmp_path / 'root'), '--out', str(tmp_path / 'o'),
                 '--scheduler', address, '--no-progress']) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and f'--scheduler {address!r}: cannot connect' in err
    assert 'Traceback' not in err


def test_a_tls_scheduler_without_a_tls_configuration_is_one_line_and_exit_1(tmp_path, capsys):
    from satmotor_ros.cli.main import main
    _csv(tmp_path / 'root' / 'm1' / 'a.csv')
    assert main(['fleet', str(tmp_path / 'root'), '--out', str(tmp_path / 'o'),
                 '--scheduler', 'tls://127.0.0.1:9', '--no-progress']) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and "--scheduler 'tls://127.0.0.1:9': cannot connect" in err
    assert 'TLS' in err


def _step(i, value, n, seconds, skipped=0, alarms=()):
    """Return a monitor step on an epoch clock: r{i}.csv, `n` samples over `seconds`."""
    start = EPOCH + i * DAY
    return {'recording': f'r{i}.csv', 'status': 'done', 'result': {
        'leakage_factor': {'value': value, 'ci95': [value - 0.01, value + 0.01]},
        'learning': False, 'trend_per_hour': 0.05, 'trend_per_day': 0.24, 'hours_to_limit': 48.0,
        'span_s': [start, start + seconds], 'recording_samples': n,
        'n_samples': 10 ** 6, 'recording_skipped': skipped,
        'alarms': list(alarms)}}


def _ratio(i, value):
    return {'status': 'done', 'recording': f'r{i}.csv', 'date': f'2026-03-{1 + i:02d}',
            'time': EPOCH + i * DAY, 'time_source': 'time column',
            'result': {'leakage_factor': value, 'ci95': [value - 0.02, value + 0.02]}}


def test_the_monitors_figure_is_taken_only_where_it_is_the_recordings_own():
    """
    Cold review F1 of issue 24: one valid step made every figure the monitor's.

    A slow log (a point a minute) and a recording of few usable samples give the monitor a
    figure with an interval that is not theirs (1.35, 1.30 here against ratios of 1.02): they
    get their ratios, each point says which, and the monitor's alarm raised on the slow log is
    not the fleet's. Its trend is then the line through the points, not the monitor's own.
    """
    raised = {'time_s': DAY + 60.0, 'kind': 'change', 'what': 'wear: leakage x1.35'}
    later = {'time_s': 3 * DAY + 60.0, 'kind': 'change', 'what': 'wear: c x1.05'}
    steps = [_step(0, 1.0, 3001, 600.0), _step(1, 1.35, 30, 1800.0, alarms=[raised]),
             _step(2, 1.30, 3001, 600.0, skipped=2900, alarms=[raised]),
             _step(3, 1.05, 3001, 600.0, alarms=[raised, later])]
    markers = [_ratio(i, v) for i, v in enumerate((1.01, 1.02, 1.02, 1.04))]
    view = motor_view('m', 'water', markers, None, steps=steps)
    points = view['leakage_factor']
    assert [p['value'] for p in points] == [1.0, 1.02, 1.02, 1.05]
    assert [p['estimator'] for p in points] == ['monitor', 'ratio', 'ratio', 'monitor']
    assert 'samples/s, below the 0.5' in points[1]['monitor_unused']
    assert 'usable samples, fewer than 150' in points[2]['monitor_unused']
    assert view['estimator'] == 'monitor+ratio' and view['trend_clock'] == RECORDING_TIMES
    assert not view['alarms']  # r1's is the slow log's; r3's 0.03 is no step on the calendar
    assert view['trend_per_day'] == pytest.approx(np.polyfit(np.arange(4.0),
                                                             [1.0, 1.02, 1.02, 1.05], 1)[0])
    steps[3]['result']['leakage_factor'] = {'value': 1.3, 'ci95': [1.29, 1.31]}  # a step
    view = motor_view('m', 'water', markers[:3] + [_ratio(3, 1.3)], None, steps=steps)
    assert [a['recording'] for a in view['alarms'] if a.get('source') == 'monitor'] == \
        ['r3.csv']  # the monitor's own, raised where its figure is taken
    slow = [_step(i, 1.35, 30, 1800.0) for i in range(4)]  # a motor of slow logs only
    view = motor_view('m', 'water', markers, None, steps=slow)
    assert view['estimator'] == 'ratio'
    assert [p['value'] for p in view['leakage_factor']] == [1.01, 1.02, 1.02, 1.04]
    fast = [_step(i, 1.35, 2 * 150 + 1, 600.0) for i in range(4)]  # 0.5 Hz, 301 samples
    assert motor_view('m', 'water', markers, None, steps=fast)['estimator'] == 'monitor'


def test_the_doc_gives_the_monitors_validity_as_the_code_has_it():
    from pathlib import Path
    from satmotor_ros.fleet.summary import MONITOR_MIN_RATE, MONITOR_MIN_SAMPLES
    text = (Path(__file__).resolve().parents[1] / 'doc' / 'fleet.md').read_text()
    text = ' '.join(text.split())
    assert f'at {MONITOR_MIN_RATE:g} a second or faster' in text
    assert f'at least {MONITOR_MIN_SAMPLES} usable samples' in text


def test_a_monitor_alarm_is_explained_like_the_ratios(tmp_path):
    """Cold review F2 of issue 24: a change alarm of the monitor's had no 'what changed'."""
    import json
    from satmotor_ros.fleet.config import FleetConfig
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.explain import CHANGE, explain_alarms
    from satmotor_ros.fleet.synthetic import LEAK_FACTOR, write_recording
    from satmotor_ros.fleet.tasks import RunOptions
    from satmotor_ros.model.io.config import default_config_path
    for i, factor in enumerate((1.0, LEAK_FACTOR)):
        write_recording(tmp_path / 'root' / 'm' / f'run_2026-03-0{1 + i}.csv', factor, 40 + i, 40)
    (motor,) = discover(tmp_path / 'root', FleetConfig())
    first, second = (r.relative for r in motor.recordings)
    baseline = {'coefficients': str(default_config_path('sm075_25.yaml')), 'liquid': 'water',
                'key': 'b'}
    markers = {first: {'status': 'done', 'content': 'a'},
               second: {'status': 'done', 'content': 'b'}}
    alarm = {'kind': 'change', 'recording': second, 'source': 'monitor', 'date': 'd',
             'what': f'unexplained (in {second})'}
    view = {'leakage_factor': [{'recording': second}], 'alarms': [alarm]}  # the first: none
    explain_alarms(view, motor, baseline, markers, RunOptions(str(tmp_path / 'out'),
                                                              liquid='water'))
    assert alarm['what'].startswith(f'unexplained (in {second}); what changed: ')
    kept = json.loads((tmp_path / 'out' / 'm' / motor.recordings[1].name / CHANGE).read_text())
    assert kept['before'] == first  # the recording before the alarm's, its point or not
    assert alarm['what'].endswith(f"what changed: {kept['what']}")


def test_a_refused_monitor_step_is_reported_and_a_rerun_starts_no_cluster(tmp_path):
    """
    Cold review F4 of issue 24: monitor/ holding a user's file made the step a failed task.

    It was in no report, and every rerun started a cluster to fail on it again. It is
    refused in one line, reported, held by a rerun (nothing to do), and run again once the
    user's directory is gone.
    """
    import json
    from satmotor_ros.fleet import run_fleet
    from satmotor_ros.fleet.chain import monitor_step
    from satmotor_ros.fleet.config import load_fleet
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.engine import plan
    from satmotor_ros.fleet.tasks import given_baseline, process_recording, RunOptions
    from satmotor_ros.model.io.config import default_config_path
    root, out = tmp_path / 'root', tmp_path / 'out'
    for i in range(2):
        series_csv(root / 'm' / f'r{i}.csv', 60 + i, EPOCH + i * DAY)
    (root / 'fleet.yaml').write_text(
        f"motors: [{{pattern: 'm/**', motor: m, liquid: water, "
        f"motor_file: '{default_config_path('sm075_25.yaml')}'}}]\n")
    (motor,) = discover(root, load_fleet(root / 'fleet.yaml'))
    run = RunOptions(str(out))
    baseline = given_baseline(motor, run)
    users = out / 'm' / 'r1.csv' / 'monitor'
    users.mkdir(parents=True)
    (users / 'notes.txt').write_text('mine\n')
    (out / '.satmotor-output.json').write_text('{"command": "fleet"}\n')
    step = None
    for rec in motor.recordings:  # what a first run's workers do
        process_recording(rec, motor.rule, baseline, run)
        step = monitor_step(rec, motor.rule, baseline, run, step)
    assert step['status'] == 'refused' and '\n' not in step['reason']
    assert 'is not an earlier output of satmotor monitor' in step['reason']
    (out / 'm' / 'deleted.csv').mkdir()  # a recording deleted from ROOT since (F10)
    (out / 'm' / 'deleted.csv' / '.fleet-done.json').write_text('{}')
    lines = []
    again = run_fleet(str(root), str(out), show_progress=False, say=lines.append)
    assert again.cluster == '' and 'no cluster started' in lines[0]
    assert 'm/deleted.csv' in lines[1] and not (out / 'm' / 'deleted.csv').exists()
    (view,) = json.loads((out / 'fleet.json').read_text())['motors']
    assert [(r['path'], r['status']) for r in view['monitor_refused']] == \
        [('m/r1.csv', 'refused')]
    assert view['leakage_factor'][-1]['estimator'] == 'ratio'  # its point: its ratio
    assert 'satmotor monitor' in (out / 'fleet.md').read_text()
    assert (users / 'notes.txt').read_text() == 'mine\n'
    (users / 'notes.txt').unlink()
    assert plan([motor], run).chain_from == {'m': 1}  # the step can run now


def test_monitor_steps_that_read_nothing_start_no_cluster(tmp_path):
    """
    Cold review of issue 24 (finding 9): a rerun left only monitor steps started a cluster.

    The steps of a motor without a baseline read no data (each is refused with the
    baseline's reason and passes the state on): a rerun that has only those left (a
    scheduler lost before them) writes them itself and starts no cluster.
    """
    from satmotor_ros.fleet import run_fleet
    from satmotor_ros.fleet.chain import read_step
    from satmotor_ros.fleet.config import FleetConfig
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.tasks import calibrate_baseline, process_recording, RunOptions
    root, out = tmp_path / 'root', tmp_path / 'out'
    for name in ('a.csv', 'b.csv'):
        (root / 'm').mkdir(parents=True, exist_ok=True)
        (root / 'm' / name).write_bytes(b'\xff\xfe garbage\n')
    (motor,) = discover(root, FleetConfig())
    run = RunOptions(str(out.resolve()), liquid='water')
    out.mkdir()
    (out / '.satmotor-output.json').write_text('{"command": "fleet"}\n')
    baseline = calibrate_baseline(motor, run)  # what a first run's workers did, but the
    assert baseline['recording'] is None  # monitor's steps: the scheduler went first
    for rec in motor.recordings:
        process_recording(rec, motor.rule, baseline, run)
    lines = []
    again = run_fleet(str(root), str(out), liquid='water', show_progress=False,
                      say=lines.append)
    assert again.cluster == '' and 'no cluster started' in lines[0]
    steps = [read_step(out / 'm' / rec.name) for rec in motor.recordings]
    assert [s['status'] for s in steps] == ['refused', 'refused']
    assert steps[1]['prev'] == steps[0]['chain']  # one chain, passed on


def _mbari_fleet(root):
    """Two motors, each with a stretch of both MBARI logs (rows below vacuum in each)."""
    from vendored_data import data_path
    stretches = {'2021.07.26T10.51.44.exp': (4000, 5500), 'FrictionIDMovesWithBiasCurr.exp':
                 (2000, 3500)}  # data lines; the first below vacuum: 5086, 3352
    for motor in ('buoy_a', 'buoy_b'):
        for name, (first, last) in stretches.items():
            lines = data_path('real', 'mbari_pto', name).read_text().splitlines(True)
            (root / motor).mkdir(parents=True, exist_ok=True)
            (root / motor / name).write_text(''.join([lines[0], *lines[1 + first:1 + last]]))
    (root / 'fleet.yaml').write_text('motors:\n' + ''.join(
        f"  - {{pattern: '{m}/**', motor: {m}, liquid: oil, family: paszota, displacement: "
        '0.30 in^3/rev, columns: mbari_pto}\n' for m in ('buoy_a', 'buoy_b')))
    return root


def test_the_mbari_logs_are_read_as_calibrate_reads_them_rows_dropped_and_said(tmp_path,
                                                                               capsys):
    """
    Cold review of issue 24 (finding 5): the fleet refused the real MBARI logs whole.

    A gauge pressure below vacuum in some rows: ``satmotor calibrate`` drops those rows with
    a warning, the fleet refused the recording. One rule now: calibrate's reader and its
    row-level handling, the rows said in the marker and fleet.md; refused whole only when
    damaged (one row too few cells, here).
    """
    from satmotor_ros.cli._bench import load_data
    from satmotor_ros.fleet.config import load_fleet
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.report import write_report
    from satmotor_ros.fleet.summary import motor_view
    from satmotor_ros.fleet.tasks import (columns_of, given_baseline, load_screened,
                                          motor_options, process_recording, Refused,
                                          RunOptions, warnings_of)
    from satmotor_ros.identify.table import IMPOSSIBLE
    from satmotor_ros.model.io.config import default_config_path
    root = _mbari_fleet(tmp_path / 'root')
    motors = discover(root, load_fleet(root / 'fleet.yaml'))
    assert [(m.motor, len(m.recordings)) for m in motors] == [('buoy_a', 2), ('buoy_b', 2)]
    run = RunOptions(str(tmp_path / 'out'))
    for motor in motors:
        options = motor_options(motor.rule, run)
        for rec in motor.recordings:
            table, _ = load_screened(rec, options, columns_of(motor.rule, run))
            capsys.readouterr()
            same = load_data(rec.path, 'mbari_pto', options.spec().geometry.displacement)
            said = capsys.readouterr().err  # what calibrate prints of it
            assert len(table) == len(same) < 1500 and table.notes == same.notes
            (note,) = warnings_of(table)
            assert note.startswith(IMPOSSIBLE) and 'below vacuum' in note
            assert said == f'warning: {rec.path}: {note}\n'
    rec = motors[0].recordings[0]  # a marker says the rows, and fleet.md
    options = motor_options(motors[0].rule, run)
    motor_file = tmp_path / 'lab.yaml'
    motor_file.write_text(default_config_path('sm075_25.yaml').read_text())
    baseline = given_baseline(motors[0], run) | {'coefficients': str(motor_file),
                                                 'liquid': 'oil'}
    marker = process_recording(rec, motors[0].rule, baseline, run)
    assert marker['status'] == 'done', marker
    assert marker['warnings'] == warnings_of(load_screened(rec, options, 'mbari_pto')[0])
    view = motor_view('buoy_a', 'oil', [marker], None)
    assert view['warnings'] == [{'path': rec.relative, 'warning': marker['warnings'][0]}]
    write_report(tmp_path / 'out', [view], {
        'root': str(root), 'recordings': 1, 'refused': 0, 'ran': 1, 'reused': 0, 'written': '',
        'estimator': 'x', 'limit': 2.0, 'cluster': '', 'fleet_file': ''})
    assert marker['warnings'][0] in (tmp_path / 'out' / 'fleet.md').read_text()
    lines = Path(rec.path).read_text().splitlines(True)
    Path(rec.path).write_text(''.join([*lines[:50], '1.0 2.0 3.0\n', *lines[50:]]))
    with pytest.raises(Refused, match='cells'):  # damaged: refused whole
        load_screened(rec, motor_options(motors[0].rule, run), 'mbari_pto')


def test_a_users_calibrate_dir_does_not_move_the_baseline(tmp_path):
    """
    Cold review F5 of issue 24: a user's file in calibrate/ moved the baseline on.

    The first recording's calibrate/ holding a user's file made the next recording the
    baseline (every figure then against another calibration). The motor gets no baseline,
    said in one line, a rerun holds that, and once the user's directory is gone the first
    recording is calibrated.
    """
    from satmotor_ros.fleet.config import FleetConfig
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.engine import plan
    from satmotor_ros.fleet.synthetic import write_recording
    from satmotor_ros.fleet.tasks import calibrate_baseline, process_recording, RunOptions
    for i in range(2):
        write_recording(tmp_path / 'root' / 'm' / f'run_2026-03-0{1 + i}.csv', 1.0, 70 + i, 24)
    (motor,) = discover(tmp_path / 'root', FleetConfig())
    run = RunOptions(str(tmp_path / 'out'), liquid='water')
    users = tmp_path / 'out' / 'm' / motor.recordings[0].name / 'calibrate'
    users.mkdir(parents=True)
    (users / 'notes.txt').write_text('mine\n')
    baseline = calibrate_baseline(motor, run)
    assert baseline['recording'] is None and motor.recordings[0].relative in baseline['reason']
    assert 'satmotor calibrate did not write' in baseline['reason']
    assert not (tmp_path / 'out' / 'm' / motor.recordings[1].name / 'calibrate').exists()
    marker = process_recording(motor.recordings[1], motor.rule, baseline, run)
    assert marker['status'] == 'refused' and marker['reason'] == baseline['reason']
    held = plan([motor], run).baselines['m']  # held: a rerun does not calibrate again
    assert held == baseline and held['conflict'] == str(users)
    (users / 'notes.txt').unlink()
    assert 'm' not in plan([motor], run).baselines  # gone: it is calibrated again
    assert [f.name for f in users.iterdir()] == []


def test_the_outputs_of_a_deleted_recording_or_motor_go_where_wholly_ours(tmp_path):
    """Cold review F10 of issue 24: a deleted recording's outputs lingered in DIR."""
    from satmotor_ros.cli._output import write_marker
    from satmotor_ros.fleet.config import FleetConfig, RESERVED
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.prune import prune
    from satmotor_ros.fleet.resume import options_key
    _csv(tmp_path / 'root' / 'm' / 'kept.csv')
    out = tmp_path / 'out'

    def made(path, extra=None):
        path.mkdir(parents=True)
        (path / '.fleet-done.json').write_text('{}')
        (path / '.fleet-monitor.json').write_text('{}')
        (path / 'health').mkdir()
        (path / 'health' / 'health.json').write_text('{}')
        write_marker(path / 'health', 'fleet-health')  # lists health.json as its own
        if extra:
            (path / extra).write_text('mine\n')
    made(out / 'm' / 'kept.csv')
    made(out / 'm' / 'gone.csv')
    made(out / 'm' / 'noted.csv', extra='notes.txt')
    made(out / 'old' / 'r.csv')
    ours = {'recording': 'old/r.csv', 'reason': None}
    (out / 'old' / 'baseline.json').write_text(json.dumps({**ours, 'key': options_key(ours)}))
    (out / 'plots').mkdir()
    root = tmp_path / 'root'
    removed = prune(out, root, discover(root, FleetConfig()), RESERVED)
    assert sorted(removed) == ['m/gone.csv', 'old', 'old/r.csv']
    assert sorted(p.name for p in (out / 'm').iterdir()) == ['kept.csv', 'noted.csv']
    assert (out / 'plots').is_dir() and not (out / 'old').exists()


def test_prune_keeps_a_users_directory_that_holds_no_baseline_of_ours(tmp_path):
    """Cold review of issue 24: a user's columns.yaml, an empty directory were pruned."""
    from satmotor_ros.fleet.config import FleetConfig, RESERVED
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.prune import prune
    _csv(tmp_path / 'root' / 'm' / 'kept.csv')
    out = tmp_path / 'out'
    (out / 'mapping').mkdir(parents=True)
    (out / 'mapping' / 'columns.yaml').write_text('time: t\n')
    (out / 'empty_for_later').mkdir()
    (out / 'cfg').mkdir()
    theirs = {'recording': 'r.csv', 'key': 'mine'}  # a baseline.json whose key is no hash
    (out / 'cfg' / 'baseline.json').write_text(json.dumps(theirs))
    root = tmp_path / 'root'
    assert prune(out, root, discover(root, FleetConfig()), RESERVED) == []
    assert (out / 'mapping' / 'columns.yaml').read_text() == 'time: t\n'
    assert (out / 'empty_for_later').is_dir() and (out / 'cfg' / 'baseline.json').is_file()


def test_an_out_last_reported_of_another_root_is_refused_unless_forced(tmp_path, capsys):
    """
    Cold review of issue 24: --out of another ROOT pruned nothing but took that ROOT's place.

    So a second run pruned the first fleet's outputs. It is refused in one line naming both
    ROOTs, before any work; ``--force`` takes DIR over, and the first ROOT's outputs go then.
    """
    from satmotor_ros.cli.main import main
    from satmotor_ros.fleet.config import FleetConfig, RESERVED
    from satmotor_ros.fleet.discover import discover
    from satmotor_ros.fleet.prune import check_root, prune, root_of
    one, two = tmp_path / 'one', tmp_path / 'two'
    _csv(one / 'm' / 'a.csv')
    _csv(two / 'n' / 'b.csv')
    out = tmp_path / 'out'
    gone = out / 'm' / 'old.csv'
    gone.mkdir(parents=True)
    (gone / '.fleet-done.json').write_text('{}')
    (out / '.satmotor-output.json').write_text('{"command": "fleet"}\n')
    report = json.dumps({'root': str(one.resolve())})
    (out / 'fleet.json').write_text(report)
    assert main(['fleet', str(two), '--out', str(out), '--no-progress']) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'Traceback' not in err
    assert f'ROOT {str(one.resolve())!r}, not {str(two.resolve())!r}' in err
    assert gone.is_dir() and (out / 'fleet.json').read_text() == report  # nothing touched
    assert root_of(out) == str(one.resolve())
    assert check_root(out, one, False) is None  # its own ROOT: used
    assert check_root(out, two, True) == str(one.resolve())  # forced: taken over, and
    assert prune(out, two, discover(two, FleetConfig()), RESERVED) == ['m/old.csv']  # pruned
    assert not gone.exists()
