# SPDX-License-Identifier: Apache-2.0
"""A live run recorded into a bag and replayed gives the numbers the node published."""

import csv

from node_harness import unique_namespace
import numpy as np
from rclpy.qos import qos_profile_sensor_data
from satmotor_ros.bags import OutTopic, write_bag
from satmotor_ros.cli.main import main
from satmotor_ros.interface import FLOAT64, FLUID_PRESSURE, JOINT_STATE
from satmotor_ros.interface import LOSS_COMPONENTS as COMPONENTS
from satmotor_ros.model.units import LPM, MPA
from satmotor_ros.nodes.motor_model import MotorModelNode
from sensor_msgs.msg import FluidPressure, JointState
from std_msgs.msg import Float64


class Recorder:
    """Record serialised messages with their receive time, as ``ros2 bag record`` does."""

    def __init__(self, harness, topics):
        """Subscribe to (topic, type, msgtype name, qos) raw."""
        self.harness, self.messages = harness, {}
        for name, kind, msgtype, qos in topics:
            self.messages[name] = (msgtype, [], [])
            harness.node.create_subscription(kind, name, self._keep(name), qos, raw=True)

    def _keep(self, name):
        def keep(data):
            _, times, payloads = self.messages[name]
            times.append(self.harness.node.get_clock().now().nanoseconds)
            payloads.append(bytes(data))
        return keep

    def write(self, path):
        """Write what was recorded into an MCAP bag."""
        write_bag(path, [OutTopic(name, msgtype, np.array(times, dtype=np.int64), payloads)
                         for name, (msgtype, times, payloads) in self.messages.items()
                         if times])


def test_live_run_recorded_and_replayed_gives_identical_predictions(harness, tmp_path):
    ns = unique_namespace('live')
    node = MotorModelNode(context=harness.context, namespace=ns)
    harness.executor.add_node(node)
    sensor = qos_profile_sensor_data
    recorder = Recorder(harness, [
        (f'{ns}/flow_command', Float64, FLOAT64, 10),
        (f'{ns}/inlet_pressure', FluidPressure, FLUID_PRESSURE, sensor),
        (f'{ns}/outlet_pressure', FluidPressure, FLUID_PRESSURE, sensor),
        (f'{ns}/joint_states', JointState, JOINT_STATE, sensor)])
    try:
        motor = harness.motor(ns)
        harness.wait_connected(motor)
        assert harness.spin_until(lambda: harness.node.count_subscribers(
            f'{ns}/inlet_pressure') >= 2, 10.0)
        rng = np.random.default_rng(11)
        steps = 25
        for k in range(steps):
            p_in = rng.uniform(5, 25) * MPA
            p_out = -MPA if k in (7, 8) else rng.uniform(0.1, 1.0) * MPA
            motor.inputs(p_in=p_in, p_out=p_out, speed=float(rng.uniform(20, 150)))
            harness.spin_for(0.05)
            motor.flow.publish(Float64(data=float(rng.uniform(2, 40)) * LPM))
            harness.spin_for(0.05)
        assert harness.spin_until(lambda: len(recorder.messages[f'{ns}/flow_command'][1])
                                  == steps, 5.0)
        harness.spin_for(0.2)
    finally:
        harness.executor.remove_node(node)
        node.destroy_node()
    live = [m.velocity[0] for m in motor.predicted]
    assert len(live) == steps - 2  # steps 7 and 8 (p_out < 0 absolute) are rejected
    recorder.write(tmp_path / 'live')
    out = tmp_path / 'replay.csv'
    assert main(['replay', str(tmp_path / 'live'), '--liquid', 'oil',
                 '--out', str(out), '--no-plot']) == 0
    with open(out, newline='') as stream:
        rows = list(csv.DictReader(stream))
    published = [r for r in rows if r['level'] != 'ERROR']
    assert len(rows) == steps and len(published) == len(live)
    assert [r['inputs'] for r in rows[7:9]] == ['outlet_pressure:NEGATIVE'] * 2
    np.testing.assert_allclose([float(r['speed [rad/s]']) for r in published], live,
                               rtol=1e-12)
    for c in COMPONENTS:
        np.testing.assert_allclose([float(r[f'{c} [l/min]']) * LPM for r in published],
                                   [m.data for m in motor.losses[c]], rtol=1e-11, atol=1e-21)
    np.testing.assert_allclose([float(r['residual [rpm]']) for r in published],
                               [m.data / (2 * np.pi / 60) for m in motor.residual], rtol=1e-9)
