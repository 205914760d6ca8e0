# SPDX-License-Identifier: Apache-2.0
"""Inputs so large that the arithmetic overflows are flagged, never returned with OK (issue 14)."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from satmotor_ros.model import InvalidInputError, MotorModel, PointStatus
from satmotor_ros.model.results import INVALID
from satmotor_ros.model.units import MPA

OIL, WATER = MotorModel.default('oil'), MotorModel.default('water')
EQ39 = MotorModel.default('oil', displacement_law='eq39')


@pytest.mark.parametrize('flow', [1e308, 5e300, 1e299, 11.0, -1e308])
def test_absurd_flow_is_invalid_on_the_point_path(flow):
    for point in (WATER.speed_point(flow, 19.9 * MPA), OIL.speed_point(flow, dp_i=10 * MPA)):
        assert point.status & INVALID and math.isnan(point.speed)


def test_absurd_flow_is_invalid_on_the_array_path_and_refused_by_default():
    flows = np.array([5e300, 1e299, 1e-3])
    out = OIL.speed(flows, dp_i=10 * MPA, errors='mask')
    assert list(out.status[:2]) == [PointStatus.BEYOND_LIMIT] * 2
    assert np.isnan(out.speed[:2]).all() and out.speed[2] > 0 and out.status[2] & INVALID == 0
    with pytest.raises(InvalidInputError, match=r'flow\[0\] = 5e\+300 m\^3/s: beyond any motor'):
        OIL.speed(flows, dp_i=10 * MPA)


def test_overflow_inside_a_solve_is_a_flag_not_an_exception():
    point = EQ39.absorbency_point(1e-9, dp=5 * MPA)
    assert point.status == PointStatus.BEYOND_LIMIT and math.isnan(point.flow)


def test_ordinary_points_are_untouched():
    point = OIL.speed_point(20e-3 / 60, 10 * MPA)
    assert point.status & INVALID == 0 and point.speed > 0


def test_operating_point_json_is_valid_json_or_one_line():
    run = [sys.executable, '-m', 'satmotor_ros.cli', 'operating-point', '--json', '--dp-i', '10']
    bad = subprocess.run([*run, '--flow', '5e300 m^3/s'], capture_output=True, text=True)
    assert bad.returncode == 1 and bad.stdout == ''
    assert 'beyond any motor' in bad.stderr and bad.stderr.count('\n') == 1
    good = subprocess.run([*run, '--flow', '0.001', '--law', 'eq39'], capture_output=True,
                          text=True)
    assert good.returncode == 0
    json.loads(good.stdout)  # bare NaN or Infinity would not parse as JSON
