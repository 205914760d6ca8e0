# SPDX-License-Identifier: Apache-2.0
"""
The health monitor at any sample rate: false alarms, a step's delay, the factor's bias.

The motor is the tests' (``test/health_data.py``: the paszota family's defaults at 2e-6
m^3/rad cycling through speeds and loads) and its flowmeter noise is the same in time
whatever the log's rate: white 0.015 l/min plus an AR(1) of 0.05 l/min whose correlation
time is 1.9 s (0.9 from one 5 Hz sample to the next), sampled at ``--rates`` Hz as a logger
reads the motor. Per rate, with the monitor's defaults (what-changed off):

- clean: ``--hours`` of healthy operation per seed; the change alarms, the mean of the
  factor (each bin's windowed figure with an interval) against the truth 1, and how often
  its 95 % interval holds 1;
- step: +20 % of the volumetric losses at a random time after the learning; the delay to
  the change alarm in minutes (median, 90th percentile, missed: none within 60 min).

Run: ``PYTHONPATH=. .venv/bin/python bench/bench_health_rates.py [--rates 0.1 0.5 10]
[--hours 100] [--seeds 2] [--steps 10]``.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import sys

os.environ.setdefault('OMP_NUM_THREADS', '1')
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402

from satmotor_ros.identify.health import (Baseline, HealthMonitor, HealthSamples,  # noqa: E402
                                          HealthSettings)
from satmotor_ros.model.units import LPM, MPA  # noqa: E402
from scipy.signal import lfilter  # noqa: E402

DISPLACEMENT = 2.0e-6
NOISE_LPM = 0.05
TAU_S = -0.2 / np.log(0.9)
CHUNK_S = 3600.0


def chunks(hours: float, rate: float, seed: int, step_s: float = np.inf,
           factor: float = 1.2):
    """Yield the recording an hour at a time (the noise's AR state carried)."""
    baseline = Baseline.for_family('paszota', DISPLACEMENT)
    model = baseline.model
    rng = np.random.default_rng(seed)
    phi = float(np.exp(-1.0 / (rate * TAU_S)))
    state = np.zeros(1)
    n_total = int(round(hours * 3600.0 * rate))
    per = int(round(CHUNK_S * rate))
    for start in range(0, n_total, per):
        t = np.arange(start, min(start + per, n_total)) / rate
        speed = 60.0 + 40.0 * np.sin(2 * np.pi * t / 47.0) + 10.0 * np.sin(2 * np.pi * t / 13.0)
        dp = (8.0 + 5.0 * np.sin(2 * np.pi * t / 31.0 + 1.0)) * MPA
        flow = model.absorbency(speed, dp=dp, errors='mask').flow
        loss = flow - model.geometry.displacement * speed
        flow = flow + np.where(t >= step_s, factor - 1.0, 0.0) * loss
        shocks = rng.normal(0.0, NOISE_LPM * np.sqrt(1 - phi ** 2), t.size)
        colored, state = lfilter([1.0], [1.0, -phi], shocks, zi=state * phi)
        flow = flow + (colored + rng.normal(0.0, 0.3 * NOISE_LPM, t.size)) * LPM
        p_out = np.full(t.size, 0.5 * MPA)
        yield HealthSamples(t, speed, flow, p_out + dp, p_out)


def monitor_run(hours: float, rate: float, seed: int, step_s: float = np.inf):
    """Run the monitor over one recording: its snapshot and its points' factors."""
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT),
                            HealthSettings(explain=False))
    values = []
    for block in chunks(hours, rate, seed, step_s):
        monitor.update(block)
        values += [(p.leakage_factor.value, p.leakage_factor.low, p.leakage_factor.high)
                   for p in monitor.pop_points() if np.isfinite(p.leakage_factor.low)]
    monitor.flush()
    return monitor.snapshot(), np.array(values).reshape(-1, 3)


def main() -> None:
    """Print the figures per rate."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rates', type=float, nargs='+', default=[0.1, 0.5, 10.0])
    parser.add_argument('--hours', type=float, default=100.0)
    parser.add_argument('--seeds', type=int, default=2)
    parser.add_argument('--steps', type=int, default=10)
    args = parser.parse_args()
    for rate in args.rates:
        alarms, op_h, means, covered = 0, 0.0, [], []
        for seed in range(args.seeds):
            snap, values = monitor_run(args.hours, rate, 500 + seed)
            alarms += sum(a.kind == 'change' for a in snap.alarms)
            op_h += snap.operating_hours
            means.append(float(np.mean(values[:, 0])) if values.size else np.nan)
            covered.append(float(np.mean((values[:, 1] <= 1.0) & (1.0 <= values[:, 2]))))
            print(f'  {rate:g} Hz clean seed {seed}: alarms '
                  f'{[round(a.time_s / 3600, 2) for a in snap.alarms]}, mean factor '
                  f'{means[-1]:.4f}, interval holds 1 in {100 * covered[-1]:.1f} %, '
                  f'h {snap.threshold:.2f}, noise {snap.noise}', flush=True)
        delays, missed = [], 0
        rng = np.random.default_rng(7)
        for k in range(args.steps):
            step_s = float(rng.uniform(1.0, 2.0)) * 3600.0
            snap, _ = monitor_run(step_s / 3600.0 + 1.0, rate, 900 + k, step_s)
            after = [a for a in snap.alarms if a.kind == 'change' and a.time_s >= step_s]
            if after and after[0].time_s - step_s <= 3600.0:
                delays.append((after[0].time_s - step_s) / 60.0)
            else:
                missed += 1
        delay = (f'median {np.median(delays):.2f} min, 90th percentile '
                 f'{np.percentile(delays, 90):.2f} min' if delays else 'none found')
        print(f'{rate:g} Hz: {alarms} false change alarms in {op_h:.0f} h of operation '
              f'({args.seeds} x {args.hours:g} h); mean factor {np.nanmean(means):.4f} '
              f'(runs {np.nanmin(means):.4f}-{np.nanmax(means):.4f}), its 95 % interval '
              'holds 1 in '
              f'{100 * np.mean(covered):.1f} % of the bins; +20 % step: {delay}, '
              f'missed {missed} of {args.steps}', flush=True)


if __name__ == '__main__':
    main()
