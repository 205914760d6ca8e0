# SPDX-License-Identifier: Apache-2.0
"""The model reproduces the paper's published numbers and the independent reference grids."""

import csv
from pathlib import Path

import numpy as np
import pytest

from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM

DATA = Path(__file__).resolve().parent / 'data'  # reference grids (test/data/README.md)
GRID_TOLERANCE = 1e-3  # doc/PAPER_MODEL.md: an implementation should agree to better than 0.1 %


def _grid(liquid):
    with (DATA / f'reference_grid_{liquid}.csv').open(encoding='utf-8') as stream:
        return list(csv.DictReader(stream))


@pytest.fixture(scope='module', params=['oil', 'water'])
def liquid(request):
    return request.param


def test_paper_speed_ratio_water_over_oil_at_5_lpm_25_mpa_is_0_560():
    oil, water = MotorModel.default('oil'), MotorModel.default('water')
    n_oil = float(oil.speed(5 * LPM, dp_i=25 * MPA).speed) / RPM
    n_water = float(water.speed(5 * LPM, dp_i=25 * MPA).speed) / RPM
    assert n_oil == pytest.approx(133.2, abs=0.05)
    assert n_water == pytest.approx(74.6, abs=0.05)
    assert n_water / n_oil == pytest.approx(0.560, abs=0.0005)


def test_paper_speed_ratio_with_eq39_is_0_559():
    oil = MotorModel.default('oil', 'eq39')
    water = MotorModel.default('water', 'eq39')
    ratio = (water.speed(5 * LPM, dp_i=25 * MPA).speed / oil.speed(5 * LPM, dp_i=25 * MPA).speed)
    assert float(ratio) == pytest.approx(0.559, abs=0.0005)


@pytest.mark.parametrize(('flow_lpm', 'peak'), [(5, 4.23), (10, 3.09), (20, 2.26), (40, 1.70)])
def test_paper_water_oil_loss_ratio_peaks_as_published(flow_lpm, peak):
    dp_i = np.linspace(0.5, 25, 2000) * MPA
    oil, water = MotorModel.default('oil'), MotorModel.default('water')
    ratio = (water.speed(flow_lpm * LPM, dp_i=dp_i).losses.total
             / oil.speed(flow_lpm * LPM, dp_i=dp_i).losses.total)
    assert ratio.max() == pytest.approx(peak, abs=0.005)
    # "up to three times": the ratio is largest for the smallest flow
    assert ratio.max() > 1.0


def test_paper_channel_drop_for_oil_is_0_03_0_44_1_76_mpa():
    from satmotor_ros.model.families.sliwinski2017.losses import channel_pressure_drop
    oil = MotorModel.default('oil')
    dp = channel_pressure_drop(np.array([5, 20, 40]) * LPM, oil.derived.ch_a, oil.derived.ch_b)
    np.testing.assert_allclose(dp / MPA, [0.03, 0.44, 1.76], atol=0.005)
    water = MotorModel.default('water')
    dp_w = channel_pressure_drop(40 * LPM, water.derived.ch_a, water.derived.ch_b)
    assert float(dp_w / dp[2]) == pytest.approx(0.95, abs=0.01)


def test_paper_clearance_is_5_865_um_unloaded_and_5_140_um_at_25_mpa():
    from satmotor_ros.model.families.sliwinski2017.losses import clearance_height
    oil = MotorModel.default('oil')
    h = clearance_height(np.array([0.0, 25 * MPA]), oil.derived.h0, oil.derived.compliance)
    np.testing.assert_allclose(h * 1e6, [5.865, 5.140], atol=5e-4)


def test_paper_eq39_is_nearly_independent_of_pressure():
    from satmotor_ros.model.families.sliwinski2017.losses import displacement_change_empirical
    oil = MotorModel.default('oil')
    dq = displacement_change_empirical(np.array([2, 25]) * MPA, 1000 * RPM, oil.coef.c1_39,
                                       oil.coef.c2_39)
    assert abs(dq[1] / dq[0] - 1) < 0.02  # eq. (33) changes by ~70 % over the same range


def test_model_matches_reference_grid_at_constant_speed(liquid):
    model, model39 = MotorModel.default(liquid), MotorModel.default(liquid, 'eq39')
    rows = [r for r in _grid(liquid) if r['case'] == 'n_const']
    n = np.array([float(r['n_rpm']) for r in rows]) * RPM
    dp_i = np.array([float(r['dp_i_MPa']) for r in rows]) * MPA
    op, op39 = model.absorbency(n, dp_i=dp_i), model39.absorbency(n, dp_i=dp_i)
    columns = {
        'Q_absorbency_lpm': op.flow / LPM, 'Q_Lfg_lpm': op.losses.flat_clearance / LPM,
        'Q_C_lpm': op.losses.commutation / LPM, 'Qvl_lpm': op.losses.total / LPM,
        'Qvl39_lpm': op39.losses.total / LPM,
    }
    for name, value in columns.items():
        expected = np.array([float(r[name]) for r in rows])
        np.testing.assert_allclose(value, expected, rtol=GRID_TOLERANCE, err_msg=name)


def test_model_matches_reference_grid_at_constant_flow(liquid):
    model, model39 = MotorModel.default(liquid), MotorModel.default(liquid, 'eq39')
    rows = [r for r in _grid(liquid) if r['case'] == 'Q_const']
    q = np.array([float(r['Q_lpm']) for r in rows]) * LPM
    dp_i = np.array([float(r['dp_i_MPa']) for r in rows]) * MPA
    op = model.speed(q, dp_i=dp_i)
    np.testing.assert_allclose(op.speed / RPM, [float(r['n_rpm']) for r in rows],
                               rtol=GRID_TOLERANCE)
    np.testing.assert_allclose(op.speed_loss / RPM, [float(r['n_i_rpm']) for r in rows],
                               rtol=GRID_TOLERANCE)
    np.testing.assert_allclose(model39.speed(q, dp_i=dp_i).speed / RPM,
                               [float(r['n_eq39_rpm']) for r in rows], rtol=GRID_TOLERANCE)


def test_model_matches_reference_speed_ratio_water_over_oil():
    rows = [r for r in _grid('water') if r['case'] == 'Q_const']
    q = np.array([float(r['Q_lpm']) for r in rows]) * LPM
    dp_i = np.array([float(r['dp_i_MPa']) for r in rows]) * MPA
    ratio = (MotorModel.default('water').speed(q, dp_i=dp_i).speed
             / MotorModel.default('oil').speed(q, dp_i=dp_i).speed)
    np.testing.assert_allclose(ratio, [float(r['n_ratio_w_over_o']) for r in rows],
                               rtol=GRID_TOLERANCE)


def test_clearance_and_displacement_change_match_the_reference_grid(liquid):
    from satmotor_ros.model.families.sliwinski2017.losses import (
        clearance_height, displacement_change, displacement_change_empirical, EMPIRICAL_DP_FLOOR,
        inertia_coefficient, pressure_speed_coefficient)
    model = MotorModel.default(liquid)
    rows = [r for r in _grid(liquid) if r['case'] == 'n_const']
    n = np.array([float(r['n_rpm']) for r in rows]) * RPM
    dp_i = np.array([float(r['dp_i_MPa']) for r in rows]) * MPA
    cm3_per_rev = 1e-6 / (2 * np.pi)
    columns = {
        'h_um': clearance_height(dp_i, model.derived.h0, model.derived.compliance) * 1e6,
        'dq33_cm3_rev': displacement_change(
            dp_i, n, pressure_speed_coefficient(model.coef.c, model.geometry),
            inertia_coefficient(model.coef.c_id, model.geometry)) / cm3_per_rev,
        'dq39_cm3_rev': displacement_change_empirical(
            np.maximum(dp_i, EMPIRICAL_DP_FLOOR), n, model.coef.c1_39,
            model.coef.c2_39) / cm3_per_rev,
    }
    for name, value in columns.items():
        expected = np.array([float(r[name]) for r in rows])
        np.testing.assert_allclose(value, expected, rtol=GRID_TOLERANCE, err_msg=name)
