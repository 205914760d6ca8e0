# SPDX-License-Identifier: Apache-2.0
"""
Benchmark the plant's 1 ms physics step against the motor's single-point call in the same run.

The floor is ``MotorModel.absorbency_point`` replaying the very calls (speed, pressure
drop, warm start) the plant makes over the same cycle: the model evaluation every step
must make. The plant adds the implicit line and
shaft solve, the relief valve, heat and (optionally) the sensors. The real-time factor
is dt / (time per step): the target is >= 100 at dt = 1 ms, i.e. < 10 us per step.

The node runs in sim mode as ``rclpy.spin`` runs it (target >= 20x); its baseline is the
plant alone doing the same work (1 kHz steps, readings at 100 Hz) in the same run.

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


LISTENER = """
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.qos import qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from satmotor_ros.nodes._spin import spin
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64
rclpy.init()
node = rclpy.create_node('listener')
for kind, topic in ((FluidPressure, 'inlet_pressure'), (FluidPressure, 'outlet_pressure'),
                    (FluidPressure, 'case_pressure'), (Float64, 'flow_measured'),
                    (JointState, 'joint_states'), (Temperature, 'fluid_temperature'),
                    (Clock, '/clock')):
    node.create_subscription(kind, topic, lambda msg: None, qos_profile_sensor_data)
try:
    spin(node)  # the project's spin: a message taken while SIGINT shuts down ends the run
except (KeyboardInterrupt, ExternalShutdownException):
    pass
"""
"""A subscriber to every sensor topic and /clock, run in its own process (``__ns`` remapped)."""


def node_factor(seconds: float, subscribed: bool) -> tuple[float, float]:
    """
    Run the virtual_motor node in sim mode for `seconds` of wall time, as ``rclpy.spin`` does.

    Parameters
    ----------
    seconds : float
        Wall time of the run, [s]
    subscribed : bool
        Whether a listener process subscribes to every sensor topic and ``/clock``, [-]

    Returns
    -------
    tuple of float
        Real-time factor over wall time, and over the process's CPU time (what the node
        costs; the wall figure also counts what the VM takes away), [-]

    """
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter

    import node_process

    from satmotor_ros.nodes.virtual_motor import VirtualMotorNode

    context = Context()
    context.init()
    executor = SingleThreadedExecutor(context=context)
    namespace = f'/bench_{os.getpid()}'
    listener = motor = None
    try:
        motor = VirtualMotorNode(context=context, namespace=namespace,
                                 parameter_overrides=[
                                     Parameter('clock_mode', value='sim'),
                                     Parameter('load.torque', value=40.0)])
        executor.add_node(motor)
        listener = node_process.start(LISTENER, '-r', f'__ns:={namespace}') \
            if subscribed else None
        if listener is not None and not node_process.spin_until(
                executor, lambda: motor.count_subscribers(f'{namespace}/joint_states') > 0):
            raise RuntimeError('the listener process did not subscribe within 30 s')
        motor._command = 20.0 * LPM
        executor.spin_once()
        sim0, wall0, cpu0 = motor.plant.state.time, time.perf_counter(), time.process_time()
        while time.perf_counter() - wall0 < seconds:
            executor.spin_once()  # no timeout, as in rclpy.spin: the node is always ready
        sim = motor.plant.state.time - sim0
        return sim / (time.perf_counter() - wall0), sim / (time.process_time() - cpu0)
    finally:
        if listener is not None:
            node_process.stop(listener)
        executor.shutdown()
        if motor is not None:
            motor.destroy_node()
        context.try_shutdown()


def plant_factor(seconds: float) -> float:
    """Step the plant alone as the node does (1 kHz, readings at 100 Hz); real-time factor."""
    plant = Plant(MotorModel.default('oil'), load=ConstantLoad(40.0))
    sim0, wall0 = plant.state.time, time.perf_counter()
    while time.perf_counter() - wall0 < seconds:
        for _ in range(10):
            plant.step(20.0 * LPM)
        plant.measure()
    return (plant.state.time - sim0) / (time.perf_counter() - wall0)


def main() -> int:
    """Run the cases and print a table; return 0."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--steps', type=int, default=20_000)
    parser.add_argument('--repeat', type=int, default=5)
    parser.add_argument('--node-seconds', type=float, default=5.0,
                        help='wall time of each node run (0: skip the node)')
    args = parser.parse_args()
    steps, repeat = args.steps, args.repeat
    rows = []
    for liquid in ('water', 'oil'):
        model = MotorModel.default(liquid)
        plant = Plant(model, load=ConstantLoad(60.0))
        plant.run(2000, 20.0 * LPM)
        # the floor replays the very calls the plant makes over the cycle (same warm starts)
        calls = []
        point = model.absorbency_point

        def spy(speed: float, dp: float, flow_guess: float | None = None,
                channels: dict[str, float] | None = None) -> object:
            calls.append((speed, dp, flow_guess))
            return point(speed, dp, flow_guess=flow_guess, channels=channels)
        plant._point = spy
        cycle(plant, steps)()
        plant._point = point

        def floor() -> None:
            for speed, dp, guess in calls:
                point(speed, dp, flow_guess=guess)
        rows.append((f'floor: absorbency_point, {liquid}', best_of(floor, len(calls), repeat)))
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
    print('| case | us / step | real-time factor at 1 kHz | x floor of its liquid |')
    print('| --- | ---: | ---: | ---: |')
    for name, seconds in rows:
        floor = floors['oil' if ', oil' in name else 'water']
        print(f'| {name} | {seconds * 1e6:.2f} | {1e-3 / seconds:.0f} | '
              f'{seconds / floor:.2f} |')
    if args.node_seconds > 0.0:
        print()
        print('| virtual_motor node, sim mode, all topics at 100 Hz, 1 kHz physics '
              '| real-time factor, wall | over CPU time | plant alone, wall | node / plant |')
        print('| --- | ---: | ---: | ---: | ---: |')
        for subscribed in (False, True):
            alone = plant_factor(args.node_seconds)
            wall, cpu = node_factor(args.node_seconds, subscribed)
            who = ('a listener process on the 6 sensor topics and /clock' if subscribed
                   else 'no subscribers')
            print(f'| {who} | {wall:.1f} | {cpu:.1f} | {alone:.0f} | {wall / alone:.2f} |')
    return 0


if __name__ == '__main__':
    sys.exit(main())
