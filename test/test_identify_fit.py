# SPDX-License-Identifier: Apache-2.0
"""The fitter: packaged values recovered, intervals that cover, clear refusals."""

from dataclasses import replace

import numpy as np
import pytest

from satmotor_ros.identify import (calibrate, check_identifiable, IdentificationError,
                                   loss_parts, LossFit)
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.model import load_motor, MotorModel


@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_fit_recovers_scaled_coefficients_with_covering_intervals(liquid):
    spec = load_motor()
    truth = (1.3, 0.8, 1.1)
    base = spec.sets[liquid]
    coef = replace(base.coefficients, a1=base.coefficients.a1 * truth[0],
                   c1=base.coefficients.c1 * truth[0], c=base.coefficients.c * truth[1],
                   c_id=base.coefficients.c_id * truth[2])
    rng = np.random.default_rng(4)
    true_model = MotorModel(spec.geometry, replace(base, coefficients=coef), spec.valid_range)
    table = generate(Plan(liquid=liquid, n_points=200), Injection(), seed=4)
    flow = true_model.absorbency(table.speed, dp=table.dp).flow
    table = replace(table, flow=flow + rng.normal(0, 1e-6, flow.size))
    parts, _ = loss_parts(MotorModel.default(liquid), table)
    report = LossFit().fit(parts).report()
    for value, (lo, hi), true in zip(report.values[:3], report.ci95[:3], truth):
        assert lo <= true <= hi
        assert value == pytest.approx(true, rel=0.15)


def _parts(**plan):
    table = generate(Plan(**plan), Injection(), seed=0)
    return loss_parts(MotorModel.default('oil'), table)[0]


@pytest.mark.parametrize(('plan', 'match'), [
    ({'n_points': 5}, 'too few points: 5'),
    ({'speed_rpm': (1000.0, 1001.0)}, 'one speed only'),
    ({'dp_mpa': (10.0, 10.2)}, 'one pressure drop only'),
])
def test_fit_refuses_data_that_cannot_determine_the_coefficients(plan, match):
    with pytest.raises(IdentificationError, match=match):
        check_identifiable(_parts(**plan))


def test_calibrate_refuses_one_speed_in_one_line():
    table = generate(Plan(speed_rpm=(500.0, 505.0)), Injection(), seed=0)
    with pytest.raises(IdentificationError, match='C_id') as info:
        calibrate(table, 'oil')
    assert '\n' not in str(info.value)


def test_fit_predict_before_fit_is_an_error():
    with pytest.raises(IdentificationError, match='not fitted'):
        LossFit().predict(_parts())


def test_fit_names_a_coefficient_the_points_cannot_move():
    parts = _parts()
    leakage, c, c_id = parts.components
    dead = replace(c_id, pieces=(('', np.zeros(len(parts))),))
    zero = replace(parts, components=(leakage, c, dead))
    with pytest.raises(IdentificationError, match='c_id_scale is not determined'):
        LossFit().fit(zero).report()
