# SPDX-License-Identifier: Apache-2.0
"""The base fits the delay of the speed reading behind the flow reading (identify.delay)."""

import contextlib
from dataclasses import replace
from functools import lru_cache
import io
import json

import numpy as np
import pytest
from satmotor_ros.cli.main import main
from satmotor_ros.identify import delay, pipeline
from satmotor_ros.identify.calibrated import Calibrated
from satmotor_ros.identify.delay import fit_delay, shifted
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.pipeline import calibrate, Options, read_rows
from satmotor_ros.identify.semireal import (build_case, estimate_noise, F11_5, FlowLag,
                                            load_trajectory, realistic, write_mbari_log)
from satmotor_ros.identify.synthetic import first_order
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import MotorModel
from satmotor_ros.model.families.defaults import default_motor
from vendored_data import data_path
import yaml

STEPPED = '2021.07.26T10.51.44.exp'
SPAN = (230.0, 400.0)  # the high-load part of the log, where its valve acts [s]
DELAY = 0.35  # the speed reading's delay injected [s]
TOLERANCE = 0.05  # a fitted delay within this of the injected one [s]


@lru_cache(maxsize=None)
def _trajectory():
    return load_trajectory(data_path('real', 'mbari_pto', STEPPED))


def _case(effects=(), delay=0.0, seed=0, span=SPAN, bad_rows=0):
    whole = _trajectory()
    trajectory = whole.crop(*span, 2)
    case = build_case(trajectory, [realistic(k, trajectory) for k in effects]
                      if effects and isinstance(effects[0], str) else effects,
                      noise=estimate_noise(whole), seed=seed, bad_rows=bad_rows)
    if delay:  # the speed read `delay` late: n_read(t) = n(t - delay)
        case = replace(case, speed=np.interp(case.time - delay, case.time, case.speed))
    return case


def _delay_of(case):
    model = MotorModel.from_spec(default_motor(displacement=F11_5), 'oil')
    read = read_rows(model, case.as_table(), Options(mode='transient'))
    return fit_delay(read.samples, model)


# -- shifting the samples --------------------------------------------------------------------

def test_the_speed_is_read_later_within_each_stretch_and_the_unserved_ends_are_counted():
    time = np.concatenate((np.arange(0.0, 10.0, 0.1), np.arange(20.0, 25.0, 0.1)))
    speed = 3.0 * time + 1.0
    table = BenchTable(speed, np.ones_like(time), np.ones_like(time), np.zeros_like(time),
                       {'time': time, 'revolutions': 2.0 * time}, {'time': 's'}, 'x', True)
    later, lost = shifted(table, 0.25, 3.0)
    # 0.25 s later: the last 3 samples of each stretch (t > end - 0.25) have no speed to read
    assert lost == 6 and len(later) == time.size - 6
    assert later.channels['time'][-1] == pytest.approx(24.6)
    np.testing.assert_allclose(later.speed, 3.0 * (later.channels['time'] + 0.25) + 1.0)
    np.testing.assert_allclose(later.channels['revolutions'], 2.0 * (later.channels['time']
                                                                     + 0.25))
    assert any('+0.25 s later' in note and '6 samples' in note for note in later.notes)
    earlier, lost = shifted(table, -0.25, 3.0)  # read earlier: the first samples go
    assert lost == 6 and earlier.channels['time'][0] == pytest.approx(0.3)
    np.testing.assert_allclose(earlier.speed, 3.0 * (earlier.channels['time'] - 0.25) + 1.0)
    assert shifted(table, 0.0, 3.0) == (table, 0)


# -- the profile -----------------------------------------------------------------------------

def test_a_delayed_speed_reading_is_found_and_an_undelayed_one_kept_at_zero():
    found = _delay_of(_case(delay=DELAY))
    assert found.fitted and found.seconds == pytest.approx(DELAY, abs=TOLERANCE)
    assert found.ci95[0] < found.seconds < found.ci95[1]
    assert found.rmse_at_delay < 0.7 * found.rmse_at_zero and found.gain > found.limit
    early = _delay_of(_case(delay=-DELAY))  # a speed read early: the other sign
    assert early.fitted and early.seconds == pytest.approx(-DELAY, abs=TOLERANCE)
    clean = _delay_of(_case())
    assert not clean.fitted and clean.seconds == 0.0 and clean.gain <= clean.limit
    assert clean.note.startswith('speed delay kept at 0: the data do not pin it')


def test_a_first_order_flow_lag_is_left_to_the_lag_term_not_taken_as_a_delay():
    lagged = _delay_of(_case([FlowLag(0.15)]))
    assert not lagged.fitted and lagged.seconds == 0.0


def _profile(case):
    """Return the delay's profile on a case's rows, one scale for all (delay._Profile)."""
    model = MotorModel.from_spec(default_motor(displacement=F11_5), 'oil')
    samples = read_rows(model, case.as_table(), Options(mode='transient')).samples
    profile = delay._Profile(samples, model, 1.5, 3.0, lags=False)
    assert delay._scaled(profile, 0.0)
    return profile


def test_a_lag_is_applied_in_its_own_shape_and_found_beside_a_delay():
    # without noise the best lag is the injected one: a flow lag through the exact filter for
    # samples linear in between (a zero-order hold had found 0.12 s for 0.1), a speed lag by
    # the reading's exact inverse (the reading plus the lag times its rate)
    grid = 0.05 * np.arange(-30, 31)
    quiet = build_case(_trajectory().crop(*SPAN, 2), [FlowLag(0.1)], noise=None)
    assert delay._best_lag(_profile(quiet), grid) == pytest.approx(0.1, abs=0.006)
    step = float(np.median(np.diff(quiet.time)))
    clean = build_case(_trajectory().crop(*SPAN, 2), [], noise=None)
    slow = replace(clean, speed=first_order(clean.speed, step, 0.1))
    assert delay._best_lag(_profile(slow), grid) == pytest.approx(-0.1, abs=0.006)
    # the joint search finds the delay and the lag together, from the delay's least alone
    late = replace(quiet, speed=np.interp(quiet.time - DELAY, quiet.time, quiet.speed))
    both = delay._joint(_profile(late), [(0.25, 0.0), (0.0, 0.2)], 1.5, 0.05)
    assert both == pytest.approx((DELAY, 0.1), abs=0.01)


class _Fitted(Exception):
    """Stops `calibrate` once the delay is fitted."""


def _logged_delay_of(case, tmp_path, monkeypatch):
    """Fit the delay as `satmotor calibrate` does on the case written as an MBARI log."""
    found = []

    def fitted(*args):
        found.append(fit_delay(*args))
        raise _Fitted

    monkeypatch.setattr(pipeline, 'fit_delay', fitted)
    path = write_mbari_log(tmp_path / 'case.exp', case)
    with pytest.raises(_Fitted):
        main(['calibrate', str(path), '--columns', 'mbari_pto', '--liquid', 'oil',
              '--displacement', '0.30 in^3/rev', '--out', str(tmp_path / 'cal')])
    return found[0]


@pytest.mark.parametrize('seed', [100, 1100])
def test_a_flow_lag_under_the_real_noise_keeps_the_delay_at_zero(tmp_path, monkeypatch, seed):
    # the semi-real bench's 0.1 s flow lag on the stepped log (its seeds 0 and 1): a delay of
    # -0.11 s and -0.07 s had beaten the best lag (applied half a step early, on a grid, each
    # row weighed alike) and taken the lag's job; with the lag free beside it, weighed by
    # the rows' noise, the delay gains nothing
    lagged = _logged_delay_of(_case([FlowLag(0.1)], seed=seed, bad_rows=1), tmp_path,
                              monkeypatch)
    assert not lagged.fitted and lagged.seconds == 0.0
    assert lagged.gain > lagged.limit  # the profile alone asks for a delay: the lag's twin
    assert lagged.gain_over_lag <= lagged.limit
    assert 'a first-order lag of the flow reading' in lagged.note


def test_a_delay_beside_a_flow_lag_is_still_fitted(tmp_path, monkeypatch):
    both = _logged_delay_of(_case([FlowLag(0.1)], delay=DELAY, seed=100, bad_rows=1), tmp_path,
                            monkeypatch)
    # a pure delay is no first-order lag: the lag free beside it, it still gains far more
    assert both.fitted and both.gain_over_lag > 10.0 * both.limit
    assert DELAY - 0.15 < both.seconds < DELAY + TOLERANCE  # the lag's 0.1 s shares it


# -- the calibration and validation ----------------------------------------------------------

def _cli(args):
    errors = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(errors):
        code = main(args)
    assert code == 0, errors.getvalue()


@pytest.mark.slow
def test_the_loop_reads_the_speed_at_the_fitted_delay_finds_the_valve_and_validate_applies_it(
        tmp_path):
    case = _case(['relief'], delay=DELAY, seed=3)
    path = write_mbari_log(tmp_path / 'delayed.exp', case)
    out = tmp_path / 'cal'
    _cli(['calibrate', str(path), '--columns', 'mbari_pto', '--liquid', 'oil',
          '--displacement', '0.30 in^3/rev', '--out', str(out)])
    result = json.loads((out / 'calibration.json').read_text())
    delay = result['speed_delay']
    assert delay['fitted'] and delay['seconds'] == pytest.approx(DELAY, abs=TOLERANCE)
    assert delay['unit'] == 's' and delay['samples_unserved'] > 0
    assert [e['effect'] for e in result['effects']] == ['threshold:dp']
    assert result['effects'][0]['direction'] == 'negative'
    report = (out / 'report.md').read_text()
    assert '`speed_delay` = ' in report and 'speed delay fitted' in report
    # the motor file carries it; validate reads the speed as late, same rig, same sensors
    assert Calibrated(out / 'coefficients.yaml').speed_delay == pytest.approx(delay['seconds'])
    _cli(['validate', str(path), '--columns', 'mbari_pto', '--liquid', 'oil',
          '--motor', str(out / 'coefficients.yaml'), '--out', str(tmp_path / 'val')])
    val = json.loads((tmp_path / 'val' / 'validation.json').read_text())
    assert val['speed_delay']['seconds'] == pytest.approx(delay['seconds'])
    motor = yaml.safe_load((out / 'coefficients.yaml').read_text())
    del motor['speed_delay']
    (tmp_path / 'no_delay.yaml').write_text(yaml.safe_dump(motor), encoding='utf-8')
    _cli(['validate', str(path), '--columns', 'mbari_pto', '--liquid', 'oil',
          '--motor', str(tmp_path / 'no_delay.yaml'), '--out', str(tmp_path / 'val0')])
    unshifted = json.loads((tmp_path / 'val0' / 'validation.json').read_text())
    assert 'speed_delay' not in unshifted
    assert val['error']['rmse_lpm'] < 0.7 * unshifted['error']['rmse_lpm']


def test_steady_points_and_steady_windows_have_no_delay_to_fit():
    table = _case(span=(0.0, 1e9)).as_table()  # the whole log: its steady windows
    windows = calibrate(table, 'oil', default_motor(displacement=F11_5),
                        Options(mode='series', compare_families=False, max_effects=1))
    assert windows.delay is None and 'speed_delay' not in windows.summary()
    rows = np.arange(0, len(table), 400)
    points = BenchTable(table.speed[rows], table.flow[rows], table.p_in[rows],
                        table.p_out[rows], {}, {}, 'points')
    steady = calibrate(points, 'oil', default_motor(displacement=F11_5),
                       Options(compare_families=False, max_effects=1))
    assert steady.delay is None and 'speed_delay' not in steady.summary()


@pytest.mark.parametrize('value', ['0.3', None, float('nan'), True])
def test_a_malformed_speed_delay_in_a_motor_file_is_refused(tmp_path, value):
    path = tmp_path / 'm.yaml'
    path.write_text(json.dumps({'speed_delay': {'seconds': value}}), encoding='utf-8')
    with pytest.raises(DataError, match='speed_delay.seconds'):
        Calibrated(path).speed_delay
    path.write_text(json.dumps({'speed_delay': {'seconds': -0.25}}), encoding='utf-8')
    assert Calibrated(path).speed_delay == -0.25
    path.write_text(json.dumps({'dynamics': {}}), encoding='utf-8')
    assert Calibrated(path).speed_delay is None
