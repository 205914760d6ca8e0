# SPDX-License-Identifier: Apache-2.0
"""A valve's response time: its law's flow through a first-order lag at every sample."""

import numpy as np
import pytest

from satmotor_ros.identify.transient import first_order, first_order_at
from satmotor_ros.model.effects import effect_from_mapping
from satmotor_ros.model.effects._base import Sampled
from satmotor_ros.model.effects.threshold import KIND
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.units import MPA

STEP = 0.02
BIN = 5


def _stretches(size, cuts):
    first = np.zeros(size, dtype=bool)
    first[[0, *cuts]] = True
    return first


def test_the_lag_of_a_few_samples_is_the_lag_of_the_whole_series_where_it_is_not_0():
    rng = np.random.default_rng(0)
    first = _stretches(3000, [1200, 2500])
    at = np.sort(rng.choice(3000, 40, replace=False))
    values = rng.uniform(0.5, 2.0, at.size)
    full = np.zeros(3000)
    full[at] = values
    every = first_order(full, np.append(np.flatnonzero(first), 3000), STEP, 0.15)
    reach, lagged = first_order_at(at, values, first, STEP, 0.15)
    np.testing.assert_allclose(lagged, every[reach], rtol=0, atol=1e-12 * values.max())
    outside = np.ones(3000, dtype=bool)
    outside[reach] = False
    assert np.all(np.abs(every[outside]) < 1e-11) and set(at) <= set(reach)


def _sampled(dp, first):
    def mean(x):
        return np.nanmean(x.reshape(-1, BIN), axis=1)

    def sparse(at, x):
        full = np.where(np.isnan(dp), np.nan, 0.0)
        full[at] = x
        return mean(full)
    return Sampled(dp, mean, sparse, lambda at, x, tau: first_order_at(at, x, first, STEP, tau),
                   STEP)


@pytest.mark.parametrize('tau', [0.0, 0.05, 0.3])
def test_the_candidate_passes_its_law_through_the_lag_at_every_sample(tau):
    rng = np.random.default_rng(1)
    size = 4000
    dp = -np.abs(rng.normal(15.0, 4.0, size)) * MPA  # one side: a valve that opens one way
    dp[::97] = np.nan  # unusable samples
    first = _stretches(size, [1500, 3100])
    samples = _sampled(dp, first)
    rows = np.nanmean(np.abs(dp).reshape(-1, BIN), axis=1)
    candidate = KIND._candidate(rows, np.ones(rows.size, dtype=bool), 'negative', False,
                                samples, (0.0, float(np.nanmax(-dp))))
    assert [s.name for s in candidate.shape] == ['threshold', 'exponent', 'response time']
    assert candidate.shape[-1].floor_is_value and candidate.shape[-1].bounds == (0.0, 1.0)
    crack, e = 20.0 * MPA, 1.3
    top = float(rows.max())  # the form is scaled to the rows' top
    law = np.nan_to_num(np.maximum(-dp - crack, 0.0) / (top - crack)) ** e
    if tau > 0.0:
        law = first_order(law, np.append(np.flatnonzero(first), size), STEP, tau)
    expected = np.nanmean(np.where(np.isnan(dp), np.nan, law).reshape(-1, BIN), axis=1)
    got = candidate.modify(2.0, crack, e, tau).additive
    np.testing.assert_allclose(got, 2.0 * expected, rtol=1e-9, atol=1e-12)
    effect = candidate.make(2.0, crack, e, tau)
    assert effect.option('response_time', 0.0) == tau and effect.direction == 'negative'


def test_steady_points_have_no_response_time():
    dp = np.linspace(1.0, 25.0, 200) * MPA
    candidate = KIND._candidate(dp, np.ones(dp.size, dtype=bool), 'both', False)
    assert [s.name for s in candidate.shape] == ['threshold', 'exponent']


def test_a_response_time_is_read_and_written_and_a_bad_one_refused_in_one_line():
    doc = {'coefficient': 1e-10, 'reference': 2e7, 'exponent': 1.0, 'response_time': 0.14,
           'direction': 'negative'}
    effect = effect_from_mapping('threshold:dp@negative', doc, 'effects')
    assert effect.option('response_time') == 0.14
    assert KIND.to_mapping(effect)['response_time'] == 0.14
    static = effect_from_mapping('threshold:dp', {'coefficient': 1e-10, 'reference': 2e7},
                                 'effects')
    assert 'response_time' not in KIND.to_mapping(static)
    for bad in (-0.1, 1.5):
        with pytest.raises(ConfigError, match=r'response_time = .*: must be within 0-1 s'):
            effect_from_mapping('threshold:dp', {**doc, 'response_time': bad,
                                                 'direction': 'both'}, 'effects')
