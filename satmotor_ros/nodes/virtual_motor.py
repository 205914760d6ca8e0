# SPDX-License-Identifier: Apache-2.0
"""
The ``virtual_motor`` node: the plant behind the topics of a real SM-0,75/25 test rig.

Subscribes ``flow_command`` and ``load_torque`` (std_msgs/Float64, m^3/s and N*m);
publishes ``inlet_pressure``, ``outlet_pressure``, ``case_pressure``
(sensor_msgs/FluidPressure, Pa absolute), ``flow_measured`` (std_msgs/Float64, m^3/s),
``joint_states`` (rad, rad/s, N*m), ``fluid_temperature`` (sensor_msgs/Temperature, degC)
with sensor-data QoS, and ``/diagnostics``. All physics is in :mod:`satmotor_ros.plant`.

``clock_mode`` ``wall`` steps the plant with the wall clock; ``sim`` steps it as fast as
possible (or ``max_speedup`` times real time) and publishes ``/clock``, so every other
node runs on ``use_sim_time``. ``lockstep`` is ``sim`` where each publish period waits
for a ``flow_command`` that answers it: simulated time advances one period per command,
so a controller on ``use_sim_time`` runs at its full rate however fast the machine is,
and a run is repeatable. A period no command answers within ``lockstep_wait`` seconds of
wall time is taken anyway (counted as ``unanswered_steps`` in the diagnostics). A negative
command feeds port B and turns the shaft backwards (doc/quadrants.md); a bad command (NaN,
beyond ``max_flow_command`` either way)
is refused: the last good one is held, the reason logged and put on ``/diagnostics``.

The motor can age: a wear that grows with the plant's running time
(``effects.clearance_wear_rate``, ``effects.leakage_wear_rate``) and a step fault
(``fault.time``, ``fault.effect``, ``fault.value``), on the plant's own clock, so in
``sim`` mode hours of operation pass in minutes; ``/diagnostics`` says when the fault struck.
"""

from __future__ import annotations

import math
import time
from typing import Any

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock
from rclpy.clock_type import ClockType
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.guard_condition import GuardCondition
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data, QoSProfile
from rclpy.time import Time as RosTime
from rclpy.timer import Timer
from rosgraph_msgs.msg import Clock as ClockMsg
from satmotor_ros.interface import CHANNELS, CLOCK_TOPIC, DIAGNOSTICS, JOINT_NAME, PRESSURE_TOPICS
from satmotor_ros.model import describe_status
from satmotor_ros.model.units import LPM
from satmotor_ros.nodes import _diagnostics as diag
from satmotor_ros.nodes import _parameters as params
from satmotor_ros.nodes._parameters import ParamSpec, RosParameter
from satmotor_ros.nodes._spin import node_main
from satmotor_ros.plant import make_load, Plant
from satmotor_ros.plant.config import parameter_specs, params_from_flat
from satmotor_ros.plant.load import LOAD_KINDS
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64

CLOCK_MODES = ('wall', 'sim', 'lockstep')
"""How the plant's time runs (``clock_mode``)."""

NODE_PARAMETERS: tuple[ParamSpec, ...] = (
    *params.MOTOR_PARAMETERS,
    ParamSpec('clock_mode', 'wall', "'wall' (real time), 'sim' (fast, publishes /clock) or "
              "'lockstep' (sim, one publish period per flow_command)", choices=CLOCK_MODES),
    ParamSpec('paused', False, 'hold the plant: no step is taken and nothing is published'),
    ParamSpec('lockstep_wait', 0.5, 'lockstep: wall time after which a period no '
              'flow_command answers is taken anyway', 's', 0.001, 60.0),
    ParamSpec('max_speedup', 0.0, 'sim mode: at most this many times real time; 0: as fast '
              'as possible', '-', 0.0, 1.0e6),
    ParamSpec('publish_rate', 100.0, 'rate of the sensor topics', 'Hz', 1.0, 1000.0),
    ParamSpec('diagnostics_period', 1.0, 'period of /diagnostics', 's', 0.01, 60.0),
    ParamSpec('max_flow_command', 100.0 * LPM, 'commands beyond it either way are refused',
              'm^3/s', 1.0e-6, 1.0e-2),
    ParamSpec('joint_name', JOINT_NAME, 'joint name in joint_states'),
    ParamSpec('frame_id', 'motor', 'frame_id of the sensor headers'),
    ParamSpec('load.kind', 'constant', 'load profile', choices=tuple(LOAD_KINDS)),
    ParamSpec('load.torque', 0.0, 'constant load torque', 'N*m', -1.0e4, 1.0e4),
    ParamSpec('load.before', 0.0, 'step load: torque before', 'N*m', -1.0e4, 1.0e4),
    ParamSpec('load.after', 0.0, 'step load: torque after', 'N*m', -1.0e4, 1.0e4),
    ParamSpec('load.time', 0.0, 'step load: time of the step', 's', 0.0, 1.0e9),
    ParamSpec('load.start', 0.0, 'ramp load: torque at t_start', 'N*m', -1.0e4, 1.0e4),
    ParamSpec('load.end', 0.0, 'ramp load: torque at t_end', 'N*m', -1.0e4, 1.0e4),
    ParamSpec('load.t_start', 0.0, 'ramp load: start', 's', 0.0, 1.0e9),
    ParamSpec('load.t_end', 1.0, 'ramp load: end', 's', 0.0, 1.0e9),
    ParamSpec('load.coefficient', 0.0, 'speed load: torque per speed', 'N*m*s/rad', 0.0,
              1.0e3),
    ParamSpec('load.offset', 0.0, 'speed load: torque at rest', 'N*m', -1.0e4, 1.0e4),
)
"""The node's own parameters; the plant's follow (:func:`parameter_specs`)."""

_LOAD_FIELDS = {'constant': ('torque',), 'step': ('before', 'after', 'time'),
                'ramp': ('start', 'end', 't_start', 't_end'), 'speed': ('coefficient', 'offset')}
MAX_LOAD_TORQUE = 1.0e4
"""Largest load torque accepted on the topic, [N*m]."""


def all_parameters() -> tuple[ParamSpec, ...]:
    """
    List every parameter the node declares.

    Returns
    -------
    tuple of ParamSpec
        Node parameters, then the plant's (from the plant records: unit, range).

    """
    plant = tuple(ParamSpec(s.name, s.default, s.description, s.unit, s.low, s.high,
                            choices=s.choices)
                  for s in parameter_specs())
    return NODE_PARAMETERS + plant


def _stamp(seconds: float) -> Time:
    nanoseconds = int(round(seconds * 1e9))
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


class Setup:
    """What the parameters decide: motor model, plant parameters, load; built and validated."""

    def __init__(self, values: dict[str, Any]) -> None:
        """
        Build everything from the parameter values; raise ValueError naming the bad one.

        Parameters
        ----------
        values : dict
            Parameter name -> value, [-]

        """
        self.values = values
        for name, allowed in (('clock_mode', CLOCK_MODES), ('load.kind', tuple(LOAD_KINDS))):
            if values[name] not in allowed:
                msg = f'{name} = {values[name]!r}: use one of {", ".join(allowed)}'
                raise ValueError(msg)
        if not values['joint_name']:
            raise ValueError('joint_name is empty')
        self.model = params.motor_options(values).build_model()
        plant_names = {s.name for s in parameter_specs()}
        self.params = params_from_flat({k: v for k, v in values.items() if k in plant_names})
        kind = values['load.kind']
        self.load = make_load(kind, **{f: values[f'load.{f}'] for f in _LOAD_FIELDS[kind]})


class VirtualMotorNode(Node):
    """
    The virtual motor as a ROS node.

    Parameters
    ----------
    node_name : str
        Node name, [-]
    **kwargs
        Passed to :class:`rclpy.node.Node` (context, namespace, parameter_overrides, ...), [-]

    """

    def __init__(self, node_name: str = 'virtual_motor', **kwargs: Any) -> None:
        """Declare parameters, build the plant, open topics and start stepping."""
        super().__init__(node_name, **kwargs)
        self._specs = {spec.name: spec for spec in all_parameters()}
        problems = params.declare(self, self._specs.values())
        if problems:  # a plant run otherwise than asked is no test: refuse, as a bad set-up is
            problem = next(iter(problems.values())).partition('; using the default')[0]
            raise ValueError(f'parameter {problem}')
        self._setup = Setup(self._values())  # an inconsistent set-up raises here
        self._liquid_source = params.liquid_source(self)
        self.plant = Plant(self._setup.model, self._setup.params, self._setup.load)
        self.add_on_set_parameters_callback(self._validate)
        self.add_post_set_parameters_callback(self._apply)
        self._command = 0.0
        self._load_torque: float | None = None
        self.rejected = 0
        self.unanswered_steps = 0  # lockstep periods taken without a flow command
        self._unanswered_reported = 0
        self.last_rejection = ''
        self._rejected_since_diagnostics = 0
        # The publishers go without rclpy's default QoS-event handlers: each adds two
        # entities to every wait of the executor, once per tick, and a subscriber keeping
        # its client library's default handlers still reports an incompatible QoS or type.
        quiet = PublisherEventCallbacks(use_default_callbacks=False)
        sensor = qos_profile_sensor_data
        self._pub = {name: self.create_publisher(FluidPressure, name, sensor,
                                                 event_callbacks=quiet)
                     for name in PRESSURE_TOPICS}
        self._flow_pub = self.create_publisher(Float64, CHANNELS['flow_measured'].topic, sensor,
                                               event_callbacks=quiet)
        self._joint_pub = self.create_publisher(JointState, CHANNELS['measured_speed'].topic,
                                                sensor, event_callbacks=quiet)
        self._temp_pub = self.create_publisher(Temperature, CHANNELS['temperature'].topic, sensor,
                                               event_callbacks=quiet)
        self._diag_pub = self.create_publisher(DiagnosticArray, DIAGNOSTICS, 10,
                                               event_callbacks=quiet)
        self._clock_pub = self.create_publisher(ClockMsg, CLOCK_TOPIC, QoSProfile(depth=10),
                                                event_callbacks=quiet)
        self._pressure = {name: FluidPressure() for name in PRESSURE_TOPICS}
        self._flow, self._joint, self._temperature = Float64(), JointState(), Temperature()
        self._clock_msg = ClockMsg()
        self._command_sub = self.create_subscription(Float64, CHANNELS['flow'].topic,
                                                     self._on_command, 10)
        self._diagnosed_at = time.monotonic()  # wall time of the last /diagnostics
        self._report_now = False  # lockstep unanswered for long: report with the next period
        self._controllers_warned = False
        self.create_subscription(Float64, CHANNELS['torque'].topic, self._on_load, 10)
        self._steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._driver: Timer | GuardCondition | None = None
        self._lockstep_timer: Timer | None = None
        # lockstep: the published period waits for its answer; a command came since then
        self._awaiting, self._answer, self._published_at = False, False, 0.0
        self._start_stepping()

    # -- parameters --------------------------------------------------------------------

    def _values(self, changes: list[RosParameter] | None = None) -> dict[str, Any]:
        values = params.values(self, self._specs.values())
        for p in changes or []:
            values[p.name] = p.value
        return values

    def _validate(self, changes: list[RosParameter]) -> SetParametersResult:
        result = params.check(self._specs, changes)
        if not result.successful:
            self.get_logger().warning(f'parameter change refused: {result.reason}')
            return result
        try:
            self._pending = Setup(self._values(changes))
        except (ValueError, OSError) as err:  # PlantError, ModelError and ConfigError too
            reason = str(err)
            self.get_logger().warning(f'parameter change refused: {reason}')
            return SetParametersResult(successful=False, reason=reason)
        return SetParametersResult(successful=True)

    def _apply(self, changes: list[RosParameter]) -> None:
        setup, old = self._pending, self._setup
        if any(p.name == 'liquid' for p in changes):
            self._liquid_source = 'parameter'
        model_changed = any(setup.values[k] != old.values[k]
                            for k in ('liquid', 'motor_file', 'displacement_law'))
        self.plant.reconfigure(setup.params, setup.model if model_changed else None)
        self.plant.load = setup.load
        self._setup = setup
        if any(setup.values[k] != old.values[k]
               for k in ('clock_mode', 'max_speedup', 'publish_rate', 'step', 'lockstep_wait',
                         'paused')):
            self._start_stepping()

    # -- inputs ------------------------------------------------------------------------

    def _refuse(self, what: str) -> None:
        self.rejected += 1
        self._rejected_since_diagnostics += 1
        self.last_rejection = what
        held = ' '.join(reversed(diag.human(self._command, 'm^3/s')))
        self.get_logger().warning(f'{what}; holding {held}', throttle_duration_sec=1.0)

    def _on_command(self, msg: Float64) -> None:
        value = msg.data
        problem = self.plant.check_command(value)
        limit = self._setup.values['max_flow_command']
        if problem is None and abs(value) > limit:
            problem = (f'flow_command.data = {value!r} m^3/s: beyond max_flow_command '
                       f'+-{limit / LPM:.4g} l/min')
        if problem is not None:
            self._refuse(problem)
        else:
            self._command = value
        self._answer = True  # a refused command answers the period too: the last good one holds
        self._answered()

    def _on_load(self, msg: Float64) -> None:
        value = msg.data
        if not (math.isfinite(value) and abs(value) <= MAX_LOAD_TORQUE):
            self._refuse(f'load torque {value!r} N*m is not finite or beyond '
                         f'{MAX_LOAD_TORQUE} N*m')
            return
        self._load_torque = value

    # -- stepping ----------------------------------------------------------------------

    def _start_stepping(self) -> None:
        if isinstance(self._driver, Timer):
            self.destroy_timer(self._driver)
        elif self._driver is not None:
            self.destroy_guard_condition(self._driver)
        if self._lockstep_timer is not None:
            self.destroy_timer(self._lockstep_timer)
            self._lockstep_timer = None
        values = self._setup.values
        self._steps_per_publish = max(1, round(1.0 / (values['publish_rate']
                                                      * self.plant.params.step)))
        period = self._steps_per_publish * self.plant.params.step
        self._sim = values['clock_mode'] in ('sim', 'lockstep')
        self._awaiting = False
        if values['paused']:
            self._driver = None
            return
        self._wall_start = time.monotonic() - self.plant.state.time
        self._next_diagnostics = self.plant.state.time
        self._ticks_wall = (time.monotonic(), self.plant.state.time)
        if values['clock_mode'] == 'lockstep':
            self._driver = self.create_guard_condition(self._tick)
            self._lockstep_timer = self.create_timer(
                values['lockstep_wait'] / 4, self._step_unanswered, clock=self._steady)
            if self.plant.state.time == 0.0:
                # the start is published first (nodes on sim time take their clock from it,
                # so that their timers do not see the first step as a jump), and the first
                # period runs at once: a controller first acts one period after the start
                self._publish_state()
                self._answer = True
            # a restart (a parameter, pause, another mode before) goes on from the period
            # last published: taken now if a command answered it, else when one does
            self._awaiting, self._published_at = True, time.monotonic()
            self._answered()
            return
        if self._sim and values['max_speedup'] == 0.0:
            # as fast as possible: a guard condition the tick re-triggers, so the executor
            # serves every other callback between ticks; a zero-period timer would do the
            # same at a tenth more cost per tick (rclpy inspects a timer's callback each call)
            self._driver = self.create_guard_condition(self._free_tick)
            self._driver.trigger()
            return
        if self._sim:
            period /= values['max_speedup']
        self._driver = self.create_timer(period, self._tick, clock=self._steady)

    def _answered(self) -> None:
        """Take the next lockstep step if a flow command answered the published period."""
        if self._awaiting and self._answer and isinstance(self._driver, GuardCondition):
            self._awaiting = False
            self._driver.trigger()

    def _step_unanswered(self) -> None:
        """Lockstep and no command within ``lockstep_wait``: take the step anyway."""
        now = time.monotonic()
        if self._awaiting and now - self._published_at >= self._setup.values['lockstep_wait']:
            self.unanswered_steps += 1
            self._answer = True
            self._answered()
            # no controller: simulated time crawls (one period per lockstep_wait), so the
            # diagnostics follow the wall clock instead, with the period this step publishes
            period = self._setup.values['diagnostics_period']
            self._report_now = now - self._diagnosed_at >= period

    def _publish_state(self) -> None:
        self._publish()  # the sensors first, then the clock that makes a controller act on them
        self._clock_msg.clock = _stamp(self.plant.state.time)
        self._clock_pub.publish(self._clock_msg)
        self._awaiting, self._answer = True, False
        self._published_at = time.monotonic()

    def _free_tick(self) -> None:
        self._tick()
        driver = self._driver
        # set_parameters() called directly from another thread may have swapped the driver
        if isinstance(driver, GuardCondition):
            driver.trigger()

    def _tick(self) -> None:
        plant = self.plant
        if self._sim:
            steps = self._steps_per_publish
        else:  # catch up with the wall clock, at most one second at a time
            behind = (time.monotonic() - self._wall_start) - plant.state.time
            steps = min(int(behind / plant.params.step), round(1.0 / plant.params.step))
        command, load = self._command, self._load_torque
        step = plant.step
        for _ in range(steps):
            step(command, load)
        if self._lockstep_timer is not None:
            self._publish_state()
            return
        if self._sim:
            self._clock_msg.clock = _stamp(plant.state.time)
            self._clock_pub.publish(self._clock_msg)
        self._publish()

    def _publish(self) -> None:
        # the messages are built once and refilled: publish() copies them, and building a
        # stamped message costs ten times as much as refilling it
        plant = self.plant
        reading = plant.measure()
        values = self._setup.values
        stamp = (_stamp(reading.time) if self._sim else self.get_clock().now().to_msg())
        frame = values['frame_id']
        sensors = plant.params.sensors
        for name, value in zip(PRESSURE_TOPICS, (reading.inlet_pressure,
                                                 reading.outlet_pressure,
                                                 reading.case_pressure)):
            msg = self._pressure[name]
            msg.header.stamp, msg.header.frame_id = stamp, frame
            msg.fluid_pressure, msg.variance = value, getattr(sensors, name).noise ** 2
            self._pub[name].publish(msg)
        self._flow.data = reading.flow
        self._flow_pub.publish(self._flow)
        joint = self._joint
        joint.header.stamp, joint.header.frame_id = stamp, frame
        joint.name = [values['joint_name']]
        joint.position, joint.velocity = [reading.angle], [reading.speed]
        joint.effort = [reading.torque]
        self._joint_pub.publish(joint)
        temp = self._temperature
        temp.header.stamp, temp.header.frame_id = stamp, frame
        temp.temperature, temp.variance = reading.temperature, sensors.temperature.noise ** 2
        self._temp_pub.publish(temp)
        if reading.time >= self._next_diagnostics or self._report_now:
            self._report_now = False
            self._next_diagnostics = reading.time + values['diagnostics_period']
            self._diagnose(stamp)

    def _fault(self) -> str:
        """Say what the step fault of ``fault.*`` is and whether it has struck."""
        fault = self.plant.params.fault
        if not fault.effect:
            return 'none'
        when = 'struck at' if self.plant.fault_struck else 'strikes at'
        return f'effects.{fault.effect} = {fault.value:g}: {when} {fault.time:g} s'

    def _controllers(self) -> int:
        """Count the publishers of flow_command (as remapped)."""
        return self.count_publishers(self._command_sub.topic_name)

    def _diagnose(self, stamp: Time) -> None:
        self._diagnosed_at = time.monotonic()
        plant = self.plant
        lockstep = self._lockstep_timer is not None
        controllers = self._controllers()
        flows = plant.flows
        now_wall, now_sim = time.monotonic(), plant.state.time
        wall0, sim0 = self._ticks_wall
        factor = (now_sim - sim0) / (now_wall - wall0) if now_wall > wall0 else 0.0
        self._ticks_wall = (now_wall, now_sim)
        level, message = 0, 'running'
        if self._rejected_since_diagnostics:
            level = 1
            message = f'refused {self._rejected_since_diagnostics} input(s): ' \
                      f'{self.last_rejection}'
        elif self.unanswered_steps > self._unanswered_reported:
            level = 1
            message = f'{self.unanswered_steps - self._unanswered_reported} lockstep ' \
                      'period(s) taken with no flow_command within lockstep_wait'
        elif lockstep and controllers > 1:
            level = 1
            message = (f'{controllers} publishers on flow_command: in lockstep the first '
                       'command answers each period, so two controllers take turns')
        elif flows.relief > 0.0:
            level, message = 1, 'relief valve open'
        if lockstep and controllers > 1 and not self._controllers_warned:
            self._controllers_warned = True
            self.get_logger().warning(f'{controllers} publishers on flow_command drive this '
                                      'lockstep plant: more than one controller?')
        self._unanswered_reported = self.unanswered_steps
        if plant.invalid_points:
            level = 2
            message = f'model refused {plant.invalid_points} point(s): ' \
                      f'{describe_status(plant.model_status)}'
        self._rejected_since_diagnostics = 0
        state = plant.state  # the true state: measure() would draw sensor noise
        values = {  # in the units a person reads
            'sim_time [s]': diag.human(now_sim, 's')[1],
            'realtime_factor [-]': f'{factor:.2f}',
            'flow_command [l/min]': diag.human(self._command, 'm^3/s')[1],
            'speed [rpm]': diag.human(state.speed, 'rad/s')[1],
            'inlet_pressure [MPa]': diag.human(state.inlet_pressure, 'Pa')[1],
            'outlet_pressure [MPa]': diag.human(state.outlet_pressure, 'Pa')[1],
            'load_torque [N*m]': 'profile' if self._load_torque is None else self._load_torque,
            'rejected_inputs': self.rejected, 'last_rejection': self.last_rejection,
            'unanswered_steps': self.unanswered_steps, 'flow_command publishers': controllers,
            'relief_flow [l/min]': diag.human(flows.relief, 'm^3/s')[1],
            'model_status': describe_status(plant.model_status),
            'model_rebuilds': plant.rebuilds, 'fault': self._fault(),
            'liquid': self._setup.values['liquid'],
            'liquid_name': plant.model.liquid.name, 'liquid_source': self._liquid_source,
        }
        status = diag.status(f'{self.get_fully_qualified_name()}: plant', plant.model.name,
                             level, message, values)
        self._diag_pub.publish(diag.array(RosTime.from_msg(stamp), [status]))


main = node_main(VirtualMotorNode, 'virtual_motor')


__all__ = ['VirtualMotorNode', 'all_parameters', 'main']


if __name__ == '__main__':
    main()
