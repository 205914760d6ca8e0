# SPDX-License-Identifier: Apache-2.0
"""The errors of a time series read with every sample are over its samples, not its bins."""

from dataclasses import replace

import numpy as np
import pytest

from satmotor_ros.cli.calibrate import _errors
from satmotor_ros.identify import calibrate
from satmotor_ros.identify.pipeline import Options
from satmotor_ros.identify.synthetic import Dynamics, generate_transient, Injection, Plan
from satmotor_ros.identify.validate import validate
from satmotor_ros.model.units import LPM

NOISE_LPM = 0.2
"""White noise of each flow reading [l/min]: a bin of 20 samples averages it down ~4.5 times."""


def _recording(seed):
    """Return a noise-free recording of the packaged model and white flow noise of its own."""
    quiet = Plan(liquid='oil', noise_flow_lpm=0.0, noise_flow_rel=0.0, noise_speed_rpm=0.0,
                 noise_pressure_mpa=0.0, noise_temperature_c=0.0)
    table = generate_transient(quiet, Injection(), Dynamics(), seed=3, duration_s=30.0)
    noise = np.random.default_rng(seed).normal(0.0, NOISE_LPM * LPM, len(table))
    return replace(table, flow=table.flow + noise), noise


@pytest.fixture(scope='module')
def calibrated():
    table, noise = _recording(11)
    return calibrate(table, 'oil', options=Options(mode='transient')), table, noise


def test_the_calibration_error_is_over_every_sample_not_over_the_bins(calibrated):
    cal, table, noise = calibrated
    summary = cal.summary()
    over, bins = summary['error_over'], summary['error_over_bins']
    assert summary['effect'] == 'none' and not summary['outliers']
    # every sample the rows hold counts once, and nearly all samples are held
    assert over == {'what': 'samples', 'n': cal.samples.n_samples,
                    'n_with_outliers': cal.samples.n_samples}
    assert over['n'] >= 0.95 * len(table) and bins['n'] == len(cal.parts) < over['n'] / 10
    # the model is the truth, so what is left at each sample is its own noise
    expected = float(np.sqrt(np.mean(noise[cal.samples.in_bins] ** 2))) / LPM
    for key in ('error_before', 'error_after', 'error_after_with_outliers'):
        assert summary[key]['rmse_lpm'] == pytest.approx(expected, rel=0.05), key
    assert summary['error_after']['max_abs_lpm'] == pytest.approx(
        float(np.max(np.abs(noise[cal.samples.in_bins]))) / LPM, rel=0.1)
    # over the bins the noise is averaged down: a figure of another size
    assert bins['error_after']['rmse_lpm'] < 0.5 * expected
    line = _errors(summary, True)
    assert f'{summary["error_after"]["rmse_lpm"]:.4g} l/min over {over["n"]} samples' in line
    assert f"over the fit's {bins['n']} rows" in line


def test_validation_is_over_every_sample_too(calibrated):
    cal, table, _ = calibrated
    again, noise = _recording(12)
    val = validate(again, cal.model, 'oil', mode='transient').summary()
    assert val['error_over']['what'] == 'samples'
    assert val['n_points'] == val['error_over']['n'] >= 0.95 * len(table)
    expected = float(np.sqrt(np.mean(noise ** 2))) / LPM
    assert val['error']['rmse_lpm'] == pytest.approx(expected, rel=0.05)
    assert val['error_over_bins']['error']['rmse_lpm'] < 0.5 * expected
