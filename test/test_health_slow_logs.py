# SPDX-License-Identifier: Apache-2.0
"""Bench logs slower than 1 Hz (a row every 5-10 s): the bins and the gap follow the step."""

from __future__ import annotations

import json
from pathlib import Path

from health_data import blocks, DISPLACEMENT, recording
import numpy as np
import pytest

from satmotor_ros.cli.main import main
from satmotor_ros.identify.health import Baseline, HealthMonitor, HealthSettings
from satmotor_ros.identify.table import write_csv

QUIET = HealthSettings(explain=False)
LIFE_H = 12.0  # the wear reaches the limit (2) here [h]


def _slow(hours: float, every: int, **kw):
    """Return a 1 Hz motor logged every `every` s (the noise is the motor's, not the log's)."""
    return recording(hours, rate_hz=1.0, **kw).take(slice(0, None, every))


def _run(samples, size: int) -> HealthMonitor:
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    for block in blocks(samples, size):
        monitor.update(block)
    monitor.flush()
    return monitor


@pytest.mark.parametrize('every', [10, 5])
def test_a_wear_logged_every_five_or_ten_seconds_gives_its_figures(every: int) -> None:
    """0.1 and 0.2 Hz: bins of 8 steps, a gap of 3; the factor, the trend, the hours."""
    samples = _slow(6.0, every, seed=4, scale=lambda t: 1.0 + t / (LIFE_H * 3600.0))
    snap = _run(samples, 5000).snapshot()
    assert snap.timing == {'sample_step_s': every, 'bin_s': 8.0 * every,
                           'max_gap_s': 3.0 * every, 'trend_point_s': 600.0}
    assert not snap.learning and not snap.alarms
    assert snap.operating_hours == pytest.approx(6.0, abs=0.03)  # no step is a gap
    factor = snap.leakage_factor
    assert factor.low <= 1.5 <= factor.high and factor.high - factor.low < 0.4
    assert snap.hours_to_limit.value == pytest.approx(LIFE_H - 6.0, rel=0.3)


def test_a_step_logged_every_ten_seconds_is_found_and_blocks_do_not_matter() -> None:
    """+30 % at 3 h in a 0.1 Hz log: one alarm within 10 min; a sample at a time, the same."""
    samples = _slow(5.0, 10, seed=1, scale=lambda t: np.where(t >= 3 * 3600.0, 1.3, 1.0))
    whole = _run(samples, 100_000).snapshot()
    assert [a.kind for a in whole.alarms] == ['change']
    assert 3 * 3600.0 <= whole.alarms[0].time_s <= 3 * 3600.0 + 600.0
    one_by_one = _run(samples, 1).snapshot()
    assert repr(one_by_one) == repr(whole)  # NaN too


def test_a_state_saved_before_the_step_is_known_resumes_as_if_it_ran_on(tmp_path: Path) -> None:
    """Saved with 7 samples held (fewer than tell the step): resumed, the same figures."""
    samples = _slow(2.0, 10, seed=2)
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT), QUIET)
    monitor.update(samples.take(slice(0, 7)))
    assert monitor.snapshot().n_samples == 7  # held, counted
    monitor.save(tmp_path / 'state.json')
    resumed = HealthMonitor.resume(tmp_path / 'state.json', monitor.baseline)
    resumed.update(samples.take(slice(7, None)))
    assert repr(resumed.snapshot()) == repr(_run(samples, 100_000).snapshot())


def test_the_cli_on_a_log_every_ten_seconds_writes_figures(tmp_path: Path) -> None:
    """The CLI on a 0.1 Hz bench CSV: not still learning, the timing in monitor.json."""
    samples = _slow(2.0, 10, seed=4)
    path = tmp_path / 'bench.csv'
    write_csv(path, {'time': ('s', samples.time), 'speed': ('rad/s', samples.speed),
                     'flow': ('m^3/s', samples.flow), 'p_in': ('Pa', samples.p_in),
                     'p_out': ('Pa', samples.p_out)})
    assert main(['monitor', str(path), '--out', str(tmp_path / 'out'), '--liquid', 'oil',
                 '--family', 'paszota', '--displacement',
                 f'{DISPLACEMENT * 2 * np.pi * 1e6:.9g}', '--no-explain']) == 0
    doc = json.loads((tmp_path / 'out' / 'monitor.json').read_text())
    assert doc['timing']['bin_s'] == 80.0 and doc['timing']['max_gap_s'] == 30.0
    assert doc['detector']['learning'] is False
    assert doc['leakage_factor_now']['value'] == pytest.approx(1.0, abs=0.15)
    assert doc['hours_to_limit'] is not None
