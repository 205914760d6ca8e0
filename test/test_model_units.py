# SPDX-License-Identifier: Apache-2.0
"""Hydraulic units convert to SI and back, and wrong units are refused by kind."""

import pytest

from satmotor_ros.model import UnitError
from satmotor_ros.model.units import from_si, LPM, MPA, parse_quantity, RPM, to_si, units_of


@pytest.mark.parametrize(('text', 'kind', 'default', 'expected'), [
    ('5', 'flow', 'l/min', 5 * LPM),
    ('8.3e-5m^3/s', 'flow', 'l/min', 8.3e-5),
    ('8.3e-5 m^3/s', 'flow', 'l/min', 8.3e-5),
    ('250bar', 'pressure', 'MPa', 25 * MPA),
    ('25', 'pressure', 'MPa', 25 * MPA),
    ('1500rpm', 'speed', 'rad/s', 1500 * RPM),
    ('40 cSt', 'viscosity', 'm^2/s', 40e-6),
    ('300 K', 'temperature', 'degC', 300 - 273.15),
    ('.5', 'pressure', 'MPa', 0.5 * MPA),
])
def test_parse_quantity_gives_si(text, kind, default, expected):
    assert parse_quantity(text, kind, default) == pytest.approx(expected)


@pytest.mark.parametrize(('text', 'kind', 'match'), [
    ('5 bar', 'flow', "unit 'bar' is not a flow unit"),
    ('fast', 'speed', "'fast' is not a number"),
    ('5 l/min', 'colour', "unknown kind of quantity 'colour'"),
])
def test_parse_quantity_refuses_wrong_units(text, kind, match):
    with pytest.raises(UnitError, match=match):
        parse_quantity(text, kind, 'l/min')


@pytest.mark.parametrize('kind', ['flow', 'pressure', 'speed', 'temperature', 'displacement'])
def test_every_unit_round_trips(kind):
    for unit in units_of(kind):
        assert from_si(to_si(12.5, unit, kind), unit, kind) == pytest.approx(12.5)
