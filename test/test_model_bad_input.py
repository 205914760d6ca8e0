# SPDX-License-Identifier: Apache-2.0
"""Bad operating points get a defined answer: a named error or a flagged physical result."""

import numpy as np
import pytest

from satmotor_ros.model import (describe_status, InvalidInputError, ModelError, MotorModel,
                                PointStatus)
from satmotor_ros.model.units import LPM, MPA, RPM


@pytest.fixture(scope='module')
def oil():
    return MotorModel.default('oil')


@pytest.mark.parametrize(('kwargs', 'match'), [
    ({'flow': np.nan, 'dp': 10 * MPA}, r'^flow = nan m\^3/s: not finite$'),
    ({'flow': np.inf, 'dp': 10 * MPA}, r'^flow = inf m\^3/s: not finite$'),
    ({'flow': -np.inf, 'dp': 10 * MPA}, r'^flow = -inf m\^3/s: not finite$'),
    ({'flow': 1e-4, 'dp': -np.inf}, r'^dp = -inf Pa: not finite$'),
    ({'flow': 1e-4, 'dp_i': np.nan}, r'^dp_i = nan Pa: not finite$'),
    ({'flow': 1e-4, 'dp': 1e6, 'p_ex': -5.0}, r'^p_ex = -5.0 Pa: negative$'),
    ({'flow': 1e-4, 'dp': 80 * MPA}, r'^dp = 80000000.0 Pa: chamber pressure drop beyond'),
])
def test_speed_raises_naming_argument_and_value(oil, kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        oil.speed(**kwargs)


def test_batch_error_names_the_first_bad_index_and_the_count(oil):
    flow = np.full(100, 5 * LPM)
    flow[[17, 40, 41]] = np.nan
    with pytest.raises(InvalidInputError,
                       match=r'^flow\[17\] = nan .*\(3 elements of this kind\)'):
        oil.speed(flow, 10 * MPA)


def test_batch_error_index_is_global_across_chunks(oil):
    flow = np.full(100_000, 5 * LPM)
    dp = np.full(100_000, 10 * MPA)
    dp[70_001] = 90 * MPA
    with pytest.raises(InvalidInputError, match=r'^dp\[70001\] = 90000000.0 Pa'):
        oil.speed(flow, dp)


def test_mask_mode_keeps_the_batch_and_reports_which_elements_are_invalid(oil):
    flow = np.array([5, np.nan, -1, 5, 5, 0.0]) * LPM
    dp = np.array([10, 10, 10, np.inf, 80, 10]) * MPA
    p_ex = np.array([0, 0, -1, 0, 0, 0]) * MPA
    op = oil.speed(flow, dp, p_ex=p_ex, errors='mask')
    assert op.invalid.tolist() == [False, True, True, True, True, False]
    assert np.isnan(op.speed[op.invalid]).all()
    assert np.isnan(op.losses.total[op.invalid]).all()
    assert op.speed[0] == pytest.approx(oil.speed(5 * LPM, 10 * MPA).speed)
    assert describe_status(op.status[1]) == 'NOT_FINITE'
    assert describe_status(op.status[2]) == 'NEGATIVE'  # p_ex; a negative flow is pump mode
    assert describe_status(op.status[3]) == 'NOT_FINITE'
    assert describe_status(op.status[4]) == 'BEYOND_LIMIT'
    assert op.status[5] & PointStatus.STALLED


def test_zero_flow_and_flow_swallowed_by_leakage_give_zero_speed(oil):
    op = oil.speed(np.array([0.0, 0.05, 0.2]) * LPM, 25 * MPA)
    assert op.speed[:2].tolist() == [0.0, 0.0]
    assert op.speed[2] > 0.0
    assert (op.status[:2] & PointStatus.STALLED).all()
    assert not op.status[2] & PointStatus.STALLED
    for law in ('eq33', 'eq39'):
        assert float(MotorModel.default('water', law).speed(0.1 * LPM, dp=25 * MPA).speed) == 0.0


def test_zero_pressure_drop_is_a_valid_unloaded_point(oil):
    op = oil.speed(5 * LPM, 0.0)
    assert 0.0 < float(op.speed) < 5 * LPM / oil.geometry.displacement
    # 5 l/min need some channel drop; 0 MPa is below the 2 MPa measured
    assert op.status == PointStatus.CHANNEL_LIMITED | PointStatus.EXTRAPOLATED
    assert float(op.dp_i) == 0.0


def test_beyond_validated_range_is_computed_and_flagged_extrapolated(oil):
    op = oil.speed(np.array([20, 20]) * LPM, np.array([20, 30]) * MPA)
    assert op.status.tolist() == [0, PointStatus.EXTRAPOLATED]
    assert np.isfinite(op.speed).all()
    fast = oil.absorbency(2000 * RPM, dp_i=10 * MPA)
    assert fast.status & PointStatus.EXTRAPOLATED


def test_forward_map_takes_negative_speed_and_rejects_eq39_below_its_floor():
    # a negative speed was refused until the model went four-quadrant (issue 13)
    oil = MotorModel.default('oil')
    backwards = oil.absorbency(-1.0, dp_i=-1e6).flow
    assert backwards.shape == () and float(backwards) == -float(oil.absorbency(1.0, dp_i=1e6).flow)
    with pytest.raises(InvalidInputError, match='below the floor of eq. \\(39\\)'):
        MotorModel.default('oil', 'eq39').absorbency(1e-4, dp_i=25 * MPA)
    assert float(MotorModel.default('oil', 'eq39').absorbency(0.0, dp_i=25 * MPA).flow) > 0.0


def test_bad_call_arguments_are_model_errors(oil):
    with pytest.raises(ModelError, match='exactly one of dp'):
        oil.speed(1e-4)
    with pytest.raises(ModelError, match='exactly one of dp'):
        oil.speed(1e-4, 1e6, dp_i=1e6)
    with pytest.raises(ModelError, match="errors = 'ignore'"):
        oil.speed(1e-4, 1e6, errors='ignore')
    with pytest.raises(ModelError, match="displacement_law = 'eq7'"):
        MotorModel.default('oil', 'eq7')


@pytest.mark.parametrize('shape', [(), (1,), (7,), (3, 4)])
def test_scalar_and_array_inputs_keep_their_shape(oil, shape):
    op = oil.speed(np.full(shape, 10 * LPM), 10 * MPA)
    assert op.speed.shape == shape
    assert op.losses.total.shape == shape
    assert op.status.shape == shape
    np.testing.assert_allclose(op.speed, float(oil.speed(10 * LPM, 10 * MPA).speed))


def test_mask_mode_over_many_chunks_keeps_every_field_aligned(oil):
    flow = np.full(50_000, 10 * LPM)
    dp = np.full(50_000, 10 * MPA)
    flow[[3, 30_000]] = np.nan
    op = oil.speed(flow, dp, errors='mask')
    assert np.flatnonzero(op.invalid).tolist() == [3, 30_000]
    for value in (op.speed, op.dp_i, op.speed_loss, *op.losses.as_dict().values()):
        assert value.shape == (50_000,)
        assert np.isnan(value[[3, 30_000]]).all()
        assert np.isfinite(np.delete(value, [3, 30_000])).all()
    assert (op.losses.external[op.losses.external == op.losses.external] == 0.0).all()


def test_results_own_their_data_and_are_read_only(oil):
    flow = np.full(5, 10 * LPM)
    dp_i = np.full(5, 10 * MPA)
    speed = np.full(5, 300 * RPM)
    for op in (oil.speed(flow, dp_i=dp_i), oil.absorbency(speed, dp_i=dp_i),
               oil.speed(flow, dp_i=dp_i, errors='mask'), oil.absorbency(speed, dp=dp_i)):
        arrays = [op.flow, op.speed, op.dp, op.dp_i, op.status, *op.losses.as_dict().values()]
        for value in arrays:
            assert not any(np.may_share_memory(value, a) for a in (flow, dp_i, speed))
            assert not value.flags.writeable
            with pytest.raises(ValueError, match='read-only'):
                value[...] = 0.0
    before = oil.speed(flow, dp_i=dp_i).speed.copy()
    flow[:] = 20 * LPM  # the caller reuses its buffer: earlier results do not change
    dp_i[:] = 0.0
    op = oil.speed(10 * LPM, dp_i=10 * MPA)
    assert float(op.speed) == pytest.approx(before[0])


def test_mismatched_shapes_raise_the_librarys_own_error(oil):
    with pytest.raises(InvalidInputError,
                       match=r'^the shapes of the arguments do not broadcast together: '
                             r'flow \(3,\), dp \(4,\), p_ex \(\)$'):
        oil.speed(np.ones(3) * LPM, np.ones(4) * MPA)
    with pytest.raises(ModelError, match='do not broadcast'):
        oil.absorbency(np.ones((2, 3)), dp_i=np.ones(2))


@pytest.mark.parametrize(('kwargs', 'match'), [
    ({'flow': '5', 'dp': 1e6}, r"^flow = '5': expected numbers, got str$"),
    ({'flow': 1e-4, 'dp': ['1', '2']}, r"^dp = \['1', '2'\]: expected numbers, got an array of"),
    ({'flow': True, 'dp': 1e6}, r'^flow = True: expected numbers, got bool$'),
    ({'flow': None, 'dp': 1e6}, r'^flow = None: expected numbers, got NoneType$'),
    ({'flow': 1e-4, 'dp': 1e6, 'p_ex': 1j}, r'^p_ex = 1j: expected numbers, got complex$'),
])
def test_strings_and_other_non_numbers_are_refused(oil, kwargs, match):
    with pytest.raises(InvalidInputError, match=match):
        oil.speed(**kwargs)


def test_extrapolated_below_the_measured_range_as_well_as_above(oil):
    dp_i = np.array([1.0, 2.0, 10.0, 25.0, 26.0]) * MPA
    op = oil.absorbency(500 * RPM, dp_i=dp_i)
    extrapolated = (op.status & PointStatus.EXTRAPOLATED) != 0
    assert extrapolated.tolist() == [True, False, False, False, True]
    slow = oil.absorbency(np.array([0.0, 99.0, 100.0, 1500.0, 1501.0]) * RPM, dp_i=10 * MPA)
    slow_flags = ((slow.status & PointStatus.EXTRAPOLATED) != 0).tolist()
    assert slow_flags == [True, True, False, False, True]
    assert oil.speed_point(5 * LPM, dp_i=25 * MPA).status == PointStatus.OK
    assert oil.speed_point(2 * LPM, dp_i=25 * MPA).status == PointStatus.EXTRAPOLATED


def test_a_user_liquid_outside_the_fitted_viscosity_is_extrapolated():
    from dataclasses import replace

    from satmotor_ros.model import Liquid, load_motor
    spec = load_motor()
    oil_set = spec.sets['oil']
    same = Liquid('same', 40e-6, 880.0, 1.5e9)  # another density, the fitted viscosity
    thin = Liquid('hot oil', 20e-6, 873.0, 1.6e9)
    assert MotorModel.from_spec(spec, 'oil', same).speed_point(20 * LPM, 10 * MPA).status == 0
    hot = MotorModel.from_spec(spec, 'oil', thin)
    assert hot.speed(20 * LPM, 10 * MPA).status == PointStatus.EXTRAPOLATED
    assert hot.speed_point(20 * LPM, 10 * MPA).status == PointStatus.EXTRAPOLATED
    widened = replace(oil_set, viscosity_range=(15e-6, 60e-6))
    model = MotorModel(spec.geometry, widened, spec.valid_range, thin)
    assert model.speed(20 * LPM, 10 * MPA).status == PointStatus.OK


def test_a_nan_speed_in_the_batch_hides_no_other_elements_stall(oil):
    flow, dp = np.array([1e-6, 1e308]), np.array([20099700.0, 19.9e6])  # stalled; speed NaN
    with np.errstate(over='ignore', invalid='ignore'):  # 1e308 overflows on the way to NaN
        op = oil.speed(flow, dp, errors='mask')
    assert np.isnan(op.speed[1])
    assert op.status.tolist() == [int(oil.speed_point(q, p).status) for q, p in zip(flow, dp)]
    assert op.status[0] & PointStatus.STALLED


def test_a_nan_element_hides_no_other_elements_extrapolation(oil):
    from satmotor_ros.model.engine.screening import flag_extrapolated
    d = oil.derived
    status = np.zeros(3, np.uint8)
    speed = np.array([2.0 * d.speed_max, np.nan, d.speed_max])
    flag_extrapolated(d, speed, np.full(3, d.dp_max), status)
    assert status.tolist() == [PointStatus.EXTRAPOLATED, 0, 0]
