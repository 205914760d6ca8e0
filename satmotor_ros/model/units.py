# SPDX-License-Identifier: Apache-2.0
"""
Units at the human edges: hydraulic units in, SI out.

Everything inside satmotor_ros is SI (REP 103). People type l/min, MPa, bar,
rpm and cSt; this module turns such quantities into SI and back. A unit is
always looked up within a *kind* (flow, pressure, ...) so that ``5 bar`` given
for a flow is an error, not a silent misreading.
"""

from __future__ import annotations

import math
import re

from satmotor_ros.model._typing import Real
from satmotor_ros.model.errors import UnitError

LPM = 1.0e-3 / 60.0
"""One litre per minute in m^3/s."""

MPA = 1.0e6
"""One megapascal in Pa."""

RPM = 2.0 * math.pi / 60.0
"""One revolution per minute in rad/s."""

CST = 1.0e-6
"""One centistokes in m^2/s."""

CM3_PER_MIN = 1.0e-6 / 60.0
"""One cm^3/min in m^3/s (eq. 32's Delta Q_vl in the paper's unit)."""

CM3_PER_REV = 1.0e-6 / (2.0 * math.pi)
"""One cm^3/rev in m^3/rad (eq. 33's and eq. 39's Delta q in the paper's unit)."""

ATMOSPHERE = 101325.0
"""Standard atmosphere in Pa: absolute (sensor_msgs/FluidPressure) minus this is gauge."""


def gauge(absolute: Real) -> Real:
    """
    Return an absolute pressure as gauge, the one conversion of readings (float or array).

    Parameters
    ----------
    absolute : float or ndarray
        Absolute pressure, [Pa]

    Returns
    -------
    float or ndarray
        absolute - :data:`ATMOSPHERE`, below 0 under vacuum, [Pa]

    """
    return absolute - ATMOSPHERE


def channel_gauge(absolute: Real) -> Real:
    """
    Return an absolute pressure as the gauge channel an effect reads: never below 0.

    Below atmosphere nothing is driven out of the motor; NaN stays NaN (it is
    flagged where it is read).

    Parameters
    ----------
    absolute : float or ndarray
        Absolute pressure, as a sensor reads it, [Pa]

    Returns
    -------
    float or ndarray
        max(:func:`gauge`, 0), [Pa]

    """
    p = gauge(absolute)
    return p * (p > 0.0) + 0.0  # + 0.0: -0.0 below atmosphere is 0.0; NaN * False is NaN


INCH = 0.0254
"""One inch in m (exact, by definition)."""

PSI = 4.4482216152605 / INCH ** 2
"""One pound-force per square inch in Pa."""

GPM = 231.0 * INCH ** 3 / 60.0
"""One US gallon (231 in^3) per minute in m^3/s."""

# kind -> unit -> (scale, offset): si = value * scale + offset
_UNITS: dict[str, dict[str, tuple[float, float]]] = {
    'flow': {
        'm^3/s': (1.0, 0.0), 'l/min': (LPM, 0.0), 'L/min': (LPM, 0.0), 'lpm': (LPM, 0.0),
        'cm^3/s': (1.0e-6, 0.0), 'l/s': (1.0e-3, 0.0), 'gpm': (GPM, 0.0),
        'in^3/s': (INCH ** 3, 0.0), 'in^3/min': (INCH ** 3 / 60.0, 0.0),
    },
    'pressure': {
        'Pa': (1.0, 0.0), 'kPa': (1.0e3, 0.0), 'MPa': (MPA, 0.0), 'GPa': (1.0e9, 0.0),
        'bar': (1.0e5, 0.0), 'barg': (1.0e5, 0.0), 'bara': (1.0e5, 0.0), 'psi': (PSI, 0.0),
        'psig': (PSI, 0.0), 'psia': (PSI, 0.0),
    },
    'speed': {
        'rad/s': (1.0, 0.0), 'rpm': (RPM, 0.0), 'rev/min': (RPM, 0.0), 'rev/s': (60.0 * RPM, 0.0),
    },
    'viscosity': {'m^2/s': (1.0, 0.0), 'cSt': (CST, 0.0), 'mm^2/s': (CST, 0.0)},
    'density': {'kg/m^3': (1.0, 0.0), 'g/cm^3': (1.0e3, 0.0)},
    'length': {'m': (1.0, 0.0), 'mm': (1.0e-3, 0.0), 'um': (1.0e-6, 0.0), 'µm': (1.0e-6, 0.0),
               'in': (INCH, 0.0)},
    'velocity': {'m/s': (1.0, 0.0), 'mm/s': (1.0e-3, 0.0), 'in/s': (INCH, 0.0)},
    'area': {'m^2': (1.0, 0.0), 'cm^2': (1.0e-4, 0.0), 'mm^2': (1.0e-6, 0.0),
             'in^2': (INCH ** 2, 0.0)},
    'displacement': {
        'm^3/rad': (1.0, 0.0), 'm^3/rev': (1.0 / (2 * math.pi), 0.0),
        'cm^3/rev': (CM3_PER_REV, 0.0), 'in^3/rev': (INCH ** 3 / (2 * math.pi), 0.0),
    },
    'temperature': {'degC': (1.0, 0.0), 'K': (1.0, -273.15)},
    'time': {'s': (1.0, 0.0), 'ms': (1.0e-3, 0.0), 'min': (60.0, 0.0)},
    'torque': {'N*m': (1.0, 0.0), 'Nm': (1.0, 0.0)},
    'leakage_coefficient': {'m^3/(s*Pa)': (1.0, 0.0), 'l/(min*MPa)': (LPM / MPA, 0.0)},
}

_QUANTITY = re.compile(r'^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S*)\s*$')


def kinds() -> tuple[str, ...]:
    """
    List the kinds of quantity this module converts.

    Returns
    -------
    tuple of str
        The kind names, e.g. ``'flow'``.

    """
    return tuple(_UNITS)


def units_of(kind: str) -> tuple[str, ...]:
    """
    List the units accepted for one kind of quantity.

    Parameters
    ----------
    kind : str
        A kind from :func:`kinds`, [-]

    Returns
    -------
    tuple of str
        Unit spellings accepted for `kind`.

    """
    return tuple(_table(kind))


def _table(kind: str) -> dict[str, tuple[float, float]]:
    try:
        return _UNITS[kind]
    except KeyError:
        msg = f'unknown kind of quantity {kind!r}; known: {", ".join(_UNITS)}'
        raise UnitError(msg) from None


def _scale(unit: str, kind: str) -> tuple[float, float]:
    table = _table(kind)
    if unit not in table:
        article = 'an' if kind[0] in 'aeiou' else 'a'
        msg = f'unit {unit!r} is not {article} {kind} unit; use one of: {", ".join(table)}'
        raise UnitError(msg)
    return table[unit]


def to_si(value: float, unit: str, kind: str) -> float:
    """
    Convert a value in `unit` to SI.

    Parameters
    ----------
    value : float
        Magnitude in `unit`, [unit]
    unit : str
        Unit spelling, e.g. ``'l/min'``, [-]
    kind : str
        Kind of quantity the unit must belong to, [-]

    Returns
    -------
    float
        The value in SI (temperature in degC, as sensor_msgs/Temperature).

    Examples
    --------
    >>> round(to_si(250.0, 'bar', 'pressure'))
    25000000

    """
    scale, offset = _scale(unit, kind)
    return value * scale + offset


def from_si(value: float, unit: str, kind: str) -> float:
    """
    Convert an SI value to `unit`.

    Parameters
    ----------
    value : float
        Magnitude in SI, [SI]
    unit : str
        Target unit spelling, [-]
    kind : str
        Kind of quantity the unit must belong to, [-]

    Returns
    -------
    float
        The value in `unit`.

    Examples
    --------
    >>> from_si(1.0e-3 / 60.0, 'l/min', 'flow')
    1.0

    """
    scale, offset = _scale(unit, kind)
    return (value - offset) / scale


def pressure_reference(unit: str) -> str | None:
    """
    Tell whether a pressure unit says gauge or absolute.

    Parameters
    ----------
    unit : str
        Pressure unit as written, [-]

    Returns
    -------
    str or None
        ``'gauge'`` for psig and barg, ``'absolute'`` for psia and bara, None for a unit that
        does not say (Pa, bar, psi, ...).

    Examples
    --------
    >>> pressure_reference('psig'), pressure_reference('PSIA'), pressure_reference('MPa')
    ('gauge', 'absolute', None)

    """
    folded = unit.lower()
    if folded in ('psig', 'barg'):
        return 'gauge'
    if folded in ('psia', 'bara'):
        return 'absolute'
    return None


def parse_quantity(text: str, kind: str, default_unit: str) -> float:
    """
    Parse ``'5'``, ``'250bar'`` or ``'8.3e-5 m^3/s'`` into an SI value.

    Parameters
    ----------
    text : str
        A number, optionally followed by a unit, [-]
    kind : str
        Kind of quantity expected, [-]
    default_unit : str
        Unit assumed when `text` gives none, [-]

    Returns
    -------
    float
        The value in SI.

    Raises
    ------
    UnitError
        If `text` is not a number with an optional known unit of `kind`.

    Examples
    --------
    >>> parse_quantity('5', 'flow', 'l/min') == 5 * LPM
    True
    >>> parse_quantity('250bar', 'pressure', 'MPa')
    25000000.0

    """
    match = _QUANTITY.match(str(text))
    if match is None:
        msg = f'{text!r} is not a number with an optional {kind} unit'
        raise UnitError(msg)
    number, unit = match.groups()
    return to_si(float(number), unit or default_unit, kind)
