# SPDX-License-Identifier: Apache-2.0
"""
Which part of a recording a fit used: its share of the samples and of the operating envelope.

The envelope is given per direction of the drop (the sign of dp = p_in - p_out, DESIGN.md
"Sign conventions"): the least and largest dp and speed of the samples in that direction.
A recording's own envelope, against which windows are judged, leaves out the
:data:`TAIL` most extreme samples at each end of each quantity (a spike is not
an operating point); a direction that holds less than :data:`MIN_DIRECTION` of
the samples is not part of it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.units import MPA, RPM

DIRECTIONS = (('positive', 1.0), ('negative', -1.0))
"""The directions of the drop by name, and their sign of dp."""

TAIL = 0.002
"""Share of a direction's samples left out at each end of its envelope, [-]."""

MIN_DIRECTION = 0.01
"""Least share of the samples for a direction to be part of a recording's envelope, [-]."""

MOST = 0.5
"""Least share of the samples steady windows must hold to be used instead of every sample."""

COVERED = 0.9
"""Least share of the recording's envelope steady windows must span to be used, [-]."""


def envelope(dp: FloatArray, speed: FloatArray, tail: float = 0.0) -> dict[str, Any]:
    """
    Return the least and largest dp and speed per direction of the drop.

    Parameters
    ----------
    dp : ndarray
        Signed drop p_in - p_out (or p_a - p_b), [Pa]
    speed : ndarray
        Signed speed, [rad/s]
    tail : float
        Share of each direction's samples left out at each end (0: min and max), [-]

    Returns
    -------
    dict
        ``{'positive' | 'negative': {'dp_mpa': [min, max], 'speed_rpm': [min, max],
        'samples': k}}`` for each direction that has a sample; dp in MPa, speed in rpm,
        both signed.

    """
    out: dict[str, Any] = {}
    finite = np.isfinite(dp) & np.isfinite(speed)
    for name, sign in DIRECTIONS:
        at = finite & (np.sign(dp) == sign)
        if not at.any():
            continue
        q = (tail, 1.0 - tail)
        lo_dp, hi_dp = (float(v) / MPA for v in np.quantile(dp[at], q))
        lo_n, hi_n = (float(v) / RPM for v in np.quantile(speed[at], q))
        out[name] = {'dp_mpa': [float(f'{lo_dp:.4g}'), float(f'{hi_dp:.4g}')],
                     'speed_rpm': [float(f'{lo_n:.4g}'), float(f'{hi_n:.4g}')],
                     'samples': int(at.sum())}
    return out


def envelope_share(inner: dict[str, Any], outer: dict[str, Any], total: int) -> float:
    """
    Return the least share of the outer envelope's span that the inner one spans.

    Taken over each direction that holds at least :data:`MIN_DIRECTION` of `total`
    samples, and over |dp| and |speed| in it: 1 when the inner envelope spans the outer,
    0 when a direction of the outer one is missing from it.

    Parameters
    ----------
    inner, outer : dict
        Envelopes as :func:`envelope` gives them, [-]
    total : int
        Samples of the recording, [-]

    Returns
    -------
    float
        The share, 0-1, [-]

    """
    share = 1.0
    for name, _ in DIRECTIONS:
        if name not in outer or outer[name]['samples'] < MIN_DIRECTION * total:
            continue
        if name not in inner:
            return 0.0
        for key in ('dp_mpa', 'speed_rpm'):
            lo, hi = _magnitudes(outer[name][key])
            a, b = _magnitudes(inner[name][key])
            span = hi - lo
            if span > 0.0:
                share = min(share, max(min(b, hi) - max(a, lo), 0.0) / span)
    return share


def _magnitudes(span: list[float]) -> tuple[float, float]:
    """Return the least and largest magnitude over a signed [min, max]."""
    lo, hi = span
    if lo <= 0.0 <= hi:
        return 0.0, max(-lo, hi)
    return min(abs(lo), abs(hi)), max(abs(lo), abs(hi))


def outside(env: dict[str, Any], dp: FloatArray, speed: FloatArray) -> np.ndarray:
    """
    Flag the samples outside an envelope (a direction it lacks counts as outside).

    Parameters
    ----------
    env : dict
        An envelope as :func:`envelope` gives it (or as calibration.json's ``coverage``
        writes it), [-]
    dp : ndarray
        Signed drop, [Pa]
    speed : ndarray
        Signed speed, [rad/s]

    Returns
    -------
    ndarray of bool
        True where a sample lies outside.

    """
    out = np.ones(dp.shape, dtype=bool)
    for name, sign in DIRECTIONS:
        if name not in env:
            continue
        at = np.sign(dp) == sign
        (lo_dp, hi_dp), (lo_n, hi_n) = env[name]['dp_mpa'], env[name]['speed_rpm']
        inside = ((dp / MPA >= lo_dp - _margin(lo_dp, hi_dp))
                  & (dp / MPA <= hi_dp + _margin(lo_dp, hi_dp))
                  & (speed / RPM >= lo_n - _margin(lo_n, hi_n))
                  & (speed / RPM <= hi_n + _margin(lo_n, hi_n)))
        out[at] = ~inside[at]
    out[dp == 0.0] = False
    return out


def _margin(lo: float, hi: float) -> float:
    """Return the slack at an envelope's edge: the rounding of a written bound."""
    return 1e-3 * max(abs(lo), abs(hi))


def coverage(samples_used: int, samples_total: int, dp: FloatArray,
             speed: FloatArray, share: float | None = None) -> dict[str, Any]:
    """
    Build calibration.json's ``coverage`` (DESIGN.md, "Calibration output").

    Parameters
    ----------
    samples_used, samples_total : int
        Samples the fit used and samples the data hold, [-]
    dp, speed : ndarray
        Signed drop [Pa] and speed [rad/s] of the samples used
    share : float, optional
        Share of the recording's envelope they span, when known, [-]

    Returns
    -------
    dict
        samples_used, samples_total, fraction, envelope (:func:`envelope`) and
        envelope_share when given.

    """
    out: dict[str, Any] = {'samples_used': int(samples_used), 'samples_total': int(samples_total),
                           'fraction': float(f'{samples_used / max(samples_total, 1):.4g}'),
                           'envelope': envelope(dp, speed)}
    if share is not None:
        out['envelope_share'] = float(f'{share:.4g}')
    return out


__all__ = ['COVERED', 'DIRECTIONS', 'MOST', 'TAIL', 'coverage',
           'envelope', 'envelope_share', 'outside']
