# SPDX-License-Identifier: Apache-2.0
"""
The ``motor_model`` node: predicted shaft speed and volumetric-loss breakdown, live.

Subscribes ``flow_command``, ``inlet_pressure``, ``outlet_pressure`` and, when they are
published, ``case_pressure``, ``fluid_temperature`` and ``joint_states``; publishes
``predicted_joint_state``, ``losses/<component>``, ``speed_residual`` and ``/diagnostics``
(DESIGN.md; names and types from :mod:`satmotor_ros.interface`). With ``losses_format``
``array`` the breakdown goes out as one ``std_msgs/Float64MultiArray`` on ``losses``
instead (its layout's one dimension is labelled with the component names, in order), and
``losses_every`` thins it to every n-th prediction: what makes the node cheap at 1 kHz.
The node holds no physics: the combination rule and the model call are
:mod:`satmotor_ros.prediction`, shared with ``satmotor replay``.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable
from typing import Any, TypeVar

from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import SetParametersResult
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import qos_profile_sensor_data, QoSProfile
from rclpy.time import Time
from rclpy.timer import Timer
from satmotor_ros.interface import (CHANNELS, DIAGNOSTICS, JOINT_NAME, LOSS_COMPONENTS,
                                    LOSSES_ARRAY, LOSSES_PREFIX, PREDICTED_JOINT_STATE,
                                    SPEED_RESIDUAL)
from satmotor_ros.model import describe_status, ModelError, MotorModel
from satmotor_ros.nodes import _diagnostics as diag
from satmotor_ros.nodes import _parameters as params
from satmotor_ros.nodes._parameters import ParamSpec, RosParameter
from satmotor_ros.nodes._spin import node_main
from satmotor_ros.prediction import (Combiner, FIELDS, INPUTS, Level, MODES, OUTPUTS, predict,
                                     Prediction, Progress, Rule, TOPICS, UNITS)
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64, Float64MultiArray, MultiArrayDimension


def _joint_name_reason(value: Any) -> str | None:
    return None if str(value).strip() else f'joint_name = {value!r}: must not be empty'


LOSSES_FORMATS = ('topics', 'array', 'both')
"""How the loss breakdown goes out: DESIGN.md losses/<component>, one array, or both."""

PARAMETERS = (
    *params.MOTOR_PARAMETERS,
    ParamSpec('publish_mode', 'on_flow', 'predict on every flow_command, or at publish_rate',
              choices=MODES),
    ParamSpec('publish_rate', 50.0, "prediction rate in publish_mode 'rate'", 'Hz', 0.1,
              1000.0),
    ParamSpec('input_timeout', 0.5, 'oldest input a prediction may use', 's', 0.001, 60.0),
    ParamSpec('joint_name', JOINT_NAME, 'joint of predicted_joint_state, and of the '
              'measured speed taken from joint_states', check=_joint_name_reason),
    ParamSpec('losses_format', 'topics', 'loss breakdown as the DESIGN.md topics '
              'losses/<component> (topics), as one Float64MultiArray on losses whose layout '
              'names the components (array, the cheapest per message), or both',
              choices=LOSSES_FORMATS),
    ParamSpec('losses_every', 1, 'publish the loss breakdown with every n-th prediction only '
              '(1: with each)', '-', 1, 1000000),
    ParamSpec('qos_depth', 10, 'queue depth of every subscription and publisher (fixed at '
              'start)', '-', 1, 1000, read_only=True),
)
"""The node's parameters: name, default, description, unit and accepted values."""

_SPECS = {spec.name: spec for spec in PARAMETERS}
MsgT = TypeVar('MsgT')
_QUIET = PublisherEventCallbacks(use_default_callbacks=False)
_QUIET_SUBSCRIPTION = SubscriptionEventCallbacks(use_default_callbacks=False)
_SPEED = OUTPUTS.index('speed')
_LOSSES = slice(_SPEED + 1, _SPEED + 1 + len(LOSS_COMPONENTS))


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
        self._problems = params.declare_logged(self, PARAMETERS)
        values = params.values(self, PARAMETERS)
        self._model: MotorModel | None = None
        self._model_error = ''
        self._liquid_source = params.liquid_source(self)
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
        self._depth = depth
        self._pub_joint = self._publisher(JointState, PREDICTED_JOINT_STATE)
        self._pub_residual = self._publisher(Float64, SPEED_RESIDUAL)
        self._pub_diag = self._publisher(DiagnosticArray, DIAGNOSTICS)
        self._pub_losses: list[Publisher[Float64]] = []
        self._pub_losses_array: Publisher[Float64MultiArray] | None = None
        self._joint_msg = JointState(name=[self._joint])  # refilled per prediction
        self._losses_msg = Float64MultiArray()
        self._loss_msgs = [Float64() for _ in LOSS_COMPONENTS]
        self._losses_msg.layout.dim = [MultiArrayDimension(
            label=','.join(LOSS_COMPONENTS), size=len(LOSS_COMPONENTS),
            stride=len(LOSS_COMPONENTS))]
        self._losses_every = values['losses_every']
        self._apply_losses_format(values['losses_format'])
        self.create_subscription(Float64, CHANNELS['flow'].topic, self._on_flow, depth)
        # The best-effort sensor subscriptions go without the default QoS-event handlers
        # too: no publisher's QoS can be incompatible with them, a publisher of a wrong type
        # reports it on its side, and the diagnostics say 'no message received'.
        for kind, name, callback in (
                (FluidPressure, 'p_in', self._pressure('p_in')),
                (FluidPressure, 'p_out', self._pressure('p_out')),
                (FluidPressure, 'p_case', self._pressure('p_case')),
                (Temperature, 'temperature', self._on_temperature),
                (JointState, 'measured_speed', self._on_joint_states)):
            self.create_subscription(kind, CHANNELS[name].topic, callback, sensor,
                                     event_callbacks=_QUIET_SUBSCRIPTION)
        self._rate_timer: Timer | None = None
        self._apply_mode()
        self.create_timer(1.0, self._publish_diagnostics)
        self.add_on_set_parameters_callback(self._check_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)

    # -- parameters -------------------------------------------------------------------------

    def _build_model(self, values: dict[str, Any]) -> None:
        try:
            self._model = params.motor_options(values).build_model()
            self._model_error = ''
        except ModelError as err:
            self._model, self._model_error = None, str(err)
            self.get_logger().error(f'no model: {err}')

    def _check_parameters(self, request: list[RosParameter]) -> SetParametersResult:
        def build(proposed: dict[str, Any], changed: set[str]) -> None:
            rule_from_parameters(proposed)
            if changed & set(params.MOTOR_KEYS):
                params.motor_options(proposed).build_model()
        return params.check_proposed(_SPECS, request, params.values(self, PARAMETERS), build,
                                     (ModelError, ValueError))

    def _apply_parameters(self, changed: list[RosParameter]) -> None:
        names = {p.name for p in changed}
        for name in names:
            self._problems.pop(name, None)  # a start-up problem is over once it is set
        if 'liquid' in names:
            self._liquid_source = 'parameter'
        values = params.values(self, PARAMETERS)
        if names & set(params.MOTOR_KEYS):
            self._build_model(values)
            self.get_logger().info(f'model now {self._describe_model()}')
        if names & {'input_timeout', 'publish_mode', 'publish_rate'}:
            self._rule = self._combiner.rule = rule_from_parameters(values)
            self._apply_mode()
        self._joint = values['joint_name']
        self._joint_msg.name = [self._joint]
        self._losses_every = values['losses_every']
        self._apply_losses_format(values['losses_format'])

    def _publisher(self, kind: type[MsgT], topic: str) -> Publisher[MsgT]:
        # Without rclpy's default QoS-event handlers: each adds two entities to every wait
        # of the executor, once per message (a subscriber's own handlers still report an
        # incompatible QoS or type).
        return self.create_publisher(kind, topic, self._depth, event_callbacks=_QUIET)

    def _apply_losses_format(self, losses_format: str) -> None:
        """Keep only the loss publishers the format uses: fewer entities in every wait."""
        if losses_format == 'array':
            for publisher in self._pub_losses:
                self.destroy_publisher(publisher)
            self._pub_losses = []
        elif not self._pub_losses:
            self._pub_losses = [self._publisher(Float64, LOSSES_PREFIX + c)
                                for c in LOSS_COMPONENTS]
        if losses_format == 'topics' and self._pub_losses_array is not None:
            self.destroy_publisher(self._pub_losses_array)
            self._pub_losses_array = None
        elif losses_format != 'topics' and self._pub_losses_array is None:
            self._pub_losses_array = self._publisher(Float64MultiArray, LOSSES_ARRAY)

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

    def _pressure(self, name: str) -> Callable[[FluidPressure], None]:
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
            pred = predict(self._model, snap, self._rule.timeout, self._progress.advance(snap))
        if self._worst is None or pred.level >= self._worst.level:
            self._worst = pred
        if pred.level != self._last_level:
            text = f'prediction {Level(pred.level).name}'
            text += '' if pred.message == 'OK' else f': {pred.message}'
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
        joint = self._joint_msg
        joint.velocity = array('d', (out[_SPEED],))  # an array is taken without a check
        joint.header.stamp.sec, joint.header.stamp.nanosec = divmod(t_ns, 1_000_000_000)
        self._pub_joint.publish(joint)
        if self._published % self._losses_every == 0:
            self._publish_losses(out[_LOSSES])
        if out[-1] == out[-1]:  # a measured speed was there: not NaN
            self._pub_residual.publish(Float64(data=out[-1]))

    def _publish_losses(self, losses: tuple[float, ...]) -> None:
        if self._pub_losses_array is not None:
            self._losses_msg.data = array('d', losses)
            self._pub_losses_array.publish(self._losses_msg)
        for publisher, msg, value in zip(self._pub_losses, self._loss_msgs, losses):
            msg.data = value  # refilled: cheaper than a new message, published at once
            publisher.publish(msg)

    # -- diagnostics ------------------------------------------------------------------------

    def _publish_diagnostics(self) -> None:
        now = self._now_ns()
        pred = self._worst if self._worst is not None else self._idle_report(now)
        self._worst = None
        values: dict[str, Any] = {}  # in the units a person reads; n/a where there is none
        for name, value, age in zip(INPUTS, pred.inputs, self._combiner.snapshot(now).ages):
            unit, text = diag.human(value, UNITS[name])
            values[f'{FIELDS[name]} [{unit}]'] = text
            values[f'{TOPICS[name]} age [s]'] = diag.human(age, 's')[1]
        units = ('Pa', 'Pa', 'Pa', 'rad/s', *(['m^3/s'] * len(LOSS_COMPONENTS)), 'rad/s')
        for name, si_unit, value in zip(OUTPUTS, units,
                                        pred.outputs or [float('nan')] * len(OUTPUTS)):
            key = LOSSES_PREFIX + name if name in LOSS_COMPONENTS else name
            unit, text = diag.human(value, si_unit)
            values[f'{key} [{unit}]'] = text
        ran = pred.valid or pred.status != 0  # an ERROR of the inputs never ran the model
        values.update({
            'model status': describe_status(pred.status) if ran else 'not run',
            'model': self._describe_model(), 'liquid': self._liquid(),
            'liquid_source': self._liquid_source,
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

    def _liquid(self) -> str:
        return str(self.get_parameter('liquid').value)

    def _idle_report(self, now: int) -> Prediction:
        """Say why no prediction was made within the timeout: the inputs' state now."""
        snap = self._combiner.snapshot(now)
        if self._model is None:
            return Prediction(now, snap.values, (), 0, Level.ERROR,
                              f'no model: {self._model_error}')
        pred = predict(self._model, snap, self._rule.timeout, self._progress.peek(now))
        if pred.valid:  # inputs fresh, but no flow_command drove a prediction
            return pred._replace(level=Level.WARN, message='no prediction within '
                                 f'input_timeout {self._rule.timeout:g} s')
        return pred


main = node_main(MotorModelNode, 'motor_model')


if __name__ == '__main__':
    main()
