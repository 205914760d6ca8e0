# SPDX-License-Identifier: Apache-2.0
"""``satmotor synthetic``: several effects, free forms, outliers, one-line errors."""

import re

import pytest

from satmotor_ros.cli.main import main
from satmotor_ros.identify import read_csv
from satmotor_ros.identify.synthetic import Injection, parse_injection
from satmotor_ros.model.units import LPM, MPA


def test_effects_of_every_form_are_read():
    assert parse_injection('external_leakage*2', 'water') == Injection.realistic(
        'external_leakage', 2.0, 'water')
    assert parse_injection('term:dp^0.76=0.8', 'oil') == Injection('term:dp^0.76', 0.8 * LPM)
    valve = parse_injection('threshold:dp=2@18', 'oil')
    assert valve.magnitude == 2 * LPM and dict(valve.shape) == {'reference': 18 * MPA}


@pytest.mark.parametrize('text', ['bogus', 'external_leakage=3', 'term:dp^0.7', 'threshold:dp=2',
                                  'external_leakage*x', 'threshold:dp=2@-5'])
def test_a_bad_effect_is_one_line_naming_it(text, tmp_path, capsys):
    assert main(['synthetic', '--effect', text, '--out', str(tmp_path / 'x.csv')]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f'--effect {text!r}: use NAME or NAME*SCALE' in err
    assert not (tmp_path / 'x.csv').exists()


def test_two_effects_and_an_outlier_are_written(tmp_path, capsys):
    out = tmp_path / 'two.csv'
    clean = tmp_path / 'clean.csv'
    assert main(['synthetic', '--liquid', 'water', '--effect', 'external_leakage', '--effect',
                 'viscosity_temperature', '--outlier', '17:1.5', '--seed', '4',
                 '--out', str(out)]) == 0
    assert main(['synthetic', '--liquid', 'water', '--effect', 'external_leakage', '--effect',
                 'viscosity_temperature', '--seed', '4', '--out', str(clean)]) == 0
    assert 'external_leakage (magnitude' in capsys.readouterr().out
    bad, good = read_csv(out), read_csv(clean)
    jump = (bad.flow - good.flow) / LPM
    assert jump[17] == pytest.approx(1.5) and abs(jump[16]) < 1e-12


@pytest.mark.parametrize('argv, match', [
    (['--points', '0'], '--points 0: must be at least 2'),
    (['--series', '1'], '--series 1: must be at least 2'),
    (['--transient', '0'], '--transient 0.0: must be at least 0.1'),
    (['--transient', 'inf'], '--transient inf: must be a finite number, at least 0.1'),
    (['--seed', '-1'], '--seed -1: must be 0 or more'),
    (['--outlier', '5:nan'], "--outlier \\['5:nan'\\]: use ROW:LPM"),
    (['--outlier', '500:3'], "--outlier \\['500:3'\\]: a row from 0 to 99"),
    (['--liquid', 'mercury'], "coefficient set 'mercury' is not in"),
    (['--effect', 'term:dp^.=1'], "term 'dp\\^\\.' is not a product of powers"),
])
def test_bad_options_are_one_line_not_a_traceback(argv, match, tmp_path, capsys):
    assert main(['synthetic', *argv, '--out', str(tmp_path / 'x.csv')]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert 'Traceback' not in ''.join(err) and re.search(match, err[-1]), err
    assert not (tmp_path / 'x.csv').exists()


def test_a_users_file_is_not_replaced_but_its_own_table_is(tmp_path, capsys):
    mine = tmp_path / 'mine.csv'
    mine.write_text('my bench data\n')
    assert main(['synthetic', '--out', str(mine)]) == 1
    assert 'exists and is not an earlier output of satmotor synthetic' in capsys.readouterr().err
    assert mine.read_text() == 'my bench data\n'
    assert main(['synthetic', '--out', str(tmp_path / 'own.csv')]) == 0
    own = ['synthetic', '--seed', '3', '--out', str(tmp_path / 'own.csv')]
    assert main(own) == 0  # its own: replaced
    assert main(['synthetic', '--force', '--out', str(mine)]) == 0
    assert len(read_csv(mine)) == 100
