# SPDX-License-Identifier: Apache-2.0
"""Outliers that cluster are a region the model misses; an isolated bad row is still left out."""

from dataclasses import replace

import numpy as np
import pytest

from satmotor_ros.identify import calibrate
from satmotor_ros.identify.regions import clustered, regions, Space
from satmotor_ros.identify.selection import Errors
from satmotor_ros.identify.synthetic import generate, Injection, Plan, with_outliers
from satmotor_ros.model.units import LPM, MPA, RPM


def _cloud(seed=0, n=400):
    rng = np.random.default_rng(seed)
    dp = rng.uniform(-25e6, 25e6, n)
    speed = rng.uniform(-1500, 1500, n) * RPM
    return dp, speed, rng.normal(size=n)


def test_a_corner_of_outliers_clusters_and_an_isolated_one_does_not():
    dp, speed, z = _cloud()
    corner = (dp < -21e6) & (speed < 0)
    z[corner] += 8.0  # a valve in one direction at the top of the drop
    lone = int(np.flatnonzero((dp > 0) & (np.abs(speed) < 500 * RPM))[0])
    z[lone] = -9.0
    flagged = np.abs(z) > 4.0
    member = clustered(flagged, z, Space(dp, speed))
    assert member[corner].all() and not member[lone]
    found = regions(flagged, z, Space(dp, speed))
    kind, rows = found[0]
    assert kind == 'operating space' and set(rows) == set(np.flatnonzero(corner))


def test_noise_alone_never_clusters():
    for seed in range(20):
        dp, speed, z = _cloud(seed)
        flagged = np.abs(z) > 2.5  # many outliers, none structural
        assert not clustered(flagged, z, Space(dp, speed, np.arange(dp.size, dtype=float))).any()


def test_a_span_of_time_clusters():
    dp, speed, z = _cloud(1)
    z[100:110] -= 7.0  # a transient the model lacks, everywhere in the operating space
    flagged = np.abs(z) > 4.0
    space = Space(dp, speed, np.arange(dp.size, dtype=float))
    assert clustered(flagged, z, space)[100:110].all()
    assert not clustered(flagged, z, Space(dp, speed))[100:110].any()


@pytest.fixture(scope='module')
def bump():
    """Calibrate on a bump of flow in one region no candidate has, beside a bad row."""
    table = generate(Plan(liquid='oil', n_points=120), Injection(), seed=2)
    dp = table.p_in - table.p_out
    region = (dp > 10e6) & (dp < 15e6) & (table.speed > 500 * RPM) & (table.speed < 1000 * RPM)
    bad = int(np.flatnonzero(~region)[5])
    table = with_outliers(replace(table, flow=table.flow + np.where(region, 0.4 * LPM, 0.0)),
                          [bad], [2.0])
    return calibrate(table, 'oil'), region, bad


def test_a_cluster_is_kept_in_the_fit_and_named_and_a_bad_row_is_still_listed(bump):
    cal, region, bad = bump
    summary = cal.summary()
    listed = {o['row'] for o in summary['outliers']}
    assert bad in listed
    assert not listed & set(np.flatnonzero(region))
    missed = summary['missed_regions'][0]
    assert missed['kind'] == 'operating space' and missed['direction'] == 'positive'
    assert missed['rows'] >= region.sum() - 2
    assert 9.5 < missed['dp_mpa'][0] < missed['dp_mpa'][1] < 15.5
    assert missed['mean_residual_lpm'] == pytest.approx(0.4, rel=0.2)


def test_errors_over_every_row_give_the_outliers_in_a_second_figure(bump):
    cal, _, bad = bump
    summary = cal.summary()
    every = Errors.of(cal.forward.final.cv_error, cal.parts.loss)
    assert summary['error_after_with_outliers'] == every.as_dict()
    assert summary['error_after_with_outliers']['max_abs_lpm'] > 1.6  # the bad row's 2.0
    assert summary['error_after']['max_abs_lpm'] < 0.6  # the bump's rows are in it
    assert summary['error_after']['max_abs_lpm'] > 0.3
    assert summary['error_before_with_outliers']['rmse_lpm'] >= summary['error_before'][
        'rmse_lpm']


def test_coverage_of_steady_points_is_every_row_and_its_envelope(bump):
    cal, _, _ = bump
    coverage = cal.summary()['coverage']
    assert coverage['samples_used'] == coverage['samples_total'] == len(cal.parts)
    dp = cal.table.p_in - cal.table.p_out
    env = coverage['envelope']
    assert set(env) == {'positive'}
    assert env['positive']['dp_mpa'] == pytest.approx([dp.min() / MPA, dp.max() / MPA],
                                                      rel=1e-3)
    assert env['positive']['samples'] == len(cal.parts)
