# SPDX-License-Identifier: Apache-2.0
"""
Scripted test cycles (speed and load steps) and their tracking metrics.

A :class:`Cycle` is a list of segments, each holding a speed set-point and a load
torque for a duration. :func:`step_metrics` measures, per set-point step, the 10-90 %
rise time, the overshoot, the steady-state error and the integral of the absolute
error (IAE). :func:`run_closed_loop` runs the plant with the controller law without
ROS, for tests and for a reference to compare the ROS demo against.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
from typing import NamedTuple

import numpy as np

from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import MPA, RPM
from satmotor_ros.plant.controller import ControllerParams, SpeedController
from satmotor_ros.plant.load import ConstantLoad
from satmotor_ros.plant.params import PlantParams
from satmotor_ros.plant.plant import Plant


@dataclass(frozen=True)
class Segment:
    """One piece of a cycle."""

    duration: float  # [s]
    setpoint: float  # speed set-point [rad/s]
    load: float  # load torque (a brake) [N*m]
    case_offset: float | None = None  # case pressure above tank at zero p_out [Pa]; None: kept


@dataclass(frozen=True)
class Cycle:
    """A sequence of set-point and load steps."""

    segments: tuple[Segment, ...]

    @property
    def duration(self) -> float:
        """Total length of the cycle, [s]."""
        return sum(s.duration for s in self.segments)

    def at(self, time: float) -> Segment:
        """
        Give the segment in force at `time` (the last one after the end).

        Parameters
        ----------
        time : float
            Time from the start of the cycle, [s]

        Returns
        -------
        Segment
            The segment.

        """
        end = 0.0
        for segment in self.segments:
            end += segment.duration
            if time < end:
                return segment
        return self.segments[-1]

    def scaled(self, duration: float) -> Cycle:
        """
        Stretch or shrink the cycle to a total duration.

        Parameters
        ----------
        duration : float
            New total length, [s]

        Returns
        -------
        Cycle
            The same steps, each segment scaled in time.

        """
        k = duration / self.duration
        return Cycle(tuple(replace(s, duration=s.duration * k) for s in self.segments))


def default_cycle() -> Cycle:
    """
    Give the demo's cycle: speed steps 300-1200 rpm and load steps 20-90 N*m, 24 s.

    Returns
    -------
    Cycle
        The cycle.

    """
    rows = ((2.0, 300.0, 20.0), (3.0, 800.0, 20.0), (3.0, 800.0, 80.0), (3.0, 1200.0, 80.0),
            (3.0, 1200.0, 40.0), (3.0, 500.0, 40.0), (3.0, 500.0, 90.0), (4.0, 900.0, 30.0))
    return Cycle(tuple(Segment(d, n * RPM, load) for d, n, load in rows))


CASE_OFFSETS = (0.05 * MPA, 0.2 * MPA, 0.4 * MPA)
"""The identification cycle's three case pressures (the drain throttled), above tank [Pa]."""


def identification_cycle() -> Cycle:
    """
    Give a bench's identification cycle: 9 steady points, 300-1200 rpm by 20-80 N*m, 36 s.

    Each speed is held while the load steps up, so every point of the grid is a steady
    window of its own: what a calibration needs to tell the losses apart, where the
    tracking cycle of :func:`default_cycle` has too few distinct points. The case drain
    is throttled to one of :data:`CASE_OFFSETS` per point, in a Latin square over speed
    and load: otherwise the case pressure follows the outlet pressure, hence the speed,
    and a leak to the case looks like the speed-driven losses (the inertia loss of
    eq. 14 above all).

    Returns
    -------
    Cycle
        The cycle.

    """
    return Cycle(tuple(Segment(4.0, n * RPM, load, CASE_OFFSETS[(i + j) % 3])
                       for i, n in enumerate((300.0, 750.0, 1200.0))
                       for j, load in enumerate((20.0, 50.0, 80.0))))


class StepMetrics(NamedTuple):
    """Tracking quality after one set-point step."""

    time: float  # when the set-point stepped [s]
    start: float  # set-point before [rad/s]
    target: float  # set-point after [rad/s]
    rise_time: float  # 10 % to 90 % of the step; NaN if never reached [s]
    overshoot: float  # beyond the target, share of the step [%]
    steady_state_error: float  # mean of target - speed over the last 20 % of the segment [rad/s]
    iae: float  # integral of |target - speed| over the segment [rad]


def step_metrics(time: np.ndarray, setpoint: np.ndarray, speed: np.ndarray,
                 load: np.ndarray | None = None) -> list[StepMetrics]:
    """
    Measure rise time, overshoot, steady-state error and IAE after each step.

    A segment ends where the set-point or the load changes; a load step is a
    segment whose set-point did not change (no rise time; its overshoot 0).

    Parameters
    ----------
    time : ndarray
        Sample times, increasing, [s]
    setpoint : ndarray
        Set-point at each sample, [rad/s]
    speed : ndarray
        Measured speed at each sample, [rad/s]
    load : ndarray, optional
        Load torque at each sample, [N*m]

    Returns
    -------
    list of StepMetrics
        One per segment (the first counts as a step from 0).

    """
    time, setpoint, speed = (np.asarray(a, dtype=float) for a in (time, setpoint, speed))
    changed = np.diff(setpoint) != 0.0
    if load is not None:
        changed |= np.diff(np.asarray(load, dtype=float)) != 0.0
    edges = [0, *np.flatnonzero(changed) + 1, len(time)]
    result = []
    for i0, i1 in zip(edges[:-1], edges[1:]):
        if i1 - i0 < 3:
            continue
        t, y = time[i0:i1], speed[i0:i1]
        target = float(setpoint[i0])
        start = float(setpoint[i0 - 1]) if i0 > 0 else 0.0
        step = target - start
        err = target - y
        iae = float(np.sum(np.abs(err[:-1]) * np.diff(t)))
        tail = err[int(0.8 * len(err)):]
        sse = float(np.mean(tail))
        if step == 0.0:
            result.append(StepMetrics(float(t[0]), start, target, math.nan, 0.0, sse, iae))
            continue
        progress = (y - start) / step
        reached10 = np.flatnonzero(progress >= 0.1)
        reached90 = np.flatnonzero(progress >= 0.9)
        rise = (float(t[reached90[0]] - t[reached10[0]])
                if len(reached10) and len(reached90) else math.nan)
        overshoot = max(0.0, float(np.max(progress)) - 1.0) * 100.0
        result.append(StepMetrics(float(t[0]), start, target, rise, overshoot, sse, iae))
    return result


class ClosedLoopRun(NamedTuple):
    """A closed-loop run sampled at the controller's rate."""

    time: np.ndarray  # [s]
    setpoint: np.ndarray  # [rad/s]
    speed: np.ndarray  # [rad/s]
    flow_command: np.ndarray  # [m^3/s]
    dp: np.ndarray  # port pressure drop [Pa]
    load: np.ndarray  # [N*m]


def run_closed_loop(model: MotorModel, cycle: Cycle, controller: ControllerParams,
                    params: PlantParams | None = None, rate: float = 100.0,
                    delay: int = 1) -> ClosedLoopRun:
    """
    Run plant and controller through a cycle without ROS.

    Parameters
    ----------
    model : MotorModel
        Motor and liquid of the plant and of the feed-forward, [-]
    cycle : Cycle
        Set-points and loads, [-]
    controller : ControllerParams
        The controller, [-]
    params : PlantParams, optional
        The plant, [-]
    rate : float
        Controller rate, [Hz]
    delay : int
        Controller periods between a measurement and its command reaching the plant
        (1 is what topics at one rate give), [-]

    Returns
    -------
    ClosedLoopRun
        Samples at each controller update.

    """
    plant = Plant(model, params, ConstantLoad())
    law = SpeedController(controller, model)
    per_update = max(1, round(1.0 / (rate * plant.params.step)))
    dt = per_update * plant.params.step
    count = int(cycle.duration / dt)
    out = np.zeros((6, count))
    pending = [0.0] * delay
    for k in range(count):
        t = k * dt
        segment = cycle.at(t)
        reading = plant.measure()
        dp = reading.inlet_pressure - reading.outlet_pressure
        pending.append(law.update(segment.setpoint, reading.speed, dp, dt))
        command = pending.pop(0)
        out[:, k] = (t, segment.setpoint, reading.speed, command, dp, segment.load)
        plant.run(per_update, command, segment.load)
    return ClosedLoopRun(*out)
