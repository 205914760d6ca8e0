# SPDX-License-Identifier: Apache-2.0
"""The rows' noise: a floor, a share of the flow and the timing jitter of fast moves."""

import numpy as np
import pytest

from satmotor_ros.identify.noise import noise_model, rates_of
from satmotor_ros.identify.parts import loss_parts
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.identify.transient import at_rest
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM

JITTER = 0.1
"""Spread of the flow reading's timing against the speed's, [s] (the MBARI logs': ~0.1 s)."""


def _jittered(seed, n=2000):
    """Rows of a recording: mostly slow, a few fast moves; residuals of a timing jitter."""
    rng = np.random.default_rng(seed)
    rate = 2.0 * np.exp(rng.normal(0.0, 1.5, n)) * LPM  # (l/min)/s: a heavy tail of fast rows
    flow = rng.uniform(0.0, 30.0, n) * LPM
    truth = np.sqrt((0.05 * LPM) ** 2 + (JITTER * rate) ** 2)
    residual = truth * rng.normal(size=n)
    residual[rng.choice(n, 3, replace=False)] += 5.0 * LPM  # gross bad rows
    # the two rate terms: the speed's (exact here) and the flow reading's (noisier)
    nuisance = {'line_compliance': rng.normal(size=n), 'speed_lag': rate,
                'flow_lag': -rate * rng.uniform(0.7, 1.3, n)}
    return residual, flow, nuisance, rate, truth


@pytest.mark.parametrize('seed', [0, 1])
def test_a_noise_that_grows_with_the_rate_is_estimated_within_a_factor_of_the_truth(seed):
    residual, flow, nuisance, rate, truth = _jittered(seed)
    sigma = noise_model(residual, flow, 6, 1e-12 * LPM, rates_of(nuisance))
    edges = np.quantile(rate, [0.0, 0.5, 0.8, 0.95, 0.99, 1.0])
    for lo, hi in zip(edges[:-1], edges[1:]):  # quiet rows and the fastest alike
        at = (rate >= lo) & (rate <= hi)
        ratio = np.sqrt(np.mean(sigma[at] ** 2) / np.mean(truth[at] ** 2))
        assert 1 / 1.5 < ratio < 1.5, (lo / LPM, hi / LPM, ratio)


def test_the_rates_are_the_transient_terms_of_a_time_series_and_none_for_steady_points():
    speed_lag, flow_lag = np.arange(3.0), -np.arange(3.0)
    rates = rates_of({'line_compliance': np.ones(3), 'speed_lag': speed_lag,
                      'flow_lag': flow_lag})
    assert len(rates) == 2
    np.testing.assert_array_equal(rates[0], speed_lag)
    np.testing.assert_array_equal(rates[1], flow_lag)
    assert rates_of({}) == () and rates_of(None) == ()


def test_without_rates_the_noise_is_a_floor_plus_a_share_of_the_flow():
    rng = np.random.default_rng(3)
    flow = rng.uniform(1.0, 30.0, 400) * LPM
    truth = np.sqrt((0.02 * LPM) ** 2 + (0.01 * flow) ** 2)
    sigma = noise_model(truth * rng.normal(size=flow.size), flow, 3, 1e-12 * LPM)
    assert np.all(np.diff(sigma[np.argsort(flow)]) >= -1e-15)  # grows with the flow only
    assert sigma.max() / sigma.min() == pytest.approx(truth.max() / truth.min(), rel=0.5)


def test_at_rest_keeps_the_noise_of_either_sign_and_a_stalled_valve_drops_a_moving_shaft():
    rng = np.random.default_rng(4)
    noise = rng.normal(0.0, 0.05, 4000) * LPM
    flow = np.concatenate((noise, [4.0 * LPM, 5.0 * LPM, -3.0 * LPM]))
    kept = at_rest(flow)
    # the bulk of the noise is kept on both sides: its mean stays ~0 (one sign only: ~0.04)
    assert kept[:noise.size].mean() > 0.999
    assert abs(np.mean(flow[:noise.size][kept[:noise.size]])) < 0.005 * LPM
    assert kept[-3] and kept[-2] and not kept[-1]  # a valve passing flow at a stall stays
    assert at_rest(np.zeros(0)).size == 0


def test_a_shaft_at_rest_reading_a_flow_against_the_drop_is_usable():
    model = MotorModel.for_displacement(4.9e-6 / (2 * np.pi), 'paszota')
    dp = np.full(4, 5.0 * MPA)
    table = BenchTable(np.array([0.0, 0.0, 500 * RPM, 500 * RPM]),
                       np.array([0.02, -0.02, 2.5, -0.02]) * LPM, dp, np.zeros(4))
    _, usable = loss_parts(model, table)
    # at rest both signs; a shaft turning with the drop and a flow against it is not
    np.testing.assert_array_equal(usable, [True, True, True, False])
