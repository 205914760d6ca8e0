# SPDX-License-Identifier: Apache-2.0
"""
The library of candidate effects: each a physical term with one coefficient.

Every candidate carries its vocabulary name (DESIGN.md: ``external_leakage``,
``viscosity_temperature``, ``clearance_wear``, ``flow_sensor_offset``,
``flow_sensor_gain``, ``speed_sensor_gain``, ``channel:<name>``,
``term:<expression>``), the regressor it uses, the unit and source of its
coefficient, and a function from the coefficient to a :class:`Modifier` of
the model's prediction. A coefficient of 0 is always the model without the
effect, so every candidate nests the baseline. The library only builds
candidates; fitting and selection live in :mod:`.fit` and :mod:`.select`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from satmotor_ros.identify.parts import LossParts, Modifier
from satmotor_ros.identify.viscosity import ViscosityLaw
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import TERMS
from satmotor_ros.model.units import LPM

NAMED_CHANNELS = ('time', 'revolutions', 'temperature', 'p_case')
"""Channels a named physical effect covers; every other channel gets ``channel:<name>``."""

MIN_SPREAD = 1.0e-3
"""A regressor must vary by this share of its largest magnitude to be offered, [-]."""


@dataclass(frozen=True)
class Candidate:
    """One candidate effect bound to the data it will be fitted on."""

    effect: str  # vocabulary id, e.g. 'external_leakage' or 'term:dp^2*n'
    regressor: str  # the channel or expression the effect uses
    unit: str  # unit of the coefficient
    source: str  # the physics or standard the term comes from
    values: FloatArray  # the regressor at each point (SI), for plots
    modify: Callable[[float], Modifier]  # coefficient -> modified prediction
    typical: float  # coefficient magnitude that changes the loss by ~1 l/min
    bounds: tuple[float, float] = (-np.inf, np.inf)  # physical range of the coefficient
    start: float = 0.0  # initial coefficient of the fit

    @property
    def label(self) -> str:
        """Return the effect with its regressor, e.g. ``external_leakage(p_case)``."""
        if ':' in self.effect or self.effect in ('flow_sensor_offset',):
            return self.effect
        return f'{self.effect}({self.regressor})'


def _varies(x: FloatArray) -> bool:
    return bool(np.all(np.isfinite(x)) and np.ptp(x) > MIN_SPREAD * np.max(np.abs(x)) > 0.0)


def _per_unit(x: FloatArray) -> float:
    """Coefficient that makes `x` contribute 1 l/min at its largest magnitude."""
    return float(LPM / max(np.max(np.abs(x)), 1e-300))


def _additive(effect: str, regressor: str, unit: str, source: str, x: FloatArray,
              bounds: tuple[float, float] = (-np.inf, np.inf), values: FloatArray | None = None
              ) -> Candidate:
    return Candidate(effect, regressor, unit, source, x if values is None else values,
                     lambda k: Modifier(additive=k * x), _per_unit(x), bounds)


def external_leakage(regressor: str, pressure: FloatArray) -> Candidate:
    """
    Build the external leakage Q_ex = k_ex p, eq. (24), driven by case or outlet pressure.

    Parameters
    ----------
    regressor : str
        ``'p_case'`` or ``'p_out'``, [-]
    pressure : ndarray
        The driving (gauge) pressure at each point, [Pa]

    Returns
    -------
    Candidate
        Coefficient k_ex >= 0, [m^3/(s*Pa)]

    """
    return _additive('external_leakage', regressor, 'm^3/(s*Pa)', 'eq. (24), lumped',
                     pressure, (0.0, np.inf))


def flow_sensor_offset(parts: LossParts) -> Candidate:
    """
    Build a flowmeter offset: Q_measured = Q + b.

    Parameters
    ----------
    parts : LossParts
        Components at the points, [-]

    Returns
    -------
    Candidate
        Coefficient b, [m^3/s]

    """
    return Candidate('flow_sensor_offset', '1', 'm^3/s', 'flowmeter zero error',
                     parts.flow, lambda b: Modifier(offset=b), LPM, (-50 * LPM, 50 * LPM))


def flow_sensor_gain(parts: LossParts) -> Candidate:
    """
    Build a flowmeter gain error: Q_measured = (1 + g) Q.

    Parameters
    ----------
    parts : LossParts
        Components at the points, [-]

    Returns
    -------
    Candidate
        Coefficient g, [-]

    """
    return Candidate('flow_sensor_gain', 'flow', '-', 'flowmeter calibration error',
                     parts.flow, lambda g: Modifier(flow_gain=1.0 + g),
                     _per_unit(parts.flow), (-0.5, 0.5))


def speed_sensor_gain(parts: LossParts) -> Candidate:
    """
    Build a speed-sensor gain error: n_measured = (1 + g) n.

    Parameters
    ----------
    parts : LossParts
        Components at the points, [-]

    Returns
    -------
    Candidate
        Coefficient g, [-]

    """
    return Candidate('speed_sensor_gain', 'speed', '-', 'speed-sensor calibration error',
                     parts.speed, lambda g: Modifier(speed_gain=1.0 + g),
                     _per_unit(parts.displacement), (-0.5, 0.5))


def viscosity_temperature(parts: LossParts, temperature: FloatArray,
                          law: ViscosityLaw) -> Candidate:
    """
    Build the leakage of eqs. (1) and (5) re-evaluated with nu(T) from a standard law.

    Parameters
    ----------
    parts : LossParts
        Components at the points, [-]
    temperature : ndarray
        Liquid temperature at each point, [degC]
    law : ViscosityLaw
        Walther (oil) or Vogel (water), pinned at the set's viscosity, [-]

    Returns
    -------
    Candidate
        Coefficient: the law's slope B (0: constant viscosity), [law.unit]

    """
    def modify(slope: float) -> Modifier:
        ratio = law.viscosity(temperature, slope) / law.reference_viscosity
        return Modifier(flat_clearance=ratio ** parts.nu_exponent_lfg,
                        commutation=ratio ** parts.nu_exponent_c)

    source = ('Walther, ASTM D341' if law.law == 'walther' else 'Vogel (water)')
    return Candidate('viscosity_temperature', 'temperature', law.unit, source, temperature,
                     modify, law.standard_slope, (0.0, 20.0 * law.standard_slope),
                     law.standard_slope)


def clearance_wear(parts: LossParts, regressor: str, exposure: FloatArray) -> Candidate:
    """
    Build clearance wear: h_R and h_S grow by w x, eqs. (1), (2) and (5) re-evaluated.

    Parameters
    ----------
    parts : LossParts
        Components at the points, [-]
    regressor : str
        ``'time'`` or ``'revolutions'``, [-]
    exposure : ndarray
        Time [s] or cumulative revolutions [rev] at each point, [s or rev]

    Returns
    -------
    Candidate
        Wear rate w >= 0, [m/s] or [m/rev]

    """
    x = exposure - np.min(exposure)

    def modify(rate: float) -> Modifier:
        grow = rate * x
        return Modifier(flat_clearance=(1.0 + grow / parts.clearance) ** parts.h_exponent,
                        commutation=(1.0 + grow / parts.clearance_satellites)
                        ** parts.hs_exponent)

    typical = float(np.mean(parts.clearance)) * 0.05 / max(float(np.max(x)), 1e-300)
    unit = 'm/s' if regressor == 'time' else 'm/rev'
    return Candidate('clearance_wear', regressor, unit, 'eqs. (1), (2), (5) with h + w x',
                     exposure, modify, typical, (0.0, np.inf))


def channel(name: str, values: FloatArray) -> Candidate:
    """
    Build a generic linear effect of a measured channel: k (x - mean x).

    Parameters
    ----------
    name : str
        Channel name without unit, [-]
    values : ndarray
        Channel at each point, [SI or as given]

    Returns
    -------
    Candidate
        Coefficient k, [m^3/s per channel unit]

    """
    x = values - float(np.mean(values))
    return _additive(f'channel:{name}', name, f'm^3/s per {name} unit',
                     'measured channel (no physical model)', x, values=values)


def term(expression: str, parts: LossParts) -> Candidate:
    """
    Build a loss term k f(n, dp_i) from :data:`TERMS`.

    Parameters
    ----------
    expression : str
        A key of :data:`TERMS`, e.g. ``'dp^2*n'``, [-]
    parts : LossParts
        Components at the points, [-]

    Returns
    -------
    Candidate
        Coefficient k, SI, [TERMS unit]

    """
    fn, unit = TERMS[expression]
    x = fn(parts.speed, parts.dp_i)
    return _additive(f'term:{expression}', expression, unit, 'not in eqs. (31)-(33)', x)


def build_library(parts: LossParts, channels: Mapping[str, FloatArray],
                  law: ViscosityLaw) -> tuple[list[Candidate], list[str]]:
    """
    Build every candidate the data can test.

    Parameters
    ----------
    parts : LossParts
        Components at the points, [-]
    channels : mapping of str to ndarray
        Extra channels at the same points (SI; temperature in degC), [-]
    law : ViscosityLaw
        Viscosity law of the liquid, [-]

    Returns
    -------
    list of Candidate
        The candidates, in a fixed order.
    list of str
        Why other candidates were not offered (missing or constant channel).

    """
    out = [flow_sensor_offset(parts), flow_sensor_gain(parts), speed_sensor_gain(parts)]
    skipped = []
    pressures = {'p_case': channels.get('p_case'), 'p_out': channels.get('p_out')}
    for name, p in pressures.items():
        if p is not None and _varies(p):
            out.append(external_leakage(name, p))
        else:
            skipped.append(f'external_leakage({name}): {_why(p)}')
    temperature = channels.get('temperature')
    if temperature is not None and _varies(temperature) and np.ptp(temperature) >= 1.0:
        out.append(viscosity_temperature(parts, temperature, law))
    else:
        skipped.append(f'viscosity_temperature: {_why(temperature)}')
    for name in ('time', 'revolutions'):
        x = channels.get(name)
        if x is not None and _varies(x):
            out.append(clearance_wear(parts, name, x))
        else:
            skipped.append(f'clearance_wear({name}): {_why(x)}')
    for name, x in channels.items():
        if name in NAMED_CHANNELS or name in ('p_out', 'p_in', 'speed', 'flow'):
            continue
        if _varies(x):
            out.append(channel(name, x))
        else:
            skipped.append(f'channel:{name}: {_why(x)}')
    out.extend(term(expr, parts) for expr in TERMS)
    return out, skipped


def _why(x: FloatArray | None) -> str:
    if x is None:
        return 'not measured'
    if not np.all(np.isfinite(x)):
        return 'has missing values'
    return 'does not vary enough'


def describe(candidate: Candidate) -> str:
    """
    Describe a candidate in one line for reports.

    Parameters
    ----------
    candidate : Candidate
        The candidate, [-]

    Returns
    -------
    str
        ``label [unit] (source)``.

    """
    return f'{candidate.label} [{candidate.unit}] ({candidate.source})'
