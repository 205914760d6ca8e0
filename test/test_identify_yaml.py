# SPDX-License-Identifier: Apache-2.0
"""A calibrated coefficients.yaml alone reproduces the data it was fitted on, effect and all."""

import numpy as np
import pytest

from satmotor_ros.identify import calibrate
from satmotor_ros.identify.effects import CalibratedModel
from satmotor_ros.identify.output import write_yaml
from satmotor_ros.identify.synthetic import generate, Injection, Plan, REALISTIC
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model.units import LPM


@pytest.mark.parametrize('liquid', ['oil', 'water'])
@pytest.mark.parametrize('effect', list(REALISTIC))
def test_calibrated_yaml_with_its_effect_reproduces_the_data(tmp_path, liquid, effect):
    plan = Plan(liquid=liquid)
    table = generate(plan, Injection.realistic(effect, 1.0, liquid), seed=21)
    cal = calibrate(table, liquid)
    path = tmp_path / 'coefficients.yaml'
    write_yaml(cal, path)
    calibrated = CalibratedModel.load(path, liquid)
    assert calibrated.effect == (cal.chosen.effect if cal.chosen else 'none')
    channels = {**table.channels, 'p_out': table.p_out}
    predicted, _ = calibrated.measured_flow(table.speed, channels, dp=table.dp)
    packaged = MotorModel.default(liquid).absorbency(table.speed, dp=table.dp).flow
    noise = float(np.sqrt(np.mean(plan.noise_lpm(table.flow, cal.model) ** 2)))
    rmse = float(np.sqrt(np.mean((table.flow - predicted) ** 2))) / LPM
    before = float(np.sqrt(np.mean((table.flow - packaged) ** 2))) / LPM
    assert rmse < 1.5 * noise
    if effect != 'none':
        assert before > rmse


def test_calibrating_again_from_a_calibrated_file_starts_without_its_effect(tmp_path):
    plan = Plan(liquid='water')
    table = generate(plan, Injection.realistic('viscosity_temperature', 1.0, 'water'), seed=5)
    path = tmp_path / 'coefficients.yaml'
    write_yaml(calibrate(table, 'water'), path)
    again = calibrate(table, 'water', load_motor(path))
    assert again.chosen is not None and again.chosen.effect == 'viscosity_temperature'
    assert any('were left out' in note for note in again.table.notes)
    assert not again.model.effects
