# SPDX-License-Identifier: Apache-2.0
"""
The monitor's bins and gap, fitted to the recording's own sample step.

A bench logger writing a row every 5 or 10 s is common; with fixed 10 s bins (a bin needs
:data:`~.monitor.MIN_BIN_SAMPLES` samples) and a 5 s gap (a longer step is no operation) such
a log never gave a figure. The bins are therefore at least :data:`BIN_STEPS` sample steps
long and a gap is :data:`GAP_STEPS` steps at least (the calibration's rule,
doc/calibration.md), the step being the median over the first :data:`STEP_SAMPLES` samples
(so it does not depend on how the samples come in blocks). At 1 Hz and faster the settings'
10 s and 5 s hold unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from satmotor_ros.identify.health.records import HealthSettings
from satmotor_ros.model._typing import FloatArray

STEP_SAMPLES = 21
"""Samples whose median time step sets the bins and the gap (20 steps)."""

BIN_STEPS = 8.0
"""A bin spans at least this many sample steps, [-]."""

GAP_STEPS = 3.0
"""A step longer than this many median steps (and than ``max_gap_s``) is a gap, [-]."""


@dataclass(frozen=True)
class Timing:
    """The bins, the gap and the trend points the monitor uses on this recording."""

    step_s: float  # median sample step (0: not measured, the settings' bins) [s]
    bin_s: float  # [s]
    gap_s: float  # [s]
    point_s: float  # trend point [s]
    window_bins: int  # bins in the windowed factor [-]

    @classmethod
    def for_step(cls, settings: HealthSettings, step_s: float) -> Timing:
        """
        Return the timing for a sample step.

        Parameters
        ----------
        settings : HealthSettings
            The shortest bin, gap, window and trend point, [-]
        step_s : float
            The median sample step; 0 for the settings as they are, [s]

        Returns
        -------
        Timing
            Bins of max(bin_s, 8 steps), a gap of max(max_gap_s, 3 steps), window and trend
            points of at least a bin.

        """
        bin_s = max(settings.bin_s, BIN_STEPS * step_s)
        window_s = max(settings.window_s, bin_s)
        return cls(step_s, bin_s, max(settings.max_gap_s, GAP_STEPS * step_s),
                   max(settings.trend_point_s, bin_s), max(1, int(round(window_s / bin_s))))


def median_step(times: FloatArray, final: bool) -> float | None:
    """
    Return the median of the first :data:`STEP_SAMPLES` samples' positive time steps.

    Parameters
    ----------
    times : numpy.ndarray
        The sample times seen so far, in order (non-finite and repeated ones allowed), [s]
    final : bool
        No more samples will come: take the steps there are, [-]

    Returns
    -------
    float or None
        The step, [s]; 0 with no step at all (final); None while there are too few steps.

    """
    finite = times[np.isfinite(times)]
    steps = np.diff(finite)
    steps = steps[steps > 0.0][:STEP_SAMPLES - 1]
    if steps.size < STEP_SAMPLES - 1 and not final:
        return None
    return float(np.median(steps)) if steps.size else 0.0


__all__ = ['BIN_STEPS', 'GAP_STEPS', 'median_step', 'STEP_SAMPLES', 'Timing']
