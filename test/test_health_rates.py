# SPDX-License-Identifier: Apache-2.0
"""
The monitor's figures hold at any sample rate: false alarms, the factor, its interval.

The flowmeter's noise is correlated over 1.9 s whatever the log's rate (``correlation_s``),
as a logger reading the same flowmeter slower sees it.
"""

from __future__ import annotations

from health_data import DISPLACEMENT, recording
import numpy as np
import pytest

from satmotor_ros.identify.health import Baseline, HealthMonitor, HealthSettings
from satmotor_ros.identify.health.noise import fit_variance
from satmotor_ros.model.units import LPM

QUIET = HealthSettings(explain=False)
TAU_S = 1.9  # the flowmeter noise's correlation time [s]


def _run(samples) -> tuple[HealthMonitor, np.ndarray]:
    """Run a monitor an hour at a time: it and its points' (value, low, high) with intervals."""
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    step = max(1, int(round(3600.0 / float(np.median(np.diff(samples.time))))))
    points = []
    for start in range(0, len(samples), step):
        monitor.update(samples.take(slice(start, start + step)))
        points += [(p.leakage_factor.value, p.leakage_factor.low, p.leakage_factor.high)
                   for p in monitor.pop_points() if np.isfinite(p.leakage_factor.low)]
    monitor.flush()
    return monitor, np.array(points)


@pytest.mark.parametrize('rate_hz', [0.5, 0.1])
def test_a_slow_log_weighs_its_samples_alike_and_its_factor_is_unbiased(rate_hz: float) -> None:
    """Below 1 Hz a difference of samples is no flow rate: no rate term, the factor is 1."""
    monitor, points = _run(recording(30.0, seed=3, rate_hz=rate_hz, correlation_s=TAU_S))
    snap = monitor.snapshot()
    assert snap.noise['sample_var_per_rate2'] == 0.0
    assert 1.0 <= snap.noise['bin_inflation'] < 4.0  # the floor fitted on every sample
    assert np.mean(points[:, 0]) == pytest.approx(1.0, abs=0.003)
    assert not snap.alarms


def test_a_one_hertz_log_still_weighs_by_the_flow_rate() -> None:
    """At 1 Hz the noise that grows with the flow's rate (timing jitter) is modelled."""
    samples = recording(2.0, seed=5, rate_hz=1.0, noise_lpm=0.0)
    rng = np.random.default_rng(5)
    rate = np.abs(np.gradient(DISPLACEMENT * samples.speed, samples.time))
    jitter = rng.normal(0.0, 0.05, len(samples)) * rate + rng.normal(0.0, 0.01 * LPM,
                                                                     len(samples))
    samples = samples.__class__(samples.time, samples.speed, samples.flow + jitter,
                                samples.p_in, samples.p_out)
    snap = _run(samples)[0].snapshot()
    assert snap.noise['sample_var_per_rate2'] > 0.0


@pytest.mark.slow
def test_the_window_interval_holds_the_truth_as_stated_on_a_half_hertz_log() -> None:
    """
    F8: the 95 % interval of the windowed factor holds 1 in 95 % of the bins (pooled).

    The level and the noise keep learning while the detector is quiet; gated on the bin's own
    deviation (the detector quiet after it), the larger deviations never taught the bins'
    variance, the interval was too narrow and held the truth in 94 % (93 % in the review).
    """
    covered = []
    for seed in (3, 4):
        _, points = _run(recording(40.0, seed=seed, rate_hz=0.5, correlation_s=TAU_S))
        covered.append(np.mean((points[:, 1] <= 1.0) & (1.0 <= points[:, 2])))
    assert 0.948 <= np.mean(covered) <= 0.98


@pytest.mark.slow
@pytest.mark.parametrize('rate_hz', [0.1, 0.5])
def test_no_false_alarm_in_a_hundred_hours_of_a_slow_log(rate_hz: float) -> None:
    """1000 h stated, 100 h run: none (0.1 expected), the threshold in bins of 8 samples."""
    snap = _run(recording(100.0, seed=500, rate_hz=rate_hz, correlation_s=TAU_S))[0].snapshot()
    assert not snap.alarms, snap.alarms
    assert snap.operating_hours == pytest.approx(100.0, rel=0.01)


def test_a_step_in_a_ten_second_log_is_found_within_a_quarter_hour() -> None:
    """+20 % of the losses at 2 h in a 0.1 Hz log: one change alarm, within 15 min."""
    samples = recording(4.0, seed=9, rate_hz=0.1, correlation_s=TAU_S,
                        scale=lambda t: np.where(t >= 7200.0, 1.2, 1.0))
    snap = _run(samples)[0].snapshot()
    assert [a.kind for a in snap.alarms] == ['change']
    assert 7200.0 <= snap.alarms[0].time_s <= 7200.0 + 900.0
    assert snap.alarms[0].after == pytest.approx(1.2, abs=0.05)


def test_the_noise_floor_without_any_rate_is_the_samples_robust_variance() -> None:
    """No rate seen (a slow log): a is the median-based variance of every residual."""
    rng = np.random.default_rng(0)
    residual = rng.normal(0.0, 2e-6, 40)
    a, b = fit_variance(np.zeros(40), residual)
    assert b == 0.0
    assert a == pytest.approx(float(np.median(residual ** 2)) / 0.454936, rel=1e-9)
