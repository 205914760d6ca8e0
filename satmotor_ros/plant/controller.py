# SPDX-License-Identifier: Apache-2.0
"""
The example speed controller's law: PI on commanded flow, anti-windup, feed-forward.

No ROS here: the ``speed_controller`` node and ``satmotor demo`` call it. The flow
command is

    Q = Q_ff(n_set, dp) + k_p (b n_set - n) + I,     dI/dt = k_i e + (Q_sat - Q) / T_t

with e = n_set - n the speed error, b the set-point weight of the proportional part
(b < 1 keeps the proportional kick off a set-point step the feed-forward already makes),
Q_sat the command clipped to the pump's range and T_t = k_p / k_i the back-calculation
time constant (anti-windup). The set-point is signed: a negative one turns the motor
backwards, through the pump's range mirrored, [-flow_max, -flow_min] (a reversing valve in
front of the same pump; the plant and the model run in all four quadrants). The
feed-forward is

- ``model``: the absorbency of eq. (36) at the set-point speed and the measured port
  pressure drop, i.e. the inverse model: the flow that gives n_set at this pressure
  (``MotorModel.absorbency_point``);
- ``naive``: q_t n_set, the ideal motor;
- ``none``: 0, the PI alone.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM
from satmotor_ros.plant.errors import PlantError
from satmotor_ros.plant.params import Bounded, parameter

FEEDFORWARDS = ('model', 'naive', 'none')
"""The feed-forward choices."""


@dataclass(frozen=True)
class ControllerParams(Bounded):
    """Gains and limits of the speed controller."""

    kp: float = parameter(
        1.5e-6, 'proportional gain, flow per speed error', 'm^3/rad', 0.0, 1.0e-3)
    ki: float = parameter(
        3.0e-5, 'integral gain, flow per integrated speed error', 'm^3/(s*rad)', 0.0, 1.0e-2)
    flow_min: float = parameter(
        0.0, 'smallest flow the pump gives (negative: it reverses)', 'm^3/s', -1.0e-2, 1.0e-2)
    flow_max: float = parameter(
        60.0 * LPM, 'largest flow the pump gives', 'm^3/s', 1.0e-7, 1.0e-2)
    setpoint_weight: float = parameter(
        0.0, 'b of the proportional part k_p (b n_set - n)', '-', 0.0, 1.0)
    feedforward: str = parameter('model', "'model', 'naive' or 'none'")
    anti_windup: bool = parameter(True, 'back-calculation of the integrator at the limits')

    def __post_init__(self) -> None:
        """Reject values outside their range and an unknown feed-forward, naming the field."""
        super().__post_init__()
        if self.feedforward not in FEEDFORWARDS:
            msg = (f'ControllerParams.feedforward = {self.feedforward!r}: use one of '
                   f'{", ".join(FEEDFORWARDS)}')
            raise PlantError(msg)
        if self.flow_max <= self.flow_min:
            msg = f'ControllerParams.flow_max = {self.flow_max!r}: must exceed flow_min'
            raise PlantError(msg)


class SpeedController:
    """
    PI speed controller on commanded flow, with anti-windup and feed-forward.

    Parameters
    ----------
    params : ControllerParams
        Gains, limits and feed-forward choice, [-]
    model : MotorModel
        The motor model for the feed-forward (and q_t for the naive one), [-]

    """

    def __init__(self, params: ControllerParams, model: MotorModel) -> None:
        """Start with an empty integrator."""
        self.params = params
        self.model = model
        self.integral = 0.0  # I [m^3/s]
        self.saturated = False
        self.feedforward_flow = 0.0  # the last Q_ff [m^3/s]
        self.feedforward_fallbacks = 0  # model feed-forward refused, naive used instead

    def reset(self) -> None:
        """Empty the integrator."""
        self.integral = 0.0
        self.saturated = False

    def feedforward(self, setpoint: float, dp: float) -> float:
        """
        Compute the feed-forward flow.

        Parameters
        ----------
        setpoint : float
            Speed set-point n_set, [rad/s]
        dp : float
            Measured port pressure drop p_in - p_out, [Pa]

        Returns
        -------
        float
            Q_ff, [m^3/s]

        """
        kind = self.params.feedforward
        if kind == 'none':
            return 0.0
        naive = self.model.geometry.displacement * setpoint
        if kind == 'naive':
            return naive
        flow = self.model.absorbency_point(setpoint, dp).flow  # any quadrant
        if flow != flow:  # beyond the model's limit: fall back, and count it
            self.feedforward_fallbacks += 1
            return naive
        return flow

    def flow_range(self, setpoint: float) -> tuple[float, float]:
        """
        Give the flow commands that may drive toward `setpoint`.

        Parameters
        ----------
        setpoint : float
            Speed set-point, signed, [rad/s]

        Returns
        -------
        tuple of float
            [flow_min, flow_max] for a set-point >= 0, the mirror [-flow_max, -flow_min]
            for a negative one, [m^3/s]

        """
        p = self.params
        return (p.flow_min, p.flow_max) if setpoint >= 0.0 else (-p.flow_max, -p.flow_min)

    def update(self, setpoint: float, speed: float, dp: float, dt: float) -> float:
        """
        Advance the controller by dt and return the flow command.

        Parameters
        ----------
        setpoint : float
            Speed set-point n_set, [rad/s]
        speed : float
            Measured speed n, [rad/s]
        dp : float
            Measured port pressure drop, [Pa]
        dt : float
            Time since the last update, [s]

        Returns
        -------
        float
            Flow command within [flow_min, flow_max], or within [-flow_max, -flow_min]
            for a negative set-point, [m^3/s]

        Raises
        ------
        PlantError
            If an input is not finite or dt is not positive.

        """
        if not (math.isfinite(setpoint) and math.isfinite(speed) and math.isfinite(dp)
                and dt > 0.0 and math.isfinite(dt)):
            msg = (f'controller inputs setpoint={setpoint!r} rad/s, speed={speed!r} rad/s, '
                   f'dp={dp!r} Pa, dt={dt!r} s: all must be finite, dt > 0')
            raise PlantError(msg)
        p = self.params
        error = setpoint - speed
        ff = self.feedforward_flow = self.feedforward(setpoint, dp)
        raw = ff + p.kp * (p.setpoint_weight * setpoint - speed) + self.integral
        low, high = self.flow_range(setpoint)
        command = min(max(raw, low), high)
        self.saturated = command != raw
        rate = p.ki * error
        if p.anti_windup and p.ki > 0.0 and p.kp > 0.0:
            rate += (command - raw) * p.ki / p.kp
        elif p.anti_windup and self.saturated and error * (raw - command) > 0.0:
            rate = 0.0  # no proportional part to track with: stop integrating outwards
        self.integral += rate * dt
        return command
