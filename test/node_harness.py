# SPDX-License-Identifier: Apache-2.0
"""
A test-side ROS harness: own Context, real publishers and subscribers, waits with deadlines.

Used by the node tests; the node under test runs in a separate process (or, for the
in-process tests, on this harness's executor).
"""

import math
import os
import subprocess
import time
import uuid

from diagnostic_msgs.msg import DiagnosticArray
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from satmotor_ros.interface import (CHANNELS, JOINT_NAME, LOSS_COMPONENTS, LOSSES_ARRAY,
                                    LOSSES_PREFIX, PREDICTED_JOINT_STATE, SPEED_RESIDUAL)
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64, Float64MultiArray


def spin_until(executor, condition, timeout=20.0):
    """
    Spin `executor` until `condition()` holds or the deadline passes.

    Parameters
    ----------
    executor : rclpy.executors.Executor
        What to spin, [-]
    condition : callable
        Returns True when done, [-]
    timeout : float
        Deadline, [s]

    Returns
    -------
    bool
        Whether the condition held, [-]

    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        executor.spin_once(timeout_sec=0.01)
    return condition()


def monitor_node(context, executor, namespace, parameters):
    """Start a motor_monitor node in-process with `parameters` (name -> value) on `executor`."""
    from satmotor_ros.nodes.motor_monitor import MotorMonitorNode
    node = MotorMonitorNode(context=context, namespace=namespace, parameter_overrides=[
        Parameter(k, value=v) for k, v in parameters.items()])
    executor.add_node(node)
    return node


def unique_namespace(tag):
    """
    Return a namespace no parallel test run can share.

    Parameters
    ----------
    tag : str
        Readable part, [-]

    Returns
    -------
    str
        E.g. ``'/t_3f2a.../tag'``, [-]

    """
    return f'/t_{uuid.uuid4().hex[:12]}/{tag}'


class Motor:
    """The harness's view of one motor: publishers of its inputs, inboxes of its outputs."""

    def __init__(self, node, namespace, joint=JOINT_NAME):
        """Create the publishers and subscriptions under `namespace`."""
        self.node, self.ns, self.joint = node, namespace, joint
        sensor = qos_profile_sensor_data

        def topic(name):
            return f'{namespace}/{CHANNELS[name].topic}'
        self.flow = node.create_publisher(Float64, topic('flow'), 10)
        self.p_in = node.create_publisher(FluidPressure, topic('p_in'), sensor)
        self.p_out = node.create_publisher(FluidPressure, topic('p_out'), sensor)
        self.p_case = node.create_publisher(FluidPressure, topic('p_case'), sensor)
        self.temp = node.create_publisher(Temperature, topic('temperature'), sensor)
        self.joints = node.create_publisher(JointState, topic('measured_speed'), sensor)
        self.predicted, self.residual, self.diagnostics = [], [], []
        self.losses = {c: [] for c in LOSS_COMPONENTS}
        self.losses_array = []
        node.create_subscription(JointState, f'{namespace}/{PREDICTED_JOINT_STATE}',
                                 self.predicted.append, 100)
        node.create_subscription(Float64, f'{namespace}/{SPEED_RESIDUAL}', self.residual.append,
                                 100)
        for c in LOSS_COMPONENTS:
            node.create_subscription(Float64, f'{namespace}/{LOSSES_PREFIX}{c}',
                                     self.losses[c].append, 100)
        node.create_subscription(Float64MultiArray, f'{namespace}/{LOSSES_ARRAY}',
                                 self.losses_array.append, 100)

    def inputs(self, p_in=None, p_out=None, p_case=None, temperature=None, speed=None):
        """Publish each input that is given, in SI units."""
        for pub, value in ((self.p_in, p_in), (self.p_out, p_out), (self.p_case, p_case)):
            if value is not None:
                pub.publish(FluidPressure(fluid_pressure=float(value)))
        if temperature is not None:
            self.temp.publish(Temperature(temperature=float(temperature)))
        if speed is not None:
            self.joints.publish(JointState(name=['other', self.joint], velocity=[0.0, speed]))

    def clear(self):
        """Forget what was received."""
        self.predicted.clear()
        self.residual.clear()
        self.diagnostics.clear()
        for inbox in self.losses.values():
            inbox.clear()
        self.losses_array.clear()


class Harness:
    """Own Context, node and executor; spin with deadlines."""

    def __init__(self):
        """Start a context in this process."""
        self.context = Context()
        self.context.init()
        self.node = Node(f'harness_{uuid.uuid4().hex[:8]}', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.motors = []
        self.clients = {}
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self._on_diag, 100)
        self.clock = self.node.create_publisher(Clock, '/clock', 10)

    def _on_diag(self, msg):
        for status in msg.status:
            for motor in self.motors:
                if status.name.startswith(motor.ns + '/'):
                    motor.diagnostics.append(status)

    def motor(self, namespace, joint=JOINT_NAME):
        """
        Attach a motor's topics.

        Parameters
        ----------
        namespace : str
            The node's namespace, [-]
        joint : str
            Its joint name, [-]

        Returns
        -------
        Motor
            The motor's publishers and inboxes, [-]

        """
        motor = Motor(self.node, namespace, joint)
        self.motors.append(motor)
        return motor

    def spin_until(self, condition, timeout=10.0):
        """Spin until `condition()` holds or `timeout` [s] passes; tell whether it held."""
        return spin_until(self.executor, condition, timeout)

    def spin_for(self, duration):
        """Spin for `duration` seconds."""
        deadline = time.monotonic() + duration
        while time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.01)

    def wait_connected(self, motor, timeout=20.0):
        """Wait until the node's subscriptions and publishers are matched with ours."""
        assert self.spin_until(lambda: motor.flow.get_subscription_count() > 0
                               and motor.p_in.get_subscription_count() > 0
                               and motor.joints.get_subscription_count() > 0
                               and self.node.count_publishers(
                                   f'{motor.ns}/{PREDICTED_JOINT_STATE}') > 0
                               and (self.node.count_publishers(
                                   f'{motor.ns}/{LOSSES_PREFIX}total') > 0
                                    or self.node.count_publishers(
                                        f'{motor.ns}/{LOSSES_ARRAY}') > 0), timeout), \
            f'node in {motor.ns} not connected within {timeout} s'

    def set_parameters(self, node_name, **values):
        """
        Set parameters of a remote node through its parameter service.

        Parameters
        ----------
        node_name : str
            Fully qualified node name, [-]
        **values : Any
            Parameter values, [-]

        Returns
        -------
        list
            One SetParametersResult per parameter, [-]

        """
        if node_name not in self.clients:  # destroyed with the harness node
            self.clients[node_name] = AsyncParameterClient(self.node, node_name)
        client = self.clients[node_name]
        assert self.spin_until(lambda: client.services_are_ready(), 20.0), \
            f'no parameter services of {node_name}'
        future = client.set_parameters([Parameter(k, value=v) for k, v in values.items()])
        assert self.spin_until(future.done, 10.0), 'set_parameters did not answer'
        return future.result().results

    def close(self):
        """Shut the executor and the context down."""
        self.executor.shutdown()
        self.node.destroy_node()
        self.context.try_shutdown()


def start_node(executable, namespace, env, cwd, *ros_args):
    """
    Start the node executable in its own process, as ``ros2 run`` would.

    Parameters
    ----------
    executable : pathlib.Path
        The installed executable, [-]
    namespace : str
        Namespace to push it into, [-]
    env : dict
        Its environment, [-]
    cwd : pathlib.Path
        Its working directory, [-]
    *ros_args : str
        More ``--ros-args`` arguments, e.g. ``'-p', 'liquid:=water'``, [-]

    Returns
    -------
    subprocess.Popen
        The process; stdout and stderr go to a file in `cwd`, [-]

    """
    log = open(cwd / f'node_{uuid.uuid4().hex[:8]}.log', 'w+')  # closed by stop_node
    env = dict(env, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    assert env.get('ROS_DOMAIN_ID'), 'ROS_DOMAIN_ID must be set'
    proc = subprocess.Popen([str(executable), '--ros-args', '-r', f'__ns:={namespace}',
                             *ros_args], cwd=cwd, env=env, stdout=log,
                            stderr=subprocess.STDOUT)
    proc.log = log
    return proc


def stop_node(proc, timeout=10.0):
    """
    Stop a node process with SIGINT, as Ctrl-C would, and return its output.

    Parameters
    ----------
    proc : subprocess.Popen
        The process, [-]
    timeout : float
        Grace period before it is killed, [s]

    Returns
    -------
    tuple
        Exit code and the process's output, [-]

    """
    if proc.poll() is None:
        proc.send_signal(2)
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout)
    proc.log.seek(0)
    output = proc.log.read()
    proc.log.close()
    os.unlink(proc.log.name)
    return proc.returncode, output


def finite(values):
    """Return True when every value is a finite number."""
    return all(math.isfinite(v) for v in values)
