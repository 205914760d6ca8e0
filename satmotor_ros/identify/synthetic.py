# SPDX-License-Identifier: Apache-2.0
"""
Synthetic bench data from the model, with effects injected and seeded noise.

The truth is always :class:`~satmotor_ros.model.MotorModel` itself: the
flow is its forward map Q(n, dp) (eqs. 34-36, channel drop coupled) with the
injected effect in its coefficient set, evaluated by the effect's own kind
(:mod:`satmotor_ros.model.effects`), and the sensor effects applied to what
the sensors report. An :class:`Injection`'s magnitude is turned into the
effect's coefficient by the kind (:meth:`~satmotor_ros.model.effects.EffectKind.scaled`).
The injected viscosity law is the liquid's standard one pinned at the mean
temperature of the data, while the candidate library pins it at the set's
viscosity, so a test still checks that the fit generalises over the pinning.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
import re

import numpy as np

from satmotor_ros.identify.table import BenchTable
from satmotor_ros.interface import CHANNELS, JOINT_NAME
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import Effect, kind_of, sensor_error, Synthetic, with_effects
from satmotor_ros.model.revolutions import revolutions
from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA, RPM
from satmotor_ros.model.viscosity import standard_law
from scipy.signal import lfilter

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
    over the test [m] for clearance_wear; b [m^3/s] for flow_sensor_offset;
    g [-] for the gains; the peak-to-peak loss change [m^3/s] for
    ``channel:<name>``; the largest extra loss [m^3/s] for ``term:<expr>``.
    """

    effect: str = 'none'  # an id of the DESIGN.md vocabulary
    magnitude: float = 0.0  # see the class docstring
    regressor: str = ''  # p_case|p_out (external_leakage), time|revolutions (wear)
    shape: tuple[tuple[str, float], ...] = ()  # kind-specific numbers (threshold: reference [Pa],
    # exponent [-])

    @classmethod
    def realistic(cls, effect: str, scale: float = 1.0, liquid: str = 'oil') -> Injection:
        """
        Build an injection at `scale` times the realistic magnitude.

        Parameters
        ----------
        effect : str
            A key of :data:`REALISTIC`, [-]
        scale : float
            Factor on the realistic magnitude, [-]
        liquid : str
            ``'oil'`` or ``'water'``, [-]

        Returns
        -------
        Injection
            The injection.

        """
        (oil, water), regressor = REALISTIC[effect]
        return cls(effect, (water if 'water' in liquid else oil) * scale, regressor)


@dataclass(frozen=True)
class Plan:
    """Operating range, duration and sensor noise of a synthetic bench test."""

    liquid: str = 'oil'  # coefficient set
    n_points: int = 100  # operating points
    speed_rpm: tuple[float, float] = (100.0, 1500.0)  # [rpm]
    dp_mpa: tuple[float, float] = (2.0, 25.0)  # port drop [MPa]
    p_out_mpa: tuple[float, float] = (0.3, 3.0)  # [MPa]
    p_case_mpa: tuple[float, float] = (0.05, 0.6)  # [MPa]
    temperature_c: tuple[float, float] = (38.0, 48.0)  # when viscosity is not injected [degC]
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
                 time: FloatArray) -> FloatArray:
    span = [i.magnitude for i in injections if i.effect == 'viscosity_temperature']
    if span:
        mid = 0.5 * sum(plan.temperature_c)
        lo, hi = mid - 0.5 * span[0], mid + 0.5 * span[0]
    else:
        lo, hi = plan.temperature_c
    # warm-up and cool-down cycles, so that temperature is no proxy for time
    phase = rng.uniform(0, 2 * np.pi)
    cycles = 0.5 * (1 + np.sin(2 * np.pi * 2.5 * time / max(time[-1], 1e-9) + phase))
    return lo + (hi - lo) * (0.7 * cycles + 0.3 * rng.uniform(0, 1, time.size))


def _channels(plan: Plan, injections: tuple[Injection, ...], rng: np.random.Generator,
              time: FloatArray, draw: int, index: np.ndarray) -> dict[str, FloatArray]:
    """Draw p_case, p_out and the extra channels `draw` times, spread by `index`."""
    channels = {'time': time, 'temperature': _temperature(plan, injections, rng, time),
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


def _measure(plan: Plan, effects: tuple[Effect, ...], rng: np.random.Generator,
             flow: FloatArray, speed: FloatArray, dp: FloatArray,
             channels: dict[str, FloatArray], noise: float) -> BenchTable:
    n = flow.size
    gain_q, offset_q = sensor_error(effects, 'flow')
    gain_n, offset_n = sensor_error(effects, 'speed')
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


def _motor_flow(plan: Plan, injections: tuple[Injection, ...], speed: FloatArray,
                dp: FloatArray, channels: dict[str, FloatArray]
                ) -> tuple[tuple[Effect, ...], FloatArray]:
    """Return the injected effects and the flow the packaged motor absorbs with them, [m^3/s]."""
    base = MotorModel.from_spec(load_motor(), plan.liquid)
    effects = _effects(base, injections, speed, dp, channels)
    return effects, true_flow(base, effects, speed, dp, channels)


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
    channels = _channels(plan, injections, rng, time, n, np.arange(n))
    channels['revolutions'] = revolutions(speed, np.diff(time, prepend=0.0))
    effects, flow = _motor_flow(plan, injections, speed, dp, channels)
    return _measure(plan, effects, rng, flow, speed, dp, channels, 1.0)


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
    effects, flow = _motor_flow(plan, injections, speed, dp, channels)
    table = _measure(plan, effects, rng, flow, speed, dp, channels, noise)
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
        return np.asarray(x, dtype=float).copy()
    e = np.exp(-dt / tau)
    c = 1.0 - tau / dt * (1.0 - e)
    y, _ = lfilter([c, 1.0 - e - c], [1.0, -e], x, zi=[(1.0 - c) * x[0]])
    return np.asarray(y, dtype=float)


@dataclass(frozen=True)
class Dynamics:
    """The transient terms to inject into a generated recording (eqs. T1-T3 of `.transient`)."""

    line_compliance: float = 0.0  # V/K of the inlet line between flowmeter and motor [m^3/Pa]
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
    first-order lag `tau_s`. The flowmeter sits upstream of the inlet line and reads
    the motor's flow plus (V/K) dp_in/dt (T1); the speed and flow readings lag
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
    effects, flow = _motor_flow(plan, injections, speed, dp, channels)
    flow = flow + dynamics.line_compliance * np.gradient(channels['p_out'] + dp, dt)
    flow = first_order(flow, dt, dynamics.flow_lag)
    read_speed = first_order(speed, dt, dynamics.speed_lag)
    pick = slice(None, None, oversample)
    channels = {name: x[pick] for name, x in channels.items()}
    table = _measure(plan, effects, rng, flow[pick], read_speed[pick], dp[pick], channels,
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
    from satmotor_ros.bags import (encode_many, FLOAT64, FLUID_PRESSURE, JOINT_STATE,
                                   OutTopic, TEMPERATURE, write_bag)
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


def _replaceable(path: Path, columns: dict[str, tuple[str, FloatArray]]) -> bool:
    """Whether `path` is free or a table this command wrote (the same header line)."""
    if not (path.exists() or path.is_symlink()):
        return True
    header = ','.join(f'{name} [{unit}]' for name, (unit, _) in columns.items())
    try:
        with path.open('rb') as file:
            return path.is_file() and file.readline().rstrip(b'\r\n') == header.encode()
    except OSError:
        return False


def main(argv: list[str] | None = None) -> int:
    """
    Write a synthetic bench CSV: ``python -m satmotor_ros.identify.synthetic``.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments, [-]

    Returns
    -------
    int
        0, or 2 with one line on stderr for a bad option, a model that cannot be built or
        an ``--out`` that exists and was not written by this command (``--force`` replaces it).

    """
    import argparse
    from satmotor_ros.identify.table import write_csv
    parser = argparse.ArgumentParser(description='Write a synthetic bench table (CSV) from '
                                                 'the model with effects injected.')
    parser.add_argument('--liquid', default='oil')
    parser.add_argument('--effect', action='append', default=[],
                        help='NAME or NAME*SCALE (NAME one of '
                             f'{", ".join(REALISTIC)}), term:EXPR=LPM or threshold:dp=LPM@MPA; '
                             'repeatable (default: none)')
    parser.add_argument('--outlier', action='append', default=[], metavar='ROW:LPM',
                        help='add LPM l/min to the flow of row ROW (repeatable)')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--points', type=int, default=100)
    parser.add_argument('--series', type=int, default=None, metavar='SAMPLES',
                        help='write a 100 Hz time series of this many samples instead')
    parser.add_argument('--transient', type=float, default=None, metavar='SECONDS',
                        help='write a 100 Hz recording of this length whose set-points change '
                             'every 0.6-1.5 s, with a line volume and sensor lags '
                             '(REALISTIC_DYNAMICS) instead')
    parser.add_argument('--bag', choices=('mcap', 'sqlite3'), default=None,
                        help='write the time series as a rosbag2 bag (directory --out)')
    parser.add_argument('--out', required=True, help='CSV file (or bag directory) to write')
    parser.add_argument('--force', action='store_true',
                        help='replace an existing --out CSV that this command did not write')
    args = parser.parse_args(argv)
    for option, value, least in (('--points', args.points, 2), ('--series', args.series, 2),
                                 ('--transient', args.transient, 0.1)):
        if value is not None and not value >= least:
            parser.error(f'{option} {value!r}: must be at least {least:g}')
    plan = Plan(liquid=args.liquid, n_points=args.points)
    try:
        injections = [parse_injection(e, args.liquid) for e in args.effect] or [Injection()]
        rows, sizes = zip(*((int(r), float(v)) for r, v in
                            (o.split(':') for o in args.outlier))) if args.outlier else ((), ())
    except ValueError as err:
        parser.error(str(err) if str(err).startswith('--') else
                     f'--outlier {args.outlier!r}: use ROW:LPM, e.g. 7:1.5')
    try:
        if args.transient is not None:
            table = generate_transient(plan, injections, REALISTIC_DYNAMICS, args.seed,
                                       duration_s=args.transient)
        elif args.series is not None:
            table = generate_series(plan, injections, args.seed, samples=args.series)
        else:
            table = generate(plan, injections, args.seed)
        if any(not 0 <= row < len(table) for row in rows):
            parser.error(f'--outlier {args.outlier!r}: a row from 0 to {len(table) - 1}')
        if rows:
            table = with_outliers(table, rows, sizes)
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        if args.bag:
            write_bag_of(args.out, table, args.bag)
        else:
            columns = to_columns(table)
            if not (args.force or _replaceable(Path(args.out), columns)):
                parser.error(f'--out {args.out!r} exists and is not a table this command wrote; '
                             'choose a new path or pass --force to replace it')
            write_csv(args.out, columns)
    except (ValueError, OSError) as err:  # a model or bag error, a path that cannot be written
        parser.error(f'{err}' if str(err) else f'--out {args.out!r}: {err!r}')
    described = ', '.join(f'{i.effect} (magnitude {i.magnitude:.4g})' for i in injections)
    print(f'wrote {args.out}: {len(table)} rows, {args.liquid}, {described}'
          + (f', outliers at rows {", ".join(map(str, rows))}' if rows else ''))
    return 0


if __name__ == '__main__':
    import sys
    sys.exit(main())
