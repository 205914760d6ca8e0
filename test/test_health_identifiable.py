# SPDX-License-Identifier: Apache-2.0
"""
A leakage factor the data cannot identify is flagged, not reported as a figure (review F1).

On the MBARI logs against their own calibration the baseline's losses (0.21 l/min mean) are
small against the residual noise (3.1 l/min): the factor read 0.46 [0.24, 0.68] with no
flag. The rule (:func:`~satmotor_ros.identify.health.records.unresolved`): the windowed
factor's 95 % half-width above ``change_fraction``. Here the same motor and cycle with a
quiet and a loud flowmeter: the loud one is flagged in monitor.json, the quiet one not.
"""

from __future__ import annotations

import math

from health_data import DISPLACEMENT, recording
import pytest
from satmotor_ros.identify.health import Baseline, Estimate, HealthMonitor, HealthSettings
from satmotor_ros.identify.health.records import unresolved
from satmotor_ros.identify.health.report import summary
from satmotor_ros.identify.health.run import MonitorRun


def test_the_rule_is_the_half_width_against_the_change_fraction():
    """Half-width 0.22 > 0.2: not identifiable; 0.064: identifiable; no interval: no flag."""
    assert 'not identifiable' in unresolved(Estimate(0.459, 0.238, 0.680), 0.2)
    assert unresolved(Estimate(0.459, 0.238, 0.680), 0.25) == ''
    assert unresolved(Estimate(0.982, 0.918, 1.045), 0.2) == ''
    assert unresolved(Estimate(1.0), 0.2) == ''


@pytest.mark.parametrize('noise_lpm, identifiable', [(0.05, True), (3.0, False)])
def test_monitor_json_flags_a_factor_lost_in_the_noise(noise_lpm, identifiable):
    """The same healthy motor: a quiet flowmeter gives a figure, a loud one a flag."""
    settings = HealthSettings(explain=False)
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), settings)
    monitor.update(recording(0.5, seed=4, rate_hz=2.0, noise_lpm=noise_lpm))
    snap = monitor.snapshot()
    assert not snap.learning and math.isfinite(snap.leakage_factor.low)
    doc = summary(MonitorRun(snap, (), (), settings, 'paszota'))
    assert doc['leakage_factor_identifiable'] is identifiable
    assert any('not identifiable' in f for f in doc['flags']) is not identifiable
