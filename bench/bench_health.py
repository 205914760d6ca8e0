# SPDX-License-Identifier: Apache-2.0
"""
The health monitor on semi-real recordings: step detection delay, false alarms, hours to limit.

Each recording tiles a real MBARI trajectory (time, speed, port pressures of one of the two
vendored logs, every sample at 50 Hz) with the flow of a known motor (the paszota family's
defaults at 0.30 in^3/rev, as :mod:`satmotor_ros.identify.semireal` builds it) and the noise
measured on that log (white, Gaussian-correlated, spikes and the timing jitter while the
flow changes), drawn afresh for every 400-440 s tile. Faults act on the motor's volumetric
losses Q_vl (the model's, at the true state): a step of +20 % at a random time, or a wear
growing linearly to the limit (2x) at a stated hour. A factor s on Q_vl is injected as the
monitor defines the leakage factor (measured Q_vl over the baseline's at the measured point):
the flow Q solves Q = q_t n + s Q_vl(Q), the channel drop of eq. (35) taken at the larger flow
(scaling the healthy flow's Q_vl instead left the motor's leak at the healthy chamber pressure,
and the monitor's trend, right by its definition, read 1.757-1.760 over 4 h at a constant
1.75; 1.751-1.752 as defined); the fixed point is solved on a grid of s once per log and
interpolated per sample, and its excess over s = 1 added to the case's healthy flow. The
baseline is the same family's defaults (the healthy motor); the monitor runs with its
defaults (1000 h false-alarm interval) on blocks of one tile, as ``satmotor monitor`` would
on the logs.

Reported:
- step: the delay from the step to the change alarm in operating minutes (the time the
  motor turned: stalled samples do not count) and in recording minutes; median and 90th
  percentile over the runs; missed steps (none within 60 min);
- clean: change alarms over hours of clean operation per log;
- wear: hours_to_limit against the truth at 25, 50 and 75 % of the way;
- cost: microseconds of CPU per sample of the monitor alone.

Run: ``PYTHONPATH=. .venv/bin/python bench/bench_health.py [--steps 20] [--clean-hours 100]
[--wear-hours 40] [--wear-runs 2] [--jobs 2]`` (the figures in the README: the defaults).
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
import json
import os
from pathlib import Path
import sys
import time
from typing import Any, Callable

os.environ.setdefault('OMP_NUM_THREADS', '1')
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from satmotor_ros.identify.health import (Baseline, HealthMonitor, HealthSamples,  # noqa: E402
                                          HealthSettings)
# the noise draws of the semi-real cases, so that each tile has fresh noise without building
# the case (the model's flow along the trajectory) again
from satmotor_ros.identify.semireal import (_correlated, _noise, build_case,  # noqa: E402
                                            estimate_noise, F11_5, load_trajectory)
from satmotor_ros.model.units import LPM  # noqa: E402

DATA = ROOT / 'test' / 'data' / 'real' / 'mbari_pto'
LOGS = {'stepped': '2021.07.26T10.51.44.exp', 'bias': 'FrictionIDMovesWithBiasCurr.exp'}
STEP = 0.2  # the step in Q_vl [-]
LIMIT = 2.0  # the default limit_leakage_factor [-]


class Tiles:
    """A log's trajectory and model flow, tiled with fresh noise and a fault on Q_vl."""

    def __init__(self, log: str, seed: int) -> None:
        """Build the case without noise once; measure the log's noise."""
        trajectory = load_trajectory(DATA / LOGS[log])
        self.noise = estimate_noise(trajectory)
        case = build_case(trajectory, noise=None)
        self.time, self.speed = case.time, case.speed
        self.p_a, self.p_b = case.p_a, case.p_b
        self.true = case.true_flow
        self.loss = case.true_flow - case.displacement * trajectory.speed_state
        self.period = float(case.time[-1] - case.time[0]) + float(np.median(np.diff(case.time)))
        self.step_s = float(np.median(np.diff(case.time)))
        self.rng = np.random.default_rng(seed)
        clean = HealthSamples(self.time, self.speed, self.true, self.p_a, self.p_b)
        used = _monitor().baseline.losses(clean, HealthSettings().min_speed).reason == 0
        dt = np.diff(self.time, prepend=self.time[0])
        self.operating = np.cumsum(np.where(used, dt, 0.0))  # operating seconds in a tile
        self.grid = np.linspace(1.0, LIMIT, 9)
        fixed = [self.consistent(s) for s in self.grid]
        # the healthy flow stays the case's; a factor adds its consistent excess to it
        self.flows = np.array([q - fixed[0] + self.true for q in fixed])

    def consistent(self, scale: float, iterations: int = 5) -> np.ndarray:
        """
        Return the flow whose Q_vl is `scale` times the baseline's there (clean, one tile).

        Q = q_t n + scale Q_vl(Q) by fixed-point steps from the scaled healthy loss (each
        step shrinks the error ~50x here); samples the monitor skips keep that start.
        """
        baseline, min_speed = _monitor().baseline, HealthSettings().min_speed
        flow = self.true + (scale - 1.0) * self.loss
        forward = np.where(self.p_a - self.p_b < 0.0, -1.0, 1.0)  # the loss's frame
        for _ in range(iterations):
            losses = baseline.losses(HealthSamples(self.time, self.speed, flow, self.p_a,
                                                   self.p_b), min_speed)
            flow = flow + np.where(losses.reason == 0, forward * (
                scale * losses.baseline - losses.measured), 0.0)
        return flow

    def flow_at(self, scale: np.ndarray) -> np.ndarray:
        """Return the clean flow with Q_vl times `scale` per sample (linear in the grid)."""
        step = self.grid[1] - self.grid[0]
        j = np.clip(((scale - self.grid[0]) // step).astype(int), 0, self.grid.size - 2)
        w = (scale - self.grid[j]) / step
        at = np.arange(scale.size)
        return (1.0 - w) * self.flows[j, at] + w * self.flows[j + 1, at]

    def operating_s(self, t1: float, t2: float) -> float:
        """Return the operating seconds (samples the monitor uses) between two times."""
        def upto(t: float) -> float:
            k, rest = divmod(t, self.period)
            i = int(np.searchsorted(self.time - self.time[0], rest, side='right'))
            return k * self.operating[-1] + (self.operating[i - 1] if i else 0.0)
        return upto(t2) - upto(t1)

    def tile(self, k: int, scale: Callable[[np.ndarray], np.ndarray]) -> HealthSamples:
        """Return tile `k` with fresh noise, Q_vl times scale(t)."""
        t = self.time - self.time[0] + k * self.period
        reading = self.flow_at(np.broadcast_to(scale(t), t.shape).astype(float))
        extra, _ = _noise(self.noise, self.step_s, t.size, self.rng)
        late = self.noise.jitter_s * _correlated(self.noise.correlation_s / self.step_s,
                                                 t.size, self.rng)
        flow = reading + extra * LPM - late * np.gradient(reading, t)
        return HealthSamples(t, self.speed, flow, self.p_a, self.p_b)


def _monitor() -> HealthMonitor:
    return HealthMonitor(Baseline.for_family('paszota', F11_5), HealthSettings(explain=False))


def step_run(log: str, seed: int) -> dict[str, Any]:
    """One run: an hour clean, then +20 % at a random time; the delay to the alarm."""
    tiles = Tiles(log, seed)
    at = 3600.0 + float(tiles.rng.uniform(0.0, tiles.period))
    monitor = _monitor()
    k = 0
    while True:
        block = tiles.tile(k, lambda t: np.where(t >= at, 1.0 + STEP, 1.0))
        alarms = monitor.update(block)
        early = [a for a in monitor.alarms if a.kind == 'change' and a.time_s < at]
        late = [a for a in alarms if a.kind == 'change' and a.time_s >= at]
        if late or block.time[-1] > at + 3600.0:
            break
        k += 1
    found = late[0] if late else None
    return {'log': log, 'seed': seed, 'step_s': at, 'false_before': len(early),
            'delay_min': None if found is None else (found.time_s - at) / 60.0,
            'delay_operating_min': None if found is None else
            tiles.operating_s(at, found.time_s) / 60.0}


def clean_run(log: str, seed: int, hours: float) -> dict[str, Any]:
    """Hours of clean operation: the change alarms raised; the CPU cost per sample."""
    tiles = Tiles(log, seed)
    monitor = _monitor()
    cpu, samples = 0.0, 0
    for k in range(int(np.ceil(hours * 3600.0 / tiles.period))):
        block = tiles.tile(k, lambda t: np.ones_like(t))
        start = time.process_time()
        monitor.update(block)
        cpu += time.process_time() - start
        samples += len(block)
    snap = monitor.snapshot()
    return {'log': log, 'seed': seed, 'hours': snap.recording_hours,
            'operating_hours': snap.operating_hours,
            'false_alarms': sum(a.kind == 'change' for a in snap.alarms),
            'limit_alarms': sum(a.kind == 'limit' for a in snap.alarms),
            'factor_end': snap.leakage_factor.value, 'us_per_sample': 1e6 * cpu / samples}


def wear_run(log: str, seed: int, life_h: float) -> dict[str, Any]:
    """Q_vl growing linearly to the limit at `life_h`: hours_to_limit at 25, 50, 75 %."""
    tiles = Tiles(log, seed)
    monitor = _monitor()
    checks = {f: f * life_h for f in (0.25, 0.5, 0.75)}
    out: dict[str, Any] = {'log': log, 'seed': seed, 'life_h': life_h}
    k = 0
    while checks:
        block = tiles.tile(k, lambda t: 1.0 + (LIMIT - 1.0) * t / (life_h * 3600.0))
        monitor.update(block)
        now = block.time[-1] / 3600.0
        for f, when in list(checks.items()):
            if now >= when:
                snap = monitor.snapshot()
                truth = life_h - now
                est = snap.hours_to_limit
                out[f'{int(100 * f)}%'] = {
                    'truth_h': truth, 'estimate_h': est.value, 'ci95': [est.low, est.high],
                    'error_pct': 100.0 * (est.value - truth) / truth,
                    'covered': bool(est.low <= truth <= est.high),
                    'change_alarms': sum(a.kind == 'change' for a in snap.alarms)}
                del checks[f]
        k += 1
    return out


def _pct(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float('nan')


def main(argv: list[str] | None = None) -> int:
    """Run the three measurements and print them (JSON, then a summary)."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--steps', type=int, default=20, help='step runs (alternating logs)')
    parser.add_argument('--clean-hours', type=float, default=100.0, help='per log')
    parser.add_argument('--wear-hours', type=float, default=40.0, help='life to the limit')
    parser.add_argument('--wear-runs', type=int, default=2, help='per log')
    parser.add_argument('--jobs', type=int, default=2)
    args = parser.parse_args(argv)
    logs = list(LOGS)
    with ProcessPoolExecutor(args.jobs) as pool:
        steps = [pool.submit(step_run, logs[i % 2], 100 + i) for i in range(args.steps)]
        clean = [pool.submit(clean_run, log, 7, args.clean_hours) for log in logs]
        wear = [pool.submit(wear_run, log, 200 + i, args.wear_hours)
                for log in logs for i in range(args.wear_runs)]
        result = {'step': [f.result() for f in steps], 'clean': [f.result() for f in clean],
                  'wear': [f.result() for f in wear]}
    print(json.dumps(result, indent=1))
    delays = [r['delay_operating_min'] for r in result['step'] if r['delay_min'] is not None]
    wall = [r['delay_min'] for r in result['step'] if r['delay_min'] is not None]
    missed = sum(r['delay_min'] is None for r in result['step'])
    print(f'\nstep +{100 * STEP:.0f} % in Q_vl, {len(result["step"])} runs: delay median '
          f'{_pct(delays, 50):.2f} min of operation ({_pct(wall, 50):.2f} min of recording), '
          f'p90 {_pct(delays, 90):.2f} ({_pct(wall, 90):.2f}); missed {missed}; false alarms '
          f'before the step {sum(r["false_before"] for r in result["step"])}')
    for r in result['clean']:
        print(f'clean {r["log"]}: {r["false_alarms"]} change alarms in {r["hours"]:.1f} h '
              f'({r["operating_hours"]:.1f} h of operation), factor at the end '
              f'{r["factor_end"]:.3f}; {r["us_per_sample"]:.2f} us CPU per sample')
    for f in ('25%', '50%', '75%'):
        errors = [r[f]['error_pct'] for r in result['wear']]
        covered = sum(r[f]['covered'] for r in result['wear'])
        print(f'wear, {f} of the way: hours_to_limit error ' + ', '.join(
            f'{e:+.0f} %' for e in errors) + f'; interval covers the truth {covered}/'
            f'{len(errors)}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
