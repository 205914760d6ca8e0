# SPDX-License-Identifier: Apache-2.0
"""
The ``speed_controller`` node: an example drive controller, speed loop on commanded flow.

Reads ``joint_states`` (measured speed), ``inlet_pressure`` and ``outlet_pressure`` (for the
model-based feed-forward) and the set-point from ``speed_setpoint`` (std_msgs/Float64,
rad/s, signed: a negative one turns the motor backwards) or the ``setpoint`` parameter;
publishes ``flow_command`` (m^3/s) at ``rate`` on the node's clock (so it follows
``/clock`` with ``use_sim_time``) and ``/diagnostics``. The law
(PI, anti-windup, feed-forward) is :class:`satmotor_ros.plant.controller.SpeedController`.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from rclpy.time import Time
from satmotor_ros.interface import CHANNELS, DIAGNOSTICS, JOINT_NAME, SPEED_SETPOINT
from satmotor_ros.model.units import RPM
from satmotor_ros.nodes import _diagnostics as diag
from satmotor_ros.nodes import _parameters as params
from satmotor_ros.nodes._parameters import ParamSpec, RosParameter
from satmotor_ros.nodes._spin import node_main
from satmotor_ros.plant.controller import ControllerParams, FEEDFORWARDS, SpeedController
from satmotor_ros.plant.errors import PlantError
from sensor_msgs.msg import FluidPressure, JointState
from std_msgs.msg import Float64

MAX_SETPOINT = 3000.0 * RPM
"""Largest speed set-point accepted either way (a negative one turns backwards), [rad/s]."""

_DEFAULTS = ControllerParams()
PARAMETERS: tuple[ParamSpec, ...] = (
    ParamSpec('setpoint', 0.0, 'speed set-point until one arrives on speed_setpoint; '
              'negative: backwards', 'rad/s', -MAX_SETPOINT, MAX_SETPOINT),
    ParamSpec('rate', 100.0, 'control rate on the node clock', 'Hz', 1.0, 1000.0),
    ParamSpec('kp', _DEFAULTS.kp, 'proportional gain', 'm^3/rad', 0.0, 1.0e-3),
    ParamSpec('ki', _DEFAULTS.ki, 'integral gain', 'm^3/(s*rad)', 0.0, 1.0e-2),
    ParamSpec('setpoint_weight', _DEFAULTS.setpoint_weight,
              'share of the set-point in the proportional part', '-', 0.0, 1.0),
    ParamSpec('flow_min', _DEFAULTS.flow_min, 'smallest flow command (negative: reverse)',
              'm^3/s', -1.0e-2, 1.0e-2),
    ParamSpec('flow_max', _DEFAULTS.flow_max, 'largest flow command', 'm^3/s', 1.0e-7,
              1.0e-2),
    ParamSpec('feedforward', _DEFAULTS.feedforward, 'feed-forward in front of the PI',
              choices=FEEDFORWARDS),
    ParamSpec('anti_windup', _DEFAULTS.anti_windup, 'back-calculation at the limits'),
    *params.MOTOR_PARAMETERS,
    ParamSpec('joint_name', JOINT_NAME, 'joint whose velocity is controlled'),
    ParamSpec('measurement_timeout', 0.5, 'older speed: hold the command, warn', 's', 0.001,
              60.0),
    ParamSpec('diagnostics_period', 1.0, 'period of /diagnostics', 's', 0.01, 60.0),
)
"""Every parameter of the node."""

_LAW = ('kp', 'ki', 'setpoint_weight', 'flow_min', 'flow_max', 'feedforward', 'anti_windup')


class SpeedControllerNode(Node):
    """
    The speed controller as a ROS node.

    Parameters
    ----------
    node_name : str
        Node name, [-]
    **kwargs
        Passed to :class:`rclpy.node.Node`, [-]

    """

    def __init__(self, node_name: str = 'speed_controller', **kwargs: Any) -> None:
        """Declare parameters, build the law, open topics, start the control timer."""
        super().__init__(node_name, **kwargs)
        self._specs = {spec.name: spec for spec in PARAMETERS}
        params.declare_logged(self, PARAMETERS)
        self.values = params.values(self, PARAMETERS)
        self.law = self._build(self.values)  # invalid start-up parameters raise here
        self._liquid_source = params.liquid_source(self)
        self.add_on_set_parameters_callback(self._validate)
        self.add_post_set_parameters_callback(self._apply)
        self.setpoint = self.values['setpoint']
        self.speed: float | None = None
        self._speed_time: Time | None = None
        self._p_in = self._p_out = math.nan
        self._last_time: Time | None = None
        self.command = 0.0
        self.rejected = 0
        self.last_rejection = ''
        self._rejected_since = 0
        self._next_diagnostics = 0.0
        self._pub = self.create_publisher(Float64, CHANNELS['flow'].topic, 10)
        self._diag = self.create_publisher(DiagnosticArray, DIAGNOSTICS, 10)
        sensor = qos_profile_sensor_data
        self.create_subscription(JointState, CHANNELS['measured_speed'].topic, self._on_joint,
                                 sensor)
        self.create_subscription(FluidPressure, CHANNELS['p_in'].topic, self._on_inlet, sensor)
        self.create_subscription(FluidPressure, CHANNELS['p_out'].topic, self._on_outlet,
                                 sensor)
        self.create_subscription(Float64, SPEED_SETPOINT, self._on_setpoint, 10)
        self._timer = self.create_timer(1.0 / self.values['rate'], self._control)

    @staticmethod
    def _build(values: dict[str, Any]) -> SpeedController:
        model = params.motor_options(values).build_model()
        if not values['joint_name']:
            raise ValueError('joint_name is empty')
        return SpeedController(ControllerParams(**{k: values[k] for k in _LAW}), model)

    def _validate(self, changes: list[RosParameter]) -> SetParametersResult:
        result = params.check(self._specs, changes)
        if not result.successful:
            self.get_logger().warning(f'parameter change refused: {result.reason}')
            return result
        values = dict(self.values)
        values.update({p.name: p.value for p in changes})
        try:
            self._pending = (values, self._build(values))
        except (ValueError, OSError) as err:
            self.get_logger().warning(f'parameter change refused: {err}')
            return SetParametersResult(successful=False, reason=str(err))
        return SetParametersResult(successful=True)

    def _apply(self, changes: list[RosParameter]) -> None:
        values, law = self._pending
        if any(p.name == 'liquid' for p in changes):
            self._liquid_source = 'parameter'
        law.integral = self.law.integral  # bumpless: keep the integrator
        self.law = law
        if values['setpoint'] != self.values['setpoint']:
            self.setpoint = values['setpoint']
        if values['rate'] != self.values['rate']:
            self.destroy_timer(self._timer)
            self._timer = self.create_timer(1.0 / values['rate'], self._control)
        self.values = values

    def _refuse(self, what: str) -> None:
        self.rejected += 1
        self._rejected_since += 1
        self.last_rejection = what
        self.get_logger().warning(what, throttle_duration_sec=1.0)

    def _on_setpoint(self, msg: Float64) -> None:
        if not (math.isfinite(msg.data) and abs(msg.data) <= MAX_SETPOINT):
            self._refuse(f'speed_setpoint.data = {msg.data!r} rad/s: not finite or beyond '
                         f'+-{MAX_SETPOINT / RPM:.0f} rpm; holding {self.setpoint / RPM:.1f} rpm')
            return
        self.setpoint = msg.data

    def _on_joint(self, msg: JointState) -> None:
        try:
            index = list(msg.name).index(self.values['joint_name'])
            speed = float(msg.velocity[index])
        except (ValueError, IndexError):
            self._refuse(f"joint_states has no velocity for {self.values['joint_name']!r}")
            return
        if not math.isfinite(speed):
            self._refuse(f'measured speed {speed!r} rad/s is not finite')
            return
        self.speed = speed
        self._speed_time = self.get_clock().now()

    def _on_inlet(self, msg: FluidPressure) -> None:
        if math.isfinite(msg.fluid_pressure):
            self._p_in = msg.fluid_pressure

    def _on_outlet(self, msg: FluidPressure) -> None:
        if math.isfinite(msg.fluid_pressure):
            self._p_out = msg.fluid_pressure

    def _control(self) -> None:
        # every tick publishes: the new command, or the held one when there is no fresh
        # measurement yet (a plant in lockstep takes each period's command as its answer)
        now = self.get_clock().now()
        last, self._last_time = self._last_time, now
        if last is None or self.speed is None or self._speed_time is None:
            self._pub.publish(Float64(data=self.command))
            return
        dt = (now - last).nanoseconds * 1e-9
        stale = (now - self._speed_time).nanoseconds * 1e-9 > self.values['measurement_timeout']
        if dt > 0.0 and not stale:
            dp = self._p_in - self._p_out
            try:
                self.command = self.law.update(self.setpoint, self.speed,
                                               dp if math.isfinite(dp) else 0.0, dt)
            except PlantError as err:  # cannot happen with the checks above; never die on it
                self._refuse(str(err))
        self._pub.publish(Float64(data=self.command))
        self._diagnose(now, stale)

    def _diagnose(self, now: Time, stale: bool) -> None:
        t = now.nanoseconds * 1e-9
        if t < self._next_diagnostics:
            return
        self._next_diagnostics = t + self.values['diagnostics_period']
        level, message = 0, 'tracking'
        if stale:
            level, message = 1, 'speed measurement is stale; command held'
        elif self._rejected_since:
            level = 1
            message = f'refused {self._rejected_since} input(s): {self.last_rejection}'
        elif self.law.saturated:
            level, message = 1, 'flow command saturated'
        self._rejected_since = 0
        values = {  # in the units a person reads; no measurement yet: n/a
            'setpoint [rpm]': diag.human(self.setpoint, 'rad/s')[1],
            'speed [rpm]': diag.human(self.speed, 'rad/s')[1],
            'flow_command [l/min]': diag.human(self.command, 'm^3/s')[1],
            'feedforward [l/min]': diag.human(self.law.feedforward_flow, 'm^3/s')[1],
            'integral [l/min]': diag.human(self.law.integral, 'm^3/s')[1],
            'feedforward': self.law.params.feedforward, 'rejected_inputs': self.rejected,
            'last_rejection': self.last_rejection, 'liquid': self.values['liquid'],
            'liquid_source': self._liquid_source,
        }
        status = diag.status(f'{self.get_fully_qualified_name()}: speed loop', 'speed loop',
                             level, message, values)
        self._diag.publish(diag.array(now, [status]))

    def controller_params(self) -> ControllerParams:
        """
        Give the law's parameters now in force.

        Returns
        -------
        ControllerParams
            A copy of the parameters.

        """
        return dataclasses.replace(self.law.params)


main = node_main(SpeedControllerNode, 'speed_controller')


if __name__ == '__main__':
    main()
