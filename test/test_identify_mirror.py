# SPDX-License-Identifier: Apache-2.0
"""
A recording and its mirror are the same motor: the calibration should not care which port is A.

Mirroring swaps the ports (p_a <-> p_b) and turns the signs of the speed and the flow. Every
figure of the calibration should be the same, and an effect that acts in one direction should
act in the other. The line compliance (T1 of :mod:`satmotor_ros.identify.transient`) reads
port A's pressure in both directions, so today it is not: the real 2021 MBARI log gives 1.12
l/min before any effect and names its relief valve; its mirror gives 0.80 and names none. The
symmetric term (the inlet's, the higher port's, in each row's frame) was tried: mirror-exact,
a base error of 0.88 on the log, but the negative-side valve is then lost and a positive
"valve" at 10.3 MPa named on 15 rows at the starts of moves (doc/calibration.md, issue 20).
The tests are strict xfails until the asymmetry is resolved.
"""

from dataclasses import replace

import pytest
from satmotor_ros.identify import calibrate, Options
from satmotor_ros.identify.columns import load_mapping, read_log
from satmotor_ros.identify.synthetic import (generate_transient, Injection, Plan,
                                             REALISTIC_DYNAMICS)
from satmotor_ros.model.units import parse_quantity
from satmotor_ros.options import MotorOptions
from vendored_data import data_path

SWAPPED = {'positive': 'negative', 'negative': 'positive', 'both': 'both'}


def mirrored(table):
    """Return the table with its ports swapped and its speed and flow turned."""
    return replace(table, speed=-table.speed, flow=-table.flow, p_in=table.p_out,
                   p_out=table.p_in, source=f'mirror of {table.source}')


def _figures(cal):
    summary = cal.summary()
    effects = sorted((e['effect'].split('@')[0], e.get('direction', 'both'))
                     for e in summary['effects'])
    return (cal.error_before.rmse_lpm, cal.error_after.rmse_lpm, effects,
            {d['term']: d.get('coefficient') for d in summary.get('dynamics', [])})


def _same(a, b, rtol):
    assert a[0] == pytest.approx(b[0], rel=rtol) and a[1] == pytest.approx(b[1], rel=rtol)


@pytest.mark.xfail(strict=True, reason='T1 reads port A in both directions (issue 20)')
def test_a_mirrored_transient_recording_gives_the_mirrored_calibration():
    plan = Plan(liquid='water', reverse_share=0.5)  # both frames: the inlet is A, then B
    table = generate_transient(plan, Injection.realistic('none', 1.0, 'water'),
                               REALISTIC_DYNAMICS, seed=2)
    options = Options(mode='transient', compare_families=False)
    one, other = (calibrate(t, 'water', options=options) for t in (table, mirrored(table)))
    first, second = _figures(one), _figures(other)
    _same(first, second, 1e-6)
    assert first[2] == second[2] == []
    assert first[3] == pytest.approx(second[3], rel=1e-6)
    assert first[3]['line_compliance'] == pytest.approx(5.0e-13, rel=0.1)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason='T1 reads port A in both directions (issue 20)')
def test_the_mirrored_mbari_log_gives_the_mirrored_calibration():
    log = data_path('real', 'mbari_pto', '2021.07.26T10.51.44.exp')
    table = read_log(log, load_mapping('mbari_pto'))
    displacement = parse_quantity('0.30 in^3/rev', 'displacement', 'cm^3/rev')
    spec = MotorOptions(liquid='oil', displacement=displacement).spec()
    one, other = (calibrate(t, 'oil', spec) for t in (table, mirrored(table)))
    first, second = _figures(one), _figures(other)
    _same(first, second, 0.02)
    named = [(e, SWAPPED[d]) for e, d in first[2]]
    assert second[2] == sorted(named)
