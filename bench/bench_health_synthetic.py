# SPDX-License-Identifier: Apache-2.0
"""
The health monitor on synthetic recordings the tests do not use: steps, drift, swings, gaps.

Each recording is ``identify.synthetic.generate_series`` (the paszota family's motor at
2e-6 m^3/rad, set-points held 20 s, sampled at 1 Hz, the plan's sensor noise times 3,
flowmeter noise 0.15 % of the reading among it) for 6 h, the monitor with its defaults
(what-changed on), fed in blocks of an hour. Cases: clean (each family, the temperature held);
a temperature swing of 10 K and 20 K the losses follow (``viscosity_temperature``); steps of
+10 % and +5 % of Q_vl at 3 h; a drift of Q_vl to +30 % over the 6 h; gaps (10 min of each
hour missing and a day off after 4 h), with and without a +10 % step; a flowmeter gain of
+0.5 % and a case leak of 0.1 l/min/MPa at 3 h. Printed per case and seed: the alarms (time,
kind, what, level before and after), the factor at the end, the hours of operation and of
recording and hours_to_limit with its interval.

Run: ``PYTHONPATH=. .venv/bin/python bench/bench_health_synthetic.py [--seeds 2]``.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
import dataclasses
import os
from pathlib import Path
import sys

os.environ.setdefault('OMP_NUM_THREADS', '1')
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402

from satmotor_ros.identify.health import (Baseline, HealthMonitor, HealthSamples,  # noqa: E402
                                          HealthSettings)
from satmotor_ros.identify.synthetic import (aging, base_model, generate_series,  # noqa: E402
                                             Injection, Plan)
from satmotor_ros.model.units import LPM, MPA  # noqa: E402

HOURS = 6.0
STEP_S = 3 * 3600.0
Edit = Callable[[HealthSamples, Plan], HealthSamples]


def run(name: str, plan: Plan, injections: list[Injection], seed: int,
        edit: Edit | None = None) -> None:
    """Monitor one recording and print what it says."""
    table = generate_series(plan, injections, seed=seed, samples=int(HOURS * 3600), rate=1.0,
                            hold_s=20.0)
    samples = HealthSamples.from_table(table)
    if edit is not None:
        samples = edit(samples, plan)
    monitor = HealthMonitor(Baseline(base_model(plan)), HealthSettings())
    for start in range(0, len(samples), 3600):
        monitor.update(samples.take(slice(start, start + 3600)))
    snap = monitor.snapshot()
    alarms = [(round(a.time_s), a.kind, a.what, round(a.before, 3), round(a.after, 3))
              for a in snap.alarms]
    limit = snap.hours_to_limit
    print(f'{name}, seed {seed}: alarms {alarms}; factor {snap.leakage_factor.value:.3f}; '
          f'{snap.operating_hours:.2f} h of operation in {snap.recording_hours:.2f} h; '
          f'hours_to_limit {limit.value:.3g} [{limit.low:.3g}, {limit.high:.3g}]', flush=True)


def scaled(factor: Callable[[np.ndarray], np.ndarray]) -> Edit:
    """Return an edit that multiplies the model's Q_vl by factor(t)."""
    def edit(samples: HealthSamples, plan: Plan) -> HealthSamples:
        model = base_model(plan)
        loss = (model.absorbency(samples.speed, dp=samples.p_in - samples.p_out,
                                 errors='mask').flow
                - model.geometry.displacement * samples.speed)
        extra = (factor(samples.time) - 1.0) * np.nan_to_num(loss)
        return dataclasses.replace(samples, flow=samples.flow + extra)
    return edit


def gaps(samples: HealthSamples, plan: Plan) -> HealthSamples:
    """Drop 10 min of every hour and put a day off after the fourth hour."""
    minute = samples.time % 3600.0
    kept = samples.take(~((minute > 1200.0) & (minute < 1800.0)))
    time = np.where(kept.time > 4 * 3600.0, kept.time + 86400.0, kept.time)
    return dataclasses.replace(kept, time=time)


def main(argv: list[str] | None = None) -> int:
    """Run every case for each seed."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=2)
    args = parser.parse_args(argv)
    plan = Plan(family='paszota', displacement=2.0e-6)
    tank = dataclasses.replace(plan, temperature_jitter=0.0)
    step10 = scaled(lambda t: np.where(t >= STEP_S, 1.1, 1.0))
    for seed in range(1, args.seeds + 1):
        for family in ('paszota', 'balawender', 'sliwinski2017'):
            run(f'clean {family}', dataclasses.replace(plan, family=family, displacement=0.0),
                [Injection()], seed)
        for span in (10.0, 20.0):
            run(f'temperature swing {span:g} K', tank,
                list(aging('paszota', wear=0.0, temperature_span=span)), seed)
        run('+10 % step', plan, [Injection()], seed, step10)
        run('+5 % step', plan, [Injection()], seed,
            scaled(lambda t: np.where(t >= STEP_S, 1.05, 1.0)))
        run('drift to +30 %', plan, [Injection()], seed,
            scaled(lambda t: 1.0 + 0.3 * t / (HOURS * 3600.0)))
        run('gaps', plan, [Injection()], seed, gaps)
        run('gaps and a +10 % step', plan, [Injection()], seed,
            lambda s, p: gaps(step10(s, p), p))
        run('flowmeter gain +0.5 %', plan,
            [Injection('flow_sensor_gain', 0.005, 'flow', onset=STEP_S)], seed)
        run('case leak', plan,
            [Injection('external_leakage', 0.1 * LPM / MPA, 'p_case', onset=STEP_S)], seed)
    return 0


if __name__ == '__main__':
    sys.exit(main())
