# SPDX-License-Identifier: Apache-2.0
"""
Benchmark the plant's 1 ms physics step against the motor's single-point call in the same run.

The floor is ``MotorModel.absorbency_point`` with a warm start at the plant's operating
point: the model evaluation every step must make. The plant adds the implicit line and
shaft solve, the relief valve, heat and (optionally) the sensors. The real-time factor
is dt / (time per step): the target is >= 100 at dt = 1 ms, i.e. < 10 us per step.

Run: ``.venv/bin/python bench/bench_plant.py [--steps N] [--repeat R]``.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
import os
import platform
import sys
import time

os.environ.setdefault('OMP_NUM_THREADS', '1')
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from satmotor_ros.model import MotorModel  # noqa: E402
from satmotor_ros.model.units import LPM  # noqa: E402
from satmotor_ros.plant import (ConstantLoad, Plant, PlantParams, SensorParams,  # noqa: E402
                                SensorSet, ShaftParams)


def best_of(run: Callable[[], None], steps: int, repeat: int) -> float:
    """Return the best time per step over `repeat` runs of `steps` steps, [s]."""
    best = float('inf')
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        best = min(best, (time.perf_counter() - start) / steps)
    return best


def cycle(plant: Plant, steps: int, measure: bool = False) -> Callable[[], None]:
    """Build a run of `steps` steps, flow alternating 10/30 l/min every 0.5 s."""
    low, high = 10.0 * LPM, 30.0 * LPM

    def run() -> None:
        step, read = plant.step, plant.measure
        for i in range(steps):
            step(low if (i // 500) % 2 else high)
            if measure:
                read()
    return run


def main() -> int:
    """Run the cases and print a table; return 0."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--steps', type=int, default=20_000)
    parser.add_argument('--repeat', type=int, default=5)
    args = parser.parse_args()
    steps, repeat = args.steps, args.repeat
    rows = []
    for liquid in ('water', 'oil'):
        model = MotorModel.default(liquid)
        plant = Plant(model, load=ConstantLoad(60.0))
        plant.run(2000, 20.0 * LPM)
        state = plant.state
        dp = state.inlet_pressure - state.outlet_pressure
        guess = float(model.absorbency_point(state.speed, dp).flow)
        point = model.absorbency_point

        def floor(speed: float = state.speed, dp: float = dp, guess: float = guess) -> None:
            for _ in range(steps):
                point(speed, dp, flow_guess=guess)
        rows.append((f'floor: absorbency_point, {liquid}', best_of(floor, steps, repeat)))
        rows.append((f'plant step, {liquid}, 10/30 l/min',
                     best_of(cycle(plant, steps), steps, repeat)))
    water = MotorModel.default('water')
    noisy = SensorSet(*(SensorParams(noise=1.0e-3) for _ in range(6)))
    plant = Plant(water, PlantParams(sensors=noisy), load=ConstantLoad(60.0))
    rows.append(('plant step + all sensors read, water',
                 best_of(cycle(plant, steps, measure=True), steps, repeat)))
    plant = Plant(water, PlantParams(shaft=ShaftParams(locked=True)))
    rows.append(('plant step, water, shaft locked, relief open',
                 best_of(cycle(plant, steps), steps, repeat)))

    print(f'# plant benchmark: best of {repeat} x {steps} steps of 1 ms; '
          f'Python {platform.python_version()}, {platform.machine()}')
    floors = {r[0].split(', ')[1]: r[1] for r in rows if r[0].startswith('floor')}
    print(f'| case | us / step | real-time factor at 1 kHz | x floor ({"water"}) |')
    print('| --- | ---: | ---: | ---: |')
    for name, seconds in rows:
        print(f'| {name} | {seconds * 1e6:.2f} | {1e-3 / seconds:.0f} | '
              f'{seconds / floors["water"]:.2f} |')
    return 0


if __name__ == '__main__':
    sys.exit(main())
