# SPDX-License-Identifier: Apache-2.0
"""The inlined compositions compute bitwise what the equation functions compute, calls gone."""

import dis

import numpy as np
import pytest

from satmotor_ros.model import MotorModel
from satmotor_ros.model._inline import inline_equations, inline_on_floats
from satmotor_ros.model.engine import screening
from satmotor_ros.model.families.sliwinski2017 import composition
from satmotor_ros.model.units import LPM, MPA, RPM

KERNELS = {'channel_pressure_drop', 'chamber_pressure_drop', 'clearance_height',
           'flat_clearance_leakage', 'commutation_leakage', 'pressure_speed_loss',
           'inertia_loss', 'absorbency', 'displacement_loss', 'external_leakage'}


def _loaded_names(func):
    """Return the globals and attributes a function's code loads, its nested functions' too."""
    code = getattr(func, '__code__', func)
    names = {i.argval for i in dis.get_instructions(code)
             if i.opname in ('LOAD_GLOBAL', 'LOAD_ATTR', 'LOAD_METHOD', 'LOAD_NAME')}
    for const in code.co_consts:
        if hasattr(const, 'co_code'):
            names |= _loaded_names(const)
    return names


def _same(a, b):
    """Whether two results (a value or a tuple of values) are bitwise equal, NaN as NaN."""
    if isinstance(a, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True) and (
        np.signbit(a) == np.signbit(b)).all()


def _both(builder, *args):
    """Return the compositions of the inlined builder and of the original one."""
    return builder(*args), builder.__wrapped__(*args)


@pytest.mark.parametrize('law', ['eq33', 'eq39'])
def test_inlined_compositions_equal_the_called_equations_bitwise(law):
    model = MotorModel.default('water', law)
    d, law_ = model.derived, model.law
    dp_i = np.array([0.0, 1e-3, 0.5, 3.0, 14.0, 25.0]) * MPA
    speed = np.array([0.0, 1e-3, 5.0, 300.0, 1000.0, 2000.0]) * RPM
    flow = np.array([0.0, 1e-6, 2.0, 10.0, 30.0, 45.0]) * LPM
    for args in [(dp_i, speed, flow), *zip(dp_i.tolist(), speed.tolist(), flow.tolist())]:
        p, n, q = args
        (channel, chamber), (channel0, chamber0) = _both(composition._drops, d)
        assert _same(channel(q), channel0(q))
        assert _same(chamber(p, q), chamber0(p, q))
        leakage, leakage0 = _both(composition._leakage, d)
        assert _same(leakage(p, 1e5), leakage0(p, 1e5))
        breakdown, breakdown0 = _both(composition._breakdown, d, law_)
        assert _same(breakdown(n, p, 1e-6), breakdown0(n, p, 1e-6))
        flow_problem, flow_problem0 = _both(composition._flow_problem, d, law_)
        (lo, upper, res), (lo0, upper0, res0) = flow_problem(n, p, 0.0), flow_problem0(n, p, 0.0)
        assert _same(lo, lo0) and _same(upper(), upper0())
        assert _same(res(q + lo), res0(q + lo0))
        speed_problem, speed_problem0 = _both(composition._speed_problem, d, law_)
        (lo, hi, res), (lo0, hi0, res0) = speed_problem(q, p, 1e-7), speed_problem0(q, p, 1e-7)
        assert _same(lo, lo0) and _same(hi, hi0)
        with np.errstate(divide='ignore', invalid='ignore'):
            assert _same(res(n + 1.0), res0(n + 1.0))


def test_the_point_path_calls_no_equation_function_it_can_inline():
    model = MotorModel.default('water')
    eqs = model._point.eqs
    _, upper, residual = eqs.flow_problem(100.0, 10 * MPA, 0.0)
    for func in (residual, upper, eqs.leakage, eqs.breakdown, eqs.chamber_drop,
                 model.law.at_speed(100.0), model._point._point):
        assert not _loaded_names(func) & KERNELS, func


def _square(x):
    return x * x


def _scaled(x):
    return _SCALE * x


_SCALE = 2.0


def _twice_read():
    return _square(float('3'))  # an argument that is not a plain name: evaluated once


def _rebound():
    _square = abs  # noqa: N806
    return _square(-3.0)


def _inlined():
    x = 3.0
    return _square(x) + _scaled(x)


def test_a_call_is_inlined_only_where_the_same_operations_run():
    assert '_square' in _loaded_names(inline_equations(_twice_read))
    assert inline_equations(_twice_read)() == 9.0
    assert inline_equations(_rebound)() == 3.0
    inlined = inline_equations(_inlined)
    assert not _loaded_names(inlined) & {'_square', '_scaled'} and inlined() == 15.0
    assert inline_equations(len) is len  # no source: unchanged


def _ten_times(x):
    return x * 10.0


def _ten_times_plus_one(x):
    return _ten_times(x) + 1.0


def _shadowed_by_a_parameter(_ten_times):
    return _ten_times_plus_one(-1.0), _ten_times(-1.0)


def _shadowed_by_an_assignment():
    _ten_times = abs  # noqa: N806
    return _ten_times_plus_one(-1.0), _ten_times(-1.0)


def _shadowed_in_a_closure():
    _ten_times = abs  # noqa: N806

    def inner():
        return _ten_times_plus_one(-1.0), _ten_times(-1.0)
    return inner()


def _shadowed_by_a_comprehension():
    return [_ten_times_plus_one(-1.0) for _ten_times in (abs,)]


@pytest.mark.parametrize('builder', [_shadowed_by_an_assignment, _shadowed_in_a_closure,
                                     _shadowed_by_a_comprehension])
def test_a_call_reading_a_global_the_builder_binds_as_a_local_is_not_inlined(builder):
    inlined = inline_equations(builder)
    assert inlined() == builder() and builder()[0] == -9.0
    assert '_ten_times_plus_one' in _loaded_names(inlined)


def test_a_call_reading_a_global_the_builder_has_as_a_parameter_is_not_inlined():
    inlined = inline_equations(_shadowed_by_a_parameter)
    assert inlined(abs) == _shadowed_by_a_parameter(abs) == (-9.0, 1.0)
    assert '_ten_times_plus_one' in _loaded_names(inlined)


def _first_doubled(x, y):
    return x * 2.0


def _fails():
    raise ZeroDivisionError('evaluated')


def _unused_call_argument():
    return _first_doubled(3.0, _fails())


def _unused_plain_arguments(y):
    return _first_doubled(3.0, y) + _first_doubled(3.0, 1.0)


def test_an_argument_the_callee_never_reads_is_still_evaluated():
    inlined = inline_equations(_unused_call_argument)
    with pytest.raises(ZeroDivisionError, match='evaluated'):
        inlined()
    assert '_first_doubled' in _loaded_names(inlined)
    plain = inline_equations(_unused_plain_arguments)  # nothing to evaluate: inlined
    assert '_first_doubled' not in _loaded_names(plain) and plain(_fails) == 12.0


def _twice(a, b):
    once = a + 1.0
    return once * b + once


def _nested(v, w):
    return _twice(v, _twice(w, 1.0))


def test_nested_calls_of_a_folded_body_each_keep_their_own_local():
    inlined = inline_equations(_nested)
    assert '_twice' not in _loaded_names(inlined)
    assert inlined(1.0, 2.0) == _nested(1.0, 2.0) == 14.0


@pytest.mark.parametrize('law', ['eq33', 'eq39'])
def test_inlined_law_methods_equal_their_originals_bitwise(law):
    model = MotorModel.default('water', law)
    law_ = model.law
    kind = type(law_)
    dp_i = np.array([0.0, 1e-3, 0.5, 1.0, 3.0, 14.0, 25.0]) * MPA
    speed = np.array([0.0, 1e-3, 5.0, 40.0, 300.0, 1000.0, 2000.0]) * RPM
    for p, n in [(dp_i, speed), *zip(dp_i.tolist(), speed.tolist())]:
        with np.errstate(divide='ignore', invalid='ignore'):
            for name in ('loss', 'floor'):
                method = getattr(kind, name)
                if hasattr(method, '__wrapped__'):
                    args = {'loss': (n, p), 'floor': (p,)}[name]
                    assert _same(method(law_, *args), method.__wrapped__(law_, *args)), name
            (floor, terms), (floor0, terms0) = (kind.at_pressure(law_, p),
                                                kind.at_pressure.__wrapped__(law_, p))
            assert _same(floor, floor0) and _same(terms(n + 1.0), terms0(n + 1.0))
            terms, terms0 = kind.at_speed(law_, n), kind.at_speed.__wrapped__(law_, n)
            assert _same(terms(p), terms0(p))
    assert law != 'eq39' or all(hasattr(getattr(kind, m), '__wrapped__')
                                for m in ('loss', 'floor'))


def _rules_on_floats(speed: float, dp_i: float) -> tuple[int, int, int, int]:
    """Apply the status rules the single-point path inlines (a module-level function)."""
    return (screening.outside_range(speed, dp_i, 2.0, 3.0, -1.0, 0.5, False),
            screening.channel_limited(dp_i), screening.input_flags(dp_i, 2.5),
            screening.below_floor(speed, dp_i))


@pytest.mark.parametrize('speed', [-1.0, 0.0, 0.5, 1.0, 3.0, 4.0, np.inf, np.nan])
@pytest.mark.parametrize('dp_i', [-2.0, -1.0, 0.0, 1.0, 2.0, 2.6, -np.inf, np.nan])
def test_rules_inlined_on_floats_give_the_flags_of_the_rules_and_their_array_form(speed, dp_i):
    inlined = inline_on_floats(_rules_on_floats)
    got = inlined(speed, dp_i)
    assert got == _rules_on_floats(speed, dp_i)
    on_arrays = _rules_on_floats(np.array([speed]), np.array([dp_i]))
    assert got == tuple(int(np.asarray(f).reshape(-1)[0]) for f in on_arrays)
    code = inlined.__code__
    assert not {'outside_range', 'channel_limited', 'input_flags'} & set(code.co_names)
    ors = [i for i in dis.get_instructions(code) if i.opname == 'BINARY_OP' and i.argrepr == '|']
    assert len(ors) == 1, 'the four tests of outside_range are joined by or (its flag by |)'
