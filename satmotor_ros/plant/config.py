# SPDX-License-Identifier: Apache-2.0
"""
The plant's parameters as a flat table of dotted names, for nodes, YAML files and the CLI.

``lines.inlet_volume``, ``effects.external_leakage``, ``sensors.flow.noise``: one name
per field of :class:`PlantParams` and its records. Description, unit and range come from
the records themselves (the field comment and the record's ``bounds``), so the table
cannot drift from the validation.
"""

from __future__ import annotations

from collections.abc import Mapping
import dataclasses
import inspect
import re
from typing import Any, NamedTuple

from satmotor_ros.plant.errors import PlantError
from satmotor_ros.plant.params import (CaseParams, EffectParams, LineParams, PlantParams,
                                       ReliefParams, SENSOR_CHANNELS, SensorParams, SensorSet,
                                       ShaftParams, ThermalParams)

GROUPS: dict[str, type] = {
    'lines': LineParams, 'relief': ReliefParams, 'shaft': ShaftParams,
    'thermal': ThermalParams, 'case': CaseParams, 'effects': EffectParams,
}
"""Records of :class:`PlantParams` by their field name (the parameter prefix)."""

CHANNEL_UNITS = {'inlet_pressure': 'Pa', 'outlet_pressure': 'Pa', 'case_pressure': 'Pa',
                 'flow': 'm^3/s', 'speed': 'rad/s', 'temperature': 'degC'}
"""SI unit of each sensed channel (noise and bias are in it)."""

_TOP = ('step', 'pump_lag', 'active_load', 'seed', 'rebuild_tolerance')
_COMMENT = re.compile(r'^\s+(\w+): [^=]+=.*#\s*(.*?)\s*\[([^\]]*)\]\s*$', re.MULTILINE)


class ParameterSpec(NamedTuple):
    """One flat plant parameter."""

    name: str  # dotted name, e.g. 'lines.inlet_volume'
    default: Any  # float, int, bool or str
    description: str
    unit: str
    low: float | None  # closed range, None when not numeric
    high: float | None


def _comments(record: type) -> dict[str, tuple[str, str]]:
    return {m.group(1): (m.group(2), m.group(3))
            for m in _COMMENT.finditer(inspect.getsource(record))}


def _specs_of(record: type, prefix: str, defaults: Any) -> list[ParameterSpec]:
    docs = _comments(record)
    bounds = getattr(record, 'bounds', {})
    specs = []
    for f in dataclasses.fields(record):
        value = getattr(defaults, f.name)
        if dataclasses.is_dataclass(value):
            continue
        text, unit = docs.get(f.name, (f.name, '-'))
        low, high = bounds.get(f.name, (None, None))
        specs.append(ParameterSpec(prefix + f.name, value, text, unit, low, high))
    return specs


def parameter_specs() -> tuple[ParameterSpec, ...]:
    """
    List every plant parameter with its default, unit and range.

    Returns
    -------
    tuple of ParameterSpec
        In a stable order: top-level, the records of :data:`GROUPS`, then the sensors.

    """
    defaults = PlantParams()
    specs = [s for s in _specs_of(PlantParams, '', defaults) if s.name in _TOP]
    for group, record in GROUPS.items():
        specs += _specs_of(record, f'{group}.', getattr(defaults, group))
    for channel in SENSOR_CHANNELS:
        for spec in _specs_of(SensorParams, f'sensors.{channel}.',
                              getattr(defaults.sensors, channel)):
            unit = CHANNEL_UNITS[channel] if spec.unit == 'unit of the channel' else spec.unit
            specs.append(spec._replace(unit=unit))
    return tuple(specs)


def flat_from_params(params: PlantParams) -> dict[str, Any]:
    """
    Flatten a :class:`PlantParams` into dotted names.

    Parameters
    ----------
    params : PlantParams
        The parameters, [-]

    Returns
    -------
    dict
        Dotted name -> value, SI.

    """
    flat: dict[str, Any] = {name: getattr(params, name) for name in _TOP}
    for group in GROUPS:
        for key, value in dataclasses.asdict(getattr(params, group)).items():
            flat[f'{group}.{key}'] = value
    for channel in SENSOR_CHANNELS:
        for key, value in dataclasses.asdict(getattr(params.sensors, channel)).items():
            flat[f'sensors.{channel}.{key}'] = value
    return flat


def params_from_flat(values: Mapping[str, Any], base: PlantParams | None = None) -> PlantParams:
    """
    Build a :class:`PlantParams` from dotted names; the rest from `base`.

    Parameters
    ----------
    values : mapping
        Dotted name -> value, SI, [-]
    base : PlantParams, optional
        Values for the names not given; the defaults when omitted, [-]

    Returns
    -------
    PlantParams
        The validated parameters.

    Raises
    ------
    PlantError
        If a name is unknown or a value is invalid; the message names it.

    """
    flat = flat_from_params(base if base is not None else PlantParams())
    unknown = sorted(set(values) - set(flat))
    if unknown:
        msg = f'unknown plant parameter {unknown[0]!r}'
        raise PlantError(msg)
    flat.update(values)
    try:
        groups = {group: record(**{f.name: flat[f'{group}.{f.name}']
                                   for f in dataclasses.fields(record)})
                  for group, record in GROUPS.items()}
        sensors = SensorSet(**{
            channel: SensorParams(**{f.name: flat[f'sensors.{channel}.{f.name}']
                                     for f in dataclasses.fields(SensorParams)})
            for channel in SENSOR_CHANNELS})
        return PlantParams(**{name: flat[name] for name in _TOP}, sensors=sensors, **groups)
    except TypeError as err:
        raise PlantError(str(err)) from None
