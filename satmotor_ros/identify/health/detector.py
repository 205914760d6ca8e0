# SPDX-License-Identifier: Apache-2.0
r"""
The change detector: a two-sided CUSUM of log-likelihood ratios on whitened bin residuals.

Each bin of samples gives a leakage factor k_b and its information I_b = sum w Lb^2 (w the
inverse of each sample's noise variance, :mod:`.noise`). Against the reference level k_ref
the standardised deviation is e_b = (k_b - k_ref) sqrt(I_b) / c, where c^2 (the residual's
variance inflation: correlated samples within a bin, the model's own error moving with the
operating point) and the lag-one autocorrelation phi of e_b across bins are estimated from
the data, never set by hand: a detector that took the samples as independent would alarm on
every slow wander of a real log. The innovation u_b = (e_b - phi e_{b-1}) / sqrt(1 - phi^2)
is then independent and standard, and a change of the losses by Delta = change_fraction k_ref
moves it by delta_b = Delta sqrt(I_b) / c sqrt((1 - phi) / (1 + phi)). The CUSUM of the
log-likelihood ratio, S = max(0, S + delta u - delta^2 / 2), on each side, alarms at h.

h comes from the false-alarm interval through Siegmund's approximation of the in-control
average run length of a CUSUM with drift delta [1]_:

.. math:: ARL_0 \approx \frac{2}{\delta^2}\left(e^{h + 1.166\delta} - h - 1.166\delta - 1\right)

with ARL_0 = 2 false_alarm_hours / bin length (the two sides share the false alarms) and
delta the median of the learning bins'. Innovations are clipped at 5 (a spike decides
nothing); the Gaussian tail is what Siegmund's formula assumes.

References
----------
.. [1] Siegmund, D. (1985). Sequential Analysis: Tests and Confidence Intervals. Springer,
   p. 27; Basseville, M., Nikiforov, I. (1993). Detection of Abrupt Changes, sec. 5.2.

"""

from __future__ import annotations

from dataclasses import dataclass
import math

CLIP = 4.0
"""Largest |innovation| the CUSUM takes: beyond it a bin is a spike, not evidence, [-]."""

DELTA_MAX = 2.0
"""Largest shift per bin the CUSUM is tuned to, [-]: with innovations clipped at CLIP a
step tuned to delta gains at most delta CLIP - delta^2 / 2, which is negative beyond 2 CLIP,
so on a quiet flowmeter (a 20 % change many sigma per bin) the detector would never alarm.
Tuned to less, it still finds the larger shift, and the threshold follows from this delta."""


def siegmund_arl(h: float, delta: float) -> float:
    """
    Return the in-control average run length of a CUSUM, [bins].

    Parameters
    ----------
    h : float
        Threshold of the log-likelihood-ratio CUSUM, [-]
    delta : float
        Shift it is tuned to, in standard deviations of one step, [-]

    Returns
    -------
    float
        Siegmund's approximation.

    Examples
    --------
    >>> round(siegmund_arl(5.0, 1.0))
    938

    """
    return math.exp(min(log_arl(h, delta), 700.0))


def log_arl(h: float, delta: float) -> float:
    """Return the log of :func:`siegmund_arl`, safe for any h and delta, [-]."""
    b = h + 1.166 * delta
    excess = b + math.log1p(-(b + 1.0) * math.exp(-b)) if b > 1e-3 else math.log(b * b / 2.0)
    return math.log(2.0) + excess - 2.0 * math.log(delta)


def threshold_for(arl: float, delta: float) -> float:
    """
    Return the threshold h whose in-control run length is `arl`, [-].

    Parameters
    ----------
    arl : float
        Wanted average run length between false alarms, [bins]
    delta : float
        Shift the CUSUM is tuned to, [-]

    Returns
    -------
    float
        h, by bisection on :func:`siegmund_arl` (which grows with h).

    """
    target = math.log(arl)
    low, high = 0.0, 1.0
    while log_arl(high, delta) < target:
        high *= 2.0
    for _ in range(100):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if log_arl(mid, delta) < target else (low, mid)
    return 0.5 * (low + high)


@dataclass
class Cusum:
    """
    Two one-sided CUSUMs of log-likelihood ratios, with where each excursion began.

    ``up`` looks for a rise of the losses, ``down`` for a fall.
    """

    h: float  # threshold [-]
    up: float = 0.0  # [-]
    down: float = 0.0  # [-]
    up_start: float = math.nan  # time its excursion began [s]
    down_start: float = math.nan  # [s]

    def step(self, u: float, delta: float, start_s: float, margin: float = 0.0) -> None:
        """
        Add one innovation.

        Parameters
        ----------
        u : float
            Standardised innovation, [-]
        delta : float
            Its shift under the change tuned to, [-]
        start_s : float
            Start of the bin it comes from, [s]
        margin : float
            How far `u` may be off with no change (the level's own uncertainty), given away
            on each side, [-]

        """
        u = max(-CLIP, min(CLIP, u))
        gain = delta * (u - margin) - 0.5 * delta * delta
        if self.up == 0.0:
            self.up_start = start_s
        if self.down == 0.0:
            self.down_start = start_s
        self.up = max(0.0, self.up + gain)
        self.down = max(0.0, self.down + delta * (-u - margin) - 0.5 * delta * delta)

    @property
    def statistic(self) -> float:
        """Return the larger side over the threshold, [-]."""
        return max(self.up, self.down) / self.h

    @property
    def quiet(self) -> bool:
        """Return whether neither side has gathered a quarter of the threshold."""
        return max(self.up, self.down) < 0.25 * self.h

    def reset(self) -> None:
        """Start both sides anew (after an alarm)."""
        self.up = self.down = 0.0
        self.up_start = self.down_start = math.nan


__all__ = ['CLIP', 'Cusum', 'DELTA_MAX', 'log_arl', 'siegmund_arl', 'threshold_for']
