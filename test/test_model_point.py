# SPDX-License-Identifier: Apache-2.0
"""The single-point path equals the array maps and the equation functions, field by field."""

import math

import numpy as np
import pytest

from satmotor_ros.model import (COMPONENTS, InvalidInputError, ModelError, MotorModel, Point,
                                PointStatus)
from satmotor_ros.model.families.sliwinski2017 import losses as eq, speed as sp
from satmotor_ros.model.units import LPM, MPA, RPM

MODELS = {(liquid, law): MotorModel.default(liquid, law)
          for liquid in ('oil', 'water') for law in ('eq33', 'eq39')}
FIELDS = ('flow', 'speed', 'dp', 'dp_i', *COMPONENTS)
RTOL = 1e-12

# dense grids over and beyond the domain: 0, tiny, the validated range, past the limit
FLOWS = np.concatenate([[0.0, 1e-4, 0.01, 0.05], np.linspace(0.1, 60.0, 37)]) * LPM
SPEEDS = np.concatenate([[0.0, 1e-3, 0.05, 1.0], np.linspace(5.0, 100.0, 8),
                         np.linspace(150.0, 2000.0, 25)]) * RPM
DROPS = np.concatenate([[0.0, 1e-3, 0.01, 0.03, 0.05], np.linspace(0.1, 3.0, 8),
                        np.linspace(4.0, 55.0, 18)]) * MPA


def _as_arrays(points):
    return {name: np.array([getattr(p, name) for p in points]) for name in Point._fields}


def _assert_equal_to_array_path(points, ops):
    got = _as_arrays(points)
    expected = {'flow': ops.flow, 'speed': ops.speed, 'dp': ops.dp, 'dp_i': ops.dp_i,
                **ops.losses.as_dict()}
    np.testing.assert_array_equal(got['status'], ops.status.ravel())
    for name in FIELDS:
        np.testing.assert_allclose(got[name], np.ravel(expected[name]), rtol=RTOL, atol=0.0,
                                   err_msg=name)


@pytest.mark.parametrize('key', MODELS)
@pytest.mark.parametrize('port', [True, False])
def test_speed_point_equals_the_array_map_on_a_dense_grid(key, port):
    model = MODELS[key]
    q, dp = (a.ravel() for a in np.meshgrid(FLOWS, DROPS))
    kwargs = {'dp': dp} if port else {'dp_i': dp}
    ops = model.speed(q, **kwargs, errors='mask')
    points = [model.speed_point(qq, **{k: float(v[i]) for k, v in kwargs.items()})
              for i, qq in enumerate(q.tolist())]
    _assert_equal_to_array_path(points, ops)
    assert not ops.invalid.all() and ops.invalid.any()  # the grid reaches both sides


@pytest.mark.parametrize('key', MODELS)
@pytest.mark.parametrize('port', [True, False])
def test_absorbency_point_equals_the_array_map_on_a_dense_grid(key, port):
    model = MODELS[key]
    n, dp = (a.ravel() for a in np.meshgrid(SPEEDS, DROPS))
    kwargs = {'dp': dp} if port else {'dp_i': dp}
    ops = model.absorbency(n, **kwargs, errors='mask')
    points = [model.absorbency_point(nn, **{k: float(v[i]) for k, v in kwargs.items()})
              for i, nn in enumerate(n.tolist())]
    _assert_equal_to_array_path(points, ops)


@pytest.mark.parametrize('key', MODELS)
def test_absorbency_point_warm_start_reaches_the_same_root(key):
    model = MODELS[key]
    n, dp = (a.ravel() for a in np.meshgrid(SPEEDS, DROPS))
    cold = [model.absorbency_point(nn, float(dd)) for nn, dd in zip(n.tolist(), dp)]
    for factor in (1.0, 1.0001, 0.999, 1.01, 0.9, 0.5, 1.5, 3.0):
        warm = [model.absorbency_point(nn, float(dd), flow_guess=c.flow * factor)
                for nn, dd, c in zip(n.tolist(), dp, cold)]
        for name in FIELDS:
            np.testing.assert_allclose([getattr(w, name) for w in warm],
                                       [getattr(c, name) for c in cold], rtol=RTOL, atol=0.0,
                                       err_msg=f'{name} from {factor} x the root')
    for guess in (0.0, -1.0, math.nan, math.inf, 1e-30):  # useless guesses are ignored
        point = model.absorbency_point(300 * RPM, 10 * MPA, flow_guess=guess)
        assert point == model.absorbency_point(300 * RPM, 10 * MPA)


@pytest.mark.parametrize('key', MODELS)
def test_breakdown_point_equals_the_array_breakdown(key):
    model = MODELS[key]
    n, dp_i = (a.ravel() for a in np.meshgrid(SPEEDS, DROPS))
    losses = model.breakdown(n, dp_i, errors='mask')
    points = [model.breakdown_point(nn, dd) for nn, dd in zip(n.tolist(), dp_i.tolist())]
    for name in COMPONENTS:
        np.testing.assert_allclose([getattr(p, name) for p in points], getattr(losses, name),
                                   rtol=RTOL, atol=0.0, err_msg=name)


D = MODELS['water', 'eq39'].derived
KERNELS = {  # every equation function with the model's constants, by its variables
    'clearance_height': (lambda p, n: eq.clearance_height(p, D.h0, D.compliance)),
    'flat_clearance_leakage': (lambda p, n: eq.flat_clearance_leakage(
        p, eq.clearance_height(p, D.h0, D.compliance), D.lfg_k, D.lfg_e)),
    'commutation_leakage': (lambda p, n: eq.commutation_leakage(p, D.com_k, D.com_e)),
    'pressure_speed_loss': (lambda p, n: eq.pressure_speed_loss(p, n, D.k_dch)),
    'inertia_loss': (lambda p, n: eq.inertia_loss(n, D.k_i)),
    'displacement_change': (lambda p, n: eq.displacement_change(p, n, D.k_p, D.k_i)),
    'displacement_loss': (lambda p, n: eq.displacement_loss(p, n, D.k_p, D.k_i)),
    'displacement_change_empirical': (lambda p, n: eq.displacement_change_empirical(
        p + eq.EMPIRICAL_DP_FLOOR, n, D.c1_39, D.c2_39)),
    'empirical_speed_floor': (lambda p, n: eq.empirical_speed_floor(p, D.c2_39)),
    'external_leakage': (lambda p, n: eq.external_leakage(p, 1e-12)),
    'channel_pressure_drop': (lambda p, n: eq.channel_pressure_drop(n * 1e-6, D.ch_a, D.ch_b)),
    'chamber_pressure_drop': (lambda p, n: eq.chamber_pressure_drop(p, n * 1e3)),
    'absorbency': (lambda p, n: sp.absorbency(n, p * 1e-12, D.qt)),
    'effective_speed': (lambda p, n: sp.effective_speed(n * 1e-6, p, 1e-6, D.es_a0, D.es_a1,
                                                        D.es_scale, D.es_b)),
    'speed_loss': (lambda p, n: sp.speed_loss(n * 1e-6, n, D.qt)),
}
KERNEL_DROPS = [0.0, 0.3 * MPA, 2 * MPA, 25 * MPA]
KERNEL_SPEEDS = [1e-3, 40 * RPM, 150 * RPM, 1000 * RPM]


@pytest.mark.parametrize('name', KERNELS)
def test_each_equation_is_one_function_for_floats_and_arrays(name):
    kernel = KERNELS[name]
    p, n = (a.ravel() for a in np.meshgrid(KERNEL_DROPS, KERNEL_SPEEDS))
    on_arrays = kernel(p, n)
    assert isinstance(on_arrays, np.ndarray) and on_arrays.shape == p.shape
    for i, (pp, nn) in enumerate(zip(p.tolist(), n.tolist())):
        on_floats = kernel(pp, nn)
        assert type(on_floats) is float, f'{name} returned {type(on_floats).__name__}'
        assert on_floats == pytest.approx(float(on_arrays[i]), rel=1e-15, abs=0.0), name


@pytest.mark.parametrize('key', MODELS)
def test_point_components_are_the_equation_functions(key):
    model = MODELS[key]
    d = model.derived
    for n, dp_i in [(150 * RPM, 2 * MPA), (1000 * RPM, 25 * MPA), (40 * RPM, 0.3 * MPA)]:
        p = model.breakdown_point(n, dp_i)
        assert p.flat_clearance == eq.flat_clearance_leakage(
            dp_i, eq.clearance_height(dp_i, d.h0, d.compliance), d.lfg_k, d.lfg_e)
        assert p.commutation == eq.commutation_leakage(dp_i, d.com_k, d.com_e)
        parts = p.compressibility + p.deformation + p.backlash + p.inertia
        assert parts == pytest.approx(model.law.loss(n, dp_i), rel=RTOL)
        if key[1] == 'eq33':
            assert p.compressibility == eq.pressure_speed_loss(dp_i, n, d.k_fc)
            assert p.inertia == eq.inertia_loss(n, d.k_i)
        assert p.flow == sp.absorbency(n, p.total, d.qt)
        assert p.dp == p.dp_i + eq.channel_pressure_drop(p.flow, d.ch_a, d.ch_b)


def test_point_is_python_floats_and_an_int_status():
    point = MODELS['oil', 'eq33'].speed_point(np.float64(5 * LPM), dp=np.array(10 * MPA))
    assert isinstance(point, Point)
    assert all(type(v) is float for v in point[:-1])
    assert type(point.status) is int and point.status == PointStatus.OK


@pytest.mark.parametrize(('call', 'flag'), [
    (lambda m: m.speed_point(math.nan, 1e6), PointStatus.NOT_FINITE),
    (lambda m: m.speed_point(1e-4, dp_i=-1.0, p_ex=-1.0), PointStatus.NEGATIVE),
    (lambda m: m.speed_point(1e-4, 1e6, p_ex=math.inf), PointStatus.NOT_FINITE),
    (lambda m: m.speed_point(1e-4, 80 * MPA), PointStatus.BEYOND_LIMIT),
    (lambda m: m.absorbency_point(-1.0, 1e6, p_ex=-5.0), PointStatus.NEGATIVE),
    (lambda m: m.absorbency_point(10.0, dp_i=math.inf), PointStatus.NOT_FINITE),
    (lambda m: m.breakdown_point(10.0, 60 * MPA), PointStatus.BEYOND_LIMIT),
])
def test_bad_values_never_raise_and_come_back_nan_and_flagged(call, flag):
    point = call(MODELS['oil', 'eq33'])
    assert point.status == flag
    assert all(math.isnan(v) for v in point[:-1])


def test_misuse_raises_model_errors():
    model = MODELS['oil', 'eq33']
    with pytest.raises(ModelError, match='exactly one of dp'):
        model.speed_point(1e-4)
    with pytest.raises(ModelError, match='exactly one of dp'):
        model.absorbency_point(10.0, 1e6, dp_i=1e6)
    with pytest.raises(InvalidInputError, match=r"^flow = '5': expected a number, got str$"):
        model.speed_point('5', 1e6)
    with pytest.raises(InvalidInputError, match=r'^dp_i = \[1.0, 2.0\]: expected one number'):
        model.breakdown_point(10.0, [1.0, 2.0])
    for bad in (np.array('5'), np.bool_(True), True, None, 1j):
        with pytest.raises(InvalidInputError, match=r'^speed = .*: expected (a|one) number'):
            model.absorbency_point(bad, 1e6)
