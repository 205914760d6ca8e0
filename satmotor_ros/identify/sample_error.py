# SPDX-License-Identifier: Apache-2.0
r"""
A time series' errors over every usable sample, not over the bins the fit reads.

In transient mode the fit reads a time series as rows, the means of its samples over short
bins (:mod:`.transient`): a reduction that averages the sensors' noise and makes the rates
of change exact. The figures a user reads are over the samples themselves (DESIGN.md,
"Calibration and validation errors are over every usable sample"): each sample a row holds
is predicted by the fitted model made whole (:func:`fitted_model`: the factors on the
packaged coefficients and the effects at their fitted values, evaluated by the model itself
as ``validate`` evaluates it, :mod:`.predicted`), plus the transient terms at that sample
(:func:`sample_rates`: each rate of change over a bin's length centred on the sample, as a
row's is over its bin), and compared with its own flow reading. The speed delay is already
in the samples. Out of sample as the rows' error: a sample takes the parameters fitted
without its row's fold (:attr:`~satmotor_ros.identify.selection.Score.folds`); a row no fold
tested (an isolated outlier, not fitted) takes the whole fit's.

What a row's mean removes stays in these figures: the sensors' noise and the fast motion
within 0.2 s that the bin averages out, so over the samples the error is larger than over
the rows.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from satmotor_ros.identify.effects import CalibratedModel
from satmotor_ros.identify.fit import LossFit
from satmotor_ros.identify.parts import loss_parts, LossParts
from satmotor_ros.identify.predicted import bare, predicted, responds
from satmotor_ros.identify.selection import Errors, Score
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import (dynamic_regressors, END_SAMPLES, first_order,
                                             flow_per_speed, parts_at, Samples, smooth)
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import kind_of


LEAST_FACTOR = 1e-12
"""Least factor on a packaged coefficient in a model made from a fit's parameters, [-]."""


@dataclass(frozen=True)
class SampleData:
    """The samples a time series' rows hold, each with the row that holds it."""

    table: BenchTable  # the samples, in time order
    parts: LossParts  # the model's components at them (no effect), the transient terms'
    # regressors as nuisance
    row: np.ndarray  # the row (bin) of the fit that holds each sample [-]
    index: np.ndarray  # each sample's position among the time series' samples [-]
    lag: Callable[[FloatArray, float], FloatArray] | None = None  # (a quantity at each of
    # these samples, tau [s]) -> it through a first-order lag of tau on the series' timeline

    def __len__(self) -> int:
        """Return the number of samples."""
        return int(self.row.size)


def _stretch_ends(first: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the first and the last sample of the stretch each sample is in."""
    index = np.arange(first.size)
    start = np.maximum.accumulate(np.where(first, index, 0))
    last = np.append(first[1:], True)
    end = np.minimum.accumulate(np.where(last, index, first.size)[::-1])[::-1]
    return start, end


def sample_rates(samples: Samples) -> tuple[FloatArray, ...]:
    """
    Compute each raw sample's rates of change of p_in, p_out, speed and flow.

    The readings are smoothed as a row's end values are (a local quadratic over
    :data:`~satmotor_ros.identify.transient.END_SAMPLES` samples); a sample's rate is the
    change over a bin's length centred on it (half a bin each side, within its stretch
    without a gap), as a row's rate is the change across its bin.

    Parameters
    ----------
    samples : Samples
        The time series as the fit read it, [-]

    Returns
    -------
    tuple of ndarray
        dp_in/dt [Pa/s], dp_out/dt [Pa/s], dn/dt [rad/s^2], dQ/dt [m^3/s^2] at every raw
        sample, as read (not in a row's frame); 0 in a stretch of one sample.

    """
    raw = samples.samples
    time = raw.channels['time']
    first = samples.first if samples.first is not None else np.eye(1, time.size, dtype=bool)[0]
    start, end = _stretch_ends(first)
    half = max(1, samples.bin_size // 2)
    index = np.arange(time.size)
    lo, hi = np.maximum(index - half, start), np.minimum(index + half, end)
    span = time[hi] - time[lo]
    moved = span > 0.0
    out = []
    for x in (raw.p_in, raw.p_out, raw.speed, raw.flow):
        ends = smooth(x, first, END_SAMPLES)
        out.append(np.where(moved, (ends[hi] - ends[lo]) / np.where(moved, span, 1.0), 0.0))
    return tuple(out)


def sample_data(model: MotorModel, samples: Samples) -> SampleData:
    """
    Evaluate the model's components and the transient terms at every sample a row holds.

    Parameters
    ----------
    model : MotorModel
        The model the rows were read with, [-]
    samples : Samples
        The rows, [-]

    Returns
    -------
    SampleData
        The samples, their components (the regressors of the transient terms the rows
        carry as nuisance, in each sample's frame) and the row of each.

    """
    held = np.flatnonzero(samples.in_bins)
    table = samples.samples.select(samples.in_bins)
    parts, usable = loss_parts(bare(model), table)
    if not usable.all():  # a row holds usable samples only; kept safe all the same
        held, table = held[usable], table.select(usable)
    rates = [r[held] for r in sample_rates(samples)]
    sign = np.asarray(parts.sign) * np.ones(held.size)
    qt = model.geometry.displacement
    dp_a, dp_b, dn, dq = (sign * r for r in rates)
    regressors = dynamic_regressors(dp_a, dp_b, dn, dq, flow_per_speed(parts, qt))
    nuisance = {name: np.nan_to_num(regressors[name]) for name in samples.parts.nuisance}
    row = np.searchsorted(samples.bounds[0], held, side='right') - 1
    size = len(samples.samples)
    starts = np.append(np.flatnonzero(samples.stretch_starts), size)

    def lag(x: FloatArray, tau: float) -> FloatArray:
        full = np.zeros(size)  # 0 at the samples no row holds: gaps in a stretch
        full[held] = x
        return first_order(full, starts, samples.step, tau)[held]
    return SampleData(table, replace(parts, nuisance=nuisance), row, held, lag)


def fitted_model(model: MotorModel, parts: LossParts, fit: LossFit,
                 u: FloatArray) -> tuple[MotorModel, dict[str, float]]:
    """
    Make the model a fit's parameters stand for, and its transient terms' coefficients.

    Parameters
    ----------
    model : MotorModel
        The model the rows were read with (no effect), [-]
    parts : LossParts
        The rows the fit was made on (their components name the factors), [-]
    fit : LossFit
        The fit, [-]
    u : ndarray
        Its parameters (its own, or a fold's, :meth:`LossFit.without`), [-]

    Returns
    -------
    MotorModel
        Each linear part's coefficients times its factor, the effects at their values
        (and what they set, e.g. k_ex).
    dict of str to float
        Nuisance regressor name -> coefficient, SI.

    """
    m = len(parts.components)
    # a factor on its bound 0 (a fold's clipped step) as a negligible one: a coefficient set
    # holds no zero coefficient
    factors = {c.part: max(float(v), LEAST_FACTOR) for c, v in zip(parts.components, u[:m])}
    coef = model.family.scaled(model.coef, factors)
    effects = tuple(c.as_effect(k, *theta) for c, k, theta in fit._effect_values(u))
    for effect in effects:
        coef = kind_of(effect).coefficients(effect, coef)
    coefficient_set = replace(model.coefficient_set, coefficients=coef, effects=effects)
    made = MotorModel(model.geometry, coefficient_set, model.valid_range, model.liquid,
                      model.displacement_law, model.name)
    q = fit.typical_.size
    return made, dict(zip(fit.nuisance_names_, (u[m:m + q] * fit.typical_).tolist()))


def _predict(data: SampleData, model: MotorModel, nuisance: dict[str, float],
             at: np.ndarray) -> FloatArray:
    """Predict the flow reading (in the samples' frame) at the samples `at` (bool)."""
    if responds(model):  # a valve's flow depends on the samples before: every one read
        flow, _ = predicted(CalibratedModel(model), data.table, data.parts, data.lag)
        flow, parts = flow[at], parts_at(data.parts, at)
    else:
        parts = parts_at(data.parts, at)
        flow, _ = predicted(CalibratedModel(model), data.table.select(at), parts)
    for name, value in nuisance.items():
        flow = flow + value * parts.nuisance[name]
    return flow


def sample_residual(data: SampleData, model: MotorModel, parts: LossParts,
                    score: Score) -> FloatArray:
    """
    Return a score's out-of-sample residual at every sample: measured minus predicted flow.

    Parameters
    ----------
    data : SampleData
        The samples, [-]
    model : MotorModel
        The model the rows were read with (no effect), [-]
    parts : LossParts
        The rows the score was fitted on, [-]
    score : Score
        The fit and its folds' parameters, [-]

    Returns
    -------
    ndarray
        In each sample's frame (NaN where the model flags a sample invalid), [m^3/s]

    """
    out = np.full(len(data), np.nan)
    untested = np.ones(len(data), dtype=bool)
    for rows, u in score.folds:
        tested = np.zeros(len(parts), dtype=bool)
        tested[rows] = True
        at = tested[data.row]
        untested &= ~at
        if at.any():
            out[at] = data.parts.flow[at] - _predict(data, *fitted_model(model, parts,
                                                                         score.fit, u), at)
    if untested.any():
        made = fitted_model(model, parts, score.fit, score.fit.u_)
        out[untested] = data.parts.flow[untested] - _predict(data, *made, untested)
    return out


def packaged_residual(data: SampleData, model: MotorModel) -> FloatArray:
    """Return the packaged model's residual at every sample (no transient term), [m^3/s]."""
    every = np.ones(len(data), dtype=bool)
    return data.parts.flow - _predict(data, model, {}, every)


@dataclass(frozen=True)
class SampleErrors:
    """A calibration's residuals at every sample, out of sample: the figures it reports."""

    data: SampleData  # the samples
    packaged: FloatArray  # the packaged model's residual, in sample [m^3/s]
    residual: tuple[FloatArray, ...]  # the baseline's, then after each effect found [m^3/s]

    def kept(self, outliers: np.ndarray | None = None) -> np.ndarray:
        """Return the samples an error is over: finite, and not in an outlier row."""
        finite: np.ndarray = np.all(np.isfinite(np.vstack([self.packaged, *self.residual])),
                                    axis=0)
        return finite if outliers is None else finite & ~outliers[self.data.row]

    def errors(self, step: int, outliers: np.ndarray | None = None) -> Errors:
        """Summarise the residual of `step` (0: no effect; -1: packaged) over the kept samples."""
        at = self.kept(outliers)
        residual = self.packaged if step < 0 else self.residual[step]
        return Errors.of(residual[at], self.data.parts.loss[at])


def sample_errors(model: MotorModel, samples: Samples, parts: LossParts,
                  scores: tuple[Score, ...]) -> SampleErrors:
    """
    Compute the residuals of the packaged model and of each score at every sample.

    Parameters
    ----------
    model : MotorModel
        The model the rows were read with (no effect), [-]
    samples : Samples
        The rows and their samples, [-]
    parts : LossParts
        The rows' components, as fitted, [-]
    scores : tuple of Score
        The baseline, then the score of each effect found, in order, [-]

    Returns
    -------
    SampleErrors
        The residuals.

    """
    data = sample_data(model, samples)
    return SampleErrors(data, packaged_residual(data, model),
                        tuple(sample_residual(data, model, parts, s) for s in scores))


__all__ = ['SampleData', 'SampleErrors', 'fitted_model', 'sample_data', 'sample_errors',
           'sample_rates', 'sample_residual']
