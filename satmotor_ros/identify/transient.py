# SPDX-License-Identifier: Apache-2.0
r"""
Every sample of a time series as data: the steady model plus the terms of a transient.

While the operating point moves, what the sensors read differs from the steady map
(eqs. 34-36) by the dynamics of the lines and of the sensors. Each difference here is linear
in one parameter, so it enters every fit as a nuisance regressor (``LossParts.nuisance``: a
free coefficient, no prior):

- (T1) line compliance: the flowmeter sits upstream of port A's line volume :math:`V_a`,
  so it also reads the flow that compresses the liquid in it, and downstream of port B's
  :math:`V_b`, so it misses what that line's liquid gives up as it expands,
  :math:`Q_{meas} = Q + (V_a/K)\,\dot p_a - (V_b/K)\,\dot p_b`. A rig metered on one
  line has one volume near 0; a displacement meter (a cylinder's piston) has both. With a
  volume for each port the fit does not depend on which port is called A: a log and its
  mirror (ports swapped, speed and flow turned) give the same fit, the two volumes swapped;
- (T2) speed lag: the speed reading lags the shaft by :math:`\tau_n`, so the model's flow at
  the true speed is :math:`Q(n_{true}) = Q(n) + \tau_n\,(\partial Q/\partial n)\,\dot n`
  (:math:`n_{true} = n + \tau_n \dot n` is exact for a first-order lag; :math:`\partial
  Q/\partial n` is :math:`q_t` plus the speed-dependent losses' share);
- (T3) flow lag: the flowmeter lags the flow by :math:`\tau_Q`,
  :math:`Q_{meas} = Q - \tau_Q \dot Q_{meas}` (exact for a first-order lag).

No derivative is estimated. The model is evaluated at every sample, and the whole equation
is averaged over short bins of consecutive samples (trapezoid rule, :data:`BIN_SECONDS`):
the mean of a derivative over a bin is exactly the change across the bin over its length,
so the derivative terms and the averaged model are filtered alike, and the average of the
model's components is exact however nonlinear the steady map. Bins never span a gap or a
sample the model cannot use; neighbouring bins share one end sample. A bin's change carries
the noise of its two end values (errors in variables, which shrink a lag's estimate by the
noise's share of the change's variance): the end values are taken from a local quadratic fit
over :data:`END_SAMPLES` samples, which leaves a third of that noise.

(T2) and (T3) differ only by the change of the loss (:math:`\dot Q = q_t \dot n +
\dot Q_{vl}`): where that is small, the data determine :math:`\tau_n - \tau_Q` well and each
lag poorly; the report says so. Neighbouring residuals are correlated: the selection's F-test
and the intervals use the variance inflation of :func:`variance_inflation`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np
from satmotor_ros.identify.errors import DataError, IdentificationError
from satmotor_ros.identify.fit import FitReport, written
from satmotor_ros.identify.noise import MAD, RATE_TERMS
from satmotor_ros.identify.parts import loss_parts, LossParts, NO_EFFECT
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.revolutions import sampled_revolutions
from scipy import ndimage, signal, special

BIN_SECONDS = 0.2
"""
Shortest bin [s]: long against the sample step (each row averages the sensors' white noise
down), short against a hydraulic transient (0.05-0.5 s), so the rows still resolve it.
"""

MAX_ROWS = 20_000
"""Most rows a fit takes: longer series get longer bins."""

MAX_CORRELATION = 0.9999
"""A dynamic term this correlated with the others (r of its fit on them) is left out."""

MIN_LAGS = 10
"""The variance inflation looks at lags up to N / MIN_LAGS, and at series of 2 MIN_LAGS or more."""

QUIET_LAGS = 5
"""Autocorrelations in a row within chance that end the residuals' memory (Politis: >= 5)."""

END_SAMPLES = 7
"""Samples of the local fit that gives a bin's end values (a third of their noise variance)."""

LAG_CORRELATION = 0.95
"""Above this |r| between the two lags' regressors the report says they barely separate."""


@dataclass(frozen=True)
class DynamicTerm:
    """One term of a transient that the steady map lacks (eqs. T1-T3)."""

    name: str  # id in calibration.json
    symbol: str  # the coefficient's symbol
    regressor: str  # what the coefficient multiplies
    unit: str  # the coefficient's unit
    equation: str  # tag in this module's docstring
    meaning: str  # one line for the report


DYNAMIC_TERMS = (
    DynamicTerm('line_compliance', 'V_a/K', 'dp_a/dt', 'm^3/Pa', 'T1',
                "flow into port A's line volume V_a at bulk modulus K (flowmeter upstream)"),
    DynamicTerm('line_compliance_b', 'V_b/K', '-dp_b/dt', 'm^3/Pa', 'T1',
                "flow out of port B's line volume V_b (flowmeter downstream)"),
    DynamicTerm('speed_lag', 'tau_n', 'dQ/dn*dn/dt', 's', 'T2',
                'the speed reading lags the shaft (first-order time constant)'),
    DynamicTerm('flow_lag', 'tau_Q', '-dQ/dt', 's', 'T3',
                'the flow reading lags the flow (first-order time constant)'),
)
"""The transient's terms, in the order they enter the fit."""


@dataclass(frozen=True)
class TransientOptions:
    """How a time series becomes rows for the fit."""

    bin_seconds: float = BIN_SECONDS  # shortest bin [s]
    gap: float = 3.0  # a time step over gap x the median step cuts the series [-]
    min_steady: int = 20  # 'auto' takes steady windows only when they give this many points [-]
    max_rows: int = MAX_ROWS  # rows a fit takes at most [-]
    screen_volumes: bool = True  # leave out a line volume the loss does not show (validate
    # applies a calibration's volumes to data that may not show them, so it keeps both) [-]

    def __post_init__(self) -> None:
        """Reject a bin <= 0, a gap <= 1 and counts < 1."""
        if not (self.bin_seconds > 0.0 and self.gap > 1.0 and self.min_steady >= 1
                and self.max_rows >= 1):
            msg = ('TransientOptions: need bin_seconds > 0, gap > 1, min_steady >= 1 and '
                   'max_rows >= 1')
            raise DataError(msg)


@dataclass(frozen=True)
class Samples:
    """The samples of a time series as rows for the fit, with the transient's regressors."""

    table: BenchTable  # one row per bin (trapezoid means), in time order
    parts: LossParts  # the model's components averaged alike, the dynamic terms as nuisance
    n_samples: int  # samples in the bins [-]
    bin_size: int  # sample steps a bin spans (at least; a run's last bin up to twice) [-]
    step: float  # median sample step [s]
    segments: int  # stretches without a gap [-]
    left_out: tuple[tuple[str, str], ...]  # dynamic terms not fitted: (name, why)
    correlation: float  # of the speed_lag and flow_lag regressors (NaN if one is out) [-]
    samples: BenchTable  # the raw samples in time order (with revolutions)
    usable: np.ndarray  # which of them the model can use [-]
    bounds: tuple[np.ndarray, np.ndarray]  # first and last sample of each row [-]
    in_bins: np.ndarray  # which of the raw samples a row holds [-]
    spikes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))  # samples
    # with an isolated spike of a reading (:func:`reading_spikes`: a flow's left out, a
    # speed's or pressure's mended), one per spiked reading [-]
    spike_size: np.ndarray = field(default_factory=lambda: np.zeros(0))  # their departure
    # from the neighbours' local fit [SI unit of the reading]
    spike_scale: np.ndarray = field(default_factory=lambda: np.zeros(0))  # the robust
    # scale of that reading's departures [SI unit of the reading]
    spike_channel: tuple[str, ...] = ()  # the reading of each: 'flow', 'speed', 'p_in', 'p_out'
    first: np.ndarray | None = None  # the first raw sample of each stretch without a gap [-]

    guard = 1
    """Rows a test fold keeps out of training on each side: neighbours share a sample."""

    @property
    def stretch_starts(self) -> np.ndarray:
        """Return True at the first raw sample of each stretch (one stretch if not known), [-]."""
        if self.first is not None:
            return self.first
        return np.asarray(np.eye(1, len(self.samples), dtype=bool)[0])


def dynamic_regressors(dp_a_dt: FloatArray, dp_b_dt: FloatArray, dn_dt: FloatArray,
                       dq_dt: FloatArray, dq_dn: FloatArray) -> dict[str, FloatArray]:
    r"""
    Compute the flow per unit coefficient of each transient term, eqs. (T1)-(T3).

    .. math:: Q_{meas} = Q(n, \Delta p_i) + \frac{V_a}{K}\,\dot p_a - \frac{V_b}{K}\,\dot p_b
        + \tau_n\,\frac{\partial Q}{\partial n}\,\dot n - \tau_Q\,\dot Q_{meas}

    Parameters
    ----------
    dp_a_dt, dp_b_dt : ndarray
        Rates of change of the pressures at ports A and B, [Pa/s]
    dn_dt : ndarray
        Rate of change of the speed reading, [rad/s^2]
    dq_dt : ndarray
        Rate of change of the flow reading, [m^3/s^2]
    dq_dn : ndarray
        The steady model's flow per unit speed (:func:`flow_per_speed`), [m^3/rad]

    Returns
    -------
    dict of str to ndarray
        Term name -> regressor: dp_a/dt [Pa/s] for V_a/K, -dp_b/dt for V_b/K,
        dQ/dn dn/dt [m^3/s^2] for tau_n, -dQ/dt [m^3/s^2] for tau_Q.

    """
    return {'line_compliance': dp_a_dt, 'line_compliance_b': -dp_b_dt,
            'speed_lag': dq_dn * dn_dt, 'flow_lag': -dq_dt}


def flow_per_speed(parts: LossParts, qt: float) -> FloatArray:
    r"""
    Differentiate the steady model's flow by speed at the packaged coefficients.

    .. math:: \frac{\partial Q}{\partial n} = q_t + \frac{\sum_j e_j Q_j}{n}

    from eq. (36): each component Q_j grows as n^e_j at a fixed chamber drop
    (for eqs. 31-33: the pressure-speed losses of eqs. 11-13 with n, the inertia
    loss of eq. 14 with n^0.5, the leakage of eqs. 1, 5 not at all).

    In a row's frame (:class:`~satmotor_ros.identify.parts.LossParts`: flow and speed
    times the sign of dp) the components grow with |n|, so the same ratio holds for a
    shaft that turns against the flow.

    Parameters
    ----------
    parts : LossParts
        Components at the rows, [-]
    qt : float
        Theoretical displacement q_t, [m^3/rad]

    Returns
    -------
    ndarray
        dQ/dn in each row's frame; q_t where the speed is 0, [m^3/rad]

    """
    speed_part = sum((c.speed_power * c.flow(NO_EFFECT) for c in parts.components),
                     np.zeros_like(parts.displacement))
    n = parts.displacement / qt if qt > 0.0 else np.zeros_like(parts.displacement)
    moving = np.abs(n) > 0.0
    return qt + np.where(moving, speed_part / np.where(moving, n, 1.0), 0.0)


def first_order(x: FloatArray, starts: np.ndarray, step: float, tau: float) -> FloatArray:
    r"""
    Return `x` through a first-order lag of `tau`, per stretch, from rest on its first value.

    Exact for an input linear between the samples (the rows' own trapezoid reading):
    :math:`y_i = E y_{i-1} + (1 - E - c) x_{i-1} + c x_i`, :math:`E = e^{-h/\tau}`,
    :math:`c = 1 - \tau (1 - E)/h`. (A zero-order hold, :math:`(1 - E) x_i`, would read the
    lag half a step early: a delay of its own the profile would then ask for.)

    Parameters
    ----------
    x : ndarray
        A quantity at every sample, finite, [any]
    starts : ndarray of int
        The first sample of each stretch, then the number of samples, [-]
    step : float
        The median sample step h, [s]
    tau : float
        The time constant, > 0, [s]

    Returns
    -------
    ndarray
        The lagged quantity, [unit of x]

    """
    keep = float(np.exp(-step / tau))
    now = 1.0 - tau / step * (1.0 - keep)
    out = np.empty_like(x)
    for lo, hi in zip(starts[:-1], starts[1:]):
        out[lo:hi], _ = signal.lfilter([now, 1.0 - keep - now], [1.0, -keep], x[lo:hi],
                                       zi=[(1.0 - now) * x[lo]])
    return out


def first_order_at(at: np.ndarray, values: FloatArray, first: np.ndarray, step: float,
                   tau: float) -> tuple[np.ndarray, FloatArray]:
    """
    Return a quantity 0 but at a few samples through :func:`first_order`, where it is not 0.

    Parameters
    ----------
    at : ndarray of int
        The samples where the quantity may differ from 0, increasing, [-]
    values : ndarray
        Its values there, [any]
    first : ndarray of bool
        True at the first sample of each stretch, at every sample, [-]
    step : float
        The median sample step, [s]
    tau : float
        The time constant, > 0, [s]

    Returns
    -------
    ndarray of int
        The samples the lag carries `at`'s values to, until they fall below 1e-12 of them, [-]
    ndarray
        The lagged quantity there (as :func:`first_order` of the whole series gives it), [any]

    """
    reach = int(np.ceil(np.log(1e-12) * tau / -step)) + 1
    marks = np.zeros(first.size + 1, dtype=int)
    np.add.at(marks, at, 1)
    np.add.at(marks, np.minimum(at + reach, first.size), -1)
    support = np.flatnonzero(np.cumsum(marks)[:-1] > 0)
    x = np.zeros(support.size + 1)  # a sample at rest before: the state between runs is ~0
    x[1 + np.searchsorted(support, at)] = values
    starts = np.unique(np.concatenate(([0], 1 + np.flatnonzero(first[support]), [x.size])))
    return support, first_order(x, starts, step, tau)[1:]


def segments(time: FloatArray, gap: float) -> tuple[np.ndarray, float]:
    """
    Find where a time series is cut by a step over `gap` times the median step.

    Parameters
    ----------
    time : ndarray
        Sample times, increasing, [s]
    gap : float
        Factor on the median step, [-]

    Returns
    -------
    ndarray of bool
        True at the first sample of each stretch without a gap.
    float
        The median step, [s]

    """
    dt = np.diff(time)
    positive = dt[dt > 0.0]
    step = float(np.median(positive)) if positive.size else 0.0
    first = np.ones(time.size, dtype=bool)
    first[1:] = (dt > gap * step) | (dt <= 0.0)
    return first, step


def bins(usable: np.ndarray, first: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """
    Cut the runs of usable samples into bins of `size` sample steps.

    Parameters
    ----------
    usable : ndarray of bool
        Samples the model can use, [-]
    first : ndarray of bool
        First sample of each stretch without a gap (:func:`segments`), [-]
    size : int
        Sample steps per bin (>= 1); a run's remainder joins its last bin, [-]

    Returns
    -------
    ndarray of int
        First sample of each bin.
    ndarray of int
        Last sample of each bin (the next bin's first when they touch).

    """
    start = usable & (first | ~np.concatenate(([False], usable[:-1])))
    stop = usable & np.concatenate((first[1:] | ~usable[1:], [True]))  # a run's last sample
    lo, hi = np.flatnonzero(start), np.flatnonzero(stop)
    count = (hi - lo) // size  # bins per run (runs of one sample give none)
    keep = count > 0
    lo, hi, count = lo[keep], hi[keep], count[keep]
    run = np.repeat(np.arange(lo.size), count)
    k = np.arange(run.size) - np.repeat(np.cumsum(count) - count, count)
    a = lo[run] + k * size
    b = np.where(k == count[run] - 1, hi[run], a + size)
    return a, b


def bin_means(time: FloatArray, x: FloatArray, a: np.ndarray, b: np.ndarray) -> FloatArray:
    r"""
    Average a sampled signal over each bin by the trapezoid rule.

    .. math:: \bar x = \frac{1}{t_b - t_a} \int_{t_a}^{t_b} x\,dt

    of the piecewise-linear signal through the samples; the mean of its derivative
    over the same bin is :math:`(x_b - x_a) / (t_b - t_a)`.

    Parameters
    ----------
    time : ndarray
        Sample times, [s]
    x : ndarray
        Samples (NaN makes the bins that hold it NaN), [any]
    a, b : ndarray of int
        First and last sample of each bin (:func:`bins`), [-]

    Returns
    -------
    ndarray
        Mean of each bin, [unit of x]

    """
    piece = 0.5 * (x[1:] + x[:-1]) * np.diff(time)
    bad = ~np.isfinite(piece)
    area = np.concatenate(([0.0], np.cumsum(np.where(bad, 0.0, piece))))
    holes = np.concatenate(([0], np.cumsum(bad)))
    return np.where(holes[b] > holes[a], np.nan, (area[b] - area[a]) / (time[b] - time[a]))


def sparse_bin_means(time: FloatArray, unknown: np.ndarray, a: np.ndarray,
                     b: np.ndarray) -> Callable[[np.ndarray, FloatArray], FloatArray]:
    """
    Return :func:`bin_means` for signals that are 0 at every sample but a few, and NaN alike.

    The pieces between two zero samples add exactly 0 to the running area, so summing only
    the pieces that touch the nonzero samples gives the same means, bit for bit, at a cost
    that grows with those samples rather than with the recording: a valve's flow, 0 below
    its crack, fitted again and again.

    Parameters
    ----------
    time : ndarray
        Sample times, [s]
    unknown : ndarray of bool
        Where the signals are NaN (the same samples for all), [-]
    a, b : ndarray of int
        First and last sample of each bin (:func:`bins`), [-]

    Returns
    -------
    callable
        (the samples `at` where a signal may differ from 0, each once and none of them
        unknown; its values there) -> its mean over each bin (NaN where a bin holds an unknown
        sample), [unit of the signal]

    """
    bad = unknown[1:] | unknown[:-1]  # the pieces a NaN makes NaN
    holes = np.concatenate(([0], np.cumsum(bad)))
    lost = holes[b] > holes[a]
    span = time[b] - time[a]
    ends, where = np.unique(np.concatenate((a, b)), return_inverse=True)
    at_a, at_b = where[:a.size], where[a.size:]

    def means(at: np.ndarray, values: FloatArray) -> FloatArray:
        x = np.zeros(time.size)
        x[at] = values
        touched = np.zeros(time.size, dtype=bool)
        touched[at] = True
        j = np.flatnonzero((touched[1:] | touched[:-1]) & ~bad)  # the pieces [t_j, t_j+1]
        # that touch `at` and hold no NaN
        area = np.concatenate(([0.0], np.cumsum(0.5 * (x[j + 1] + x[j])
                                                * (time[j + 1] - time[j]))))
        # the pieces before each end: a piece counts for every end after it
        before = np.cumsum(np.bincount(np.searchsorted(ends, j, side='right'),
                                       minlength=ends.size + 1))
        return np.where(lost, np.nan, (area[before[at_b]] - area[before[at_a]]) / span)
    return means


def smooth(x: FloatArray, first: np.ndarray, window: int) -> FloatArray:
    r"""
    Smooth samples by a local quadratic fit over `window` samples (Savitzky-Golay), per stretch.

    .. math:: \hat x_i = \sum_{k=-m}^{m} \frac{3(3m^2 + 3m - 1) - 15k^2}
        {(2m - 1)(2m + 1)(2m + 3)}\,x_{i+k}

    exact for a quadratic, with 3(3m^2 + 3m - 1) / ((2m - 1)(2m + 1)(2m + 3)) of the
    white noise's variance left (1/3 for 7 samples); the m samples at each end of a
    stretch, and stretches shorter than the window, stay as measured.

    Parameters
    ----------
    x : ndarray
        Samples, [any]
    first : ndarray of bool
        First sample of each stretch without a gap, [-]
    window : int
        Odd number of samples 2m + 1 >= 5, [-]

    Returns
    -------
    ndarray
        The smoothed samples, [unit of x]

    """
    m = window // 2
    k = np.arange(-m, m + 1, dtype=float)
    weight = ((3.0 * (3 * m * m + 3 * m - 1) - 15.0 * k * k)
              / ((2 * m - 1) * (2 * m + 1) * (2 * m + 3)))
    out = x.astype(float, copy=True)
    starts = np.flatnonzero(first)
    for lo, hi in zip(starts, np.append(starts[1:], x.size)):
        if hi - lo >= window:
            out[lo + m:hi - m] = np.convolve(x[lo:hi], weight, 'valid')
    return out


def _channel_means(time: FloatArray, x: FloatArray, a: np.ndarray,
                   b: np.ndarray) -> FloatArray:
    """Trapezoid means of a channel; a bin with a NaN sample takes its finite samples' mean."""
    out = bin_means(time, x, a, b)
    finite = np.isfinite(x)
    if finite.all():
        return out
    total = np.concatenate(([0.0], np.cumsum(np.where(finite, x, 0.0))))
    count = np.concatenate(([0], np.cumsum(finite)))
    with np.errstate(invalid='ignore', divide='ignore'):
        plain = (total[b + 1] - total[a]) / (count[b + 1] - count[a])
    return np.where(np.isfinite(out), out, plain)


def _base(parts: LossParts) -> FloatArray:
    return np.column_stack([*(c.flow(NO_EFFECT) for c in parts.components),
                            parts.displacement])


def _screen(regressors: dict[str, FloatArray],
            parts: LossParts) -> tuple[dict[str, FloatArray], list[tuple[str, str]]]:
    """Leave out the dynamic terms the data cannot determine, saying why."""
    kept: dict[str, FloatArray] = {}
    left_out = []
    base = _base(parts)
    for term in DYNAMIC_TERMS:
        x = regressors[term.name]
        if not np.all(np.isfinite(x)) or not np.any(x):
            left_out.append((term.name, f'{term.regressor} is zero throughout'))
            continue
        others = np.column_stack([base, *kept.values()])
        coef, *_ = np.linalg.lstsq(others, x, rcond=None)
        r2 = 1.0 - float(np.sum((x - others @ coef) ** 2) / np.sum(x ** 2))
        if r2 > MAX_CORRELATION ** 2:
            left_out.append((term.name, f'{term.regressor} is a combination of the other '
                                        f'regressors (r = {np.sqrt(max(r2, 0.0)):.5f})'))
            continue
        kept[term.name] = x
    return kept, left_out


LINE_VOLUMES = ('line_compliance', 'line_compliance_b')
"""The two line volumes of (T1): a rig metered on one line has only one of them."""

VOLUME_T = 2.0
"""Least |t| of a line volume in a least-squares fit of the loss on the base and every
dynamic term (its variance inflated for the residuals' correlation) to keep it, [-]."""


def _line_volumes(kept: dict[str, FloatArray], left_out: list[tuple[str, str]],
                  parts: LossParts) -> tuple[dict[str, FloatArray], list[tuple[str, str]]]:
    """
    Leave out a line volume the loss does not show (|t| < :data:`VOLUME_T`), saying so.

    A free coefficient on a line no flowmeter meets costs every later test power and can
    soak up part of an effect; the screen is the same for both ports, so a recording and
    its mirror keep the same volumes.
    """
    names = list(kept)
    x = np.column_stack([_base(parts), *kept.values()])
    x = x / np.where(np.any(x, axis=0), np.linalg.norm(x, axis=0), 1.0)  # t is scale-free
    coef, *_ = np.linalg.lstsq(x, parts.loss, rcond=None)
    residual = parts.loss - x @ coef
    dof = max(residual.size - x.shape[1], 1)
    variance = float(residual @ residual) / dof * variance_inflation(residual)
    scale = np.sqrt(variance * np.abs(np.diag(np.linalg.pinv(x.T @ x))))
    with np.errstate(divide='ignore', invalid='ignore'):
        t = dict(zip(names, np.abs(coef[-len(names):]) / scale[-len(names):])) if names else {}
    weak = [name for name in LINE_VOLUMES if name in t and not t[name] >= VOLUME_T]
    return ({k: v for k, v in kept.items() if k not in weak},
            left_out + [(name, f'the loss does not show it (|t| = {t[name]:.2f} < '
                               f'{VOLUME_T:g} in a least-squares fit with every term)')
                        for name in weak])


REST_BAND = 5.0
"""A sample whose speed reads 0 is usable unless its flow runs against the drop by more than
this many robust spreads of those samples' flow readings, [-]."""


def at_rest(flow: FloatArray) -> np.ndarray:
    """
    Return which flow readings of samples whose speed reads 0 are usable.

    A shaft at rest passes its leak (small against the noise, so its flow reads either sign)
    and whatever a valve passes while it stalls (the way the drop pushes). Keeping only the
    readings the way the drop pushes (:func:`~satmotor_ros.identify.parts.loss_parts` for a
    turning shaft) would bias the rest samples by the noise's half-mean, a phantom flow
    offset; a reading against the drop beyond the noise is a shaft that turns while its
    speed reads 0 (a speed reading that drops out at the start of a pump stroke), which the
    model cannot explain. The band below zero is :data:`REST_BAND` robust spreads (1.4826
    median |Q| of these readings), so the noise is cut nowhere near its bulk.

    Parameters
    ----------
    flow : ndarray
        Flow readings of samples whose speed reads 0, in the row's frame, [m^3/s]

    Returns
    -------
    ndarray of bool
        True where the reading is usable.

    """
    if not flow.size:
        return np.ones(0, dtype=bool)
    inside: np.ndarray = flow > -REST_BAND * MAD * float(np.median(np.abs(flow)))
    return inside


def transient_samples(model: MotorModel, table: BenchTable,
                      options: TransientOptions | None = None) -> Samples:
    """
    Turn every usable sample of a time series into bins for the fit, with the transient terms.

    Parameters
    ----------
    model : MotorModel
        The model whose steady map is evaluated at each sample, [-]
    table : BenchTable
        Raw samples with a ``time`` channel, [-]
    options : TransientOptions, optional
        Bin length, gap and row limit, [-]

    Returns
    -------
    Samples
        Bins, their model components and the dynamic regressors.

    Raises
    ------
    DataError
        If there is no time channel.
    IdentificationError
        If no two neighbouring samples are usable.

    """
    options = options or TransientOptions()
    if 'time' not in table.channels:
        msg = "all-samples mode needs a 'time [s]' column for the transient terms"
        raise DataError(msg)
    order = np.argsort(table.channels['time'], kind='stable')
    if np.any(np.diff(order) != 1):
        table = table.select(order)
    time = table.channels['time']
    first, step = segments(time, options.gap)
    found = reading_spikes(table, first)
    table = found.mended(table)  # a spiked speed or pressure: its neighbours' fit
    channels = dict(table.channels)
    if 'revolutions' not in channels:
        channels['revolutions'] = sampled_revolutions(table.speed, time)
    table = replace(table, channels=channels, units={**table.units, 'revolutions': 'rev'})
    all_parts, usable = loss_parts(model, table)
    still = all_parts.speed == 0.0  # at the usable samples
    moving = np.zeros(still.size, dtype=bool)
    moving[still] = ~at_rest(all_parts.flow[still])
    rest = np.zeros(time.size, dtype=bool)  # speed reads 0, the flow against the drop
    rest[usable] = moving
    spike = np.zeros(time.size, dtype=bool)
    spike[found.left_out()] = True  # a spiked flow: the sample is left out
    if ((spike | rest) & usable).any():  # a bad sample decides nothing: left out like an
        all_parts = parts_at(all_parts, ~(spike | rest)[usable])  # unusable one
        usable = usable & ~spike & ~rest
    size = max(1, int(round(options.bin_seconds / step)) if step > 0.0 else 1)
    size = max(size, int(np.ceil(int(usable.sum()) / options.max_rows)))
    where = np.flatnonzero(usable)  # parts are at the usable samples only

    def at_samples(x: FloatArray | float) -> FloatArray:
        full = np.full(time.size, np.nan)
        full[where] = x
        return full

    # a bin stays in one frame of the loss (the sign of dp: quadrants, LossParts.sign)
    frame = at_samples(all_parts.sign)
    a, b = bins(usable, first | np.concatenate(([True], frame[1:] != frame[:-1])), size)
    if not a.size:
        msg = (f'{table.source}: no two neighbouring usable samples (need a flow the model can '
               f'give and a chamber drop between 0 and {model.dp_limit / 1e6:.1f} MPa)')
        raise IdentificationError(msg)

    def mean(x: FloatArray) -> FloatArray:
        return bin_means(time, x, a, b)

    averaged: dict[str, Any] = {f.name: mean(at_samples(getattr(all_parts, f.name)))
                                for f in fields(all_parts)
                                if isinstance(getattr(all_parts, f.name), np.ndarray)}
    averaged['components'] = tuple(
        replace(c, pieces=tuple((k, mean(at_samples(x))) for k, x in c.pieces))
        for c in all_parts.components)
    parts = replace(all_parts, **averaged)
    ends = [smooth(x, first, END_SAMPLES)
            for x in (table.p_in, table.p_out, table.speed, table.flow)]
    sign = frame[a]  # the row's frame: its flow, loss and regressors are s times the readings'
    dp_a, dp_b, dn, dq = (sign * (x[b] - x[a]) / (time[b] - time[a]) for x in ends)
    regressors = dynamic_regressors(dp_a, dp_b, dn, dq,
                                    flow_per_speed(parts, model.geometry.displacement))
    nuisance, left_out = _screen(regressors, parts)
    if options.screen_volumes:
        nuisance, left_out = _line_volumes(nuisance, left_out, parts)
    parts = parts.with_nuisance(nuisance)
    rows = BenchTable(mean(table.speed), mean(table.flow), mean(table.p_in), mean(table.p_out),
                      {k: _channel_means(time, v, a, b) for k, v in table.channels.items()},
                      table.units,
                      table.source, True, table.notes)
    in_bins = np.zeros(time.size + 1, dtype=int)
    np.add.at(in_bins, a, 1)
    np.add.at(in_bins, b + 1, -1)
    held = np.cumsum(in_bins)[:-1] > 0
    n_samples = int(np.count_nonzero(held))
    n_segments = int(first.sum())
    note = (f'all samples: {n_samples} of {len(table)} ({100.0 * n_samples / len(table):.0f} %) '
            f'in {n_segments} stretch(es) without a gap, step {step:.4g} s, averaged over '
            f'bins of {size} steps ({size * step:.3g} s, {a.size} rows)'
            + left_out_samples(model, table, usable | spike | rest, held, int(spike.sum()),
                               int(rest.sum())) + found.mended_note())
    rows = replace(rows, notes=rows.notes + (note,))
    lags = [nuisance[name] for name in RATE_TERMS if name in nuisance]
    correlation = float(np.corrcoef(lags[0], lags[1])[0, 1]) if len(lags) == 2 else np.nan
    return Samples(rows, parts, n_samples, size, step, n_segments, tuple(left_out),
                   correlation, table, usable, (a, b), held, found.at, found.size,
                   found.scale, found.channel, first)


SPIKE_HALF = 3
"""Samples on each side of a sample whose local quadratic fit predicts it, [-]."""

SPIKE_LIMIT = 5.0
"""Least departure of a spike from its neighbours' fit, in robust standard deviations, [-]."""

SPIKE_SCALE_HALF = 50
"""Samples on each side whose departures give a sample's local noise scale, [-]."""

SPIKE_SIDES = 0.5
"""Least departure of a spike from the lines through the samples on each side, as a share of
its departure from the quadratic through both, [-]."""


def _extrapolation(m: int) -> FloatArray:
    """Return weights that give, from m samples in order, the next one on their line, [-]."""
    k = np.arange(m, dtype=float)
    weights: FloatArray = np.array([1.0, float(m)]) @ np.linalg.pinv(
        np.column_stack([np.ones(m), k]))
    return weights


def spikes(x: FloatArray, first: np.ndarray) -> tuple[np.ndarray, FloatArray, float]:
    r"""
    Flag the isolated spikes of a sampled reading: one sample far off its neighbours' curve.

    Each sample is predicted by a quadratic through the :data:`SPIKE_HALF` samples on each
    side (itself left out), a linear filter (per stretch without a gap; the ends are never
    flagged). A sample is a spike when its departure from that prediction exceeds
    :data:`SPIKE_LIMIT` standard deviations of the departures within
    :data:`SPIKE_SCALE_HALF` samples (from their mean magnitude, at least the robust one of
    all departures; or the Gaussian quantile that a clean series of N samples exceeds with
    chance 5 %, if larger), is the largest within :data:`SPIKE_HALF` samples, and departs
    the same way by at least :data:`SPIKE_SIDES` of it from the line through the samples
    before it and from the line through those after it (a kink, where a transient starts,
    lies on both lines; a step on one; a curve departs from the quadratic by little). A
    bad reading of one sample is thus found before the samples are averaged into rows,
    where it would be diluted below the rows' outlier limit, while a fast but smooth
    transient is not.

    Parameters
    ----------
    x : ndarray
        The samples, [any]
    first : ndarray of bool
        First sample of each stretch without a gap, [-]

    Returns
    -------
    ndarray of bool
        True at a spike.
    ndarray
        Each sample's departure from its neighbours' fit (0 at the ends), [unit of x]
    float
        The robust standard deviation of the departures, [unit of x]

    """
    m = SPIKE_HALF
    k = np.array([j for j in range(-m, m + 1) if j], dtype=float)
    design = np.column_stack([np.ones_like(k), k, k * k])
    weight = np.linalg.pinv(design)[0]  # the quadratic's value at 0 from the others
    kernel = np.concatenate((weight[:m], [0.0], weight[m:]))
    departure = np.zeros(x.size)
    starts = np.flatnonzero(first)
    for lo, hi in zip(starts, np.append(starts[1:], x.size)):
        if hi - lo > 2 * m:
            departure[lo + m:hi - m] = x[lo + m:hi - m] - np.convolve(
                x[lo:hi], kernel[::-1], 'valid')
    departure[~np.isfinite(departure)] = 0.0
    flagged = np.zeros(x.size, dtype=bool)
    moved = np.abs(departure[departure != 0.0])  # a quantised reading rests on exact zeros
    scale = float(MAD * np.median(moved)) if moved.size else 0.0
    if not scale > 0.0:
        return flagged, departure, scale
    size = np.abs(departure)
    # the noise may grow with the reading: each sample is judged by its neighbourhood's
    # scale (never below the whole series' robust
    # scale, by the mean |departure| there: a median of a quantised reading's departures
    # rests on its resolution)
    local = np.maximum(np.sqrt(np.pi / 2.0) * ndimage.uniform_filter1d(
        size, 2 * SPIKE_SCALE_HALF + 1, mode='nearest'), scale)
    limit = max(SPIKE_LIMIT, float(special.ndtri(1.0 - 0.025 / max(x.size, 1)))) * local
    i = np.flatnonzero(size > limit)
    i = i[(i >= m) & (i + m < x.size)]
    i = i[size[i] >= ndimage.maximum_filter1d(size, 2 * m + 1)[i]]  # the largest near it
    # a spike departs alike from the line through the samples before and after it; a
    # kink or the start of a transient (on both lines) and a step (on one) do not
    weights = _extrapolation(m)
    spiked = np.ones(i.size, dtype=bool)
    for side in (np.arange(-m, 0), np.arange(m, 0, -1)):  # x[i - m:i] and x[i + m:i:-1]
        d = x[i[:, None] + side] @ weights - x[i]
        spiked &= (np.sign(-d) == np.sign(departure[i])) & (np.abs(d) >= SPIKE_SIDES * size[i])
    flagged[i[spiked]] = True
    return flagged, departure, scale


SPIKE_SPAN = 0.05
"""Least departure of a spike of a reading the model is evaluated at (the speed, the port
pressures), as a share of that reading's span (1st to 99th percentile of the series), [-]."""

SPIKE_READINGS = (('flow', 0.0), ('speed', SPIKE_SPAN), ('p_in', SPIKE_SPAN),
                  ('p_out', SPIKE_SPAN))
"""The readings searched for spikes, each with the least share of its span a spike departs by."""


@dataclass(frozen=True)
class ReadingSpikes:
    """The isolated spikes of a time series' readings: one entry per spiked reading."""

    at: np.ndarray  # the sample of each, in time order [-]
    channel: tuple[str, ...]  # its reading: 'flow', 'speed', 'p_in' or 'p_out'
    size: np.ndarray  # its departure from the neighbours' fit [SI unit of the reading]
    scale: np.ndarray  # the robust scale of that reading's departures [SI unit of the reading]

    def left_out(self) -> np.ndarray:
        """Return the samples whose flow reading spiked: they are left out."""
        return self.at[[c == 'flow' for c in self.channel]].astype(int)

    def mended(self, table: BenchTable) -> BenchTable:
        """
        Return the table with each spiked speed or pressure replaced by its neighbours' fit.

        Parameters
        ----------
        table : BenchTable
            The samples the spikes were found in, in time order, [-]

        Returns
        -------
        BenchTable
            The same samples; a spiked flow reading stays (its sample is left out).

        """
        out = {name: getattr(table, name).copy() for name in set(self.channel) - {'flow'}}
        for i, name, d in zip(self.at, self.channel, self.size):
            if name != 'flow':
                out[name][i] -= d
        return replace(table, **out) if out else table

    def mended_note(self) -> str:
        """Say which readings of the speed and pressures were mended, or ''."""
        counts = [(n, self.channel.count(n)) for n, _ in SPIKE_READINGS[1:] if n in self.channel]
        if not counts:
            return ''
        return ('; mended: isolated spikes of ' + ', '.join(f'{k} {n}' for n, k in counts)
                + " reading(s), each replaced by its neighbours' fit (listed as outliers)")


def reading_spikes(table: BenchTable, first: np.ndarray) -> ReadingSpikes:
    """
    Find the isolated spikes of the flow, the speed and both port pressures (:func:`spikes`).

    The flow is the reading the fit explains: a spike beyond its noise would pull the fit,
    and a value made up for it would be data the error is judged on, so its sample is left
    out. The speed and the pressures are where the model is evaluated: a spike of theirs is
    replaced by its neighbours' fit (:meth:`ReadingSpikes.mended`), so the sample's flow
    still counts and the rows are those of the recording without the glitch. Their
    one-sample departures of a few tenths of an MPa or a few rad/s (a pressure ringing
    sampled at 50 Hz, a speed computed from an encoder's counts) are errors in the
    variables every sample carries, not bad readings: a spike of theirs must also depart by
    :data:`SPIKE_SPAN` of the reading's span.

    Parameters
    ----------
    table : BenchTable
        The samples in time order, [-]
    first : ndarray of bool
        First sample of each stretch without a gap, [-]

    Returns
    -------
    ReadingSpikes
        Each spiked reading of a sample, in time order.

    """
    found = []
    for name, share in SPIKE_READINGS:
        x = getattr(table, name)
        flagged, departure, scale = spikes(x, first)
        if share > 0.0 and flagged.any():
            lo, hi = np.percentile(x[np.isfinite(x)], [1.0, 99.0])
            flagged &= np.abs(departure) > share * (hi - lo)
        found += [(int(i), name, float(departure[i]), scale) for i in np.flatnonzero(flagged)]
    found.sort(key=lambda f: f[0])
    return ReadingSpikes(np.array([f[0] for f in found], dtype=int),
                         tuple(f[1] for f in found), np.array([f[2] for f in found]),
                         np.array([f[3] for f in found]))


def left_out_samples(model: MotorModel, table: BenchTable, usable: np.ndarray,
                     held: np.ndarray, n_spikes: int = 0, n_rest: int = 0) -> str:
    """
    Say why samples are in no row: which the model cannot use, and which no bin holds.

    Parameters
    ----------
    model : MotorModel
        The model evaluated at the samples, [-]
    table : BenchTable
        The samples in time order, [-]
    usable : ndarray of bool
        Which the model can use (:func:`~satmotor_ros.identify.parts.loss_parts`), the
        spikes among them, [-]
    held : ndarray of bool
        Which a row holds, [-]
    n_spikes : int
        Samples left out as spikes of the flow reading (:func:`reading_spikes`), [-]
    n_rest : int
        Samples of a shaft reading no speed left out by :func:`at_rest`, [-]

    Returns
    -------
    str
        ``'; left out: ...'`` with the count of each reason, or ``''`` when none is.

    """
    dp = table.p_in - table.p_out
    with np.errstate(invalid='ignore'):
        s = np.where(dp < 0.0, -1.0, 1.0)
        finite = np.isfinite(table.flow) & np.isfinite(table.speed) & np.isfinite(dp)
        no_flow = finite & ~((s * table.flow > 0.0) | (s * table.speed <= 0.0))
    reasons = [(int((~finite).sum()), 'without a finite reading'),
               (int((no_flow & ~usable).sum()), 'with no flow the model can give (a shaft '
                'that turns with the drop and no flow that way)'),
               (int((finite & ~no_flow & ~usable).sum()), 'with a chamber drop outside 0 to '
                f'{model.dp_limit / 1e6:.3g} MPa'),
               (n_spikes, 'isolated spikes of the flow reading (listed as outliers)'),
               (n_rest, 'with a speed of 0 and a flow against the drop beyond the noise (a '
                'shaft that turns while its speed reads 0)'),
               (int((usable & ~held).sum()) - n_spikes - n_rest,
                'in runs of usable samples too short for a bin')]
    said = [f'{k} {why}' for k, why in reasons if k]
    return '; left out: ' + ', '.join(said) if said else ''


def averaged(samples: Samples, x: FloatArray) -> FloatArray:
    """
    Average a quantity given at every raw sample over the rows' bins, as the rows were.

    Parameters
    ----------
    samples : Samples
        The rows, [-]
    x : ndarray
        The quantity at each of ``samples.samples`` (NaN where unknown), [any]

    Returns
    -------
    ndarray
        Its trapezoid mean over each row's bin, [unit of x]

    """
    return bin_means(samples.samples.channels['time'], x, *samples.bounds)


def averaged_sparse(samples: Samples) -> Callable[[np.ndarray, FloatArray], FloatArray]:
    """
    Return :func:`averaged` for quantities 0 at every raw sample but a few, NaN where dp is.

    Parameters
    ----------
    samples : Samples
        The rows, [-]

    Returns
    -------
    callable
        (the raw samples where the quantity may differ from 0, each once and all usable;
        its values there) -> its trapezoid mean over each row's bin (:func:`sparse_bin_means`).

    """
    raw = samples.samples
    unknown = ~samples.usable | np.isnan(raw.p_in - raw.p_out)
    return sparse_bin_means(raw.channels['time'], unknown, *samples.bounds)


def parts_at(parts: LossParts, keep: np.ndarray) -> LossParts:
    """
    Return the components at the rows where `keep` is true.

    Parameters
    ----------
    parts : LossParts
        Components at every row, [-]
    keep : ndarray of bool
        Rows to keep, [-]

    Returns
    -------
    LossParts
        The same fields, nuisance columns and components at the kept rows.

    """
    kept: dict[str, Any] = {f.name: getattr(parts, f.name)[keep] for f in fields(parts)
                            if isinstance(getattr(parts, f.name), np.ndarray)}
    kept['components'] = tuple(replace(c, pieces=tuple((k, x[keep]) for k, x in c.pieces))
                               for c in parts.components)
    kept['nuisance'] = {k: x[keep] for k, x in parts.nuisance.items()}
    return replace(parts, **kept)


def dynamics_summary(fit: FitReport, samples: Samples) -> list[dict[str, Any]]:
    """
    Describe the fitted dynamic terms for calibration.json and the report.

    Parameters
    ----------
    fit : FitReport
        A fit on the samples; the dynamic terms are among its names, [-]
    samples : Samples
        The samples it was fitted on, [-]

    Returns
    -------
    list of dict
        Per term of :data:`DYNAMIC_TERMS`: ``term``, ``symbol``, ``regressor``,
        ``equation``, ``meaning``, ``unit``, and either ``coefficient`` and
        ``ci95`` (SI, in ``unit``) with ``nonzero`` (the interval excludes 0) and
        ``physical`` (false for a negative value: a volume over a bulk modulus and a
        time constant are >= 0, so a negative fit is no estimate and ``impossible``
        says so), or ``left_out`` with the reason; a ``note`` on the two lags when
        their regressors correlate beyond :data:`LAG_CORRELATION`.

    """
    at = {name.removeprefix('nuisance:'): i for i, name in enumerate(fit.names)}
    reasons = dict(samples.left_out)
    out = []
    for term in DYNAMIC_TERMS:
        entry: dict[str, Any] = {'term': term.name, 'symbol': term.symbol,
                                 'regressor': term.regressor, 'unit': term.unit,
                                 'equation': term.equation, 'meaning': term.meaning}
        if term.name in at:
            lo, hi = (float(v) for v in fit.ci95[at[term.name]])
            value = float(fit.values[at[term.name]])
            entry.update(coefficient=written(value), ci95=[written(lo), written(hi)],
                         nonzero=bool(lo > 0.0 or hi < 0.0), physical=bool(value >= 0.0))
            if value < 0.0:
                entry['impossible'] = (f'{term.symbol} < 0 cannot be (it is >= 0): not an '
                                       'estimate; the term absorbs what the model lacks')
            if term.name in RATE_TERMS and abs(samples.correlation) > LAG_CORRELATION:
                entry['note'] = (f"the two lags' regressors correlate (r = "
                                 f'{samples.correlation:.4f}): the data determine tau_n - '
                                 'tau_Q far better than either')
        else:
            entry['left_out'] = reasons.get(term.name, 'not fitted')
        out.append(entry)
    return out


def variance_inflation(residual: FloatArray) -> float:
    r"""
    Estimate how much the correlation of neighbouring residuals inflates a variance.

    The inflation is the long-run variance over the variance, :math:`1 + 2\sum_k
    \lambda(k/M)\,\rho_k`, from the residuals' own autocorrelation :math:`\rho_k` (in
    time order) through Politis' flat-top lag window (:math:`\lambda = 1` to M/2, falling
    linearly to 0 at M): the factor by which the variance of a mean (and of a least-squares
    coefficient on a slowly varying regressor) exceeds the independent case; N / inflation
    is the effective number of samples. M is twice the memory m: the first lag after which
    :data:`QUIET_LAGS` autocorrelations in a row stay below
    :math:`2\sqrt{\log_{10} N / N}` (what N independent residuals pass by chance), so the
    window reaches as far as the data show a positive correlation and no further (the
    negative lobes that a short series' estimates show by chance would cancel it), and
    at most sqrt(N) (or N / :data:`MIN_LAGS`) lags: further lags rest on too few
    independent pairs, and a slow effect the model still lacks (wear, before it is
    found) would count as noise that leaves a handful of effective rows. A flat
    window is not biased down over the memory as Bartlett's, and is far steadier than batch
    means, whose longest blocks decide with a few means each: on noise like the MBARI logs'
    (a 0.12 s Gaussian correlation, 0.2 s rows, inflation 2.36) batch means gave 1.1-3.5
    (sd 0.75), this gives 2.24 (sd 0.20) over 850 rows.

    Parameters
    ----------
    residual : ndarray
        Residuals in time order, [any]

    Returns
    -------
    float
        The inflation, >= 1, [-]

    """
    r = residual[np.isfinite(residual)]
    if r.size < 2 * MIN_LAGS:
        return 1.0
    r = r - r.mean()
    variance = float(np.mean(r ** 2))
    if variance == 0.0:
        return 1.0
    rho = autocorrelation(r, min(r.size // MIN_LAGS, int(np.ceil(np.sqrt(r.size)))))
    quiet = rho < 2.0 * np.sqrt(np.log10(r.size) / r.size)
    memory = rho.size
    for m in range(rho.size - QUIET_LAGS + 1):
        if quiet[m:m + QUIET_LAGS].all():
            memory = m
            break
    width = 2 * max(memory, 1)
    k = np.arange(1, min(width, rho.size) + 1)
    window = np.minimum(1.0, 2.0 * (1.0 - k / width))
    return max(1.0, 1.0 + 2.0 * float(np.sum(window * rho[:k.size])))


def autocorrelation(residual: FloatArray, lags: int) -> FloatArray:
    """
    Return the autocorrelation of zero-mean residuals at lags 1 to `lags`.

    Parameters
    ----------
    residual : ndarray
        Zero-mean residuals in time order, [any]
    lags : int
        The largest lag, [-]

    Returns
    -------
    ndarray
        rho_1 ... rho_lags (the biased estimator: sums over N), [-]

    """
    n = residual.size
    spectrum = np.fft.rfft(residual, 2 * n)
    cov = np.fft.irfft(spectrum * np.conj(spectrum), 2 * n)[:lags + 1]
    return np.asarray(cov[1:] / cov[0])


def transient_section(summary: dict[str, Any], inflation: float) -> list[str]:
    """
    Write the report's lines on the transient terms.

    Parameters
    ----------
    summary : dict
        calibration.json's object, with ``dynamics``, [-]
    inflation : float
        Variance inflation of the final fit's residuals, [-]

    Returns
    -------
    list of str
        Markdown lines.

    """
    lines = ['## Transient terms', '',
             f'Fitted with the model on every sample, each as a nuisance regressor without '
             f'prior (`satmotor_ros.identify.transient`); intervals and F-tests allow for the '
             f'correlation of neighbouring residuals (variance inflation {inflation:.3g}).', '']
    rows = []
    for d in summary['dynamics']:
        if 'coefficient' in d and 'impossible' in d:
            lo, hi = d['ci95']
            value = f'{d["coefficient"]:.4g} **impossible**'
            interval = f'[{lo:.4g}, {hi:.4g}]: {d["impossible"]}'
        elif 'coefficient' in d:
            lo, hi = d['ci95']
            value = f'{d["coefficient"]:.4g}'
            interval = f'[{lo:.4g}, {hi:.4g}]' + ('' if d['nonzero'] else ' (includes 0)')
        else:
            value, interval = 'left out', d['left_out']
        rows.append([f'`{d["term"]}` ({d["equation"]})', f'{d["symbol"]} [{d["unit"]}]',
                     value, interval, d['meaning']])
    lines += ['| term | coefficient | value | ci95 | meaning |', '| --- | --- | --- | --- | --- |']
    lines += ['| ' + ' | '.join(row) + ' |' for row in rows]
    notes = {d['note'] for d in summary['dynamics'] if 'note' in d}
    return lines + [''] + [f'{note}.' for note in sorted(notes)] + ([''] if notes else [])
