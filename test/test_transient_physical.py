# SPDX-License-Identifier: Apache-2.0
"""A negative line compliance or lag is physically impossible: flagged, never an estimate."""

from satmotor_ros.identify import calibrate, Options
from satmotor_ros.identify.synthetic import Dynamics, generate_transient, Injection, Plan
from satmotor_ros.identify.transient import transient_section


def _dynamics(dynamics, seed):
    table = generate_transient(Plan(liquid='oil'), Injection(), dynamics, seed=seed,
                               duration_s=60.0)
    cal = calibrate(table, 'oil', options=Options(mode='transient'))
    return cal, {d['term']: d for d in cal.summary()['dynamics']}


def test_a_negative_compliance_is_flagged_impossible_in_json_and_report():
    cal, found = _dynamics(Dynamics(line_compliance=-5e-13, speed_lag=0.02, flow_lag=0.05), 11)
    d = found['line_compliance']
    assert d['coefficient'] < 0.0 and d['physical'] is False
    assert 'cannot be' in d['impossible']
    section = '\n'.join(transient_section(cal.summary(), 1.0))
    line = next(x for x in section.splitlines() if '`line_compliance`' in x)
    assert 'impossible' in line and 'includes 0' not in line


def test_positive_terms_are_physical_and_carry_no_flag():
    _, found = _dynamics(Dynamics(line_compliance=5e-13, speed_lag=0.02, flow_lag=0.05), 12)
    assert 'left_out' in found.pop('line_compliance_b')  # no volume on port B's line
    for d in found.values():
        assert d['physical'] is True and 'impossible' not in d, d
