# SPDX-License-Identifier: Apache-2.0
"""
Outliers that cluster: a region of the operating space the model misses, not bad rows.

A robust fit that drops every point beyond a few noise levels also drops an effect that
lives in a corner of the operating space (a relief valve that opens at the top of the
drop in one direction, a leak in one speed band, a transient in one time span). A bad
row is isolated: its neighbours fit. So an outlier counts as *clustered* when, among its
:data:`NEIGHBOURS` nearest rows in the operating space (signed dp and signed speed, each
scaled by its range) or in time, at least :data:`MIN_AGREE` miss the same way by more
than :data:`NEIGHBOUR_Z` noise levels, and by at least 1/:data:`LIKE` of the outlier's
miss; so does an outlier next to a clustered one that misses alike (the region's edge).
Clustered outliers stay in the fits, where the candidates may explain them; only
isolated ones are left out. Clustered outliers that the final model still misses are
grouped into regions (neighbours linked) and named in the report.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import LPM, MPA, RPM
from scipy import spatial

NEIGHBOURS = 8
"""Nearest rows an outlier's neighbourhood holds, [-]."""

NEIGHBOUR_Z = 2.0
"""Standardised residual of the outlier's sign beyond which a neighbour misses with it, [-]."""

LIKE = 3.0
"""A neighbour misses alike when the outlier's residual is at most this many times its own."""

MIN_AGREE = 3
"""
Fewest neighbours that miss with an outlier for it to cluster: 3 of 8 rows of Gaussian
noise pass 2 standard deviations with a chance of 9e-4, so an isolated bad row is
almost never kept, [-].
"""

MIN_REGION = 3
"""Fewest outliers a region the report names holds, [-]."""


@dataclass(frozen=True)
class Space:
    """Where the rows lie: the coordinates in which outliers may cluster."""

    dp: FloatArray  # signed drop p_in - p_out [Pa]
    speed: FloatArray  # signed speed [rad/s]
    time: FloatArray | None = None  # [s], or None for steady points without time
    cache: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def spaces(self) -> list[FloatArray]:
        """Return the scaled coordinates: the operating space, then time (if any)."""
        if 'spaces' not in self.cache:
            def scaled(x: FloatArray) -> FloatArray:
                span = float(np.ptp(x)) if x.size else 0.0
                return (x - float(np.min(x))) / span if span > 0.0 else np.zeros_like(x)
            out = [np.column_stack([scaled(self.dp), scaled(self.speed)])]
            if self.time is not None and np.all(np.isfinite(self.time)):
                out.append(scaled(self.time)[:, None])
            self.cache['spaces'] = out
        return list(self.cache['spaces'])

    def neighbours(self, which: int, at: np.ndarray, k: int) -> np.ndarray:
        """
        Return the `k` nearest other rows of each row in `at`.

        Parameters
        ----------
        which : int
            The space, as :meth:`spaces` orders them, [-]
        at : ndarray of int
            Rows, [-]
        k : int
            Neighbours of each, [-]

        Returns
        -------
        ndarray of int
            ``(at.size, k)`` rows, nearest first.

        """
        coords = self.spaces()[which]
        key = f'tree{which}'
        if key not in self.cache:  # a step asks many times: build each tree once
            self.cache[key] = spatial.cKDTree(coords)
        _, idx = self.cache[key].query(coords[at], k=k + 1)
        idx = np.asarray(idx).reshape(at.size, k + 1)
        own = idx == at[:, None]
        keep = np.where(own.any(axis=1, keepdims=True), ~own, np.arange(k + 1) < k)
        return idx[keep].reshape(at.size, k)


def clustered(flagged: np.ndarray, z: FloatArray, space: Space) -> np.ndarray:
    """
    Flag the outliers whose neighbours miss the same way: the model misses a region.

    Parameters
    ----------
    flagged : ndarray of bool
        The outliers, [-]
    z : ndarray
        Standardised residual (residual over the noise) at every row, [-]
    space : Space
        Where the rows lie, [-]

    Returns
    -------
    ndarray of bool
        True at an outlier of whose :data:`NEIGHBOURS` nearest rows, in the operating
        space or in time, at least :data:`MIN_AGREE` miss alike (a residual of its sign
        beyond :data:`NEIGHBOUR_Z` and beyond 1/:data:`LIKE` of its own), or one that
        clusters does (a subset of `flagged`).

    """
    out = np.zeros(flagged.shape, dtype=bool)
    k = min(NEIGHBOURS, flagged.size - 1)
    if k < 2 or not flagged.any():
        return out
    at = np.flatnonzero(flagged)
    sign = np.sign(z)
    nears = [space.neighbours(i, at, k) for i in range(len(space.spaces()))]
    size = np.abs(z)

    def alike(near: np.ndarray) -> np.ndarray:
        # a neighbour misses alike: the same sign, beyond NEIGHBOUR_Z, within a factor LIKE
        missed: np.ndarray = ((z[near] * sign[at, None] > NEIGHBOUR_Z)
                              & (size[at, None] <= LIKE * size[near]))  # numpy types it as Any
        return missed

    for near in nears:
        out[at[np.sum(alike(near), axis=1) >= MIN_AGREE]] = True
    while True:  # the region's edge: an outlier beside a clustered one that misses alike
        grown = out.copy()
        for near in nears:
            grown[at[np.any(out[near] & alike(near), axis=1)]] = True
        if np.array_equal(grown, out):
            return out
        out = grown


def regions(flagged: np.ndarray, z: FloatArray, space: Space) -> list[tuple[str, np.ndarray]]:
    """
    Group the clustered outliers into regions: neighbours of the same sign linked.

    Regions are grouped in each space apart: in the operating space (a corner of dp
    and speed, in one direction or both) and in time (a span of a recording).

    Parameters
    ----------
    flagged : ndarray of bool
        Outliers under the final model, [-]
    z : ndarray
        Standardised residual at every row, [-]
    space : Space
        Where the rows lie, [-]

    Returns
    -------
    list of (str, ndarray of int)
        ``'operating space'`` or ``'time span'`` and the rows of each region of at
        least :data:`MIN_REGION`, most rows first.

    """
    member = clustered(flagged, z, space)
    at = np.flatnonzero(member)
    if at.size < MIN_REGION:
        return []
    sign = np.sign(z)
    k = min(NEIGHBOURS, flagged.size - 1)
    found: list[tuple[str, np.ndarray]] = []
    for i, kind in zip(range(len(space.spaces())), ('operating space', 'time span')):
        near = space.neighbours(i, at, k)
        found += [(kind, g) for g in _linked(at, near, sign)]
    return sorted(found, key=lambda g: -g[1].size)


def _linked(at: np.ndarray, near: np.ndarray, sign: FloatArray) -> list[np.ndarray]:
    """Return the groups of rows `at` linked to a neighbour of the same sign in `at`."""
    parent = np.arange(at.size)

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = int(parent[i])
        return i

    position = {int(r): j for j, r in enumerate(at)}
    for j, row in enumerate(at):
        for other in near[j]:
            o = position.get(int(other))
            if o is not None and sign[other] == sign[row]:
                parent[root(j)] = root(o)
    groups: dict[int, list[int]] = {}
    for j, row in enumerate(at):
        groups.setdefault(root(j), []).append(int(row))
    return [np.array(sorted(g)) for g in groups.values() if len(g) >= MIN_REGION]


def describe(kind: str, rows: np.ndarray, residual: FloatArray, space: Space) -> dict[str, Any]:
    """
    Describe a region for calibration.json: where it lies and how much the model misses.

    Parameters
    ----------
    kind : str
        ``'operating space'`` or ``'time span'`` (:func:`regions`), [-]
    rows : ndarray of int
        The region's rows, [-]
    residual : ndarray
        Measured minus fitted flow at every row (in the row's frame), [m^3/s]
    space : Space
        Where the rows lie, [-]

    Returns
    -------
    dict
        kind, rows, direction (of dp: positive, negative or both), dp_mpa and speed_rpm
        [min, max], time_s [min, max] (when there is time), mean_residual_lpm and
        the residual's sign as ``'model too low'`` / ``'model too high'``.

    """
    dp, n = space.dp[rows], space.speed[rows]
    signs = set(np.sign(dp[dp != 0.0]).tolist())
    direction = 'both' if len(signs) != 1 else ('positive' if signs == {1.0} else 'negative')
    out: dict[str, Any] = {
        'kind': kind, 'rows': int(rows.size), 'direction': direction,
        'dp_mpa': [float(f'{float(np.min(dp)) / MPA:.4g}'),
                   float(f'{float(np.max(dp)) / MPA:.4g}')],
        'speed_rpm': [float(f'{float(np.min(n)) / RPM:.4g}'),
                      float(f'{float(np.max(n)) / RPM:.4g}')]}
    if space.time is not None:
        t = space.time[rows]
        out['time_s'] = [float(f'{float(np.min(t)):.5g}'), float(f'{float(np.max(t)):.5g}')]
    mean = float(np.mean(residual[rows]))
    out['mean_residual_lpm'] = float(f'{mean / LPM:.4g}')
    return out


__all__ = ['LIKE', 'MIN_AGREE', 'MIN_REGION', 'NEIGHBOUR_Z', 'NEIGHBOURS', 'Space', 'clustered',
           'describe', 'regions']
