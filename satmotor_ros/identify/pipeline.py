# SPDX-License-Identifier: Apache-2.0
"""
Calibration end to end: steady points, baseline fit, candidate selection, refit.

The pieces stay apart (PySINDy style): :mod:`.candidates` builds the
library, :mod:`.fit` fits, :mod:`.selection` chooses; this module only
composes them and collects what ``calibration.json`` reports.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np

from satmotor_ros.identify.candidates import build_library, Candidate
from satmotor_ros.identify.errors import DataError, IdentificationError
from satmotor_ros.identify.fit import check_identifiable, FitReport
from satmotor_ros.identify.parts import loss_parts, LossParts, predict_flow
from satmotor_ros.identify.selection import CrossValidatedSelector, Errors, Selection
from satmotor_ros.identify.steady import extract_steady, looks_like_series, SteadyTolerance
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import load_motor, MotorModel, MotorSpec
from satmotor_ros.model.revolutions import sampled_revolutions
from satmotor_ros.model.viscosity import standard_law, ViscosityLaw

Mode = Literal['auto', 'points', 'series']


@dataclass(frozen=True)
class Options:
    """How to calibrate: selection hyperparameters and the steady-state tolerances."""

    alpha: float = 0.05  # family-wise significance level [-]
    n_folds: int = 5  # cross-validation folds [-]
    min_gain: float = 0.05  # least cut of the cross-validated error [-]
    tie: float = 0.05  # near-tie margin of cross-validated error [-]
    mode: Mode = 'auto'  # rows are steady points, a time series, or decide from the data
    seed: int = 0  # fold shuffle [-]
    steady: SteadyTolerance = field(default_factory=SteadyTolerance)


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
    selection: Selection  # ranking and choice
    baseline: FitReport  # the model refitted without an effect
    final: FitReport  # the model refitted with the chosen effect (or the baseline)
    error_packaged: Errors  # the packaged model, in sample
    error_before: Errors  # baseline, out of sample
    error_after: Errors  # with the effect, out of sample

    @property
    def chosen(self) -> Candidate | None:
        """Return the chosen effect's candidate, or None."""
        return self.selection.chosen.candidate if self.selection.chosen else None

    def summary(self) -> dict[str, Any]:
        """
        Build the calibration.json object, with exactly the DESIGN.md fields.

        Returns
        -------
        dict
            liquid, n_points, effect, regressor, coefficient, ci95, unit,
            error_before, error_after, candidates. With no effect, regressor,
            coefficient, ci95 and unit are null.

        """
        chosen = self.chosen
        coefficient = ci95 = None
        if chosen is not None:
            coefficient = _round(self.final.values[3])
            ci95 = [_round(v) for v in self.final.ci95[3]]
        ranked = [self.selection.baseline, *self.selection.ranking]
        ranked.sort(key=lambda s: s.cv_rmse)
        return {
            'liquid': self.liquid, 'n_points': len(self.parts),
            'effect': chosen.effect if chosen else 'none',
            'regressor': chosen.regressor if chosen else None,
            'coefficient': coefficient, 'ci95': ci95,
            'unit': chosen.unit if chosen else None,
            'error_before': self.error_before.as_dict(),
            'error_after': self.error_after.as_dict(),
            'candidates': [
                {'effect': s.candidate.effect if s.candidate else 'none',
                 'regressor': s.candidate.regressor if s.candidate else None,
                 'cv_rmse_lpm': _round(s.cv_rmse / 1.0e-3 * 60.0)} for s in ranked],
        }


def _round(x: float) -> float:
    return float(f'{float(x):.5g}')


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
        msg = f"mode = {mode!r}: use 'auto', 'points' or 'series'"
        raise DataError(msg)
    series = table.time_series or looks_like_series(table)
    if mode == 'series' or (mode == 'auto' and series):
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


def _errors(parts: LossParts, error: np.ndarray) -> Errors:
    return Errors.of(error, parts.loss)


def _without_effects(spec: MotorSpec, liquid: str,
                     table: BenchTable) -> tuple[MotorSpec, BenchTable]:
    """Start from a set's coefficients without its effects: the calibration looks anew."""
    fitted = spec.sets[liquid]
    if not fitted.effects:
        return spec, table
    coef = fitted.coefficients
    if any(e.kind == 'external_leakage' for e in fitted.effects):
        coef = replace(coef, external_leakage=0.0)  # its effect named the pressure; gone too
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
    model = MotorModel.from_spec(spec, liquid)
    points = steady_points(table, options.mode, options.steady)
    parts, usable = loss_parts(model, points)
    if not usable.all():
        points = points.select(usable, f'left out {int((~usable).sum())} points outside the '
                                       'model (no forward flow, negative speed or chamber '
                                       'drop out of range)')
    check_identifiable(parts)
    law = standard_law(model.liquid, liquid)
    channels = {**points.channels, 'p_out': points.p_out}
    candidates, skipped = build_library(parts, channels, law)
    c_floor = model.c_fc_beta / model.c if model.c > 0 else 0.0
    selector = CrossValidatedSelector(options.alpha, options.n_folds, options.min_gain,
                                      options.tie, 'time' in points.channels, c_floor,
                                      options.seed)
    selection = selector.select(parts, candidates)
    baseline = selection.baseline.fit.report()
    chosen = selection.chosen
    final = chosen.fit.report() if chosen is not None else baseline
    packaged = parts.flow - predict_flow(parts, np.ones(3))
    before = _errors(parts, selection.baseline.cv_error)
    after = _errors(parts, chosen.cv_error) if chosen is not None else before
    return Calibration(liquid, spec, model, points, parts, law, tuple(candidates),
                       tuple(skipped), selection, baseline, final,
                       _errors(parts, packaged), before, after)


__all__ = ['Calibration', 'IdentificationError', 'Options', 'calibrate', 'steady_points']
