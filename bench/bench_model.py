# SPDX-License-Identifier: Apache-2.0
"""
Benchmark the model on 10^6 operating points against a floor measured in the same run.

The floor is the same arithmetic as ``MotorModel.speed`` (channel drop, clearance, the
two leakages, eq. (40), the loss breakdown and the speed loss) written as fused numpy
expressions over the whole arrays, with every constant folded and no input screening,
no status flags and no per-equation functions: what numpy alone costs for this job.

Run: ``make bench`` or ``.venv/bin/python bench/bench_model.py [--points N] [--repeat R]``.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

os.environ.setdefault('OMP_NUM_THREADS', '1')  # one core, as the targets are stated
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

import numpy as np  # noqa: E402

from satmotor_ros.model import MotorModel  # noqa: E402
from satmotor_ros.model.units import LPM, MPA, RPM  # noqa: E402


def floor(model: MotorModel, flow: np.ndarray, dp: np.ndarray) -> tuple[np.ndarray, ...]:
    """Compute speed, speed loss and breakdown in fused expressions (the baseline)."""
    g, c, liq = model.geometry, model.coef, model.liquid
    nu_cst, rho = liq.kinematic_viscosity * 1e6, liq.density
    e = 1.0 / (2.0 - c.beta)
    k_lfg = (c.a1 * (g.module * 1e3) ** ((1 - c.beta) * e) * nu_cst ** (-c.beta * e)
             * (2e12 / (c.k * c.a2 * rho)) ** e * LPM)
    k_c = (c.c1 * (g.commutation_diameter * 1e3 * g.clearance_satellites * 1e6) ** c.c2
           * (1 / (rho * nu_cst * c.c3)) ** c.gamma * MPA ** -c.gamma)
    h0 = 0.5 * (g.clearance_rotor + g.clearance_satellites)
    slope = (c.d_c * g.height * 1e3 + c.d_k) * 1e-12
    m2h, qt = g.m2h, g.displacement_cm3_per_rev
    cm3min = 1e-6 / 60.0
    dp_i = dp - ((c.c_t / LPM ** 2) * rho * flow + (c.c_l / LPM) * rho * nu_cst * 1e-3) * flow
    h = h0 - slope * dp_i
    q_lfg = k_lfg * (h * h * h * dp_i) ** e
    q_c = k_c * dp_i ** c.gamma
    x = np.maximum(flow - q_lfg - q_c, 0.0) * (2 * np.sqrt(RPM) / cm3min)
    b = c.c_id * m2h
    root = x / (np.sqrt((2 / np.sqrt(RPM)) * (qt + (model.c * m2h / MPA) * dp_i) * x + b * b) + b)
    n = root * root
    ps = dp_i * n * (m2h * cm3min / (MPA * RPM))
    fc, dch, bl = model.c_fc_beta * ps, model.c_dch * ps, model.c_b * ps
    ine = (c.c_id * m2h * cm3min / np.sqrt(RPM)) * np.sqrt(n)
    total = q_lfg + q_c + fc + dch + bl + ine
    return n, flow / g.displacement - n, dp_i, q_lfg, q_c, fc, dch, bl, ine, total


def best_time(fn, repeat: int) -> float:
    """Return the best wall time of `repeat` calls, [s]."""
    best = float('inf')
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    """Run the benchmark and print points per second and ratios to the floor."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--points', type=int, default=10**6)
    parser.add_argument('--repeat', type=int, default=7)
    args = parser.parse_args()
    rng = np.random.default_rng(20261122)
    n_pts = args.points
    flow = rng.uniform(2.0, 45.0, n_pts) * LPM  # across the paper's 5..40 l/min
    dp = rng.uniform(4.0, 25.0, n_pts) * MPA  # above the channel drop at 45 l/min
    speed = rng.uniform(50.0, 1500.0, n_pts) * RPM
    model = MotorModel.default('water')
    model39 = MotorModel.default('water', 'eq39')

    check = model.speed(flow[:1000], dp[:1000])
    np.testing.assert_allclose(floor(model, flow[:1000], dp[:1000])[0], check.speed, rtol=1e-9)

    def full(m, fn):
        op = fn()
        return op.speed, op.speed_loss, op.losses.total

    cases = [
        ('floor: fused numpy, breakdown + speed', lambda: floor(model, flow, dp)),
        ('speed(): breakdown + closed-form eq. (40)',
         lambda: full(model, lambda: model.speed(flow, dp))),
        ('speed(): iterative, eq. (39)',
         lambda: full(model39, lambda: model39.speed(flow, dp))),
        ('speed(): iterative, eq. (33) forced',
         lambda: full(model, lambda: model.speed(flow, dp, method='iterative'))),
        ('absorbency(): dp_ich coupled to Q, iterative',
         lambda: full(model, lambda: model.absorbency(speed, dp))),
    ]
    print(f'satmotor_ros model benchmark: {n_pts:,} points, best of {args.repeat}, '
          f'numpy {np.__version__}, Python {platform.python_version()}, {platform.machine()}')
    print(f'{"case":48s} {"time [ms]":>10s} {"points/s":>12s} {"x floor":>8s}')
    floor_time = None
    for name, fn in cases:
        elapsed = best_time(fn, args.repeat)
        floor_time = floor_time or elapsed
        print(f'{name:48s} {elapsed * 1e3:10.1f} {n_pts / elapsed:12.3g} '
              f'{elapsed / floor_time:8.2f}')


if __name__ == '__main__':
    main()
