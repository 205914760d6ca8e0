# SPDX-License-Identifier: Apache-2.0
"""The base's note on a kept channel drop reads whole (cold review of issue 20, finding 8)."""

import numpy as np
from satmotor_ros.identify import base as base_module
from satmotor_ros.identify.base import _with_factor, fit_base
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import MotorModel
from satmotor_ros.model.families.defaults import default_motor
from satmotor_ros.model.units import CM3_PER_REV, LPM, MPA, RPM


def _pinned_points():
    """Steady points of a motor whose channel drop is half the guess: the data pin it."""
    spec = default_motor('sliwinski2017', 4.92 * CM3_PER_REV)
    channel = MotorModel.from_spec(spec, 'oil').family.channel
    truth = MotorModel.from_spec(_with_factor(spec, 'oil', channel, 0.5), 'oil')
    rng = np.random.default_rng(1)
    speed = rng.uniform(300.0, 5000.0, 400) * RPM
    dp = rng.uniform(2.0, 20.0, 400) * MPA
    flow = truth.absorbency(speed, dp, errors='mask').flow
    ok = np.isfinite(flow)
    flow = flow + rng.normal(0.0, 0.02 * LPM, 400)
    return spec, BenchTable(speed[ok], flow[ok], dp[ok] + 0.5 * MPA,
                            np.full(int(ok.sum()), 0.5 * MPA))


def test_a_drop_kept_for_an_interval_over_the_whole_range_says_so_with_no_empty_field(
        monkeypatch):
    spec, points = _pinned_points()
    # the profile's interval spans the range (as on the 10 Hz variant of the 2021 MBARI log)
    monkeypatch.setattr(base_module, '_interval', lambda profile, best, bound, level:
                        (0.0, bound))
    base = fit_base(spec, 'oil', points)
    assert not base.fitted
    assert 'the 95 % profile interval spans the whole range (factor range 0-' in base.note
    assert '(,' not in base.note and '( ' not in base.note
    why = {k['coefficient']: k['why'] for k in base.kept}['c_t']
    assert why.startswith('the 95 % profile interval spans the whole range (factor range 0-')


def test_a_drop_the_data_do_not_pin_gives_its_gain_and_range():
    spec, points = _pinned_points()
    base = fit_base(spec, 'oil', BenchTable(
        points.speed[:40], points.flow[:40] + np.random.default_rng(2).normal(0.0, 2 * LPM, 40),
        points.p_in[:40], points.p_out[:40]))
    note = base.note
    assert 'the data do not pin it (profile: chi2 gain ' in note, note
    assert ', factor range 0-' in note and '(,' not in note
