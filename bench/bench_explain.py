# SPDX-License-Identifier: Apache-2.0
"""
What changed: how often the monitor's explanation names the right kind of a step.

A step of a share of the motor's volumetric losses Q_vl, of three kinds, each the same size
in l/min on average: the internal leakage (Q_vl times 1 + size), a leak to the case
(k p, p the case pressure, or the outlet's when no case pressure is recorded) and a
flowmeter gain (Q times 1 + g). The explainer
(:func:`satmotor_ros.identify.health.explain.explain_change`) gets what the monitor gives it:
the samples of the 15 min before the change and of the 15 min after, kept at 4 Hz.

Two kinds of recordings:
- ``synthetic``: the paszota family's motor at 2e-6 m^3/rad cycling through set-points held
  20 s (``identify.synthetic.generate_series`` at 2 Hz, its realistic sensor noise times 3);
- ``semireal``: the MBARI trajectories tiled with the noise measured on them, as
  ``bench_health.py`` builds them (the outlet pressure nearly constant there).

Each answer is scored ``right`` (the kind alone; the two gains named together count as a
gain), ``tied`` (the right kind named beside another, as fitting alike), ``unexplained`` or
``wrong``.

Run: ``PYTHONPATH=. .venv/bin/python bench/bench_explain.py [--sizes 0.2 0.1 0.05]
[--seeds 5] [--recordings synthetic semireal]``.
"""

from __future__ import annotations

import argparse
from collections import Counter
import dataclasses
import os
from pathlib import Path
import sys

os.environ.setdefault('OMP_NUM_THREADS', '1')
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / 'bench'))

import numpy as np  # noqa: E402

from satmotor_ros.identify.health import Baseline, HealthSamples  # noqa: E402
from satmotor_ros.identify.health.explain import explain_change  # noqa: E402
from satmotor_ros.identify.synthetic import (base_model, generate_series, Injection,  # noqa: E402
                                             Plan)

KINDS = {'internal leakage': 'wear', 'case leak': 'external_leakage',
         'flow sensor gain': 'sensor gain'}
"""Kind stepped in -> what a right answer contains."""

SIDE_S = 900.0
"""Seconds of samples on each side of the change, [s]."""


def _at_4hz(samples: HealthSamples) -> HealthSamples:
    grid = np.floor(samples.time * 4.0)
    return samples.take(np.concatenate([[True], grid[1:] != grid[:-1]]))


def _steps(samples: HealthSamples, loss: np.ndarray, drive: np.ndarray, size: float,
           after: np.ndarray) -> dict[str, np.ndarray]:
    """
    Return the flow of each kind of step, equal in l/min on average over `after`.

    `loss` is Q_vl in the frame where it runs forward (signed back by the port drop's sign).
    """
    used = after & np.isfinite(loss)
    mean_loss = float(np.mean(np.abs(loss[used])))
    extra_leak = size * mean_loss / float(np.mean(np.abs(drive[used]))) * np.abs(drive)
    gain = size * mean_loss / float(np.mean(np.abs(samples.flow[used])))
    sign = np.sign(samples.p_in - samples.p_out)
    return {'internal leakage': samples.flow + np.where(after, size * np.nan_to_num(loss) * sign,
                                                        0.0),
            'case leak': samples.flow + np.where(after, extra_leak * sign, 0.0),
            'flow sensor gain': samples.flow * np.where(after, 1.0 + gain, 1.0)}


def synthetic(seed: int, size: float, case_measured: bool) -> dict[str, str]:
    """One synthetic recording, each kind stepped in at its middle."""
    plan = Plan(family='paszota', displacement=2.0e-6)
    table = generate_series(plan, [Injection()], seed=seed, samples=int(4 * SIDE_S * 2),
                            rate=2.0, hold_s=20.0)
    samples = HealthSamples.from_table(table)
    baseline = Baseline(base_model(plan))
    model = baseline.model
    loss = (model.absorbency(samples.speed, dp=samples.p_in - samples.p_out,
                             errors='mask').flow - model.geometry.displacement * samples.speed)
    drive = samples.p_case if case_measured else samples.p_out
    if not case_measured:
        samples = dataclasses.replace(samples, p_case=None)
    return _explain(samples, baseline, loss, drive, size, 2.0 * SIDE_S)


def semireal(seed: int, size: float) -> dict[str, str]:
    """One semi-real recording (two tiles a side), the case leak on the outlet pressure."""
    import bench_health
    log = list(bench_health.LOGS)[seed % 2]
    tiles = bench_health.Tiles(log, 300 + seed)
    baseline = bench_health._monitor().baseline
    parts = [tiles.tile(k, np.ones_like) for k in range(4)]
    samples = HealthSamples(*(np.concatenate([getattr(p, name) for p in parts])
                              for name in ('time', 'speed', 'flow', 'p_in', 'p_out')))
    change = float(parts[2].time[0])
    losses = baseline.losses(samples, 0.5)
    loss = np.where(losses.reason == 0, losses.baseline, np.nan)
    return _explain(samples, baseline, loss, samples.p_out, size, change)


def _explain(samples: HealthSamples, baseline: Baseline, loss: np.ndarray, drive: np.ndarray,
             size: float, change: float) -> dict[str, str]:
    after = samples.time >= change
    answers = {}
    for kind, flow in _steps(samples, loss, drive, size, after).items():
        stepped = _at_4hz(dataclasses.replace(samples, flow=flow))
        before = stepped.take((stepped.time < change) & (stepped.time >= change - SIDE_S))
        since = stepped.take((stepped.time >= change) & (stepped.time < change + SIDE_S))
        answers[kind] = explain_change(before, since, baseline)
    return answers


def score(kind: str, answer: str) -> str:
    """Return right, tied, unexplained or wrong."""
    if answer == 'unexplained':
        return 'unexplained'
    key = KINDS[kind]
    tie = ' (they fit alike here)' in answer and not answer.startswith('flow or speed')
    if key in answer:
        return 'tied' if tie else 'right'
    return 'wrong'


def main(argv: list[str] | None = None) -> int:
    """Run the cases and print the tally per recording, size and kind."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--sizes', type=float, nargs='+', default=[0.2, 0.1, 0.05])
    parser.add_argument('--seeds', type=int, default=5)
    parser.add_argument('--recordings', nargs='+', default=['synthetic', 'semireal'],
                        choices=['synthetic', 'semireal'])
    args = parser.parse_args(argv)
    for recording in args.recordings:
        for size in args.sizes:
            tally: dict[str, Counter[str]] = {}
            for seed in range(args.seeds):
                runs = ([synthetic(seed, size, seed % 2 == 0)] if recording == 'synthetic'
                        else [semireal(seed, size)])
                for answers in runs:
                    for kind, answer in answers.items():
                        tally.setdefault(kind, Counter())[score(kind, answer)] += 1
                        print(f'  {recording} +{100 * size:.0f} % seed {seed} {kind}: {answer}',
                              flush=True)
            for kind, counts in tally.items():
                print(f'{recording}, +{100 * size:.0f} % of Q_vl, {kind}: ' + ', '.join(
                    f'{counts[k]} {k}' for k in ('right', 'tied', 'unexplained', 'wrong')),
                    flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
