# SPDX-License-Identifier: Apache-2.0
"""One demo run over ROS: the nodes in one executor, a set-point script and a recorder."""

from __future__ import annotations

from collections import Counter
import os
from pathlib import Path
import struct
import time
from typing import Any, Callable

from diagnostic_msgs.msg import DiagnosticArray
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from satmotor_ros.bags.custom import LIQUID_KEY, MOTOR_KEY
from satmotor_ros.cli._common import CliError
from satmotor_ros.cli._demo_report import RunResult, write_run_bag
from satmotor_ros.cli._safe_signals import signals_at_safe_points
from satmotor_ros.interface import (CHANNELS, CLOCK, CLOCK_TOPIC, DIAGNOSTIC_ARRAY,
                                    DIAGNOSTICS, FLOAT64, FLUID_PRESSURE, JOINT_STATE,
                                    MODEL_OUTPUTS, SPEED_SETPOINT, TEMPERATURE, TOPIC_TYPES)
from satmotor_ros.nodes.motor_model import MotorModelNode
from satmotor_ros.nodes.speed_controller import SpeedControllerNode
from satmotor_ros.nodes.virtual_motor import VirtualMotorNode
from satmotor_ros.plant.scenario import Cycle
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64

_TYPES = {FLOAT64: Float64, FLUID_PRESSURE: FluidPressure, JOINT_STATE: JointState,
          TEMPERATURE: Temperature, DIAGNOSTIC_ARRAY: DiagnosticArray, CLOCK: Clock}

CONTROL_RATE = 100.0
"""Rate of the controller and of the set-point script, [Hz]."""

LOCKSTEP_WAIT = 2.0
"""Wall time the virtual motor waits for a flow command before it publishes again, [s]."""

DISCOVERY_TIMEOUT = 10.0
"""Longest wait for the run's nodes to find each other, [s]."""

_RELIABLE = {CHANNELS['flow'].topic, CHANNELS['torque'].topic,
             *(t for t in TOPIC_TYPES if t.startswith(MODEL_OUTPUTS))}
RECORDED = (  # topic relative to the run's namespace, type, reliable publisher?
    *((topic, msgtype, topic in _RELIABLE) for topic, msgtype in TOPIC_TYPES.items()),
    (SPEED_SETPOINT, FLOAT64, True), (DIAGNOSTICS, DIAGNOSTIC_ARRAY, True),
    (CLOCK_TOPIC, CLOCK, True),
)
"""Every topic of a run, relative to its namespace (DESIGN.md names and types)."""


class Script(Node):
    """Publish the cycle's speed set-point and load torque on simulated time."""

    def __init__(self, cycle: Cycle, motor: Node | None = None, rate: float = CONTROL_RATE,
                 **kwargs: Any) -> None:
        """Tick at `rate` [Hz] on the node clock (use_sim_time); `motor` takes the case offsets."""
        super().__init__('demo_script', **kwargs)
        self.cycle = cycle
        self._motor = motor
        self._case_offset: float | None = None
        self._setpoint = self.create_publisher(Float64, SPEED_SETPOINT, 10)
        self._load = self.create_publisher(Float64, CHANNELS['torque'].topic, 10)
        self.create_timer(1.0 / rate, self._tick)

    def _tick(self) -> None:
        segment = self.cycle.at(self.get_clock().now().nanoseconds * 1e-9)
        offset = segment.case_offset
        if self._motor is not None and offset is not None and offset != self._case_offset:
            self._motor.set_parameters([Parameter('case.offset', value=offset)])
            self._case_offset = offset
        self._setpoint.publish(Float64(data=segment.setpoint))
        self._load.publish(Float64(data=segment.load))


_STAMPED = frozenset({FLUID_PRESSURE, JOINT_STATE, TEMPERATURE, DIAGNOSTIC_ARRAY, CLOCK})
"""Types whose serialised form starts with a time (a header's stamp or the clock)."""

_TIME = struct.Struct('<iI')


def _leading_time(data: bytes) -> int:
    """
    Read the time a little-endian CDR message starts with (after its 4-byte encapsulation).

    Parameters
    ----------
    data : bytes
        A serialised message of one of the :data:`_STAMPED` types, [-]

    Returns
    -------
    int
        The time, [ns]

    """
    sec, nanosec = _TIME.unpack_from(data, 4)
    return int(sec) * 1_000_000_000 + int(nanosec)


class Recorder(Node):
    """
    Keep every message of the run as serialised CDR, stamped with simulated time.

    A message with a header (and ``/clock``) is logged at its own stamp; any other at the
    last ``/clock`` the recorder took before it, as ``ros2 bag record --use-sim-time`` does.
    The executor serves a node's subscriptions in the order they were made, one message
    each per wait, and ``/clock`` is made first: with the plant in lockstep, each message
    is logged at the period it answers whatever order the executor serves the nodes in.
    """

    def __init__(self, topics: list[tuple[str, str, bool]], **kwargs: Any) -> None:
        """Subscribe raw to every topic, ``/clock`` first, depth 1000 so nothing is dropped."""
        super().__init__('demo_recorder', **kwargs)
        self.messages: dict[str, list[tuple[int, bytes]]] = {}
        self.types: dict[str, str] = {}
        self._clock_ns = 0
        for name, msgtype, reliable in sorted(topics, key=lambda t: t[1] != CLOCK):
            qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE if reliable
                             else ReliabilityPolicy.BEST_EFFORT)
            key = name if name.startswith('/') else '/' + name
            store = self.messages.setdefault(key, [])
            self.types[key] = msgtype
            keep = (self._clock_keeper(store) if msgtype == CLOCK
                    else self._keeper(store, msgtype in _STAMPED))
            self.create_subscription(_TYPES[msgtype], name, keep, qos, raw=True)

    def _clock_keeper(self, store: list[tuple[int, bytes]]) -> Callable[[bytes], None]:
        def keep(data: bytes) -> None:
            self._clock_ns = _leading_time(data)
            store.append((self._clock_ns, data))
        return keep

    def _keeper(self, store: list[tuple[int, bytes]],
                stamped: bool) -> Callable[[bytes], None]:
        def keep(data: bytes) -> None:
            store.append((_leading_time(data) if stamped else self._clock_ns, data))
        return keep

    def until(self, end_ns: int) -> dict[str, list[tuple[int, bytes]]]:
        """
        Give the messages logged at or before a time.

        Parameters
        ----------
        end_ns : int
            Last log time kept, [ns]

        Returns
        -------
        dict
            Topic: list of (log time [ns], CDR bytes).

        """
        return {topic: [m for m in kept if m[0] <= end_ns]
                for topic, kept in self.messages.items()}


def _wait_connected(executor: SingleThreadedExecutor, nodes: list[Node],
                    check: Callable[[], None]) -> None:
    """
    Spin until every publisher of the run is matched by every subscription on its topic.

    The virtual motor is paused meanwhile, so the run starts only when no node can miss
    a message: together with the motor's lockstep, this makes a run repeatable.

    Raises
    ------
    CliError
        If the nodes have not found each other within :data:`DISCOVERY_TIMEOUT`.

    """
    wanted = Counter(sub.topic_name for node in nodes for sub in node.subscriptions)
    publishers = [pub for node in nodes for pub in node.publishers]
    deadline = time.monotonic() + DISCOVERY_TIMEOUT
    while not all(pub.get_subscription_count() >= wanted[pub.topic_name] for pub in publishers):
        if time.monotonic() > deadline:
            missing = sorted({pub.topic_name for pub in publishers
                              if pub.get_subscription_count() < wanted[pub.topic_name]})
            raise CliError(f'the demo nodes did not find each other within '
                           f'{DISCOVERY_TIMEOUT:g} s (unmatched: {", ".join(missing)})')
        executor.spin_once(timeout_sec=0.01)
        check()  # a Ctrl-C is raised here, never inside the executor's internals


def run_cycle(liquid: str, feedforward: str, cycle: Cycle, effects: dict[str, Any],
              bag: Path, progress: Any, rate: float = CONTROL_RATE) -> RunResult:
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
    rate : float
        Rate of the controller, the set-point script and the virtual motor's
        publishing (:data:`CONTROL_RATE`; the demo's), [Hz]

    Returns
    -------
    RunResult
        The recorded run.

    """
    namespace = f'/satmotor_demo_{os.getpid()}/{liquid}_{feedforward}'
    context = Context()
    # /clock and /diagnostics are global names: moved into the run's namespace, so that
    # another demo (or any sim-time system) on the same ROS domain cannot cross this run
    context.init(args=['--ros-args', '-r', f'/clock:={namespace}/clock',
                       '-r', f'/diagnostics:={namespace}/diagnostics'])
    with signals_at_safe_points() as check:  # Ctrl-C between spins, not in a finaliser
        executor = SingleThreadedExecutor(context=context)
        nodes: list[Node] = []
        try:
            motor = VirtualMotorNode(context=context, namespace=namespace, parameter_overrides=[
                Parameter('clock_mode', value='lockstep'), Parameter('paused', value=True),
                Parameter('lockstep_wait', value=LOCKSTEP_WAIT), Parameter('liquid', value=liquid),
                Parameter('publish_rate', value=rate),
                *(Parameter(k, value=v) for k, v in effects.items())])
            sim = [Parameter('use_sim_time', value=True)]
            controller = SpeedControllerNode(context=context, namespace=namespace,
                                             parameter_overrides=[
                                                 *sim, Parameter('liquid', value=liquid),
                                                 Parameter('feedforward', value=feedforward),
                                                 Parameter('rate', value=rate)])
            predictor = MotorModelNode(context=context, namespace=namespace, parameter_overrides=[
                *sim, Parameter('liquid', value=liquid)])
            script = Script(cycle, motor, rate, context=context, namespace=namespace,
                            parameter_overrides=sim)
            recorder = Recorder(list(RECORDED), context=context, namespace=namespace)
            nodes = [recorder, script, controller, predictor, motor]
            for node in nodes:
                executor.add_node(node)
            _wait_connected(executor, nodes, check)
            motor.set_parameters([Parameter('paused', value=False)])
            label = f'{liquid}/{"ff" if feedforward == "model" else "pi"}'
            start = time.monotonic()
            plant = motor.plant
            # two periods past the end: every message that answers the last period is in
            beyond = cycle.duration + 2.0 / rate
            while plant.state.time < beyond:
                executor.spin_once(timeout_sec=0.1)
                check()
                if progress is not None:
                    progress.show(label, min(plant.state.time, cycle.duration))
            wall = time.monotonic() - start
            sim_seconds = cycle.duration
            unanswered = motor.unanswered_steps
        finally:
            executor.shutdown()
            for node in nodes:
                node.destroy_node()
            context.try_shutdown()
    if progress is not None:
        progress.run_done(sim_seconds)
    messages = recorder.until(round(cycle.duration * 1e9))
    write_run_bag(bag, messages, recorder.types,
                  {LIQUID_KEY: liquid, MOTOR_KEY: plant.model.name})
    return RunResult(liquid, feedforward, bag, messages, recorder.types, wall, sim_seconds,
                     unanswered)
