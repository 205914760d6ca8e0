# SPDX-License-Identifier: Apache-2.0
"""``satmotor calibrate``: exact JSON fields, a loadable YAML, real plots, one-line errors."""

from dataclasses import replace
import json

import numpy as np
import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import write_csv
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM

FIELDS = ['liquid', 'family', 'n_points', 'effect', 'name', 'direction',
          'regressor', 'coefficient', 'ci95', 'unit',
          'error_before', 'error_after', 'error_before_with_outliers',
          'error_after_with_outliers', 'error_over', 'coverage', 'effects', 'outliers',
          'missed_regions', 'candidates', 'family_comparison', 'mode', 'mode_reason']


def _csv(path, table, extra=()):
    columns = {'time': ('s', table.channels['time']), 'speed': ('rpm', table.speed / RPM),
               'flow': ('l/min', table.flow / LPM), 'p_in': ('MPa', table.p_in / MPA),
               'p_out': ('bar', table.p_out / 1e5),
               'temperature': ('degC', table.channels['temperature']),
               'p_case': ('kPa', table.channels['p_case'] / 1e3),
               'aux': ('V', table.channels['aux'])}
    for name in extra:
        columns[name] = ('-', np.linspace(0.0, 1.0, len(table)))
    write_csv(path, columns)
    return path


def _run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope='module')
def leak_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('leak')
    table = generate(Plan(liquid='water'), Injection.realistic('external_leakage', 1, 'water'),
                     seed=7)
    data = _csv(tmp / 'bench.csv', table)
    code = main(['calibrate', str(data), '--liquid', 'water', '--out', str(tmp / 'out')])
    return code, tmp / 'out', table


def test_calibrate_writes_json_with_exactly_the_design_fields(leak_run):
    code, out, _ = leak_run
    assert code == 0
    result = json.loads((out / 'calibration.json').read_text())
    assert list(result) == FIELDS
    assert result['effect'] == 'external_leakage'
    assert result['regressor'] == 'p_case'
    assert result['ci95'][0] <= 0.4 * LPM / MPA <= result['ci95'][1]
    assert set(result['error_before']) == {'rmse_lpm', 'mean_abs_pct', 'max_abs_lpm'}
    assert result['error_after']['rmse_lpm'] * 2 < result['error_before']['rmse_lpm']
    assert all(set(c) == {'effect', 'regressor', 'cv_rmse_lpm'} for c in result['candidates'])
    cv = [c['cv_rmse_lpm'] for c in result['candidates']]
    assert cv == sorted(cv)


def test_calibrated_yaml_loads_and_its_model_explains_the_data(leak_run):
    _, out, table = leak_run
    spec = load_motor(out / 'coefficients.yaml')
    model = MotorModel.from_spec(spec, 'water')
    assert model.coef.external_leakage > 0
    block = (out / 'coefficients.yaml').read_text()
    assert 'effects:' in block and 'regressor: p_case' in block
    packaged = MotorModel.default('water')
    p_case = table.channels['p_case']
    assert model.channels == ('p_case',)
    fitted = model.absorbency(table.speed, dp=table.dp, channels={'p_case': p_case}).flow
    before = packaged.absorbency(table.speed, dp=table.dp).flow
    rms = lambda x: float(np.sqrt(np.mean(x ** 2))) / LPM  # noqa: E731
    assert rms(table.flow - fitted) < 0.04
    assert rms(table.flow - before) > 2 * rms(table.flow - fitted)


def test_calibrated_yaml_names_its_data_without_the_machines_directories(leak_run):
    _, out, _ = leak_run
    head = (out / 'coefficients.yaml').read_text().splitlines()[0]
    assert 'calibrated on bench.csv (' in head and str(out.parent) not in head


def test_calibrate_report_has_real_plots(leak_run):
    _, out, _ = leak_run
    report = (out / 'report.md').read_text()
    for name in ('residuals.png', 'characteristics.png', 'ranking.png'):
        assert f'({name})' in report
        data = (out / name).read_bytes()
        assert data[:8] == b'\x89PNG\r\n\x1a\n' and len(data) > 10000
    assert 'external_leakage(p_case)' in report


def test_calibrate_clean_data_exits_zero_with_effect_none(tmp_path, capsys):
    table = generate(Plan(liquid='oil'), Injection(), seed=3)
    data = _csv(tmp_path / 'clean.csv', table, extra=('strain',))
    code, out, _ = _run(capsys, 'calibrate', data, '--liquid', 'oil', '--out', tmp_path / 'o')
    assert code == 0
    assert out.startswith('effect: none')
    result = json.loads((tmp_path / 'o' / 'calibration.json').read_text())
    assert result['effect'] == 'none' and result['coefficient'] is None
    assert any(c['effect'] == 'channel:strain' for c in result['candidates'])
    assert 'effects:' not in (tmp_path / 'o' / 'coefficients.yaml').read_text()


def test_calibrate_line_counts_the_rows_its_error_is_over_and_gives_it_with_outliers(
        tmp_path, capsys):
    table = generate(Plan(liquid='oil'), Injection(), seed=3)
    flow = table.flow.copy()
    flow[5] += 3.0 * LPM
    data = _csv(tmp_path / 'bad_row.csv', replace(table, flow=flow))
    code, out, _ = _run(capsys, 'calibrate', data, '--liquid', 'oil', '--out', tmp_path / 'o')
    result = json.loads((tmp_path / 'o' / 'calibration.json').read_text())
    n, left_out = result['n_points'], len(result['outliers'])
    assert code == 0 and left_out == 1
    # the first figure leaves the outlier out: the line counts the rows it is really over
    assert f'l/min over {n - left_out} of {n} points' in out
    with_them = (f'{result["error_before_with_outliers"]["rmse_lpm"]:.4g} -> '
                 f'{result["error_after_with_outliers"]["rmse_lpm"]:.4g} l/min')
    assert f'with them {with_them}' in out
    assert result['error_after_with_outliers']['rmse_lpm'] > 3 * result['error_after'][
        'rmse_lpm']


def test_calibrate_line_says_how_many_samples_the_error_is_not_over(tmp_path, capsys):
    table = generate(Plan(liquid='oil'), Injection(), seed=3)
    p_in = table.p_in.copy()
    p_in[:30] = table.p_out[:30] + 0.05 * MPA  # less than the channels take: no prediction
    data = _csv(tmp_path / 'low.csv', replace(table, p_in=p_in))
    code, out, _ = _run(capsys, 'calibrate', data, '--liquid', 'oil', '--out', tmp_path / 'o')
    coverage = json.loads((tmp_path / 'o' / 'calibration.json').read_text())['coverage']
    left_out = coverage['samples_total'] - coverage['samples_used']
    assert code == 0 and left_out >= 25 and coverage['samples_total'] == len(table)
    assert f'; {left_out} of {len(table)} samples left out, the error is not over them' in out


def test_calibrate_line_names_a_near_tie(tmp_path, capsys):
    table = generate(Plan(liquid='oil'), Injection.realistic('flow_sensor_gain'), seed=2)
    data = _csv(tmp_path / 'gain.csv', table)
    code, out, _ = _run(capsys, 'calibrate', data, '--liquid', 'oil', '--out', tmp_path / 'o')
    assert code == 0
    first, other = ('flow_sensor_gain', 'speed_sensor_gain')
    if out.startswith('effect: speed_sensor_gain'):
        first, other = other, first
    assert out.startswith(f'effect: {first}') and f'near tie with {other}' in out


@pytest.mark.parametrize(('text', 'match'), [
    ('speed [rpm],flow [l/min],p_in [MPa]\n1,2,3\n', "missing required column 'p_out'"),
    ('speed [rpm],flow [gal/h],p_in [MPa],p_out [MPa]\n1,2,3,4\n', "unknown flow unit 'gal/h'"),
    ('speed [rpm],flow [l/min],p_in [MPa],p_out [MPa]\n' + '600,20,10,1\n' * 20,
     'one speed only'),
    ('speed [rpm],flow [l/min],p_in [MPa],p_out [MPa]\n600,20,10,1\n700,22,12,1\n',
     'too few points'),
])
def test_calibrate_unusable_data_is_one_line_and_exit_1(tmp_path, capsys, text, match):
    data = tmp_path / 'bad.csv'
    data.write_text(text)
    code, out, err = _run(capsys, 'calibrate', data, '--liquid', 'oil', '--out', tmp_path / 'o')
    assert code == 1
    assert match in err
    assert err.count('\n') == 1 and err.startswith('satmotor: error: ')


def test_calibrate_unknown_liquid_is_one_line(tmp_path, capsys):
    data = _csv(tmp_path / 'b.csv', generate(Plan(), Injection(), seed=0))
    code, _, err = _run(capsys, 'calibrate', data, '--liquid', 'glycol', '--out',
                        tmp_path / 'out')
    assert code == 1 and "--liquid 'glycol'" in err


def test_calibrate_replaces_its_own_output_but_no_user_file_and_no_input(leak_run, tmp_path,
                                                                         capsys):
    _, out, _ = leak_run
    data = out.parent / 'bench.csv'
    before = (out / 'calibration.json').read_bytes()
    code, _, err = _run(capsys, 'calibrate', data, '--liquid', 'water', '--out', out)
    assert code == 0 and err == ''
    assert (out / 'calibration.json').read_bytes() == before  # deterministic rerun
    mine = tmp_path / 'mine'
    mine.mkdir()
    (mine / 'report.md').write_text('my notes')
    code, _, err = _run(capsys, 'calibrate', data, '--liquid', 'water', '--out', mine)
    assert code == 1 and len(err.strip().splitlines()) == 1 and '--force' in err
    assert sorted(p.name for p in mine.iterdir()) == ['report.md']
    code, _, err = _run(capsys, 'calibrate', data, '--liquid', 'water', '--out', data)
    assert code == 1 and 'is or contains the input' in err
    assert data.read_bytes().startswith(b'time [s]')


@pytest.mark.parametrize('option, value, match', [
    ('--folds', '0', "argument --folds: '0': must be at least 2"),
    ('--folds', 'x', "argument --folds: 'x': not a whole number"),
    ('--alpha', 'nan', "argument --alpha: 'nan': must be between 0 and 1"),
    ('--alpha', '2', "argument --alpha: '2': must be between 0 and 1"),
])
def test_calibrate_options_out_of_range_are_one_line_naming_the_option(option, value, match,
                                                                       tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(['calibrate', 'x.csv', '--liquid', 'oil', option, value, '--out',
              str(tmp_path / 'o')])
    err = capsys.readouterr().err.strip().splitlines()
    assert info.value.code == 2 and match in err[-1]
