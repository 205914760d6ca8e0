# SPDX-License-Identifier: Apache-2.0
"""The one root solver on its own: scalar and array forms, tolerances, flags, properties."""

import math
import warnings

from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

from satmotor_ros.model import MotorModel, PointStatus
from satmotor_ros.model.engine.solve import solve_increasing, solve_increasing_scalar, Tolerance
from satmotor_ros.model.units import LPM, MPA, RPM

NO_ROOT, NOT_CONVERGED = int(PointStatus.NO_ROOT), int(PointStatus.NOT_CONVERGED)


def _cube(x):
    return x ** 3 - 2.0, 3.0 * x * x


def _both(func, lo, hi, x0, tol, **kwargs):
    """Run both forms on one problem; return the scalar result after checking they agree."""
    x, status = solve_increasing_scalar(func, lo, hi, x0, tol, **kwargs)
    xs, statuses = solve_increasing(func, np.array([lo]), np.array([hi]), np.array([x0]), tol,
                                    **kwargs)
    assert (float(xs[0]), int(statuses[0])) == (x, status) or (
        math.isnan(x) and math.isnan(xs[0]) and status == statuses[0])
    return x, status


def test_newton_converges_to_the_root_from_the_upper_end():
    x, status = solve_increasing(_cube, np.array([0.0, 1.0]), np.array([2.0, 4.0]),
                                 np.array([2.0, 4.0]), Tolerance(0.0, 1e-13))
    np.testing.assert_allclose(x, 2.0 ** (1 / 3), rtol=1e-15)
    assert (status == 0).all()
    root = _both(_cube, 0.0, 2.0, 2.0, Tolerance(0.0, 1e-13))[0]
    assert root == pytest.approx(2.0 ** (1 / 3), rel=1e-15)


def test_without_a_usable_slope_it_bisects_to_the_bracket_tolerance():
    calls = []

    def flat(x):
        calls.append(1)
        return x ** 3 - 2.0, 0.0 * x  # no slope: every step is a bisection

    x, status = solve_increasing_scalar(flat, 0.0, 2.0, 2.0, Tolerance(1e-6))
    assert status == 0 and abs(x - 2.0 ** (1 / 3)) <= 1e-6
    assert 19 <= len(calls) <= 23  # log2(2 / 1e-6) = 21 halvings
    assert _both(flat, 0.0, 2.0, 2.0, Tolerance(1e-6, maxiter=5))[1] == NOT_CONVERGED


def test_relative_tolerance_scales_with_the_estimate():
    def flat(x):
        return x - 3e6, 0.0 * x

    x, status = _both(flat, 0.0, 4e6, 4e6, Tolerance(0.0, 1e-9))
    assert status == 0 and abs(x - 3e6) <= 1e-9 * 3e6 * 2


def test_an_element_with_a_nan_residual_stops_at_once_as_no_root():
    def func(x):
        f, s = _cube(x)
        return np.where([True, False], f, np.nan), s

    x, status = solve_increasing(func, np.array([0.0, 0.0]), np.array([2.0, 2.0]),
                                 np.array([2.0, 1.5]), Tolerance(1e-12))
    assert status.tolist() == [0, NO_ROOT] and x[1] == 1.5
    assert x[0] == pytest.approx(2.0 ** (1 / 3), rel=1e-12)
    assert solve_increasing_scalar(lambda x: (math.nan, 1.0), 0.0, 2.0, 1.5, Tolerance(1e-12)) \
        == (1.5, NO_ROOT)


def test_a_bracket_closing_on_a_jump_is_no_root_not_a_root():
    def step(x):
        return (-1.0 if x < 1.0 else 1.0) + 0.0 * x, 0.0 * x  # no root, a jump at 1

    x, status = _both(step, 0.0, 2.0, 2.0, Tolerance(1e-9), check=1e-3)
    assert status == NO_ROOT and x == pytest.approx(1.0, abs=1e-8)


def test_the_mirror_bound_of_a_fixed_point_closes_an_open_bracket():
    def residual(x):  # x = g(x) with g(x) = 2 / (1 + x), falling; root 1
        return x - 2.0 / (1.0 + x), 1.0 + 2.0 / (1.0 + x) ** 2

    x, status = _both(residual, 0.0, math.inf, 0.0, Tolerance(0.0, 1e-14), mirror=True)
    assert status == 0 and x == pytest.approx(1.0, rel=1e-14)


def test_integer_brackets_are_accepted():
    x, status = solve_increasing(_cube, np.array([0]), np.array([2]), np.array([2]),
                                 Tolerance(1e-12))
    assert x.dtype == np.float64 and x[0] == pytest.approx(2.0 ** (1 / 3), rel=1e-12)


def test_a_closed_bracket_is_done_before_any_evaluation():
    def never(x):
        raise AssertionError('evaluated')

    x, status = solve_increasing(never, np.array([1.0]), np.array([1.0]), np.array([1.0]),
                                 Tolerance(0.0))
    assert (status == 0).all() and x[0] == 1.0
    assert solve_increasing_scalar(never, 1.0, 1.0, 1.0, Tolerance(0.0)) == (1.0, 0)


@settings(max_examples=300, deadline=None)
@given(root=st.floats(-50.0, 50.0), power=st.sampled_from([1, 3, 5]),
       width=st.floats(1e-3, 100.0), left=st.floats(0.0, 1.0), start=st.floats(0.0, 1.0),
       jump=st.floats(-2.0, 2.0), maxiter=st.integers(1, 60))
def test_every_answer_is_in_its_bracket_and_ok_only_with_a_small_residual(
        root, power, width, left, start, jump, maxiter):
    # increasing f with a root (jump = 0) or a jump across zero at `root` (no root)
    def func(x):
        d = x - root
        return d ** power + (jump if d >= 0.0 else -jump) * (jump > 0), power * d ** (power - 1)

    lo = root - left * width
    hi = lo + width
    x0 = lo + start * width
    check = 1e-6
    tol = Tolerance(1e-12, 1e-12, maxiter=maxiter)
    for x, status in [solve_increasing_scalar(func, lo, hi, x0, tol, check)]:
        assert lo <= x <= hi  # the bracket is respected
        assert status in (0, NO_ROOT, NOT_CONVERGED)
        if status == 0:  # OK means a small residual at x (or one Newton step below it)
            assert abs(func(x)[0]) <= max(check, 1e-6)
        if jump > 1e-3 and lo < root < hi:
            assert status != 0  # a jump across zero is never reported as a root
    xs, statuses = solve_increasing(lambda v: tuple(np.array([func(float(v[0]))[i]])
                                                    for i in range(2)),
                                    np.array([lo]), np.array([hi]), np.array([x0]), tol, check)
    assert (float(xs[0]), int(statuses[0])) == (x, status)  # one algorithm, two forms


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
