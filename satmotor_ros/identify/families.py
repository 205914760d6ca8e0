# SPDX-License-Identifier: Apache-2.0
"""
The structure before the effect: which model family the data support best, out of sample.

Each family of :mod:`satmotor_ros.model.families` is fitted to the same points without any
effect (its channel drop where the data pin it, :mod:`.base`, then one factor per linear
part of its Q_vl, :func:`~.parts.loss_parts`) and scored by
its cross-validated error of Q_vl, with the folds and the selector the effect search uses,
weighted by the noise (:func:`weighted_rmse`, one noise for all: the families' own estimates
averaged; a recording's fast moves, whose timing jitter makes them the noisiest rows, do not
decide).
The motor's own family (its file's, or the SM-0,75/25's) is kept unless another one cuts
that error by more than the selector's ``min_gain``: like an effect, a change of structure
has to earn its place. A family pinned by the user (``--family``) is not compared.

The two best families are a near tie when the runner-up's out-of-sample error is within
the noise of the winner's: a one-sided paired test (Diebold and Mariano's) on the
difference of their squared standardised out-of-sample errors of Q_vl at the same points,
its variance inflated by the correlation of neighbouring rows of a time series, does not reject
at the selector's ``alpha`` that the runner-up is as good. The data then do not tell the two
structures apart, whichever was kept.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
import math
from typing import Any

import numpy as np
from satmotor_ros.identify.base import BaseFit, fit_base
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.parts import loss_parts, LossParts
from satmotor_ros.identify.selection import CrossValidatedSelector, Errors
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import variance_inflation
from satmotor_ros.model import MotorModel, MotorSpec
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.errors import ModelError
from satmotor_ros.model.families import FAMILY_NAMES
from satmotor_ros.model.families.defaults import default_motor
from satmotor_ros.model.units import LPM
from scipy import special


@dataclass(frozen=True)
class FamilyScore:
    """One family's baseline, fitted and cross-validated on the common points."""

    family: str  # the family's name
    factors: tuple[str, ...]  # the factors fitted (one per linear part of Q_vl)
    error: Errors | None  # out of sample, at the points no family calls an outlier
    note: str = ''  # why the family could not be scored, when error is None
    weighted: float = math.inf  # noise-weighted out-of-sample RMSE (:func:`weighted_rmse`)
    # at the same points, what the families are ranked by [m^3/s]

    @property
    def rmse(self) -> float:
        """Return the noise-weighted out-of-sample RMSE of Q_vl, inf when not scored, [m^3/s]."""
        return self.weighted if self.error is not None else math.inf


@dataclass(frozen=True)
class NearTie:
    """The two best families, whose out-of-sample errors differ by less than their noise."""

    winner: str  # the family with the least out-of-sample error
    runner_up: str  # the next one
    p_value: float  # one-sided paired test that the runner-up is worse [-]
    alpha: float  # the level it is not significant at [-]

    @property
    def note(self) -> str:
        """Return the sentence the report and calibration.json give."""
        return (f'near tie: {self.runner_up} is within the noise of {self.winner} (paired test '
                f'of their squared standardised out-of-sample errors of Q_vl, p = '
                f'{self.p_value:.2g} >= {self.alpha:g}): the data do not tell the two '
                'structures apart')

    def as_dict(self) -> dict[str, Any]:
        """Return the tie for ``calibration.json``'s ``family_comparison``."""
        return {'families': [self.winner, self.runner_up],
                'p_value': float(f'{self.p_value:.3g}'), 'note': self.note}


def paired_p_value(better: FloatArray, worse: FloatArray, inflation: float = 1.0) -> float:
    """
    Return the one-sided p-value that `worse` errs more than `better` (Diebold-Mariano).

    The statistic is the mean of d = worse^2 - better^2 over its standard error,
    sqrt(inflation var(d) / N), against Student's t with N - 1 degrees of freedom.

    Parameters
    ----------
    better, worse : ndarray
        Two models' out-of-sample errors at the same points, [m^3/s]
    inflation : float
        Variance inflation of d by the correlation of neighbouring points (1 for
        independent points), [-]

    Returns
    -------
    float
        The p-value; 1 when d is identically 0, 0 when it is a positive constant, [-]

    """
    d = np.asarray(worse, dtype=float) ** 2 - np.asarray(better, dtype=float) ** 2
    mean = float(np.mean(d))
    spread = float(np.std(d, ddof=1)) if d.size > 1 else 0.0
    if spread == 0.0:
        return 1.0 if mean <= 0.0 else 0.0
    t = mean / (spread * math.sqrt(inflation / d.size))
    return float(special.stdtr(d.size - 1, -t))


def weighted_rmse(error: FloatArray, sigma: FloatArray) -> float:
    """
    Return the RMSE of errors weighted by the noise, in the units of the errors.

    sqrt(mean((e/sigma)^2) mean(sigma^2)): the plain RMSE when the noise is the same at
    every point; where it is not, each point counts by its precision, so the noisiest rows
    (the fast moves of a recording) do not decide.

    Parameters
    ----------
    error : ndarray
        Errors at the points, [m^3/s]
    sigma : ndarray
        Noise at the points, [m^3/s]

    Returns
    -------
    float
        The weighted RMSE, [m^3/s]

    """
    return float(np.sqrt(np.mean((error / sigma) ** 2) * np.mean(sigma ** 2)))


@dataclass(frozen=True)
class FamilyChoice:
    """The comparison of the families and the one the calibration continues with."""

    chosen: str  # the family calibrated further
    scores: tuple[FamilyScore, ...]  # best first; empty when pinned
    n_points: int  # points the families were compared on [-]
    verdict: str  # why this family, one sentence
    tie: NearTie | None = None  # the two best families, when the data do not tell them apart
    bases: Mapping[str, BaseFit] = field(default_factory=dict)  # each family's base (.base)

    def as_list(self) -> list[dict[str, Any]]:
        """Return the comparison for ``calibration.json``: one entry per family, best first."""
        return [{'family': s.family, 'factors': list(s.factors),
                 'cv_error': s.error.as_dict() if s.error is not None else None,
                 **({'cv_error_weighted_lpm': float(f'{s.weighted / LPM:.4g}')}
                    if s.error is not None else {}),
                 **({'note': s.note} if s.note else {})} for s in self.scores]


def family_specs(spec: MotorSpec, default: bool) -> dict[str, MotorSpec]:
    """
    Return a motor of every family: `spec` for its own, the others' defaults at its size.

    Parameters
    ----------
    spec : MotorSpec
        The motor given (a file, the packaged SM-0,75/25 or a motor of a displacement), [-]
    default : bool
        Whether `spec` is the packaged SM-0,75/25 (the others then use its geometry), [-]

    Returns
    -------
    dict of str to MotorSpec
        Family name -> motor, `spec`'s family first.

    """
    displacement = None if default else spec.geometry.displacement
    specs = {spec.family: spec}
    for name in FAMILY_NAMES:
        if name not in specs:
            specs[name] = default_motor(name, displacement)
    return specs


def _parts_on(models: dict[str, MotorModel], points: BenchTable,
              nuisance: Mapping[str, FloatArray]
              ) -> tuple[BenchTable, dict[str, LossParts | str]]:
    """Keep the points every family can use; return them and each family's parts there."""
    common = np.ones(len(points), dtype=bool)
    for model in models.values():
        try:
            common &= loss_parts(model, points)[1]
        except IdentificationError:
            continue
    if not common.any():
        msg = f'{points.source}: no point is usable by every model family'
        raise IdentificationError(msg)
    if not common.all():
        points = points.select(common)
    kept = {k: x[common] for k, x in nuisance.items()}
    parts: dict[str, LossParts | str] = {}
    for name, model in models.items():
        try:
            parts[name] = loss_parts(model, points)[0].with_nuisance(kept)
        except IdentificationError as err:
            parts[name] = str(err)
    return points, parts


def compare_families(points: BenchTable, liquid: str, specs: dict[str, MotorSpec],
                     selector: Callable[[], CrossValidatedSelector], min_gain: float,
                     nuisance: Mapping[str, FloatArray] | None = None) -> FamilyChoice:
    """
    Fit each family's baseline on the same points and choose the structure.

    Parameters
    ----------
    points : BenchTable
        Steady points (or samples), [-]
    liquid : str
        Coefficient set, [-]
    specs : dict of str to MotorSpec
        One motor per family, the motor's own family first (:func:`family_specs`), [-]
    selector : callable
        Makes the selector the effect search uses (same folds and noise model), [-]
    min_gain : float
        Least cut of the out-of-sample error for a family to replace the motor's own, [-]
    nuisance : mapping of str to ndarray, optional
        Regressors every family's fit takes beside its own parts (a transient
        recording's terms, :mod:`.transient`), at the points, [SI]

    Returns
    -------
    FamilyChoice
        The families scored, best first, and the one chosen.

    Raises
    ------
    IdentificationError
        If no family can be fitted to the points.

    """
    models, bases = {}, {}
    for name, spec in specs.items():
        try:
            models[name] = MotorModel.from_spec(spec, liquid)
        except ModelError:
            continue
        try:  # the base each family earns: its channel drop where the data pin it
            bases[name] = fit_base(spec, liquid, points, nuisance)
        except IdentificationError:
            continue
        models[name] = MotorModel.from_spec(bases[name].spec, liquid)
    common, parts = _parts_on(models, points, nuisance or {})
    scored = {}
    variances: list[FloatArray] = []
    outlier = np.zeros(len(common), dtype=bool)
    for name, p in parts.items():
        if isinstance(p, str):
            continue
        try:
            forward = selector().select(p, ())
        except IdentificationError as err:
            parts[name] = str(err)
            continue
        scored[name] = (p, forward.steps[0].baseline.cv_error)
        variances.append(forward.sigma ** 2)
        outlier |= forward.outliers
    keep = ~outlier if (~outlier).any() else np.ones(len(common), dtype=bool)
    # one noise for all: the families' own estimates, averaged (their variances)
    sigma = np.sqrt(np.mean(variances, axis=0))[keep] if variances else np.ones(0)
    scores = []
    for name in specs:
        if name in scored:
            p, error = scored[name]
            scores.append(FamilyScore(name, p.names, Errors.of(error[keep], p.loss[keep]),
                                      weighted=weighted_rmse(error[keep], sigma)))
        elif name in models:
            scores.append(FamilyScore(name, (), None, str(parts.get(name, 'not fitted'))))
        else:
            scores.append(FamilyScore(name, (), None, 'no model for this liquid'))
    own = scores[0]
    scores.sort(key=lambda s: s.rmse)
    best = scores[0]
    if best.error is None:
        msg = f'{points.source}: no model family could be fitted ({own.note})'
        raise IdentificationError(msg)
    n = int(keep.sum())
    tie = _near_tie(scores, scored, keep, selector(), sigma)
    if best.family == own.family:
        verdict = (f'{own.family} has the least noise-weighted out-of-sample error of the '
                   'families')
        return FamilyChoice(own.family, tuple(scores), n, verdict, tie, bases)
    if own.error is not None and best.rmse >= (1.0 - min_gain) * own.rmse:
        verdict = (f'{own.family} kept: {best.family} cuts the noise-weighted out-of-sample '
                   f'error by only {100.0 * (1.0 - best.rmse / own.rmse):.1f} % (need > '
                   f'{100.0 * min_gain:.0f} %)')
        return FamilyChoice(own.family, tuple(scores), n, verdict, tie, bases)
    cut = (f'cuts the noise-weighted out-of-sample error of {own.family} by '
           f'{100.0 * (1.0 - best.rmse / own.rmse):.1f} %' if own.error is not None
           else f'fits where {own.family} cannot')
    return FamilyChoice(best.family, tuple(scores), n, f'{best.family} {cut}', tie, bases)


def _near_tie(scores: list[FamilyScore], scored: Mapping[str, tuple[LossParts, FloatArray]],
              keep: np.ndarray, selector: CrossValidatedSelector,
              sigma: FloatArray) -> NearTie | None:
    """Return the two best families when the runner-up is within the winner's noise."""
    if len(scores) < 2 or scores[1].error is None:
        return None
    winner, runner = (scored[s.family][1][keep] / sigma for s in scores[:2])
    d = runner ** 2 - winner ** 2
    inflation = variance_inflation(d) if selector.correlated else 1.0
    p_value = paired_p_value(winner, runner, inflation)
    if p_value < selector.alpha:
        return None
    return NearTie(scores[0].family, scores[1].family, p_value, selector.alpha)


__all__ = ['FamilyChoice', 'FamilyScore', 'NearTie', 'compare_families', 'family_specs',
           'paired_p_value', 'weighted_rmse']
