# SPDX-License-Identifier: Apache-2.0
"""
The virtual motor: lines, relief valves, shaft and heat around the model's motor.

State: pressure p_in of the line at port A, p_out of the line at port B (both
absolute), shaft speed omega and angle theta, liquid temperature T. Per step of dt:

0. the pump delivers the flow command through a first-order lag; a negative
   command feeds port B (a directional valve: the pump line and the return line
   swap, and the shaft turns backwards);
1. the motor model gives the absorbency Q_m(omega, dp) at the start of the step
   (eqs. (34)-(36) of Śliwiński 2017, through the model's single-point path, in
   any quadrant: doc/quadrants.md);
2. a linearly implicit (backward Euler) step solves the line pressures (P1),
   a relief valve on each line (P2), the return valve (P3) and the shaft (P4), (P5)
   together, with Q_m linearised as
   ``Q_m' = Q_m + q_t (omega' - omega) + G (dp' - dp)``, G >= 0 the secant
   leakage conductance. Stiff terms (line compliance against valves and
   displacement) are implicit, so the step is stable for water and small
   volumes at any dt; at a steady state the linearisation is exact, so the
   plant settles on the model's eqs. (36)/(40);
3. dry friction sticks and slips (Karnopp): a resting shaft stays at rest
   while the net torque is within the static limit;
4. the temperature follows the lost power (P8), explicitly;
5. drifting effects (viscosity, wear) rebuild the motor when their value moved;
6. a step fault (``params.fault``) swaps in its effects once the clock reaches its time.

Effects are injected through their kinds (:mod:`satmotor_ros.model.effects`):
the plant's motor model evaluates the motor effects at the plant's channels,
drifting effects rebuild it within ``rebuild_tolerance``, an external leakage
leaves the inlet line implicitly, and sensor effects act on the readings.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from satmotor_ros.model import MotorModel
from satmotor_ros.model._inline import inline_equations
from satmotor_ros.model.effects import (check_effects, Conditions, Effect, kind_of,
                                        plant_injection, PlantInjection, sensor_error)
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.motor import with_effects
from satmotor_ros.model.revolutions import revolutions
from satmotor_ros.model.units import channel_gauge
from satmotor_ros.model.viscosity import standard_law
from satmotor_ros.plant.config import params_from_flat
from satmotor_ros.plant.equations import (case_pressure, driving_torque, friction_torque,
                                          return_flow, temperature_rate)
from satmotor_ros.plant.errors import PlantError
from satmotor_ros.plant.load import ConstantLoad, LoadProfile
from satmotor_ros.plant.motor import MotorCache
from satmotor_ros.plant.params import PlantParams
from satmotor_ros.plant.sensors import Sensor

_DP_REF = 0.1e6
"""Pressure drop below which the leakage conductance is taken as secant to this value, [Pa]."""

MAX_FLOW_COMMAND = 1.0e-2
"""Largest flow command the plant accepts, either sign (600 l/min), [m^3/s]."""


class PlantState(NamedTuple):
    """The plant's state (SI, absolute pressures)."""

    time: float  # [s]
    inlet_pressure: float  # p_in [Pa]
    outlet_pressure: float  # p_out [Pa]
    speed: float  # omega [rad/s]
    angle: float  # theta [rad]
    temperature: float  # T [degC]


class StepFlows(NamedTuple):
    """The flows of the last step, as the integrator balanced them, [m^3/s]."""

    command: float  # from the pump into line A; < 0: into line B (after the pump's lag)
    motor: float  # into the motor's port A (model absorbency, linearised)
    relief: float  # relief valves, both lines to tank
    leakage: float  # external-leakage effects, pump line to tank
    model_external: float  # the model's own external leakage Q_ex (eq. 24), return line
    returned: float  # return valve, return line (B; A for a negative command) to tank
    cavitation_in: float  # make-up that held p_in at the vapour pressure
    cavitation_out: float  # make-up that held p_out at the vapour pressure


class Measurement(NamedTuple):
    """What the sensors read (SI, absolute pressures, degC)."""

    time: float  # [s]
    inlet_pressure: float  # [Pa]
    outlet_pressure: float  # [Pa]
    case_pressure: float  # [Pa]
    flow: float  # flow into the motor [m^3/s]
    speed: float  # [rad/s]
    angle: float  # [rad]
    torque: float  # shaft torque delivered to the load [N*m]
    temperature: float  # [degC]


class Plant:
    """
    The virtual SM-0,75/25 on its test rig, stepped at a fixed dt.

    Parameters
    ----------
    model : MotorModel
        The motor and liquid; the only source of the volumetric losses, [-]
    params : PlantParams, optional
        Lines, valves, shaft, heat, effects and sensors, [-]
    load : LoadProfile, optional
        Load torque law; no load when omitted. A passive load (the default,
        ``params.active_load`` False) brakes: its torque opposes the motion and
        holds a resting shaft like dry friction. An active load drives the
        shaft backwards when the pressure cannot hold it, [-]

    Examples
    --------
    >>> from satmotor_ros.model import MotorModel
    >>> plant = Plant(MotorModel.default('oil'))
    >>> plant.run(100, 20e-3 / 60.0)
    >>> plant.state.speed > 0.0
    True

    """

    def __init__(self, model: MotorModel, params: PlantParams | None = None,
                 load: LoadProfile | None = None) -> None:
        """Fold the parameters into the constants of the step."""
        self.params = params if params is not None else PlantParams()
        self.load = load if load is not None else ConstantLoad()
        self._base = model
        self._struck = False
        self._prepare_fault()
        self._build_motor()
        self._set_constants()
        self.reset()

    def _prepare_fault(self) -> None:
        """Build and check the effects of the step fault now, so a bad one fails at set-up."""
        fault = self.params.fault
        self._fault_at = math.inf  # plant time of a fault still to strike [s]
        self._faulted: tuple[Effect, ...] = self.params.effects
        if fault.effect:
            self._faulted = params_from_flat({f'effects.{fault.effect}': fault.value},
                                             self.params).effects
            try:
                check_effects(self._faulted, 'fault', self._base.family.name)
            except ConfigError as err:
                raise PlantError(str(err)) from None
            self._fault_at = fault.time

    def _build_motor(self) -> None:
        """Inject the effects: the motor ones into the model, the rest sorted by kind."""
        motor = getattr(self, '_motor', None)
        self._rebuilt = getattr(self, '_rebuilt', 0) + (motor.rebuilds if motor else 0)
        p, base = self.params, self._base
        effects = self._faulted if self._struck else p.effects
        try:
            check_effects(effects, 'PlantParams.effects', base.family.name)
        except ConfigError as err:
            raise PlantError(str(err)) from None
        bound = effects
        if bound:  # effects that leave the law to the liquid take its standard one
            law = standard_law(base.liquid, base.coefficient_set.name)
            bound = tuple(kind_of(e).bind(e, law, p.thermal.reference) for e in bound)
        self._injection: PlantInjection = plant_injection(bound)
        self._drifting = bool(self._injection.drift)
        self._injected = (p.effects, p.thermal.reference)
        self._motor = MotorCache(with_effects(base, self._injection.motor), p.rebuild_tolerance)
        self._point = self._motor.model.absorbency_point
        self._q_guess: float | None = None
        # the revolutions are read only as a channel, by the model's effects or a drift
        self._counts_revolutions = self._drifting or bool(self._motor.model.channels)

    def _set_constants(self) -> None:
        p = self.params
        model = self._motor.model
        dt = self._dt = p.step
        k = model.liquid.bulk_modulus
        lines, relief, shaft = p.lines, p.relief, p.shaft
        self._qt = model.geometry.displacement
        self._a = lines.inlet_volume / (k * dt)
        self._c = lines.outlet_volume / (k * dt)
        self._m = shaft.inertia / dt
        self._b = shaft.viscous_friction
        self._tc = shaft.coulomb_friction
        self._cp = shaft.pressure_friction
        self._locked = shaft.locked
        self._active_load = p.active_load
        self._pt = lines.tank_pressure
        self._pv = lines.vapour_pressure
        self._gr = lines.return_conductance
        self._pr0 = lines.tank_pressure + lines.back_pressure
        self._kv = relief.conductance
        self._pcr = lines.tank_pressure + relief.cracking_pressure
        self._e0, self._e1 = self._bypass()
        th = p.thermal
        self._heat = (th.heat_capacity, th.cooling, th.ambient)
        self._lag = dt / (p.pump_lag + dt)
        self._solve_constants = (self._qt, self._a, self._c, self._e0, self._e1, self._gr,
                                 self._pr0, self._kv, self._pcr)

    def _bypass(self) -> tuple[float, float]:
        """Return e0, e1 of the injected leakage k * gauge pressure = e1 * p_out + e0."""
        case, pt = self.params.case, self.params.lines.tank_pressure
        e0 = e1 = 0.0
        for channel, k in self._injection.bypass:
            if channel == 'p_case':  # eq. (P6): p_case - p_t = offset + share (p_out - p_t)
                e1 += k * case.outlet_share
                e0 += k * (case.offset - case.outlet_share * pt)
            elif channel == 'p_out':
                e1 += k
                e0 -= k * pt
            else:
                msg = f'an inlet-line leakage driven by {channel!r}: use p_case or p_out'
                raise PlantError(msg)
        return e0, e1

    def reset(self, inlet_pressure: float | None = None, outlet_pressure: float | None = None,
              speed: float = 0.0, temperature: float | None = None) -> None:
        """
        Put the plant at rest (or at a given state) at t = 0, sensors reseeded.

        Parameters
        ----------
        inlet_pressure : float, optional
            p_in, absolute; the return back pressure when omitted, [Pa]
        outlet_pressure : float, optional
            p_out, absolute; the return back pressure when omitted, [Pa]
        speed : float
            omega, [rad/s]
        temperature : float, optional
            T; the thermal parameters' initial value when omitted, [degC]

        """
        self._n = 0
        self._t = 0.0
        self._q_pump = 0.0  # flow the pump delivers [m^3/s]
        self._p_in = self._pr0 if inlet_pressure is None else float(inlet_pressure)
        self._p_out = self._pr0 if outlet_pressure is None else float(outlet_pressure)
        self._w = 0.0 if self._locked else float(speed)
        self._theta = 0.0
        self._temp = self.params.thermal.initial if temperature is None else float(temperature)
        if self._struck:  # back to t = 0: the motor as configured, the fault to come
            self._struck = False
            self._build_motor()
            self._set_constants()
        self._prepare_fault()
        self._revolutions = 0.0
        self._q_guess = None
        self._lin = (0.0, 0.0, 0.0, 0.0)  # last good (G, h, channel drop, model Q_ex)
        self._last = (0.0, self._p_in, self._p_out, (False, False))  # q, p_a, p_b, reliefs
        self._torque = 0.0
        self._dp_i = 0.0
        self.model_status = 0  # PointStatus flags of the last model evaluation
        self.invalid_points = 0  # steps that fell back on the last good linearisation
        self._make_sensors()

    def reconfigure(self, params: PlantParams, model: MotorModel | None = None) -> None:
        """
        Change parameters (and optionally the motor) and keep the state.

        Parameters
        ----------
        params : PlantParams
            New parameters, [-]
        model : MotorModel, optional
            A new motor or liquid; the drifting effects restart from it, [-]

        """
        self.params = params
        injected = (params.effects, params.thermal.reference)
        self._base = model or self._base
        self._prepare_fault()  # a fault already due strikes again at the next step
        if (model is not None or params.rebuild_tolerance != self._motor.tolerance
                or injected != self._injected or self._struck):
            self._struck = False
            self._build_motor()
            self._drift()
        self._set_constants()
        if self._locked:
            self._w = 0.0
        self._make_sensors()

    def _make_sensors(self) -> None:
        p = self.params
        self._rng = np.random.default_rng(p.seed)
        self._sensors_for(self._rng)

    def _sensors_for(self, rng: np.random.Generator) -> None:
        p = self.params
        s, effects = p.sensors, self._injection.sensors
        self._sensors = (
            Sensor(s.inlet_pressure, rng), Sensor(s.outlet_pressure, rng),
            Sensor(s.case_pressure, rng), Sensor(s.flow, rng, sensor_error(effects, 'flow')),
            Sensor(s.speed, rng, sensor_error(effects, 'speed')), Sensor(s.temperature, rng))

    @property
    def model(self) -> MotorModel:
        """Motor model in use now (with the motor effects, rebuilt by the drifting ones)."""
        return self._motor.model

    @property
    def fault_struck(self) -> bool:
        """Whether the step fault of ``params.fault`` has struck."""
        return self._struck

    @property
    def rebuilds(self) -> int:
        """How many times the drifting effects rebuilt the motor model."""
        return self._rebuilt + self._motor.rebuilds

    @property
    def state(self) -> PlantState:
        """State after the last step."""
        return PlantState(self._t, self._p_in, self._p_out, self._w, self._theta, self._temp)

    def step(self, flow_command: float, load_torque: float | None = None) -> None:
        """
        Advance the plant by one step dt.

        Parameters
        ----------
        flow_command : float
            Flow from the pump into line A (negative: into line B), at most
            MAX_FLOW_COMMAND either way, [m^3/s]
        load_torque : float, optional
            Load torque for this step instead of the load profile, [N*m]

        Raises
        ------
        PlantError
            If the command is not finite or beyond +-MAX_FLOW_COMMAND (the state is unchanged).

        """
        if not -MAX_FLOW_COMMAND <= flow_command <= MAX_FLOW_COMMAND:
            msg = (f'flow_command = {flow_command!r} m^3/s: outside [-{MAX_FLOW_COMMAND}, '
                   f'{MAX_FLOW_COMMAND}]')
            raise PlantError(msg)
        load, slope, dry = self._load_torques(load_torque)
        flow = self._pump(flow_command)
        lin = self._linearise()
        p, r, relief, w_new = self._solve_step(flow, lin, load, slope, dry)
        self._last = (flow, p, r, relief)  # as solved: the flows balance with these
        pv = self._pv  # a line below the vapour pressure is held there by make-up flow
        self._settle(pv if pv > p else p, pv if pv > r else r, w_new, lin[2], flow)  # max()
        if self._drifting:
            self._drift()
        if self._t >= self._fault_at:
            self._strike()

    def _strike(self) -> None:
        """Swap in the fault's effects; the state, the sensors' noise stream carry on."""
        self._struck, self._fault_at = True, math.inf
        self._build_motor()
        self._drift()
        self._set_constants()
        self._sensors_for(self._rng)

    def _load_torques(self, load_torque: float | None) -> tuple[float, float, float]:
        """Return the load torque, its slope over speed and the dry friction it adds to."""
        if load_torque is None:
            load, slope = self.load.at(self._t)
        elif load_torque - load_torque == 0.0:  # finite
            load, slope = load_torque, 0.0
        else:
            msg = f'load_torque = {load_torque!r} N*m: not finite'
            raise PlantError(msg)
        if not self._active_load:  # a brake: |t0| adds to the dry friction
            return 0.0, slope, self._tc + abs(load)
        return load, slope, self._tc

    def _pump(self, flow_command: float) -> float:
        """Follow the command with the pump's first-order lag (implicit: any lag >= 0)."""
        self._q_pump += self._lag * (flow_command - self._q_pump)
        return self._q_pump

    def _linearise(self) -> tuple[float, float, float, float]:
        """Linearise the motor at the start of the step as Q_m' = q_t w' + G dp' + h."""
        w, dp, qt = self._w, self._p_in - self._p_out, self._qt
        channels = self._channels() if self._motor.model.channels else None
        pt = self._point(w, dp, flow_guess=self._q_guess, channels=channels)  # any quadrant
        q, dp_i, q_id, qx, self.model_status = pt[0], pt[3], pt[9], abs(pt[10]), pt[12]
        if q != q:  # NaN: the model refused the point; keep the last good linearisation
            self.invalid_points += 1
            return self._lin
        self._q_guess = q
        qtw = qt * w
        # the conductance leaves out eq. (14)'s loss, which does not grow with the pressure
        g = abs(q - qtw - q_id) / max(abs(dp), _DP_REF)
        self._lin = (g, q - qtw - g * dp, dp - dp_i, qx)
        return self._lin

    def _solve_step(self, flow: float, lin: tuple[float, float, float, float], load: float,
                    slope: float, dry: float) -> tuple[float, float, tuple[bool, bool], float]:
        """Solve the lines and the shaft: sliding, sticking or breaking away (Karnopp)."""
        w, dich = self._w, lin[2]
        relief = (self._p_in > self._pcr, self._p_out > self._pcr)
        if w == 0.0:
            p, r, relief = self._solve(flow, lin, 0.0, 0.0, relief)
            sign = 0.0 if self._locked else self._breakaway(p - r - dich, load, dry)
            if sign == 0.0:
                return p, r, relief, 0.0
        else:
            sign = 1.0 if w > 0.0 else -1.0
        dp = self._p_in - self._p_out
        kt = self._qt * (1.0 - self._cp * sign * (1.0 if dp >= dich else -1.0))
        den = self._m + self._b + slope
        w0 = (self._m * w - kt * dich - sign * dry - load) / den
        wk = kt / den
        p, r, relief = self._solve(flow, lin, w0, wk, relief)
        w_new = w0 + wk * (p - r)
        if w_new * sign < 0.0:  # friction stops the shaft within the step
            p, r, relief = self._solve(flow, lin, 0.0, 0.0, relief)
            w_new = 0.0
        return p, r, relief, w_new

    @inline_equations
    def _settle(self, p: float, r: float, w_new: float, dich: float, flow: float) -> None:
        """Take the new state: torque, heat (P8), angle, revolutions and time."""
        dt = self._dt
        dp_i = self._dp_i = p - r - dich
        torque = 0.0
        if w_new != 0.0:
            torque = (driving_torque(dp_i, self._qt)
                      - friction_torque(w_new, dp_i, self._qt, self._b, self._tc, self._cp))
        self._torque = torque
        heat_capacity, cooling, ambient = self._heat
        loss_power = abs(flow) * ((p if flow >= 0.0 else r) - self._pt) - w_new * torque
        self._temp += dt * temperature_rate(loss_power, self._temp, ambient, heat_capacity,
                                            cooling)
        self._p_in, self._p_out, self._w = p, r, w_new
        self._theta += w_new * dt
        if self._counts_revolutions:
            self._revolutions = revolutions(w_new, dt, self._revolutions)
        self._n += 1
        self._t = self._n * dt

    def _breakaway(self, dp_i: float, load: float, dry: float) -> float:
        """Return 0 while static friction holds the shaft, else the direction it breaks away."""
        drive = self._qt * dp_i - load
        if abs(drive) <= dry + self._cp * self._qt * abs(dp_i):
            return 0.0
        return 1.0 if drive > 0.0 else -1.0

    def _solve(self, q_cmd: float, lin: tuple[float, float, float, float], w0: float,
               wk: float, relief: tuple[bool, bool]) -> tuple[float, float, tuple[bool, bool]]:
        """
        Solve the implicit line pressures p_a, p_b with omega' = w0 + wk (p_a - p_b).

        In the frame of the pump line P (A, or B for a negative command) and the
        return line R, with d = +-1 the direction and Q_m' = d (q_t omega' + G
        (p_a - p_b) + h) the motor flow from P to R:

        Pump:   a (P - p_P)  = |Q_cmd| - Q_m' - Q_rv(P) - Q_x(R)        (P1), (P2)
        Return: c (R - p_R) = Q_m' - Q_ex - Q_r(R) - Q_rv(R)             (P1), (P2), (P3)

        Each relief valve is tried in its last state and switched if the
        solution contradicts it.
        """
        g, h, _, qx = lin
        qt, a, c, e0, e1, gr, pr0, kv, pcr = self._solve_constants
        d = 1.0 if q_cmd >= 0.0 else -1.0
        if d < 0.0:  # the directional valve feeds B: the lines swap
            a, c = c, a
            p_pump, p_return, on_pump, on_return = self._p_out, self._p_in, relief[1], relief[0]
        else:
            p_pump, p_return, on_pump, on_return = self._p_in, self._p_out, relief[0], relief[1]
        qwk = qt * wk
        qw0 = qt * (d * w0)
        a11 = a + g + qwk
        a12 = e1 - g - qwk
        a21 = -g - qwk
        a22 = c + g + gr + qwk
        b1 = a * p_pump + d * q_cmd - d * h - e0 - qw0
        b2 = c * p_return + d * h - qx + gr * pr0 + qw0
        p = r = 0.0
        for _ in range(4):
            c11, d1 = (a11 + kv, b1 + kv * pcr) if on_pump else (a11, b1)
            c22, d2 = (a22 + kv, b2 + kv * pcr) if on_return else (a22, b2)
            det = c11 * c22 - a12 * a21
            p = (d1 * c22 - a12 * d2) / det
            r = (c11 * d2 - a21 * d1) / det
            if (p > pcr) == on_pump and (r > pcr) == on_return:
                break
            if (p > pcr) != on_pump:
                on_pump = not on_pump
            else:
                on_return = not on_return
        if d < 0.0:
            return r, p, (on_return, on_pump)
        return p, r, (on_pump, on_return)

    def _drift(self) -> None:
        """Rebuild the motor when a drifting effect has moved its viscosity or clearances."""
        base = self._motor.base
        now = Conditions(base.liquid.kinematic_viscosity, 0.0, 0.0, 0.0)
        channels = self._channels()
        for effect in self._injection.drift:
            now = kind_of(effect).condition(effect, channels[effect.regressor], now)
        if self._motor.update(now.viscosity, now.growth, now.leakage):
            self._q_guess = None
            self._point = self._motor.model.absorbency_point

    def run(self, steps: int, flow_command: float, load_torque: float | None = None) -> None:
        """
        Advance by `steps` steps at a constant command.

        Parameters
        ----------
        steps : int
            Number of steps, [-]
        flow_command : float
            Flow from the pump, [m^3/s]
        load_torque : float, optional
            Load torque instead of the load profile, [N*m]

        """
        step = self.step
        for _ in range(steps):
            step(flow_command, load_torque)

    @property
    def flows(self) -> StepFlows:
        """Flows the last step balanced (constant over the step)."""
        q_cmd, p, r, relief = self._last
        g, h, _, qx = self._lin
        # a line solved below the vapour pressure was held there by make-up flow
        cav_in = max(self._pv - p, 0.0) * self._a
        cav_out = max(self._pv - r, 0.0) * self._c
        motor = self._qt * self._w + g * (p - r) + h
        back = r if q_cmd >= 0.0 else p  # the return line
        return StepFlows(
            command=q_cmd, motor=motor,
            relief=(self._kv * (p - self._pcr) if relief[0] else 0.0)
            + (self._kv * (r - self._pcr) if relief[1] else 0.0),
            leakage=self._e1 * back + self._e0, model_external=qx,
            returned=return_flow(back, self._pr0, 0.0, self._gr),
            cavitation_in=cav_in, cavitation_out=cav_out)

    @property
    def chamber_pressure_drop(self) -> float:
        """Pressure drop in the working chambers dp_i after the last step, [Pa]."""
        return self._dp_i

    @property
    def shaft_torque(self) -> float:
        """Torque the shaft delivers to the load, after friction, [N*m]."""
        return self._torque

    def case_pressure(self) -> float:
        """
        Compute the case pressure now, eq. (P6).

        Returns
        -------
        float
            Case pressure, absolute, [Pa]

        """
        case = self.params.case
        return case_pressure(self._p_out, self._pt, case.offset, case.outlet_share)

    def _channels(self) -> dict[str, float]:
        """Return what a calibrated coefficient set's effects read (gauge Pa, degC, s, rev)."""
        return {'p_case': channel_gauge(self.case_pressure()),
                'p_in': channel_gauge(self._p_in),
                'p_out': channel_gauge(self._p_out), 'temperature': self._temp,
                'time': self._t, 'revolutions': self._revolutions}

    def measure(self) -> Measurement:
        """
        Read every sensor at the current time.

        Returns
        -------
        Measurement
            The readings, with the sensor and effect errors applied.

        """
        t = self._t
        s_in, s_out, s_case, s_flow, s_speed, s_temp = self._sensors
        flows = self.flows
        return Measurement(
            time=t, inlet_pressure=s_in.read(t, self._p_in),
            outlet_pressure=s_out.read(t, self._p_out),
            case_pressure=s_case.read(t, self.case_pressure()),
            flow=s_flow.read(t, flows.motor + flows.leakage), speed=s_speed.read(t, self._w),
            angle=self._theta, torque=self._torque, temperature=s_temp.read(t, self._temp))

    def check_command(self, flow_command: float) -> str | None:
        """
        Say what is wrong with a flow command, if anything.

        Parameters
        ----------
        flow_command : float
            A candidate command, [m^3/s]

        Returns
        -------
        str or None
            The reason it would be refused, or None when it is acceptable.

        """
        if not isinstance(flow_command, (int, float)) or not math.isfinite(flow_command):
            return f'flow command {flow_command!r} is not a finite number'
        if abs(flow_command) > MAX_FLOW_COMMAND:
            return (f'flow command {flow_command!r} m^3/s is beyond +-{MAX_FLOW_COMMAND} '
                    'm^3/s')
        return None


__all__ = ['MAX_FLOW_COMMAND', 'Measurement', 'Plant', 'PlantError', 'PlantState',
           'StepFlows']
