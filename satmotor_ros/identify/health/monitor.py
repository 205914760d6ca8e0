# SPDX-License-Identifier: Apache-2.0
"""
The health monitor: samples in, the leakage factor, its trend, change and limit alarms out.

Samples are evaluated a block at a time (vectorised, :meth:`Baseline.losses`) and pooled
into bins of ``bin_s`` (longer on a log slower than 1 Hz: :mod:`.timing`): the bin's
weighted least-squares leakage factor k_b = sum w Lb Lm / sum w Lb^2 and its information
I_b = sum w Lb^2, with w the inverse of each sample's noise variance (:mod:`.noise`). The
bins then drive, at constant cost and memory, the windowed factor (the pooled factor over
``window_s``), the trend (:mod:`.trend`) and the change detector (:mod:`.detector`).

The first ``learn_hours`` of operation teach the monitor the data: first (a third of it)
the sample noise model; then the level k_ref, the
bins' variance inflation c^2 and autocorrelation phi, the reference operating point and the
detector's threshold. The detector's level and noise model keep learning slowly
(``reference_hours``) while the detector is quiet, so a slow wear shows as a trend and a
limit, a step as a change. After a change alarm the level is the one since the change, and
the trend restarts.

While learning, the windowed factor's interval needs the bins' c^2 and phi, which are only
known once learned: before the first learning ends the factor has no interval (NaN: null in
``monitor.json``, nan in ``health.csv``) and its points carry ``learning``; taking the bins
as independent (c^2 = 1, phi = 0) gave 95 % intervals that held the truth about half the
time. A re-learning after a change alarm keeps the last learned c^2 and phi until it ends
(its points carry ``learning`` too, with intervals).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import asdict, replace
import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.health.baseline import Baseline, IMPLAUSIBLE, NON_FINITE, OK
from satmotor_ros.identify.health.detector import Cusum, DELTA_MAX, threshold_for
from satmotor_ros.identify.health.noise import fit_variance
from satmotor_ros.identify.health.records import (Alarm, Estimate, HealthPoint, HealthSamples,
                                                  HealthSettings, HealthSnapshot, SKIP_REASONS)
from satmotor_ros.identify.health.state import check_settings, check_state, compatible, template
from satmotor_ros.identify.health.timing import median_step, Timing
from satmotor_ros.identify.health.trend import MIN_POINTS, Trend
from satmotor_ros.model._typing import FloatArray

FIELDS = ('n', 'sbb', 'sbm', 'op_s', 'disp', 'lb', 'speed', 'dp')
"""Sums per bin: samples, information, cross term, operating seconds, q_t n, baseline loss,
|n| and |dp|."""

MIN_BIN_SAMPLES = 5
"""A bin with fewer used samples gives no factor."""

NOISE_SAMPLES = 200_000
"""Most samples kept to fit the sample noise model (a spread subset beyond)."""

Explainer = Callable[[HealthSamples, HealthSamples, Baseline], str]
"""What-changed: (samples before, samples since the change, baseline) -> the effect named."""

PENDING = 'pending'
"""What a change alarm says until the samples since the change have been learned and its
candidates run (``learn_hours`` later): the snapshot's alarms then carry the name."""

GROSS = 8.0
"""A bin deviation beyond this many robust standard deviations is a spike, clipped before it
enters the noise model, [-]."""

EPS = 1e-9
"""Relative slack on the durations that end a stage: a sum of 60 steps of 10 s is 600 s
whether the clock ran from 0 or from an epoch (float rounding must not add a bin)."""

KEEP_HZ = 4.0
"""Raw samples kept per second for what-changed (the candidates take at most 3000 a side,
spread evenly, so more would only cost memory and state-file size), [1/s]."""

RATE_STEP_S = 1.0
"""Longest sample step (the log's median) over which a difference measures the flow's rate,
[s]. On a slower log the difference spans the operating cycle, not the reading's instant:
as a weight it made the factor of a bin a few samples' (a bin's variance 125 times the
model's at 0.1 Hz), so there every sample weighs alike (var = a)."""

LEVEL_POINTS = 6
"""Trend points (an hour at the default 10 min) before its line is the detector's level."""

STATE_VERSION = 2
"""Version of the saved state's layout."""


class HealthMonitor:
    """
    Track a motor's health against a baseline model, one block of samples at a time.

    Parameters
    ----------
    baseline : Baseline
        The healthy motor, [-]
    settings : HealthSettings, optional
        The false-alarm interval, limits and windows, [-]
    explainer : callable, optional
        What-changed on a change alarm; the calibration candidates
        (:func:`~satmotor_ros.identify.health.explain.explain_change`) by default, [-]

    Examples
    --------
    >>> from satmotor_ros.identify.health import Baseline, HealthMonitor
    >>> monitor = HealthMonitor(Baseline.for_family('paszota', 7.8e-7))
    >>> monitor.snapshot().learning
    True

    """

    def __init__(self, baseline: Baseline, settings: HealthSettings | None = None,
                 explainer: Explainer | None = None) -> None:
        """Start empty: the first samples teach the noise model."""
        self.baseline = baseline
        self.settings = settings or HealthSettings()
        if explainer is None:
            from satmotor_ros.identify.health.explain import explain_change
            explainer = explain_change
        self.explainer = explainer
        s = self.settings
        self.t0 = math.nan  # first sample [s]
        self.t_last = math.nan  # last sample [s]
        self.last_flow_rate_x = (math.nan, math.nan)  # (time, q_t n signed) of the last sample
        self.n_samples = 0
        self.skipped = dict.fromkeys(SKIP_REASONS, 0)
        self.op_s = 0.0  # operating seconds used
        # stage 1: the sample noise model
        self.noise_rate: list[FloatArray] = []
        self.noise_residual: list[FloatArray] = []
        self.var_a = math.nan
        self.var_b = math.nan
        # bins
        self.bin_index = -1
        self.open_bin = np.zeros(len(FIELDS))
        self.carry = np.zeros(len(FIELDS))  # a closed bin too thin for a factor, joining the next
        self.n_noise = 0  # usable samples that taught the noise model (stage 1)
        self.n_binned = 0  # usable samples in bins that gave a factor
        # stage 2: the level, c, phi, the reference point, h
        self.learn_bins: list[list[float]] = []  # k, I, op_s, speed, dp, sbm, sbb per bin
        self.learning = True
        self.k_ref = math.nan
        self.ref_num = 0.0  # forgetting sums of sbm and sbb for k_ref
        self.ref_den = 0.0
        self.c2 = math.nan
        self.phi = 0.0
        self.rho_num = 0.0  # forgetting sums of e_b e_(b-1) and e_b^2 for phi
        self.rho_den = 0.0
        self.e_prev = 0.0
        self.delta_unit = math.nan  # delta per sqrt(I_b) [-]
        self.pending = -1  # the change alarm waiting for its explanation (index), or -1
        self.n_c = 0.0  # bins (forgetting) the bins' variance c^2 was estimated from
        self.learn_end_s = math.nan  # end of the last learning bin [s]
        self.cusum = Cusum(math.inf)
        self.since = {'up': [0.0, 0.0], 'down': [0.0, 0.0]}  # sbm, sbb since each start
        self.reference_speed = math.nan
        self.reference_dp = math.nan
        self.reference_loss = math.nan  # baseline Q_vl at the reference [m^3/s]
        self.limit_k = s.limit_leakage_factor
        self.step_s = math.nan  # the sample step the bins follow, once known [s]
        self.timing = Timing.for_step(s, 0.0)
        self.held: list[HealthSamples] = []  # the first samples, until the step is known
        self.window: deque[tuple[float, float, float]] = deque(maxlen=self.timing.window_bins)
        self.trend = Trend(s.trend_hours)
        self.trend_point = np.zeros(4)  # sbm, sbb, op_s, start time
        self.trend_point[3] = math.nan
        # the bins of the last explain_s: (end [s], sbm, sbb, op_s, operation then [s]), so
        # that a change alarm restarts the trend from where the change began
        self.trend_bins: deque[list[float]] = deque()
        self.last_point: HealthPoint | None = None
        self.points: list[HealthPoint] = []
        self.alarms: list[Alarm] = []
        self.acknowledged = 0  # the first this many alarms are acknowledged
        self.in_limit = False
        self.change_s = math.nan
        self.what_changed = ''
        self.recent: deque[HealthSamples] = deque()  # raw usable samples for what-changed
        self.kept_grid = math.nan  # KEEP_HZ grid cell of the last sample kept

    # ------------------------------------------------------------------ samples in
    def update(self, block: HealthSamples) -> list[Alarm]:
        """
        Take a block of samples (in time order, after those already given).

        Parameters
        ----------
        block : HealthSamples
            The samples, [-]

        Returns
        -------
        list of Alarm
            The alarms raised by this block (a condition already raised is not repeated).

        """
        if len(block) == 0:
            return []
        if math.isnan(self.step_s):  # the bins follow the step of the first samples
            self.held.append(block)
            if not self._fix_step(final=False):
                return []
            block = _concat(self.held)
            self.held = []
        return self._update(block)

    def flush(self) -> list[Alarm]:
        """
        Take the samples held while too few came to know their step (the end of the data).

        Returns
        -------
        list of Alarm
            The alarms they raise (:meth:`update`'s).

        """
        if not self.held:
            return []
        self._fix_step(final=True)
        block, self.held = _concat(self.held), []
        return self._update(block)

    def _fix_step(self, final: bool) -> bool:
        """Fix the bins and the gap from the held samples' step; False if too few yet."""
        times = np.concatenate([np.asarray(b.time, dtype=float) for b in self.held])
        step = median_step(times, final)
        if step is None:
            return False
        self.step_s = step
        self.timing = Timing.for_step(self.settings, step)
        self.window = deque(self.window, maxlen=self.timing.window_bins)
        return True

    def _update(self, block: HealthSamples) -> list[Alarm]:
        """Take a block, the timing known."""
        s = self.settings
        time = np.asarray(block.time, dtype=float)
        if math.isnan(self.t0) and np.isfinite(time).any():
            self.t0 = float(time[np.isfinite(time)][0])
        losses = self.baseline.losses(block, s.min_speed)
        reason = losses.reason.copy()
        # stale: time that does not advance (a repeated or late sample)
        previous = np.concatenate([[self.t_last], time[:-1]])
        running = np.fmax.accumulate(np.where(np.isfinite(previous), previous, -np.inf))
        stale = np.isfinite(time) & ~(time > running)
        reason[(reason == OK) & stale] = 4
        for code, name in enumerate(SKIP_REASONS, start=1):
            self.skipped[name] += int(np.sum(reason == code))
        self.n_samples += len(block)
        used = reason == OK
        dt = np.diff(np.concatenate([[self.t_last], time]))
        dt = np.where(np.isfinite(dt) & (dt > 0) & (dt <= self.timing.gap_s), dt, 0.0)
        rate = self._rate(block, time, np.isin(reason, (NON_FINITE, IMPLAUSIBLE)))
        if np.isfinite(time).any():
            self.t_last = float(np.nanmax(np.concatenate([[self.t_last], time])))
        alarms: list[Alarm] = []
        if not used.any():
            return alarms
        op = np.where(used, dt, 0.0)
        self._keep_recent(block, used)
        residual = losses.measured - losses.baseline
        if math.isnan(self.var_a):  # stage 1: these samples teach the noise model only
            need = self.settings.learn_hours * 3600.0 / 3.0 * (1.0 - EPS) - self.op_s
            early = np.cumsum(op) < need
            early[:int(np.argmin(early)) + 1] = True  # up to the sample that completes it
            teach = used & early
            self.n_noise += int(teach.sum())
            self.op_s += float(op[teach].sum())
            self._gather_noise(rate[teach], residual[teach])
            used = used & ~early
            op = np.where(used, op, 0.0)
            if math.isnan(self.var_a) or not used.any():
                return alarms
        base = losses.baseline
        w = 1.0 / (self.var_a + self.var_b * rate ** 2)
        lb, lm = np.where(used, base, 0.0), np.where(used, losses.measured, 0.0)
        contributions = np.vstack([used.astype(float), w * lb * lb, w * lb * lm, op,
                                   np.where(used, losses.displacement, 0.0), lb,
                                   np.where(used, losses.speed, 0.0),
                                   np.where(used, losses.dp, 0.0)])
        index = np.floor((time - self.t0) / self.timing.bin_s)
        index = np.where(used & np.isfinite(index), index, -1).astype(np.int64)
        if self.bin_index < 0:
            self.bin_index = int(index[used][0])
        first = self.bin_index
        index = np.where(used, np.maximum(index, first), first)
        # only the bins that hold samples: an empty bin changes nothing, and a gap of days
        # (or a bench CSV from 0 s, then an epoch log) would be millions of them
        bins, where = np.unique(index, return_inverse=True)
        sums: FloatArray = np.vstack([
            np.bincount(where.ravel(), weights=row, minlength=bins.size).astype(float)
            for row in contributions])
        if bins[0] != first:  # the open bin got no new sample: it closes as it is
            bins = np.concatenate([[first], bins])
            sums = np.hstack([np.zeros((len(FIELDS), 1)), sums])
        sums[:, 0] += self.open_bin
        for k in range(bins.size - 1):
            alarms += self._close_bin(sums[:, k], int(bins[k]))
        self.open_bin = sums[:, -1].copy()
        self.bin_index = int(bins[-1])
        self._prune_recent()
        return alarms

    def _rate(self, block: HealthSamples, time: FloatArray, bad: np.ndarray) -> FloatArray:
        """
        Return |d(q_t n)/dt| per sample, the previous block's last sample carried, [m^3/s^2].

        A `bad` sample's speed (non-finite or gross) is no speed: the rates beside it are 0,
        as beside a NaN, so a 1e30 reading weighs on no neighbour.
        """
        x = self.baseline.displacement * np.where(bad, np.nan,
                                                  np.asarray(block.speed, dtype=float))
        t_prev, x_prev = self.last_flow_rate_x
        dx = np.diff(np.concatenate([[x_prev], x]))
        dt = np.diff(np.concatenate([[t_prev], time]))
        with np.errstate(invalid='ignore', divide='ignore'):
            rate = np.abs(dx / dt)
        rate = np.where(np.isfinite(rate) & (dt > 0) & (dt <= self.timing.gap_s), rate, 0.0)
        if self.timing.step_s > RATE_STEP_S:  # the step is no measure of the flow's rate
            rate = np.zeros_like(rate)
        if len(time):
            self.last_flow_rate_x = (float(time[-1]), float(x[-1]))
        return rate

    def _keep_recent(self, block: HealthSamples, used: np.ndarray) -> None:
        """Keep used raw samples, :data:`KEEP_HZ` a second at most, for what-changed."""
        if not self.settings.explain:
            return
        grid = np.floor(np.asarray(block.time, dtype=float) * KEEP_HZ)
        previous = np.concatenate([[self.kept_grid], grid[:-1]])
        keep = used & (grid != previous)
        if np.isfinite(grid).any():
            self.kept_grid = float(np.nanmax(grid))
        if keep.any():
            self.recent.append(block.take(keep))

    def _prune_recent(self) -> None:
        """Forget samples no change could need: ``explain_s`` before any change still open."""
        s = self.settings
        horizon = self.t_last - 2.0 * s.explain_s - 3600.0 * s.learn_hours
        if self.pending >= 0:
            horizon = min(horizon, self.t0 + self.alarms[self.pending].change_s - s.explain_s)
        while self.recent and self.recent[0].time[-1] < horizon:
            self.recent.popleft()

    def _gather_noise(self, rate: FloatArray, residual: FloatArray) -> None:
        """Stage 1: keep residuals until a third of the learning time, then fit the noise."""
        self.noise_rate.append(rate)
        self.noise_residual.append(residual)
        if self.op_s < self.settings.learn_hours * 3600.0 / 3.0 * (1.0 - EPS):
            return
        rate_all, residual_all = np.concatenate(self.noise_rate), np.concatenate(
            self.noise_residual)
        if rate_all.size > NOISE_SAMPLES:
            pick = np.linspace(0, rate_all.size - 1, NOISE_SAMPLES).astype(int)
            rate_all, residual_all = rate_all[pick], residual_all[pick]
        self.var_a, self.var_b = fit_variance(rate_all, residual_all)
        self.noise_rate, self.noise_residual = [], []

    # ------------------------------------------------------------------ bins
    def _close_bin(self, sums: FloatArray, index: int) -> list[Alarm]:
        """Take one finished bin: learning, or the detector, window, trend and limits."""
        s = self.settings
        end_s = self.t0 + (index + 1) * self.timing.bin_s
        self.op_s += float(sums[3])  # operation is counted bin by bin: the clock of the trend
        # a bin too thin for a factor (the edge of a gap, a log dropping samples) joins the
        # next one: every usable sample counts in a bin (it was dropped, unsaid)
        sums = sums + self.carry
        n, sbb, sbm, op_s, disp, lb, speed, dp = (float(x) for x in sums)
        if n < MIN_BIN_SAMPLES or sbb <= 0.0:
            self.carry = np.asarray(sums, dtype=float).copy()
            return []
        self.carry = np.zeros(len(FIELDS))
        self.n_binned += int(round(n))
        k_b = sbm / sbb
        self.window.append((sbm, sbb, op_s))
        alarms: list[Alarm] = []
        if self.learning:
            self.learn_end_s = end_s
            self.learn_bins.append([k_b, sbb, op_s, speed / n, dp / n, sbm])
            if sum(row[2] for row in self.learn_bins) \
                    >= s.learn_hours * 3600.0 * 2.0 / 3.0 * (1.0 - EPS) \
                    and len(self.learn_bins) >= 10:
                self._finish_learning()
        else:
            alarms += self._detect(k_b, sbb, sbm, end_s - self.timing.bin_s, end_s)
        self._add_to_trend(sbm, sbb, op_s, end_s, self.op_s)
        self.trend_bins.append([end_s, sbm, sbb, op_s, self.op_s])
        while self.trend_bins[0][0] < end_s - s.explain_s:
            self.trend_bins.popleft()
        alarms += self._check_limit(end_s)
        window = self._window_factor()
        eta = disp / (disp + window.value * lb) if disp + window.value * lb > 0 else math.nan
        level, level_hw, *_ = self.trend.estimate(self.op_s / 3600.0)
        self.last_point = HealthPoint(end_s - self.t0, self.op_s / 3600.0, window, k_b,
                                      Estimate(level, level - level_hw, level + level_hw),
                                      self.cusum.statistic if not self.learning else 0.0, eta,
                                      self.learning)
        self.points.append(self.last_point)
        return alarms

    def _finish_learning(self) -> None:
        """Stage 2 done: the level, c^2, phi, the reference point and the threshold."""
        s = self.settings
        rows = np.array(self.learn_bins)
        k, info, op_s, speed, dp, sbm = rows.T
        self.ref_num, self.ref_den = float(sbm.sum()), float(info.sum())
        self.k_ref = self.ref_num / self.ref_den
        e = (k - self.k_ref) * np.sqrt(info)
        robust = 1.4826 * float(np.median(np.abs(e - np.median(e))))
        robust = robust if robust > 0 else float(np.std(e)) or 1.0
        # only gross spikes are clipped: a heavy tail is the noise's, and the threshold
        # assumes no lighter one than the data have
        clipped = np.clip(e, -GROSS * robust, GROSS * robust)
        self.c2 = max(float(np.mean(clipped ** 2)), 1e-12)
        self.rho_num = float(np.sum(clipped[1:] * clipped[:-1]))
        self.rho_den = float(np.sum(clipped ** 2))
        self.phi = self._phi()
        self.n_c = float(len(e))
        self.e_prev = float(clipped[-1] / math.sqrt(self.c2 * self._c2_margin()))
        shift = s.change_fraction * abs(self.k_ref)
        self.delta_unit = (shift / math.sqrt(self.c2 * self._c2_margin())
                           * math.sqrt((1 - self.phi) / (1 + self.phi)))
        delta = min(self.delta_unit * float(np.median(np.sqrt(info))), DELTA_MAX)
        bin_hours = float(np.mean(op_s)) / 3600.0
        arl = 2.0 * s.false_alarm_hours / max(bin_hours, 1e-9)
        self.cusum = Cusum(threshold_for(arl, delta))
        if math.isnan(self.reference_loss):
            self._reference_point(speed, dp, info)
        self.learning = False
        self.learn_bins = []
        if self.pending >= 0:
            self._explain(self.learn_end_s)

    def _phi(self) -> float:
        phi = self.rho_num / self.rho_den if self.rho_den > 0 else 0.0
        return min(max(phi, 0.0), 0.95)

    def _reference_point(self, speed: FloatArray, dp: FloatArray, info: FloatArray) -> None:
        """Fix the reference point (the settings', or the information-weighted median)."""
        s = self.settings
        self.reference_speed = s.reference_speed if s.reference_speed is not None \
            else _weighted_median(speed, info)
        self.reference_dp = s.reference_dp if s.reference_dp is not None \
            else _weighted_median(dp, info)
        model = self.baseline.model
        at = model.absorbency(np.array([self.reference_speed]), dp=np.array([self.reference_dp]),
                              errors='mask', channels=self._reference_channels())
        q = float(at.flow[0])
        qn = self.baseline.displacement * self.reference_speed
        self.reference_loss = q - qn
        eta = s.limit_volumetric_efficiency
        if eta is not None and self.reference_loss > 0:
            self.limit_k = qn * (1.0 / eta - 1.0) / self.reference_loss

    def _reference_channels(self) -> dict[str, FloatArray] | None:
        needs = self.baseline.model.channels
        if not needs:
            return None
        values = {'p_case': 0.0, 'p_out': 0.0, 'time': 0.0,
                  'temperature': self.baseline.reference_temperature}
        return {name: np.array([values.get(name, 0.0)]) for name in needs}

    def _detect(self, k_b: float, sbb: float, sbm: float, start_s: float,
                end_s: float) -> list[Alarm]:
        """Run the CUSUM on one bin; alarm, re-level and restart the trend on a change."""
        s = self.settings
        c = math.sqrt(self.c2 * self._c2_margin())
        e = (k_b - self._level()) * math.sqrt(sbb) / c
        u = (e - self.phi * self.e_prev) / math.sqrt(1.0 - self.phi ** 2)
        previous, self.e_prev = self.e_prev, e
        delta = min(self.delta_unit * math.sqrt(sbb), DELTA_MAX)
        # the level is known to +-2 standard errors only: a bin's innovation may be off by
        # that much with no change (its standard error in innovation units is
        # sqrt(I_b / I_level)); the CUSUM gives that much away on each side
        margin = 2.0 * math.sqrt(sbb / self.ref_den) if self.ref_den > 0 else 0.0
        was = (self.cusum.up, self.cusum.down)
        # whether the bin teaches the level and the noise is decided before it is seen: gated
        # on its own deviation (quiet after it), the bins beyond ~2.4 sigma never taught c^2,
        # which ran 13 % low in standard deviation, and the stated false-alarm interval failed
        quiet = self.cusum.quiet
        self.cusum.step(u, delta, start_s, margin)
        for side, before in zip(('up', 'down'), was):
            if before == 0.0:
                self.since[side] = [0.0, 0.0]
            if getattr(self.cusum, side) > 0.0:
                self.since[side][0] += sbm
                self.since[side][1] += sbb
        if self.cusum.statistic >= 1.0:
            return [self._change(end_s)]
        if quiet:
            lam = math.exp(-(self.window[-1][2] / 3600.0) / s.reference_hours)
            self.ref_num = lam * self.ref_num + sbm
            self.ref_den = lam * self.ref_den + sbb
            self.k_ref = self.ref_num / self.ref_den
            # e is in units of the margined c: back to the learned c's units
            scaled = e * math.sqrt(self._c2_margin())
            clipped = max(-GROSS, min(GROSS, scaled))
            self.c2 = lam * self.c2 + (1.0 - lam) * self.c2 * clipped ** 2
            self.rho_num = lam * self.rho_num + clipped * max(-GROSS, min(GROSS, previous))
            self.rho_den = lam * self.rho_den + clipped ** 2
            self.phi = self._phi()
            self.n_c = lam * self.n_c + 1.0
        return []

    def _c2_margin(self) -> float:
        """
        Return the factor on c^2 that makes it an upper 95 % bound, [-].

        c^2 is estimated from n_c bins (effectively n_c (1 - phi)/(1 + phi) independent
        ones); a threshold taken from an underestimated noise alarms far more often than
        stated, so the detector uses the variance's upper bound (chi-square, normal
        approximation), which tends to c^2 as the bins accumulate.
        """
        n_eff = max(self.n_c * (1.0 - self.phi) / (1.0 + self.phi), 2.0)
        return 1.0 + 1.645 * math.sqrt(2.0 / n_eff)

    def _level(self) -> float:
        """
        Return the level the detector holds a bin against.

        The trend's line where its slope is significant (a wear is a trend, not a change),
        else the slowly forgetting mean k_ref.
        """
        level, _, slope, slope_hw, _ = self.trend.estimate(self.op_s / 3600.0)
        if self.trend.n >= LEVEL_POINTS and math.isfinite(level) and abs(slope) > slope_hw:
            return level
        return self.k_ref

    def _change(self, end_s: float) -> Alarm:
        """Raise a change: estimate where it began, name it, re-level, restart the trend."""
        side = 'up' if self.cusum.up >= self.cusum.down else 'down'
        start = self.cusum.up_start if side == 'up' else self.cusum.down_start
        num, den = self.since[side]
        after = num / den if den > 0 else self.k_ref
        statistic = self.cusum.statistic
        what = PENDING if self.settings.explain else 'unexplained'
        alarm = Alarm(end_s - self.t0, 'change', what, statistic, start - self.t0,
                      self._level(), after)
        self.alarms.append(alarm)
        self.pending = len(self.alarms) - 1
        self.change_s, self.what_changed = start - self.t0, what
        self.k_ref = after
        # the change may have changed the residual's noise too: learn level and noise anew
        self.learning = True
        self.learn_bins = []
        self.cusum.reset()
        self.since = {'up': [0.0, 0.0], 'down': [0.0, 0.0]}
        self.e_prev = 0.0
        self.trend = Trend(self.settings.trend_hours)
        self.trend_point[:] = [0.0, 0.0, 0.0, math.nan]
        # the trend restarts from the change: the bins since it began (the alarm's own bin
        # follows), not from the alarm, nor with the bins of the old level
        slack = EPS * max(1.0, abs(start))
        for end, sbm, sbb, op_s, total in self.trend_bins:
            if end - self.timing.bin_s >= start - slack:
                self._add_to_trend(sbm, sbb, op_s, end, total)
        self.window.clear()
        return alarm

    def _explain(self, end_s: float) -> None:
        """
        Settle the pending change: its level after, learned, and what it was.

        The name comes from the raw samples before the change and since, up to `end_s`.
        """
        index, self.pending = self.pending, -1
        alarm = replace(self.alarms[index], after=self.k_ref)
        self.alarms[index] = alarm
        if not self.settings.explain:
            return
        what = 'unexplained'
        if self.recent:
            every = _concat(list(self.recent))
            start = self.t0 + alarm.change_s
            # bounds in time, not in blocks: the same samples whatever the blocks were
            before = every.take((every.time < start)
                                & (every.time >= start - self.settings.explain_s))
            after = every.take((every.time >= start) & (every.time < end_s))
            try:
                what = self.explainer(before, after, self.baseline)
            except (ValueError, ArithmeticError):
                what = 'unexplained'
        self.alarms[index] = replace(alarm, what=what)
        self.what_changed = what

    def _add_to_trend(self, sbm: float, sbb: float, op_s: float, end_s: float,
                      op_total: float) -> None:
        """Pool the bin into the current trend point; close the point when long enough."""
        point = self.trend_point
        if math.isnan(point[3]):
            point[3] = end_s - self.timing.bin_s
        point[:3] += (sbm, sbb, op_s)
        point_s = self.timing.point_s
        long_enough = end_s - point[3] >= point_s * (1.0 - EPS)
        if long_enough and point[2] >= 0.5 * point_s and point[1] > 0:
            self.trend.add(op_total / 3600.0 - 0.5 * point[2] / 3600.0, point[0] / point[1])
            point[:] = [0.0, 0.0, 0.0, math.nan]

    def _check_limit(self, end_s: float) -> list[Alarm]:
        """Raise the limit once when the trend or the window's lower bound crosses it."""
        if not math.isfinite(self.limit_k):
            return []
        level, *_ = self.trend.estimate(self.op_s / 3600.0)
        window = self._window_factor()
        crossed = limit_crossed(level, window.low, self.limit_k)
        if crossed and not self.in_limit:
            self.in_limit = True
            value = level if math.isfinite(level) else window.value
            alarm = Alarm(end_s - self.t0, 'limit',
                          f'leakage factor {value:.3g} >= limit {self.limit_k:.3g}', value)
            self.alarms.append(alarm)
            return [alarm]
        # back below with confidence: a new crossing is new
        if self.in_limit and limit_cleared(level, window.high, self.limit_k):
            self.in_limit = False
        return []

    def acknowledge(self, count: int | None = None) -> int:
        """
        Acknowledge the alarms raised so far, or the first `count` of them.

        An acknowledged alarm stays in :attr:`alarms` (the history is kept) and changes no
        figure: the detector's reference is already the level learned since the change, and
        the leakage factor stays against the baseline, since the limit is on it. It only says
        that someone has seen the alarm, so that a status (the node's) goes back to OK;
        acknowledgements only grow, and an alarm raised later is new.

        Parameters
        ----------
        count : int, optional
            Alarms acknowledged from the first; all raised so far by default (more than
            were raised: all of them), [-]

        Returns
        -------
        int
            The alarms acknowledged now.

        """
        raised = len(self.alarms)
        wanted = raised if count is None else min(max(int(count), 0), raised)
        self.acknowledged = max(self.acknowledged, wanted)
        return self.acknowledged

    # ------------------------------------------------------------------ figures out
    def _window_factor(self) -> Estimate:
        """Return the pooled factor over the window with its 95 % interval."""
        if not self.window:
            return Estimate(math.nan)
        num = sum(w[0] for w in self.window)
        den = sum(w[1] for w in self.window)
        if den <= 0:
            return Estimate(math.nan)
        k = num / den
        c2, phi = self._noise_now()
        if not math.isfinite(c2):  # first learning: the bins' correlation is not known
            return Estimate(k)
        half = 1.96 * math.sqrt(c2 * (1 + phi) / (1 - phi) / den)
        return Estimate(k, k - half, k + half)

    def _noise_now(self) -> tuple[float, float]:
        """Return c^2 and phi: the last learned ones (NaN before the first learning ends)."""
        return self.c2, self.phi

    def snapshot(self) -> HealthSnapshot:
        """
        Return everything the monitor knows now.

        Returns
        -------
        HealthSnapshot
            The figures with their intervals, the counts and every alarm.

        """
        op_h = self.op_s / 3600.0
        level, level_hw, slope, slope_hw, phi_t = self.trend.estimate(op_h)
        to_limit = _hours_to(self.limit_k, level, level_hw, slope, slope_hw)
        why = ''
        if self.in_limit:  # crossed by the rule (limit_crossed): no trend needed to say so
            to_limit = Estimate(0.0, 0.0, 0.0)
            why = (f'0: the limit is crossed (leakage factor {self.limit_k:.3g}: the trend or '
                   "the window's 95 % lower bound reached it)")
        elif math.isnan(to_limit.value):
            since = (f'the change at {self.change_s:.0f} s' if math.isfinite(self.change_s)
                     else 'the first sample')
            why = (f'null: no trend yet since {since}: {self.trend.n} of {MIN_POINTS} points of '
                   f'{self.timing.point_s:g} s of operation')
        recording_h = (self.t_last - self.t0) / 3600.0 if math.isfinite(self.t0) else 0.0
        ratio = recording_h / op_h if op_h > 0 else 1.0
        window = self._window_factor()
        c2, phi = self._noise_now()
        eta_ref = Estimate(math.nan)
        if math.isfinite(self.reference_loss) and math.isfinite(window.value):
            qn = self.baseline.displacement * self.reference_speed
            eta = [qn / (qn + k * self.reference_loss) for k in
                   (window.value, window.high, window.low)]
            eta_ref = Estimate(*eta)
        point = self.last_point
        return HealthSnapshot(
            time_s=self.t_last - self.t0 if math.isfinite(self.t0) else math.nan,
            operating_hours=op_h, recording_hours=recording_h, learning=self.learning,
            leakage_factor=window, trend=Estimate(level, level - level_hw, level + level_hw),
            trend_per_hour=Estimate(slope, slope - slope_hw, slope + slope_hw),
            hours_to_limit=Estimate(ratio * to_limit.value, ratio * to_limit.low,
                                    ratio * to_limit.high),
            operating_hours_to_limit=to_limit, limit_leakage_factor=self.limit_k,
            volumetric_efficiency=point.volumetric_efficiency if point else math.nan,
            volumetric_efficiency_reference=eta_ref, reference_speed=self.reference_speed,
            reference_dp=self.reference_dp,
            statistic=0.0 if self.learning else self.cusum.statistic, threshold=self.cusum.h,
            noise={'sample_var_rest': self.var_a, 'sample_var_per_rate2': self.var_b,
                   'bin_inflation': c2, 'bin_autocorrelation': phi,
                   'trend_autocorrelation': phi_t,
                   'reference_temperature': self.baseline.reference_temperature},
            n_samples=self.n_samples + sum(len(b) for b in self.held),
            n_skipped=sum(self.skipped.values()),
            n_used={'noise_model': self.n_noise, 'bins': self.n_binned,
                    'open': int(round(self.open_bin[0] + self.carry[0])),
                    'held': sum(len(b) for b in self.held)},
            skipped=dict(self.skipped), alarms=tuple(self.alarms), change_s=self.change_s,
            in_limit=self.in_limit, hours_to_limit_why=why,
            what_changed=self.what_changed, acknowledged=self.acknowledged,
            timing={'sample_step_s': self.step_s, 'bin_s': self.timing.bin_s,
                    'max_gap_s': self.timing.gap_s, 'trend_point_s': self.timing.point_s})

    def pop_points(self) -> list[HealthPoint]:
        """
        Return the bins' figures since the last call, and forget them (bounded memory).

        Returns
        -------
        list of HealthPoint
            One per bin with a factor, in time order.

        """
        points, self.points = self.points, []
        return points

    # ------------------------------------------------------------------ state
    def save(self, path: str | Path) -> Path:
        """
        Save the state to a file, whole or not at all (a temporary name, then renamed).

        Parameters
        ----------
        path : str or pathlib.Path
            The state file (JSON), [-]

        Returns
        -------
        pathlib.Path
            The file.

        """
        path = Path(path)
        tmp = path.with_name(f'.{path.name}.partial-{os.getpid()}')
        tmp.write_text(json.dumps(_to_json(self._state())), encoding='utf-8')
        os.replace(tmp, path)
        return path

    def _state(self) -> dict[str, Any]:
        skip = {'baseline', 'explainer', 'settings', 'recent', 'points', 'last_point', 'timing',
                'held', 'trend_bins'}
        state = {k: v for k, v in vars(self).items() if k not in skip}
        state['cusum'] = asdict(self.cusum)
        state['trend'] = self.trend.state()
        state['window'] = list(self.window)
        state['alarms'] = [asdict(a) for a in self.alarms]
        state['settings'] = asdict(self.settings)
        state['recent'] = [asdict(b) for b in self.recent]
        state['held'] = [asdict(b) for b in self.held]
        state['trend_bins'] = [list(b) for b in self.trend_bins]
        state['version'] = STATE_VERSION
        state['baseline'] = self.baseline.fingerprint
        return state

    @classmethod
    def resume(cls, path: str | Path, baseline: Baseline,
               explainer: Explainer | None = None) -> HealthMonitor:
        """
        Resume a monitor from a state file written by :meth:`save`.

        Parameters
        ----------
        path : str or pathlib.Path
            The state file, [-]
        baseline : Baseline
            The same baseline the state was made with, [-]
        explainer : callable, optional
            As for the constructor, [-]

        Returns
        -------
        HealthMonitor
            The monitor as it was saved.

        Raises
        ------
        DataError
            If the file is not a state of this version (the message names the field).

        """
        try:
            state = _from_json(json.loads(Path(path).read_text(encoding='utf-8')))
        except (OSError, ValueError) as err:
            msg = f'{path}: not a health state (cut short, or not JSON: {err})'
            raise DataError(msg) from None
        if not isinstance(state, dict) or state.get('version') != STATE_VERSION:
            version = state.get('version') if isinstance(state, dict) else None
            msg = f'{path}: version = {version!r}: need {STATE_VERSION}'
            raise DataError(msg)
        if state.get('baseline') != baseline.fingerprint:
            msg = (f'{path}: baseline = {state.get("baseline")!r} in the state, '
                   f'{baseline.fingerprint!r} given: the state was made against another model')
            raise DataError(msg)
        settings = check_settings(state.pop('settings', None), str(path))
        monitor = cls(baseline, settings, explainer)
        like = template(monitor._state())
        like.pop('settings')
        check_state(compatible(state), like, str(path))  # names the field, or all is there
        try:
            monitor._restore(state)
        except (KeyError, TypeError, ValueError, IndexError) as err:  # what the check missed
            msg = f'{path}: not a health state ({type(err).__name__}: {err})'
            raise DataError(msg) from None
        return monitor

    def _restore(self, state: dict[str, Any]) -> None:
        """Take the fields of a checked state."""
        settings = self.settings
        self.cusum = Cusum(**state.pop('cusum'))
        trend = Trend(settings.trend_hours)
        for key, value in state.pop('trend').items():
            setattr(trend, key, value)
        self.trend = trend
        window = [tuple(w) for w in state.pop('window')]
        self.alarms = [Alarm(**a) for a in state.pop('alarms')]
        self.recent.extend(_samples(b) for b in state.pop('recent'))
        self.held = [_samples(b) for b in state.pop('held', [])]
        self.trend_bins = deque(state.pop('trend_bins'))
        for name in ('version', 'baseline'):
            state.pop(name)
        state['last_flow_rate_x'] = tuple(state['last_flow_rate_x'])
        for key, value in state.items():
            setattr(self, key, value)
        if not math.isnan(self.step_s):
            self.timing = Timing.for_step(settings, self.step_s)
        self.window = deque(window, maxlen=self.timing.window_bins)


def _to_json(x: Any) -> Any:
    """Make a state JSON-able: arrays as lists, non-finite floats as strings."""
    if isinstance(x, dict):
        return {k: _to_json(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_to_json(v) for v in x]
    if isinstance(x, np.ndarray):
        if x.dtype == bool:
            return {'__bool__': x.tolist()}
        return {'__array__': [_to_json(float(v)) for v in x.ravel()]}
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else repr(float(x))
    if isinstance(x, np.integer):
        return int(x)
    return x


def _from_json(x: Any) -> Any:
    if isinstance(x, dict):
        if '__array__' in x:
            return np.array([_from_json(v) for v in x['__array__']], dtype=float)
        if '__bool__' in x:
            return np.array(x['__bool__'], dtype=bool)
        return {k: _from_json(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_from_json(v) for v in x]
    if x in ('nan', 'inf', '-inf'):
        return float(x)
    return x


def _concat(blocks: list[HealthSamples]) -> HealthSamples:
    """Join blocks (optional channels kept only when every block has them)."""
    def join(name: str) -> np.ndarray | None:
        parts = [getattr(b, name) for b in blocks]
        return None if any(p is None for p in parts) else np.concatenate(parts)

    def every(name: str) -> FloatArray:
        return np.concatenate([getattr(b, name) for b in blocks])

    stale = None
    if any(b.stale is not None for b in blocks):  # a node's blocks say which are stale
        stale = np.concatenate([np.zeros(len(b), dtype=bool) if b.stale is None else b.stale
                                for b in blocks])
    return HealthSamples(every('time'), every('speed'), every('flow'), every('p_in'),
                         every('p_out'), join('p_case'), join('temperature'), stale)


def _samples(saved: dict[str, Any]) -> HealthSamples:
    """Rebuild samples saved as a dict of arrays (or None)."""
    def get(name: str) -> np.ndarray | None:
        value = saved.get(name)
        return None if value is None else np.asarray(value)
    return HealthSamples(np.asarray(saved['time'], dtype=float),
                         np.asarray(saved['speed'], dtype=float),
                         np.asarray(saved['flow'], dtype=float),
                         np.asarray(saved['p_in'], dtype=float),
                         np.asarray(saved['p_out'], dtype=float),
                         get('p_case'), get('temperature'), get('stale'))


def _weighted_median(x: FloatArray, w: FloatArray) -> float:
    order = np.argsort(x)
    cum = np.cumsum(w[order])
    return float(x[order][np.searchsorted(cum, 0.5 * cum[-1])])


def limit_crossed(level: float, window_low: float, limit: float) -> bool:
    """
    Tell whether the leakage factor has crossed its limit: the one rule, for every door.

    Crossed when the trend's level, or the windowed factor's 95 % lower bound, is at or
    above the limit: a single noisy window above it is not a crossing.

    Parameters
    ----------
    level : float
        The trend's level now (NaN without a trend), [-]
    window_low : float
        The windowed factor's 95 % lower bound (NaN without an interval), [-]
    limit : float
        The limit as a leakage factor, [-]

    Returns
    -------
    bool
        True when crossed.

    """
    return (math.isfinite(level) and level >= limit) or (
        math.isfinite(window_low) and window_low >= limit)


def limit_cleared(level: float, window_high: float, limit: float) -> bool:
    """
    Tell whether a crossed limit is left behind with confidence (a new crossing is new).

    Parameters
    ----------
    level : float
        The trend's level now, [-]
    window_high : float
        The windowed factor's 95 % upper bound, [-]
    limit : float
        The limit as a leakage factor, [-]

    Returns
    -------
    bool
        True when the upper bound is below 90 % of the limit and the trend is below it.

    """
    above = math.isfinite(level) and level >= limit
    return window_high < 0.9 * limit and not above


def _hours_to(limit: float, level: float, level_hw: float, slope: float,
              slope_hw: float) -> Estimate:
    """Return the hours until the line reaches `limit`, with an interval (inf: never)."""
    if not all(math.isfinite(x) for x in (limit, level, slope)):
        return Estimate(math.nan)
    if level >= limit:
        return Estimate(0.0, 0.0, 0.0)
    low_rate, high_rate = slope - slope_hw, slope + slope_hw
    # a slope whose interval holds no rise gives no date: its sign is the noise's
    value = (limit - level) / slope if low_rate > 0 else math.inf
    soonest = max(limit - (level + level_hw), 0.0) / high_rate if high_rate > 0 else math.inf
    latest = (limit - (level - level_hw)) / low_rate if low_rate > 0 else math.inf
    return Estimate(value, soonest, latest)


__all__ = ['Explainer', 'HealthMonitor', 'limit_cleared', 'limit_crossed']
