# SPDX-License-Identifier: Apache-2.0
"""
Synthetic bench data from the model, with effects injected and seeded noise.

The truth is always :class:`~satmotor_ros.model.MotorModel` itself: the
flow is its forward map Q(n, dp) (eqs. 34-36, channel drop coupled) with the
injected effect in its coefficient set, evaluated by the effect's own kind
(:mod:`satmotor_ros.model.effects`), and the sensor effects applied to what
the sensors report. An :class:`Injection`'s magnitude is turned into the
effect's coefficient by the kind (:meth:`~satmotor_ros.model.effects.EffectKind.scaled`).
The injected viscosity law is the liquid's standard one, in a bench table pinned at the
mean temperature of the data, while the candidate library pins it at the set's
viscosity, so a test still checks that the fit generalises over the pinning. A
recording's oil is the model's liquid: its law gives the model's viscosity where the
standard law does, and without the injection it is held there.

A recording can age (:func:`aging`): a wear that grows with the hours of the recording,
the family's own (:func:`wear_kind`), and a step fault: any injection with an `onset`
is absent before that time and present after it (a wear then starts growing there).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
import math
from pathlib import Path
import re

import numpy as np

from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import first_order as lagged
from satmotor_ros.interface import (CHANNELS, FLOAT64, FLUID_PRESSURE, JOINT_NAME, JOINT_STATE,
                                    TEMPERATURE)
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import Effect, kind_of, ranked, sensor_error, Synthetic
from satmotor_ros.model.effects._wear import Wear
from satmotor_ros.model.motor import with_effects
from satmotor_ros.model.revolutions import revolutions
from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA, RPM
from satmotor_ros.model.viscosity import standard_law
from satmotor_ros.options import MotorOptions

EFFECTS = ('none', 'external_leakage', 'viscosity_temperature', 'clearance_wear',
           'flow_sensor_offset', 'flow_sensor_gain', 'speed_sensor_gain', 'channel:aux',
           'term:dp^2*n')
"""The effects :func:`generate` can inject (any ``channel:<name>`` or ``term:<expr>`` too)."""

REALISTIC = {
    'none': ((0.0, 0.0), ''),
    'external_leakage': ((0.4 * LPM / MPA, 0.4 * LPM / MPA), 'p_case'),  # k_ex [m^3/(s*Pa)]
    'viscosity_temperature': ((30.0, 30.0), 'temperature'),  # temperature span [K]
    # clearance growth over the test [m]: about doubles the oil's small leakage by the end
    'clearance_wear': ((1.5e-6, 0.8e-6), 'time'),
    'flow_sensor_offset': ((0.25 * LPM, 0.25 * LPM), '1'),  # b [m^3/s], 0.4 % of 60 l/min
    'flow_sensor_gain': ((0.01, 0.01), 'flow'),  # g [-]
    'speed_sensor_gain': ((0.01, 0.01), 'speed'),  # g [-]
    'channel:aux': ((0.2 * LPM, 0.2 * LPM), 'aux'),  # peak-to-peak loss change [m^3/s]
    'term:dp^2*n': ((0.5 * LPM, 0.5 * LPM), 'dp^2*n'),  # largest extra loss [m^3/s]
}
"""
Realistic magnitudes (oil, water) and the regressor per effect, in the units of :class:`Injection`.

About 5-20 times the noise of Q_vl that the default :class:`Plan` gives
(0.027 l/min); the sweep also runs half of them, near the detection limit.
"""


@dataclass(frozen=True)
class Injection:
    """
    One effect to inject.

    `magnitude` means: k_ex [m^3/(s*Pa)] for external_leakage; the
    temperature span [K] for viscosity_temperature; the clearance growth
    over the test [m] for clearance_wear; the relative growth of the leakage
    over the test [-] for leakage_wear; b [m^3/s] for flow_sensor_offset;
    g [-] for the gains; the peak-to-peak loss change [m^3/s] for
    ``channel:<name>``; the largest extra loss [m^3/s] for ``term:<expr>``,
    each over the samples from `onset` on (a wear grows from there to the end).
    """

    effect: str = 'none'  # an id of the DESIGN.md vocabulary
    magnitude: float = 0.0  # see the class docstring
    regressor: str = ''  # p_case|p_out (external_leakage), time|revolutions (wear)
    shape: tuple[tuple[str, float], ...] = ()  # kind-specific numbers (threshold: reference [Pa],
    # exponent [-])
    onset: float = -math.inf  # time of the data it steps in at (a step fault) [s]

    @classmethod
    def realistic(cls, effect: str, scale: float = 1.0, liquid: str = 'oil') -> Injection:
        """
        Build an injection at `scale` times the realistic magnitude.

        Parameters
        ----------
        effect : str
            A key of :data:`REALISTIC` or :data:`FAMILY_REALISTIC`, [-]
        scale : float
            Factor on the realistic magnitude, [-]
        liquid : str
            ``'oil'`` or ``'water'``, [-]

        Returns
        -------
        Injection
            The injection.

        """
        (oil, water), regressor = {**REALISTIC, **FAMILY_REALISTIC}[effect]
        return cls(effect, (water if 'water' in liquid else oil) * scale, regressor)


@dataclass(frozen=True)
class Plan:
    """Operating range, duration and sensor noise of a synthetic bench test."""

    liquid: str = 'oil'  # coefficient set
    family: str = ''  # model family of the motor; '': the packaged SM-0,75/25's own
    displacement: float = 0.0  # of a family's default motor; 0: the SM-0,75/25's [m^3/rad]
    n_points: int = 100  # operating points
    speed_rpm: tuple[float, float] = (100.0, 1500.0)  # [rpm]
    dp_mpa: tuple[float, float] = (2.0, 25.0)  # port drop [MPa]
    p_out_mpa: tuple[float, float] = (0.3, 3.0)  # [MPa]
    p_case_mpa: tuple[float, float] = (0.05, 0.6)  # [MPa]
    temperature_c: tuple[float, float] = (38.0, 48.0)  # when viscosity is not injected: the
    # steady points' range, a recording's oil held at its middle [degC]
    temperature_jitter: float = 0.3  # share of the span drawn anew per set-point; 0: only the
    # slow warm-up and cool-down cycles, as a tank of oil [-]
    duration_s: float = 3600.0  # test duration [s]
    noise_flow_lpm: float = 0.02  # flowmeter noise, absolute [l/min]
    noise_flow_rel: float = 0.0005  # flowmeter noise, share of reading [-]
    noise_speed_rpm: float = 0.3  # [rpm]
    noise_pressure_mpa: float = 0.01  # [MPa]
    noise_temperature_c: float = 0.1  # [degC]
    extra_channels: tuple[str, ...] = ('aux',)  # channels with no effect unless injected
    reverse_share: float = 0.0  # share of the points turned backwards (n < 0) [-]
    pump_share: float = 0.0  # share driven as a pump: dp against the flow [-]

    def noise_lpm(self, flow: FloatArray, model: MotorModel) -> FloatArray:
        """
        Compute the standard deviation of the measured Q_vl that the sensor noise causes.

        Parameters
        ----------
        flow : ndarray
            Flow, [m^3/s]
        model : MotorModel
            The model (for q_t), [-]

        Returns
        -------
        ndarray
            Noise of Q - q_t n, [l/min]

        """
        q = np.hypot(self.noise_flow_lpm, self.noise_flow_rel * flow / LPM)
        n = model.geometry.displacement * self.noise_speed_rpm * RPM / LPM
        return np.hypot(q, n)


FAMILY_REALISTIC = {
    'leakage_wear': ((0.5, 0.5), 'time'),  # relative growth of the leakage over the test [-]
}
"""Realistic magnitudes of effects only other families than the packaged motor's have."""


def injected_effect(base: MotorModel, injection: Injection, speed: FloatArray,
                    dp: FloatArray, channels: dict[str, FloatArray]) -> Effect | None:
    """
    Turn an injection into the registry's effect at the data's operating points.

    Parameters
    ----------
    base : MotorModel
        The packaged model, [-]
    injection : Injection
        The effect and its magnitude, [-]
    speed : ndarray
        True speed, [rad/s]
    dp : ndarray
        True port drop, [Pa]
    channels : dict of str to ndarray
        Channels (time [s], revolutions [rev], temperature [degC], p_case, p_out [Pa],
        extra), [-]

    Returns
    -------
    Effect or None
        The effect; None for ``'none'``.

    """
    if injection.effect == 'none':
        return None
    kind = kind_of(Effect(injection.effect, 0.0))
    dp_i = base.absorbency(speed, dp=dp, errors='mask').dp_i
    data = Synthetic(np.abs(speed), np.abs(dp_i), channels,
                     standard_law(base.liquid, base.coefficient_set.name), injection.shape,
                     np.sign(speed), np.abs(dp))
    return kind.scaled(injection.effect, injection.magnitude, injection.regressor, data)


def true_flow(base: MotorModel, effects: tuple[Effect, ...], speed: FloatArray, dp: FloatArray,
              channels: dict[str, FloatArray]) -> FloatArray:
    """
    Compute the flow the motor really absorbs, with the physical effects injected.

    Parameters
    ----------
    base : MotorModel
        The packaged model, [-]
    effects : tuple of Effect
        The injected effects (a sensor effect leaves the flow alone), [-]
    speed : ndarray
        True speed, [rad/s]
    dp : ndarray
        True port drop, [Pa]
    channels : dict of str to ndarray
        The channels the effect reads, [-]

    Returns
    -------
    ndarray
        Flow, [m^3/s]

    """
    motor = tuple(e for e in effects if not kind_of(e).sensor)
    if not motor:
        return base.absorbency(speed, dp=dp).flow
    model = with_effects(base, motor)
    needed = {name: channels[name] for name in model.channels}
    return model.absorbency(speed, dp=dp, channels=needed).flow


def _operating_points(plan: Plan, rng: np.random.Generator,
                      n: int) -> tuple[FloatArray, FloatArray]:
    speed = rng.uniform(*plan.speed_rpm, n) * RPM
    dp = rng.uniform(*plan.dp_mpa, n) * MPA
    if plan.reverse_share or plan.pump_share:  # four quadrants (doc/quadrants.md)
        backwards = np.where(rng.uniform(0.0, 1.0, n) < plan.reverse_share, -1.0, 1.0)
        against = np.where(rng.uniform(0.0, 1.0, n) < plan.pump_share, -1.0, 1.0)
        speed, dp = backwards * speed, backwards * against * dp
    return speed, dp


def _temperature(plan: Plan, injections: tuple[Injection, ...], rng: np.random.Generator,
                 time: FloatArray, recording: bool) -> FloatArray:
    """
    Draw the oil's temperature, [degC].

    With ``viscosity_temperature`` injected it spans the injection's magnitude and the
    losses follow it. Without, a bench table's points are set at temperatures drawn over the
    plan's range that the losses ignore (a channel that does not matter, which calibration
    must not take for an effect); a recording's oil is held where the liquid's standard law
    gives the model's viscosity (the losses at it, which do not move): a temperature that moved
    while the losses did not would be a motor no oil makes, and a monitor that reads the
    temperature, as it must, would alarm on it.
    """
    span = [i.magnitude for i in injections if i.effect == 'viscosity_temperature']
    if span:
        mid = 0.5 * sum(plan.temperature_c)
        lo, hi = mid - 0.5 * span[0], mid + 0.5 * span[0]
    else:
        lo, hi = plan.temperature_c
    # warm-up and cool-down cycles, so that temperature is no proxy for time
    phase = rng.uniform(0, 2 * np.pi)
    cycles = 0.5 * (1 + np.sin(2 * np.pi * 2.5 * time / max(time[-1], 1e-9) + phase))
    jitter = plan.temperature_jitter
    temperature: FloatArray = lo + (hi - lo) * ((1.0 - jitter) * cycles
                                                + jitter * rng.uniform(0, 1, time.size))
    if recording and not span:  # drawn all the same: the other channels' draws do not move
        base = base_model(plan)
        held = standard_law(base.liquid, base.coefficient_set.name).reference_temperature
        return np.full_like(temperature, held)
    return temperature


def _channels(plan: Plan, injections: tuple[Injection, ...], rng: np.random.Generator,
              time: FloatArray, draw: int, index: np.ndarray,
              recording: bool = True) -> dict[str, FloatArray]:
    """Draw p_case, p_out and the extra channels `draw` times, spread by `index`."""
    channels = {'time': time,
                'temperature': _temperature(plan, injections, rng, time, recording),
                'p_case': rng.uniform(*plan.p_case_mpa, draw)[index] * MPA,
                'p_out': rng.uniform(*plan.p_out_mpa, draw)[index] * MPA}
    names = list(plan.extra_channels)
    for injection in injections:
        match = re.fullmatch(r'channel:(\w+)', injection.effect)
        if match and match.group(1) not in names:
            names.append(match.group(1))
    for name in names:
        channels[name] = rng.uniform(0.0, 1.0, draw)[index]
    return channels


def _errors(spans: Spans, channel: str) -> tuple[FloatArray, FloatArray]:
    """Return the gain and offset of an instrument at each row, as its spans' effects make."""
    errors = np.array([sensor_error(effects, channel) for effects in spans.effects])
    return errors[spans.which, 0], errors[spans.which, 1]


def _measure(plan: Plan, spans: Spans, rng: np.random.Generator,
             flow: FloatArray, speed: FloatArray, dp: FloatArray,
             channels: dict[str, FloatArray], noise: float) -> BenchTable:
    n = flow.size
    gain_q, offset_q = _errors(spans, 'flow')
    gain_n, offset_n = _errors(spans, 'speed')
    sd_q = np.hypot(plan.noise_flow_lpm * LPM, plan.noise_flow_rel * flow) * noise
    flow_m = gain_q * flow + offset_q + rng.normal(0.0, 1.0, n) * sd_q
    speed_m = (gain_n * speed + offset_n
               + rng.normal(0.0, plan.noise_speed_rpm * RPM * noise, n))
    sd_p = plan.noise_pressure_mpa * MPA * noise
    low = channels.pop('p_out') + rng.normal(0.0, sd_p, n)  # the low port: B unless dp < 0
    p_in = low + np.maximum(dp, 0.0) + rng.normal(0.0, sd_p, n)
    p_out = low + np.maximum(-dp, 0.0)
    channels['temperature'] = channels['temperature'] + rng.normal(
        0.0, plan.noise_temperature_c * noise, n)
    channels['p_case'] = channels['p_case'] + rng.normal(0.0, sd_p, n)
    units = {'speed': 'rad/s', 'flow': 'm^3/s', 'p_in': 'Pa', 'p_out': 'Pa', 'time': 's',
             'revolutions': 'rev', 'temperature': 'degC', 'p_case': 'Pa'}
    return BenchTable(speed_m, flow_m, p_in, p_out, channels, units, '<synthetic>')


def _effects(base: MotorModel, injections: tuple[Injection, ...], speed: FloatArray,
             dp: FloatArray, channels: dict[str, FloatArray]) -> tuple[Effect, ...]:
    effects = (injected_effect(base, i, speed, dp, channels) for i in injections)
    return tuple(e for e in effects if e is not None)


@dataclass(frozen=True)
class Spans:
    """Stretches of a recording between onsets: the effects of each and the span of each row."""

    effects: tuple[tuple[Effect, ...], ...]  # what is injected in each span
    which: np.ndarray  # span of each row [-]

    def __getitem__(self, rows: slice) -> Spans:
        """Return the spans of some rows."""
        return Spans(self.effects, self.which[rows])


def base_model(plan: Plan) -> MotorModel:
    """
    Build the motor a plan's data come from: the packaged SM-0,75/25, or a family's.

    Parameters
    ----------
    plan : Plan
        Liquid, family and displacement, [-]

    Returns
    -------
    MotorModel
        The model (without effects).

    """
    if not plan.family and not plan.displacement:
        return MotorModel.from_spec(load_motor(), plan.liquid)
    return MotorOptions(liquid=plan.liquid, family=plan.family,
                        displacement=plan.displacement).build_model()


def _motor_flow(plan: Plan, injections: tuple[Injection, ...], speed: FloatArray,
                dp: FloatArray, channels: dict[str, FloatArray],
                recording: bool = True) -> tuple[Spans, FloatArray]:
    """
    Return the injected effects per span and the flow the motor absorbs with them, [m^3/s].

    In a recording the viscosity law is pinned where the liquid's standard law gives the
    model's viscosity (:func:`_temperature`), not at the data's mean temperature.
    """
    base = base_model(plan)
    law = standard_law(base.liquid, base.coefficient_set.name)
    time = channels['time']
    steps = sorted({i.onset for i in injections if i.onset > time[0]})
    effect_of = {}
    for i, injection in enumerate(injections):  # each scaled on the rows it acts on
        rows = time >= injection.onset
        if rows.any():
            effect = injected_effect(base, injection, speed[rows], dp[rows],
                                     {k: v[rows] for k, v in channels.items()})
            if recording and effect is not None and effect.name == 'viscosity_temperature':
                effect = replace(effect, reference_temperature=law.reference_temperature)
            effect_of[i] = effect
    which = np.searchsorted(np.asarray(steps), time, side='right')
    flow = np.empty_like(speed)
    spans = []
    for span, start in enumerate([-math.inf, *steps]):
        effects = tuple(e for i, e in effect_of.items()
                        if e is not None and injections[i].onset <= max(start, time[0]))
        spans.append(effects)
        rows = which == span
        if rows.any():
            flow[rows] = true_flow(base, effects, speed[rows], dp[rows],
                                   {k: v[rows] for k, v in channels.items()})
    return Spans(tuple(spans), which), flow


def wear_kind(family: str) -> str:
    """
    Name the wear a motor of `family` has: the Wear kind of the registry made for it.

    Parameters
    ----------
    family : str
        Model family; '' the default's, [-]

    Returns
    -------
    str
        ``clearance_wear`` (sliwinski2017) or ``leakage_wear`` (balawender, paszota).

    """
    family = family or 'sliwinski2017'
    return next(k.name for k in ranked() if isinstance(k, Wear)
                and (k.families is None or family in k.families))


def aging(family: str = '', wear: float = 1.0, fault: Injection | None = None,
          liquid: str = 'oil', temperature_span: float = 0.0) -> tuple[Injection, ...]:
    """
    Build the injections of an ageing motor: its family's wear over the data, and a fault.

    Parameters
    ----------
    family : str
        Model family; '' the default's, [-]
    wear : float
        Factor on the wear's realistic growth over the recording (:data:`REALISTIC`:
        clearances 1.5 um in oil; :data:`FAMILY_REALISTIC`: the leakage +50 %); 0: no
        wear, [-]
    fault : Injection, optional
        A step fault (an injection with its `onset`), [-]
    liquid : str
        ``'oil'`` or ``'water'``, [-]
    temperature_span : float
        The losses follow the temperature over this span, by the liquid's own viscosity
        law (``viscosity_temperature``), as a real motor's do; 0: the oil is held at the
        middle of the plan's temperatures (the recording's temperature does not move), [K]

    Returns
    -------
    tuple of Injection
        For :func:`generate_series` (at a slow rate for hours; ``Plan.temperature_jitter``
        0 for a temperature that moves as a tank's) and the others.

    """
    worn = (Injection.realistic(wear_kind(family), wear, liquid),) if wear else ()
    warm = ((Injection('viscosity_temperature', temperature_span, 'temperature'),)
            if temperature_span else ())
    return worn + warm + ((fault,) if fault is not None else ())


def _injections(injection: Injection | Sequence[Injection]) -> tuple[Injection, ...]:
    return (injection,) if isinstance(injection, Injection) else tuple(injection)


def generate(plan: Plan, injection: Injection | Sequence[Injection],
             seed: int = 0) -> BenchTable:
    """
    Generate a bench table of steady operating points.

    Parameters
    ----------
    plan : Plan
        Range, duration and noise, [-]
    injection : Injection or sequence of Injection
        The effect(s) to inject, [-]
    seed : int
        Seed of the operating points and the noise, [-]

    Returns
    -------
    BenchTable
        Measured points (SI) with time, revolutions, temperature, p_case and
        the plan's extra channels.

    """
    rng = np.random.default_rng(seed)
    n = plan.n_points
    speed, dp = _operating_points(plan, rng, n)
    time = np.sort(rng.uniform(0.0, plan.duration_s, n))
    injections = _injections(injection)
    channels = _channels(plan, injections, rng, time, n, np.arange(n), recording=False)
    channels['revolutions'] = revolutions(speed, np.diff(time, prepend=0.0))
    spans, flow = _motor_flow(plan, injections, speed, dp, channels, recording=False)
    return _measure(plan, spans, rng, flow, speed, dp, channels, 1.0)


def with_outliers(table: BenchTable, rows: Sequence[int], size_lpm: Sequence[float]) -> BenchTable:
    """
    Return a table with gross errors added to the flow of some rows (a bad reading).

    Parameters
    ----------
    table : BenchTable
        A generated table, [-]
    rows : sequence of int
        Rows to spoil, [-]
    size_lpm : sequence of float
        Error added at each, [l/min]

    Returns
    -------
    BenchTable
        The table, the flow of those rows off by the errors.

    """
    flow = table.flow.copy()
    flow[list(rows)] += np.asarray(size_lpm, dtype=float) * LPM
    return replace(table, flow=flow)


def generate_series(plan: Plan, injection: Injection | Sequence[Injection], seed: int = 0,
                    samples: int = 20000,
                    rate: float = 100.0, hold_s: float = 8.0, tau_s: float = 0.3,
                    noise: float = 3.0) -> BenchTable:
    """
    Generate a time series of set-point steps with first-order transients.

    Parameters
    ----------
    plan : Plan
        Range and noise (multiplied by `noise` per sample), [-]
    injection : Injection or sequence of Injection
        The effect(s) to inject, [-]
    seed : int
        Seed, [-]
    samples : int
        Number of samples, [-]
    rate : float
        Sample rate, [Hz]
    hold_s : float
        Time each set-point is held, [s]
    tau_s : float
        Time constant of speed and pressure between set-points, [s]
    noise : float
        Factor on the plan's noise for raw samples, [-]

    Returns
    -------
    BenchTable
        Raw samples, ``time_series`` True.

    """
    rng = np.random.default_rng(seed)
    time = np.arange(samples) / rate
    steps = int(np.ceil(time[-1] / hold_s)) + 1
    sp_speed, sp_dp = _operating_points(plan, rng, steps)
    k = np.minimum((time / hold_s).astype(int), steps - 1)
    alpha = 1.0 - np.exp(-1.0 / (rate * tau_s))
    speed, dp = np.empty(samples), np.empty(samples)
    s, d = sp_speed[0], sp_dp[0]
    target_s, target_d = sp_speed[k], sp_dp[k]
    for i in range(samples):  # first-order lag (a loop; 1e5 samples take ~0.1 s)
        s += alpha * (target_s[i] - s)
        d += alpha * (target_d[i] - d)
        speed[i], dp[i] = s, d
    injections = _injections(injection)
    channels = _channels(plan, injections, rng, time, steps, k)
    channels['revolutions'] = revolutions(speed, 1.0 / rate)
    spans, flow = _motor_flow(plan, injections, speed, dp, channels)
    table = _measure(plan, spans, rng, flow, speed, dp, channels, noise)
    return replace(table, time_series=True)


def first_order(x: FloatArray, dt: float, tau: float) -> FloatArray:
    r"""
    Follow a sampled input with a first-order lag, starting at rest on its first value.

    Exact for an input linear between the samples (first-order hold):

    .. math:: y_i = E y_{i-1} + (1 - E - c)\,x_{i-1} + c\,x_i, \quad E = e^{-dt/\tau},
        \quad c = 1 - \frac{\tau}{dt}(1 - E)

    Parameters
    ----------
    x : ndarray
        Input samples, [any]
    dt : float
        Sample step, [s]
    tau : float
        Time constant; 0 returns `x`, [s]

    Returns
    -------
    ndarray
        The lagged samples, [unit of x]

    """
    if tau <= 0.0:
        return np.array(x, dtype=np.float64)
    return lagged(np.asarray(x, dtype=float), np.array([0, len(x)]), dt, tau)


@dataclass(frozen=True)
class Dynamics:
    """The transient terms to inject into a generated recording (eqs. T1-T3 of `.transient`)."""

    line_compliance: float = 0.0  # V_a/K of port A's line, flowmeter upstream [m^3/Pa]
    line_compliance_b: float = 0.0  # V_b/K of port B's line, flowmeter downstream [m^3/Pa]
    speed_lag: float = 0.0  # first-order time constant of the speed reading [s]
    flow_lag: float = 0.0  # first-order time constant of the flow reading [s]


REALISTIC_DYNAMICS = Dynamics(line_compliance=5.0e-13, speed_lag=0.02, flow_lag=0.05)
"""About 0.5 l of oil in hoses (effective bulk modulus 1 GPa), a 20 ms speed, a 50 ms flow lag."""


def generate_transient(plan: Plan, injection: Injection | Sequence[Injection],
                       dynamics: Dynamics = Dynamics(), seed: int = 0, duration_s: float = 90.0,
                       rate: float = 100.0, hold_s: tuple[float, float] = (0.6, 1.5),
                       tau_s: float = 0.15, noise: float = 3.0,
                       oversample: int = 5) -> BenchTable:
    """
    Generate a recording whose set-points change every `hold_s` seconds, with its dynamics.

    Speed, pressure drop and outlet pressure follow random set-points through a
    first-order lag `tau_s`. The flowmeter reads the motor's flow plus
    (V_a/K) dp_a/dt - (V_b/K) dp_b/dt (T1); the speed and flow readings lag
    through first-order filters (T2, T3). Simulated at `oversample` times the rate.

    Parameters
    ----------
    plan : Plan
        Range and noise (multiplied by `noise` per sample), [-]
    injection : Injection or sequence of Injection
        The effect(s) to inject, [-]
    dynamics : Dynamics
        Line compliance and sensor lags, [-]
    seed : int
        Seed, [-]
    duration_s : float
        Length of the recording, [s]
    rate : float
        Sample rate, [Hz]
    hold_s : (float, float)
        Shortest and longest time a set-point holds, [s]
    tau_s : float
        Time constant of speed and pressures between set-points, [s]
    noise : float
        Factor on the plan's noise for raw samples, [-]
    oversample : int
        Simulation steps per sample, [-]

    Returns
    -------
    BenchTable
        Raw samples, ``time_series`` True.

    """
    rng = np.random.default_rng(seed)
    dt = 1.0 / (rate * oversample)
    time = np.arange(int(round(duration_s / dt)), dtype=float) * dt
    changes = np.cumsum(rng.uniform(*hold_s, int(duration_s / hold_s[0]) + 2))
    k = np.searchsorted(changes, time, side='right')
    steps = int(k[-1]) + 1
    sp_speed, sp_dp = _operating_points(plan, rng, steps)
    speed, dp = (first_order(x[k], dt, tau_s) for x in (sp_speed, sp_dp))
    injections = _injections(injection)
    channels = _channels(plan, injections, rng, time, steps, k)
    channels['p_out'] = first_order(channels['p_out'], dt, tau_s)
    channels['revolutions'] = revolutions(speed, dt)
    spans, flow = _motor_flow(plan, injections, speed, dp, channels)
    flow = (flow + dynamics.line_compliance * np.gradient(channels['p_out'] + dp, dt)
            - dynamics.line_compliance_b * np.gradient(channels['p_out'], dt))
    flow = first_order(flow, dt, dynamics.flow_lag)
    read_speed = first_order(speed, dt, dynamics.speed_lag)
    pick = slice(None, None, oversample)
    channels = {name: x[pick] for name, x in channels.items()}
    table = _measure(plan, spans[pick], rng, flow[pick], read_speed[pick], dp[pick], channels,
                     noise)
    return replace(table, time_series=True)


def write_bag_of(path: str | Path, table: BenchTable, storage: str = 'mcap',
                 flow_topic: str = 'flow_measured',
                 custom_data: dict[str, str] | None = None) -> None:
    """
    Record a generated time series as a rosbag2 bag of the DESIGN.md topics.

    Parameters
    ----------
    path : str or pathlib.Path
        Bag directory to create, [-]
    table : BenchTable
        A generated time series (with time, temperature, p_case), [-]
    storage : {'mcap', 'sqlite3'}
        Storage plugin, [-]
    flow_topic : str
        Topic of the flow: ``flow_measured`` or ``flow_command``, [-]
    custom_data : dict, optional
        What the bag records of itself (:mod:`satmotor_ros.bags.custom`), [-]

    """
    from satmotor_ros.bags import encode_many, OutTopic, write_bag
    t_ns = 1_700_000_000_000_000_000 + np.round(table.channels['time'] * 1e9).astype(np.int64)

    def pressure(name: str, p: FloatArray) -> OutTopic:  # FluidPressure is absolute
        return OutTopic(f'/{CHANNELS[name].topic}', FLUID_PRESSURE, t_ns + 1000,
                        encode_many(FLUID_PRESSURE, {'fluid_pressure': p + ATMOSPHERE}, t_ns))

    topics = [OutTopic(f'/{flow_topic}', FLOAT64, t_ns + 2000,
                       encode_many(FLOAT64, {'data': table.flow})),
              pressure('p_in', table.p_in), pressure('p_out', table.p_out),
              pressure('p_case', table.channels['p_case']),
              OutTopic(f'/{CHANNELS["temperature"].topic}', TEMPERATURE, t_ns + 3000,
                       encode_many(TEMPERATURE, {'temperature': table.channels['temperature']},
                                   t_ns)),
              OutTopic(f'/{CHANNELS["measured_speed"].topic}', JOINT_STATE, t_ns, encode_many(
                  JOINT_STATE, {'position': np.cumsum(table.speed) * 0.01,
                                'velocity': table.speed}, t_ns, joint=JOINT_NAME))]
    for name, values in table.channels.items():
        if name not in ('time', 'revolutions', 'temperature', 'p_case'):
            topics.append(OutTopic(f'/{name}', FLOAT64, t_ns + 4000,
                                   encode_many(FLOAT64, {'data': values})))
    write_bag(path, topics, storage, custom_data=custom_data)


def to_columns(table: BenchTable) -> dict[str, tuple[str, FloatArray]]:
    """
    Express a generated table in hydraulic units for a bench CSV.

    Parameters
    ----------
    table : BenchTable
        A generated table, [-]

    Returns
    -------
    dict of str to (str, ndarray)
        Column name -> (unit, values in that unit).

    """
    columns = {'time': ('s', table.channels['time']), 'speed': ('rpm', table.speed / RPM),
               'flow': ('l/min', table.flow / LPM), 'p_in': ('MPa', table.p_in / MPA),
               'p_out': ('MPa', table.p_out / MPA),
               'temperature': ('degC', table.channels['temperature']),
               'p_case': ('MPa', table.channels['p_case'] / MPA)}
    for name, values in table.channels.items():
        if name not in columns and name != 'revolutions':
            columns[name] = ('-', values)
    return columns


def parse_injection(text: str, liquid: str) -> Injection:
    """
    Read one ``--effect`` of the command line.

    ``NAME`` or ``NAME*SCALE`` is a :data:`REALISTIC` effect at SCALE times its
    realistic magnitude; ``term:EXPR=LPM`` a power term (e.g. ``term:dp^0.76=0.8``)
    whose largest extra loss is LPM l/min; ``threshold:dp=LPM@MPA`` a valve that
    cracks open at MPA MPa and adds LPM l/min at the top of the range.

    Parameters
    ----------
    text : str
        As typed, [-]
    liquid : str
        ``'oil'`` or ``'water'``, [-]

    Returns
    -------
    Injection
        The injection.

    Raises
    ------
    ValueError
        Naming the text and what is expected.

    """
    name, _, size = text.partition('=')
    try:
        if name.startswith('term:') and size:
            return Injection(name, float(size) * LPM)
        if name == 'threshold:dp' and '@' in size:
            loss, _, crack = size.partition('@')
            if float(crack) >= 0.0:  # a valve cracks at a drop; below zero it is never shut
                return Injection(name, float(loss) * LPM,
                                 shape=(('reference', float(crack) * MPA),))
        effect, _, scale = text.partition('*')
        if effect in REALISTIC and not size:
            return Injection.realistic(effect, float(scale or 1.0), liquid)
    except ValueError:
        pass
    msg = (f'--effect {text!r}: use NAME or NAME*SCALE (NAME one of {", ".join(REALISTIC)}), '
           'term:EXPR=LPM (e.g. term:dp^0.76=0.8) or threshold:dp=LPM@MPA')
    raise ValueError(msg)
