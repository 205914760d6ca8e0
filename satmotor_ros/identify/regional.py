# SPDX-License-Identifier: Apache-2.0
"""
An effect confined to a region of a recording, judged where it acts: the local gain.

A relief valve that opens in one direction at the top of the drop acts on a few per cent
of a recording's rows; how many depends on how long the recording idles elsewhere, not on
the valve. Its cut of the cross-validated error over every row is diluted by that share, so
the global least gain (``min_gain``) refuses a valve that removes a tenth of the error where
it opens. An effect whose extra loss is exactly zero outside a region (:func:`acting`) is
therefore judged, on a time series, by its out-of-sample gain over the rows where it acts:
both figures (noise-weighted and plain) must fall there by ``min_gain``, and the gain must
recur: the rows fall in separate events (runs of rows apart by more than a cross-validation
block, so each event is out of sample in its own fold, and the residuals of two events are
not correlated), and the plain error must fall in so many of them that chance (a sign test:
each event better or worse with probability 1/2) gives as many with probability below
:data:`RECUR_ALPHA`: 5 events of 5, 6 of 6 or 7 of 8 at least. A threshold that bends to the
transients at the start of a few moves improves some and worsens others; a valve opens every
time the drop passes its crack.
The global tests still hold (the F-test with the variance inflation, the plain error over
every row must not rise), and the weighted error over every row must not rise beyond chance:
the base's coefficients move with the effect, so over the other rows that error moves by a
fraction of a per cent either way, and its sign alone would turn on one row; it fails when
the baseline's gain over the candidate recurs across the blocks (:func:`recurrence`, one-sided
at :data:`RECUR_ALPHA`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from satmotor_ros.identify.fit import huber_rho
from satmotor_ros.model._typing import FloatArray
from scipy import special

RECUR_ALPHA = 0.05
"""Significance of the sign test over the events where the out-of-sample error falls, [-]."""

CONFINED = 0.25
"""Largest share of the rows a confined effect acts on, [-]."""


@dataclass(frozen=True)
class LocalGain:
    """A confined candidate's out-of-sample gain over the rows where it acts."""

    rows: int  # rows fitted where the effect acts [-]
    events: int  # separate runs of those rows [-]
    improved: int  # events where the out-of-sample error falls [-]
    weighted: float  # relative cut of the noise-weighted (Huber) error there [-]
    plain: float  # relative cut of the plain RMSE there [-]

    @property
    def chance(self) -> float:
        """Return the chance of at least as many improved events of as many at random, [-]."""
        if self.improved <= 0:
            return 1.0
        return float(special.bdtrc(self.improved - 1, self.events, 0.5))

    def passes(self, min_gain: float) -> bool:
        """Return whether both cuts reach `min_gain` and the gain recurs across events."""
        return (self.chance < RECUR_ALPHA and self.weighted >= min_gain
                and self.plain >= min_gain)

    def says(self) -> str:
        """Say the local gain, one clause."""
        return (f'where it acts ({self.rows} rows in {self.events} events) it cuts the '
                f'cross-validated error by {100 * self.weighted:.1f} % (plain '
                f'{100 * self.plain:.1f} %), in {self.improved} of the {self.events} events '
                f'(by chance: {self.chance:.2g})')


def acting(additive: FloatArray | float, n: int) -> np.ndarray | None:
    """
    Return the rows where an effect's extra loss is not zero, if that is a small region.

    Parameters
    ----------
    additive : ndarray or float
        The effect's extra loss at every row (a modifier's ``additive``), [m^3/s]
    n : int
        Rows, [-]

    Returns
    -------
    ndarray of bool or None
        Where it acts, when that is at most :data:`CONFINED` of the rows and not none;
        None otherwise (an effect that acts everywhere is judged over every row).

    """
    if np.ndim(additive) == 0:
        return None
    at = np.asarray(np.asarray(additive) != 0.0, dtype=bool)
    if at.shape != (n,) or not 0 < int(at.sum()) <= CONFINED * n:
        return None
    return at


def _weighted_rho(error: FloatArray, sigma: FloatArray) -> FloatArray:
    """Return Huber's 2 rho of errors standardised by the noise, back in their units, [-]."""
    return huber_rho(error / sigma) * sigma * sigma


def local_gain(at: np.ndarray, base_error: FloatArray, error: FloatArray, sigma: FloatArray,
               index: np.ndarray, block: int) -> LocalGain:
    """
    Return the out-of-sample gain of a candidate over the rows where it acts.

    Parameters
    ----------
    at : ndarray of bool
        Where the candidate acts, at every row, [-]
    base_error, error : ndarray
        Out-of-sample errors of the baseline and of the candidate at every row, [m^3/s]
    sigma : ndarray
        Noise at every row, [m^3/s]
    index : ndarray of int
        The rows fitted, in time order, [-]
    block : int
        Rows of a cross-validation block: runs farther apart are separate events, [-]

    Returns
    -------
    LocalGain
        Rows, events, improved events and the two relative cuts.

    """
    where = np.flatnonzero(at[index])  # positions among the rows fitted
    if not where.size:
        return LocalGain(0, 0, 0, 0.0, 0.0)
    rows = index[where]
    s = sigma[rows]
    before = _weighted_rho(base_error[rows], s)
    after = _weighted_rho(error[rows], s)
    cut = np.split(np.arange(where.size), np.flatnonzero(np.diff(where) > max(block, 1)) + 1)
    # an event's few rows: whether the flow as read is predicted better (the noise model,
    # fitted to the whole recording, weighs a handful of rows by little more than chance)
    squared = (base_error[rows] ** 2, error[rows] ** 2)
    improved = sum(int(squared[1][c].sum() < squared[0][c].sum()) for c in cut)
    weighted = 1.0 - float(np.sqrt(after.sum() / max(before.sum(), 1e-300)))
    plain = 1.0 - float(np.sqrt(np.sum(error[rows] ** 2)
                                / max(float(np.sum(base_error[rows] ** 2)), 1e-300)))
    return LocalGain(int(rows.size), len(cut), improved, weighted, plain)


@dataclass(frozen=True)
class Recurrence:
    """A candidate's out-of-sample gain block by block over a time series (Diebold-Mariano)."""

    blocks: int  # cross-validation blocks with rows fitted [-]
    improved: int  # blocks whose noise-weighted error falls [-]
    t: float  # mean cut of a block's weighted error over its standard error [-]

    @property
    def chance(self) -> float:
        """Return the one-sided chance of a mean cut at least as large at random, [-]."""
        if self.blocks < 2 or not np.isfinite(self.t):
            return 1.0
        return float(special.stdtr(self.blocks - 1, -self.t))

    def passes(self) -> bool:
        """Return whether the cut recurs: its chance is below :data:`RECUR_ALPHA`."""
        return self.chance < RECUR_ALPHA

    def says(self) -> str:
        """Say the recurrence, one clause."""
        return (f'its out-of-sample gain recurs in {self.improved} of {self.blocks} blocks '
                f'(t = {self.t:.2f}, by chance: {self.chance:.2g})')


def recurrence(base_error: FloatArray, error: FloatArray, sigma: FloatArray,
               index: np.ndarray, block: int) -> Recurrence:
    """
    Return whether a candidate's out-of-sample gain recurs over the blocks of a time series.

    The rows fitted are cut, in time order, into the cross-validation blocks (each held out
    in its own fold, a few correlation times of the residuals long, so the blocks' figures
    are nearly independent); a block's figure is its noise-weighted (Huber) error under the
    baseline minus under the candidate, and the mean of those over its standard error is a
    t statistic with blocks - 1 degrees of freedom (the Diebold-Mariano test of two
    forecasts, on blocks). An effect of the motor or of a sensor cuts the error wherever it
    acts, recording after recording; a form that bends to a few slow swings of the noise
    cuts it in some blocks and raises it in others.

    Parameters
    ----------
    base_error, error : ndarray
        Out-of-sample errors of the baseline and of the candidate at every row, [m^3/s]
    sigma : ndarray
        Noise at every row, [m^3/s]
    index : ndarray of int
        The rows fitted, in time order, [-]
    block : int
        Rows of a cross-validation block, [-]

    Returns
    -------
    Recurrence
        Blocks, improved blocks and the t statistic.

    """
    rows = np.asarray(index)
    s = sigma[rows]
    cut = _weighted_rho(base_error[rows], s) - _weighted_rho(error[rows], s)
    edges = np.arange(0, rows.size, max(block, 1))
    sums = np.add.reduceat(cut, edges) if rows.size else np.zeros(0)
    if sums.size < 2:
        return Recurrence(int(sums.size), int(np.sum(sums > 0.0)), np.nan)
    spread = float(np.std(sums, ddof=1))
    t = float(np.mean(sums)) / (spread / np.sqrt(sums.size)) if spread > 0.0 else (
        np.inf if np.mean(sums) > 0.0 else np.nan)
    return Recurrence(int(sums.size), int(np.sum(sums > 0.0)), t)


__all__ = ['CONFINED', 'LocalGain', 'RECUR_ALPHA', 'Recurrence', 'acting', 'local_gain',
           'recurrence']
