# SPDX-License-Identifier: Apache-2.0
"""
Effects the paper's model lacks, added to a coefficient set as data.

``satmotor calibrate`` writes the effect it found into the ``effects:`` block
of a coefficient set in ``coefficients.yaml``; :func:`effect_from_mapping`
reads it back into an :class:`Effect`, and :mod:`.conditioned` evaluates it
with the measured channels the effect needs. The kinds (DESIGN.md vocabulary):

=========================  ============================================================
``external_leakage``       Q_ex = k_ex p (eq. 24), p the gauge pressure named by
                           ``regressor`` (``p_case`` or ``p_out``)
``viscosity_temperature``  nu(T) of a Walther or Vogel law replaces the liquid's
                           viscosity in eqs. (1), (5) and (35)
``clearance_wear``         h_R and h_S grow by k (x - reference) >= 0, x = ``time`` [s]
                           or ``revolutions`` [rev], in eqs. (1), (2) and (5)
``channel:<name>``         extra loss k (x - reference) in Q_vl, x the channel <name>
``term:<expression>``      extra loss k f(n, dp_i) in Q_vl, f one of :data:`TERMS`
``flow_sensor_offset``     the flowmeter reads Q + k
``flow_sensor_gain``       the flowmeter reads (1 + k) Q
``speed_sensor_gain``      the speed sensor reads (1 + k) n
=========================  ============================================================

Sensor effects describe the instruments, not the motor: the model's maps take
the true flow and return the true speed, and :func:`true_flow` and
:func:`true_speed` convert readings.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
import math
from typing import Any

from satmotor_ros.model.errors import ConfigError

TERMS: Mapping[str, tuple[Callable[[Any, Any], Any], str]] = {
    'n^2': (lambda n, dp: n ** 2, 'm^3/s/(rad/s)^2'),
    'n^1.5': (lambda n, dp: n ** 1.5, 'm^3/s/(rad/s)^1.5'),
    'dp^2': (lambda n, dp: dp ** 2, 'm^3/s/Pa^2'),
    'dp^0.5': (lambda n, dp: dp ** 0.5, 'm^3/s/Pa^0.5'),
    'dp^2*n': (lambda n, dp: dp ** 2 * n, 'm^3/s/(Pa^2*rad/s)'),
    'dp*n^2': (lambda n, dp: dp * n ** 2, 'm^3/s/(Pa*(rad/s)^2)'),
    'dp*n^0.5': (lambda n, dp: dp * n ** 0.5, 'm^3/s/(Pa*(rad/s)^0.5)'),
    'dp^0.5*n': (lambda n, dp: dp ** 0.5 * n, 'm^3/s/(Pa^0.5*rad/s)'),
}
"""
Functions of speed n [rad/s] and chamber drop dp = dp_i [Pa] that eqs. (31)-(33) lack.

Left out on purpose, as the model or a named effect already has them: 1
(flowmeter offset), n (sensor gains), n^0.5 (C_id, eq. 14), dp*n (C, eq. 33)
and dp (the leakage of eqs. 1 and 5 is close to linear in dp).
"""

KINDS = ('external_leakage', 'viscosity_temperature', 'clearance_wear', 'channel', 'term',
         'flow_sensor_offset', 'flow_sensor_gain', 'speed_sensor_gain')
"""Kinds of effect; ``channel`` and ``term`` take ``:<name>`` after them."""

SENSOR_KINDS = ('flow_sensor_offset', 'flow_sensor_gain', 'speed_sensor_gain')
"""Kinds that describe an instrument, not the motor."""

_DOCUMENTARY = ('unit', 'ci95', 'source', 'evaluation')
"""Keys written for the reader; the model does not use them."""

_KEYS = {
    'external_leakage': ('regressor', 'coefficient'),
    'viscosity_temperature': ('regressor', 'coefficient', 'law', 'reference_temperature',
                              'reference_viscosity', 'vogel_c'),
    'clearance_wear': ('regressor', 'coefficient', 'reference'),
    'channel': ('regressor', 'coefficient', 'reference'),
    'term': ('regressor', 'coefficient'),
    'flow_sensor_offset': ('regressor', 'coefficient'),
    'flow_sensor_gain': ('regressor', 'coefficient'),
    'speed_sensor_gain': ('regressor', 'coefficient'),
}
_REQUIRED = {
    'viscosity_temperature': ('law', 'reference_temperature', 'reference_viscosity'),
    'clearance_wear': ('regressor', 'reference'),
    'channel': ('reference',),
}
_REGRESSORS = {
    'external_leakage': ('p_case', 'p_out'),
    'viscosity_temperature': ('temperature',),
    'clearance_wear': ('time', 'revolutions'),
}


@dataclass(frozen=True)
class Effect:
    """One effect of a coefficient set, SI (temperature in degC)."""

    name: str  # id as in the YAML: a kind, or 'channel:<name>' / 'term:<expression>'
    coefficient: float  # k, in the unit the kind implies (m^3/(s*Pa), m/s, -, ...)
    regressor: str = ''  # channel or expression the effect reads
    reference: float = 0.0  # x where the effect is zero (wear, channel) [unit of x]
    law: str = ''  # viscosity_temperature: 'walther' or 'vogel'
    reference_temperature: float = math.nan  # where the viscosity is the liquid's [degC]
    reference_viscosity: float = math.nan  # the viscosity there [m^2/s]
    vogel_c: float = 140.0  # Vogel C [K]

    @property
    def kind(self) -> str:
        """Return the kind, without a ``:<name>`` suffix."""
        return self.name.split(':', 1)[0]

    @property
    def channel(self) -> str | None:
        """Return the measured channel the effect reads, or None."""
        if self.kind in ('external_leakage', 'viscosity_temperature', 'clearance_wear',
                         'channel'):
            return self.regressor
        return None


def effect_from_mapping(name: Any, doc: Any, where: str) -> Effect:
    """
    Build one validated :class:`Effect` from its YAML block.

    Parameters
    ----------
    name : Any
        The block's key, e.g. ``'external_leakage'`` or ``'term:dp^2*n'``, [-]
    doc : Any
        The block: ``coefficient`` and what the kind needs, [-]
    where : str
        Key path quoted in errors, [-]

    Returns
    -------
    Effect
        The effect.

    Raises
    ------
    ConfigError
        Naming the key and the value for an unknown kind, key, regressor or law,
        a missing key, or a value that is not a finite number.

    """
    name = str(name)
    kind, _, suffix = name.partition(':')
    where = f'{where}.{name}'
    if kind not in KINDS or (kind in ('channel', 'term')) != bool(suffix):
        msg = (f'{where}: unknown effect {name!r} (known: {", ".join(KINDS[:3])}, '
               f'channel:<name>, term:<expression>, {", ".join(SENSOR_KINDS)})')
        raise ConfigError(msg)
    if not isinstance(doc, Mapping):
        msg = f'{where} must be a mapping, got {type(doc).__name__}: {doc!r}'
        raise ConfigError(msg)
    known = _KEYS[kind]
    unknown = sorted(set(map(str, doc)) - set(known) - set(_DOCUMENTARY))
    missing = [k for k in ('coefficient', *_REQUIRED.get(kind, ())) if k not in doc]
    if unknown or missing:
        what = (f'unknown key(s) {", ".join(unknown)}' if unknown
                else f'missing key(s) {", ".join(missing)}')
        msg = f'{where} has {what} (known: {", ".join(known)})'
        raise ConfigError(msg)
    values = {k: _finite(doc[k], f'{where}.{k}') for k in known
              if k in doc and k not in ('regressor', 'law')}
    regressor = _regressor(kind, suffix, doc.get('regressor'), where)
    law = str(doc.get('law', ''))
    if kind == 'viscosity_temperature' and law not in ('walther', 'vogel'):
        msg = f"{where}.law = {doc.get('law')!r}: use 'walther' or 'vogel'"
        raise ConfigError(msg)
    k = values['coefficient']
    if kind in ('flow_sensor_gain', 'speed_sensor_gain') and not -0.5 < k < 0.5:
        msg = f'{where}.coefficient = {k!r}: a sensor gain error lies in (-0.5, 0.5)'
        raise ConfigError(msg)
    return Effect(name=name, regressor=regressor, law=law, **values)


def _regressor(kind: str, suffix: str, value: Any, where: str) -> str:
    if kind == 'channel':
        if value is not None and str(value) != suffix:
            msg = f'{where}.regressor = {value!r}: a channel effect reads its own channel'
            raise ConfigError(msg)
        return suffix
    if kind == 'term':
        if suffix not in TERMS:
            msg = f'{where}: unknown term {suffix!r} (known: {", ".join(TERMS)})'
            raise ConfigError(msg)
        return suffix
    allowed = _REGRESSORS.get(kind)
    if allowed is None:
        return '' if value is None else str(value)
    value = allowed[0] if value is None else value
    if value not in allowed:
        msg = f'{where}.regressor = {value!r}: use {" or ".join(allowed)}'
        raise ConfigError(msg)
    return str(value)


def _finite(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        msg = f'{where} = {value!r}: expected a finite number'
        raise ConfigError(msg)
    return float(value)


def true_flow(effects: tuple[Effect, ...], reading: Any) -> Any:
    """
    Return the flow through the motor from a flowmeter reading.

    Parameters
    ----------
    effects : tuple of Effect
        The coefficient set's effects, [-]
    reading : float or ndarray
        What the flowmeter reads, [m^3/s]

    Returns
    -------
    float or ndarray
        The flow: ``reading - k`` (offset), ``reading / (1 + k)`` (gain), else the reading, [m^3/s]

    """
    for effect in effects:
        if effect.kind == 'flow_sensor_offset':
            reading = reading - effect.coefficient
        elif effect.kind == 'flow_sensor_gain':
            reading = reading / (1.0 + effect.coefficient)
    return reading


def flow_reading(effects: tuple[Effect, ...], flow: Any) -> Any:
    """
    Return what the flowmeter reads at a flow through the motor.

    Parameters
    ----------
    effects : tuple of Effect
        The coefficient set's effects, [-]
    flow : float or ndarray
        Flow through the motor, [m^3/s]

    Returns
    -------
    float or ndarray
        ``(1 + k) Q`` (gain), ``Q + k`` (offset), else `flow`, [m^3/s]

    """
    for effect in reversed(effects):
        if effect.kind == 'flow_sensor_gain':
            flow = flow * (1.0 + effect.coefficient)
        elif effect.kind == 'flow_sensor_offset':
            flow = flow + effect.coefficient
    return flow


def true_speed(effects: tuple[Effect, ...], reading: Any) -> Any:
    """
    Return the true shaft speed from a speed-sensor reading.

    Parameters
    ----------
    effects : tuple of Effect
        The coefficient set's effects, [-]
    reading : float or ndarray
        What the speed sensor reads, [rad/s]

    Returns
    -------
    float or ndarray
        ``reading / (1 + k)`` with a speed-sensor gain, else the reading, [rad/s]

    """
    for effect in effects:
        if effect.kind == 'speed_sensor_gain':
            reading = reading / (1.0 + effect.coefficient)
    return reading
