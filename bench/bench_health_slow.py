# SPDX-License-Identifier: Apache-2.0
"""
The health monitor on bench logs slower than 1 Hz: a row every 5 or 10 s.

The motor is the tests' (``test/health_data.py``: the paszota family's defaults cycling
through speeds and loads, a flowmeter's white and 10 s-correlated noise) run at 1 Hz and
logged every `every` samples, as a slow bench logger reads a motor. Per log rate, over
``--seeds`` runs of 8 h each with the monitor's defaults:

- clean: change alarms in the hours of clean operation;
- step: +20 % of the volumetric losses at 3 h: the delay to the change alarm [s];
- wear: the losses growing linearly to the limit (2x) at 12 h: hours_to_limit at 8 h
  (truth 4 h, two thirds of the way) and its error.

Run: ``PYTHONPATH=.:test .venv/bin/python bench/bench_health_slow.py [--seeds 6]``.
"""

from __future__ import annotations

import argparse

from health_data import DISPLACEMENT, recording  # the tests' motor (PYTHONPATH test/)
import numpy as np

from satmotor_ros.identify.health import Baseline, HealthMonitor, HealthSettings

HOURS = 8.0
STEP_S = 3 * 3600.0
LIFE_H = 12.0


def _snapshot(every: int, seed: int, scale):
    samples = recording(HOURS, seed=seed, rate_hz=1.0, scale=scale).take(slice(0, None, every))
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT),
                            HealthSettings(explain=False))
    monitor.update(samples)
    monitor.flush()
    return monitor.snapshot()


def main() -> None:
    """Print the figures per log rate."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=6)
    seeds = range(100, 100 + parser.parse_args().seeds)
    for every in (10, 5):
        clean = sum(len(_snapshot(every, s, None).alarms) for s in seeds)
        delays, missed = [], 0
        for s in seeds:
            alarms = [a for a in _snapshot(every, s, lambda t: np.where(t >= STEP_S, 1.2, 1.0))
                      .alarms if a.time_s >= STEP_S]
            if alarms:
                delays.append(alarms[0].time_s - STEP_S)
            else:
                missed += 1
        errors = [100.0 * (_snapshot(every, s, lambda t: 1.0 + t / (LIFE_H * 3600.0))
                           .hours_to_limit.value / (LIFE_H - HOURS) - 1.0) for s in seeds]
        print(f'every {every} s: clean {clean} change alarms in {len(seeds) * HOURS:.0f} h; '
              f'+20 % step found after {np.min(delays):.0f}-{np.max(delays):.0f} s '
              f'(median {np.median(delays):.0f}), missed {missed} of {len(seeds)}; '
              f'hours_to_limit at 2/3 of the way {np.nanmin(errors):+.0f} to '
              f'{np.nanmax(errors):+.0f} % ({int(np.isnan(errors).sum())} without one: a change '
              'alarm restarted the trend)', flush=True)


if __name__ == '__main__':
    main()
