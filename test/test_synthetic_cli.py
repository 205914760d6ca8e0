# SPDX-License-Identifier: Apache-2.0
"""The synthetic-table command line: several effects, free forms, outliers, one-line errors."""

import pytest

from satmotor_ros.identify import read_csv
from satmotor_ros.identify.synthetic import Injection, main, parse_injection
from satmotor_ros.model.units import LPM, MPA


def test_effects_of_every_form_are_read():
    assert parse_injection('external_leakage*2', 'water') == Injection.realistic(
        'external_leakage', 2.0, 'water')
    assert parse_injection('term:dp^0.76=0.8', 'oil') == Injection('term:dp^0.76', 0.8 * LPM)
    valve = parse_injection('threshold:dp=2@18', 'oil')
    assert valve.magnitude == 2 * LPM and dict(valve.shape) == {'reference': 18 * MPA}


@pytest.mark.parametrize('text', ['bogus', 'external_leakage=3', 'term:dp^0.7', 'threshold:dp=2',
                                  'external_leakage*x'])
def test_a_bad_effect_is_one_line_naming_it(text, tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main(['--effect', text, '--out', str(tmp_path / 'x.csv')])
    assert info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f'--effect {text!r}: use NAME or NAME*SCALE' in err
    assert not (tmp_path / 'x.csv').exists()


def test_two_effects_and_an_outlier_are_written(tmp_path, capsys):
    out = tmp_path / 'two.csv'
    clean = tmp_path / 'clean.csv'
    assert main(['--liquid', 'water', '--effect', 'external_leakage', '--effect',
                 'viscosity_temperature', '--outlier', '17:1.5', '--seed', '4',
                 '--out', str(out)]) == 0
    assert main(['--liquid', 'water', '--effect', 'external_leakage', '--effect',
                 'viscosity_temperature', '--seed', '4', '--out', str(clean)]) == 0
    assert 'external_leakage (magnitude' in capsys.readouterr().out
    bad, good = read_csv(out), read_csv(clean)
    jump = (bad.flow - good.flow) / LPM
    assert jump[17] == pytest.approx(1.5) and abs(jump[16]) < 1e-12
