# SPDX-License-Identifier: Apache-2.0
"""
Every output names an effect alike: its id, its side and a valve's crack pressure.

Cold review of issue 20 (finding 5): the YAML key and the report's result said
``threshold:dp@negative``, the summary line, calibration.json, validation.json and the
report's coefficient table ``threshold:dp`` (no side, no crack), and the interval of the
valve's k >= 0 spanned 0.
"""

import json
import re

import numpy as np
import pytest
from satmotor_ros.cli import main
from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.parts import loss_parts
from satmotor_ros.identify.pipeline import _coefficient_interval
from satmotor_ros.identify.valve_reach import says
from satmotor_ros.model import MotorModel
from satmotor_ros.model.effects import Effect, effect_name
from satmotor_ros.model.units import MPA
from satmotor_ros.model.viscosity import standard_law
from test_effect_direction import _four_quadrants, NEGATIVE
import yaml

NAME = re.compile(r'threshold:dp@negative cracking at (1[78]\.?\d*) MPa')


def test_the_name_carries_the_side_and_the_crack_pressure():
    valve = Effect('threshold:dp', 2e-10, 'dp', 19.868e6, direction='negative',
                   options=(('exponent', 1.0),))
    assert effect_name(valve) == 'threshold:dp@negative cracking at 19.87 MPa'
    assert effect_name(Effect('threshold:dp', 2e-10, 'dp', 18e6)) == \
        'threshold:dp cracking at 18 MPa'
    assert effect_name(Effect('external_leakage', 1e-12, 'p_case')) == 'external_leakage'
    assert effect_name(Effect('external_leakage', 1e-12, 'p_out', direction='positive')) == \
        'external_leakage@positive'


@pytest.fixture(scope='module')
def valve_outputs(tmp_path_factory):
    """Calibrate a one-sided valve from four-quadrant rows, then validate the file on them."""
    work = tmp_path_factory.mktemp('names')
    table = _four_quadrants(NEGATIVE, np.random.default_rng(3), count=300)
    data = work / 'valve.csv'
    rows = zip(table.speed, table.flow, table.p_in, table.p_out)
    data.write_text('speed [rad/s],flow [m^3/s],p_in [Pa],p_out [Pa]\n' + ''.join(
        ','.join(repr(float(v)) for v in row) + '\n' for row in rows), encoding='utf-8')
    return work, data


def test_every_output_of_calibrate_and_validate_gives_the_same_name(valve_outputs, capsys):
    work, data = valve_outputs
    assert main(['calibrate', str(data), '--liquid', 'oil', '--out', str(work / 'cal')]) == 0
    line = capsys.readouterr().out
    summary = json.loads((work / 'cal' / 'calibration.json').read_text(encoding='utf-8'))
    name = summary['name']
    assert NAME.fullmatch(name), name
    crack = float(NAME.fullmatch(name).group(1)) * MPA
    assert crack == pytest.approx(summary['effects'][0]['threshold']['value'], rel=1e-3)
    assert summary['effects'][0]['name'] == name and summary['direction'] == 'negative'
    assert summary['effect'] == 'threshold:dp'  # the vocabulary's id (DESIGN.md), side apart
    assert f'effect: {name} (dp, coefficient' in line
    report = (work / 'cal' / 'report.md').read_text(encoding='utf-8')
    assert f'**Effects: `{name}`**' in report
    assert f'| + `{name}` |' in report  # the table of the errors after each effect
    assert re.search(rf'^\| `{re.escape(name)}` \| {summary["coefficient"]:.5g} ', report, re.M)
    assert not re.search(r'`threshold:dp`', report)  # never without its side
    reach = summary['effects'][0]['full_drop']  # the law at the top of its side's drop
    assert reach['fitted_dp_mpa'] <= reach['data_dp_mpa'] <= 28.0
    assert f'{says(summary["effects"][0])}.' in report
    doc = yaml.safe_load((work / 'cal' / 'coefficients.yaml').read_text(encoding='utf-8'))
    (key,) = doc['coefficient_sets']['oil']['effects']
    assert name.startswith(key + ' ') and key == 'threshold:dp@negative'
    # the valve's k >= 0: its interval stays above 0 and holds the estimate
    low, high = summary['ci95']
    assert 0.0 < low < summary['coefficient'] < high

    assert main(['validate', str(data), '--liquid', 'oil', '--out', str(work / 'val'),
                 '--motor', str(work / 'cal' / 'coefficients.yaml')]) == 0
    assert f'effects: {name};' in capsys.readouterr().out
    result = json.loads((work / 'val' / 'validation.json').read_text(encoding='utf-8'))
    (effect,) = result['effects']
    assert effect['name'] == name and effect['direction'] == 'negative'
    assert effect['threshold']['value'] == pytest.approx(crack, rel=1e-3)
    assert f'Effects in the model: {name}.' in \
        (work / 'val' / 'report.md').read_text(encoding='utf-8')


class _Report:
    """The parts of a fit report the interval reads: values, covariance, ci95."""

    def __init__(self, values, sd, t=1.96):
        self.values = np.asarray(values, dtype=float)
        self.covariance = np.diag(np.asarray(sd, dtype=float) ** 2)
        self.ci95 = np.column_stack([self.values - t * np.asarray(sd),
                                     self.values + t * np.asarray(sd)])


def _valve_candidate():
    table = _four_quadrants(NEGATIVE, np.random.default_rng(3), count=300)
    bare = MotorModel.default('oil')
    parts, _ = loss_parts(bare, table)
    candidates, _ = build_library(parts, {}, standard_law(bare.liquid, 'oil'))
    return next(c for c in candidates if c.effect == 'threshold:dp'
                and c.direction == 'negative')


def test_the_interval_of_a_valves_k_is_on_the_log_scale_and_never_spans_zero():
    candidate = _valve_candidate()
    assert candidate.bounds[0] == 0.0 and [s.name for s in candidate.shape][-1].endswith(
        'exponent')
    # three factors, then the valve: its size well determined, its exponent not, so that
    # k = size / x^e spans decades (a linear interval ran below 0)
    middle = [0.5 * (lo + hi) for lo, hi in (s.bounds for s in candidate.shape)]
    values = [1.0, 1.0, 1.0, 1.0, *middle]
    sd = [0.1, 0.1, 0.1, 0.05, *[0.01] * len(middle)]
    sd[-1] = 0.4  # the exponent, in its fitted units
    value, (low, high) = _coefficient_interval(_Report(values, sd), 3, candidate)
    assert value == pytest.approx(candidate.as_effect(*values[3:]).coefficient)
    assert 0.0 < low < value < high
    assert np.log(high / value) == pytest.approx(np.log(value / low), rel=1e-6)  # log-symmetric
    assert high / low > 10.0  # the exponent's uncertainty is decades of k
    # well determined, it is the linear (delta-method) interval to first order
    tight = [0.1, 0.1, 0.1, 1e-4, *[1e-5] * len(middle)]
    value, (low, high) = _coefficient_interval(_Report(values, tight), 3, candidate)
    assert 0.0 < low and (high - value) == pytest.approx(value - low, rel=1e-3)
