# SPDX-License-Identifier: Apache-2.0
"""
After a change: the trend restarts where it began, hours_to_limit is a figure or says why not.

Review of issue 23, F4 and F6. A change alarm restarts the trend; it restarted at the alarm
(the bins between the change and the alarm were left in the old line) and, with no trend
for the next 40 min, hours_to_limit was NaN even past a crossed limit while the node kept
publishing the number from before the change. Now the trend restarts from the bins since the
change began, hours_to_limit is 0 once the limit is crossed (the estimator's one rule,
``limit_crossed``) and NaN otherwise with the reason (``hours_to_limit_why``).
"""

from __future__ import annotations

import math

from health_data import blocks, DISPLACEMENT, recording
import numpy as np
import pytest

from satmotor_ros.identify.health import Baseline, HealthMonitor, HealthSettings
from satmotor_ros.identify.health.monitor import limit_cleared, limit_crossed

STEP_S = 1.2 * 3600.0
"""The change, after an hour of wear (+10 % an hour) that gives a finite hours_to_limit, [s]."""


def _walk(after: float, hours: float) -> list[tuple[float, object, list]]:
    """Run the wear, then a step to `after`, in 5 min blocks: (end, snapshot, alarms) each."""
    baseline = Baseline.for_family('paszota', DISPLACEMENT)
    samples = recording(hours, seed=1, rate_hz=1.0, baseline=baseline,
                        scale=lambda t: np.where(t >= STEP_S, after, 1.0 + 0.1 * t / 3600.0))
    monitor = HealthMonitor(baseline, HealthSettings(explain=False))
    seen = []
    for block in blocks(samples, 300):
        alarms = monitor.update(block)
        seen.append((float(block.time[-1]), monitor.snapshot(), alarms,
                     float(monitor.trend_point[3])))
    return seen


def _change(seen: list) -> tuple[int, object]:
    """Return the index of the block that raised the change alarm, and the alarm."""
    for k, (_, _, alarms, _) in enumerate(seen):
        for alarm in alarms:
            if alarm.kind == 'change':
                return k, alarm
    raise AssertionError('no change alarm')


def test_a_limit_crossing_change_gives_0_hours_never_the_old_figure() -> None:
    """Wear, then 2.4 (limit 2): a figure before, then 0 (crossed) or NaN with why."""
    seen = _walk(2.4, 1.5)
    k, alarm = _change(seen)
    before = [s.hours_to_limit.value for _, s, _, _ in seen[:k]]
    assert any(h > 0 for h in before), before  # a figure (inf: not drifting) the node held
    assert 0.0 <= alarm.change_s - STEP_S <= 60.0 and alarm.time_s - alarm.change_s >= 30.0
    # the trend's first point starts at the change, not at the alarm's bin
    assert seen[k][3] == pytest.approx(alarm.change_s)
    for _, snap, _, _ in seen[k:]:
        h = snap.hours_to_limit.value
        if snap.in_limit:
            assert h == 0.0 and snap.hours_to_limit_why.startswith('0: the limit is crossed')
        else:
            assert math.isnan(h), h
            assert f'since the change at {alarm.change_s:.0f} s' in snap.hours_to_limit_why
    assert seen[-1][1].in_limit and any(a.kind == 'limit' for a in seen[-1][1].alarms)


def test_below_the_limit_the_hours_are_unknown_until_the_new_trend_has_its_points() -> None:
    """Wear, then 1.4: NaN since the change with how many points there are, then a figure."""
    seen = _walk(1.4, 2.2)
    k, alarm = _change(seen)
    unknown = [s for _, s, _, _ in seen[k:] if math.isnan(s.hours_to_limit.value)]
    assert unknown and all(f'since the change at {alarm.change_s:.0f} s: ' in s.hours_to_limit_why
                           and ' of 4 points of 600 s' in s.hours_to_limit_why for s in unknown)
    last = seen[-1][1]
    assert not last.in_limit and not math.isnan(last.hours_to_limit.value)
    assert last.hours_to_limit_why == ''
    # the new line is the new level's: it starts near 1.4, not pulled down by the old one
    assert last.trend.value == pytest.approx(1.4, abs=0.1)


def test_the_limit_rule_is_the_trend_or_the_window_s_lower_bound() -> None:
    """One noisy window above the limit is no crossing; its lower bound or the trend is."""
    assert not limit_crossed(1.9, 1.95, 2.0)
    assert not limit_crossed(math.nan, math.nan, 2.0)
    assert limit_crossed(2.0, math.nan, 2.0) and limit_crossed(math.nan, 2.0, 2.0)
    assert limit_cleared(1.5, 1.79, 2.0) and not limit_cleared(2.1, 1.5, 2.0)
    assert not limit_cleared(1.5, 1.81, 2.0)
