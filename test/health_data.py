# SPDX-License-Identifier: Apache-2.0
"""Synthetic recordings for the health monitor's tests: a motor running, losses scaled."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from satmotor_ros.identify.health import Baseline, HealthSamples
from satmotor_ros.model.units import LPM, MPA
from scipy.signal import lfilter

DISPLACEMENT = 2.0e-6
"""q_t/(2 pi) of the test motor, [m^3/rad]."""


def recording(hours: float, seed: int = 0, rate_hz: float = 5.0, noise_lpm: float = 0.05,
              scale: Callable[[np.ndarray], np.ndarray] | None = None,
              baseline: Baseline | None = None, t0: float = 0.0,
              correlation_s: float | None = None) -> HealthSamples:
    """
    Return a motor cycling through speeds and loads, its losses times `scale(t)`.

    The noise is white plus a slow correlated part (an AR(1) of 0.9 from one sample to the
    next: 2 s at 5 Hz), as a real flowmeter's; with `correlation_s` the AR(1)'s correlation
    time is that many seconds whatever the rate (a logger reading the same flowmeter slower).
    """
    baseline = baseline or Baseline.for_family('paszota', DISPLACEMENT)
    rng = np.random.default_rng(seed)
    t = t0 + np.arange(int(hours * 3600 * rate_hz)) / rate_hz
    speed = 60.0 + 40.0 * np.sin(2 * np.pi * t / 47.0) + 10.0 * np.sin(2 * np.pi * t / 13.0)
    dp = (8.0 + 5.0 * np.sin(2 * np.pi * t / 31.0 + 1.0)) * MPA
    model = baseline.model
    flow = model.absorbency(speed, dp=dp, errors='mask').flow
    loss = flow - model.geometry.displacement * speed
    if scale is not None:
        flow = flow + (scale(t) - 1.0) * loss
    if noise_lpm:
        phi = 0.9 if correlation_s is None else float(np.exp(-1.0 / (rate_hz * correlation_s)))
        shocks = rng.normal(0.0, noise_lpm * np.sqrt(1 - phi ** 2), t.size)
        shocks[0] = 0.0
        colored = lfilter([1.0], [1.0, -phi], shocks)
        flow = flow + (colored + rng.normal(0.0, 0.3 * noise_lpm, t.size)) * LPM
    p_out = np.full(t.size, 0.5 * MPA)
    return HealthSamples(t, speed, flow, p_out + dp, p_out)


def blocks(samples: HealthSamples, size: int) -> list[HealthSamples]:
    """Cut samples into blocks of `size`."""
    return [samples.take(slice(i, i + size)) for i in range(0, len(samples), size)]


def series_csv(path, seed: int, start: float, factor: float | None = None,
               duration_s: float = 600.0, samples: int = 3000, rate: float = 5.0) -> None:
    """Write a water motor's synthetic time series from epoch `start`, its losses x `factor`."""
    from satmotor_ros.fleet.synthetic import _scaled
    from satmotor_ros.identify.synthetic import generate_series, Injection, Plan, to_columns
    from satmotor_ros.identify.table import write_csv
    table = generate_series(Plan(liquid='water', n_points=20, duration_s=duration_s),
                            Injection(), seed, samples=samples, rate=rate)
    columns = to_columns(table if factor is None else _scaled(table, factor))
    columns['time'] = ('s', columns['time'][1] + start)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_csv(path, columns)
