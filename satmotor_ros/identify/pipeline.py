# SPDX-License-Identifier: Apache-2.0
"""
Calibration end to end: steady points, baseline fit, forward selection of effects, refit.

The pieces stay apart (PySINDy style): :mod:`.candidates` builds the
library, :mod:`.fit` fits, :mod:`.selection` chooses; this module only
composes them and collects what ``calibration.json`` reports.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np

from satmotor_ros.identify.base import (BaseFit, EMPTIED, emptied, fit_base, guessed,
                                        open_channels)
from satmotor_ros.identify.candidates import build_library, Candidate, Sampled
from satmotor_ros.identify.coverage import (coverage, COVERED, envelope, envelope_share, MOST,
                                            TAIL)
from satmotor_ros.identify.delay import DelayFit, fit_delay, kept, shifted
from satmotor_ros.identify.errors import DataError, IdentificationError
from satmotor_ros.identify.families import compare_families, family_specs, FamilyChoice
from satmotor_ros.identify.fit import check_identifiable, FitReport, MIN_POINTS, written
from satmotor_ros.identify.parts import loss_parts, LossParts, predict_flow
from satmotor_ros.identify.regions import describe, Space
from satmotor_ros.identify.sample_error import sample_errors, SampleErrors
from satmotor_ros.identify.selection import (at_bound, CrossValidatedSelector, Errors, Forward,
                                             Score, Selection)
from satmotor_ros.identify.steady import (extract_steady, looks_like_series, steady_windows,
                                          SteadyTolerance)
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import (averaged, averaged_sparse, dynamics_summary,
                                             first_order_at, Samples, transient_samples,
                                             TransientOptions)
from satmotor_ros.identify.valve_reach import valve_reach
from satmotor_ros.model import load_motor, MotorModel, MotorSpec
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import (coefficients_without, Effect, effect_name, kind_of,
                                        measured_range)
from satmotor_ros.model.revolutions import sampled_revolutions
from satmotor_ros.model.units import LPM
from satmotor_ros.model.viscosity import standard_law, ViscosityLaw

Mode = Literal['auto', 'points', 'series', 'transient']
MODES: tuple[Mode, ...] = ('auto', 'points', 'series', 'transient')
"""Rows are steady points, a series' steady windows, a series' every sample, or decide."""


@dataclass(frozen=True)
class Options:
    """How to calibrate: selection hyperparameters and the steady-state tolerances."""

    alpha: float = 0.05  # family-wise significance level [-]
    n_folds: int = 5  # cross-validation folds [-]
    min_gain: float = 0.05  # least cut of the cross-validated error [-]
    tie: float = 0.05  # near-tie margin of cross-validated error [-]
    max_effects: int = 4  # most effects the forward selection adds [-]
    mode: Mode = 'auto'  # see MODES
    seed: int = 0  # fold shuffle [-]
    compare_families: bool = True  # choose the model family first; False: the motor's, pinned
    steady: SteadyTolerance = field(default_factory=SteadyTolerance)
    transient: TransientOptions = field(default_factory=TransientOptions)


@dataclass(frozen=True)
class Calibration:
    """Everything a calibration found, for calibration.json, the YAML and the report."""

    liquid: str  # coefficient set calibrated
    spec: MotorSpec  # the motor the packaged values came from
    model: MotorModel  # the packaged model for the liquid
    table: BenchTable  # the steady points used (usable rows only)
    parts: LossParts  # model components at those points
    law: ViscosityLaw  # the liquid's viscosity-temperature law
    candidates: tuple[Candidate, ...]  # the library built for the data
    skipped: tuple[str, ...]  # candidates not offered, and why
    forward: Forward  # every step of the forward selection, the final model, the outliers
    baseline: FitReport  # the model refitted without an effect
    final: FitReport  # the model refitted with every effect found (or the baseline)
    error_packaged: Errors  # the packaged model, in sample
    error_before: Errors  # baseline, out of sample (outliers left out); a time series' over
    # every sample its rows hold (:mod:`.sample_error`)
    error_after: Errors  # with every effect, out of sample (outliers left out), as error_before
    rows: np.ndarray | None  # row of the table each point came from (None: a time series)
    family: FamilyChoice | None = None  # the families compared (None: pinned by the user)
    mode: Mode = 'points'  # how the rows were read (never 'auto')
    mode_reason: str = ''  # why, one sentence
    samples: Samples | None = None  # the time series' samples in 'transient' mode
    inflation: float = 1.0  # variance inflation of the final fit's residuals [-]
    n_folds: int = 5  # cross-validation folds asked for (at most one per point) [-]
    base: BaseFit | None = None  # the nonlinear coefficients the base fitted and kept
    coverage: dict[str, Any] = field(default_factory=dict)  # Rows.coverage
    delay: DelayFit | None = None  # the speed reading's delay (None: no time series)
    over: SampleErrors | None = None  # the residuals at every sample (None: steady rows)

    @property
    def selection(self) -> Selection:
        """Return the forward selection's first step (the first effect, or none)."""
        return self.forward.steps[0]

    @property
    def found(self) -> tuple[Score, ...]:
        """Return the effects found, in order."""
        return self.forward.found

    @property
    def chosen(self) -> Score | None:
        """Return the first effect found (its ``effect`` and ``label`` as fitted), or None."""
        return self.found[0] if self.found else None

    def effects(self) -> tuple[Effect, ...]:
        """Return the effects found at their fitted values, in order, with their fitted range."""
        data = {**self.table.channels, 'p_out': self.table.p_out, 'dp_i': self.parts.dp_i,
                'dp': self.parts.dp,
                'speed': self.parts.speed, 'flow': np.abs(self.parts.flow)}

        def fitted_on(effect: Effect) -> Effect:
            # an effect of the backward direction learns only from the rows that run backwards
            at = self.inliers & self.parts.reverse if kind_of(effect).reverse else self.inliers
            return measured_range(effect, {k: np.asarray(v)[at] for k, v in data.items()
                                           if np.shape(v) == at.shape})
        return tuple(fitted_on(e) for _, e in self.forward.final.fit.found())

    @property
    def inliers(self) -> np.ndarray:
        """Return which points are not outliers under the final model."""
        return ~self.forward.outliers

    def errors(self, score: Score) -> Errors:
        """Return a score's out-of-sample errors at the points (or samples) not outliers."""
        step = next((i for i, s in enumerate(self.found, 1) if s is score),
                    0 if score is self.selection.baseline else None)
        if self.over is not None and step is not None:
            return self.over.errors(step, self.forward.outliers)
        return self.row_errors(score)

    def row_errors(self, score: Score) -> Errors:
        """Return a score's out-of-sample errors over the rows the fit reads, outliers left out."""
        at = self.inliers
        return Errors.of(score.cv_error[at], self.parts.loss[at])

    def error_over(self) -> dict[str, Any]:
        """
        Say what the errors are over; a time series' also gives the figures over its rows.

        Returns
        -------
        dict
            ``error_over``: ``what`` ('samples', 'steady windows' or 'points'), ``n``
            (those the errors are over, outliers left out) and ``n_with_outliers``; in
            transient mode also ``error_over_bins``: the same four errors over the rows
            (the bins' means the fit reads), with ``n`` and ``n_with_outliers`` rows.

        """
        outliers = self.forward.outliers
        if self.over is None:
            what = 'steady windows' if self.mode == 'series' else 'points'
            return {'error_over': {'what': what, 'n': int(np.count_nonzero(~outliers)),
                                   'n_with_outliers': len(self.parts)}}
        loss, at = self.parts.loss, self.inliers
        before, after = self.selection.baseline.cv_error, self.forward.final.cv_error
        return {'error_over': {'what': 'samples', 'n': int(self.over.kept(outliers).sum()),
                               'n_with_outliers': int(self.over.kept().sum())},
                'error_over_bins': {
                    'n': int(at.sum()), 'n_with_outliers': len(self.parts),
                    'error_before': Errors.of(before[at], loss[at]).as_dict(),
                    'error_after': Errors.of(after[at], loss[at]).as_dict(),
                    'error_before_with_outliers': Errors.of(before, loss).as_dict(),
                    'error_after_with_outliers': Errors.of(after, loss).as_dict()}}

    def effect_rows(self) -> list[dict[str, Any]]:
        """
        Describe each effect found, in order, for ``calibration.json``.

        Returns
        -------
        list of dict
            effect, regressor, coefficient, ci95, unit, p_value and error_after (of
            its step); expression and exponents of a term; fitted_range (min and max
            of each quantity the effect reads over the inliers it was fitted on, SI);
            threshold of a threshold.

        """
        rows = []
        position = len(self.parts.components) + len(self.parts.nuisance)
        for score, effect in zip(self.found, self.effects()):
            candidate = score.added
            value, ci95 = _coefficient_interval(self.final, position, candidate)
            row: dict[str, Any] = {
                'effect': effect.name if candidate.shape else candidate.effect,
                'name': effect_name(effect),
                'regressor': effect.regressor if candidate.shape else candidate.regressor,
                'coefficient': written(value), 'ci95': [written(v) for v in ci95],
                'unit': candidate.unit, 'p_value': float(f'{score.p_value:.3g}'),
                'error_after': self.errors(score).as_dict(), 'direction': effect.direction}
            if effect.kind == 'term':
                row['expression'] = effect.suffix
                row['exponents'] = {k: written(effect.option(k)) for k in ('dp', 'n')}
                row['exponents_ci95'] = {
                    s_.name.split()[0]: [written(v) for v in self.final.ci95[position + 1 + j]]
                    for j, s_ in enumerate(candidate.shape)}
            if effect.fitted_range:
                row['fitted_range'] = {q: [written(lo), written(hi)]
                                       for q, lo, hi in effect.fitted_range}
            note = one_sided(candidate, effect)
            if note:
                row['direction_note'] = note
            if effect.kind == 'threshold':
                row['threshold'] = {'regressor': 'dp', 'value': written(effect.reference),
                                    'unit': 'Pa',
                                    'ci95': [written(v) for v in self.final.ci95[position + 1]]}
                row['exponent'] = written(effect.option('exponent'))
                if len(candidate.shape) > 2 and self.samples is not None:  # read in time
                    row['response_time'] = _response(effect, self.final.ci95[position + 3])
            row.update(valve_reach(self, effect))  # a valve's law at the top of the drop
            rows.append(row)
            position += 1 + len(candidate.shape)
        return rows

    def outlier_rows(self) -> list[dict[str, Any]]:
        """Return each outlier: row (or time), measured flow and residual [l/min]."""
        out = []
        residual = self.parts.flow - self.forward.final.fit.predict(self.parts)
        time = self.table.channels.get('time')
        for i in np.flatnonzero(self.forward.outliers):
            row: dict[str, Any] = {}
            if self.rows is not None:
                row['row'] = int(self.rows[i])
            if time is not None:
                row['time'] = written(time[i])
            row.update(flow_lpm=written(self.parts.flow[i] / LPM),
                       residual_lpm=written(residual[i] / LPM),
                       noise_sd=written(abs(residual[i]) / self.forward.sigma[i]))
            out.append(row)
        return out + self.spike_rows()

    def spike_rows(self) -> list[dict[str, Any]]:
        """
        Return each spike of a reading (a time series' only).

        A flow's spike is a sample left out; a speed's or pressure's is a reading replaced
        by its neighbours' fit.

        Returns
        -------
        list of dict
            time, sample (its index in the time-ordered data), flow_lpm, reading (the
            reading that spiked: flow, speed, p_in or p_out), departure (its departure from
            its neighbours' local fit, in SI: m^3/s, rad/s or Pa), residual_lpm (that
            departure of a flow reading) and noise_sd (the departure in robust standard
            deviations of all that reading's departures), one per spiked reading.

        """
        s = self.samples
        if s is None or not s.spikes.size:
            return []
        time, flow = s.samples.channels['time'], s.samples.flow
        return [{'time': written(time[j]), 'sample': int(j), 'flow_lpm': written(flow[j] / LPM),
                 'reading': name, 'departure': written(d),
                 'residual_lpm': written(d / LPM) if name == 'flow' else None,
                 'noise_sd': written(abs(d) / sd)}
                for j, name, d, sd in zip(s.spikes, s.spike_channel, s.spike_size,
                                          s.spike_scale)]

    def missed_regions(self) -> list[dict[str, Any]]:
        """
        Describe each region the final model misses (:mod:`.regions`), largest miss first.

        Returns
        -------
        list of dict
            kind, rows, direction, dp_mpa, speed_rpm, time_s (a time series) and
            mean_residual_lpm (measured minus predicted flow, as read), per region.

        """
        p = self.parts
        residual = (p.flow - self.forward.final.fit.predict(p)) * p.sign
        space = Space(p.sign * p.dp, p.rotation * p.speed, self.table.channels.get('time'))
        found = [describe(kind, rows, residual, space) for kind, rows in self.forward.missed]
        # the largest miss first: a few rows far off before many rows a little off
        return sorted(found, key=lambda r: -r['rows'] * abs(r['mean_residual_lpm']))

    def summary(self) -> dict[str, Any]:
        """
        Build the calibration.json object, with exactly the DESIGN.md fields.

        Returns
        -------
        dict
            liquid, n_points, effect, name, direction, regressor, coefficient, ci95,
            unit, error_before, error_after, effects, outliers, candidates,
            family_comparison, the transient mode's fields, and ``warnings``
            when the data are implausible or a fitted value is on a bound. The
            top-level effect fields are those of the first effect; with no
            effect, regressor, coefficient, ci95 and unit are null.

        """
        effects = self.effect_rows()
        first = effects[0] if effects else {}
        ranked = [self.selection.baseline, *self.selection.ranking]
        ranked.sort(key=lambda s: s.cv_rmse)
        return {
            'liquid': self.liquid, 'family': self.model.family.name,
            'n_points': len(self.parts),
            'effect': first.get('effect', 'none'), 'name': first.get('name', 'none'),
            'direction': first.get('direction'), 'regressor': first.get('regressor'),
            'coefficient': first.get('coefficient'), 'ci95': first.get('ci95'),
            'unit': first.get('unit'),
            'error_before': self.error_before.as_dict(),
            'error_after': self.error_after.as_dict(),
            **self.with_outliers(),
            **self.error_over(),
            'coverage': self.coverage,
            'effects': effects, 'outliers': self.outlier_rows(),
            'missed_regions': self.missed_regions(),
            'candidates': [
                {'effect': s.effect, 'regressor': s.candidate.regressor if s.candidate else None,
                 'cv_rmse_lpm': written(s.cv_rmse / LPM)} for s in ranked],
            'family_comparison': self.family_comparison(),
            **self.mode_fields(),
            **self.warnings(),
        }

    def with_outliers(self) -> dict[str, dict[str, float]]:
        """
        Return the errors before and after over every row, outliers included.

        Returns
        -------
        dict
            ``error_before_with_outliers`` and ``error_after_with_outliers``: out of
            sample as ``error_before`` and ``error_after``, over every row (every
            steady point or window; a time series' every sample) instead of those that
            are not outliers (the samples of an outlier row included).

        """
        if self.over is not None:
            last = len(self.found)
            return {'error_before_with_outliers': self.over.errors(0).as_dict(),
                    'error_after_with_outliers': self.over.errors(last).as_dict()}
        loss = self.parts.loss
        return {'error_before_with_outliers':
                Errors.of(self.selection.baseline.cv_error, loss).as_dict(),
                'error_after_with_outliers':
                Errors.of(self.forward.final.cv_error, loss).as_dict()}

    def warnings(self) -> dict[str, list[str]]:
        """
        Return ``{'warnings': [...]}`` when something is wrong with the result (else nothing).

        Returns
        -------
        dict
            The warnings: the data are implausible (beginning :data:`IMPLAUSIBLE`), the
            channel drop left out most of a direction (:data:`~.base.EMPTIED`), a
            candidate that fitted better than the ones chosen from was refused because
            its fit ended on a bound, or a factor of the final fit ended on a bound (both
            beginning :data:`AT_BOUND`): a value on a bound is not an estimate.

        """
        found = [note for note in self.table.notes if note.startswith((IMPLAUSIBLE, EMPTIED))]
        found += [f'{AT_BOUND}: step {i}: {at_bound(score)}: the data ask for a value beyond '
                  'its range, so the fit gives the bound, not an estimate; refused'
                  for i, step in enumerate(self.forward.steps, 1) for score in step.refused]
        found += [f'{AT_BOUND}: {name} ends on its bound {bound:.4g} in the final fit: not an '
                  'estimate, and its interval is not valid; the packaged value is far from '
                  'what these data ask for' for name, bound in self.forward.final.fit.pinned()]
        return {'warnings': found} if found else {}

    def family_comparison(self) -> dict[str, Any]:
        """
        Return how the family was chosen: the verdict, each family's error, any near tie.

        ``base`` says which nonlinear coefficients the base fitted and kept (:mod:`.base`).
        """
        base = {'base': self.base.as_dict()} if self.base is not None else {}
        if self.family is None:
            return {'verdict': f'{self.model.family.name} pinned by the user (--family)',
                    'n_points': None, 'families': [], **base}
        return {'verdict': self.family.verdict, 'n_points': self.family.n_points,
                'families': self.family.as_list(),
                'near_tie': self.family.tie.as_dict() if self.family.tie else None, **base}

    def mode_fields(self) -> dict[str, Any]:
        """
        Build calibration.json's fields on how the rows were read.

        Returns
        -------
        dict
            ``mode`` and ``mode_reason`` always; for all samples also ``n_samples``,
            ``bin_size`` (sample steps per row), ``variance_inflation`` and ``dynamics``
            (each transient term's coefficient with its ci95, unit and meaning,
            :func:`~satmotor_ros.identify.transient.dynamics_summary`).

        """
        delay = {'speed_delay': self.delay.as_dict()} if self.delay is not None else {}
        if self.samples is None:
            return {'mode': self.mode, 'mode_reason': self.mode_reason, **delay}
        return {'mode': self.mode, 'mode_reason': self.mode_reason, **delay,
                'n_samples': self.samples.n_samples, 'bin_size': self.samples.bin_size,
                'variance_inflation': written(self.inflation),
                'dynamics': dynamics_summary(self.final, self.samples)}


def one_sided(candidate: Candidate, effect: Effect) -> str:
    """
    Say when an effect fitted on both sides of dp acts on one only, since the data hold one.

    Parameters
    ----------
    candidate : Candidate
        The candidate fitted, [-]
    effect : Effect
        The effect found, [-]

    Returns
    -------
    str
        One sentence, or '' when the directions agree.

    """
    if candidate.direction != 'both' or effect.direction == 'both':
        return ''
    other = 'positive' if effect.direction == 'negative' else 'negative'
    return (f'{effect.key}: fitted on both signs of dp, it acts on the {effect.direction} side '
            f'only, because the data hold no {other} drop beyond its crack: whether it also '
            f'opens the {other} way, these data cannot say')


def _coefficient_interval(report: FitReport, position: int,
                          candidate: Candidate) -> tuple[float, tuple[float, float]]:
    """Return an effect's coefficient as written and its 95 % interval (delta method)."""
    size = 1 + len(candidate.shape)
    values = report.values[position:position + size]
    if not candidate.shape:
        return float(values[0]), (float(report.ci95[position, 0]), float(report.ci95[position, 1]))
    cov = report.covariance[position:position + size, position:position + size]
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    t = (report.ci95[position, 1] - values[0]) / max(sd[0], 1e-300)

    def coefficient(x: np.ndarray) -> float:
        return candidate.as_effect(*x).coefficient

    grad = np.empty(size)
    for j in range(size):
        h = 1e-6 * max(abs(values[j]), sd[j], 1e-12)
        step = np.zeros(size)
        step[j] = h
        grad[j] = (coefficient(values + step) - coefficient(values - step)) / (2 * h)
    value = coefficient(values)
    if candidate.bounds[0] >= 0.0 and value > 0.0:
        # k >= 0 and, for a fitted form, k = size / x^e: on the log scale the exponent enters
        # linearly, and the interval stays within the bound (a linear one spanned 0)
        spread = min(float(t * np.sqrt(max(float(grad @ cov @ grad), 0.0))) / value, 700.0)
        return value, (value * float(np.exp(-spread)), value * float(np.exp(spread)))
    half = float(t * np.sqrt(max(float(grad @ cov @ grad), 0.0)))
    return value, (value - half, value + half)


def is_series(table: BenchTable) -> bool:
    """Return whether the rows are a time series' samples (a bag, or rows that look so)."""
    return table.time_series or looks_like_series(table)


def steady_points(table: BenchTable, mode: Mode = 'auto',
                  tol: SteadyTolerance | None = None) -> BenchTable:
    """
    Turn a table into steady operating points.

    In ``'auto'`` mode a table is a time series when it has a time column and
    successive rows differ by far less than the operating range
    (:func:`~satmotor_ros.identify.steady.looks_like_series`); its steady
    windows then become the points. Otherwise each row is a point.

    Parameters
    ----------
    table : BenchTable
        Rows as read, [-]
    mode : {'auto', 'points', 'series'}
        How to read the rows, [-]
    tol : SteadyTolerance, optional
        Steady-state tolerances, [-]

    Returns
    -------
    BenchTable
        Steady points, sorted by time when there is a time column.

    """
    if mode not in ('auto', 'points', 'series'):
        msg = f"mode = {mode!r}: steady points come from 'auto', 'points' or 'series'"
        raise DataError(msg)
    if mode == 'series' or (mode == 'auto' and is_series(table)):
        return extract_steady(table, tol)
    if 'time' in table.channels:
        order = np.argsort(table.channels['time'], kind='stable')
        table = table.select(order)
        if 'revolutions' not in table.channels:
            channels = dict(table.channels)
            channels['revolutions'] = sampled_revolutions(table.speed, table.channels['time'])
            table = BenchTable(table.speed, table.flow, table.p_in, table.p_out, channels,
                               {**table.units, 'revolutions': 'rev'}, table.source, False,
                               table.notes + ('revolutions integrated from speed between '
                                              'the rows (trapezoid)',))
    return table


@dataclass(frozen=True)
class Rows:
    """The rows a calibration fits, and how they were read."""

    table: BenchTable  # steady points, or a time series' bins
    parts: LossParts  # the model's components at them
    source_rows: np.ndarray | None  # row of the data each came from (None: a time series)
    mode: Mode  # 'points', 'series' or 'transient'
    reason: str  # why that mode, one sentence
    samples: Samples | None = None  # the time series' samples in 'transient' mode
    coverage: dict[str, Any] = field(default_factory=dict)  # coverage.coverage() of the rows


def _steady_rows(model: MotorModel, table: BenchTable, points: BenchTable, mode: Mode,
                 reason: str, check: bool, used: int | None = None) -> Rows:
    rows = _source_rows(table, points)
    parts, usable = loss_parts(model, points)
    if not usable.all():
        points = points.select(usable, f'left out {int((~usable).sum())} points outside the '
                                       'model (no flow the model can give, or a chamber '
                                       'drop out of range)')
        rows = None if rows is None else rows[usable]
    if check:
        check_identifiable(parts)
    dp = points.p_in - points.p_out
    return Rows(points, parts, rows, mode, reason,
                coverage=coverage(len(points) if used is None else used, len(table), dp,
                                  points.speed))


def _transient_rows(model: MotorModel, table: BenchTable, options: Options,
                    reason: str, check: bool) -> Rows:
    samples = transient_samples(model, table, options.transient)
    if len(samples.parts) < MIN_POINTS:
        msg = (f'too few rows: {samples.n_samples} of {len(table)} samples are '
               f'usable, {len(samples.parts)} rows of {samples.bin_size} sample steps, need >= '
               f'{MIN_POINTS}; a sample needs finite readings and a chamber drop within the '
               "model's limit, and a row needs neighbouring samples without a gap")
        raise IdentificationError(msg)
    if check:
        check_identifiable(samples.parts)
    raw = samples.samples
    at = samples.in_bins
    return Rows(samples.table, samples.parts, None, 'transient', reason, samples,
                coverage(samples.n_samples, len(table), (raw.p_in - raw.p_out)[at],
                         raw.speed[at]))


def read_rows(model: MotorModel, table: BenchTable, options: Options,
              check: bool = True) -> Rows:
    """
    Read the rows as the mode says; in ``'auto'``, a time series' every sample by default.

    In ``'auto'`` mode a time series is read as its steady windows only when there are
    at least ``options.transient.min_steady`` of them, they hold most of its samples
    (:data:`~satmotor_ros.identify.coverage.MOST`) and span its operating envelope
    (:data:`~satmotor_ros.identify.coverage.COVERED` of the range of |dp| and of |n| in
    each direction it runs in); otherwise every usable sample is used, with the transient
    terms. Effects that live between the windows (a valve that opens during the fast
    moves) are thus never hidden by the choice of rows.

    Parameters
    ----------
    model : MotorModel
        The model evaluated at the rows, [-]
    table : BenchTable
        The data as read, [-]
    options : Options
        Its ``mode``, ``steady`` and ``transient`` settings, [-]
    check : bool
        Refuse rows that cannot determine the fitted coefficients
        (:func:`~satmotor_ros.identify.fit.check_identifiable`); False to evaluate
        a model without fitting it, [-]

    Returns
    -------
    Rows
        The rows, the model's components there, the mode and why, and the coverage.

    """
    mode = options.mode
    if mode not in MODES:
        msg = f'mode = {mode!r}: use one of {", ".join(MODES)}'
        raise DataError(msg)
    if mode == 'transient':
        return _transient_rows(model, table, options, 'asked for (--mode transient)', check)
    if mode != 'auto' or not is_series(table):
        why = {'points': 'asked for (--mode points)', 'series': 'asked for (--mode series)',
               'auto': 'the rows are not a time series: each is a steady point'}[mode]
        if mode == 'series' or (mode == 'auto' and is_series(table)):
            points, used = steady_windows(table, options.steady)
            return _steady_rows(model, table, points, 'series', why, check, used)
        points = steady_points(table, mode, options.steady)
        return _steady_rows(model, table, points, 'points', why, check)
    least = max(options.transient.min_steady, MIN_POINTS)
    try:
        points, used = steady_windows(table, options.steady)
        rows = _steady_rows(model, table, points, 'series', '', check, used)
    except (DataError, IdentificationError) as err:
        why = f'no usable steady windows ({err})'
    else:
        why = _windows_verdict(table, rows, least)
        if not why:
            share = rows.coverage['envelope_share']
            return replace(rows, reason=(
                f'a time series whose {len(rows.parts)} steady windows (>= {least}) hold '
                f'{100 * rows.coverage["fraction"]:.0f} % of the samples (>= '
                f'{100 * MOST:.0f} %) and span {100 * share:.0f} % of its operating envelope '
                f'(>= {100 * COVERED:.0f} %)'))
    return _transient_rows(model, table, options,
                           f'a time series of {len(table)} samples whose {why}: every sample '
                           'used, with the transient terms', check)


def _windows_verdict(table: BenchTable, rows: Rows, least: int) -> str:
    """Say why the steady windows do not stand for the recording ('' when they do)."""
    dp = table.p_in - table.p_out
    recording = envelope(dp, table.speed, TAIL)
    share = envelope_share(rows.coverage['envelope'], recording, len(table))
    rows.coverage['envelope_share'] = float(f'{share:.4g}')
    fraction = rows.coverage['fraction']
    held = (f'{len(rows.parts)} steady windows hold {100 * fraction:.0f} % of the samples and '
            f'span {100 * share:.0f} % of its operating envelope')
    if len(rows.parts) < least:
        return f'{held} (need >= {least} windows)'
    if fraction < MOST:
        return f'{held} (need >= {100 * MOST:.0f} % of the samples)'
    if share < COVERED:
        return f'{held} (need >= {100 * COVERED:.0f} % of the envelope in each direction)'
    return ''


def _without_effects(spec: MotorSpec, liquid: str,
                     table: BenchTable) -> tuple[MotorSpec, BenchTable]:
    """Start from a set's coefficients without its effects: the calibration looks anew."""
    fitted = spec.sets[liquid]
    if not fitted.effects:
        return spec, table
    coef = coefficients_without(fitted.effects, fitted.coefficients)  # what they set, too
    bare = replace(fitted, coefficients=coef, effects=())
    names = ', '.join(e.name for e in fitted.effects)
    note = f'{spec.source}: its effects ({names}) were left out; the calibration looks anew'
    return (replace(spec, sets={**spec.sets, liquid: bare}),
            replace(table, notes=table.notes + (note,)))


def calibrate(table: BenchTable, liquid: str = 'oil', spec: MotorSpec | None = None,
              options: Options | None = None) -> Calibration:
    """
    Calibrate the model on a bench table and look for one missing effect.

    Parameters
    ----------
    table : BenchTable
        Steady points or a time series, [-]
    liquid : str
        Coefficient set to calibrate (``'oil'`` or ``'water'``), [-]
    spec : MotorSpec, optional
        Motor whose packaged values start the fit; the SM-0,75/25 when omitted, [-]
    options : Options, optional
        Selection and steady-state settings, [-]

    Returns
    -------
    Calibration
        The result.

    Raises
    ------
    IdentificationError
        If the data cannot determine the coefficients (the message says why).

    """
    options = options or Options()
    spec = spec or load_motor()
    if liquid not in spec.sets:
        msg = f'liquid {liquid!r} is not a coefficient set of {spec.name} ({", ".join(spec.sets)})'
        raise IdentificationError(msg)
    spec, table = _without_effects(spec, liquid, table)
    table, delay, first_read = _with_delay(spec, liquid, table, options)
    spec, model, read, choice = _family_and_rows(spec, liquid, table, options, first_read)
    spec, model, read, base = _with_base(spec, liquid, table, options, read, choice)
    points, parts, rows, samples = read.table, read.parts, read.source_rows, read.samples
    note = implausible(parts)
    if note:
        points = replace(points, notes=points.notes + (note,))
    law = standard_law(model.liquid, liquid)
    channels = {**points.channels, 'p_in': points.p_in, 'p_out': points.p_out}
    candidates, skipped = build_library(parts, channels, law, model.family.name,
                                        _sampled(samples))
    selector = _selector(options, points, samples)
    forward = selector.select(parts, candidates, points.channels.get('time'))
    first = forward.steps[0]
    packaged_error = parts.flow - predict_flow(parts, np.ones(len(parts.components)))
    at = ~forward.outliers
    if int(at.sum()) < MIN_POINTS:
        msg = (f'{int((~at).sum())} of {len(at)} points are outliers of every model: check the '
               'units and the column mapping (e.g. a speed in rpm labelled rad/s)')
        raise IdentificationError(msg)
    index = np.flatnonzero(at)
    inflation = selector.inflation(parts, forward.final.fit, forward.sigma, index)
    base_inflation = selector.inflation(parts, first.baseline.fit, forward.sigma, index)
    errors = (Errors.of(packaged_error[at], parts.loss[at]),
              Errors.of(first.baseline.cv_error[at], parts.loss[at]),
              Errors.of(forward.final.cv_error[at], parts.loss[at]))
    over = None
    if samples is not None:  # the figures over every sample, not over the bins (DESIGN.md)
        over = sample_errors(model, samples, parts, (first.baseline, *forward.found))
        last = len(forward.found)
        errors = (over.errors(-1, forward.outliers), over.errors(0, forward.outliers),
                  over.errors(last, forward.outliers))
    return Calibration(liquid, spec, model, points, parts, law, tuple(candidates),
                       tuple(skipped), forward, first.baseline.fit.report(base_inflation),
                       forward.final.fit.report(inflation), *errors, rows, choice,
                       read.mode, read.reason, samples, inflation,
                       options.n_folds, base, read.coverage, delay, over)


def _with_delay(spec: MotorSpec, liquid: str, table: BenchTable,
                options: Options) -> tuple[BenchTable, DelayFit | None, Rows | None]:
    """
    Fit the delay of the speed reading behind the flow reading (:mod:`.delay`) on a series.

    Only a time series read with every sample has one to fit; steady points, and a series
    read as its steady windows, keep 0. A fitted delay shifts the speed of every sample, and
    the rows are read again from the shifted samples (in the mode and for the reason the
    first reading gave).

    Returns
    -------
    BenchTable
        The samples, the speed shifted by a fitted delay.
    DelayFit or None
        The delay fitted or kept (None: the rows are no time series).
    Rows or None
        The rows read, for the family comparison (None: to be read).

    """
    steady = options.mode in ('points', 'series')
    if 'time' not in table.channels or not is_series(table) or steady:
        return table, None, None
    try:
        read = read_rows(_open(spec, liquid), table, options)
    except (DataError, IdentificationError):
        return table, kept('the rows could not be read at no delay'), None
    if read.samples is None:
        return table, kept('the rows are steady windows, where the readings do not move'), read
    delay = fit_delay(read.samples, _open(spec, liquid), options.transient.gap)
    if not delay.fitted:
        return table, delay, read
    table, lost = shifted(table, delay.seconds, options.transient.gap)
    again = read_rows(_open(spec, liquid), table, replace(options, mode=read.mode))
    return table, replace(delay, unserved=lost), replace(
        again, reason=read.reason, coverage={**read.coverage, **again.coverage})


def _with_base(spec: MotorSpec, liquid: str, table: BenchTable, options: Options, read: Rows,
               choice: FamilyChoice | None) -> tuple[MotorSpec, MotorModel, Rows, BaseFit]:
    """
    Fit the base's channel drop where the data pin it (:mod:`.base`); re-read the rows.

    The rows of a guessed motor were read without a channel drop (:func:`.open_channels`);
    they are read again with the drop fitted or kept, and the report and stderr warn
    when that leaves out most of one direction's samples.
    """
    base = choice.bases.get(choice.chosen) if choice is not None else None
    if base is None:
        base = fit_base(spec, liquid, read.table, read.parts.nuisance)
    model = MotorModel.from_spec(base.spec, liquid)
    if base.changed or guessed(spec):
        again = read_rows(model, table, replace(options, mode=read.mode))
        read = replace(again, reason=read.reason, coverage={**read.coverage, **again.coverage})
    note = emptied(model, table, base)
    if note:
        read = replace(read, table=replace(read.table, notes=read.table.notes + (note,)))
    return base.spec, model, read, base


def _open(spec: MotorSpec, liquid: str) -> MotorModel:
    """Return the model the rows are read with: a guessed channel drop left out (:mod:`.base`)."""
    return MotorModel.from_spec(open_channels(spec, liquid), liquid)


def _response(effect: Effect, ci95: FloatArray) -> dict[str, Any]:
    """Return a valve's response time [s] with its interval (0: the law itself)."""
    seconds = effect.option('response_time', 0.0)
    return {'seconds': written(seconds), 'unit': 's',
            'ci95': [written(max(float(v), 0.0)) if seconds else 0.0 for v in ci95],
            'note': ('the law itself: no lag the data can tell at this sampling'
                     if seconds == 0.0 else 'its flow follows the law through a first-order lag')}


def _sampled(samples: Samples | None) -> Sampled | None:
    """Return the samples the rows average, as the candidates read them (None: steady rows)."""
    if samples is None:
        return None
    raw = samples.samples
    dp = np.where(samples.usable, raw.p_in - raw.p_out, np.nan)
    first = samples.stretch_starts
    return Sampled(dp, lambda x: averaged(samples, x), averaged_sparse(samples),
                   lambda at, x, tau: first_order_at(at, x, first, samples.step, tau),
                   samples.step)


def _selector(options: Options, points: BenchTable,
              samples: Samples | None) -> CrossValidatedSelector:
    return CrossValidatedSelector(options.alpha, options.n_folds, options.min_gain, options.tie,
                                  'time' in points.channels, options.seed, options.max_effects,
                                  samples.guard if samples else 0, samples is not None,
                                  _block(samples))


BLOCK_SECONDS = 2.0
"""Length of a cross-validation block of a time series' rows, [s]: a few correlation
times of the residuals (a transient's 0.05-0.5 s), short against the recording."""


def _block(samples: Samples | None) -> int:
    """Return the rows of a cross-validation block of a time series (0: steady points)."""
    if samples is None:
        return 0
    seconds = samples.bin_size * samples.step
    return max(2 * samples.guard + 1, int(np.ceil(BLOCK_SECONDS / seconds)) if seconds > 0 else 1)


def _family_and_rows(spec: MotorSpec, liquid: str, table: BenchTable, options: Options,
                     first: Rows | None = None
                     ) -> tuple[MotorSpec, MotorModel, Rows, FamilyChoice | None]:
    """Read the rows with the motor's family (or take `first`), compare the families there."""
    model = MotorModel.from_spec(spec, liquid)
    if not options.compare_families:
        return spec, model, first or read_rows(_open(spec, liquid), table, options), None
    read: Rows | None = None
    try:
        read = first or read_rows(_open(spec, liquid), table, options)
        compared = read.table  # in transient mode the bins' means: the steady maps compared
    except IdentificationError as err:  # the motor's own family cannot use the data; another may
        steady: Mode = options.mode if options.mode != 'transient' else 'auto'
        try:
            compared = steady_points(table, steady, options.steady)
        except DataError:
            raise err from None
    samples = read.samples if read is not None else None
    specs = family_specs(spec, spec.source == load_motor().source)
    # on a transient recording's bins every family fits its steady map with the transient terms
    choice = compare_families(compared, liquid, specs,
                              lambda: _selector(options, compared, samples), options.min_gain,
                              read.parts.nuisance if read is not None else None)
    if read is not None and choice.chosen == model.family.name:
        return spec, model, read, choice
    spec = specs[choice.chosen]
    model = MotorModel.from_spec(spec, liquid)
    if read is None:
        return spec, model, read_rows(_open(spec, liquid), table, options), choice
    again = read_rows(_open(spec, liquid), table, replace(options, mode=read.mode))
    # why the mode: as decided on the first reading
    return spec, model, replace(again, reason=read.reason,
                                coverage={**read.coverage, **again.coverage}), choice


IMPLAUSIBLE = 'implausible data'
"""How the note on data no motor can produce begins (the report and stderr give it)."""

AT_BOUND = 'at a bound'
"""How a warning of a fitted value on a bound of its range begins (not an estimate)."""


def implausible(parts: LossParts) -> str | None:
    """
    Say whether the volumetric losses exceed the flow itself at more than a tenth of the points.

    Q_vl = Q - q_t n is larger in magnitude than Q only where q_t n > 2 Q: a motor turning
    twice as fast as its flow allows. That is a wrong unit (a speed in rpm labelled
    [rad/s]), a wrong displacement or a wrong flow unit, not an effect to fit.

    Parameters
    ----------
    parts : LossParts
        The model's components at the points, [-]

    Returns
    -------
    str or None
        The note (beginning :data:`IMPLAUSIBLE`), or None when the data are plausible.

    """
    over = np.abs(parts.loss) > np.abs(parts.flow)
    if over.sum() <= 0.1 * over.size:
        return None
    ratio = float(np.median(np.abs(parts.loss) / np.abs(parts.flow)))
    return (f'{IMPLAUSIBLE}: the volumetric losses Q - q_t n are larger than the flow itself '
            f'at {int(over.sum())} of {over.size} points (median |Q_vl|/Q = {ratio:.3g}); '
            'check the units of speed and flow (a speed in rpm labelled [rad/s]?) and the '
            'displacement')


def _source_rows(table: BenchTable, points: BenchTable) -> np.ndarray | None:
    """Return the table row of each point (sorted by time as :func:`steady_points` does)."""
    if len(points) != len(table) or table.time_series:
        return None
    if 'time' in table.channels:
        return np.argsort(table.channels['time'], kind='stable')
    return np.arange(len(table))


__all__ = ['AT_BOUND', 'Calibration', 'IdentificationError', 'MODES', 'Mode', 'Options', 'Rows',
           'calibrate', 'one_sided', 'read_rows', 'steady_points']
