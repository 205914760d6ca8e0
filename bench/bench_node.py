# SPDX-License-Identifier: Apache-2.0
"""
Benchmark the motor_model node's input-to-output latency against a bare relay node.

Two node processes are measured one after the other in the same run, each fed
``flow_command`` at 1 kHz (and the pressures at 100 Hz) from this process:
- relay: subscribes ``flow_command`` and publishes the same message on ``relay_out``,
  no computation (the floor of rclpy's take -> callback -> publish path);
- motor_model: the node, from this source tree, publishing ``predicted_joint_state``.
Latency is the time from publishing a flow_command to receiving its output here (one
monotonic clock for all processes). Each output is matched to its input by value: the
flows are all distinct and the predicted speed grows with the flow, so a lost message
is a drop, not a shifted pairing. Reported: p50/p99 latency, the ratio to the relay,
drops, and the node process's CPU time per input message (/proc).

Run: ``ROS_DOMAIN_ID=.. python bench/bench_node.py [--seconds 30] [--rate 1000]
[--param losses_format:=array] [--rounds 5]``.
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

import node_process  # noqa: E402
import numpy as np  # noqa: E402
import rclpy  # noqa: E402
from rclpy.node import Node  # noqa: E402
from satmotor_ros.model import MotorModel  # noqa: E402
from satmotor_ros.model.units import LPM, MPA  # noqa: E402
from sensor_msgs.msg import FluidPressure, JointState  # noqa: E402
from std_msgs.msg import Float64  # noqa: E402

P_IN, P_OUT = 20 * MPA, 0.2 * MPA


class Relay(Node):
    """Subscribe flow_command, publish it unchanged on relay_out: no computation."""

    def __init__(self) -> None:
        """Create the subscription and the publisher."""
        super().__init__('relay')
        self.pub = self.create_publisher(Float64, 'relay_out', 10)
        self.create_subscription(Float64, 'flow_command', self.pub.publish, 10)


def run_relay() -> None:
    """Spin the relay node (the child process)."""
    rclpy.init()
    node = Relay()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def measure(kind: str, seconds: float, rate: float, namespace: str,
            parameters: tuple[str, ...] = ()) -> dict[str, float]:
    """
    Start one node process, feed it, and measure its latency.

    Parameters
    ----------
    kind : {'relay', 'motor_model'}
        Which node, [-]
    seconds : float
        Length of the measurement, [s]
    rate : float
        flow_command rate, [Hz]
    namespace : str
        Namespace of the node, [-]
    parameters : tuple of str
        ``name:=value`` parameters of the node, [-]

    Returns
    -------
    dict
        p50, p99 [ms], drops, sent, cpu per message [us].

    """
    code = ('import sys; sys.path.insert(0, %r); import bench_node; bench_node.run_relay()'
            % str(ROOT / 'bench')) if kind == 'relay' else \
        'from satmotor_ros.nodes.motor_model import main; main()'
    extra = [arg for p in parameters for arg in ('-p', p)]
    proc = node_process.start(code, '-r', f'__ns:={namespace}', *extra)
    n = int(seconds * rate)
    flows = (5.0 + 30.0 * np.arange(n) / n) * LPM
    received: list[tuple[int, float]] = []
    sent = np.zeros(n, dtype=np.int64)
    with node_process.driver(proc) as (node, executor):
        flow_pub = node.create_publisher(Float64, f'{namespace}/flow_command', 10)
        p_in = node.create_publisher(FluidPressure, f'{namespace}/inlet_pressure', 10)
        p_out = node.create_publisher(FluidPressure, f'{namespace}/outlet_pressure', 10)
        if kind == 'relay':
            output = f'{namespace}/relay_out'
            node.create_subscription(Float64, output,
                                     lambda m: received.append((time.monotonic_ns(), m.data)),
                                     10)
        else:
            output = f'{namespace}/predicted_joint_state'
            node.create_subscription(
                JointState, output,
                lambda m: received.append((time.monotonic_ns(), m.velocity[0])), 10)
        node_process.spin_until(executor, lambda: bool(
            flow_pub.get_subscription_count() and node.count_publishers(output)))
        for _ in range(20):  # the pressures arrive before the first flow_command
            p_in.publish(FluidPressure(fluid_pressure=P_IN))
            p_out.publish(FluidPressure(fluid_pressure=P_OUT))
            executor.spin_once(timeout_sec=0.01)
        cpu0 = node_process.cpu_seconds(proc.pid)

        def publish(k: int) -> None:
            if k % max(1, int(rate / 100)) == 0:
                p_in.publish(FluidPressure(fluid_pressure=P_IN))
                p_out.publish(FluidPressure(fluid_pressure=P_OUT))
            sent[k] = time.monotonic_ns()
            flow_pub.publish(Float64(data=flows[k]))

        node_process.spin_feeding(executor, node_process.on_schedule(rate, n, publish), 1.0)
        cpu = node_process.cpu_seconds(proc.pid) - cpu0
    if kind == 'relay':
        keys = flows
    else:
        keys = MotorModel.default('oil').speed(flows, P_IN - P_OUT).speed
    values = np.array([v for _, v in received])
    index = np.clip(np.searchsorted(keys, values), 0, n - 1)
    left = np.clip(index - 1, 0, n - 1)
    index = np.where(np.abs(keys[left] - values) < np.abs(keys[index] - values), left, index)
    latency = (np.array([t for t, _ in received]) - sent[index]) / 1e6
    return {'p50': float(np.percentile(latency, 50)), 'p99': float(np.percentile(latency, 99)),
            'sent': n, 'drops': n - len(np.unique(index)), 'cpu_us': cpu / n * 1e6}


def main() -> None:
    """Measure the relay, then the node, and print the comparison."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seconds', type=float, default=30.0)
    parser.add_argument('--rate', type=float, default=1000.0)
    parser.add_argument('--param', action='append', default=[], metavar='NAME:=VALUE',
                        help='a motor_model parameter, e.g. losses_format:=array (repeatable)')
    parser.add_argument('--rounds', type=int, default=1,
                        help='relay and node measured in turn this many times; the ratios of '
                             'each round and their median (a shared machine drifts)')
    args = parser.parse_args()
    ns = f'/bench_{uuid.uuid4().hex[:8]}'
    print(f'{args.rate:g} Hz for {args.seconds:g} s, {" ".join(args.param) or "defaults"}, '
          f'ROS_DOMAIN_ID {os.environ.get("ROS_DOMAIN_ID", "0")}')
    print(f'{"node":12s} {"p50 [ms]":>9s} {"p99 [ms]":>9s} {"sent":>7s} {"drops":>6s} '
          f'{"CPU/msg [us]":>13s}')
    ratios = []
    for k in range(args.rounds):
        relay = measure('relay', args.seconds, args.rate, f'{ns}/relay{k}')
        model = measure('motor_model', args.seconds, args.rate, f'{ns}/motor{k}',
                        tuple(args.param))
        for name, r in (('relay', relay), ('motor_model', model)):
            print(f'{name:12s} {r["p50"]:9.3f} {r["p99"]:9.3f} {r["sent"]:7d} {r["drops"]:6d} '
                  f'{r["cpu_us"]:13.1f}')
        ratios.append([model[key] / relay[key] for key in ('p50', 'p99', 'cpu_us')])
        print(f'ratio motor_model/relay: p50 {ratios[-1][0]:.2f}x, p99 {ratios[-1][1]:.2f}x, '
              f'CPU/msg {ratios[-1][2]:.2f}x (load {os.getloadavg()[0]:.1f})')
    if args.rounds > 1:
        p50, p99, cpu = np.median(ratios, axis=0)
        print(f'median of {args.rounds} rounds: p50 {p50:.2f}x, p99 {p99:.2f}x, '
              f'CPU/msg {cpu:.2f}x')


if __name__ == '__main__':
    main()
