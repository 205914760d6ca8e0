# SPDX-License-Identifier: Apache-2.0
"""A port valve around the motor's maps: its flag and the channels reach every path."""

import copy

import pytest
from satmotor_ros.model import INVALID, MotorModel, PointStatus
from satmotor_ros.model.io.config import default_config_path, motor_from_mapping
from satmotor_ros.model.units import MPA, RPM
import yaml

BASE = yaml.safe_load(default_config_path().read_text(encoding='utf-8'))
VALVE = {'coefficient': 2.0e-10, 'reference': 18.0 * MPA, 'exponent': 1.0,
         'fitted_range': {'dp': [18.0 * MPA, 20.0 * MPA]}}
LEAK = {'regressor': 'p_case', 'coefficient': 3e-12}
EXTRAPOLATED = int(PointStatus.EXTRAPOLATED)


def model(effects, leak=0.0):
    doc = copy.deepcopy(BASE)
    doc['coefficient_sets']['oil']['effects'] = effects
    doc['coefficient_sets']['oil']['coefficients']['external_leakage'] = leak
    return MotorModel.from_spec(motor_from_mapping(doc), 'oil')


RANGED = model({'threshold:dp': VALVE})


@pytest.mark.parametrize('sign', [1.0, -1.0])
def test_a_valve_read_beyond_its_fitted_drops_flags_every_path(sign):
    n = sign * 800.0 * RPM
    for drop, flagged in ((19.0, False), (23.5, True)):
        dp = sign * drop * MPA
        forward = RANGED.absorbency_point(n, dp)
        assert not forward.status & int(INVALID)
        chamber = RANGED.absorbency_point(n, dp_i=forward.dp_i)
        port = RANGED.speed_point(forward.flow, dp)
        inner = RANGED.speed_point(forward.flow, dp_i=forward.dp_i)
        for point in (forward, chamber, port, inner):
            assert bool(point.status & EXTRAPOLATED) is flagged, (drop, point)
        assert port.speed == pytest.approx(n, rel=1e-7)
        assert inner.speed == pytest.approx(n, rel=1e-7)


@pytest.mark.parametrize('sign', [1.0, -1.0])
def test_the_channels_reach_the_motor_inside_the_valve_paths(sign):
    """With the valve shut or open, a case leak reads the p_case it is given."""
    both = model({'threshold:dp': {k: v for k, v in VALVE.items() if k != 'fitted_range'},
                  'external_leakage': LEAK}, leak=LEAK['coefficient'])
    leak_only = model({'external_leakage': LEAK}, leak=LEAK['coefficient'])
    n, case = sign * 800.0 * RPM, {'p_case': 0.4 * MPA}
    for drop in (10.0, 22.0):  # shut, open
        dp = sign * drop * MPA
        forward = both.absorbency_point(n, dp, channels=case)
        alone = leak_only.absorbency_point(n, dp, channels=case)
        valve = forward.flow - alone.flow
        assert valve == pytest.approx(sign * 2.0e-10 * max(drop * MPA - 18.0 * MPA, 0.0),
                                      rel=1e-9, abs=1e-15)
        assert forward.external == pytest.approx(sign * 3e-12 * 0.4 * MPA, rel=1e-9)
        for point in (both.speed_point(forward.flow, dp, channels=case),
                      both.speed_point(forward.flow, dp_i=forward.dp_i, channels=case),
                      both.absorbency_point(n, dp_i=forward.dp_i, channels=case)):
            assert not point.status & int(INVALID)
            assert point.external == pytest.approx(sign * 3e-12 * 0.4 * MPA, rel=1e-9)
            assert point.flow == pytest.approx(forward.flow, rel=1e-9)
            assert point.speed == pytest.approx(n, rel=1e-7)
        shifted = both.speed_point(forward.flow, dp_i=forward.dp_i, channels={'p_case': 0.0})
        assert shifted.speed > n if sign > 0 else shifted.speed < n  # less leak, more speed
