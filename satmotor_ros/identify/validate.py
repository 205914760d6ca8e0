# SPDX-License-Identifier: Apache-2.0
"""
Validation: the error of a given model on new data, without refitting.

The points are the calibration's (:func:`~satmotor_ros.identify.pipeline.steady_points`,
:func:`~satmotor_ros.identify.parts.loss_parts`) and the error is the
calibration's, of the volumetric losses Q_vl = Q - q_t n
(:meth:`~satmotor_ros.identify.selection.Errors.of`); the prediction is the
model's own, effects and instruments included
(:class:`~satmotor_ros.identify.effects.CalibratedModel`), at the chamber drop
the calibration uses. A calibration validated on its own data therefore gives
its in-sample error. Nothing is fitted, so no cross-validation is needed.
Points the model flags invalid are left out; points it flags EXTRAPOLATED
(outside its validated range, or an effect evaluated outside the data it was
fitted on) are kept and counted.

On a time series read with every sample the error is over every sample the rows hold
(:mod:`.sample_error`), the error over the rows' means beside it (``error_over_bins``);
the bench's transient terms (line
compliance, sensor lags) are the calibration's own, read from the motor file's
``dynamics`` and applied unchanged, so the headline error stays out of sample;
a file without them gives the error without transient terms as the headline and
the error after fitting them on the data validated only as a second figure,
labelled in sample.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from satmotor_ros.identify.coverage import outside
from satmotor_ros.identify.delay import shifted
from satmotor_ros.identify.effects import CalibratedModel
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.parts import loss_parts, LossParts
from satmotor_ros.identify.pipeline import is_series, Mode, Options, read_rows
from satmotor_ros.identify.predicted import bare, predicted
from satmotor_ros.identify.sample_error import sample_data, SampleData
from satmotor_ros.identify.selection import Errors
from satmotor_ros.identify.steady import SteadyTolerance
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import averaged, parts_at, Samples, TransientOptions
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray


@dataclass(frozen=True)
class Validation:
    """A model held against data: the points, its prediction and its errors."""

    liquid: str  # coefficient set validated
    model: MotorModel  # the model as given, effects included
    table: BenchTable  # the points used (usable rows only)
    parts: LossParts  # measured flow, speed, drops and Q_vl at those points
    residual: FloatArray  # measured minus predicted Q_vl [m^3/s]
    error: Errors  # the residual summarised as calibration.json does
    effects: tuple[dict[str, Any], ...]  # the model's effects as loaded
    invalid: int = 0  # points (rows) left out because the model flags them invalid [-]
    extrapolated: int = 0  # points (rows) kept that the model flags EXTRAPOLATED [-]
    coverage: dict[str, Any] = field(default_factory=dict)  # the rows' Rows.coverage
    outside: dict[str, Any] | None = None  # samples outside the calibrated envelope
    flagged: np.ndarray | None = None  # which of the points are flagged EXTRAPOLATED [-]
    transient: dict[str, Any] | None = None  # how the transient terms entered `error`
    in_sample: Errors | None = None  # the error after fitting them on these data (2nd figure)
    delay: dict[str, Any] | None = None  # the calibration's speed delay, as applied
    over_bins: dict[str, Any] | None = None  # a time series': the error over its rows' means

    def describe_effects(self) -> str:
        """Return the effects' names, comma-separated, or ``'none'``."""
        return ', '.join(e['name'] for e in self.effects) or 'none'

    def summary(self) -> dict[str, Any]:
        """
        Build the validation.json object (DESIGN.md, "Validation output").

        Returns
        -------
        dict
            n_points and error first (over every sample on a time series read with every
            sample; ``error_over`` says what over, and ``error_over_bins`` gives the error
            over the rows' means beside it), then the liquid, motor, effects, source,
            n_flagged (every point or row the model flags), n_invalid (those left
            out: the model flags them invalid) and n_extrapolated (those kept but
            flagged EXTRAPOLATED: outside the validated range or an effect's fitted
            range), coverage (DESIGN.md) and outside_calibrated_envelope (the samples
            used that lie outside the envelope the model was calibrated on: samples,
            of, share; null figures when the motor file holds no envelope); on a time
            series read with every sample also transient_terms (how they entered
            ``error``: the calibration's, or none) and error_transient_fitted_in_sample
            (the error after fitting them on these data: in sample, not the headline), and
            speed_delay when the motor file's delay of the speed reading was applied.

        """
        transient = {} if self.transient is None else {'transient_terms': self.transient}
        if self.delay is not None:
            transient['speed_delay'] = self.delay
        if self.in_sample is not None:
            transient['error_transient_fitted_in_sample'] = self.in_sample.as_dict()
        over = {'error_over': {'what': 'samples' if self.over_bins else 'points',
                               'n': len(self.parts)}}
        if self.over_bins is not None:
            over['error_over_bins'] = self.over_bins
        return {'n_points': len(self.parts), 'error': self.error.as_dict(), **over, **transient,
                'liquid': self.liquid, 'motor': self.model.name,
                'effects': list(self.effects), 'data': self.table.source,
                'n_flagged': self.invalid + self.extrapolated, 'n_invalid': self.invalid,
                'n_extrapolated': self.extrapolated, 'coverage': self.coverage,
                'outside_calibrated_envelope': self.outside or {
                    'samples': None, 'of': None, 'share': None,
                    'note': 'the motor file holds no calibrated envelope (coverage)'}}


def validate(table: BenchTable, model: MotorModel, liquid: str, mode: Mode = 'auto',
             tol: SteadyTolerance | None = None,
             calibrated: dict[str, Any] | None = None,
             dynamics: dict[str, float] | None = None,
             speed_delay: float | None = None) -> Validation:
    """
    Compute the error of `model` on `table` without fitting anything.

    Parameters
    ----------
    table : BenchTable
        Steady points or a time series, [-]
    model : MotorModel
        The model to hold against the data (a calibrated file's, effects and
        all), [-]
    liquid : str
        Its coefficient set, for the report, [-]
    mode : {'auto', 'points', 'series', 'transient'}
        How to read the rows, as for a calibration, [-]
    tol : SteadyTolerance, optional
        Steady-state tolerances, [-]
    calibrated : dict, optional
        The envelope the model was calibrated on
        (:attr:`~satmotor_ros.identify.calibrated.Calibrated.envelope`); every sample of
        `table` is counted against it, [-]
    dynamics : dict, optional
        The calibration's transient terms
        (:attr:`~satmotor_ros.identify.calibrated.Calibrated.dynamics`), applied unchanged
        when the rows are samples; without them the headline error has no transient terms,
        [-]
    speed_delay : float, optional
        The calibration's delay of the speed reading behind the flow reading
        (:attr:`~satmotor_ros.identify.calibrated.Calibrated.speed_delay`): on a time series
        the speed is read that much later (:func:`~satmotor_ros.identify.delay.shifted`),
        as the calibration read it, [s]

    Returns
    -------
    Validation
        The points, the residual and its errors.

    Raises
    ------
    IdentificationError
        If no point is usable (the message says why).
    DataError
        If the model's effects need a channel the data lack (the message names it).

    """
    options = Options(mode=mode, steady=tol or SteadyTolerance(),
                      transient=TransientOptions(screen_volumes=False))
    delay = None
    if (speed_delay is not None and mode not in ('points', 'series') and 'time' in table.channels
            and is_series(table)):
        table, lost = shifted(table, speed_delay, options.transient.gap)
        delay = {'seconds': speed_delay, 'samples_unserved': lost,
                 'note': "the calibration's delay of the speed reading, applied unchanged"}
    read = read_rows(bare(model), table, options, check=False)
    beyond = _outside(calibrated, table)
    if read.samples is not None:
        return replace(_validate_samples(read.samples, model, liquid, dynamics),
                       coverage=read.coverage, outside=beyond, delay=delay)
    points = read.table
    parts, usable = loss_parts(bare(model), points)
    if not usable.all():
        points = points.select(usable, f'left out {int((~usable).sum())} points outside the '
                                       'model (no flow the model can give, or a chamber '
                                       'drop out of range)')
    evaluated = CalibratedModel(model)
    flow, extrapolated = predicted(evaluated, points, parts)
    flagged = ~np.isfinite(flow)
    if flagged.all():
        msg = f'{points.source}: the model flags every point invalid'
        raise IdentificationError(msg)
    if flagged.any():
        keep = ~flagged
        points = points.select(keep, f'left out {int(flagged.sum())} points the model flags '
                                     'invalid (its status is not OK there)')
        parts, _ = loss_parts(bare(model), points)
        flow, extrapolated = flow[keep], extrapolated[keep]
    points = _note_extrapolated(points, int(extrapolated.sum()), 'points')
    residual = parts.flow - flow
    return Validation(liquid, model, points, parts, residual, Errors.of(residual, parts.loss),
                      tuple(evaluated.describe()), int(flagged.sum()), int(extrapolated.sum()),
                      read.coverage, beyond, flagged=extrapolated)


def _outside(calibrated: dict[str, Any] | None, rows: BenchTable) -> dict[str, Any] | None:
    """Count the rows (every sample of the data) outside the calibrated envelope; None without."""
    if calibrated is None:
        return None
    dp, speed = rows.p_in - rows.p_out, rows.speed
    out = outside(calibrated, dp, speed) & np.isfinite(dp) & np.isfinite(speed)
    return {'samples': int(out.sum()), 'of': int(out.size),
            'share': float(f'{out.sum() / max(out.size, 1):.4g}')}


def _note_extrapolated(points: BenchTable, count: int, what: str) -> BenchTable:
    """Add a note on the points (or rows) the model flags EXTRAPOLATED, when there are any."""
    if not count:
        return points
    return replace(points, notes=points.notes + (
        f'{count} {what} flagged EXTRAPOLATED, kept in the error: outside the range the '
        "model's coefficients were validated on, or where an effect is evaluated outside the "
        'data it was fitted on (its fitted_range)',))


def _validate_samples(samples: Samples, model: MotorModel, liquid: str,
                      dynamics: dict[str, float] | None) -> Validation:
    """
    Hold the model against every sample a time series' rows hold (:mod:`.sample_error`).

    The model is evaluated at every sample; the bench's transient terms (line compliance,
    sensor lags) are the calibration's (`dynamics`), applied unchanged at each sample, or
    none; nothing is fitted for the headline error (:func:`_transient_terms`). The same
    error over the rows (the bins' means a calibration fits) is kept as ``over_bins``.
    """
    data = sample_data(model, samples)
    calibrated = CalibratedModel(model)
    predicted_flow, extrapolated = predicted(calibrated, data.table, data.parts, data.lag)
    good = np.isfinite(predicted_flow)
    if not good.any():
        msg = f'{samples.samples.source}: the model flags every sample invalid'
        raise IdentificationError(msg)
    bins = _over_bins(samples, data, predicted_flow, dynamics)
    points, parts = data.table, data.parts
    if not good.all():
        points = points.select(good, f'left out {int((~good).sum())} samples the model flags '
                                     'invalid (its status is not OK there)')
        parts = parts_at(parts, good)
    residual, extrapolated = (parts.flow - predicted_flow[good]), extrapolated[good]
    points = _note_extrapolated(points, int(extrapolated.sum()), 'samples')
    headline, transient, in_sample = _transient_terms(residual, parts, dynamics)
    points = replace(points, notes=points.notes + (transient['note'],))
    return Validation(liquid, model, points, parts, headline, Errors.of(headline, parts.loss),
                      tuple(calibrated.describe()), int((~good).sum()), int(extrapolated.sum()),
                      flagged=extrapolated, transient=transient,
                      in_sample=None if in_sample is None else Errors.of(in_sample, parts.loss),
                      over_bins=bins)


def _over_bins(samples: Samples, data: SampleData, predicted_flow: FloatArray,
               dynamics: dict[str, float] | None) -> dict[str, Any]:
    """Return the headline error over the rows: each row's mean of the predictions."""
    full = np.full(len(samples.samples), np.nan)
    full[data.index] = predicted_flow * data.parts.sign
    residual = samples.parts.flow - averaged(samples, full) * samples.parts.sign
    good = np.isfinite(residual)
    for name, value in (dynamics or {}).items():
        if name in samples.parts.nuisance:
            residual = residual - value * samples.parts.nuisance[name]
    return {'n': int(good.sum()),
            'error': Errors.of(residual[good], samples.parts.loss[good]).as_dict()}


def _transient_terms(residual: FloatArray, parts: LossParts,
                     dynamics: dict[str, float] | None
                     ) -> tuple[FloatArray, dict[str, Any], FloatArray | None]:
    """
    Apply the calibration's transient terms to the residual; fit them only for a 2nd figure.

    Returns the headline residual (the calibration's terms applied unchanged, or none:
    out of sample), how it was made (validation.json's ``transient_terms``), and the
    residual after fitting the terms on these data by least squares (in sample), None
    when the data give no term.
    """
    x = parts.nuisance
    in_sample = None
    if x:
        columns = np.column_stack(list(x.values()))
        in_sample = residual - columns @ np.linalg.lstsq(columns, residual, rcond=None)[0]
    if dynamics is None:
        return residual, {
            'error': 'no transient terms (the motor file holds none)', 'applied': {},
            'note': ('the motor file holds no transient terms (dynamics): the error is without '
                     'them; error_transient_fitted_in_sample fits them on these data (in '
                     'sample, not a validation)')}, in_sample
    applied = {name: value for name, value in dynamics.items() if name in x}
    for name, value in applied.items():
        residual = residual - value * x[name]
    unused = sorted(set(dynamics) - set(applied))
    missing = (f'; not applicable here: {", ".join(unused)} (the data give no such term)'
               if unused else '')
    return residual, {
        'error': "the calibration's transient terms applied unchanged (out of sample)",
        'applied': applied,
        'note': ("the calibration's transient terms (" + (', '.join(applied) or 'none fitted')
                 + ') applied unchanged: they describe the bench, not the model' + missing)
    }, in_sample


__all__ = ['Validation', 'validate']
