# SPDX-License-Identifier: Apache-2.0
"""
What a calibrated valve passes at the top of the drop, and where its law outruns the data.

A valve's law k max(0, |dp| - x_c)^e is fitted on rows (a time series' bins of 0.2 s): at the
highest drop of the rows it is an estimate, but the samples reach higher drops than their
bins' means (a pressure that peaks as a move starts), and a steep law read there can give
more flow than the whole flow measured: a relief cannot pass more than its supply. The
report and ``calibration.json`` (``full_drop`` of a valve's entry) therefore give both: the
law at the rows' highest drop on the valve's side, and at the data's highest drop, with the
flow measured there, whether it lies beyond the fitted range (where the model flags
EXTRAPOLATED) and how many samples of its side measured less flow than the law gives.

The law is not capped in the fit: the prediction of the measured flow may not read the
measurement. Given the flow instead (the inverse map, :mod:`satmotor_ros.model.engine.valves`),
the model solves V = V(dp(Q - V)), which never passes more than Q.
"""

from __future__ import annotations

from typing import Any, TYPE_CHECKING

import numpy as np

from satmotor_ros.identify.fit import written
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import Effect, kind_of
from satmotor_ros.model.engine.screening import fitted_bounds
from satmotor_ros.model.units import LPM, MPA

if TYPE_CHECKING:  # pragma: no cover - for the annotations only
    from satmotor_ros.identify.pipeline import Calibration


def _side(effect: Effect, dp: FloatArray) -> np.ndarray:
    """Return which drops lie on the valve's side (dp < 0 for 'negative', dp >= 0 'positive')."""
    negative = np.asarray(dp, dtype=float) < 0.0
    if effect.direction == 'both':
        return np.ones(negative.shape, dtype=bool)
    return negative if effect.direction == 'negative' else ~negative


def _law(effect: Effect, dp: FloatArray) -> FloatArray:
    """Return the valve's flow at port drops `dp` (any sign), [m^3/s]."""
    loss = kind_of(effect).loss(effect)
    assert loss is not None  # a bypass kind has a law
    return np.asarray(loss(np.zeros_like(dp), np.asarray(dp, dtype=float)), dtype=float)


def full_drop(effect: Effect, row_dp: FloatArray, sample_dp: FloatArray,
              sample_flow: FloatArray) -> dict[str, Any]:
    """
    Read a valve's law at the rows' and the data's highest drop of its side.

    Parameters
    ----------
    effect : Effect
        The valve (a bypass kind) with its fitted range, [-]
    row_dp : ndarray
        Port drop p_in - p_out of the rows it was fitted on (the inliers), [Pa]
    sample_dp, sample_flow : ndarray
        Port drop and measured flow of every sample used (the rows themselves for steady
        points), [Pa], [m^3/s]

    Returns
    -------
    dict
        ``fitted_dp_mpa`` and ``fitted_flow_lpm`` (the law at the rows' highest |dp| of its
        side), ``data_dp_mpa``, ``flow_lpm`` and ``measured_flow_lpm`` (at the sample of the
        highest |dp| of its side: the law, and |flow| measured there), ``extrapolated``
        (that drop lies beyond the fitted range: the model flags it EXTRAPOLATED) and
        ``above_measured`` (samples of its side where the law gives more than the |flow|
        measured, which no valve can pass) with ``above_measured_from_mpa`` (the least |dp|
        of them, or None); empty when no row or sample lies on its side.

    """
    rows = np.abs(np.asarray(row_dp, dtype=float)[_side(effect, row_dp)])
    on = _side(effect, sample_dp)
    drop = np.abs(np.asarray(sample_dp, dtype=float)[on])
    flow = np.abs(np.asarray(sample_flow, dtype=float)[on])
    if not rows.size or not drop.size:
        return {}
    top = int(np.argmax(drop))
    law = _law(effect, drop)
    above = law > flow
    high = {q: hi for q, _, hi in fitted_bounds(effect.fitted_range)}.get('dp')
    return {
        'fitted_dp_mpa': written(float(np.max(rows)) / MPA),
        'fitted_flow_lpm': written(float(_law(effect, np.array([np.max(rows)]))[0]) / LPM),
        'data_dp_mpa': written(float(drop[top]) / MPA),
        'flow_lpm': written(float(law[top]) / LPM),
        'measured_flow_lpm': written(float(flow[top]) / LPM),
        'extrapolated': bool(high is not None and drop[top] > high),
        'above_measured': int(np.count_nonzero(above)),
        'above_measured_from_mpa': written(float(np.min(drop[above])) / MPA)
        if above.any() else None,
    }


def valve_reach(cal: Calibration, effect: Effect) -> dict[str, Any]:
    """
    Return ``{'full_drop': ...}`` for a valve of a calibration (:func:`full_drop`), else {}.

    Parameters
    ----------
    cal : Calibration
        The result: its rows (the inliers) and, on a time series, its samples, [-]
    effect : Effect
        One of its effects, with its fitted range, [-]

    Returns
    -------
    dict
        ``{'full_drop': {...}}`` for a bypass kind with data on its side; {} otherwise.

    """
    if not kind_of(effect).bypass:
        return {}
    row_dp = (cal.parts.sign * cal.parts.dp)[cal.inliers]
    s = cal.samples
    if s is None:
        sample_dp, sample_flow = cal.table.dp, cal.table.flow
    else:
        at = np.asarray(s.in_bins, dtype=bool)
        sample_dp, sample_flow = s.samples.dp[at], s.samples.flow[at]
    reach = full_drop(effect, row_dp, sample_dp, sample_flow)
    return {'full_drop': reach} if reach else {}


def says(entry: dict[str, Any]) -> str:
    """
    Say in one sentence what a valve's entry of ``calibration.json`` passes at full drop.

    Parameters
    ----------
    entry : dict
        An entry of ``effects`` with ``name`` and ``full_drop``, [-]

    Returns
    -------
    str
        The sentence ('' without ``full_drop``).

    """
    f = entry.get('full_drop')
    if not f:
        return ''
    text = (f"`{entry['name']}` passes {f['fitted_flow_lpm']:.3g} l/min at the highest drop of "
            f"the rows it was fitted on ({f['fitted_dp_mpa']:.4g} MPa); at the data's highest "
            f"drop on its side ({f['data_dp_mpa']:.4g} MPa, one sample) its law gives "
            f"{f['flow_lpm']:.3g} l/min where {f['measured_flow_lpm']:.3g} l/min were measured")
    if f['extrapolated']:
        text += ', beyond the fitted range (extrapolated: the model flags it)'
    if f['above_measured']:
        text += (f". **At {f['above_measured']} sample(s) of its side (from "
                 f"{f['above_measured_from_mpa']:.4g} MPa) the law gives more than the whole "
                 'flow measured**, which no valve can pass (a relief passes at most its supply): '
                 'there it does not hold')
    return text


__all__ = ['full_drop', 'says', 'valve_reach']
