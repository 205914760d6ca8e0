# SPDX-License-Identifier: Apache-2.0
"""An effect whose fit ends on a bound of its range is not an estimate: refused and said."""

import json

import pytest

from satmotor_ros.cli import main
from satmotor_ros.identify import pipeline
from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.fit import LossFit
from satmotor_ros.identify.parts import loss_parts
from satmotor_ros.identify.selection import CrossValidatedSelector
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model.viscosity import standard_law
from test_calibrate_cli import _csv


def _gain(g, seed=3):
    """Return a table whose flowmeter reads (1 + g) Q; a gain error lies in (-0.5, 0.5)."""
    return generate(Plan(liquid='oil'), Injection('flow_sensor_gain', g, 'flow'), seed=seed)


def _library(table, stand_ins=False):
    """Return the parts and candidates; without the fitted forms that mimic a gain."""
    model = MotorModel.default('oil')
    parts, _ = loss_parts(model, table)
    channels = {**table.channels, 'p_out': table.p_out}
    candidates, _ = build_library(parts, channels, standard_law(model.liquid, 'oil'))
    if not stand_ins:
        candidates = [c for c in candidates if not c.effect.startswith(('term:', 'threshold:'))]
    return parts, candidates


GAIN_AT_BOUND = [('flow_sensor_gain(flow)', -0.5)]


@pytest.mark.parametrize(('g', 'pinned'), [(-0.3, []), (-0.55, GAIN_AT_BOUND)])
def test_a_fit_says_which_parameter_ends_on_a_bound(g, pinned):
    parts, candidates = _library(_gain(g))
    gain = [c for c in candidates if c.effect == 'flow_sensor_gain']
    fit = LossFit(gain).fit(parts)
    assert [(name, round(bound, 9)) for name, bound in fit.pinned(effects_only=True)] == pinned
    if not pinned:
        assert fit.effect_coefficient == pytest.approx(g, abs=0.01)


def test_a_gain_beyond_its_bound_is_refused_not_chosen_at_the_bound():
    parts, candidates = _library(_gain(-0.55))
    step = CrossValidatedSelector().select(parts, candidates).steps[0]
    assert step.ranking[0].effect == 'flow_sensor_gain'  # the best fit, but at -0.5
    assert step.chosen is not None and step.chosen.effect != 'flow_sensor_gain'
    assert step.runner_up is None or not step.runner_up.fit.pinned(effects_only=True)
    assert [s.effect for s in step.refused][:1] == ['flow_sensor_gain']
    assert ('refused, not an estimate (the data ask for a value beyond the range): '
            'flow_sensor_gain(flow) at its bound -0.5') in step.verdict


def test_a_gain_within_its_range_is_still_found():
    parts, candidates = _library(_gain(-0.3), stand_ins=True)
    step = CrossValidatedSelector().select(parts, candidates).steps[0]
    found = {s.effect for s in (step.chosen, step.runner_up) if s is not None}
    assert 'flow_sensor_gain' in found and step.refused == ()


@pytest.fixture()
def without_stand_ins(monkeypatch):
    """Calibrate without the fitted forms, so that the pinned gain would win."""
    library = pipeline.build_library

    def build(*args):
        candidates, skipped = library(*args)
        return [c for c in candidates if not c.effect.startswith(('term:', 'threshold:'))], skipped
    monkeypatch.setattr(pipeline, 'build_library', build)


def test_calibrate_warns_of_a_refused_effect_in_json_report_and_stderr(
        tmp_path, capsys, without_stand_ins):
    data = _csv(tmp_path / 'bench.csv', _gain(-0.55))
    assert main(['calibrate', str(data), '--liquid', 'oil', '--out', str(tmp_path / 'out')]) == 0
    out, err = capsys.readouterr()
    summary = json.loads((tmp_path / 'out' / 'calibration.json').read_text())
    warning = ('at a bound: step 1: flow_sensor_gain(flow) at its bound -0.5: the data ask for '
               'a value beyond its range, so the fit gives the bound, not an estimate; refused')
    assert warning in summary['warnings']
    assert f'warning: {data}: {warning}\n' in err
    assert out.startswith('WARNING implausible data and at a bound (see report.md); ')
    assert summary['effect'] != 'flow_sensor_gain'
    assert all(e['effect'] != 'flow_sensor_gain' for e in summary['effects'])
    report = (tmp_path / 'out' / 'report.md').read_text()
    assert f'- **{warning}**' in report
    load_motor(tmp_path / 'out' / 'coefficients.yaml')  # no gain of -0.5 (which would not load)


def test_the_report_marks_a_candidate_at_its_bound(tmp_path, capsys):
    data = _csv(tmp_path / 'bench.csv', _gain(-0.55))
    assert main(['calibrate', str(data), '--liquid', 'oil', '--out', str(tmp_path / 'out')]) == 0
    capsys.readouterr()
    report = (tmp_path / 'out' / 'report.md').read_text()
    row = next(line for line in report.splitlines() if line.startswith('| `flow_sensor_gain'))
    assert row.endswith('| -0.5 - (at a bound: flow_sensor_gain(flow) at its bound -0.5) |')
