# SPDX-License-Identifier: Apache-2.0
"""Two model families the data do not tell apart are named a near tie (paired test)."""

import numpy as np
import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import calibrate
from satmotor_ros.identify.families import paired_p_value
from satmotor_ros.identify.report import write_report
from test_identify_families import _points_csv, _table_of


def test_the_paired_test_tells_noise_from_a_worse_model():
    rng = np.random.default_rng(1)
    a, b = rng.normal(0.0, 1.0, (2, 200))
    assert paired_p_value(a, a) == 1.0
    assert paired_p_value(a, b) > 0.05  # two draws of the same noise
    assert paired_p_value(a, 1.1 * a) < 1e-6  # 10 % more error at every point
    assert paired_p_value(1.1 * a, a) > 1 - 1e-6  # one-sided: the first is the worse
    # neighbours that share their error count as fewer points: the same gap means less
    assert paired_p_value(a, 1.1 * b, inflation=4.0) > paired_p_value(a, 1.1 * b)


def test_families_the_data_cannot_tell_apart_are_a_near_tie(tmp_path):
    # eqs. (31)-(33) reproduce balawender's default losses of the SM-0,75/25 to the noise
    cal = calibrate(_table_of('balawender'), 'oil')
    tie = cal.summary()['family_comparison']['near_tie']
    assert set(tie['families']) == {'sliwinski2017', 'balawender'}
    assert tie['p_value'] >= 0.05
    assert tie['note'].startswith(f'near tie: {tie["families"][1]} is within the noise of '
                                  f'{tie["families"][0]}')
    report = write_report(cal, tmp_path, cal.summary()).read_text()
    note = tie['note']
    assert f'**N{note[1:]}.**' in report and 'of Q_vl' in note


@pytest.mark.parametrize('family', ['paszota', 'sliwinski2017'])
def test_a_family_clearly_ahead_is_no_tie(family, tmp_path):
    cal = calibrate(_table_of(family), 'oil')
    assert cal.model.family.name == family
    assert cal.summary()['family_comparison']['near_tie'] is None
    assert 'near tie' not in write_report(cal, tmp_path, cal.summary()).read_text().lower()


def test_the_summary_line_names_the_family_it_ties_with(tmp_path, capsys):
    data = _points_csv('balawender', tmp_path / 'points.csv')
    assert main(['calibrate', str(data), '--liquid', 'oil', '--out', str(tmp_path / 'a')]) == 0
    assert '; family sliwinski2017 (near tie with balawender);' in capsys.readouterr().out
