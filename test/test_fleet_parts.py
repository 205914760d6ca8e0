# SPDX-License-Identifier: Apache-2.0
"""The fleet's parts without a cluster: fleet.yaml, discovery, resume, trend and alarms."""

from datetime import datetime, timezone
import os

from health_data import series_csv
import numpy as np
import pytest

from satmotor_ros.cli.main import main
from satmotor_ros.fleet.config import FleetConfig, load_fleet
from satmotor_ros.fleet.discover import (BAG_START, discover, MTIME, PATH_DATE, path_date,
                                         TIME_COLUMN)
from satmotor_ros.fleet.errors import FleetError
from satmotor_ros.fleet.resume import is_done, options_key, stat_of, write_done
from satmotor_ros.fleet.summary import DAY, MONITOR_EPOCH, motor_view, rank

HEADER = 'time [s],speed [rpm],flow [l/min],p_in [MPa],p_out [MPa]\n'
EPOCH = datetime(2026, 3, 1, tzinfo=timezone.utc).timestamp()


def _csv(path, first_time=0.0):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(HEADER + f'{first_time},1000,20,10,1\n{first_time + 1},1000,20,10,1\n')
    return path


@pytest.mark.parametrize(('text', 'said'), [
    ('motors: [{pattern: "a/**", motor: m1, colour: red}]', "unknown key 'colour'"),
    ('motors: [{pattern: "a/**"}]', 'motor is missing'),
    ('motors: [{pattern: "a/**", motor: m1, liquid: beer}]', "liquid = 'beer'"),
    ('motors: [{pattern: "a/**", motor: m1, displacement: 5 furlongs}]',
     "displacement = '5 furlongs'"),
    ('motors: [{pattern: "a/**", motor: "../up"}]', "motor = '../up'"),
    ('motors: [{pattern: "a/**", motor: m1, motor_file: nope.yaml}]', 'no such file'),
    ('vessels: []', 'need one key, motors'),
    ('motors: [{pattern: [1], motor: m1}]', 'pattern = [1]'),
])
def test_fleet_yaml_is_read_strictly_one_line_naming_key_and_value(tmp_path, text, said):
    path = tmp_path / 'fleet.yaml'
    path.write_text(text)
    with pytest.raises(FleetError, match='motors') as err:
        load_fleet(path)
    assert said in str(err.value) and '\n' not in str(err.value)


def test_fleet_yaml_first_matching_pattern_wins_and_parents_match(tmp_path):
    path = tmp_path / 'fleet.yaml'
    path.write_text('motors:\n'
                    '  - {pattern: "ships/*/pump_a", motor: special, displacement: 10cm^3/rev}\n'
                    '  - {pattern: "ships/**", motor: other, liquid: oil}\n')
    config = load_fleet(path)
    assert config.rule_for('ships/kestrel/pump_a/2026-03-01.csv').motor == 'special'
    assert config.rule_for('ships/kestrel/pump_b/x.csv').motor == 'other'
    assert config.rule_for('rigs/x.csv') is None
    assert config.rules[0].displacement == pytest.approx(10e-6 / (2 * np.pi))


def test_discovery_groups_by_first_level_and_orders_by_time_and_says_how(tmp_path):
    _csv(tmp_path / 'm1' / 'b.csv', EPOCH + DAY)  # epoch time column
    _csv(tmp_path / 'm1' / 'a.csv', EPOCH + 2 * DAY)
    _csv(tmp_path / 'm1' / 'sub' / 'run_2026-02-27T0930.csv')  # relative time: path date
    undated = _csv(tmp_path / 'm2' / 'undated.csv')
    os.utime(undated, (EPOCH, EPOCH))
    bag = tmp_path / 'm2' / 'bag1'
    bag.mkdir()
    (bag / 'metadata.yaml').write_text(
        'rosbag2_bagfile_information:\n  starting_time:\n'
        f'    nanoseconds_since_epoch: {int((EPOCH + DAY) * 1e9)}\n')
    (tmp_path / 'm2' / 'notes.txt').write_text('not a recording without a column mapping\n')
    lost = tmp_path / 'm2' / 'lost_2026-01-01'  # its metadata.yaml never written: still found
    lost.mkdir()
    (lost / 'lost_0.mcap').write_bytes(b'\x89MCAP0\r\n')
    motors = discover(tmp_path, FleetConfig())
    assert [m.motor for m in motors] == ['m1', 'm2']
    m1, m2 = motors
    assert [r.relative for r in m1.recordings] == ['m1/sub/run_2026-02-27T0930.csv',
                                                   'm1/b.csv', 'm1/a.csv']
    assert [r.time_source for r in m1.recordings] == [PATH_DATE, TIME_COLUMN, TIME_COLUMN]
    assert m1.recordings[0].date == '2026-02-27T09:30:00+00:00'
    assert m1.recordings[0].name == 'sub__run_2026-02-27T0930.csv'
    assert [(r.relative, r.kind, r.time_source) for r in m2.recordings] == [
        ('m2/lost_2026-01-01', 'bag', PATH_DATE), ('m2/undated.csv', 'csv', MTIME),
        ('m2/bag1', 'bag', BAG_START)]


def test_a_csv_time_in_ms_is_read_in_its_unit(tmp_path):
    """Cold review F7 of issue 24: a ``time [ms]`` epoch was no epoch (1.77e12): dated by mtime."""
    for name, unit, scale, day in (('a.csv', 'ms', 1e3, 2), ('b.csv', 'min', 1 / 60, 1)):
        path = tmp_path / 'm' / name
        path.parent.mkdir(parents=True, exist_ok=True)
        first = (EPOCH + day * DAY) * scale
        path.write_text(f'time [{unit}],speed [rpm],flow [l/min],p_in [MPa],p_out [MPa]\n'
                        f'{first!r},1000,20,10,1\n{first + scale!r},1000,20,10,1\n')
        os.utime(path, (EPOCH, EPOCH))
    (motor,) = discover(tmp_path, FleetConfig())
    assert [(r.relative, r.time_source) for r in motor.recordings] == [
        ('m/b.csv', TIME_COLUMN), ('m/a.csv', TIME_COLUMN)]
    assert [r.time for r in motor.recordings] == pytest.approx([EPOCH + DAY, EPOCH + 2 * DAY])


def test_motor_ids_are_distinct_and_never_a_report_file(tmp_path):
    """Directories that make one safe id, or a report's name, stay apart (F7, F8)."""
    root = tmp_path / 'root'
    for top in ('a b', 'a_b', 'a?b', 'plots', 'fleet.json', 'FLEET', 'given', 'root'):
        _csv(root / top / 'r.csv')
    _csv(root / 'x.csv')  # ROOT's own file: motor 'root', apart from the directory 'root'
    _csv(root / 'ships' / 'r.csv')
    (root / 'fleet.yaml').write_text('motors: [{pattern: "ships/**", motor: given}]\n')
    motors = discover(root, load_fleet(root / 'fleet.yaml'))
    ids = {m.motor: [r.relative for r in m.recordings] for m in motors}
    assert len(ids) == 10 and ids['a_b'] == ['a_b/r.csv'] and ids['given'] == ['ships/r.csv']
    reserved = {'fleet', 'fleet.json', 'fleet.md', 'plots'}
    assert not {i.lower() for i in ids} & reserved
    again = {m.motor for m in discover(root, load_fleet(root / 'fleet.yaml'))}
    assert again == set(ids)  # deterministic
    assert ids['root'] == ['root/r.csv']
    assert sorted(i.split('~')[0] for i in set(ids) - {'a_b', 'given', 'root'}) == [
        'FLEET', 'a_b', 'a_b', 'fleet.json', 'given', 'plots', 'root']


@pytest.mark.parametrize('motor', ['fleet.json', 'fleet.md', 'plots', 'Fleet'])
def test_a_fleet_yaml_motor_named_as_a_report_file_is_refused_in_one_line(tmp_path, motor):
    path = tmp_path / 'fleet.yaml'
    path.write_text(f'motors: [{{pattern: "a/**", motor: {motor}}}]')
    with pytest.raises(FleetError, match=f"motor = '{motor}': the name of the report") as err:
        load_fleet(path)
    assert '\n' not in str(err.value)


def test_a_mapped_log_is_timed_by_its_epoch_column_and_roots_own_date_is_not_one(tmp_path):
    """
    F4: a log is timed by its epoch ``time`` column through its mapping, not its mtime.

    A date in ROOT's own path is no recording's.
    """
    root = tmp_path / '2024-05-01' / 'fleet'
    log = root / 'rig' / 'run.log'
    log.parent.mkdir(parents=True)
    log.write_text('stamp\tn\tq\tpa\tpb\n'
                   + ''.join(f'{(EPOCH + 2 * DAY + i) * 1e3:.0f}\t1000\t20\t10\t1\n'
                             for i in range(3)))
    os.utime(log, (EPOCH, EPOCH))
    _csv(root / 'm2' / 'no_time.csv')  # neither time column nor date below ROOT: mtime
    os.utime(root / 'm2' / 'no_time.csv', (EPOCH + DAY, EPOCH + DAY))
    (root / 'fleet.yaml').write_text(
        'motors: [{pattern: "rig/**", motor: rig, columns: {columns: {time: {column: stamp, '
        'unit: ms}, speed: {column: n, unit: rpm}, flow: {column: q, unit: l/min}, '
        'p_in: {column: pa, unit: MPa}, p_out: {column: pb, unit: MPa}}}}]\n')
    m2, rig = discover(root, load_fleet(root / 'fleet.yaml'))
    assert [(r.kind, r.time_source, r.time) for r in rig.recordings] == [
        ('log', TIME_COLUMN, EPOCH + 2 * DAY)]
    assert [(r.time_source, r.time) for r in m2.recordings] == [(MTIME, EPOCH + DAY)]


def test_path_date_takes_the_last_date_of_the_path():
    assert path_date('2025-01-01/run_20260301_120000.csv') == EPOCH + 12 * 3600
    assert path_date('unit7/run_99.csv') is None
    assert path_date('log_2026.03.01T10.51.44.exp') == EPOCH + 10 * 3600 + 51 * 60 + 44
    assert path_date('x/2026.03.01.csv') == EPOCH  # review 24 finding 4: dotted dates
    assert path_date('v2026.03-01.csv') is None  # mixed separators: not a date
    assert path_date('2026-13-45.csv') is None


def test_resume_is_done_by_stat_then_by_content_and_never_for_other_options(tmp_path):
    data = _csv(tmp_path / 'r.csv')
    out = tmp_path / 'out'
    from satmotor_ros.fleet.resume import content_of
    key = options_key({'calibrate': False})
    write_done(out, {'options': key, 'stat': stat_of(data), 'content': content_of(data)})
    assert is_done(out, data, key) is not None
    os.utime(data, (EPOCH, EPOCH))  # touched: same content
    assert is_done(out, data, key) is not None
    assert is_done(out, data, options_key({'calibrate': True})) is None
    data.write_text(HEADER + '0,1000,21,10,1\n')
    assert is_done(out, data, key) is None
    assert not list(out.glob('*.partial-*'))


def test_a_recording_whose_output_was_deleted_is_not_done(tmp_path):
    """The done-marker lists the outputs: one deleted since, the recording is redone."""
    data = _csv(tmp_path / 'r.csv')
    out = tmp_path / 'out'
    (out / 'health').mkdir(parents=True)
    (out / 'health' / 'health.json').write_text('{}')
    key = options_key({'calibrate': False})
    write_done(out, {'options': key, 'stat': stat_of(data)})
    assert is_done(out, data, key) is not None
    (out / 'health' / 'health.json').unlink()
    assert is_done(out, data, key) is None


def test_a_rerun_on_other_options_leaves_no_earlier_output_behind(tmp_path):
    """
    F6: validate/ of a run with --validate is gone after one without, and not listed.

    A directory of the user's, or one of ours the user wrote into, is kept (not the tool's).
    """
    from satmotor_ros.fleet.resume import read_done
    from satmotor_ros.fleet.synthetic import write_recording
    from satmotor_ros.fleet.tasks import process_recording, RunOptions
    from satmotor_ros.model.io.config import default_config_path
    write_recording(tmp_path / 'root' / 'm1' / 'd00.csv', 1.2, 1, 30, EPOCH)
    motor = discover(tmp_path / 'root', FleetConfig())[0]
    rec = motor.recordings[0]
    baseline = {'recording': None, 'coefficients': str(default_config_path('sm075_25.yaml')),
                'liquid': 'water', 'key': 'b'}
    out = tmp_path / 'out' / 'm1' / rec.name
    (out / 'mine').mkdir(parents=True)
    (out / 'mine' / 'notes.txt').write_text('keep')

    def run(validate):
        marker = process_recording(rec, motor.rule, baseline,
                                   RunOptions(str(tmp_path / 'out'), validate=validate,
                                              liquid='water'))
        assert marker['status'] == 'done', marker['reason']
        return {o.split('/')[0] for o in read_done(out)['outputs']}

    assert run(True) == {'health', 'validate'}
    assert run(False) == {'health'} and not (out / 'validate').exists()
    assert run(True) == {'health', 'validate'}
    (out / 'validate' / 'extra.txt').write_text('the user wrote into it: theirs now')
    assert run(False) == {'health'} and (out / 'validate' / 'extra.txt').is_file()
    assert (out / 'mine' / 'notes.txt').read_text() == 'keep'


def test_toggling_validate_redoes_validate_only(tmp_path, monkeypatch):
    """
    Cold review of issue 24 (finding 7): toggling --validate redid every output.

    Each output has its own key: calibrate/ and health/ are kept when theirs are the same
    (calibrate is not run again), validate/ is written, and dropped again without it; the
    motor's monitor steps do not depend on it.
    """
    import satmotor_ros.cli.calibrate as calibrate_cli
    from satmotor_ros.fleet.chain import monitor_step
    from satmotor_ros.fleet.engine import plan
    from satmotor_ros.fleet.resume import read_done
    from satmotor_ros.fleet.synthetic import write_recording
    from satmotor_ros.fleet.tasks import given_baseline, process_recording, RunOptions
    from satmotor_ros.model.io.config import default_config_path
    root, out = tmp_path / 'root', tmp_path / 'out'
    write_recording(root / 'm1' / 'd00.csv', 1.2, 1, 20, EPOCH)
    (root / 'fleet.yaml').write_text(
        f"motors: [{{pattern: 'm1/**', motor: m1, liquid: water, "
        f"motor_file: '{default_config_path('sm075_25.yaml')}'}}]\n")
    (motor,) = discover(root, load_fleet(root / 'fleet.yaml'))
    (rec,) = motor.recordings
    first = RunOptions(str(out), calibrate=True)
    baseline = given_baseline(motor, first)
    done = process_recording(rec, motor.rule, baseline, first)
    monitor_step(rec, motor.rule, baseline, first, None)
    here = out / 'm1' / rec.name
    stamps = {p: p.stat().st_mtime_ns for p in here.rglob('*') if p.is_file()
              and p.parts[len(here.parts)] in ('calibrate', 'health', 'monitor')}
    assert any('calibrate' in p.parts for p in stamps) and done['status'] == 'done'

    def not_again(*args, **kwargs):
        raise AssertionError('calibrate run again')

    monkeypatch.setattr(calibrate_cli, 'calibrate_into', not_again)
    for validate in (True, False):
        run = RunOptions(str(out), calibrate=True, validate=validate)
        assert plan([motor], run).todo == [rec] and not plan([motor], run).chain_from
        marker = process_recording(rec, motor.rule, baseline, run)
        assert marker['status'] == 'done', marker['reason']
        assert marker['result'] == done['result']
        assert {o.split('/')[0] for o in read_done(here)['outputs']} == \
            {'calibrate', 'health', *(['validate'] if validate else [])}
        assert (here / 'validate').is_dir() == validate
        assert {p: p.stat().st_mtime_ns for p in stamps} == stamps  # kept as they were


def test_a_report_drops_the_plots_of_motors_it_no_longer_has(tmp_path):
    """F6: a motor gone (renamed, removed) since the last report leaves no plot behind."""
    from satmotor_ros.fleet.report import write_report
    header = {'root': 'r', 'written': 'w', 'recordings': 1, 'refused': 0, 'ran': 1,
              'reused': 0, 'estimator': 'e', 'limit': 2.0}
    views = [motor_view(m, 'water', [], None) for m in ('a', 'b')]
    write_report(tmp_path, views, header)
    (tmp_path / 'plots' / 'c.png').write_bytes(b'never in a report: not ours')
    write_report(tmp_path, views[1:], header)
    assert sorted(p.name for p in (tmp_path / 'plots').iterdir()) == ['b.png', 'c.png',
                                                                      'fleet.png']


def test_a_touched_recording_is_hashed_once_and_a_motor_file_once_per_run(
        tmp_path, monkeypatch):
    """
    F9: a touched recording (same content) is hashed by the first rerun only.

    Its hash is kept by its new stat in DIR; a motor's file is hashed once a run, not once a
    recording.
    """
    from satmotor_ros.fleet import resume, tasks
    from satmotor_ros.fleet.engine import plan
    from satmotor_ros.model.io.config import default_config_path
    root = tmp_path / 'root'
    for day in range(3):
        _csv(root / 'm1' / f'r{day}.csv', EPOCH + day * DAY)
    motor_file = str(default_config_path('sm075_25.yaml'))
    (root / 'fleet.yaml').write_text('motors: [{pattern: "m1/**", motor: m1, liquid: water, '
                                     f'motor_file: {motor_file}}}]\n')
    motors = discover(root, load_fleet(root / 'fleet.yaml'))
    run = tasks.RunOptions(str(tmp_path / 'out'))
    key = options_key(tasks.recording_options(motors[0].rule, run,
                                              tasks.given_baseline(motors[0], run)['key']))
    for rec in motors[0].recordings:
        write_done(tmp_path / 'out' / 'm1' / rec.name, {'options': key, **tasks.input_of(rec)})
    calls = []
    real = resume.content_of
    for module in (resume, tasks):
        monkeypatch.setattr(module, 'content_of', lambda p: calls.append(str(p)) or real(p))

    def hashed():
        calls.clear()
        assert len(plan(motors, run).done) == 3
        assert calls.count(motor_file) <= 1
        return [c for c in calls if c != motor_file]

    assert hashed() == []  # the stat says it: no data read
    os.utime(motors[0].recordings[0].path, (EPOCH, EPOCH))  # touched: same content
    assert hashed() == [motors[0].recordings[0].path]
    assert hashed() == []
    cache = resume.HashCache(tmp_path / 'out')  # a baseline, a step, a marker check one file
    os.utime(motors[0].recordings[1].path, (EPOCH, EPOCH))
    calls.clear()
    assert cache.content(motors[0].recordings[1].path) == cache.content(
        motors[0].recordings[1].path) and calls == [motors[0].recordings[1].path]


def _markers(values, start=EPOCH, half=0.003):
    return [{'status': 'done', 'recording': f'r{i}.csv', 'date': f'd{i:02d}',
             'time': start + i * DAY, 'time_source': TIME_COLUMN,
             'result': {'leakage_factor': v, 'ci95': [v - half, v + half], 'alarms': []}}
            for i, v in enumerate(values)]


def test_wear_gives_a_trend_and_days_to_limit_but_no_change_alarm():
    rng = np.random.default_rng(1)
    values = 1.0 + 0.05 * np.arange(10) + rng.normal(0, 0.002, 10)
    view = motor_view('w', 'water', _markers(values), None, limit=2.0)
    assert view['alarms'] == []
    assert view['trend_per_day'] == pytest.approx(0.05, rel=0.05)
    assert view['days_to_limit'] == pytest.approx((2.0 - 1.45) / 0.05, rel=0.1)


@pytest.mark.parametrize('n', range(3, 11))
def test_a_steady_wear_of_3_to_10_recordings_is_a_trend_not_changes(n):
    """
    F5: wear of 0.12 a day (past MIN_STEP each day) is a trend, not changes.

    Three recordings read as two change alarms when a lone other step was taken for no wear.
    """
    rng = np.random.default_rng(n)
    values = 1.0 + 0.12 * np.arange(n) + rng.normal(0, 0.002, n)
    view = motor_view('w', 'water', _markers(values), None, limit=3.0)
    assert view['alarms'] == []
    assert view['trend_per_day'] == pytest.approx(0.12, rel=0.1)


@pytest.mark.parametrize(('values', 'at'), [([1.0, 1.001, 1.6], 'r2.csv'),
                                            ([1.0, 1.6, 1.601], 'r1.csv'),
                                            ([1.5, 1.52, 1.0], 'r2.csv')])
def test_three_recordings_with_a_step_are_one_change_at_the_step(values, at):
    view = motor_view('s', 'water', _markers(values), None, limit=2.0)
    assert [(a['kind'], a['recording']) for a in view['alarms']] == [('change', at)]


def test_a_slope_three_recordings_cannot_tell_from_noise_gives_no_date():
    """Three recordings, slope 5 standard errors up: with one degree of freedom that is noise."""
    view = motor_view('h', 'water', _markers([1.0, 1.01, 1.03]), None, limit=2.0)
    assert view['trend_per_day'] == pytest.approx(0.015)
    assert view['days_to_limit'] is None


def test_the_doc_gives_the_student_bound_the_days_to_the_limit_need():
    """doc/fleet.md says the t-bound ``summary._trend`` uses (it said 2 standard errors)."""
    from pathlib import Path
    from scipy.stats import t as student
    text = ' '.join((Path(__file__).resolve().parents[1] / 'doc' / 'fleet.md').read_text(
        encoding='utf-8').split())
    assert 'by two standard errors' not in text
    assert (f'{student.ppf(0.975, 1):.1f} of them with three recordings, '
            f'{student.ppf(0.975, 8):.1f} with ten') in text
    rng = np.random.default_rng(9)  # ten recordings, slope 2.19 standard errors: below 2.31
    values = 1.0 + 0.0004 * np.arange(10) + rng.normal(0, 0.002, 10)
    view = motor_view('t', 'water', _markers(values), None, limit=2.0)
    assert view['trend_per_day'] > 0 and view['days_to_limit'] is None


def test_a_step_is_one_change_alarm_and_the_trend_restarts_after_it():
    rng = np.random.default_rng(2)
    values = np.r_[np.ones(5), 1.5 * np.ones(5)] + rng.normal(0, 0.002, 10)
    view = motor_view('s', 'water', _markers(values), None, limit=2.0)
    assert [(a['kind'], a['recording']) for a in view['alarms']] == [('change', 'r5.csv')]
    assert '+50 %' in view['alarms'][0]['what']
    assert view['days_to_limit'] is None  # flat since the step
    crossed = motor_view('x', 'water', _markers([1.0, 1.5, 2.05]), None, limit=2.0)
    assert crossed['days_to_limit'] == 0.0
    assert [a['kind'] for a in crossed['alarms']] == ['limit']  # 0.5 then 0.55 a day: wear


def test_ranking_is_soonest_to_the_limit_first():
    views = [motor_view('flat', '', _markers([1.0, 1.0, 1.001, 1.0]), None),
             motor_view('slow', '', _markers(1.0 + 0.01 * np.arange(5)), None),
             motor_view('fast', '', _markers(1.0 + 0.1 * np.arange(5)), None),
             motor_view('none', '', [], None)]
    assert [v['motor'] for v in rank(views)] == ['fast', 'slow', 'flat', 'none']


def test_ranking_puts_a_motor_near_its_limit_after_a_step_ahead_of_a_slow_drift():
    """A leak to 1.95 (limit 2) two days ago has no trend yet: still ranked first."""
    rng = np.random.default_rng(3)
    leak = np.r_[np.ones(8), 1.95, 1.95] + rng.normal(0, 0.002, 10)
    views = [motor_view('slow', '', _markers(1.0 + 0.0004 * np.arange(10)), None, limit=2.0),
             motor_view('leak', '', _markers(leak), None, limit=2.0)]
    assert views[1]['days_to_limit'] is None
    assert [v['motor'] for v in rank(views)] == ['leak', 'slow']


def test_ranking_counts_days_from_the_fleets_latest_recording():
    """A motor last seen 120 days ago reaches its limit before one seen today, same drift."""
    old = motor_view('old', '', _markers(1.0 + 0.01 * np.arange(5)), None, limit=2.0)
    new = motor_view('new', '', _markers(1.0 + 0.01 * np.arange(5), EPOCH + 120 * DAY), None,
                     limit=2.0)
    assert old['days_to_limit'] == pytest.approx(new['days_to_limit'])  # the same drift
    assert [v['motor'] for v in rank([new, old])] == ['old', 'new']


def test_fleet_command_refuses_a_bad_fleet_yaml_and_an_out_it_did_not_write(tmp_path, capsys):
    _csv(tmp_path / 'root' / 'm1' / 'a.csv')
    bad = tmp_path / 'bad.yaml'
    bad.write_text('motors: [{pattern: "*", motor: m1, speed: 3}]')
    assert main(['fleet', str(tmp_path / 'root'), '--out', str(tmp_path / 'o'),
                 '--fleet', str(bad)]) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and "unknown key 'speed'" in err
    theirs = tmp_path / 'theirs'
    theirs.mkdir()
    (theirs / 'keep.txt').write_text('mine')
    assert main(['fleet', str(tmp_path / 'root'), '--out', str(theirs)]) == 1
    assert 'not an earlier output of satmotor fleet' in capsys.readouterr().err
    assert main(['fleet', str(tmp_path / 'nothing'), '--out', str(tmp_path / 'o')]) == 1
    assert 'not a directory' in capsys.readouterr().err


def test_force_never_replaces_a_report_file_a_fleet_run_did_not_write(tmp_path, capsys):
    """Cold review F9 of issue 24: --force replaced the user's own fleet.md."""
    import json
    from satmotor_ros.fleet.report import not_ours, write_report
    _csv(tmp_path / 'root' / 'm1' / 'a.csv')
    theirs = tmp_path / 'theirs'
    theirs.mkdir()
    (theirs / 'fleet.md').write_text('my notes\n')
    assert main(['fleet', str(tmp_path / 'root'), '--out', str(theirs), '--force']) == 1
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and 'fleet.md not written by satmotor fleet' in err
    assert (theirs / 'fleet.md').read_text() == 'my notes\n'
    ours = tmp_path / 'ours'  # what a run wrote is ours; an edit, or a user's plot, is not
    ours.mkdir()
    header = {'root': 'r', 'recordings': 0, 'refused': 0, 'ran': 0, 'reused': 0,
              'written': 'now', 'estimator': 'e', 'limit': 2.0}
    write_report(ours, [], header)
    assert not_ours(ours, ['m1']) == []
    (ours / 'plots' / 'm1.png').write_bytes(b'\x89PNG mine')
    (ours / 'fleet.md').write_text('edited\n')
    assert not_ours(ours, ['m1']) == ['fleet.md', 'plots/m1.png']
    (ours / '.satmotor-output.json').write_text(json.dumps({'command': 'fleet'}))
    assert not_ours(ours, []) == []  # a marker from before the digests: taken at its word


@pytest.mark.slow
def test_a_bag_recording_is_timed_by_its_start_and_watched_by_the_health_monitor(tmp_path):
    from satmotor_ros.fleet.synthetic import make_fleet
    from satmotor_ros.fleet.chain import monitor_step
    from satmotor_ros.fleet.tasks import calibrate_baseline, process_recording, RunOptions
    import json
    root = make_fleet(tmp_path / 'root', days=2, points=20, bags=True, motors=())
    (motor,) = discover(root, FleetConfig())
    assert motor.motor == 'bagged' and [r.kind for r in motor.recordings] == ['bag', 'bag']
    assert [r.time_source for r in motor.recordings] == [BAG_START, BAG_START]
    assert motor.recordings[0].date.startswith('2026-03-01T08:00')
    run = RunOptions(str(tmp_path / 'out'))  # the bags record their liquid
    baseline = calibrate_baseline(motor, run)
    assert baseline['recording'] == 'bagged/b00' and baseline['liquid'] == 'water'
    marker = process_recording(motor.recordings[1], motor.rule, baseline, run)
    assert marker['status'] == 'done', marker
    assert marker['result']['leakage_factor'] == pytest.approx(1.0, abs=0.02)
    step = monitor_step(motor.recordings[1], motor.rule, baseline, run, None)
    assert step['status'] == 'done' and step['result']['n_samples'] > 1000
    monitor = tmp_path / 'out' / 'bagged' / 'b01' / 'monitor'  # as `satmotor monitor` writes
    assert json.loads((monitor / '.satmotor-output.json').read_text())['command'] == 'monitor'
    assert json.loads((monitor / 'monitor.json').read_text())['n_samples'] > 1000


def test_one_monitor_runs_through_the_motors_recordings_in_time_order(tmp_path):
    from satmotor_ros.fleet.chain import monitor_step, valid_steps
    from satmotor_ros.fleet.tasks import RunOptions
    from satmotor_ros.identify.health.report import FILES
    from satmotor_ros.model.io.config import default_config_path
    for day in range(2):  # 10 min each: one alone never leaves learn_hours (0.25 h)
        series_csv(tmp_path / 'root' / 'm1' / f'r{day}.csv', day, EPOCH + day * 660.0)
    motor = discover(tmp_path / 'root', FleetConfig())[0]
    run = RunOptions(str(tmp_path / 'out'), liquid='water')
    baseline = {'coefficients': str(default_config_path('sm075_25.yaml')), 'liquid': 'water',
                'key': 'b'}
    rule = motor.rule
    steps = [monitor_step(motor.recordings[0], rule, baseline, run, None)]
    steps.append(monitor_step(motor.recordings[1], rule, baseline, run, steps[0]))
    assert [s['status'] for s in steps] == ['done', 'done']
    assert [s['result']['learning'] for s in steps] == [True, False]  # the same monitor
    assert [(s['result']['recording_samples'], s['result']['n_samples']) for s in steps] == \
        [(3000, 3000), (3000, 6000)]  # its own samples, and the monitor's since its first
    assert steps[1]['prev'] == steps[0]['chain']
    for rec in motor.recordings:  # what `satmotor monitor` writes, per recording
        assert {p.name for p in (tmp_path / 'out' / 'm1' / rec.name / 'monitor').iterdir()} \
            >= set(FILES)
    assert valid_steps(motor, run, 'b') == steps
    with open(motor.recordings[0].path, 'a') as file:  # a changed first: the chain redone
        file.write(f'{EPOCH + 601},1000,20,10,1\n')
    assert valid_steps(motor, run, 'b') == []


def _monitor_chain(tmp_path):
    """Run the fleet's monitor chain over tmp_path/root's motor: (the motor, its steps)."""
    from satmotor_ros.fleet.chain import monitor_step
    from satmotor_ros.fleet.tasks import RunOptions
    from satmotor_ros.model.io.config import default_config_path
    motor = discover(tmp_path / 'root', FleetConfig())[0]
    run = RunOptions(str(tmp_path / 'out'), liquid='water')
    baseline = {'coefficients': str(default_config_path('sm075_25.yaml')), 'liquid': 'water',
                'key': 'b'}
    steps = []
    for rec in motor.recordings:
        steps.append(monitor_step(rec, motor.rule, baseline, run, steps[-1] if steps else None))
    return motor, steps


def test_the_monitors_trend_per_operating_hour_is_made_per_calendar_day(tmp_path):
    """
    Cold review F3 of issue 24: the trend per day was 24 x the trend per OPERATING hour.

    Four 20-minute series at 1 Hz, 2 h apart (a healthy motor: a wear's steps between them,
    against the detector's low noise, are changes that restart the trend): the monitor
    operates 1.3 of the 6.3 h its clock spans; a calendar day holds 24 x that share of
    operating hours.
    """
    for i in range(4):
        series_csv(tmp_path / 'root' / 'm1' / f'r{i}.csv', 50 + i, EPOCH + i * 7200.0,
                   duration_s=1200.0, samples=1200, rate=1.0)
    _, steps = _monitor_chain(tmp_path)
    last = steps[-1]['result']
    share = last['operating_hours'] / last['recording_hours']
    assert last['trend_per_hour'] is not None and last['trend_per_hour'] != 0
    assert 0.1 < share < 0.3  # 1.3 h of operation over 6.3 h
    view = motor_view('m1', 'water', [], None, steps=steps)
    assert view['trend_clock'] == MONITOR_EPOCH
    assert view['trend_per_day'] == pytest.approx(24.0 * last['trend_per_hour'] * share)


def test_a_monitored_motors_view_is_the_monitors_figures_and_named_alarms():
    """On an epoch clock (calendar time) the monitor's own trend is the motor's."""
    steps = [{'recording': f'r{i}.csv', 'status': 'done', 'result': {
        'leakage_factor': {'value': v, 'ci95': [v - 0.01, v + 0.01]}, 'learning': False,
        'trend_per_hour': 0.05, 'trend_per_day': 0.24, 'hours_to_limit': 48.0,
        'recording_samples': 451, 'recording_skipped': 0,
        'span_s': [EPOCH + i * 100.0, EPOCH + i * 100.0 + 90],
        'alarms': [{'time_s': 150.0, 'kind': 'change', 'what': 'wear: leakage x1.3'}]
        if i else []}} for i, v in enumerate((1.0, 1.3))]
    markers = _markers([1.0, 1.0])
    view = motor_view('m', 'water', markers, None, steps=steps)
    assert [p['value'] for p in view['leakage_factor']] == [1.0, 1.3]
    assert {p['estimator'] for p in view['leakage_factor']} == {'monitor'}
    assert view['trend_per_day'] == pytest.approx(0.24) and view['days_to_limit'] == 2.0
    assert [(a['kind'], a['recording']) for a in view['alarms']] == [('change', 'r1.csv')]
    assert view['alarms'][0]['what'].startswith('wear: leakage x1.3')
    assert view['trend_clock'] == MONITOR_EPOCH


def test_a_change_the_monitor_has_not_named_yet_says_what_it_waits_for():
    """Cold review of issue 24 (finding 9): fleet.md said 'pending', and not what was."""
    from satmotor_ros.identify.health import HealthSettings
    from satmotor_ros.identify.health.monitor import PENDING
    steps = [{'recording': f'r{i}.csv', 'status': 'done', 'result': {
        'leakage_factor': {'value': v, 'ci95': [v - 0.01, v + 0.01]}, 'learning': False,
        'trend_per_hour': None, 'trend_per_day': None, 'hours_to_limit': None,
        'recording_samples': 451, 'recording_skipped': 0,
        'span_s': [EPOCH + i * 100.0, EPOCH + i * 100.0 + 90],
        'alarms': [{'time_s': 150.0, 'kind': 'change', 'what': PENDING}] if i else []}}
        for i, v in enumerate((1.0, 1.3))]
    view = motor_view('m', 'water', _markers([1.0, 1.3]), None, steps=steps)
    (alarm,) = view['alarms']
    assert alarm['what'] == ('not named yet by the monitor: it names a change once it has '
                             f'learned {HealthSettings().learn_hours:g} h of operation after '
                             'it, and the recordings since hold less (in r1.csv)')


def test_an_empty_csv_is_refused_in_one_clear_line(tmp_path):
    """Cold review of issue 24 (finding 9): a 0-byte CSV read 'truncated mid-row: ... empty'."""
    from satmotor_ros.fleet.tasks import EMPTY, load_screened, motor_options, Refused, RunOptions
    (tmp_path / 'root' / 'm').mkdir(parents=True)
    (tmp_path / 'root' / 'm' / 'a.csv').write_bytes(b'')
    (motor,) = discover(tmp_path / 'root', FleetConfig())
    with pytest.raises(Refused) as err:
        load_screened(motor.recordings[0], motor_options(motor.rule, RunOptions(
            str(tmp_path / 'out'), liquid='water')), '')
    assert str(err.value) == EMPTY


def test_a_recording_timed_by_its_mtime_among_timed_ones_is_kept_off_the_time_line():
    """
    Cold review of issue 24 (finding 4): an mtime-dated recording took over the time line.

    Copied today among recordings of March, it was the motor's latest, its factor bent the
    trend and the ranking. It is listed apart (its factor, said why in fleet.md); a motor
    whose recordings all have only their mtime keeps them on its line.
    """
    from satmotor_ros.fleet.report import markdown
    markers = _markers([1.0, 1.06, 1.12, 1.18, 1.24])
    copied = {**_markers([1.0], start=EPOCH + 200 * DAY)[0], 'recording': 'copy.csv',
              'time_source': MTIME}
    view = motor_view('m', 'water', [*markers, copied], None)
    assert view['trend_per_day'] == pytest.approx(0.06)
    assert view['last_time'] == markers[-1]['time'] and view['recordings'] == 6
    assert [p['recording'] for p in view['leakage_factor']] == [m['recording'] for m in markers]
    assert [u['recording'] for u in view['undated']] == ['copy.csv']
    text = ' '.join(markdown([view], {'root': '/r', 'recordings': 6, 'refused': 0, 'ran': 6,
                                      'reused': 0, 'written': '', 'estimator': 'x',
                                      'limit': 2.0, 'cluster': '', 'fleet_file': ''}).split())
    assert "only their file's modification time" in text and '`copy.csv`' in text
    alone = [{**m, 'time_source': MTIME} for m in markers]  # all alike: one time line
    view = motor_view('m', 'water', alone, None)
    assert not view['undated'] and len(view['leakage_factor']) == 5


def test_without_a_baseline_the_damaged_keep_their_reason_and_the_sound_say_why(tmp_path):
    from satmotor_ros.fleet.synthetic import make_fleet
    from satmotor_ros.fleet.tasks import calibrate_baseline, process_recording, RunOptions
    from satmotor_ros.fleet.tasks import NO_LIQUID, ZERO_PRESSURE
    root = make_fleet(tmp_path / 'root', days=5, points=20, motors=('patchy',))
    (motor,) = discover(root, load_fleet(root / 'fleet.yaml'))
    run = RunOptions(str(tmp_path / 'out'))  # no liquid anywhere: no baseline
    baseline = calibrate_baseline(motor, run)
    assert baseline['reason'] == f'no baseline: tug_d/d00.csv was tried first and {NO_LIQUID}'
    reasons = {rec.relative: process_recording(rec, motor.rule, baseline, run)['reason']
               for rec in motor.recordings}
    assert 'truncated mid-row' in reasons.pop('tug_d/d02.csv')
    assert reasons.pop('tug_d/d04.csv') == ZERO_PRESSURE
    assert 'UTF-8' in reasons.pop('tug_d/d99_garbage.csv')
    assert set(reasons.values()) == {baseline['reason']}
    from satmotor_ros.fleet.engine import plan
    work = plan([motor], run)  # a rerun: the no-baseline is kept, nothing of it redone
    assert work.baselines[motor.motor]['reason'] == baseline['reason'] and work.todo == []
    assert plan([motor], RunOptions(str(tmp_path / 'out'), liquid='water')).todo  # new options
    with open(motor.recordings[-1].path, 'a') as file:
        file.write('1\n')
    assert plan([motor], run).baselines == {}  # a recording changed: the baseline tried again


@pytest.mark.parametrize(('text', 'said'), [
    ('motors: [{pattern: "a/**", motor: m1, liquid: oil}, '
     '{pattern: "b/**", motor: m1, liquid: water}]',
     "motors[1].liquid = 'water': motors[0] gives motor 'm1' 'oil'"),
    ('motors: [{pattern: "a/**", motor: m1}, {pattern: "b/**", motor: m1, family: paszota}]',
     "motors[1].family = 'paszota'"),
    ('motors: [{pattern: "a/**", motor: m1, displacement: 1e308 m^3/rev}]',
     "motors[0]: displacement = '1e308 m^3/rev': outside"),
    ('motors: [{pattern: "a/**", motor: m1, motor_file: fleet.yaml}]',
     "motors[0]: motor_file = 'fleet.yaml'"),
])
def test_fleet_yaml_contradictions_are_refused_at_load_in_one_line(tmp_path, text, said):
    path = tmp_path / 'fleet.yaml'
    path.write_text(text)
    with pytest.raises(FleetError) as err:
        load_fleet(path)
    assert said in str(err.value) and '\n' not in str(err.value)


def test_the_synthetic_fleet_program_says_one_line_and_replaces_only_its_own(tmp_path, capsys):
    from satmotor_ros.fleet.synthetic import main as synthetic
    root = tmp_path / 'fl'
    for argv, said in [([str(root), '--days'], '--days'), ([], 'ROOT'),
                       ([str(root), '--days', '0'], "--days: '0': need a whole number")]:
        assert synthetic(argv) == 1
        err = capsys.readouterr().err
        assert said in err and err.count('\n') == 1, err
    (tmp_path / 'a_file').write_text('mine')
    theirs = tmp_path / 'theirs'
    _csv(theirs / 'vessel_a' / 'day00.csv')
    for target in (tmp_path / 'a_file', theirs):
        assert synthetic([str(target), '--days', '1']) == 1
        err = capsys.readouterr().err
        assert str(target) in err and err.count('\n') == 1
    assert (tmp_path / 'a_file').read_text() == 'mine'
    assert (theirs / 'vessel_a' / 'day00.csv').read_text().startswith(HEADER)
    assert synthetic([str(root), '--days', '1']) == 0
    assert synthetic([str(root), '--days', '2']) == 0  # its own: replaced
    assert sorted(p.name for p in (root / 'vessel_a').iterdir()) == ['day00.csv', 'day01.csv']


def test_a_mapping_or_motor_file_edited_in_place_is_a_new_key(tmp_path):
    """A rerun redoes a motor whose column mapping or motor file changed, not only its path."""
    from satmotor_ros.fleet.config import MotorRule
    from satmotor_ros.fleet.tasks import baseline_rule_key, recording_options, RunOptions
    mapping, motor = tmp_path / 'cols.yaml', tmp_path / 'motor.yaml'
    mapping.write_text('columns: {p_a: {column: pa, unit: MPa}}\n')
    motor.write_text('name: m\n')
    rule = MotorRule('m/*', 'm', columns=str(mapping), motor_file=str(motor))
    run = RunOptions(out=str(tmp_path / 'out'))

    def keys():
        return (options_key(recording_options(rule, run, 'b')), baseline_rule_key(rule, run))

    before = keys()
    assert keys() == before
    mapping.write_text('columns: {p_a: {column: pa, unit: bar}}\n')
    after_mapping = keys()
    assert after_mapping[0] != before[0] and after_mapping[1] != before[1]
    motor.write_text('name: m2\n')
    assert keys()[0] != after_mapping[0]


def test_a_monitor_alarm_on_an_epoch_clock_is_the_recordings_it_was_raised_in(tmp_path):
    """
    Cold review of issue 24 (finding 1): on epoch times every monitor alarm was dropped.

    The chain's alarm ``time_s`` is on the monitor's clock (from its first sample) and a
    step's ``span_s`` on the data's (epoch): compared as they were, the alarm fell before
    every span, was pinned to the learning recording and discarded. Two healthy days, then a
    leak x1.6: the change is the third recording's, as the real chain writes it.
    """
    for day in range(3):
        series_csv(tmp_path / 'root' / 'm1' / f'r{day}.csv', 101 + day, EPOCH + day * DAY,
                   factor=1.6 if day == 2 else 1.0)
    motor, steps = _monitor_chain(tmp_path)
    (alarm,) = steps[-1]['result']['alarms']
    assert alarm['kind'] == 'change' and alarm['time_s'] < 3 * DAY  # the monitor's clock
    markers = [{'status': 'done', 'recording': rec.relative, 'date': f'd{i}', 'time': rec.time,
                'time_source': rec.time_source, 'result': {'leakage_factor': v, 'ci95':
                                                           [v - 0.01, v + 0.01]}}
               for i, (rec, v) in enumerate(zip(motor.recordings, (1.0, 1.0, 1.6)))]
    view = motor_view('m1', 'water', markers, None, steps=steps)
    assert [(a['kind'], a['recording']) for a in view['alarms']] == [('change', 'm1/r2.csv')]


def _monitored(values, alarm_day):
    """Return one monitor's steps through daily 10-minute recordings, an alarm on a day."""
    return [{'recording': f'r{i}.csv', 'status': 'done', 'result': {
        'leakage_factor': {'value': v, 'ci95': [v - 0.03, v + 0.03]}, 'learning': False,
        'trend_per_hour': None, 'trend_per_day': None, 'hours_to_limit': None,
        'recording_samples': 3000, 'recording_skipped': 0,
        'span_s': [EPOCH + i * DAY, EPOCH + i * DAY + 600.0],
        'alarms': [{'time_s': alarm_day * DAY + 30.0, 'kind': 'change', 'what': 'wear'}]}}
        for i, v in enumerate(values)]


def test_a_monitor_without_a_trend_leaves_the_motor_the_calendar_line():
    """
    Cold review of issue 24 (finding 1): a monitor with no trend left the motor none.

    The monitor's own trend is None when each day's wear is a change to it; the motor then
    gets the line through the figures against the recordings' times, not "not drifting".
    """
    values = 1.0 + 0.06 * np.arange(8)
    view = motor_view('m', 'water', _markers(values), None, steps=_monitored(values, 3))
    assert view['trend_per_day'] == pytest.approx(0.06)
    assert view['days_to_limit'] == pytest.approx((2.0 - values[-1]) / 0.06)
    assert view['trend_clock'] != MONITOR_EPOCH


def test_a_monitor_change_alarm_is_the_motors_where_the_calendar_sees_a_step():
    """
    Cold review of issue 24: the monitor raised two change alarms on a steady wear.

    On its operating clock a day's wear between two recordings is a jump (it saw no time
    pass): its detector calls it a step. On the calendar it is the trend, so the fleet
    keeps a monitor's change alarm only where the calendar shows a step too: a leak's.
    """
    wear = 1.0 + 0.06 * np.arange(8)
    view = motor_view('m', 'water', _markers(wear), None, steps=_monitored(wear, 3))
    assert view['alarms'] == []  # the jump at r3 is the wear on the calendar
    leak = np.array([1.0] * 4 + [1.6] * 4)
    view = motor_view('m', 'water', _markers(leak), None, steps=_monitored(leak, 4))
    assert [(a['kind'], a['recording']) for a in view['alarms']] == [('change', 'r4.csv')]
    assert view['alarms'][0]['what'] == 'wear (in r4.csv)'  # the monitor's, not the ratios'


def test_a_bag_with_garbage_metadata_is_refused_whole_in_one_line(tmp_path):
    """
    Cold review of issue 24 (finding 3): a garbage metadata.yaml was a failed task.

    Reading the bag's liquid raised its BagError out of the task (worker tracebacks, and a
    failed task is redone by every rerun): it is a damaged recording, refused in one line.
    """
    from satmotor_ros.fleet.synthetic import make_fleet
    from satmotor_ros.fleet.tasks import (calibrate_baseline, load_screened, motor_options,
                                          Refused, RunOptions)
    root = make_fleet(tmp_path / 'root', days=1, points=20, bags=True, motors=())
    (bag,) = [p.parent for p in root.rglob('metadata.yaml')]
    (bag / 'metadata.yaml').write_text('garbage: [\n')
    (motor,) = discover(root, FleetConfig())
    (rec,) = motor.recordings
    for liquid in ('water', ''):
        run = RunOptions(str(tmp_path / 'out'), liquid=liquid)
        with pytest.raises(Refused, match='metadata.yaml: cannot read it') as err:
            load_screened(rec, motor_options(motor.rule, run), '')
        assert '\n' not in str(err.value)
        baseline = calibrate_baseline(motor, run)  # the first recording: refused, said
        assert baseline.get('recording') is None and 'metadata.yaml' in str(baseline), baseline


def test_a_motor_without_a_trend_says_why():
    """Cold review of issue 24 (finding 9): 'fewer than 3 recordings' on eight of them."""
    from satmotor_ros.fleet.report import trend_text
    points = [{'value': 1.0}] * 8
    assert 'since the last step' in trend_text({'trend_per_day': None,
                                                'leakage_factor': points})
    assert trend_text({'trend_per_day': None, 'leakage_factor': points[:2]}) == \
        'n/a (2 recording(s) with a figure, fewer than 3)'
    assert trend_text({'trend_per_day': 0.06, 'leakage_factor': points}) == '+0.0600'
