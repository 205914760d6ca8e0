# SPDX-License-Identifier: Apache-2.0
"""The loop closed: a demo bag with a hidden effect -> calibrate -> a smaller speed residual."""

import csv
import json

import numpy as np
import pytest
from satmotor_ros.cli.demo import parse_effects
from satmotor_ros.cli.main import main
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.plant.scenario import default_cycle
import yaml

pytestmark = [pytest.mark.ros, pytest.mark.slow]

WEAR = 3e-9  # clearance growth injected into the virtual motor [m/rev]
RATE = 50.0  # controller, set-point and plant publishing rate: half the demo's [Hz]


def _residuals(path):
    with open(path, newline='') as f:
        rows = [r for r in csv.DictReader(f) if r['residual [rpm]']]
    return np.array([float(r['residual [rpm]']) for r in rows])


def test_demo_bag_with_wear_is_calibrated_and_the_new_yaml_shrinks_the_speed_residual(
        tmp_path, capsys):
    """
    The virtual motor wears its clearances; nobody tells the calibration.

    The demo's run with the model's feed-forward (``satmotor demo --duration 96`` makes it
    and the PI-alone run, which is not needed here) records the virtual motor, controller
    and motor_model over ROS. Calibrating the bag must name the wear, write it as data, and
    the motor_model prediction (``satmotor replay`` runs the node's own code; test_replay_live
    holds them equal) with the new file must track the measured speed better than with the
    packaged one. 96 s: at 48 s (6e-9) or 24 s (3e-9) the tracking cycle's steps are too
    short for the calibration to name the wear. At half the demo's rate (50 Hz, 4 800
    samples) the run costs half its CPU (the nodes' work is per message) and the figures
    keep their margins: the wear at 1.002 of the injected, the RMS residual at 0.35 of the
    packaged file's (0.33 at 100 Hz; limit 0.6).
    """
    from satmotor_ros.cli._demo_ros import run_cycle  # imports rclpy
    bag = tmp_path / 'water_model'
    run_cycle('water', 'model', default_cycle().scaled(96.0),
              parse_effects([f'clearance_wear={WEAR}']), bag, None, RATE)
    cal = tmp_path / 'cal'
    assert main(['calibrate', str(bag), '--liquid', 'water', '--out', str(cal)]) == 0
    result = json.loads((cal / 'calibration.json').read_text())
    assert result['effect'] == 'clearance_wear'
    assert 0.7 * WEAR < result['coefficient'] < 1.3 * WEAR
    block = yaml.safe_load((cal / 'coefficients.yaml').read_text())
    assert 'clearance_wear' in block['coefficient_sets']['water']['effects']
    model = MotorModel.from_spec(load_motor(cal / 'coefficients.yaml'), 'water')
    assert model.channels in (('revolutions',), ('time',))

    common = ['replay', str(bag), '--liquid', 'water', '--no-plot']
    assert main([*common, '--out', str(tmp_path / 'before.csv')]) == 0
    assert main([*common, '--motor', str(cal / 'coefficients.yaml'),
                 '--out', str(tmp_path / 'after.csv')]) == 0
    capsys.readouterr()
    before, after = _residuals(tmp_path / 'before.csv'), _residuals(tmp_path / 'after.csv')
    assert len(after) == len(before) > 1000  # the effect's channel never blocked a prediction
    assert abs(np.median(after)) < 0.2 * abs(np.median(before))
    assert np.sqrt(np.mean(after ** 2)) < 0.6 * np.sqrt(np.mean(before ** 2))
