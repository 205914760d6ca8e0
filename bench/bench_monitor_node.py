# SPDX-License-Identifier: Apache-2.0
"""
Benchmark the motor_monitor node's CPU per sample at 100 Hz input.

The node runs in a process of its own (from this source tree, the packaged oil motor as
baseline, learning for ``--learn-hours``); this process plays a synthetic recording of the
packaged motor (``identify.synthetic.generate_series``) onto its topics at ``--rate``:
``inlet_pressure``, ``outlet_pressure``, ``case_pressure``, ``fluid_temperature``,
``flow_measured`` and ``joint_states`` per sample, six messages. Reported: the node
process's CPU time (/proc) per sample it took, the estimator's own share
(``HealthMonitor.update`` on the same samples in blocks of one update period, timed here),
the share of one core, and the floor: a bare node subscribing the same six topics with
callbacks that do nothing, fed the same way (what rclpy costs before any work).

Run: ``ROS_DOMAIN_ID=.. python bench/bench_monitor_node.py [--seconds 60] [--rate 100]``.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import sys
import time
import uuid

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # this source tree's satmotor_ros

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
import node_process  # noqa: E402
from rclpy.qos import qos_profile_sensor_data  # noqa: E402
from satmotor_ros.identify.health import (Baseline, HealthMonitor, HealthSamples,  # noqa: E402
                                          HealthSettings)
from satmotor_ros.identify.synthetic import generate_series, Injection, Plan  # noqa: E402
from satmotor_ros.interface import CHANNELS, DIAGNOSTICS, JOINT_NAME  # noqa: E402
from satmotor_ros.model.units import ATMOSPHERE  # noqa: E402
from sensor_msgs.msg import FluidPressure, JointState, Temperature  # noqa: E402
from std_msgs.msg import Float64  # noqa: E402

PACKAGED = ROOT / 'config' / 'sm075_25.yaml'


def run_floor() -> None:
    """Subscribe the six topics with empty callbacks (the child process of the floor)."""
    import rclpy
    rclpy.init()
    node = rclpy.create_node('floor')
    for kind, name in ((FluidPressure, 'p_in'), (FluidPressure, 'p_out'),
                       (FluidPressure, 'p_case'), (Temperature, 'temperature'),
                       (Float64, 'flow_measured'), (JointState, 'measured_speed')):
        node.create_subscription(kind, CHANNELS[name].topic, lambda msg: None,
                                 qos_profile_sensor_data)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def estimator_us(samples: HealthSamples, block: int, learn_hours: float) -> float:
    """Return the estimator's own cost per sample fed in blocks of `block`, [us]."""
    monitor = HealthMonitor(Baseline.load(PACKAGED, 'oil'), HealthSettings(
        learn_hours=learn_hours))
    start = time.process_time()
    for i in range(0, len(samples), block):
        monitor.update(samples.take(slice(i, i + block)))
        monitor.pop_points()
    return (time.process_time() - start) / len(samples) * 1e6


def measure(seconds: float, rate: float, learn_hours: float,
            floor: bool = False) -> dict[str, float]:
    """
    Start the node, play the recording onto its topics at `rate`, and read its CPU.

    Parameters
    ----------
    seconds : float
        Length of the measurement, [s]
    rate : float
        Samples per second, [Hz]
    learn_hours : float
        The node's learning time, [h]
    floor : bool
        Measure the bare subscriber instead of the node, [-]

    Returns
    -------
    dict
        samples sent and taken, node CPU per sample [us], estimator share [us], core share.

    """
    n = int(seconds * rate)
    table = generate_series(Plan(), [Injection()], seed=1, samples=n, rate=rate)
    samples = HealthSamples.from_table(table)
    namespace = f'/bench_{uuid.uuid4().hex[:8]}'
    code = ('import sys; sys.path.insert(0, %r); import bench_monitor_node as b; '
            'b.run_floor()' % str(ROOT / 'bench')) if floor else \
        'from satmotor_ros.nodes.motor_monitor import main; main()'
    params = [] if floor else ['-p', f'motor_file:={PACKAGED}', '-p',
                               f'learn_hours:={learn_hours}', '-p', 'diagnostics_period:=1.0']
    proc = node_process.start(code, '-r', f'__ns:={namespace}', *params)
    with node_process.driver(proc) as (node, executor):
        sensor = qos_profile_sensor_data
        pressure = {name: node.create_publisher(
            FluidPressure, f'{namespace}/{CHANNELS[name].topic}', sensor)
            for name in ('p_in', 'p_out', 'p_case')}
        flow = node.create_publisher(Float64, f'{namespace}/{CHANNELS["flow_measured"].topic}',
                                     sensor)
        temperature = node.create_publisher(
            Temperature, f'{namespace}/{CHANNELS["temperature"].topic}', sensor)
        joint = node.create_publisher(
            JointState, f'{namespace}/{CHANNELS["measured_speed"].topic}', sensor)
        taken = [0]

        def on_diagnostics(msg: DiagnosticArray) -> None:
            for status in msg.status:
                if status.name.startswith(namespace):
                    taken[0] = int({kv.key: kv.value for kv in status.values}['samples taken'])
        node.create_subscription(DiagnosticArray, DIAGNOSTICS, on_diagnostics, 10)
        node_process.spin_until(executor, lambda: bool(joint.get_subscription_count()))
        time.sleep(1.0)  # the node's own start-up, outside the measurement
        cpu0, taken0 = node_process.cpu_seconds(proc.pid), taken[0]

        def publish(k: int) -> None:
            for name, values in (('p_in', samples.p_in), ('p_out', samples.p_out),
                                 ('p_case', samples.p_case)):
                pressure[name].publish(FluidPressure(
                    fluid_pressure=float(values[k]) + ATMOSPHERE))
            temperature.publish(Temperature(temperature=float(samples.temperature[k])))
            flow.publish(Float64(data=float(samples.flow[k])))
            msg = JointState(name=[JOINT_NAME], velocity=[float(samples.speed[k])])
            msg.header.stamp = node.get_clock().now().to_msg()
            joint.publish(msg)

        # drain 2.5 s: the last update and diagnostics
        node_process.spin_feeding(executor, node_process.on_schedule(rate, n, publish), 2.5)
        cpu = node_process.cpu_seconds(proc.pid) - cpu0
    got = n if floor else max(taken[0] - taken0, 1)
    own = estimator_us(samples, max(1, int(rate)), learn_hours)
    return {'sent': n, 'taken': got, 'cpu_us': cpu / got * 1e6, 'estimator_us': own,
            'core': cpu / seconds}


def main() -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seconds', type=float, default=60.0)
    parser.add_argument('--rate', type=float, default=100.0)
    parser.add_argument('--learn-hours', type=float, default=0.005,
                        help='short, so that most of the run is past learning')
    args = parser.parse_args()
    r = measure(args.seconds, args.rate, args.learn_hours)
    print(f'{args.rate:g} Hz for {args.seconds:g} s (load {os.getloadavg()[0]:.1f}): '
          f'{r["taken"]} of {r["sent"]} samples taken; node CPU {r["cpu_us"]:.0f} us/sample '
          f'({100 * r["core"]:.1f} % of a core), of which the estimator '
          f'{r["estimator_us"]:.1f} us/sample')
    bare = measure(args.seconds, args.rate, args.learn_hours, floor=True)
    print(f'floor, a bare subscriber of the six topics: {bare["cpu_us"]:.0f} us/sample '
          f'({100 * bare["core"]:.1f} % of a core); node/floor '
          f'{r["cpu_us"] / bare["cpu_us"]:.2f}x (load {os.getloadavg()[0]:.1f})')


if __name__ == '__main__':
    main()
