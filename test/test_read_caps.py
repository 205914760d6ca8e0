# SPDX-License-Identifier: Apache-2.0
"""Caps on CSV columns and plot size: one line, a bounded plot, said in the report (issue 14)."""

import os
from pathlib import Path
import re
import struct
import subprocess
import sys

import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import DataError, read_csv
from satmotor_ros.identify import report
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.limits import CSV_MAX_COLUMNS
from test_calibrate_cli import _csv

ROOT = Path(__file__).resolve().parents[1]


def test_a_csv_of_3000_columns_is_refused_at_once(tmp_path):
    path = tmp_path / 'wide.csv'
    names = ['speed [rpm]', 'flow [l/min]', 'p_in [MPa]', 'p_out [MPa]']
    names += [f'c{i} [V]' for i in range(2996)]
    path.write_text(','.join(names) + '\n' + ('1,' * 2999 + '1\n') * 20)
    with pytest.raises(DataError, match=f'3000 columns, more than the {CSV_MAX_COLUMNS} read '
                                        r'\(the cap SATMOTOR_CSV_MAX_COLUMNS'):
        read_csv(path)


def test_caps_are_overridden_through_the_environment():
    code = 'from satmotor_ros import limits; print(limits.CSV_MAX_COLUMNS, limits.PLOT_MAX_PANELS)'
    env = {**os.environ, 'PYTHONPATH': str(ROOT), 'SATMOTOR_CSV_MAX_COLUMNS': '4000',
           'SATMOTOR_PLOT_MAX_PANELS': '9'}
    out = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True, text=True,
                         check=True).stdout
    assert out.split() == ['4000', '9']


def _png_size(path):
    width, height = struct.unpack('>II', path.read_bytes()[16:24])
    return width, height


@pytest.mark.slow
def test_residual_grid_is_capped_and_the_report_says_so(tmp_path, monkeypatch):
    table = generate(Plan(liquid='oil'), Injection.realistic('external_leakage', 1, 'oil'),
                     seed=3)
    data = _csv(tmp_path / 'bench.csv', table, extra=[f'x{i}' for i in range(8)])
    assert main(['calibrate', str(data), '--liquid', 'oil', '--out', str(tmp_path / 'a')]) == 0
    full = _png_size(tmp_path / 'a' / 'residuals.png')
    monkeypatch.setattr(report, 'PLOT_MAX_PANELS', 6)
    assert main(['calibrate', str(data), '--liquid', 'oil', '--out', str(tmp_path / 'b')]) == 0
    capped = _png_size(tmp_path / 'b' / 'residuals.png')
    assert capped[0] == full[0] and capped[1] == 2 * 240 < full[1]  # 2 rows of 3 panels
    text = (tmp_path / 'b' / 'report.md').read_text()
    assert re.search(r'The residual plot shows the first 6 of 1\d quantities \(the cap '
                     'SATMOTOR_PLOT_MAX_PANELS', text)
    assert 'residual plot shows the first' not in (tmp_path / 'a' / 'report.md').read_text()
