# SPDX-License-Identifier: Apache-2.0
"""
What changed: the calibration loop's candidates on the samples since a change and before it.

The samples on each side of the change (at most :data:`MOST_SAMPLES` each, spread evenly)
go through the calibration's own machinery, unchanged: the baseline's loss components at
every sample (:func:`~satmotor_ros.identify.parts.loss_parts`), the candidate library built
for those data (:func:`~satmotor_ros.identify.candidates.build_library`) and the
cross-validated forward selection with time-ordered blocked folds
(:class:`~satmotor_ros.identify.selection.CrossValidatedSelector`). An effect the samples
since the change ask for and those before do not is what changed.

That selection guards calibration against effects the data do not need, so on a change of
some per cent of the losses it often asks for nothing. The change is known to be there,
though (the alarm), so the explanations are then weighed against each other
(:func:`_contrast`): the samples of both sides in one least-squares fit, the model's
components scaled by factors both sides share, plus one explanation acting since the change
only: either a component's factor moving (a wear of that loss) or a named kind of the
candidate library (its first-order change of the prediction, by the kind's own modifier: a
leak to the case, a sensor's gain or offset). The explanation with the least residual is
named when it beats the next by a likelihood ratio of 20 (residual sums of squares
2 ln 20 residual variances apart, the variance inflated by the residuals' correlation, from
batch means); when it does not, both are named, as fitting alike; when none beats no
change by the 99 % chi-square point, the change is ``unexplained``.
"""

from __future__ import annotations

from dataclasses import replace
import math

import numpy as np

from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.fit import MIN_POINTS
from satmotor_ros.identify.health.baseline import Baseline
from satmotor_ros.identify.health.noise import fit_variance
from satmotor_ros.identify.health.records import HealthSamples
from satmotor_ros.identify.parts import loss_parts, LossParts, NO_EFFECT, predict_flow
from satmotor_ros.identify.selection import CrossValidatedSelector, Forward, Score
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import Candidate
from satmotor_ros.model.units import LPM

GAINS = ('flow_sensor_gain', 'speed_sensor_gain')
"""Two kinds that tie where the flow follows the speed: named together when they do."""

MOST_SAMPLES = 3000
"""Samples each side is cut to (evenly spread): the selection's cost grows with them."""

BLOCK_SECONDS = 2.0
"""Length of a cross-validation block, as calibration uses on a time series, [s]."""

WORDS = {'external_leakage': 'leak (external leakage)', 'clearance_wear': 'wear (clearances)',
         'leakage_wear': 'wear (leakage)', 'flow_sensor_gain': 'flow sensor gain',
         'flow_sensor_offset': 'flow sensor offset', 'speed_sensor_gain': 'speed sensor gain',
         'threshold': 'valve (a flow above a pressure threshold)'}
"""Effect kind -> how the monitor names it (the kind's id follows in brackets)."""

CONTRASTED = ('external_leakage', 'flow_sensor_gain', 'flow_sensor_offset', 'speed_sensor_gain')
"""Kinds :func:`_contrast` weighs beside the components' own factors (a wear is a component's
factor moving; a kind with a shape to fit, a threshold, is left to the selection)."""

SIGNED = CONTRASTED
"""Kinds named with the way they moved (:func:`_signed`): a leak, a sensor's gain or offset."""

DECISIVE = 2.0 * math.log(20.0)
"""Residual variances by which the best explanation must beat the next, [-]."""

BATCH = 40
"""Consecutive residuals per batch of :func:`_inflation` (10 s at the monitor's 4 Hz)."""

SIGNIFICANT = 6.635
"""Residual variances by which it must beat no change: chi-square, 1 dof, 99 %, [-]."""


def _keep(samples: HealthSamples, most: int = MOST_SAMPLES) -> np.ndarray:
    """Return the rows a side is cut to: at most `most` with a flow, spread evenly."""
    keep = np.flatnonzero(np.isfinite(samples.flow))
    if keep.size > most:
        keep = keep[np.linspace(0, keep.size - 1, most).astype(int)]
    return keep


def _table(samples: HealthSamples, baseline: Baseline, most: int = MOST_SAMPLES) -> BenchTable:
    keep = _keep(samples, most)
    channels = {'time': samples.time[keep]}
    if samples.temperature is not None:
        channels['temperature'] = samples.temperature[keep]
    if 'p_case' in baseline.model.channels or samples.p_case is not None:
        channels['p_case'] = (samples.p_out if samples.p_case is None else samples.p_case)[keep]
    return BenchTable(samples.speed[keep], samples.flow[keep], samples.p_in[keep],
                      samples.p_out[keep], channels, time_series=True)


def _select(samples: HealthSamples, baseline: Baseline) -> tuple[Forward, tuple[str, ...]]:
    """Run the forward selection on one side; return it and the factor names."""
    table = _table(samples, baseline)
    model = baseline.model
    bare = type(model)(model.geometry, replace(model.coefficient_set, effects=()),
                       model.valid_range, model.liquid, model.displacement_law, model.name)
    parts, usable = loss_parts(bare, table)
    points = table.select(usable)
    if len(points) < 4 * MIN_POINTS:
        msg = f'{len(points)} usable samples on one side of the change'
        raise IdentificationError(msg)
    channels = {**points.channels, 'p_in': points.p_in, 'p_out': points.p_out}
    candidates, _ = build_library(parts, channels, baseline.law, model.family.name)
    time = points.channels['time']
    step = float(np.median(np.diff(time))) if time.size > 1 else 1.0
    block = max(3, int(np.ceil(BLOCK_SECONDS / max(step, 1e-6))))
    selector = CrossValidatedSelector(time_ordered=True, correlated=True, block=block,
                                      guard=1, max_effects=1)
    return selector.select(parts, candidates, time), parts.names


def explain_change(before: HealthSamples, after: HealthSamples, baseline: Baseline) -> str:
    """
    Name the effect that tells the samples since a change from those before it.

    Parameters
    ----------
    before : HealthSamples
        Samples before the change, [-]
    after : HealthSamples
        Samples since the change, [-]
    baseline : Baseline
        The healthy motor, [-]

    Returns
    -------
    str
        The effect's name, or ``'unexplained'``.

    """
    try:
        fwd_before, _ = _select(before, baseline)
        fwd_after, _ = _select(after, baseline)
    except IdentificationError:
        return 'unexplained'
    known = {score.effect for score in fwd_before.found}
    for step in fwd_after.steps:
        score = step.chosen
        if score is None or score.effect in known:
            continue
        kind = _kind(score)
        word = _signed(kind, _coefficient(score))
        runner = step.runner_up
        if runner is not None and {kind, _kind(runner)} == set(GAINS):
            # a flow gain and a speed gain fit alike where the flow follows the speed
            word = _gain_tie({kind: _coefficient(score), _kind(runner): _coefficient(runner)})
        if word == 'unexplained':
            return word
        return f'{word} [{score.label}]'
    return _contrast(before, after, baseline)


def _coefficient(score: Score) -> float:
    """Return the coefficient a score fitted for its effect (NaN if it holds none)."""
    try:
        return float(score.fit.found()[-1][1].coefficient)
    except (IndexError, AttributeError, TypeError, ValueError, IdentificationError):
        return math.nan


def _signed(kind: str, value: float) -> str:
    """
    Name an effect with the way it moved since the change (review of issue 23, F5).

    A leak or a sensor error has a sign: a leak that grows and one that shrinks (a seal
    seating again) are different news, and so are a flowmeter reading high or low. The
    coefficient is the change since the change (:func:`_contrast`), or the effect the samples
    since it ask for and those before do not; its sign says which way. Without a sign (NaN,
    0) the effect is not named at all: ``unexplained``.
    """
    word = WORDS.get(kind, kind)
    if kind not in SIGNED:
        return word
    if not (math.isfinite(value) and value != 0.0):
        return 'unexplained'
    way = 'up' if value > 0 else 'down'
    if kind in GAINS:
        return f'{word} {way} {abs(value) * 100:.2g} %'
    if kind == 'flow_sensor_offset':
        return f'{word} {way} {abs(value) / LPM:.2g} l/min'
    return f'{word} {way}'


def _gain_tie(values: dict[str, float]) -> str:
    """Name a flow and a speed gain that fit alike, each with its way (they move opposite)."""
    ways = [_signed(kind, values[kind]).removeprefix(WORDS[kind]).strip() for kind in GAINS]
    if 'unexplained' in ways:
        return 'unexplained'
    return f'flow or speed sensor gain (they fit alike here: flow {ways[0]} / speed {ways[1]})'


def _kind(score: Score) -> str:
    """Return the effect kind a score added."""
    effect = score.candidate.effect if score.candidate is not None else score.effect
    return effect.split(':')[0]


def _contrast(before: HealthSamples, after: HealthSamples, baseline: Baseline) -> str:
    """Weigh the explanations of the change on both sides at once; name the best."""
    def join(name: str) -> FloatArray:
        return np.concatenate([getattr(before, name), getattr(after, name)])

    both = HealthSamples(join('time'), join('speed'), join('flow'), join('p_in'),
                         join('p_out'), _joined(before.p_case, after.p_case),
                         _joined(before.temperature, after.temperature))
    table = _table(both, baseline, 2 * MOST_SAMPLES)
    x = baseline.displacement * both.speed
    dt = np.diff(both.time, prepend=np.nan)
    with np.errstate(invalid='ignore', divide='ignore'):
        rate = np.abs(np.diff(x, prepend=np.nan) / dt)
    rate = np.where(np.isfinite(rate) & (dt > 0), rate, 0.0)[_keep(both, 2 * MOST_SAMPLES)]
    model = baseline.model
    bare = type(model)(model.geometry, replace(model.coefficient_set, effects=()),
                       model.valid_range, model.liquid, model.displacement_law, model.name)
    try:
        parts, usable = loss_parts(bare, table)
    except IdentificationError:
        return 'unexplained'
    since = (table.channels['time'] >= after.time[0])[usable] if len(after) else usable[usable]
    if min(int(since.sum()), int((~since).sum())) < 4 * MIN_POINTS:
        return 'unexplained'
    rate = rate[usable]
    points = table.select(usable)
    channels = {**points.channels, 'p_in': points.p_in, 'p_out': points.p_out}
    candidates, _ = build_library(parts, channels, baseline.law, model.family.name)
    shared = np.column_stack([c.flow(NO_EFFECT) for c in parts.components])
    y = parts.flow - parts.displacement
    # each sample weighed by its noise, as the monitor does (:mod:`.noise`), fitted before
    a, b = fit_variance(rate[~since], (y - shared.sum(axis=1))[~since])
    root = 1.0 / np.sqrt(a + b * rate ** 2)
    shared, y = shared * root[:, None], y * root
    columns = {f'wear: the {c.name.removesuffix("_scale")} part of the losses': shared[:, j]
               for j, c in enumerate(parts.components)}
    kinds = {f'{WORDS[_kind_of(c)]} [{c.label}]': _kind_of(c)
             for c in candidates if _kind_of(c) in CONTRASTED and not c.shape}
    columns.update({name: _first_order(parts, c) * root for name, c in zip(kinds, (
        c for c in candidates if _kind_of(c) in CONTRASTED and not c.shape))})
    rss0, _, _ = _lsq(shared, y)
    fits = {name: _lsq(np.column_stack([shared, np.where(since, x, 0.0)]), y)
            for name, x in columns.items()
            if np.all(np.isfinite(x)) and np.any(x[since] != 0.0)}
    if not fits:
        return 'unexplained'
    ranked = sorted(fits, key=lambda name: fits[name][0])
    best_rss, coef, residual = fits[ranked[0]]
    variance = best_rss / max(residual.size - shared.shape[1] - 1, 1) * _inflation(residual)
    if not (rss0 - best_rss) / variance >= SIGNIFICANT:
        return 'unexplained'
    named = _named(ranked[0], coef, list(columns), kinds)
    if len(ranked) > 1 and (fits[ranked[1]][0] - best_rss) / variance < DECISIVE:
        if {kinds.get(name) for name in ranked[:2]} == set(GAINS):
            label = ranked[0].partition(' [')[2].removesuffix(']')
            tie = _gain_tie({kinds[name]: float(fits[name][1][-1]) for name in ranked[:2]})
            return tie if tie == 'unexplained' else f'{tie} [{label}]'
        second = _named(ranked[1], fits[ranked[1]][1], list(columns), kinds)
        if 'unexplained' in (named, second):
            return 'unexplained'
        return f'{named} or {second} (they fit alike here)'
    return named


def _inflation(residual: FloatArray) -> float:
    """
    Return the residuals' long-run variance over their variance, by batch means, [-].

    Correlated noise (a flowmeter's slow wander, a log's timing jitter) makes a sum of
    squares worth fewer independent samples: the variance of the means of
    :data:`BATCH` consecutive residuals, times BATCH, over the residuals' variance (at
    least 1).
    """
    batches = residual.size // BATCH
    if batches < 10 or not np.var(residual) > 0:
        return 1.0
    means = residual[:batches * BATCH].reshape(batches, BATCH).mean(axis=1)
    return max(1.0, float(BATCH * np.var(means) / np.var(residual)))


def _joined(a: FloatArray | None, b: FloatArray | None) -> FloatArray | None:
    return None if a is None or b is None else np.concatenate([a, b])


def _kind_of(candidate: Candidate) -> str:
    return candidate.effect.split(':')[0]


def _first_order(parts: LossParts, candidate: Candidate) -> FloatArray:
    """Return d(prediction)/d(coefficient) at 0 by the kind's own modifier, [m^3/s per unit]."""
    ones = np.ones(len(parts.components))
    step = candidate.typical * 1e-3  # a thousandth of a l/min at the largest
    moved = predict_flow(parts, ones, candidate.modify(step))
    return np.asarray((moved - predict_flow(parts, ones)) / step, dtype=float)


def _lsq(design: FloatArray, y: FloatArray) -> tuple[float, FloatArray, FloatArray]:
    """Return the residual sum of squares, the coefficients and the residuals of y ~ design."""
    scale = np.max(np.abs(design), axis=0)
    scale[scale == 0] = 1.0
    coef, *_ = np.linalg.lstsq(design / scale, y, rcond=None)
    coef = coef / scale
    residual = y - design @ coef
    return float(residual @ residual), coef, residual


def _named(name: str, coef: FloatArray, names: list[str], kinds: dict[str, str]) -> str:
    """Give a component's wear the factor it moved by (since over before), a kind its way."""
    if not name.startswith('wear: '):
        signed = _signed(kinds[name], float(coef[-1]))
        label = name.partition(' [')[2]
        return signed if signed == 'unexplained' else f'{signed} [{label}'
    before = coef[names.index(name)]
    ratio = (before + coef[-1]) / before if before else math.inf
    word = name if ratio >= 1.0 else name.replace('wear', 'recovery', 1)
    # the factor of one part of the losses, not of all of them (the alarm's before and
    # after give that): a small part may grow several times for a change of some per cent
    return f'{word} x{ratio:.2f}'


__all__ = ['explain_change', 'MOST_SAMPLES', 'WORDS']
