# SPDX-License-Identifier: Apache-2.0
"""What monitor.json and the node's diagnostics say of the hours to the limit."""

from __future__ import annotations

from dataclasses import replace
import json
import math
import sys

from health_data import DISPLACEMENT, recording
import pytest

from satmotor_ros.identify.health import Baseline, Estimate, HealthMonitor, HealthSettings
from satmotor_ros.identify.health.report import summary
from satmotor_ros.identify.health.run import MonitorRun


@pytest.fixture(scope='module')
def snapshot():
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT),
                            HealthSettings(explain=False))
    monitor.update(recording(0.05, rate_hz=2.0))
    return monitor.snapshot(), monitor.settings


def _doc(snapshot, hours: Estimate) -> dict:
    snap, settings = snapshot
    run = MonitorRun(replace(snap, hours_to_limit=hours), (), (), settings, 'paszota')
    return json.loads(json.dumps(summary(run), allow_nan=False))


def test_a_trend_that_does_not_rise_gives_a_number_in_strict_json(snapshot) -> None:
    """Not drifting: DESIGN's one number, the largest double (JSON has no Infinity)."""
    doc = _doc(snapshot, Estimate(math.inf, 12.5, math.inf))
    assert doc['hours_to_limit'] == sys.float_info.max
    assert doc['hours_to_limit_ci95'] == [12.5, sys.float_info.max]
    assert doc['hours_to_limit_note'].startswith('never')


def test_a_rising_trend_gives_its_hours_and_no_trend_yet_gives_null(snapshot) -> None:
    """A crossing is its hours (6 digits); before any trend there is no figure to give."""
    doc = _doc(snapshot, Estimate(40.0000004, 30.0, 55.0))
    assert doc['hours_to_limit'] == 40.0 and doc['hours_to_limit_ci95'] == [30.0, 55.0]
    assert doc['hours_to_limit_note'].startswith('hours')
    doc = _doc(snapshot, Estimate(math.nan))
    assert doc['hours_to_limit'] is None and doc['hours_to_limit_ci95'] == [None, None]
    assert doc['hours_to_limit_note'].startswith('null')


def test_the_node_diagnostics_say_what_the_figure_means(snapshot) -> None:
    """The diagnostics carry the figure as the topic does (inf) and monitor.json's note."""
    pytest.importorskip('rclpy')
    from satmotor_ros.nodes.motor_monitor import _figures
    snap, _ = snapshot
    values = _figures(replace(snap, hours_to_limit=Estimate(math.inf, 12.5, math.inf)))
    assert values['hours_to_limit [h]'] == 'inf'
    assert values['hours_to_limit note'] == _doc(
        snapshot, Estimate(math.inf, 12.5, math.inf))['hours_to_limit_note']
