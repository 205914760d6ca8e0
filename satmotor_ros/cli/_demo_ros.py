# SPDX-License-Identifier: Apache-2.0
"""One demo run over ROS: the nodes in one executor, a set-point script and a recorder."""

from __future__ import annotations

import os
from pathlib import Path
import time
from typing import Any, Callable

from diagnostic_msgs.msg import DiagnosticArray
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from satmotor_ros.cli._demo_report import RunResult, write_run_bag
from satmotor_ros.interface import (CHANNELS, CLOCK, DIAGNOSTIC_ARRAY, FLOAT64, MODEL_OUTPUTS,
                                    TOPIC_TYPES)
from satmotor_ros.nodes.motor_model import MotorModelNode
from satmotor_ros.nodes.speed_controller import SpeedControllerNode
from satmotor_ros.nodes.virtual_motor import VirtualMotorNode
from satmotor_ros.plant.scenario import Cycle
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64

_TYPES = {'std_msgs/msg/Float64': Float64, 'sensor_msgs/msg/FluidPressure': FluidPressure,
          'sensor_msgs/msg/JointState': JointState, 'sensor_msgs/msg/Temperature': Temperature,
          'diagnostic_msgs/msg/DiagnosticArray': DiagnosticArray,
          'rosgraph_msgs/msg/Clock': Clock}

CONTROL_RATE = 100.0
"""Rate of the controller and of the set-point script, [Hz]."""

_RELIABLE = {CHANNELS['flow'].topic, CHANNELS['torque'].topic,
             *(t for t in TOPIC_TYPES if t.startswith(MODEL_OUTPUTS))}
RECORDED = (  # topic relative to the run's namespace, type, reliable publisher?
    *((topic, msgtype, topic in _RELIABLE) for topic, msgtype in TOPIC_TYPES.items()),
    ('speed_setpoint', FLOAT64, True), ('/diagnostics', DIAGNOSTIC_ARRAY, True),
    ('/clock', CLOCK, True),
)
"""Every topic of a run, relative to its namespace (DESIGN.md names and types)."""


class Script(Node):
    """Publish the cycle's speed set-point and load torque on simulated time."""

    def __init__(self, cycle: Cycle, **kwargs: Any) -> None:
        """Start the timer on the node clock (use_sim_time)."""
        super().__init__('demo_script', **kwargs)
        self.cycle = cycle
        self._setpoint = self.create_publisher(Float64, 'speed_setpoint', 10)
        self._load = self.create_publisher(Float64, CHANNELS['torque'].topic, 10)
        self.create_timer(1.0 / CONTROL_RATE, self._tick)

    def _tick(self) -> None:
        segment = self.cycle.at(self.get_clock().now().nanoseconds * 1e-9)
        self._setpoint.publish(Float64(data=segment.setpoint))
        self._load.publish(Float64(data=segment.load))


class Recorder(Node):
    """Keep every message of the run as serialised CDR, stamped with simulated time."""

    def __init__(self, topics: list[tuple[str, str, bool]], sim_time: Callable[[], float],
                 **kwargs: Any) -> None:
        """Subscribe raw to every topic, depth 1000 so that nothing is dropped."""
        super().__init__('demo_recorder', **kwargs)
        self.messages: dict[str, list[tuple[int, bytes]]] = {}
        self.types: dict[str, str] = {}
        self._now = sim_time
        for name, msgtype, reliable in topics:
            qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE if reliable
                             else ReliabilityPolicy.BEST_EFFORT)
            key = name if name.startswith('/') else '/' + name
            store = self.messages.setdefault(key, [])
            self.types[key] = msgtype
            self.create_subscription(_TYPES[msgtype], name, self._keeper(store), qos, raw=True)

    def _keeper(self, store: list[tuple[int, bytes]]) -> Callable[[bytes], None]:
        now = self._now

        def keep(data: bytes) -> None:
            store.append((int(round(now() * 1e9)), data))
        return keep


def run_cycle(liquid: str, feedforward: str, cycle: Cycle, effects: dict[str, Any],
              bag: Path, progress: Any) -> RunResult:
    """
    Run the cycle once over ROS and write its bag.

    Parameters
    ----------
    liquid : str
        ``'water'`` or ``'oil'``, [-]
    feedforward : str
        The controller's feed-forward, ``'model'`` or ``'none'``, [-]
    cycle : Cycle
        Set-points and loads, [-]
    effects : dict
        ``effects.<name>`` plant parameters to inject, [-]
    bag : pathlib.Path
        Bag directory to create, [-]
    progress : Progress or None
        Progress bar, [-]

    Returns
    -------
    RunResult
        The recorded run.

    """
    namespace = f'/satmotor_demo_{os.getpid()}/{liquid}_{feedforward}'
    context = Context()
    context.init()
    executor = SingleThreadedExecutor(context=context)
    nodes: list[Node] = []
    try:
        motor = VirtualMotorNode(context=context, namespace=namespace, parameter_overrides=[
            Parameter('clock_mode', value='sim'), Parameter('liquid', value=liquid),
            Parameter('publish_rate', value=CONTROL_RATE),
            *(Parameter(k, value=v) for k, v in effects.items())])
        sim = [Parameter('use_sim_time', value=True)]
        controller = SpeedControllerNode(context=context, namespace=namespace,
                                         parameter_overrides=[
                                             *sim, Parameter('liquid', value=liquid),
                                             Parameter('feedforward', value=feedforward),
                                             Parameter('rate', value=CONTROL_RATE)])
        predictor = MotorModelNode(context=context, namespace=namespace, parameter_overrides=[
            *sim, Parameter('liquid', value=liquid)])
        script = Script(cycle, context=context, namespace=namespace, parameter_overrides=sim)
        recorder = Recorder(list(RECORDED), lambda: motor.plant.state.time, context=context,
                            namespace=namespace)
        nodes = [recorder, script, controller, predictor, motor]
        for node in nodes:
            executor.add_node(node)
        label = f'{liquid}/{"ff" if feedforward == "model" else "pi"}'
        start = time.monotonic()
        plant = motor.plant
        while plant.state.time < cycle.duration:
            executor.spin_once(timeout_sec=0.1)
            if progress is not None:
                progress.show(label, plant.state.time)
        for _ in range(50):  # let the last messages in
            executor.spin_once(timeout_sec=0.0)
        wall = time.monotonic() - start
        sim_seconds = plant.state.time
    finally:
        executor.shutdown()
        for node in nodes:
            node.destroy_node()
        context.try_shutdown()
    if progress is not None:
        progress.run_done(sim_seconds)
    write_run_bag(bag, recorder.messages, recorder.types)
    return RunResult(liquid, feedforward, bag, recorder.messages, recorder.types, wall,
                     sim_seconds)
