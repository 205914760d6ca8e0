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
    k_p = model.c_lumped * m2h / MPA
    root = x / (np.sqrt((2 / np.sqrt(RPM)) * (qt + k_p * dp_i) * x + b * b) + b)
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
         lambda: full(model, lambda: model.speed(flow, dp, errors='mask'))),
        ('speed(): iterative, eq. (39)',
         lambda: full(model39, lambda: model39.speed(flow, dp, errors='mask'))),
        ('speed(): iterative, eq. (33) forced',
         lambda: full(model, lambda: model.speed(flow, dp, method='iterative', errors='mask'))),
        ('absorbency(): dp_ich coupled to Q, iterative',
         lambda: full(model, lambda: model.absorbency(speed, dp, errors='mask'))),
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


def per_call(fn, args: list[tuple], repeat: int) -> float:
    """Return the best time per call of `fn` over the argument list, [s]."""
    def run() -> None:
        for a in args:
            fn(*a)
    return best_time(run, repeat) / len(args)


def single_points(repeat: int) -> None:
    """Time one operating point per call: the point path against the array maps."""
    from satmotor_ros.model import load_motor, MotorModel
    rng = np.random.default_rng(7)
    count = 2000
    flow = (rng.uniform(2.0, 45.0, count) * LPM).tolist()
    dp = (rng.uniform(4.0, 25.0, count) * MPA).tolist()
    speed = (rng.uniform(50.0, 1500.0, count) * RPM).tolist()
    spec = load_motor()
    print(f'\nsingle operating points: {count} per run, best of {repeat}, microseconds per call')
    print(f'{"case":58s} {"point":>7s} {"array":>7s} {"ratio":>6s}')
    for law in ('eq33', 'eq39'):
        m = MotorModel.from_spec(spec, 'water', None, law)
        warm = [(n, p, m.absorbency_point(n, p).flow * 1.001) for n, p in zip(speed, dp)]
        cases = [
            (f'speed_point(Q, dp), {law}', m.speed_point, m.speed, list(zip(flow, dp))),
            (f'speed_point(Q, dp_i=), {law}', lambda q, p: m.speed_point(q, dp_i=p),
             lambda q, p: m.speed(q, dp_i=p), list(zip(flow, dp))),
            (f'absorbency_point(n, dp), cold start, {law}', m.absorbency_point, m.absorbency,
             list(zip(speed, dp))),
            (f'absorbency_point(n, dp), flow_guess 0.1 % off, {law}',
             lambda n, p, g: m.absorbency_point(n, p, flow_guess=g),
             lambda n, p, g: m.absorbency(n, p), warm),
            (f'breakdown_point(n, dp_i), {law}', m.breakdown_point, m.breakdown,
             list(zip(speed, dp))),
        ]
        for name, point, array, args in cases:
            t_point = per_call(point, args, repeat)
            t_array = per_call(array, args[:200], max(1, repeat // 3))
            print(f'{name:58s} {t_point * 1e6:7.2f} {t_array * 1e6:7.1f} '
                  f'{t_array / t_point:6.0f}')
    water = spec.sets['water']
    t_ctor = per_call(lambda: MotorModel(spec.geometry, water, spec.valid_range), [()] * 500,
                      repeat)
    print(f'{"MotorModel(...) construction":58s} {t_ctor * 1e6:7.2f}')


if __name__ == '__main__':
    main()
    single_points(7)
