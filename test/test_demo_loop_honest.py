# SPDX-License-Identifier: Apache-2.0
"""The demo's loop claims no more than it shows: named, separable, physical, hold time."""

import numpy as np
import pytest

from satmotor_ros.cli import _demo_loop
from satmotor_ros.cli._demo_loop import _hold, separation, verdict
from satmotor_ros.identify import calibrate, Options
from satmotor_ros.identify.synthetic import (Dynamics, generate, generate_transient, Injection,
                                             Plan)
from satmotor_ros.plant.scenario import CASE_OFFSETS, identification_cycle


@pytest.fixture(scope='module')
def leak():
    """Calibrate a bench table with a leak to the case: external_leakage is found."""
    injection = Injection.realistic('external_leakage', 1.0, 'water')
    cal = calibrate(generate(Plan(liquid='water'), injection, seed=4), 'water')
    summary = cal.summary()
    assert summary['effects'][0]['effect'] == 'external_leakage'
    return cal, summary


def test_named_only_when_the_interval_covers_the_injected_value(leak):
    cal, summary = leak
    lo, hi = summary['effects'][0]['ci95']
    inside = verdict({'external_leakage': 0.5 * (lo + hi)}, summary, cal)
    assert inside[0].startswith('It named the injected `external_leakage`')
    outside = verdict({'external_leakage': 3.0 * hi}, summary, cal)
    assert 'does not cover the injected' in outside[0] and 'not named' in outside[0]
    missing = verdict({'clearance_wear': 1e-9}, summary, cal)
    assert missing[0].startswith('It did not name the injected `clearance_wear`')


def test_the_correlation_with_the_base_parameters_is_reported(leak, monkeypatch):
    cal, summary = leak
    other, r = separation(cal, cal.found[0].label)
    assert other in {c.name for c in cal.parts.components} and 0.0 < abs(r) <= 1.0
    names = list(cal.final.names)
    expected = max((abs(cal.final.correlation[names.index(cal.found[0].label), names.index(n)])
                    for n in names if n == other))
    assert abs(r) == pytest.approx(expected)
    lo, hi = summary['effects'][0]['ci95']
    said = ' '.join(verdict({'external_leakage': 0.5 * (lo + hi)}, summary, cal))
    assert f'r = {r:+.3f}' in said
    monkeypatch.setattr(_demo_loop, 'UNSEPARABLE', min(abs(r), 0.999) - 1e-3)  # now inseparable
    said = verdict({'external_leakage': 0.5 * (lo + hi)}, summary, cal)
    assert 'cannot tell it apart' in said[0] and 'not named' in said[0]
    assert 'not separable' in said[1]


def test_a_negative_transient_term_is_said_to_be_no_estimate():
    table = generate_transient(Plan(liquid='oil'), Injection(),
                               Dynamics(line_compliance=-5e-13, speed_lag=0.02, flow_lag=0.05),
                               seed=11, duration_s=60.0)
    cal = calibrate(table, 'oil', options=Options(mode='transient'))
    said = ' '.join(verdict({}, cal.summary(), cal))
    assert '`line_compliance`' in said and 'no estimates' in said


@pytest.mark.parametrize('duration', [2.0, 6.0, 12.0, 24.0, 100.0])
def test_the_hold_time_said_is_the_one_run(duration):
    cycle = identification_cycle().scaled(1.5 * duration)
    assert _hold(cycle) == f'{1.5 * duration / 9:.3g} s'
    assert {round(s.duration, 9) for s in cycle.segments} == {round(1.5 * duration / 9, 9)}


def test_the_case_pressure_steps_are_orthogonal_to_speed_load_and_time():
    cycle = identification_cycle()
    offset = np.array([s.case_offset for s in cycle.segments])
    assert set(offset) == set(CASE_OFFSETS)
    for other in ([s.setpoint for s in cycle.segments], [s.load for s in cycle.segments],
                  np.arange(len(cycle.segments))):
        assert abs(np.corrcoef(offset, other)[0, 1]) < 1e-9
    scaled = cycle.scaled(7.0).segments
    assert all(s.case_offset == c.case_offset for s, c in zip(scaled, cycle.segments))
