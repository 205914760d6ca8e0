# SPDX-License-Identifier: Apache-2.0
"""No silent wrong value: eq. (36) holds and the maps round-trip at every valid point."""

import csv
from pathlib import Path

import numpy as np
import pytest

from satmotor_ros.model import INVALID, InvalidInputError, MotorModel, PointStatus
from satmotor_ros.model.families.sliwinski2017.losses import channel_pressure_drop
from satmotor_ros.model.units import LPM, MPA, RPM

DATA = Path(__file__).resolve().parent / 'data'  # reference grids (test/data/README.md)
MODELS = {(liquid, law): MotorModel.default(liquid, law)
          for liquid in ('oil', 'water') for law in ('eq33', 'eq39')}
RTOL = 1e-9
FLOW_ATOL = 1e-20  # [m^3/s], the solves' absolute resolution
# dense near zero load and zero speed, where eq. (39) and the channel drop misbehaved
FLOWS = np.concatenate([np.linspace(0.0, 1.0, 60), np.linspace(1.0, 60.0, 90)]) * LPM
DROPS = np.concatenate([np.linspace(0.0, 3.0, 80), np.linspace(3.0, 30.0, 40)]) * MPA
SPEEDS = np.concatenate([np.linspace(0.0, 100.0, 80), np.linspace(100.0, 2000.0, 60)]) * RPM
STALLED = int(PointStatus.STALLED)


def _grid(a, b):
    return (x.ravel() for x in np.meshgrid(a, b))


def _kwargs(port, dp):
    return {'dp': dp} if port else {'dp_i': dp}


def _channel(model, flow):
    return channel_pressure_drop(flow, model.derived.ch_a, model.derived.ch_b)


def _assert_eq36(model, ops, valid):
    """Q = q_t n + Q_vl, eq. (36), wherever the shaft turns."""
    flow = model.geometry.displacement * ops.speed + ops.losses.total
    np.testing.assert_allclose(flow[valid], ops.flow[valid], rtol=RTOL, atol=FLOW_ATOL)


@pytest.mark.parametrize('key', MODELS)
@pytest.mark.parametrize('port', [True, False])
def test_inverse_map_satisfies_eq36_and_round_trips_on_a_dense_grid(key, port):
    model = MODELS[key]
    q, dp = _grid(FLOWS, DROPS)
    ops = model.speed(q, **_kwargs(port, dp), errors='mask')
    valid = ~ops.invalid
    turning = valid & ((ops.status & STALLED) == 0)
    assert turning.sum() > 0.7 * q.size
    _assert_eq36(model, ops, turning)
    # STALLED means what it says: the leakage alone takes at least the flow
    stalled = valid & ~turning
    np.testing.assert_array_equal(ops.speed[stalled], 0.0)
    assert (ops.losses.total[stalled] >= ops.flow[stalled] * (1 - RTOL)).all()
    # forward at the speed found gives the flow back, at the same chamber drop
    back = model.absorbency(ops.speed[turning], **_kwargs(port, dp[turning]), errors='mask')
    assert not back.invalid.any()
    np.testing.assert_allclose(back.flow, q[turning], rtol=RTOL, atol=FLOW_ATOL)
    np.testing.assert_allclose(back.dp_i, ops.dp_i[turning], rtol=RTOL, atol=RTOL * MPA)
    if port:  # eq. (34) with eq. (35) at the flow found
        dp_i = np.maximum(dp - _channel(model, q), 0.0)
        np.testing.assert_allclose(ops.dp_i[valid], dp_i[valid], rtol=0, atol=RTOL * MPA)


@pytest.mark.parametrize('key', MODELS)
@pytest.mark.parametrize('port', [True, False])
def test_forward_map_satisfies_eq36_and_round_trips_on_a_dense_grid(key, port):
    model = MODELS[key]
    n, dp = _grid(SPEEDS, DROPS)
    ops = model.absorbency(n, **_kwargs(port, dp), errors='mask')
    valid = ~ops.invalid
    flags = ops.status[~valid] & int(INVALID)
    if key[1] == 'eq33':
        assert (flags == PointStatus.BEYOND_LIMIT).all()  # only past the 50.6 MPa limit
    _assert_eq36(model, ops, valid)
    if port:  # the coupled solve: dp_i = dp - dp_ich(Q) at the flow returned
        dp_i = np.maximum(dp - _channel(model, ops.flow), 0.0)
        np.testing.assert_allclose(ops.dp_i[valid], dp_i[valid], rtol=0, atol=RTOL * MPA)
    moving = valid & (n > 0)
    back = model.speed(ops.flow[moving], **_kwargs(port, dp[moving]), errors='mask')
    assert not back.invalid.any()
    np.testing.assert_allclose(back.speed, n[moving], rtol=RTOL, atol=1e-9 * RPM)


def test_eq39_with_a_port_drop_near_zero_chamber_drop_round_trips():
    # issue 5: said OK yet back-solved to 205 rpm (eq. 39 jumped at dp_i = 0)
    model = MODELS['oil', 'eq39']
    forward = model.absorbency(201 * RPM, 0.05 * MPA)
    assert not forward.status & INVALID
    back = model.speed(forward.flow, 0.05 * MPA)
    assert float(back.speed) == pytest.approx(201 * RPM, rel=RTOL)


def test_eq39_near_stall_is_no_root_not_a_silent_zero_speed():
    # issue 5: 0.005 l/min above the leakage came back n = 0 STALLED, the flow unaccounted
    model = MODELS['water', 'eq39']
    leak = float(model.breakdown(0.0, 10 * MPA).total)
    flow = leak + np.array([0.0, 0.005, 0.02]) * LPM
    ops = model.speed(flow, dp_i=10 * MPA, errors='mask')
    assert ops.status.tolist() == [PointStatus.STALLED | PointStatus.EXTRAPOLATED,
                                   PointStatus.NO_ROOT, 0 | PointStatus.EXTRAPOLATED]
    assert np.isnan(ops.speed[1]) and ops.speed[2] > 0.0
    assert model.speed_point(float(flow[1]), dp_i=10 * MPA).status == PointStatus.NO_ROOT
    with pytest.raises(InvalidInputError, match=r'^flow\[1\] = .* m\^3/s: eq. \(36\) .*no root'):
        model.speed(flow, dp_i=10 * MPA)


def test_a_solve_that_runs_out_of_iterations_is_flagged_not_converged(monkeypatch):
    from satmotor_ros.model.engine import forward, inverse, solve
    real = solve.solve_increasing
    for module in (forward, inverse):
        monkeypatch.setattr(module, 'solve_increasing',
                            lambda f, lo, hi, x0, tol, *a, **k: real(f, lo, hi, x0,
                                                                     tol._replace(maxiter=1),
                                                                     *a, **k))
    model = MODELS['water', 'eq39']
    ops = model.speed(np.array([5.0, 20.0]) * LPM, 10 * MPA, errors='mask')
    assert (ops.status == PointStatus.NOT_CONVERGED).all()
    assert np.isnan(ops.speed).all()
    with pytest.raises(InvalidInputError, match=r'^flow\[0\] = .*did not converge'):
        model.speed(np.array([5.0, 20.0]) * LPM, 10 * MPA)
    forward = MODELS['oil', 'eq33'].absorbency(300 * RPM, 10 * MPA, errors='mask')
    assert forward.status == PointStatus.NOT_CONVERGED


def _port_rows(liquid, case):
    with (DATA / f'reference_grid_port_{liquid}.csv').open(encoding='utf-8') as stream:
        rows = [r for r in csv.DictReader(stream) if r['case'] == case]
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0] if k != 'case'}


@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_inverse_map_with_port_drop_matches_the_port_reference_grid(liquid):
    ref = _port_rows(liquid, 'inverse')
    ops = MODELS[liquid, 'eq33'].speed(ref['Q_lpm'] * LPM, ref['dp_MPa'] * MPA)
    np.testing.assert_allclose(ops.speed / RPM, ref['n_rpm'], rtol=1e-6)
    np.testing.assert_allclose(ops.dp_i / MPA, ref['dp_i_MPa'], rtol=1e-6)
    np.testing.assert_allclose((ops.dp - ops.dp_i) / MPA, ref['dp_ich_MPa'], rtol=1e-6)


@pytest.mark.parametrize('liquid', ['oil', 'water'])
def test_forward_map_with_port_drop_matches_the_port_reference_grid(liquid):
    ref = _port_rows(liquid, 'forward')
    model = MODELS[liquid, 'eq33']
    ops = model.absorbency(ref['n_rpm'] * RPM, ref['dp_MPa'] * MPA)
    np.testing.assert_allclose(ops.flow / LPM, ref['Q_lpm'], rtol=1e-6)
    np.testing.assert_allclose(ops.dp_i / MPA, ref['dp_i_MPa'], rtol=1e-6)
    np.testing.assert_allclose((ops.dp - ops.dp_i) / MPA, ref['dp_ich_MPa'], rtol=1e-6)
    speeds, drops = ref['n_rpm'] * RPM, ref['dp_MPa'] * MPA
    points = [model.absorbency_point(n, dp) for n, dp in zip(speeds, drops)]
    np.testing.assert_allclose([p.flow / LPM for p in points], ref['Q_lpm'], rtol=1e-6)


def test_the_maps_give_the_same_fields_in_chunks_as_in_one_chunk(monkeypatch):
    """Chunk boundaries, masked elements and a component 0 throughout (Q_ex) change nothing."""
    from satmotor_ros.model.engine import batch
    model, p_ex = MODELS['water', 'eq39'], 0.5 * MPA
    assert model.derived.k_ex == 0.0  # the external leakage stays 0 in every chunk
    rng = np.random.default_rng(3)
    flow, dp = rng.uniform(-5.0, 60.0, 40) * LPM, rng.uniform(-1.0, 30.0, 40) * MPA
    speed = rng.uniform(-50.0, 2000.0, 40) * RPM
    flow[::9] = np.nan
    speed[::7] = np.nan  # negative speeds and drops are valid (four quadrants): mask others
    calls = [lambda: model.speed(flow, dp, p_ex=p_ex, method='iterative', errors='mask'),
             lambda: model.absorbency(speed.reshape(8, 5), dp.reshape(8, 5), p_ex=p_ex,
                                      errors='mask')]
    whole = [call() for call in calls]
    monkeypatch.setattr(batch, 'CHUNK', 7)  # 6 chunks, the last one short
    for one, chunked in zip(whole, (call() for call in calls)):
        assert (chunked.status & int(INVALID)).any() and (chunked.status == 0).any()
        for name in ('flow', 'speed', 'dp', 'dp_i', 'status'):
            np.testing.assert_array_equal(getattr(chunked, name), getattr(one, name))
        for name, value in chunked.losses.as_dict().items():
            np.testing.assert_array_equal(value, getattr(one.losses, name))
