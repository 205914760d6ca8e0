# SPDX-License-Identifier: Apache-2.0
"""A composition specialised per displacement law reads the law's equations in place."""

import numpy as np
import pytest

from satmotor_ros.model import MotorModel
from satmotor_ros.model._inline import inline_per_class
from satmotor_ros.model.units import LPM, MPA, RPM
from test_model_inline import _loaded_names

LAW_TERMS = {'loss_at', 'floor_at', 'pressure_state', 'speed_terms', 'speed_state',
             'pressure_terms', 'displacement_change_empirical', 'displacement_loss',
             'empirical_speed_floor'}


@pytest.mark.parametrize('law', ['eq33', 'eq39'])
def test_the_solvers_residuals_call_none_of_the_laws_equations(law):
    eqs = MotorModel.default('water', law)._point.eqs
    _, upper, flow_residual = eqs.flow_problem(100.0, 10 * MPA, 0.0)
    speed_residual = eqs.speed_problem(20 * LPM, 10 * MPA, 1e-6)[2]
    for func in (flow_residual, upper, speed_residual, eqs.breakdown,
                 eqs.law.at_pressure(10 * MPA)[1], eqs.law.at_speed(100.0)):
        assert not _loaded_names(func) & LAW_TERMS, func


@pytest.mark.parametrize('law', ['eq33', 'eq39'])
def test_law_methods_equal_their_static_equations(law):
    model = MotorModel.default('water', law)
    kind, (a, b) = type(model.law), model.law.constants
    speed = np.array([0.0, 5.0, 300.0, 2000.0]) * RPM
    dp_i = np.array([0.0, 0.5, 3.0, 25.0]) * MPA
    with np.errstate(divide='ignore', invalid='ignore'):
        assert np.array_equal(model.law.loss(speed, dp_i), kind.loss_at(speed, dp_i, a, b))
        assert np.array_equal(model.law.floor(dp_i), kind.floor_at(dp_i, a, b))
        floor, p, p_slope = kind.pressure_state(dp_i, a, b)
        at_floor, terms = model.law.at_pressure(dp_i)
        assert np.array_equal(at_floor, floor)
        assert np.array_equal(terms(speed + 1.0), kind.speed_terms(speed + 1.0, p, p_slope, a, b))


class _Doubling:

    @staticmethod
    def scale(x):
        return x * 2.0


class _Tripling:

    @staticmethod
    def scale(x):
        return x * 3.0

    @staticmethod
    def branching(x):
        if x > 0.0:
            return x
        return -x


@inline_per_class('kind')
def _scaled(kind, x):
    return kind.scale(x) + 1.0


@inline_per_class('kind')
def _branching(kind, x):
    return kind.branching(x)


def test_each_class_gets_its_own_compilation():
    assert _scaled(_Doubling(), 2.0) == 5.0 and _scaled(_Tripling(), 2.0) == 7.0
    assert _scaled(_Doubling(), 1.0) == _scaled.__wrapped__(_Doubling(), 1.0) == 3.0


def test_a_static_method_of_statements_stays_a_call():
    assert _branching(_Tripling(), -2.0) == 2.0


def _square(x):
    return x * x


def _square_of_sum(a, b):
    return _square(a + b)  # arithmetic read twice: bound once, (x := a + b) * x


def _doubled_size(x):
    return abs(x) * 2.0  # a builtin


def _size_of(y):
    return _doubled_size(y - 5.0)


def test_arithmetic_read_twice_is_bound_once_and_builtins_are_inlined():
    from satmotor_ros.model._inline import inline_equations
    squared, sized = inline_equations(_square_of_sum), inline_equations(_size_of)
    assert '_square' not in _loaded_names(squared) and squared(1.5, 2.0) == 12.25
    assert '_doubled_size' not in _loaded_names(sized) and sized(1.0) == 8.0
