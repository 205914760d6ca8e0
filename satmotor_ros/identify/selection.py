# SPDX-License-Identifier: Apache-2.0
"""
Model selection: which candidate effect, if any, the data ask for.

Each candidate is refitted with the model and scored by its K-fold
cross-validated error (contiguous, time-ordered folds for data in time
order, seeded shuffled folds otherwise). The best candidate is accepted
only if it passes two tests against the baseline (the model refitted
without any effect): a nested-model F-test at the significance ``alpha``,
Bonferroni-corrected for the number of candidates tried, and a cut of the
cross-validated error by at least ``min_gain``. Otherwise the answer is
``none``. A runner-up that passes the same tests is reported as a near tie
when its cross-validated error is within ``tie`` of the winner's, or when it
removes all but ``tie`` of the error the winner removes (on data with little
noise both errors left are tiny, and their ratio means nothing); among the
first kind a named physical effect goes before ``channel:`` and ``term:``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from satmotor_ros.identify.candidates import Candidate
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.fit import LossFit
from satmotor_ros.identify.parts import LossParts
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import LPM
from scipy import special


@dataclass(frozen=True)
class Errors:
    """Errors of the volumetric losses Q_vl, as calibration.json reports them."""

    rmse_lpm: float  # root mean square, [l/min]
    mean_abs_pct: float  # mean |error| as % of the mean |measured Q_vl|, [%]
    max_abs_lpm: float  # largest |error|, [l/min]

    @classmethod
    def of(cls, error: FloatArray, loss: FloatArray) -> Errors:
        """
        Summarise errors of Q_vl.

        Parameters
        ----------
        error : ndarray
            Measured minus predicted Q_vl, [m^3/s]
        loss : ndarray
            Measured Q_vl, [m^3/s]

        Returns
        -------
        Errors
            The three figures.

        """
        scale = max(float(np.mean(np.abs(loss))), 1e-300)
        return cls(float(np.sqrt(np.mean(error ** 2)) / LPM),
                   float(100.0 * np.mean(np.abs(error)) / scale),
                   float(np.max(np.abs(error)) / LPM))

    def as_dict(self) -> dict[str, float]:
        """Return the figures by name, rounded to 4 significant digits."""
        return {k: float(f'{v:.4g}') for k, v in vars(self).items()}


@dataclass(frozen=True)
class Score:
    """One candidate (or the baseline) fitted, cross-validated and tested."""

    candidate: Candidate | None  # None: the baseline
    fit: LossFit  # fitted on all points
    cv_error: FloatArray  # out-of-sample error of Q_vl at each point [m^3/s]
    cv_rmse: float  # [m^3/s]
    p_value: float  # F-test against the baseline (1 for the baseline) [-]

    @property
    def label(self) -> str:
        """Return the candidate's label, or ``'none'`` for the baseline."""
        return self.candidate.label if self.candidate is not None else 'none'

    @property
    def effect(self) -> str:
        """Return the candidate's effect, or ``'none'`` for the baseline."""
        return self.candidate.effect if self.candidate is not None else 'none'


@dataclass(frozen=True)
class Selection:
    """The outcome of model selection."""

    baseline: Score  # the model refitted without any effect
    ranking: tuple[Score, ...]  # candidates, best cross-validated error first
    chosen: Score | None  # the accepted effect, or None
    runner_up: Score | None  # a near tie of the chosen effect, or None
    verdict: str  # why the effect was accepted or not, one sentence
    alpha: float  # family-wise significance level [-]


def priority(effect: str) -> int:
    """
    Rank a candidate's kind for near ties: named effects, then channels, then terms.

    Parameters
    ----------
    effect : str
        The candidate's effect, [-]

    Returns
    -------
    int
        0 for a named physical effect, 1 for ``channel:``, 2 for ``term:``.

    """
    return 2 if effect.startswith('term:') else int(effect.startswith('channel:'))


def folds(n: int, k: int, time_ordered: bool, seed: int = 0) -> list[np.ndarray]:
    """
    Split point indices into K folds.

    Parameters
    ----------
    n : int
        Number of points, [-]
    k : int
        Number of folds (at most `n`), [-]
    time_ordered : bool
        Contiguous blocks in order (time series) rather than shuffled, [-]
    seed : int
        Seed of the shuffle, [-]

    Returns
    -------
    list of ndarray
        Test indices of each fold.

    """
    order = np.arange(n) if time_ordered else np.random.default_rng(seed).permutation(n)
    return [np.sort(part) for part in np.array_split(order, min(k, n))]


class CrossValidatedSelector:
    """
    Rank candidate effects by cross-validated error and accept one only if significant.

    Parameters
    ----------
    alpha : float
        Family-wise significance level of the F-tests, [-]
    n_folds : int
        Number of cross-validation folds, [-]
    min_gain : float
        Least relative cut of the cross-validated error, [-]
    tie : float
        Relative margin of cross-validated error within which the runner-up
        counts as a near tie (of the winner's error, or of the error it removes), [-]
    time_ordered : bool
        Whether the points are in time order (contiguous folds), [-]
    c_floor : float
        Smallest factor on C (see :class:`LossFit`), [-]
    seed : int
        Seed of the fold shuffle, [-]

    """

    def __init__(self, alpha: float = 0.05, n_folds: int = 5, min_gain: float = 0.05,
                 tie: float = 0.05, time_ordered: bool = False, c_floor: float = 0.0,
                 seed: int = 0) -> None:
        """Validate and store the hyperparameters."""
        if not 0.0 < alpha < 1.0:
            msg = f'alpha = {alpha!r}: must be in (0, 1)'
            raise IdentificationError(msg)
        if n_folds < 2:
            msg = f'n_folds = {n_folds!r}: must be >= 2'
            raise IdentificationError(msg)
        if not 0.0 <= min_gain < 1.0 or tie < 0.0:
            msg = f'min_gain = {min_gain!r}, tie = {tie!r}: need 0 <= min_gain < 1, tie >= 0'
            raise IdentificationError(msg)
        self.alpha, self.n_folds, self.min_gain, self.tie = alpha, n_folds, min_gain, tie
        self.time_ordered, self.c_floor, self.seed = time_ordered, c_floor, seed
        self.noise_ = 0.0

    def score(self, parts: LossParts, candidate: Candidate | None,
              baseline_rss: float | None = None) -> Score:
        """
        Fit one candidate on all points and on each training fold.

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        candidate : Candidate or None
            The effect; None scores the baseline, [-]
        baseline_rss : float, optional
            RSS of the baseline, for the F-test, [(m^3/s)^2]

        Returns
        -------
        Score
            The fit, its out-of-sample errors and its p-value.

        """
        full = LossFit(candidate, self.c_floor, self.noise_).fit(parts)
        n = len(parts)
        error = np.empty(n)
        everything = np.arange(n)
        for test in folds(n, self.n_folds, self.time_ordered, self.seed):
            train = np.setdiff1d(everything, test, assume_unique=True)
            model = LossFit(candidate, self.c_floor, self.noise_).fit(parts, train)
            error[test] = parts.flow[test] - model.predict(parts, test)
        p_value = 1.0
        if candidate is not None and baseline_rss is not None:
            dof = n - full.n_params
            if dof > 0 and full.rss_ > 0.0:
                f = max(baseline_rss - full.rss_, 0.0) / (full.rss_ / dof)
                p_value = float(special.fdtrc(1, dof, f))
            elif baseline_rss > full.rss_:
                p_value = 0.0
        return Score(candidate, full, error, float(np.sqrt(np.mean(error ** 2))), p_value)

    def _passes(self, score: Score, baseline: Score, m: int) -> bool:
        return (score.p_value < self.alpha / m
                and score.cv_rmse < (1.0 - self.min_gain) * baseline.cv_rmse)

    def select(self, parts: LossParts, candidates: Sequence[Candidate]) -> Selection:
        """
        Score the baseline and every candidate, and choose.

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        candidates : sequence of Candidate
            The library built for these data, [-]

        Returns
        -------
        Selection
            Ranking, choice, runner-up and the reason.

        """
        free = LossFit(None, self.c_floor).fit(parts)
        self.noise_ = float(np.sqrt(free.rss_ / max(len(parts) - free.n_params, 1)))
        baseline = self.score(parts, None)
        scores = [self.score(parts, c, baseline.fit.rss_) for c in candidates]
        ranking = tuple(sorted(scores, key=lambda s: s.cv_rmse))
        m = max(len(candidates), 1)
        if not ranking:
            return Selection(baseline, ranking, None, None, 'no candidate could be tested',
                             self.alpha)
        top = ranking[0]
        gain = 1.0 - top.cv_rmse / baseline.cv_rmse if baseline.cv_rmse > 0 else 0.0
        if not self._passes(top, baseline, m):
            verdict = (f'none: the best candidate, {top.label}, cuts the cross-validated '
                       f'error by {100 * gain:.1f} % (need > {100 * self.min_gain:.0f} %) with '
                       f'p = {top.p_value:.2g} (need < {self.alpha:g}/{m})')
            return Selection(baseline, ranking, None, None, verdict, self.alpha)
        removed = baseline.cv_rmse - top.cv_rmse
        close = [s for s in ranking if self._passes(s, baseline, m) and (
            s.cv_rmse <= (1.0 + self.tie) * top.cv_rmse
            or s.cv_rmse - top.cv_rmse <= self.tie * removed)]
        contenders = [s for s in close if s.cv_rmse <= (1.0 + self.tie) * top.cv_rmse]
        best = min(contenders, key=lambda s: (priority(s.effect), s.cv_rmse))
        # a runner-up also when it removes nearly all the error the winner removes: on data
        # with little noise the two errors left are both tiny and far apart in ratio
        others = [s for s in close if s.effect != best.effect]
        others.sort(key=lambda s: priority(s.effect) != priority(best.effect))
        runner = others[0] if others else None
        gain = 1.0 - best.cv_rmse / baseline.cv_rmse
        verdict = (f'{best.label}: cuts the cross-validated error by {100 * gain:.1f} %, '
                   f'p = {best.p_value:.2g} < {self.alpha:g}/{m}')
        if runner is not None:
            runner_gain = 1.0 - runner.cv_rmse / baseline.cv_rmse
            verdict += (f'; near tie with {runner.label} (cross-validated error '
                        f'{100 * (runner.cv_rmse / best.cv_rmse - 1):+.1f} %, it cuts the '
                        f'error by {100 * runner_gain:.1f} %): the data barely tell them apart')
            if priority(runner.effect) > priority(best.effect):
                verdict += ', and a named physical effect goes before a generic term'
        return Selection(baseline, ranking, best, runner, verdict, self.alpha)
