# SPDX-License-Identifier: Apache-2.0
"""
Every sample is accounted for: skipped with a reason, or used (noise model, a bin, open, held).

A bin with fewer than ``MIN_BIN_SAMPLES`` usable samples (the edge of a gap, a log dropping
samples) joins the next bin: its samples were dropped, unsaid (at 60 % dropout, half the
usable samples).
"""

from __future__ import annotations

from health_data import DISPLACEMENT, recording
from hypothesis import given, HealthCheck, settings, strategies as st
import numpy as np
import pytest

from satmotor_ros.identify.health import Baseline, HealthMonitor, HealthSettings

QUIET = HealthSettings(explain=False)
SAMPLES = recording(1.0, seed=2, rate_hz=2.0)


def _monitor() -> HealthMonitor:
    return HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(drop=st.floats(0.0, 0.9), seed=st.integers(0, 2 ** 16), block=st.integers(1, 4000),
       gaps=st.lists(st.tuples(st.floats(0.0, 3600.0), st.floats(1.0, 900.0)), max_size=3),
       stalled=st.floats(0.0, 0.3))
def test_every_sample_is_skipped_with_a_reason_or_used(drop, seed, block, gaps, stalled):
    """n_samples = skipped (by reason) + noise model + bins + open + held, for any log."""
    rng = np.random.default_rng(seed)
    keep = rng.uniform(size=len(SAMPLES)) >= drop
    for start, length in gaps:
        keep &= ~((SAMPLES.time >= start) & (SAMPLES.time < start + length))
    samples = SAMPLES.take(keep)
    speed = np.where(rng.uniform(size=len(samples)) < stalled, 0.0, samples.speed)
    samples = samples.__class__(samples.time, speed, samples.flow, samples.p_in, samples.p_out)
    monitor = _monitor()
    for start in range(0, len(samples), block):
        monitor.update(samples.take(slice(start, start + block)))
        snap = monitor.snapshot()
        assert snap.n_samples == snap.n_skipped + sum(snap.n_used.values())
        assert snap.n_skipped == sum(snap.skipped.values())
    monitor.flush()
    snap = monitor.snapshot()
    assert snap.n_samples == len(samples)
    assert snap.n_samples == snap.n_skipped + sum(snap.n_used.values())
    assert snap.n_used['held'] == 0


@pytest.mark.parametrize('drop', [0.0, 0.6])
def test_a_log_dropping_most_samples_keeps_them_in_its_bins(drop: float) -> None:
    """1 Hz with 60 % of the samples lost: bins of 4 join the next, none is lost."""
    samples = recording(3.0, seed=1, rate_hz=1.0)
    samples = samples.take(np.random.default_rng(0).uniform(size=len(samples)) >= drop)
    monitor = _monitor()
    monitor.update(samples)
    monitor.flush()
    snap = monitor.snapshot()
    used = snap.n_samples - snap.n_skipped
    assert snap.n_used['bins'] >= 0.96 * used  # the rest taught the noise model, or is open
    assert snap.n_used['noise_model'] + snap.n_used['bins'] + snap.n_used['open'] == used
    assert snap.leakage_factor.low <= 1.0 <= snap.leakage_factor.high
    assert not snap.learning and not snap.alarms
