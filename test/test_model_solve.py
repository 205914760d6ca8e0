# SPDX-License-Identifier: Apache-2.0
"""The bracketed Newton solver on its own: bisection, tolerances, NaN and the iteration limit."""

import warnings

import numpy as np
import pytest

from satmotor_ros.model import MotorModel
from satmotor_ros.model.solve import solve_increasing
from satmotor_ros.model.units import LPM, MPA, RPM


def _cube(x):
    return x ** 3 - 2.0, 3.0 * x * x


def test_newton_converges_to_the_root_from_the_upper_end():
    x, ok = solve_increasing(_cube, np.array([0.0, 1.0]), np.array([2.0, 4.0]),
                             np.array([2.0, 4.0]), xtol=0.0, rtol=1e-13)
    np.testing.assert_allclose(x, 2.0 ** (1 / 3), rtol=1e-15)
    assert ok.all()


def test_without_a_usable_slope_it_bisects_to_the_bracket_tolerance():
    calls = []

    def flat(x):
        calls.append(1)
        return x ** 3 - 2.0, np.zeros_like(x)  # no slope: every step is a bisection

    x, ok = solve_increasing(flat, np.array([0.0]), np.array([2.0]), np.array([2.0]),
                             xtol=1e-6)
    assert ok.all() and abs(x[0] - 2.0 ** (1 / 3)) <= 1e-6
    assert 19 <= len(calls) <= 23  # log2(2 / 1e-6) = 21 halvings
    x, ok = solve_increasing(flat, np.array([0.0]), np.array([2.0]), np.array([2.0]),
                             xtol=1e-6, maxiter=5)
    assert not ok.any()


def test_relative_tolerance_scales_with_the_estimate():
    def flat(x):
        return x - 3e6, np.zeros_like(x)

    x, ok = solve_increasing(flat, np.array([0.0]), np.array([4e6]), np.array([4e6]),
                             xtol=0.0, rtol=1e-9)
    assert ok.all() and abs(x[0] - 3e6) <= 1e-9 * 3e6 * 2


def test_an_element_with_a_nan_residual_stops_at_once():
    def func(x):
        f, s = _cube(x)
        return np.where([True, False], f, np.nan), s

    x, ok = solve_increasing(func, np.array([0.0, 0.0]), np.array([2.0, 2.0]),
                             np.array([2.0, 1.5]), xtol=1e-12)
    assert ok.all() and x[1] == 1.5
    assert x[0] == pytest.approx(2.0 ** (1 / 3), rel=1e-12)


def test_integer_brackets_are_accepted():
    x, ok = solve_increasing(_cube, np.array([0]), np.array([2]), np.array([2]), xtol=1e-12)
    assert x.dtype == np.float64 and x[0] == pytest.approx(2.0 ** (1 / 3), rel=1e-12)


def test_a_closed_bracket_is_done_before_any_evaluation():
    def never(x):
        raise AssertionError('evaluated')

    x, ok = solve_increasing(never, np.array([1.0]), np.array([1.0]), np.array([1.0]),
                             xtol=0.0)
    assert ok.all() and x[0] == 1.0


@pytest.mark.parametrize('law', ['eq33', 'eq39'])
@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_maps_raise_no_numpy_warnings_at_zero_speed_and_pressure(law, liquid):
    model = MotorModel.default(liquid, law)
    speed = np.array([0.0, 1e-6, 50.0, 300.0]) * RPM
    drop = np.array([0.0, 1e-3, 0.5, 1.0, 10.0]) * MPA
    n, dp = (a.ravel() for a in np.meshgrid(speed, drop))
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        for kind in ('dp', 'dp_i'):
            model.absorbency(n, **{kind: dp}, errors='mask')
            model.speed(np.array([0.0, 0.01, 5.0]) * LPM, **{kind: 10 * MPA}, errors='mask')
            model.speed(np.array([0.0, 0.01, 5.0]) * LPM, **{kind: 0.0}, errors='mask',
                        method='iterative')
