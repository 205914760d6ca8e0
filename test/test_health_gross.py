# SPDX-License-Identifier: Apache-2.0
"""
Gross finite readings (a logger's 1e30 fill value, a broken message) are skipped as NaN is.

Review of issue 23, F8: a reading outside the physical envelope (``baseline.GROSS`` times the
model's validated range) is counted ``implausible`` and skipped, and weighs on nothing else
(not the flow's rate beside it, not the whole block): the figures are those of the same data
with NaN there. Both doors: the estimator, and ``satmotor monitor`` on a CSV.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

from health_data import DISPLACEMENT, recording
import numpy as np
import pytest

from satmotor_ros.cli.main import main
from satmotor_ros.identify.health import Baseline, HealthMonitor, HealthSamples, HealthSettings
from satmotor_ros.identify.health.baseline import GROSS
from satmotor_ros.identify.table import write_csv

SETTINGS = HealthSettings(explain=False)
ROWS = np.r_[200:203, 1500:1503, 2800:2803]
"""Spiked samples: in the noise model's stage, mid-run, and in the last window."""


def _baseline() -> Baseline:
    return Baseline.for_family('paszota', DISPLACEMENT)


@pytest.fixture(scope='module')
def clean() -> HealthSamples:
    """0.42 h of a healthy motor at 2 Hz."""
    return recording(0.42, seed=1, rate_hz=2.0, baseline=_baseline())


def _with(samples: HealthSamples, channel: str, value: float) -> HealthSamples:
    column = np.asarray(getattr(samples, channel), dtype=float).copy()
    column[ROWS] = value
    return dataclasses.replace(samples, **{channel: column})


def _run(samples: HealthSamples) -> tuple[list[float], dict[str, int]]:
    monitor = HealthMonitor(_baseline(), SETTINGS)
    monitor.update(samples)
    factors = [p.bin_factor for p in monitor.pop_points()]
    snap = monitor.snapshot()
    return factors + [snap.leakage_factor.value, snap.leakage_factor.low,
                      snap.operating_hours, snap.noise['sample_var_rest']], snap.skipped


@pytest.mark.parametrize(('channel', 'value'), [('flow', 1e30), ('flow', -1e30),
                                                ('p_in', 1e30), ('p_out', -1e30),
                                                ('speed', 1e30), ('speed', -1e4)])
def test_a_gross_reading_is_skipped_as_a_non_finite_one(clean: HealthSamples, channel: str,
                                                        value: float) -> None:
    """The figures are those of NaN in the same samples; counted implausible, not non-finite."""
    got, skipped = _run(_with(clean, channel, value))
    want, nan_skipped = _run(_with(clean, channel, math.nan))
    assert got == want
    assert skipped['implausible'] == len(ROWS) == nan_skipped['non_finite']
    assert skipped['non_finite'] == 0 and sum(skipped.values()) == len(ROWS)


def test_the_physical_envelope_is_gross_times_the_validated_range() -> None:
    """Twice the range is a motor run hard (the MBARI logs): kept; beyond GROSS times: not."""
    baseline = _baseline()
    valid = baseline.model.valid_range
    speed = np.array([2.0, 0.99 * GROSS, 1.01 * GROSS, 1.0]) * valid.speed_max
    dp = np.array([2.0, 1.0, 1.0, 1.01 * GROSS]) * valid.dp_max
    block = HealthSamples(np.arange(4.0), speed, baseline.displacement * speed, dp,
                          np.zeros(4), temperature=np.array([40.0, 90.0, 40.0, 40.0]))
    assert baseline.physical(block).tolist() == [True, True, False, False]
    hot = dataclasses.replace(block, temperature=np.array([40.0, 500.0, 40.0, 40.0]))
    assert not baseline.physical(hot)[1]


def test_satmotor_monitor_skips_them_as_the_estimator_does(clean: HealthSamples,
                                                           tmp_path: Path) -> None:
    """A CSV with a 1e4 rad/s speed (not absurd to the reader) at ROWS: counted, skipped."""
    spiked = _with(clean, 'speed', 1e4)
    path = tmp_path / 'run.csv'
    write_csv(path, {'time': ('s', spiked.time), 'speed': ('rad/s', spiked.speed),
                     'flow': ('m^3/s', spiked.flow), 'p_in': ('Pa', spiked.p_in),
                     'p_out': ('Pa', spiked.p_out)})
    assert main(['monitor', str(path), '--out', str(tmp_path / 'out'), '--liquid', 'oil',
                 '--family', 'paszota', '--displacement',
                 f'{DISPLACEMENT * 2 * np.pi * 1e6:.9g}', '--no-explain']) == 0
    doc = json.loads((tmp_path / 'out' / 'monitor.json').read_text())
    assert doc['skipped']['implausible'] == len(ROWS) == doc['n_skipped']
    want, _ = _run(_with(clean, 'speed', math.nan))
    assert doc['leakage_factor_now']['value'] == pytest.approx(want[-4], rel=1e-4)  # CSV digits
