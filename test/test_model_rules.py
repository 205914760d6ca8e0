# SPDX-License-Identifier: Apache-2.0
"""The status rules at their edges, and the floor of eq. (39) named when it refuses."""

import math

import numpy as np
import pytest

from satmotor_ros.model import InvalidInputError, MotorModel, PointStatus
from satmotor_ros.model.engine.screening import beyond_limit, CEILINGS, input_flags
from satmotor_ros.model.units import MPA, RPM


@pytest.mark.parametrize('ceiling', sorted(set(CEILINGS.values())))
def test_an_input_at_its_ceiling_is_computed_and_just_above_it_is_beyond_any_motor(ceiling):
    above = math.nextafter(ceiling, math.inf)
    assert input_flags(ceiling, ceiling) == 0
    assert input_flags(above, ceiling) == int(PointStatus.BEYOND_LIMIT)
    assert input_flags(-above, ceiling) == int(PointStatus.NEGATIVE | PointStatus.BEYOND_LIMIT)
    assert list(input_flags(np.array([ceiling, above]), ceiling)) == [
        0, int(PointStatus.BEYOND_LIMIT)]


def test_a_chamber_drop_at_the_model_limit_is_computed_and_just_above_it_is_not():
    model = MotorModel.default('oil')
    limit = model.dp_limit
    assert beyond_limit(limit, limit) == 0
    assert beyond_limit(math.nextafter(limit, math.inf), limit) == int(PointStatus.BEYOND_LIMIT)
    assert model.breakdown_point(100 * RPM, limit).status & int(PointStatus.BEYOND_LIMIT) == 0


def test_a_speed_below_the_floor_of_eq_39_is_refused_naming_the_speed_and_the_law():
    model = MotorModel.default('oil', 'eq39')
    with pytest.raises(InvalidInputError,
                       match=r'^speed = [0-9.e+-]+ rad/s: below the floor of eq\. \(39\), '
                             r'where its loss diverges$'):
        model.absorbency(0.01 * RPM, dp_i=20 * MPA)
