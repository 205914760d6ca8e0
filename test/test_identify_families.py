# SPDX-License-Identifier: Apache-2.0
"""Calibrate chooses the model family before the effect, out of sample; --family pins it."""

import json

import numpy as np
import pytest
from satmotor_ros.cli.main import main
from satmotor_ros.identify import calibrate, Options, write_csv
from satmotor_ros.identify.output import write_json, write_yaml
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model.families import FAMILY_NAMES
from satmotor_ros.model.families.defaults import default_motor
from satmotor_ros.model.units import LPM, MPA, RPM


def _table_of(family, seed=3, noise_lpm=0.02):
    """Steady points of the SM-0,75/25 as `family` with its default coefficients."""
    model = MotorModel.from_spec(default_motor(family), 'oil')
    rng = np.random.default_rng(seed)
    speed = np.repeat(np.linspace(200.0, 1500.0, 8), 6) * RPM
    dp = np.tile(np.linspace(2.0, 20.0, 6), 8) * MPA
    flow = np.asarray(model.absorbency(speed, dp).flow, dtype=float)
    flow = flow + rng.normal(0.0, noise_lpm * LPM, flow.size)
    return BenchTable(speed, flow, dp, np.zeros_like(dp), {}, {}, f'<{family} points>')


def _points_csv(family, path):
    """Write :func:`_table_of` `family` as a bench CSV of ports A and B; return its path."""
    table = _table_of(family)
    write_csv(path, {'speed': ('rpm', table.speed / RPM), 'flow': ('l/min', table.flow / LPM),
                     'p_a': ('MPa', table.p_in / MPA), 'p_b': ('MPa', table.p_out / MPA)})
    return path


def test_calibrate_finds_the_family_that_made_the_data():
    family = 'paszota'
    cal = calibrate(_table_of(family), 'oil')
    assert cal.model.family.name == family
    scores = cal.family.scores
    assert [s.family for s in scores][0] == family
    assert {s.family for s in scores} == set(FAMILY_NAMES)
    own = next(s for s in scores if s.family == 'sliwinski2017')
    assert scores[0].rmse < 0.95 * own.rmse
    assert cal.family.verdict.startswith(f'{family} cuts the noise-weighted out-of-sample error')


def test_a_family_that_fits_no_better_does_not_replace_the_motors_own():
    # eqs. (31)-(33) with three free factors reproduce balawender's default losses of the
    # SM-0,75/25 to the noise: no reason to change the structure
    cal = calibrate(_table_of('balawender'), 'oil')
    assert cal.model.family.name == 'sliwinski2017'
    errors = {s.family: s.rmse for s in cal.family.scores}
    assert errors['balawender'] < 1.1 * errors['sliwinski2017'] < 2.0 * 0.02 * LPM


def test_calibrate_keeps_the_motors_family_on_its_own_data_and_pins_on_request(tmp_path):
    table = generate(Plan(liquid='oil'), Injection(), seed=4)
    cal = calibrate(table, 'oil')
    assert cal.model.family.name == 'sliwinski2017'
    summary = write_json(cal, tmp_path / 'calibration.json')
    assert summary['family'] == 'sliwinski2017'
    comparison = summary['family_comparison']
    assert len(comparison['families']) == 3 and comparison['n_points'] > 0
    assert all(f['cv_error']['rmse_lpm'] > 0 for f in comparison['families'])
    pinned = calibrate(table, 'oil', options=Options(compare_families=False))
    assert pinned.family is None
    pinned_comparison = pinned.summary()['family_comparison']
    assert pinned_comparison.pop('base')['fitted'] == []  # the SM-0,75/25's own: kept
    assert pinned_comparison == {
        'verdict': 'sliwinski2017 pinned by the user (--family)', 'n_points': None,
        'families': []}


def test_a_calibrated_family_writes_a_yaml_of_that_family_that_loads(tmp_path):
    cal = calibrate(_table_of('paszota', noise_lpm=0.2), 'oil')
    write_yaml(cal, tmp_path / 'coefficients.yaml')
    spec = load_motor(tmp_path / 'coefficients.yaml')
    assert spec.family == 'paszota'
    factors = dict(zip(cal.final.names, cal.final.values))
    packaged = default_motor('paszota').sets['oil'].coefficients
    assert factors['losses_scale'] != 1.0
    assert spec.sets['oil'].coefficients.k_g == pytest.approx(
        packaged.k_g * factors['losses_scale'])


@pytest.mark.slow
def test_cli_family_pins_and_displacement_sizes_the_compared_families(tmp_path, capsys):
    data = _points_csv('paszota', tmp_path / 'points.csv')
    assert main(['calibrate', str(data), '--liquid', 'oil', '--out', str(tmp_path / 'a')]) == 0
    assert 'family paszota' in capsys.readouterr().out
    result = json.loads((tmp_path / 'a' / 'calibration.json').read_text())
    assert result['family'] == 'paszota' and len(result['family_comparison']['families']) == 3
    assert '## Model family' in (tmp_path / 'a' / 'report.md').read_text()
    assert main(['calibrate', str(data), '--liquid', 'oil', '--family', 'sliwinski2017',
                 '--out', str(tmp_path / 'b')]) == 0
    result = json.loads((tmp_path / 'b' / 'calibration.json').read_text())
    assert result['family'] == 'sliwinski2017'
    assert result['family_comparison']['families'] == []
