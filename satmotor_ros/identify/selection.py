# SPDX-License-Identifier: Apache-2.0
"""
Model selection: which candidate effects, if any, the data ask for, one after the other.

Forward selection: each step refits every candidate not yet found on top of the
effects found so far and scores it by its K-fold cross-validated error
(contiguous, time-ordered folds for data in time order, seeded shuffled folds
otherwise). The best candidate is accepted only if it passes two tests against
the step's baseline (the model with the effects found so far): a nested-model
F-test at the significance ``alpha``, Bonferroni-corrected for the number of
candidates tried, and a cut of the cross-validated error by at least
``min_gain``; and its plain (unweighted) out-of-sample RMSE over the step's
rows, the figure the report gives, must fall too: an effect that the noise-
weighted figure prefers while the error a user reads rises is not kept. The
loop stops at the first step whose best candidate fails; the answer is then the
effects found, or ``none``. A runner-up that passes the same tests is reported
as a near tie when its cross-validated error is within ``tie`` of the winner's,
or when it removes all but ``tie`` of the error the winner removes (on data
with little noise both errors left are tiny, and their ratio means nothing);
among the first kind a named physical effect goes before ``channel:``,
``term:`` and ``threshold:``, and before a fitted form that beats it by less
than :data:`FORM_TIE` of the error removed (a form with free exponents bends
towards anything).

A candidate whose fit leaves an effect's parameter on a bound of its range (a
sensor gain at -0.5, an exponent at its limit) is never accepted: the data ask
for a value beyond the range, so the fitted value is the bound and not an
estimate, and both the F-test (whose F distribution assumes the best fit is a
stationary point inside the range) and the interval from the Jacobian mean
nothing there. The effect as the model has it does not explain the data;
the step goes on with the candidates that are estimated, and says which
candidates it refused when they fitted better than all of those.

Every step weighs the points by a noise model estimated from the residuals
of the step's best-fitting model (:mod:`.noise`): the F-test and the
cross-validated error are those of standardised residuals, through Huber's
loss, and the points that are isolated outliers under that model and under
the model with each candidate (judged per candidate, so a row that any
candidate explains stays in) are left out of the step's fits, so that a bad
row decides nothing, while a point that an effect explains is never mistaken
for one. Outliers that cluster in
the operating space or in time (:mod:`.regions`) are structure, not bad rows:
they stay in every fit, where a candidate may explain them, and those the
final model still misses are named as regions.

Rows of a time series (:mod:`.transient`) have correlated residuals: the folds
are then blocks of about two seconds of rows dealt to the folds in turn (so that
every fold's training holds rows of each event the recording repeats, a valve
that opens at the top of each stroke), each block's ``guard`` rows on each side
are kept out of its fold's training, and the
F-test divides the statistic and the number of rows by the variance inflation
of the baseline's residuals or of the candidate's, whichever is larger (a
candidate that bends to slow noise whitens its own residuals).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from satmotor_ros.identify.candidates import Candidate
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.fit import HUBER, huber_rho, LossFit
from satmotor_ros.identify.noise import noise_model, outliers, rates_of, robust_scale
from satmotor_ros.identify.parts import LossParts
from satmotor_ros.identify.regional import (acting, local_gain, LocalGain, RECUR_ALPHA,
                                            recurrence)
from satmotor_ros.identify.regions import clustered, regions, Space
from satmotor_ros.identify.transient import variance_inflation
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import effect_name
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


FORM_TIE = 0.1
"""A named effect goes before a fitted form (``term:``, ``threshold:``) that beats it when it
removes all but this share of the error the form removes, [-]."""


@dataclass(frozen=True)
class Score:
    """One candidate (or a step's baseline) fitted, cross-validated and tested."""

    candidate: Candidate | None  # None: the step's baseline (the effects found before)
    fit: LossFit  # fitted on the step's points
    cv_error: FloatArray  # out-of-sample error of Q_vl at every point [m^3/s]
    cv_rmse: float  # noise-weighted, robust cross-validated error [m^3/s]
    p_value: float  # F-test against the step's baseline (1 for the baseline) [-]
    rmse: float = np.nan  # plain out-of-sample RMSE over the rows fitted [m^3/s]
    folds: tuple[tuple[np.ndarray, FloatArray], ...] = ()  # each fold's test points and
    # the parameters fitted without them (:meth:`LossFit.without`): what predicted them

    @property
    def label(self) -> str:
        """Return the effect as found (a fitted form by its expression), or ``'none'``."""
        if self.candidate is None:
            return 'none'
        if self.candidate.shape:  # the one name of every output (a valve's side and crack)
            return effect_name(self.fit.found()[-1][1])
        return self.candidate.label

    @property
    def added(self) -> Candidate:
        """Return the candidate this score tested (an error for a baseline)."""
        if self.candidate is None:
            raise IdentificationError('a baseline adds no effect')
        return self.candidate

    @property
    def effect(self) -> str:
        """Return the effect id as found, or ``'none'`` for the baseline."""
        if self.candidate is None:
            return 'none'
        return self.fit.found()[-1][1].key if self.candidate.shape else self.candidate.effect


@dataclass(frozen=True)
class Selection:
    """The outcome of one step of forward selection."""

    baseline: Score  # the model with the effects found before this step
    ranking: tuple[Score, ...]  # candidates, best cross-validated error first
    chosen: Score | None  # the accepted effect, or None (the loop stops)
    runner_up: Score | None  # a near tie of the chosen effect, or None
    verdict: str  # why the effect was accepted or not, one sentence
    alpha: float  # family-wise significance level [-]
    sigma: FloatArray  # noise model of the step at every point [m^3/s]
    left_out: np.ndarray  # bool: outliers even under the step's best model, not fitted
    refused: tuple[Score, ...] = ()  # ahead of the candidates chosen from, but on a bound
    confined: bool = False  # chosen by its gain where it acts (:mod:`.regional`)


@dataclass(frozen=True)
class Forward:
    """The outcome of forward selection: the steps, the final model and its outliers."""

    steps: tuple[Selection, ...]  # every step; the last one chose nothing (or hit the limit)
    final: Score  # the model with every effect found
    sigma: FloatArray  # noise model of the last step [m^3/s]
    outliers: np.ndarray  # bool: isolated and beyond the outlier limit under the final model
    missed: tuple[tuple[str, np.ndarray], ...] = ()  # kind and rows of each region missed

    @property
    def found(self) -> tuple[Score, ...]:
        """Return the accepted effects' scores, in the order found."""
        return tuple(s.chosen for s in self.steps if s.chosen is not None)


def priority(effect: str) -> int:
    """
    Rank a candidate's kind for near ties: named effects, then channels, then fitted forms.

    Parameters
    ----------
    effect : str
        The candidate's effect, [-]

    Returns
    -------
    int
        0 for a named effect, 1 for ``channel:``, 2 for ``term:`` and ``threshold:``.

    """
    return 2 if effect.startswith(('term:', 'threshold:')) else int(effect.startswith('channel:'))


def same_effect(a: Candidate, b: Candidate) -> bool:
    """Return whether two candidates are one effect: a kind once, a listed suffix once."""
    def key(c: Candidate) -> str:
        return c.effect.partition(':')[0] if c.shape or ':' not in c.effect else c.effect
    return key(a) == key(b)


def determined(fit: LossFit) -> bool:
    """Return whether the data determine every parameter of a fit (a fitted form's shape too)."""
    try:
        fit.report()
    except IdentificationError:
        return False
    return True


def folds(n: int, k: int, time_ordered: bool, seed: int = 0,
          block: int = 0) -> list[np.ndarray]:
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
    block : int
        Rows of a block (> 0, time order only): the rows are cut into blocks in time
        order, dealt to the folds in turn, so that every fold's training holds rows of
        every stretch the recording visits more than once; 0: K contiguous folds, [-]

    Returns
    -------
    list of ndarray
        Test indices of each fold.

    """
    k = min(k, n)
    if time_ordered and block > 0 and n >= 2 * k * block:
        dealt = (np.arange(n) // block) % k
        return [np.flatnonzero(dealt == j) for j in range(k)]
    order = np.arange(n) if time_ordered else np.random.default_rng(seed).permutation(n)
    return [np.sort(part) for part in np.array_split(order, k)]


class CrossValidatedSelector:
    """
    Add candidate effects one by one while one cuts the cross-validated error significantly.

    Parameters
    ----------
    alpha : float
        Family-wise significance level of each step's F-tests, [-]
    n_folds : int
        Number of cross-validation folds, [-]
    min_gain : float
        Least relative cut of the cross-validated error, [-]
    tie : float
        Relative margin of cross-validated error within which the runner-up
        counts as a near tie (of the winner's error, or of the error it removes), [-]
    time_ordered : bool
        Whether the points are in time order (contiguous folds), [-]
    seed : int
        Seed of the fold shuffle, [-]
    max_effects : int
        Most effects the loop adds, [-]
    guard : int
        Rows on each side of a contiguous test fold also kept out of its training
        (neighbours that share a sample); 0 for independent rows, [-]
    correlated : bool
        Whether neighbouring residuals are correlated (a time series' rows): the
        F-test then uses the variance inflation, [-]
    block : int
        Rows per block of blocked-interleaved folds (:func:`folds`); 0 for K contiguous
        folds, [-]

    """

    def __init__(self, alpha: float = 0.05, n_folds: int = 5, min_gain: float = 0.05,
                 tie: float = 0.05, time_ordered: bool = False, seed: int = 0,
                 max_effects: int = 4, guard: int = 0, correlated: bool = False,
                 block: int = 0) -> None:
        """Validate and store the hyperparameters."""
        if not 0.0 < alpha < 1.0:
            msg = f'alpha = {alpha!r}: must be in (0, 1)'
            raise IdentificationError(msg)
        if n_folds < 2:
            msg = f'n_folds = {n_folds!r}: must be >= 2'
            raise IdentificationError(msg)
        if not 0.0 <= min_gain < 1.0 or tie < 0.0 or max_effects < 1:
            msg = (f'min_gain = {min_gain!r}, tie = {tie!r}, max_effects = {max_effects!r}: '
                   'need 0 <= min_gain < 1, tie >= 0, max_effects >= 1')
            raise IdentificationError(msg)
        self.alpha, self.n_folds, self.min_gain, self.tie = alpha, n_folds, min_gain, tie
        self.time_ordered, self.seed, self.max_effects = time_ordered, seed, max_effects
        self.guard = guard if time_ordered else 0
        self.block = block if time_ordered else 0
        self.correlated = correlated
        self._tried: dict[int, FloatArray] = {}  # candidate id -> its parameters last fitted
        self._space: Space | None = None  # where the rows lie, for clusters of outliers

    def score(self, parts: LossParts, effects: Sequence[Candidate], sigma: FloatArray,
              index: np.ndarray, start: FloatArray | None = None,
              baseline: Score | None = None) -> Score:
        """
        Fit a model on the points in `index` and on each training fold of them.

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        effects : sequence of Candidate
            The effects found so far, then the candidate (none for a baseline), [-]
        sigma : ndarray
            Noise at every point, [m^3/s]
        index : ndarray of int
            The points fitted (outliers left out), [-]
        start : ndarray, optional
            Initial values (a fit of the model without the candidate, or with it), [-]
        baseline : Score, optional
            The step's baseline, for the F-test; None scores a baseline, [-]

        Returns
        -------
        Score
            The fit, its out-of-sample errors and its p-value.

        """
        full = LossFit(effects, sigma, HUBER).fit(parts, index, start)
        if baseline is not None and effects[-1].shape and start is not None \
                and len(start) > baseline.fit.u_.size and (
                    effects[-1].effect.startswith('threshold:')
                    or full.pinned(effects_only=True)):
            # a form's shape from the outlier screen's fit (one scale, Tukey's weights, which
            # reject the few rows where a valve opens) may sit in another basin than this
            # step's weights have (a valve slid to an offset: exponent 0.05, crack at the
            # bottom), and a fit that ends on a bound is no estimate: for a valve, and for a
            # form on a bound, the form's own starts are tried too, the better fit kept
            own = LossFit((*effects[:-1], _near_top(effects[-1])), sigma, HUBER).fit(
                parts, index, baseline.fit.u_)
            full = own if own.objective_ < full.objective_ else full
        error = parts.flow - full.predict(parts)  # out of sample where not fitted
        tested = []
        for test in folds(index.size, self.n_folds, self.time_ordered, self.seed, self.block):
            u = full.without(_guarded(test, self.guard, index.size))
            error[index[test]] = parts.flow[index[test]] - full.predict(parts, index[test], u)
            tested.append((index[test], u))
        z = error[index] / sigma[index]
        cv = float(np.sqrt(np.mean(huber_rho(z)) * np.mean(sigma[index] ** 2)))
        p_value = 1.0
        if baseline is not None:
            q = full.n_params - baseline.fit.n_params
            dof = index.size - full.n_params
            drop = max(baseline.fit.objective_ - full.objective_, 0.0)
            # under the null: the baseline's residuals keep the slow noise a candidate may
            # have bent to, so the larger of the two inflations is the honest one
            inflation = max(self.inflation(parts, full, sigma, index),
                            self.inflation(parts, baseline.fit, sigma, index))
            if dof > 0 and full.objective_ > 0.0:
                f = drop / q / (full.objective_ / dof) / inflation
                p_value = float(special.fdtrc(q, max(int(index.size / inflation)
                                                     - full.n_params, 1), f))
            elif drop > 0.0:
                p_value = 0.0
        rmse = float(np.sqrt(np.mean(error[index] ** 2)))
        return Score(effects[-1] if baseline is not None else None, full, error, cv, p_value,
                     rmse, tuple(tested))

    def inflation(self, parts: LossParts, fit: LossFit, sigma: FloatArray,
                  index: np.ndarray) -> float:
        """
        Return the variance inflation of a fit's standardised residuals (1 unless correlated).

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        fit : LossFit
            A fit on the points in `index`, [-]
        sigma : ndarray
            Noise at every point, [m^3/s]
        index : ndarray of int
            The points fitted, in time order, [-]

        Returns
        -------
        float
            :func:`~satmotor_ros.identify.transient.variance_inflation`, >= 1, [-]

        """
        if not self.correlated:
            return 1.0
        return variance_inflation((parts.flow[index] - fit.predict(parts, index))
                                  / sigma[index])

    def _significant(self, score: Score, baseline: Score, m: int) -> bool:
        # the weighted figure chooses; the plain error the report gives must fall too
        return (score.p_value < self.alpha / m
                and score.cv_rmse < (1.0 - self.min_gain) * baseline.cv_rmse
                and not score.rmse >= baseline.rmse
                and determined(score.fit))

    def _passes(self, score: Score, baseline: Score, m: int) -> bool:
        return self._significant(score, baseline, m) and not score.fit.pinned(effects_only=True)

    # -- an effect confined to a region of a time series, judged where it acts (.regional)
    def _local(self, score: Score, baseline: Score, sigma: FloatArray,
               index: np.ndarray) -> LocalGain | None:
        at = acting(score.fit.last_modifier().additive, sigma.size)
        if not self.correlated or at is None:
            return None
        return local_gain(at, baseline.cv_error, score.cv_error, sigma, index, self.block)

    def _worse(self, score: Score, baseline: Score, sigma: FloatArray,
               index: np.ndarray) -> bool:
        """
        Return whether a confined candidate's weighted error over every row rises beyond chance.

        Its rows are a few per cent of the recording, and the base's coefficients move with
        it: over the other rows the weighted cross-validated error may rise by a fraction of
        a per cent either way, and the sign of that decides nothing (one row deleted flips
        it). The error rises beyond chance when the baseline's gain over the candidate recurs
        across the blocks (:func:`~.regional.recurrence`, the same one-sided test at
        :data:`~.regional.RECUR_ALPHA`, its false-positive rate).
        """
        if score.cv_rmse < baseline.cv_rmse:
            return False
        return recurrence(score.cv_error, baseline.cv_error, sigma, index,
                          self.block).passes()

    def _confined(self, estimated: Sequence[Score], baseline: Score, sigma: FloatArray,
                  index: np.ndarray, m: int) -> Score | None:
        """Return the best candidate passing every test but the gain, which it has locally."""
        for score in estimated:
            if not (score.p_value < self.alpha / m
                    and not self._worse(score, baseline, sigma, index)
                    and not score.rmse >= baseline.rmse and determined(score.fit)):
                continue
            local = self._local(score, baseline, sigma, index)
            if local is not None and local.passes(self.min_gain):
                return score
        return None

    def _noise(self, parts: LossParts, found: tuple[Candidate, ...], pool: Sequence[Candidate],
               start: FloatArray | None) -> tuple[FloatArray, np.ndarray, list[LossFit]]:
        """
        Estimate the step's noise from its best-fitting model, and the rows it leaves out.

        A row is left out when it is an isolated outlier (:meth:`_isolated`) under the
        best-fitting model and under the model with each candidate: a row that any
        candidate explains stays in every fit of the step.
        """
        floor = 1e-9 * float(np.max(np.abs(parts.flow)))
        everything = np.arange(len(parts))
        plain = LossFit(found).fit(parts, start=start)
        scale = max(robust_scale(parts.flow - plain.predict(parts), plain.n_params), floor)
        base = LossFit(found, scale, HUBER).fit(parts, start=plain.u_)
        scale = max(robust_scale(parts.flow - base.predict(parts), base.n_params), floor)
        # the best-fitting model judged by Tukey's biweight: a candidate that bends to meet
        # one bad row gains nothing by it
        base = LossFit(found, scale, redescending=True).fit(parts, start=base.u_)
        fits = [LossFit((*found, c), scale, redescending=True).fit(
            parts, everything, np.concatenate((base.u_, self._tried.get(id(c), []))))
            for c in pool]
        best = min([base, *fits], key=lambda f: f.objective_)
        residual = parts.flow - best.predict(parts)
        # a time series' rows: the noise may grow with how fast the flow changes (timing)
        sigma = noise_model(residual, parts.flow, best.n_params, floor,
                            rates_of(parts.nuisance))
        left_out = self._isolated(parts, residual, sigma)
        for fit in fits:  # an outlier only if it stays one under each candidate's model
            if not left_out.any():
                break
            left_out &= self._isolated(parts, parts.flow - fit.predict(parts), sigma)
        return sigma, left_out, fits

    def _isolated(self, parts: LossParts, residual: FloatArray,
                  sigma: FloatArray) -> np.ndarray:
        """Flag the outliers that do not cluster (:mod:`.regions`): the rows left out."""
        flagged = outliers(residual, sigma)
        if not flagged.any():
            return flagged
        isolated: np.ndarray = flagged & ~clustered(flagged, residual / sigma,
                                                    self.space(parts))  # numpy types it as Any
        return isolated

    def space(self, parts: LossParts) -> Space:
        """Return where the rows lie (signed drop and speed, and time when given)."""
        if self._space is None or self._space.dp.size != len(parts):
            self._space = Space(parts.sign * parts.dp, parts.rotation * parts.speed)
        return self._space

    def step(self, parts: LossParts, found: tuple[Candidate, ...],
             pool: Sequence[Candidate], start: FloatArray | None,
             recur: bool = False) -> Selection:
        """
        Test every candidate of `pool` on top of the effects `found`, and choose.

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        found : tuple of Candidate
            Effects found in the steps before, [-]
        pool : sequence of Candidate
            Candidates still to test, [-]
        start : ndarray, optional
            The fit of the model with `found`, to start from, [-]
        recur : bool
            Whether an effect chosen over every row must also recur across the blocks of
            the time series (:func:`~.regional.recurrence`): after a valve, [-]

        Returns
        -------
        Selection
            Ranking, choice, runner-up and the reason.

        """
        sigma, left_out, first = self._noise(parts, found, pool, start)
        index = np.flatnonzero(~left_out)
        baseline = self.score(parts, found, sigma, index, start)
        scores = [self.score(parts, (*found, c), sigma, index, f.u_, baseline)
                  for c, f in zip(pool, first)]
        for c, s_ in zip(pool, scores):  # the next step starts each candidate where it ended
            self._tried[id(c)] = s_.fit.u_[-1 - len(c.shape):]
        ranking = tuple(sorted(scores, key=lambda s: s.cv_rmse))
        m = max(len(pool), 1)
        estimated = [s for s in ranking if not s.fit.pinned(effects_only=True)]
        # refused: a candidate ahead of every estimated one, which the tests would have chosen
        # had its fit not ended on a bound
        limit = estimated[0].cv_rmse if estimated else np.inf
        refused = tuple(s for s in ranking if s not in estimated and s.cv_rmse < limit
                        and self._significant(s, baseline, m))
        done = Selection(baseline, ranking, None, None, '', self.alpha, sigma, left_out,
                         refused)
        if not estimated:
            return _with_verdict(done, 'no candidate could be tested' if not ranking else
                                 'none: every candidate ends on a bound of its range'
                                 + _at_bound(refused))
        # a valve that passes every test is not hidden behind a candidate that fails them (a
        # gain that the weighted figure prefers while the plain error rises: it bends to the
        # valve's misses); any other candidate must be the best
        top = estimated[0]
        if not self._passes(top, baseline, m):
            top = next((s for s in estimated if s.effect.startswith('threshold:')
                        and self._passes(s, baseline, m)), top)
        gain = 1.0 - top.cv_rmse / baseline.cv_rmse if baseline.cv_rmse > 0 else 0.0
        if not self._passes(top, baseline, m):
            confined = self._confined(estimated, baseline, sigma, index, m)
            if confined is not None:
                local = self._local(confined, baseline, sigma, index)
                verdict = _local_verdict(confined, baseline, self.alpha, m, local)
                return Selection(baseline, ranking, confined, None, verdict + _at_bound(refused),
                                 self.alpha, sigma, left_out, refused, True)
            return _with_verdict(done, (
                f'{"none" if not found else "no further effect"}: the best candidate, '
                f'{top.label}, cuts the cross-validated error by {100 * gain:.1f} % (need > '
                f'{100 * self.min_gain:.0f} %) with p = {top.p_value:.2g} (need < '
                f'{self.alpha:g}/{m}), its plain RMSE {_plain(baseline, top)} (must fall)'
                + _at_bound(refused)))
        removed = baseline.cv_rmse - top.cv_rmse
        close = [s for s in ranking if self._passes(s, baseline, m) and (
            s.cv_rmse <= (1.0 + self.tie) * top.cv_rmse
            or s.cv_rmse - top.cv_rmse <= self.tie * removed)]
        contenders = [s for s in close if s.cv_rmse <= (1.0 + self.tie) * top.cv_rmse]
        if priority(top.effect) == 2:  # a fitted form bends to anything: a named effect that
            # removes nearly as much goes first (the form stays the runner-up)
            named = [s for s in ranking if priority(s.effect) < 2 and self._passes(s, baseline, m)
                     and s.cv_rmse - top.cv_rmse <= FORM_TIE * removed]
            contenders += named
            close += [s for s in named if s not in close]
        best = min(contenders, key=lambda s: (priority(s.effect), s.cv_rmse))
        # a runner-up also when it removes nearly all the error the winner removes: on data
        # with little noise the two errors left are both tiny and far apart in ratio
        others = [s for s in close if s.effect != best.effect]
        others.sort(key=lambda s: priority(s.effect) != priority(best.effect))
        runner = others[0] if others else None
        gain = 1.0 - best.cv_rmse / baseline.cv_rmse
        if recur:
            again = recurrence(baseline.cv_error, best.cv_error, sigma, index, self.block)
            if again.chance >= RECUR_ALPHA / m:
                return _with_verdict(done, (
                    f'no further effect: the best candidate, {best.label}, cuts the '
                    f'cross-validated error by {100 * gain:.1f} % with p = {best.p_value:.2g}, '
                    f'but after a valve an effect must also recur across the recording: '
                    f'{again.says()} (need < {RECUR_ALPHA:g}/{m})' + _at_bound(refused)))
        verdict = (f'{best.label}: cuts the cross-validated error by {100 * gain:.1f} %, '
                   f'p = {best.p_value:.2g} < {self.alpha:g}/{m}, plain RMSE '
                   f'{_plain(baseline, best)}')
        if runner is not None:
            verdict += _tie(best, runner, baseline)
        if top is not best and priority(top.effect) == 2 and (runner is None
                                                              or runner.effect != top.effect):
            verdict += _tie(best, top, baseline).replace('near tie', 'also near', 1)
        return Selection(baseline, ranking, best, runner, verdict + _at_bound(refused),
                         self.alpha, sigma, left_out, refused)

    def select(self, parts: LossParts, candidates: Sequence[Candidate],
               time: FloatArray | None = None) -> Forward:
        """
        Add effects while the best remaining candidate passes the tests.

        Parameters
        ----------
        parts : LossParts
            Components at the points, [-]
        candidates : sequence of Candidate
            The library built for these data, [-]
        time : ndarray, optional
            Time of each point, where outliers may also cluster, [s]

        Returns
        -------
        Forward
            The steps, the final model and its outliers.

        """
        found: tuple[Candidate, ...] = ()
        steps: list[Selection] = []
        self._tried = {}
        self._space = Space(parts.sign * parts.dp, parts.rotation * parts.speed,
                            None if time is None else np.asarray(time, dtype=float))
        start = None
        valve = False
        while True:
            pool = [c for c in candidates if not any(same_effect(c, f) for f in found)]
            step = self.step(parts, found, pool, start, valve and self.correlated)
            steps.append(step)
            if step.chosen is None:
                break
            found = (*found, step.chosen.added)
            start = step.chosen.fit.u_
            # after a valve (an effect confined to a region, or a threshold), the search goes
            # on, but a form fitted on a few openings moves with the next step's weights (the
            # noise re-estimated without its misses), and any candidate may bend to that: a
            # further effect must recur across the recording's blocks (.regional)
            valve = valve or step.confined or step.chosen.effect.startswith('threshold:')
            if len(found) >= self.max_effects:
                break
        # the model as accepted (the last step only re-weighs it to test what is left)
        accepted = [s.chosen for s in steps if s.chosen is not None]
        final = accepted[-1] if accepted else steps[0].baseline
        residual = parts.flow - final.fit.predict(parts)
        sigma = steps[-1].sigma
        flagged = outliers(residual, sigma)
        return Forward(tuple(steps), final, sigma, self._isolated(parts, residual, sigma),
                       tuple(regions(flagged, residual / sigma, self.space(parts))))


def _near_top(candidate: Candidate) -> Candidate:
    """
    Return a valve candidate started at its last start only (its crack nearest the top).

    A valve cracks near the top of its side's drops (the threshold's starts end there), and
    a valve's fit evaluates it at every sample of a time series, the dearest fit of a step:
    the second fit from the form's own starts tries that one. Other forms keep every start.
    """
    if not candidate.effect.startswith('threshold:'):
        return candidate
    return replace(candidate, shape=tuple(replace(s_, starts=s_.starts[-1:])
                                          for s_ in candidate.shape))


def _guarded(test: np.ndarray, guard: int, n: int) -> np.ndarray:
    """Return a test fold with each of its contiguous runs widened by `guard` positions."""
    if not guard:
        return test
    kept = np.zeros(n, dtype=bool)
    for step in range(-guard, guard + 1):
        kept[np.clip(test + step, 0, n - 1)] = True
    return np.flatnonzero(kept)


def _plain(baseline: Score, score: Score) -> str:
    """Say how a candidate moves the plain out-of-sample RMSE, [l/min]."""
    return f'{baseline.rmse / LPM:.4g} -> {score.rmse / LPM:.4g} l/min'


ENDS_SEARCH = ('the search goes on, and a further effect must also recur across the '
               "recording's blocks (a form fitted on a few openings moves with the next "
               "step's noise weights, and a candidate may bend to that)")
"""What the report says after an effect chosen where it acts."""


def _local_verdict(score: Score, baseline: Score, alpha: float, m: int,
                   local: LocalGain | None) -> str:
    """Say why an effect confined to a region was accepted by its gain where it acts."""
    cut = 1.0 - score.cv_rmse / baseline.cv_rmse
    every = (f'cuts the cross-validated error by {100 * cut:.1f} %' if cut > 0.0 else
             f'raises the cross-validated error by {-100 * cut:.1f} %, within chance')
    return (f'{score.label}: an effect confined to a region: '
            f'{"" if local is None else local.says()}; p = {score.p_value:.2g} < {alpha:g}/{m}; '
            f'over every row it {every}, plain RMSE {_plain(baseline, score)}; {ENDS_SEARCH}')


def _with_verdict(step: Selection, verdict: str) -> Selection:
    return Selection(step.baseline, step.ranking, step.chosen, step.runner_up, verdict,
                     step.alpha, step.sigma, step.left_out, step.refused)


def at_bound(score: Score) -> str:
    """
    Say which of a candidate's parameters ended on a bound of its range.

    Parameters
    ----------
    score : Score
        A candidate whose fit left an effect's parameter on a bound, [-]

    Returns
    -------
    str
        E.g. ``'flow_sensor_gain(flow) at its bound -0.5'`` or ``'term:dp^0.05*n (term:dp^a*n^b
        dp exponent at its bound 0.05)'``.

    """
    pinned = score.fit.pinned(effects_only=True)
    own = [f'at its bound {bound:.4g}' for name, bound in pinned if name == score.added.label]
    other = [f'{name} at its bound {bound:.4g}' for name, bound in pinned
             if name != score.added.label]
    return ' '.join([score.label, *own] + ([f'({", ".join(other)})'] if other else []))


def _at_bound(refused: Sequence[Score]) -> str:
    """Say which candidates were refused because their fit ended on a bound."""
    if not refused:
        return ''
    return ('; refused, not an estimate (the data ask for a value beyond the range): '
            + '; '.join(at_bound(s) for s in refused))


def _tie(best: Score, runner: Score, baseline: Score) -> str:
    """Say that two effects explain the data almost equally well, and what that means."""
    runner_gain = 1.0 - runner.cv_rmse / baseline.cv_rmse
    text = (f'; near tie with {runner.label} (cross-validated error '
            f'{100 * (runner.cv_rmse / best.cv_rmse - 1):+.1f} %, it cuts the error by '
            f'{100 * runner_gain:.1f} %): the data barely tell them apart')
    kinds = {priority(best.effect), priority(runner.effect)}
    sensor = [s.label for s in (best, runner) if s.effect.endswith(('sensor_gain',
                                                                   'sensor_offset'))]
    if sensor and 2 in kinds:
        form = best if priority(best.effect) == 2 else runner
        text += (f', so an instrument error ({sensor[0]}) and a loss of the motor '
                 f'({form.label}) explain the data equally well: check the instrument '
                 f'against a reference before recalibrating it')
    elif priority(runner.effect) > priority(best.effect):
        text += ', and a named physical effect goes before a generic term'
    return text
