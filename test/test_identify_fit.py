# SPDX-License-Identifier: Apache-2.0
"""The fitter: packaged values recovered, intervals that cover, clear refusals."""

from dataclasses import replace

import numpy as np
import pytest

from satmotor_ros.identify import (calibrate, check_identifiable, IdentificationError,
                                   loss_parts, LossFit)
from satmotor_ros.identify.candidates import build_library
from satmotor_ros.identify.fit import HUBER
from satmotor_ros.identify.synthetic import generate, Injection, Plan
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model.viscosity import standard_law
from scipy.optimize._numdiff import approx_derivative


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


def _fit_cases():
    """Return parts with a nuisance regressor and candidates of each shape: a valve, a gain."""
    table = generate(Plan(liquid='oil', n_points=120), Injection('flow_sensor_gain', 0.1, 'flow'),
                     seed=5)
    model = MotorModel.default('oil')
    parts, _ = loss_parts(model, table)
    parts = parts.with_nuisance({'drift': np.linspace(-1.0, 1.0, len(parts))})
    channels = {**table.channels, 'p_out': table.p_out}
    candidates, _ = build_library(parts, channels, standard_law(model.liquid, 'oil'))
    chosen = [next(c for c in candidates if c.effect.startswith(kind))
              for kind in ('threshold:', 'flow_sensor_gain')]
    return parts, chosen


@pytest.mark.parametrize('robust', ['plain', 'huber', 'tukey'])
def test_the_fits_jacobian_is_exact_in_the_linear_parameters_and_scipys_in_the_effects(
        robust, monkeypatch):
    parts, chosen = _fit_cases()
    sigma = np.full(len(parts), 0.05 * float(np.std(parts.loss)))
    index = np.arange(0, len(parts), 2)
    options = {'plain': {}, 'huber': {'robust': HUBER}, 'tukey': {'redescending': True}}[robust]
    for effects in ((), chosen[:1], chosen):
        fit = LossFit(effects, sigma, **options)
        fit._layout(parts)
        lower, upper, starts = fit._starts(parts, None)
        residual, jacobian = fit._problem(parts, index, lower, upper)
        u = np.clip(starts[-1] + 0.1, lower, upper)
        u[0] = upper[0]  # a step turned back at the bound
        linear = fit.m_ + fit.typical_.size
        ours = jacobian(u)
        forward = approx_derivative(residual, u, method='2-point', bounds=(lower, upper))
        central = approx_derivative(residual, u, method='3-point', bounds=(lower, upper))
        # the factors and nuisance coefficients: the derivative (central differences agree
        # to 1e-7 of each column, forward ones only to their step's error)
        scale = np.max(np.abs(central[:, :linear]), axis=0)
        assert np.all(np.abs(ours[:, :linear] - central[:, :linear]) <= 1e-7 * scale)
        assert not np.array_equal(ours[:, :linear], forward[:, :linear])
        assert np.array_equal(ours[:, linear:], forward[:, linear:])  # the effects': scipy's
        ours = LossFit(effects, sigma, **options).fit(parts, index)
        problem = LossFit._problem
        monkeypatch.setattr(LossFit, '_problem', lambda self, *a: (problem(self, *a)[0],
                                                                   '2-point'))
        theirs = LossFit(effects, sigma, **options).fit(parts, index)
        monkeypatch.undo()
        # the same optimum as with scipy's forward differences in every column, or a lower
        # one (a gain beside a valve: a flat valley the rougher slopes stop in earlier)
        assert ours.objective_ <= theirs.objective_ * (1.0 + 1e-8)
