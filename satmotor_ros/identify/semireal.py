# SPDX-License-Identifier: Apache-2.0
"""
Semi-real recordings: a real log's trajectory, a flow from a known model, effects and noise.

The time, signed speed and port pressures are a real recording's (read through its column
mapping); the flow is what a known motor (a family at a displacement) absorbs along that
trajectory, plus the effects injected here, plus noise whose size, serial correlation and
spikes are measured on the same log. The effects are written out here, each in its own form,
and deliberately not through the candidate library: a relief valve opens by a smooth law that
is not the ``threshold`` candidate's, a leak and wear are plain laminar terms. A case is
written in the log's own text format (:func:`write_mbari_log`), so it goes through
``satmotor calibrate --columns`` exactly as a user's file would.

The flow of the model is evaluated at the smoothed speed and pressures (the true state); the
file reports the log's own speed and pressure readings, with their quantisation, noise and
spikes, so those sensors are as real as the trajectory.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np
from satmotor_ros.identify.columns import load_mapping, read_log
from satmotor_ros.identify.synthetic import first_order
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.families.defaults import default_motor
from satmotor_ros.model.units import INCH, LPM, MPA, PSI, RPM
from scipy.ndimage import median_filter, uniform_filter1d

F11_5 = 0.30 * INCH ** 3 / (2.0 * np.pi)
"""Displacement of the Parker F11-5 of the MBARI rig, 0.30 in^3/rev, [m^3/rad]."""

MBARI_AREA = 1.375 * INCH ** 2
"""Piston area of the MBARI rig's cylinder, [m^2] (config/mbari_pto.columns.yaml)."""

STEADY_RPM_PER_S = 50.0
"""A stretch is steady (for the noise estimate) while |dn/dt| stays below this, [rpm/s]."""

MOVING_LPM_PER_S = 3.0
"""The flow changes fast enough for its timing to show above this rate, [(l/min)/s]."""

SPIKE_SAMPLES = 3

TRUE_CHANNEL_DROP = 0.3 * MPA
"""The true motor's channel drop (eq. (35)) at :data:`TRUE_CHANNEL_SPEED`'s flow, [Pa].

A velocity-head estimate for the F11-5: at 26 l/min its ports (about 10 mm bore) run oil at
5.5 m/s, a velocity head rho v^2/2 of 13 kPa; some 20 of them over the ports, the distributor
and the bends give 0.3 MPa. The family's drop scaled by similarity from the SM-0,75/25 (9.4
MPa there) is a guess the data of a real rig refute (doc/semireal.md)."""

TRUE_CHANNEL_SPEED = 5300.0 * RPM
"""Speed at whose flow q_t n the true channel drop is :data:`TRUE_CHANNEL_DROP`, [rad/s].

At one speed the passages' velocities scale with the size (similarity), so the factor on the
family's scaled coefficients is one for every displacement."""
"""Samples of the running median that takes the readings' spikes out of the true state."""


@dataclass(frozen=True)
class Trajectory:
    """
    A real recording's time, speed and port pressures, as read (SI, gauge).

    The state (``*_state``) is the readings with isolated spikes removed (a running median of
    :data:`SPIKE_SAMPLES` at the log's own rate): what the motor's flow follows. A wider
    smoothing would bend the fast transients (a 0.2 s window moves q_t n by 0.2 l/min RMS on
    the MBARI logs, more than their noise) and plant an error that no real motor has.
    """

    time: FloatArray  # [s]
    speed: FloatArray  # signed shaft speed reading [rad/s]
    p_a: FloatArray  # port A, the inlet when the flow is positive [Pa]
    p_b: FloatArray  # port B [Pa]
    flow: FloatArray  # the log's own flow reading, for the noise estimate only [m^3/s]
    speed_state: FloatArray  # [rad/s]
    p_a_state: FloatArray  # [Pa]
    p_b_state: FloatArray  # [Pa]
    source: str = '<trajectory>'

    def __len__(self) -> int:
        """Return the number of samples."""
        return int(self.time.size)

    def crop(self, start_s: float, stop_s: float, step: int = 1) -> Trajectory:
        """
        Keep the samples in [start_s, stop_s), every `step`-th one.

        Parameters
        ----------
        start_s, stop_s : float
            Time span, [s]
        step : int
            Keep one sample in `step`, [-]

        Returns
        -------
        Trajectory
            The cropped trajectory.

        """
        keep = np.flatnonzero((self.time >= start_s) & (self.time < stop_s))[::step]
        return replace(self, **{f.name: getattr(self, f.name)[keep] for f in fields(self)
                                if f.name != 'source'})


def load_trajectory(path: str | Path, mapping: str | Path = 'mbari_pto') -> Trajectory:
    """
    Read a real log's trajectory through a column mapping (doc/columns.md).

    Parameters
    ----------
    path : str or pathlib.Path
        The log, [-]
    mapping : str or pathlib.Path
        A mapping file or a packaged mapping's name, [-]

    Returns
    -------
    Trajectory
        Its time, speed, port pressures and flow (rows the reader drops are gaps).

    """
    table = read_log(path, load_mapping(mapping))
    speed, p_a, p_b = (median_filter(x, SPIKE_SAMPLES, mode='nearest')
                       for x in (table.speed, table.p_in, table.p_out))
    return Trajectory(np.asarray(table.channels['time'], dtype=float), table.speed,
                      table.p_in, table.p_out, table.flow, speed, p_a, p_b, str(path))


@dataclass(frozen=True)
class Noise:
    """Noise of a flow reading derived from a piston, as measured on a real log."""

    white_lpm: float  # sample-to-sample noise [l/min]
    colored_lpm: float  # standard deviation of the serially correlated part [l/min]
    correlation_s: float  # its correlation time: the Gaussian kernel's width [s]
    spike_rate: float  # share of samples with an isolated spike [-]
    spike_lpm: float  # typical spike size [l/min]
    step_s: float = 0.02  # sample step of the log it was measured on [s]
    jitter_s: float = 0.0  # spread of the timing between the flow and the speed readings [s]


def _steady_stretches(table: Trajectory, least: int) -> list[np.ndarray]:
    rpm = uniform_filter1d(table.speed / RPM, 25)
    rate = np.gradient(rpm, table.time)
    steady = (np.abs(rate) < STEADY_RPM_PER_S) & (np.abs(rpm) > 4.0 * STEADY_RPM_PER_S)
    edges = np.flatnonzero(np.diff(steady.astype(int))) + 1
    return [s for s in np.split(np.arange(len(table)), edges) if steady[s[0]] and s.size >= least]


def estimate_noise(table: Trajectory, displacement: float = F11_5) -> Noise:
    """
    Measure the noise of Q - q_t n on a real log's steady stretches.

    Within a steady stretch the residual's deviation from its mean is noise (the losses
    hardly move); its spread, its autocorrelation and the isolated spikes of the whole log
    (a sample far from its neighbours' median) give the noise model. The autocorrelation of
    the real logs falls like a Gaussian, exp(-(k dt)^2 / (4 s^2)) (white noise through a
    Gaussian kernel of width s), not like an AR(1): 0.98, 0.86, 0.57, 0.03 at 1, 5, 10, 25
    samples on the 2021 log. s is fitted to the mean autocorrelation of the stretches.

    Parameters
    ----------
    table : Trajectory
        The whole real log, [-]
    displacement : float
        q_t/(2 pi) of its motor, [m^3/rad]

    Returns
    -------
    Noise
        The measured noise.

    """
    residual = (table.flow - displacement * table.speed) / LPM
    stretches = _steady_stretches(table, 100)
    if not stretches:
        msg = f'{table.source}: no steady stretch to measure the noise on'
        raise ValueError(msg)
    deviation = np.concatenate([residual[s] - residual[s].mean() for s in stretches])
    step = np.concatenate([np.diff(table.flow[s] / LPM) for s in stretches])
    white = 1.4826 * float(np.median(np.abs(step))) / np.sqrt(2.0)
    robust = 1.4826 * float(np.median(np.abs(deviation)))
    # a few stretches hold a real transition; winsorised, they still widen the tails
    total = float(np.std(np.clip(deviation, -5.0 * robust, 5.0 * robust)))
    step_s = float(np.median(np.diff(table.time)))
    lags = np.arange(1, 41)
    acf = np.array([np.mean([np.corrcoef(residual[s][:-k], residual[s][k:])[0, 1]
                             for s in stretches]) for k in lags])
    widths = np.linspace(0.5, 40.0, 400) * step_s
    misfit = [np.sum((acf - np.exp(-(lags * step_s) ** 2 / (4 * w ** 2))) ** 2) for w in widths]
    jump = residual - median_filter(residual, 5, mode='nearest')
    spikes = np.abs(jump) > 4.0 * total
    size = float(np.median(np.abs(jump[spikes]))) if spikes.any() else 4.0 * total
    return Noise(float(white), float(np.sqrt(max(total ** 2 - white ** 2, 0.0))),
                 float(widths[int(np.argmin(misfit))]), float(spikes.mean()), size, step_s,
                 _jitter(table, residual, displacement, step_s))


def _jitter(table: Trajectory, residual: FloatArray, displacement: float,
            step_s: float) -> float:
    """
    Return the spread of the flow reading's timing against the speed's, [s].

    While the flow changes, the residual's spread grows in proportion to the rate of change
    (on the MBARI logs 0.03 l/min at rest, ~2 l/min at 10-30 (l/min)/s, 5-8 at 30-100): the
    readings are off in time by a varying amount. That amount is the residual's deviation from
    its 2 s running median over the rate, robustly, where the flow changes by more than
    :data:`MOVING_LPM_PER_S`.
    """
    flow = uniform_filter1d(displacement * table.speed / LPM, 9)
    rate = np.abs(np.gradient(flow, table.time))
    window = 2 * int(1.0 / step_s) + 1
    deviation = residual - median_filter(residual, window, mode='nearest')
    moving = rate > MOVING_LPM_PER_S
    if not moving.any():
        return 0.0
    return 1.4826 * float(np.median(np.abs(deviation[moving]) / rate[moving]))


@dataclass(frozen=True)
class ReliefValve:
    r"""
    A relief or bypass valve across the ports that opens in one direction only.

    Its poppet lifts smoothly from the crack pressure (a softplus knee of width `width`) and
    passes orifice flow, from the high to the low port:

    .. math:: Q_v = Q_{full}\,\frac{w\,\ln(1 + e^{(s\,\Delta p - p_c)/w})}{p_f - p_c}
        \sqrt{\frac{\max(s\,\Delta p, 0)}{p_f}}, \quad s = \pm 1

    which is not the ``threshold`` candidate's :math:`k \max(0, |\Delta p| - x_c)^e`.
    """

    crack: float  # crack pressure p_c [Pa]
    direction: int  # +1: opens while p_a > p_b; -1: while p_b > p_a
    full_flow: float  # flow at the full drop p_f [m^3/s]
    full_drop: float  # p_f [Pa]
    width: float = 0.3 * MPA  # knee width w [Pa]

    kind = 'threshold:dp'

    def flow(self, dp: FloatArray, speed: FloatArray, t: FloatArray) -> FloatArray:
        """Return the valve's flow into port A, [m^3/s]."""
        x = self.direction * dp
        lift = self.width * np.logaddexp(0.0, (x - self.crack) / self.width)
        orifice = np.sqrt(np.maximum(x, 0.0) / self.full_drop)
        return self.direction * self.full_flow * lift / (self.full_drop - self.crack) * orifice


@dataclass(frozen=True)
class DemandRelief:
    """
    A relief valve whose flow the demand sets: it clamps the drop near its crack, one way only.

    Past the crack the drop hardly rises: the valve opens fully within `width` (a steep,
    saturating characteristic), and what it passes is what the motor does not take, which
    changes from one opening to the next: each opening (a run of samples past the crack)
    passes `full_flow` times its own factor, drawn in [1 - spread, 1 + spread]. The flow at
    one drop thus scatters by the demand, as on the MBARI rig, and no law of the drop alone
    (the ``threshold`` candidate's) gives it.
    """

    crack: float  # crack pressure p_c [Pa]
    direction: int  # +1: opens while p_a > p_b; -1: while p_b > p_a
    full_flow: float  # mean flow of a fully open valve [m^3/s]
    width: float = 0.15 * MPA  # drop over the crack at which it is fully open [Pa]
    spread: float = 0.5  # relative spread of the openings' flows [-]
    seed: int = 0  # of the openings' factors [-]

    kind = 'threshold:dp'

    def flow(self, dp: FloatArray, speed: FloatArray, t: FloatArray) -> FloatArray:
        """Return the valve's flow into port A, [m^3/s]."""
        x = self.direction * dp
        lift = np.clip((x - self.crack) / self.width, 0.0, 1.0)
        opening = np.cumsum(np.diff(np.concatenate(([0], (lift > 0.0).astype(int)))) > 0)
        factors = np.random.default_rng(self.seed).uniform(
            1.0 - self.spread, 1.0 + self.spread, int(opening[-1]) + 1 if opening.size else 1)
        return self.direction * self.full_flow * factors[opening] * lift


def demand_relief(trajectory: Trajectory, scale: float = 1.0, *, direction: int = -1,
                  crack_fraction: float = 0.97, seed: int = 0) -> DemandRelief:
    """
    Build a demand-set relief valve passing 5 l/min on average, `scale` times that.

    Parameters
    ----------
    trajectory : Trajectory
        The (cropped) trajectory the valve will act on, [-]
    scale : float
        Factor on the flow, [-]
    direction : {-1, 1}
        Sign of p_a - p_b where it opens, [-]
    crack_fraction : float
        The crack pressure over the 99th percentile of the drop in its direction (the
        largest drop is a spike of the readings), [-]
    seed : int
        Seed of the openings' flows, [-]

    Returns
    -------
    DemandRelief
        The valve.

    """
    top = float(np.percentile(direction * (trajectory.p_a - trajectory.p_b), 99.0))
    return DemandRelief(crack_fraction * top, direction, 5.0 * LPM * scale, seed=seed)


@dataclass(frozen=True)
class ExternalLeak:
    """
    A leak to the drain from one port: k times that port's gauge pressure (eq. 24's form).

    Like every loss it runs from the high-pressure side: a motor takes in that much more, a
    pump (the flow against the drop) delivers that much less, so the flow into port A moves by
    sign(p_a - p_b) k p.
    """

    coefficient: float  # k [m^3/(s*Pa)]
    port: str = 'outflow'  # 'outflow': the port the flow leaves by; 'inflow': the other
    kind = 'external_leakage'

    def flow(self, dp: FloatArray, speed: FloatArray, t: FloatArray, p_a: FloatArray,
             p_b: FloatArray) -> FloatArray:
        """Return the extra flow into port A, [m^3/s]."""
        forward = speed >= 0.0
        outflow = np.where(forward, p_b, p_a)
        pressure = outflow if self.port == 'outflow' else np.where(forward, p_a, p_b)
        return np.sign(dp) * self.coefficient * np.maximum(pressure, 0.0)


@dataclass(frozen=True)
class Wear:
    """A laminar leakage from the high to the low port that grows linearly with time."""

    end_flow: float  # extra leakage at `reference_drop` at the end of the case [m^3/s]
    reference_drop: float = 10.0 * MPA  # [Pa]
    kind = 'clearance_wear'

    def flow(self, dp: FloatArray, speed: FloatArray, t: FloatArray) -> FloatArray:
        """Return the extra flow into port A, [m^3/s]."""
        grown = (t - t[0]) / max(float(t[-1] - t[0]), 1e-9)
        flow: FloatArray = self.end_flow * grown * dp / self.reference_drop  # Any to numpy
        return flow


@dataclass(frozen=True)
class FlowGain:
    """The flow reading is (1 + g) Q."""

    gain: float
    kind = 'flow_sensor_gain'


@dataclass(frozen=True)
class SpeedGain:
    """The speed reading is (1 + g) n."""

    gain: float
    kind = 'speed_sensor_gain'


@dataclass(frozen=True)
class FlowLag:
    """The flow reading follows the flow through a first-order lag."""

    tau: float  # [s]
    kind = 'flow_lag'


Injected = ReliefValve | DemandRelief | ExternalLeak | Wear | FlowGain | SpeedGain | FlowLag
"""The effects a semi-real case can carry."""

KINDS = ('relief', 'external_leakage', 'clearance_wear', 'flow_sensor_gain',
         'speed_sensor_gain', 'flow_lag')
"""The kinds :func:`realistic` builds."""


def realistic(kind: str, trajectory: Trajectory, scale: float = 1.0, *, direction: int = -1,
              crack_fraction: float = 0.75) -> Injected:
    """
    Build an effect of `kind` at `scale` times a realistic size for this trajectory.

    Realistic sizes: a relief valve passing 4 l/min at the largest drop of its direction
    (the MBARI rig's own passes 4-5 l/min), cracking at `crack_fraction` of that drop; a leak
    of 0.5 l/min at the largest outflow-port pressure; wear adding 0.5 l/min of leakage at
    10 MPa by the end; 2 % sensor gains; a 0.1 s flow-reading lag.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`, [-]
    trajectory : Trajectory
        The (cropped) trajectory the effect will act on, [-]
    scale : float
        Factor on the realistic size, [-]
    direction : {-1, 1}
        The valve's direction (sign of p_a - p_b where it opens), [-]
    crack_fraction : float
        The valve's crack pressure over the largest drop of its direction, [-]

    Returns
    -------
    Injected
        The effect.

    """
    if kind == 'relief':
        top = float(np.max(direction * (trajectory.p_a - trajectory.p_b)))
        return ReliefValve(crack_fraction * top, direction, 4.0 * LPM * scale, top)
    if kind == 'external_leakage':
        outflow = np.where(trajectory.speed >= 0.0, trajectory.p_b, trajectory.p_a)
        return ExternalLeak(0.5 * LPM * scale / float(np.percentile(outflow, 99)))
    if kind == 'clearance_wear':
        return Wear(0.5 * LPM * scale)
    if kind == 'flow_sensor_gain':
        return FlowGain(0.02 * scale)
    if kind == 'speed_sensor_gain':
        return SpeedGain(0.02 * scale)
    if kind == 'flow_lag':
        return FlowLag(0.1 * scale)
    msg = f'kind {kind!r}: use one of {", ".join(KINDS)}'
    raise ValueError(msg)


@dataclass(frozen=True)
class Case:
    """A semi-real recording: readings to write, and the truth behind them."""

    time: FloatArray  # [s]
    speed: FloatArray  # speed reading [rad/s]
    flow: FloatArray  # flow reading [m^3/s]
    p_a: FloatArray  # [Pa]
    p_b: FloatArray  # [Pa]
    true_flow: FloatArray  # the model's flow with the motor effects, no sensor error [m^3/s]
    base_flow: FloatArray  # the model's flow without any effect [m^3/s]
    noiseless: FloatArray  # the flow reading before noise and bad rows [m^3/s]
    effects: tuple[Injected, ...] = ()
    family: str = 'paszota'
    displacement: float = F11_5  # [m^3/rad]
    bad_rows: tuple[int, ...] = ()  # rows given a gross flow error
    notes: tuple[str, ...] = field(default=())

    def as_table(self) -> BenchTable:
        """Return the readings as the bench table the mapping would read, [-]."""
        return BenchTable(self.speed, self.flow, self.p_a, self.p_b, {'time': self.time},
                          {'time': 's'}, '<semireal>', time_series=True)


def true_motor(family: str = 'paszota', displacement: float = F11_5) -> MotorModel:
    """
    Return the motor whose flow a case is: a family's defaults with a plausible channel drop.

    The defaults are scaled by similarity from the SM-0,75/25, and so is their channel drop
    of eq. (35): half the hydraulic power of a 4.9 cm^3/rev motor at full flow, above the
    port drop at which a real rig's motor runs (the base caps such a guess at the port drop of
    each direction's motor-mode rows, :mod:`.base`). The true motor's drop is
    :data:`TRUE_CHANNEL_DROP` at :data:`TRUE_CHANNEL_SPEED`; every other coefficient is the
    family's default.

    Parameters
    ----------
    family : str
        The motor's model family, [-]
    displacement : float
        q_t/(2 pi), [m^3/rad]

    Returns
    -------
    MotorModel
        The true motor (oil).

    """
    spec = default_motor(family, displacement)
    model = MotorModel.from_spec(spec, 'oil')
    factor = TRUE_CHANNEL_DROP / float(model.equations.channel_drop(
        displacement * TRUE_CHANNEL_SPEED))
    chosen = spec.sets['oil']
    coef = replace(chosen.coefficients, **{n: getattr(chosen.coefficients, n) * factor
                                           for n in model.family.channel})
    return MotorModel.from_spec(replace(spec, sets={**spec.sets, 'oil': replace(
        chosen, coefficients=coef)}), 'oil')


def _correlated(width: float, n: int, rng: np.random.Generator) -> FloatArray:
    """Return unit-variance white noise through a Gaussian kernel `width` samples wide."""
    reach = int(np.ceil(4.0 * width))
    kernel = np.exp(-0.5 * (np.arange(-reach, reach + 1) / max(width, 1e-3)) ** 2)
    shocks = rng.normal(0.0, 1.0, n + 2 * reach)
    return np.convolve(shocks, kernel / np.sqrt(np.sum(kernel ** 2)), mode='valid')


def _noise(noise: Noise, step_s: float, n: int,
           rng: np.random.Generator) -> tuple[FloatArray, list[int]]:
    """Return white + correlated + spiked noise at samples `step_s` apart, [l/min], and spikes."""
    colored = noise.colored_lpm * _correlated(noise.correlation_s / step_s, n, rng)
    out = colored + rng.normal(0.0, noise.white_lpm, n)
    rows = sorted(set(rng.choice(n, size=rng.poisson(noise.spike_rate * n), replace=False)))
    out[rows] += rng.choice([-1.0, 1.0], len(rows)) * noise.spike_lpm * rng.uniform(
        1.0, 2.0, len(rows))
    return out, [int(r) for r in rows]


def build_case(trajectory: Trajectory, effects: Sequence[Injected] = (), *,
               noise: Noise | None, family: str = 'paszota', displacement: float = F11_5,
               seed: int = 0, bad_rows: int = 0, bad_lpm: float = 2.0) -> Case:
    """
    Compute a semi-real case along a real trajectory.

    Parameters
    ----------
    trajectory : Trajectory
        The real time, speed and pressures (cropped as wanted), [-]
    effects : sequence of Injected
        The effects to inject (at most one of each class), [-]
    noise : Noise or None
        The flow reading's noise (:func:`estimate_noise` of the whole log); None for none, [-]
    family : str
        The motor's model family, with its defaults at `displacement` and a plausible
        channel drop (:func:`true_motor`), [-]
    displacement : float
        q_t/(2 pi), [m^3/rad]
    seed : int
        Seed of the noise and of the bad rows, [-]
    bad_rows : int
        Rows given a gross flow error of +-`bad_lpm` (isolated bad readings), [-]
    bad_lpm : float
        Size of that error, [l/min]

    Returns
    -------
    Case
        The readings and the truth.

    """
    rng = np.random.default_rng(seed)
    t = trajectory.time
    speed, p_a, p_b = trajectory.speed_state, trajectory.p_a_state, trajectory.p_b_state
    dp = p_a - p_b
    model = true_motor(family, displacement)
    base = model.absorbency(speed, dp=dp, errors='mask').flow
    if not np.isfinite(base).all():
        msg = f'{trajectory.source}: the {family} model has no flow at some samples'
        raise ValueError(msg)
    true = base.copy()
    for effect in effects:
        if isinstance(effect, ExternalLeak):
            true += effect.flow(dp, speed, t, p_a, p_b)
        elif isinstance(effect, (ReliefValve, DemandRelief, Wear)):
            true += effect.flow(dp, speed, t)
    reading = true
    step_s = float(np.median(np.diff(t)))
    for effect in effects:
        if isinstance(effect, FlowLag):
            reading = first_order(reading, step_s, effect.tau)
    gain_q = 1.0 + sum(e.gain for e in effects if isinstance(e, FlowGain))
    gain_n = 1.0 + sum(e.gain for e in effects if isinstance(e, SpeedGain))
    reading = gain_q * reading
    noiseless = reading
    notes = []
    if noise is not None:
        extra, spiked = _noise(noise, step_s, len(t), rng)
        late = noise.jitter_s * _correlated(noise.correlation_s / step_s, len(t), rng)
        reading = reading + extra * LPM - late * np.gradient(reading, t)
        notes.append(f'noise {noise}; spikes at rows {spiked}')
    bad = tuple(int(r) for r in np.sort(rng.choice(len(t), size=bad_rows, replace=False)))
    reading = reading.copy()
    reading[list(bad)] += rng.choice([-1.0, 1.0], len(bad)) * bad_lpm * LPM
    return Case(t, gain_n * trajectory.speed, reading, trajectory.p_a, trajectory.p_b, true,
                base, noiseless, tuple(effects), family, displacement, bad, tuple(notes))


MBARI_HEADER = '#time(s),Spd(in/s),RPM,LowerHydPress(psig),UpperHydPress(psig)'
"""The columns of an MBARI log that ``--columns mbari_pto`` reads (the optional ones left out)."""


def write_mbari_log(path: str | Path, case: Case) -> Path:
    """
    Write a case as an MBARI test-machine log (read it with ``--columns mbari_pto``).

    The cells have the real logs' resolution: 0.01 s, 0.001 in/s, 0.001 rpm, 0.001 psi.

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write, [-]
    case : Case
        The case, [-]

    Returns
    -------
    pathlib.Path
        The file.

    """
    spd = -case.flow / MBARI_AREA / INCH  # Q = -Spd * area (the mapping's sign)
    rows = np.column_stack([case.time, spd, case.speed / RPM, case.p_b / PSI, case.p_a / PSI])
    path = Path(path)
    np.savetxt(path, rows, fmt=['%.2f', '%.3f', '%.3f', '%.3f', '%.3f'], header=MBARI_HEADER[1:],
               comments='#')
    return path


__all__ = ['build_case', 'Case', 'demand_relief', 'DemandRelief', 'estimate_noise',
           'ExternalLeak', 'F11_5', 'FlowGain',
           'FlowLag', 'Injected', 'KINDS', 'load_trajectory', 'MBARI_AREA', 'Noise', 'realistic',
           'ReliefValve', 'SpeedGain', 'Trajectory', 'true_motor', 'TRUE_CHANNEL_DROP',
           'TRUE_CHANNEL_SPEED', 'Wear', 'write_mbari_log']
