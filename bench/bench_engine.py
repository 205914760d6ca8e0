# SPDX-License-Identifier: Apache-2.0
"""
Benchmark the evaluation engine against another tree of the package in the same run.

Each case runs in a child process per tree (``PYTHONPATH`` set to that tree), the trees
alternating, best of the rounds: one operating point on every path (the 5 us target), the
closed-form array map against the fused-numpy floor of :mod:`bench_model` (the 1.2x
target) and the plant's 1 ms step (no slower than the other tree). Times are the thread's CPU
time: on a loaded machine the wall clock counts other processes' turns.

Run: ``.venv/bin/python bench/bench_engine.py --base /path/to/main/worktree [--rounds R]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

CHILD = r"""
import json, os, sys, time
os.environ.setdefault('OMP_NUM_THREADS', '1')
sys.path.insert(0, sys.argv[1])  # this bench's directory, for the floor of bench_model
import numpy as np
from bench_model import floor
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM
from satmotor_ros.plant import ConstantLoad, Plant


def best(run, count, repeat):
    out = float('inf')
    for _ in range(repeat):
        start = time.thread_time()
        run()
        out = min(out, (time.thread_time() - start) / count)
    return out


rng = np.random.default_rng(7)
count = 2000
flow = (rng.uniform(2.0, 45.0, count) * LPM).tolist()
dp = (rng.uniform(4.0, 25.0, count) * MPA).tolist()
speed = (rng.uniform(50.0, 1500.0, count) * RPM).tolist()
rows = {}
for law in ('eq33', 'eq39'):
    m = MotorModel.default('water', law)
    warm = [(n, p, m.absorbency_point(n, p).flow * 1.001) for n, p in zip(speed, dp)]
    back = [(-q, p) for q, p in zip(flow, dp)]
    cases = {
        f'speed_point(Q, dp), {law}': (m.speed_point, list(zip(flow, dp))),
        f'speed_point(Q, dp_i=), {law}': (lambda q, p: m.speed_point(q, dp_i=p),
                                          list(zip(flow, dp))),
        f'speed_point(-Q, dp), pump, {law}': (m.speed_point, back),
        f'absorbency_point(n, dp), cold, {law}': (m.absorbency_point, list(zip(speed, dp))),
        f'absorbency_point(n, dp), warm, {law}': (
            lambda n, p, g: m.absorbency_point(n, p, flow_guess=g), warm),
        f'breakdown_point(n, dp_i), {law}': (m.breakdown_point, list(zip(speed, dp))),
    }
    for name, (fn, args) in cases.items():
        def run(fn=fn, args=args):
            for a in args:
                fn(*a)
        rows[name + ' [us]'] = best(run, len(args), 5) * 1e6

n_pts = 10**6
rng = np.random.default_rng(20261122)
q = rng.uniform(2.0, 45.0, n_pts) * LPM
d = rng.uniform(4.0, 25.0, n_pts) * MPA
m = MotorModel.default('water')
t_floor = best(lambda: floor(m, q, d), 1, 5)
t_map = best(lambda: m.speed(q, d, errors='mask'), 1, 5)
rows['closed-form speed() of 1e6 points [ms]'] = t_map * 1e3
rows['  x fused-numpy floor'] = t_map / t_floor
for liquid in ('water', 'oil'):
    plant = Plant(MotorModel.default(liquid), load=ConstantLoad(60.0))
    plant.run(2000, 20.0 * LPM)
    low, high = 10.0 * LPM, 30.0 * LPM

    def cycle(plant=plant, steps=10000):
        step = plant.step
        for i in range(steps):
            step(low if (i // 500) % 2 else high)
    rows[f'plant step, {liquid}, 10/30 l/min [us]'] = best(cycle, 10000, 5) * 1e6
print(json.dumps(rows))
"""


def measure(tree: str) -> dict[str, float]:
    """Run the cases once in a child process on `tree`; return their times by name."""
    env = {**os.environ, 'PYTHONPATH': tree, 'OMP_NUM_THREADS': '1'}
    out = subprocess.run([sys.executable, '-c', CHILD, HERE], env=env, check=True,
                         capture_output=True, text=True, cwd=tree).stdout
    result: dict[str, float] = json.loads(out.strip().splitlines()[-1])
    return result


def main() -> None:
    """Measure both trees, alternating, and print the best of each case side by side."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--base', required=True, help='the tree to compare against')
    parser.add_argument('--rounds', type=int, default=3)
    args = parser.parse_args()
    this = os.path.dirname(HERE)
    best: dict[str, dict[str, float]] = {'base': {}, 'this': {}}
    for _ in range(args.rounds):
        for label, tree in (('base', args.base), ('this', this)):
            for name, value in measure(tree).items():
                best[label][name] = min(value, best[label].get(name, float('inf')))
    print(f'| case | base ({args.base}) | this ({this}) | this / base |')
    print('| --- | ---: | ---: | ---: |')
    for name, value in best['this'].items():
        base = best['base'].get(name, float('nan'))
        print(f'| {name} | {base:.3g} | {value:.3g} | {value / base:.2f} |')


if __name__ == '__main__':
    main()
