# SPDX-License-Identifier: Apache-2.0
"""``satmotor validate``: a calibration's own error on its data, a second log, whole outputs."""

from dataclasses import replace
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from satmotor_ros.cli import validate as validate_cli
from satmotor_ros.cli._output import MARKER
from satmotor_ros.identify import calibrate, Errors, write_csv
from satmotor_ros.identify.calibrated import Calibrated
from satmotor_ros.identify.output import write_yaml
from satmotor_ros.identify.pipeline import Options
from satmotor_ros.identify.synthetic import (generate, generate_transient, Injection, Plan,
                                             REALISTIC_DYNAMICS)
from satmotor_ros.model.units import LPM, MPA, RPM
from satmotor_ros.options import MotorOptions

ERROR_FIELDS = {'rmse_lpm', 'mean_abs_pct', 'max_abs_lpm'}


def _csv(path, table, drop=()):
    columns = {'time': ('s', table.channels['time']), 'speed': ('rpm', table.speed / RPM),
               'flow': ('l/min', table.flow / LPM), 'p_in': ('MPa', table.p_in / MPA),
               'p_out': ('bar', table.p_out / 1e5),
               'temperature': ('degC', table.channels['temperature']),
               'p_case': ('kPa', table.channels['p_case'] / 1e3)}
    write_csv(path, {k: v for k, v in columns.items() if k not in drop})
    return str(path)


def _validate(capsys, data, out, liquid, motor='', mode='auto'):
    code = validate_cli.command(data, str(out), mode, MotorOptions(liquid, str(motor)))
    stdout, stderr = capsys.readouterr()
    result = json.loads((out / 'validation.json').read_text()) if code == 0 else None
    return code, result, stdout, stderr


def _in_sample(cal):
    """Return the calibration's in-sample error of Q_vl, from its final fit."""
    fit = (cal.selection.chosen or cal.selection.baseline).fit
    return Errors.of(cal.parts.flow - fit.predict(cal.parts), cal.parts.loss)


CASES = [('water', 'external_leakage'), ('water', 'viscosity_temperature'),
         ('oil', 'flow_sensor_gain'), ('water', 'speed_sensor_gain')]


@pytest.fixture(scope='module', params=CASES, ids=[effect for _, effect in CASES])
def calibrated(request, tmp_path_factory):
    liquid, effect = request.param
    tmp = tmp_path_factory.mktemp(effect)
    injection = Injection.realistic(effect, 1.0, liquid)
    first = generate(Plan(liquid=liquid), injection, seed=11)
    second = generate(Plan(liquid=liquid), injection, seed=12)
    cal = calibrate(first, liquid)
    write_yaml(cal, tmp / 'coefficients.yaml')
    return (liquid, effect, cal, tmp, _csv(tmp / 'first.csv', first),
            _csv(tmp / 'second.csv', second))


def test_a_calibration_validated_on_its_own_data_gives_its_in_sample_error(calibrated, capsys):
    liquid, _, cal, tmp, first, _ = calibrated
    assert cal.chosen is not None  # the two sensor gains are a known near tie: either will do
    effect = cal.chosen.effect
    code, result, stdout, _ = _validate(capsys, first, tmp / 'own', liquid,
                                        tmp / 'coefficients.yaml')
    assert code == 0
    assert list(result)[:2] == ['n_points', 'error'] and set(result['error']) == ERROR_FIELDS
    assert result['n_points'] == len(cal.parts)
    assert [e['effect'] for e in result['effects']] == [effect]
    in_sample = _in_sample(cal)
    for name in ERROR_FIELDS:
        assert result['error'][name] == pytest.approx(getattr(in_sample, name), rel=1e-3)
    assert result['error']['rmse_lpm'] == pytest.approx(cal.error_after.rmse_lpm, rel=0.15)
    assert f'{result["error"]["rmse_lpm"]:.4g} l/min' in stdout and effect in stdout


def test_the_calibration_holds_on_a_second_log_and_the_packaged_motor_does_not(
        calibrated, capsys):
    liquid, _, cal, tmp, _, second = calibrated
    code, result, _, _ = _validate(capsys, second, tmp / 'second', liquid,
                                   tmp / 'coefficients.yaml')
    assert code == 0
    rmse = result['error']['rmse_lpm']
    assert rmse < 1.3 * cal.error_after.rmse_lpm
    code, packaged, stdout, _ = _validate(capsys, second, tmp / 'packaged', liquid)
    assert code == 0 and packaged['effects'] == [] and 'effects: none' in stdout
    assert packaged['error']['rmse_lpm'] > 2.0 * rmse, (packaged, rmse)
    assert packaged['error']['max_abs_lpm'] > result['error']['max_abs_lpm']


def test_report_and_plot_of_the_residual_against_each_channel(calibrated, capsys):
    liquid, _, _, tmp, _, second = calibrated
    out = tmp / 'plots'
    assert _validate(capsys, second, out, liquid, tmp / 'coefficients.yaml')[0] == 0
    assert sorted(os.listdir(out)) == [MARKER, 'report.md', 'residuals.png', 'validation.json']
    assert (out / 'residuals.png').read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    report = (out / 'report.md').read_text()
    assert '![residuals](residuals.png)' in report
    assert 'Q_vl = Q - q_t n' in report


def test_the_residual_is_measured_minus_predicted_on_the_rows_as_read(tmp_path, capsys):
    """A flowmeter reading 1 l/min high shows as +1 l/min at every point."""
    table = generate(Plan(liquid='oil'), Injection(), seed=3)
    clean = _csv(tmp_path / 'clean.csv', table)
    shifted = _csv(tmp_path / 'shifted.csv', type(table)(
        table.speed, table.flow + LPM, table.p_in, table.p_out, table.channels, table.units,
        table.source))
    _, base, _, _ = _validate(capsys, clean, tmp_path / 'a', 'oil', mode='points')
    _, high, _, _ = _validate(capsys, shifted, tmp_path / 'b', 'oil', mode='points')
    assert base['error']['rmse_lpm'] < 0.1
    assert high['error']['rmse_lpm'] == pytest.approx(1.0, abs=0.1)
    assert high['error']['max_abs_lpm'] > 0.9


@pytest.mark.slow
def test_a_recording_is_read_as_calibrate_reads_it(tmp_path, capsys):
    from satmotor_ros.identify.synthetic import generate_series, write_bag_of
    series = generate_series(Plan(liquid='oil'), Injection(), seed=2, samples=6000)
    write_bag_of(tmp_path / 'bag', series, 'mcap')
    code, result, _, stderr = _validate(capsys, str(tmp_path / 'bag'), tmp_path / 'out', 'oil')
    assert code == 0, stderr
    # every sample (the rows a calibration fits, the bins' means, are the second figure)
    assert result['error_over'] == {'what': 'samples', 'n': result['n_points']}
    assert 3 <= result['error_over_bins']['n'] < 6000 <= result['n_points'] + 60
    assert result['error']['rmse_lpm'] < 0.2
    code, samples, stdout, _ = _validate(capsys, str(tmp_path / 'bag'), tmp_path / 'rows',
                                         'oil', mode='points')
    assert code == 0 and samples['n_points'] > 1000
    assert 'nothing refitted' in stdout
    # every sample, a motor file without transient terms: the headline has none; the terms
    # fitted on the data validated are only a second figure, labelled in sample
    _, rows, stdout, _ = _validate(capsys, str(tmp_path / 'bag'), tmp_path / 'transient',
                                   'oil', mode='transient')
    assert 'nothing refitted (no transient terms' in stdout
    assert 'in sample, with the transient terms fitted on these data' in stdout
    assert rows['transient_terms']['applied'] == {}
    second = rows['error_transient_fitted_in_sample']['rmse_lpm']
    assert second <= rows['error']['rmse_lpm']
    assert 'In sample, not a validation' in (tmp_path / 'transient' / 'report.md').read_text()


@pytest.fixture(scope='module')
def transient_file(tmp_path_factory):
    """Calibrate on every sample of a recording with a bench's dynamics; give another day."""
    tmp = tmp_path_factory.mktemp('transient')

    def recording(seed):
        return generate_transient(Plan(liquid='oil'), Injection(), REALISTIC_DYNAMICS,
                                  seed=seed, duration_s=60.0)
    cal = calibrate(recording(3), 'oil', options=Options(mode='transient'))
    write_yaml(cal, tmp / 'coefficients.yaml')
    today = recording(4)
    data = _csv(tmp / 'today.csv', replace(today, channels={
        **today.channels, 'temperature': np.full(len(today), 40.0),
        'p_case': np.zeros(len(today))}))
    return tmp, cal, data


def _with_dynamics(source, target, dynamics):
    text = source.read_text().split('\ndynamics:')[0]
    lines = [f'  {name}: {value!r}' for name, value in (dynamics or {}).items()]
    target.write_text(text + ('\ndynamics:\n' + '\n'.join(lines) if dynamics else '') + '\n')
    return target


def test_validate_applies_the_calibrations_transient_terms_unchanged(
        transient_file, tmp_path, capsys):
    tmp, cal, data = transient_file
    fitted = {d['term']: d['coefficient'] for d in cal.summary()['dynamics']
              if 'coefficient' in d}
    assert Calibrated(tmp / 'coefficients.yaml').dynamics == fitted
    assert fitted['flow_lag'] == pytest.approx(REALISTIC_DYNAMICS.flow_lag, rel=0.2)
    runs = {}
    for name, dynamics in (('own', fitted), ('spoilt', {**fitted, 'flow_lag': 0.0}),
                           ('none', None)):
        motor = _with_dynamics(tmp / 'coefficients.yaml', tmp_path / f'{name}.yaml', dynamics)
        code, runs[name], stdout, stderr = _validate(capsys, data, tmp_path / name, 'oil',
                                                     motor, mode='transient')
        assert code == 0, stderr
    own, spoilt, none = runs['own'], runs['spoilt'], runs['none']
    assert own['transient_terms']['applied'] == fitted
    assert 'applied unchanged (out of sample)' in own['transient_terms']['error']
    # out of sample: the headline follows the file's terms; the in-sample figure does not
    assert own['error']['rmse_lpm'] < 0.8 * spoilt['error']['rmse_lpm']
    assert none['error']['rmse_lpm'] > 1.2 * own['error']['rmse_lpm']
    second = {name: run['error_transient_fitted_in_sample'] for name, run in runs.items()}
    assert second['own'] == second['spoilt'] == second['none']
    assert second['own']['rmse_lpm'] <= own['error']['rmse_lpm']
    assert 'no transient terms' in none['transient_terms']['error']
    assert "calibration's transient terms" in (tmp_path / 'own' / 'report.md').read_text()


def test_a_malformed_dynamics_block_is_refused_in_one_line(transient_file, tmp_path, capsys):
    tmp, _, data = transient_file
    motor = _with_dynamics(tmp / 'coefficients.yaml', tmp_path / 'bad.yaml', {'flow_lag': 'x'})
    code, _, stdout, stderr = _validate(capsys, data, tmp_path / 'out', 'oil', motor,
                                        mode='transient')
    assert code == 1 and stdout == '' and len(stderr.strip().splitlines()) == 1
    assert "dynamics.flow_lag = 'x'" in stderr


@pytest.fixture(scope='module')
def leak_file(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('leak')
    table = generate(Plan(liquid='water'),
                     Injection.realistic('external_leakage', 1.0, 'water'), seed=7)
    write_yaml(calibrate(table, 'water'), tmp / 'coefficients.yaml')
    return tmp, table


def test_the_line_says_how_many_samples_the_error_is_not_over(leak_file, tmp_path, capsys):
    tmp, table = leak_file
    p_in = table.p_in.copy()
    p_in[:30] = table.p_out[:30] + 0.05 * MPA  # less than the channels take: no prediction
    data = _csv(tmp_path / 'low.csv', replace(table, p_in=p_in))
    code, result, stdout, _ = _validate(capsys, data, tmp_path / 'v', 'water',
                                        tmp / 'coefficients.yaml')
    left_out = len(table) - result['n_points']
    assert code == 0 and left_out >= 25 and result['coverage']['samples_total'] == len(table)
    assert f'over {result["n_points"]} points' in stdout
    assert f'{left_out} of {len(table)} samples left out, the error is not over them' in stdout
    # those rows lie outside the calibrated envelope (a 0.05 MPa drop): counted with the rest
    beyond = result['outside_calibrated_envelope']
    assert beyond['of'] == len(table) and beyond['samples'] >= 30
    assert f'{beyond["samples"]} of {len(table)} samples' in stdout


@pytest.mark.parametrize('case, message', [
    ('missing', "DATA '{tmp}/nope.csv': no such file or directory"),
    ('liquid', "--liquid 'glycol': not a coefficient set"),
    ('columns', 'flow'),
    ('channel', 'p_case'),
    ('motor', 'nope.yaml'),
])
def test_bad_input_exits_1_with_one_line_and_writes_nothing(leak_file, tmp_path, capsys, case,
                                                            message):
    tmp, table = leak_file
    data, liquid, motor = _csv(tmp_path / 'data.csv', table), 'water', tmp / 'coefficients.yaml'
    if case == 'missing':
        data = str(tmp_path / 'nope.csv')
    elif case == 'liquid':
        liquid = 'glycol'
    elif case == 'columns':
        data = _csv(tmp_path / 'no_flow.csv', table, drop=('flow',))
    elif case == 'channel':
        data = _csv(tmp_path / 'no_case.csv', table, drop=('p_case',))
    else:
        motor = tmp_path / 'nope.yaml'
    code, _, stdout, stderr = _validate(capsys, data, tmp_path / 'out', liquid, motor)
    assert code == 1 and stdout == ''
    assert len(stderr.strip().splitlines()) == 1
    assert message.format(tmp=tmp_path) in stderr
    assert not (tmp_path / 'out').exists()


def test_outputs_appear_whole_or_not_at_all(leak_file, tmp_path, capsys, monkeypatch):
    tmp, table = leak_file
    data, out = _csv(tmp_path / 'data.csv', table), tmp_path / 'out'
    assert _validate(capsys, data, out, 'water', tmp / 'coefficients.yaml')[0] == 0
    before = {name: (out / name).read_bytes() for name in os.listdir(out)}

    def broken(val, path):
        path.write_bytes(b'half a png')
        raise OSError(28, 'No space left on device')

    from satmotor_ros.identify import validation_report
    monkeypatch.setattr(validation_report, '_plot_residuals', broken)
    code, _, _, stderr = _validate(capsys, data, out, 'water')
    assert code == 1 and 'No space left on device' in stderr
    assert {name: (out / name).read_bytes() for name in os.listdir(out)} == before


def test_satmotor_validate_runs_as_a_program(leak_file, tmp_path):
    tmp, table = leak_file
    data = _csv(tmp_path / 'data.csv', table)
    env = {**os.environ, 'PYTHONPATH': os.pathsep.join(sys.path)}
    proc = subprocess.run(
        [sys.executable, '-m', 'satmotor_ros.cli', 'validate', data, '--motor',
         str(tmp / 'coefficients.yaml'), '--liquid', 'water', '--out', str(tmp_path / 'out')],
        capture_output=True, text=True, env=env, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    result = json.loads((tmp_path / 'out' / 'validation.json').read_text())
    assert f'RMSE of Q_vl {result["error"]["rmse_lpm"]:.4g} l/min' in proc.stdout
    assert np.isfinite(result['error']['rmse_lpm']) and result['n_points'] == len(table)
