# SPDX-License-Identifier: Apache-2.0
"""
What changed: the calibration loop's candidates on the samples since a change and before it.

The samples on each side of the change (at most :data:`MOST_SAMPLES` each, spread evenly)
go through the calibration's own machinery, unchanged: the baseline's loss components at
every sample (:func:`~satmotor_ros.identify.parts.loss_parts`), the candidate library built
for those data (:func:`~satmotor_ros.identify.candidates.build_library`) and the
cross-validated forward selection with time-ordered blocked folds
(:class:`~satmotor_ros.identify.selection.CrossValidatedSelector`). An effect the samples
since the change ask for and those before do not is what changed. When neither side asks
for an effect, the components' fitted factors are compared: one that moved beyond both
sides' 95 % intervals names a change of that loss (a wear of the clearances scales the
leakage). Otherwise the change is ``unexplained``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.fit import MIN_POINTS
from satmotor_ros.identify.health.baseline import Baseline
from satmotor_ros.identify.health.records import HealthSamples
from satmotor_ros.identify.parts import loss_parts
from satmotor_ros.identify.selection import CrossValidatedSelector, Forward, Score
from satmotor_ros.identify.table import BenchTable

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


def _table(samples: HealthSamples, baseline: Baseline) -> BenchTable:
    keep = np.flatnonzero(np.isfinite(samples.flow))
    if keep.size > MOST_SAMPLES:
        keep = keep[np.linspace(0, keep.size - 1, MOST_SAMPLES).astype(int)]
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
        fwd_before, names = _select(before, baseline)
        fwd_after, _ = _select(after, baseline)
    except IdentificationError:
        return 'unexplained'
    known = {score.effect for score in fwd_before.found}
    for step in fwd_after.steps:
        score = step.chosen
        if score is None or score.effect in known:
            continue
        word = WORDS.get(_kind(score), _kind(score))
        runner = step.runner_up
        if runner is not None and {_kind(score), _kind(runner)} == set(GAINS):
            # a flow gain and a speed gain fit alike where the flow follows the speed
            word = 'flow or speed sensor gain (they fit alike here)'
        return f'{word} [{score.label}]'
    return _factors(fwd_before, fwd_after, names)


def _kind(score: Score) -> str:
    """Return the effect kind a score added."""
    effect = score.candidate.effect if score.candidate is not None else score.effect
    return effect.split(':')[0]


def _factors(before: Forward, after: Forward, names: tuple[str, ...]) -> str:
    """Name the component whose factor moved beyond both intervals, or 'unexplained'."""
    try:
        a, b = before.final.fit.report(), after.final.fit.report()
    except IdentificationError:
        return 'unexplained'
    best, best_ratio = '', 1.0
    for i, name in enumerate(names):
        lo_a, hi_a = a.ci95[i]
        lo_b, hi_b = b.ci95[i]
        apart = lo_b > hi_a or hi_b < lo_a
        ratio = float(b.values[i] / a.values[i]) if a.values[i] else np.inf
        if apart and abs(np.log(ratio)) > abs(np.log(best_ratio)):
            best, best_ratio = name, ratio
    if not best:
        return 'unexplained'
    word = 'wear' if best_ratio > 1.0 else 'recovery'
    # the factor of one part of the losses, not of all of them (the alarm's before and
    # after give that): a small part may grow several times for a change of some per cent
    return f'{word}: the {best.removesuffix("_scale")} part of the losses x{best_ratio:.2f}'


__all__ = ['explain_change', 'MOST_SAMPLES', 'WORDS']
