# SPDX-License-Identifier: Apache-2.0
"""
The ``motor_model`` node: predicted shaft speed and volumetric-loss breakdown, live.

Subscribes ``flow_command``, ``inlet_pressure``, ``outlet_pressure`` and, when they are
published, ``case_pressure``, ``fluid_temperature`` and ``joint_states``; publishes
``predicted_joint_state``, ``losses/<component>``, ``speed_residual`` and ``/diagnostics``
(DESIGN.md). The node holds no physics: the combination rule and the model call are
:mod:`satmotor_ros.prediction`, shared with ``satmotor replay``.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from builtin_interfaces.msg import Time as TimeMsg
from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import SetParametersResult
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data, QoSProfile
from rclpy.time import Time
from satmotor_ros.model import (COMPONENTS, describe_status, load_motor, ModelError,
                                MotorModel)
from satmotor_ros.nodes import _diagnostics as diag
from satmotor_ros.nodes import _parameters as params
from satmotor_ros.nodes._parameters import ParamSpec
from satmotor_ros.nodes._spin import spin
from satmotor_ros.prediction import (Combiner, FIELDS, INPUTS, Level, MODES, predict_point,
                                     Prediction, Progress, Rule, TOPICS, UNITS)
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64


def _joint_name_reason(value: Any) -> str | None:
    return None if str(value).strip() else f'joint_name = {value!r}: must not be empty'


PARAMETERS = (
    ParamSpec('liquid', 'oil', "coefficient set and its liquid: 'oil' or 'water' for the "
              'packaged SM-0,75/25, or any set of motor_file'),
    ParamSpec('viscosity', 0.0, 'kinematic viscosity of a user liquid run on the set; 0: the '
              "set's own liquid", 'm^2/s', 0.0, 1.0e-2),
    ParamSpec('density', 0.0, "density of a user liquid; 0: the set's own", 'kg/m^3', 0.0,
              1.0e5),
    ParamSpec('bulk_modulus', 0.0, "bulk modulus of a user liquid; 0: the set's own", 'Pa', 0.0,
              1.0e12),
    ParamSpec('motor_file', '', 'motor specification YAML (geometry, coefficient sets); '
              'empty: the packaged SM-0,75/25'),
    ParamSpec('displacement_law', 'eq33', 'change of displacement: physical eq. (33) or '
              'empirical eq. (39)', choices=('eq33', 'eq39')),
    ParamSpec('publish_mode', 'on_flow', 'predict on every flow_command, or at publish_rate',
              choices=MODES),
    ParamSpec('publish_rate', 50.0, "prediction rate in publish_mode 'rate'", 'Hz', 0.1,
              1000.0),
    ParamSpec('input_timeout', 0.5, 'oldest input a prediction may use', 's', 0.001, 60.0),
    ParamSpec('joint_name', 'motor_shaft', 'joint of predicted_joint_state, and of the '
              'measured speed taken from joint_states', check=_joint_name_reason),
    ParamSpec('qos_depth', 10, 'queue depth of every subscription and publisher (fixed at '
              'start)', '-', 1, 1000, read_only=True),
)
"""The node's parameters: name, default, description, unit and accepted values."""

_SPECS = {spec.name: spec for spec in PARAMETERS}
_MODEL_KEYS = ('liquid', 'viscosity', 'density', 'bulk_modulus', 'motor_file',
               'displacement_law')


def model_from_parameters(values: dict[str, Any]) -> MotorModel:
    """
    Build the motor model the parameters describe.

    Parameters
    ----------
    values : dict
        Parameter name -> value (see :data:`PARAMETERS`), [SI]

    Returns
    -------
    MotorModel
        The model.

    Raises
    ------
    ModelError
        If the motor file, the set or the user liquid is invalid; the message names it.

    """
    spec = load_motor(values['motor_file'] or None)
    name = values['liquid']
    if name not in spec.sets:
        raise ModelError(f'liquid = {name!r}: not a coefficient set of {spec.source} '
                         f'(has: {", ".join(spec.sets)})')
    overrides = {key: float(values[param]) for key, param in (
        ('kinematic_viscosity', 'viscosity'), ('density', 'density'),
        ('bulk_modulus', 'bulk_modulus')) if values[param] > 0.0}
    liquid = None
    if overrides:
        liquid = dataclasses.replace(spec.sets[name].liquid, name=f'user liquid on {name}',
                                     **overrides)
    return MotorModel.from_spec(spec, name, liquid, values['displacement_law'])


def rule_from_parameters(values: dict[str, Any]) -> Rule:
    """
    Build the combination rule the parameters describe.

    Parameters
    ----------
    values : dict
        Parameter name -> value (see :data:`PARAMETERS`), [SI]

    Returns
    -------
    Rule
        Timeout, mode and rate.

    """
    return Rule(timeout=float(values['input_timeout']), mode=values['publish_mode'],
                rate=float(values['publish_rate']))


class MotorModelNode(Node):
    """
    Predict the motor's shaft speed and losses from its input topics.

    Parameters
    ----------
    node_name : str
        Name of the node, [-]
    **kwargs : Any
        Passed to :class:`rclpy.node.Node` (namespace, context, parameter_overrides, ...), [-]

    """

    def __init__(self, node_name: str = 'motor_model', **kwargs: Any) -> None:
        """Declare parameters, build the model, create publishers and subscriptions."""
        super().__init__(node_name, **kwargs)
        self._problems = params.declare(self, PARAMETERS)
        for problem in self._problems.values():
            self.get_logger().error(f'parameter {problem}')
        values = params.values(self, PARAMETERS)
        self._model: MotorModel | None = None
        self._model_error = ''
        self._build_model(values)
        self._rule = rule_from_parameters(values)
        self._combiner = Combiner(self._rule)
        self._joint = values['joint_name']
        self._worst: Prediction | None = None  # the worst prediction since the last report
        self._published = self._rejected = self._no_joint = 0
        self._progress = Progress()  # time and revolutions for the effects that read them
        self._last_level = -1
        depth = values['qos_depth']
        sensor = QoSProfile(depth=depth, reliability=qos_profile_sensor_data.reliability,
                            durability=qos_profile_sensor_data.durability,
                            history=qos_profile_sensor_data.history)
        self._pub_joint = self.create_publisher(JointState, 'predicted_joint_state', depth)
        self._pub_losses = [self.create_publisher(Float64, f'losses/{c}', depth)
                            for c in COMPONENTS]
        self._pub_residual = self.create_publisher(Float64, 'speed_residual', depth)
        self._pub_diag = self.create_publisher(DiagnosticArray, '/diagnostics', depth)
        self.create_subscription(Float64, 'flow_command', self._on_flow, depth)
        self.create_subscription(FluidPressure, 'inlet_pressure', self._pressure('p_in'),
                                 sensor)
        self.create_subscription(FluidPressure, 'outlet_pressure', self._pressure('p_out'),
                                 sensor)
        self.create_subscription(FluidPressure, 'case_pressure', self._pressure('p_case'),
                                 sensor)
        self.create_subscription(Temperature, 'fluid_temperature', self._on_temperature, sensor)
        self.create_subscription(JointState, 'joint_states', self._on_joint_states, sensor)
        self._rate_timer = None
        self._apply_mode()
        self.create_timer(1.0, self._publish_diagnostics)
        self.add_on_set_parameters_callback(self._check_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)

    # -- parameters -------------------------------------------------------------------------

    def _build_model(self, values: dict[str, Any]) -> None:
        try:
            self._model, self._model_error = model_from_parameters(values), ''
        except ModelError as err:
            self._model, self._model_error = None, str(err)
            self.get_logger().error(f'no model: {err}')

    def _check_parameters(self, request: list[Parameter]) -> SetParametersResult:
        result = params.check(_SPECS, request)
        if not result.successful:
            return result
        proposed = params.values(self, PARAMETERS)
        proposed.update({p.name: p.value for p in request if p.name in _SPECS})
        try:
            rule_from_parameters(proposed)
            if any(p.name in _MODEL_KEYS for p in request):
                model_from_parameters(proposed)
        except (ModelError, ValueError) as err:
            return SetParametersResult(successful=False, reason=str(err))
        return SetParametersResult(successful=True)

    def _apply_parameters(self, changed: list[Parameter]) -> None:
        names = {p.name for p in changed}
        for name in names:
            self._problems.pop(name, None)  # a start-up problem is over once it is set
        values = params.values(self, PARAMETERS)
        if names & set(_MODEL_KEYS):
            self._build_model(values)
            self.get_logger().info(f'model now {self._describe_model()}')
        if names & {'input_timeout', 'publish_mode', 'publish_rate'}:
            self._rule = self._combiner.rule = rule_from_parameters(values)
            self._apply_mode()
        self._joint = values['joint_name']

    def _apply_mode(self) -> None:
        if self._rate_timer is not None:
            self.destroy_timer(self._rate_timer)
            self._rate_timer = None
        if self._rule.mode == 'rate':
            self._rate_timer = self.create_timer(1.0 / self._rule.rate, self._on_tick)

    def _describe_model(self) -> str:
        if self._model is None:
            return f'none ({self._model_error})'
        m = self._model
        effects = ', '.join(e.name for e in m.effects) or 'none'
        return (f'{m.name}, {m.coefficient_set.name} set, {m.liquid.name}, '
                f'{m.displacement_law}, effects: {effects}')

    # -- inputs -----------------------------------------------------------------------------

    def _now_ns(self) -> int:
        return self.get_clock().now().nanoseconds

    def _on_flow(self, msg: Float64) -> None:
        t = self._now_ns()
        self._combiner.update('flow', msg.data, t)
        if self._rule.mode == 'on_flow':
            self._predict(t)

    def _pressure(self, name: str):  # noqa: ANN202 (callback factory)
        def on_pressure(msg: FluidPressure) -> None:
            self._combiner.update(name, msg.fluid_pressure, self._now_ns())
        return on_pressure

    def _on_temperature(self, msg: Temperature) -> None:
        self._combiner.update('temperature', msg.temperature, self._now_ns())

    def _on_joint_states(self, msg: JointState) -> None:
        try:
            i = msg.name.index(self._joint)
            speed = msg.velocity[i]
        except (ValueError, IndexError):
            self._no_joint += 1  # no such joint, or no velocity for it: not a measurement
            return
        self._combiner.update('measured_speed', speed, self._now_ns())

    def _on_tick(self) -> None:
        self._predict(self._now_ns())

    # -- prediction -------------------------------------------------------------------------

    def _predict(self, t_ns: int) -> None:
        snap = self._combiner.snapshot(t_ns)
        if self._model is None:
            pred = Prediction(t_ns, snap.values, (), 0, Level.ERROR,
                              f'no model: {self._model_error}')
        else:
            pred = predict_point(self._model, snap, self._rule.timeout,
                                 self._progress.advance(snap))
        if self._worst is None or pred.level >= self._worst.level:
            self._worst = pred
        if pred.level != self._last_level:
            text = f'prediction {Level(pred.level).name}: {pred.message}'
            if pred.level == Level.OK:  # one call site per severity (rclpy requires it)
                self.get_logger().info(text)
            elif pred.level == Level.WARN:
                self.get_logger().warning(text)
            else:
                self.get_logger().error(text)
            self._last_level = pred.level
        if not pred.valid:
            self._rejected += 1
            return
        self._published += 1
        out = pred.outputs
        joint = JointState(name=[self._joint], velocity=[out[3]])
        joint.header.stamp = TimeMsg(sec=t_ns // 1_000_000_000, nanosec=t_ns % 1_000_000_000)
        self._pub_joint.publish(joint)
        for k, publisher in enumerate(self._pub_losses):
            publisher.publish(Float64(data=out[4 + k]))
        if out[-1] == out[-1]:  # a measured speed was there: not NaN
            self._pub_residual.publish(Float64(data=out[-1]))

    # -- diagnostics ------------------------------------------------------------------------

    def _publish_diagnostics(self) -> None:
        now = self._now_ns()
        pred = self._worst if self._worst is not None else self._idle_report(now)
        self._worst = None
        values: dict[str, Any] = {}
        for name, value, age in zip(INPUTS, pred.inputs, self._combiner.snapshot(now).ages):
            values[f'{FIELDS[name]} [{UNITS[name]}]'] = value
            values[f'{TOPICS[name]} age [s]'] = age
        names = ('dp', 'dp_i', 'p_ex', 'speed', *COMPONENTS, 'residual')
        units = ('Pa', 'Pa', 'Pa', 'rad/s', *(['m^3/s'] * len(COMPONENTS)), 'rad/s')
        for name, unit, value in zip(names, units, pred.outputs or [float('nan')] * 13):
            key = f'losses/{name}' if name in COMPONENTS else name
            values[f'{key} [{unit}]'] = value
        values.update({
            'model status': describe_status(pred.status), 'model': self._describe_model(),
            'predictions published': self._published,
            'predictions rejected': self._rejected,
            'joint_states without joint': self._no_joint, 'joint_name': self._joint,
            'publish_mode': self._rule.mode, 'input_timeout [s]': self._rule.timeout,
        })
        message = pred.message
        level = pred.level
        if self._problems:
            level = max(level, Level.ERROR)
            message = f'{message}; parameter {"; ".join(self._problems.values())}'
        name = f'{self.get_fully_qualified_name()}: motor model'
        self._pub_diag.publish(diag.array(Time(nanoseconds=now), [diag.status(
            name, self._model.name if self._model else 'motor', level, message, values)]))

    def _idle_report(self, now: int) -> Prediction:
        """Say why no prediction was made within the timeout: the inputs' state now."""
        snap = self._combiner.snapshot(now)
        if self._model is None:
            return Prediction(now, snap.values, (), 0, Level.ERROR,
                              f'no model: {self._model_error}')
        pred = predict_point(self._model, snap, self._rule.timeout, self._progress.peek(now))
        if pred.valid:  # inputs fresh, but no flow_command drove a prediction
            return pred._replace(level=Level.WARN, message='no prediction within '
                                 f'input_timeout {self._rule.timeout:g} s')
        return pred


def main(args: list[str] | None = None) -> None:
    """
    Run the node (the ``motor_model`` console script).

    Parameters
    ----------
    args : list of str, optional
        Command-line arguments, including ROS arguments, [-]

    """
    rclpy.init(args=args)
    node = None
    try:
        node = MotorModelNode()
        spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
