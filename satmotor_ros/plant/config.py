# SPDX-License-Identifier: Apache-2.0
"""
The plant's parameters as a flat table of dotted names, for nodes, YAML files and the CLI.

``lines.inlet_volume``, ``effects.external_leakage``, ``sensors.flow.noise``: one name
per field of :class:`PlantParams` and its records, plus the node parameters every
effect kind declares (:attr:`~satmotor_ros.model.effects.EffectKind.plant_parameters`).
Description, unit and range come from the records' field metadata and from the kinds,
so the table cannot drift from the validation.
"""

from __future__ import annotations

from collections.abc import Mapping
import dataclasses
import math
from typing import Any, NamedTuple

from satmotor_ros.model.effects import Effect, KINDS, ranked
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.plant.errors import PlantError
from satmotor_ros.plant.params import (CaseParams, FaultParams, LineParams, PlantParams,
                                       ReliefParams, SENSOR_CHANNELS, SensorParams, SensorSet,
                                       ShaftParams, ThermalParams)

GROUPS: dict[str, type] = {
    'lines': LineParams, 'relief': ReliefParams, 'shaft': ShaftParams,
    'thermal': ThermalParams, 'case': CaseParams, 'fault': FaultParams,
}
"""Records of :class:`PlantParams` by their field name (the parameter prefix)."""

CHANNEL_UNITS = {'inlet_pressure': 'Pa', 'outlet_pressure': 'Pa', 'case_pressure': 'Pa',
                 'flow': 'm^3/s', 'speed': 'rad/s', 'temperature': 'degC'}
"""SI unit of each sensed channel (noise and bias are in it)."""

_TOP = ('step', 'pump_lag', 'active_load', 'seed', 'rebuild_tolerance')


class ParameterSpec(NamedTuple):
    """One flat plant parameter."""

    name: str  # dotted name, e.g. 'lines.inlet_volume'
    default: Any  # float, int, bool or str
    description: str
    unit: str
    low: float | None  # closed range, None when not numeric
    high: float | None
    choices: tuple[str, ...] = ()  # allowed strings


def _specs_of(record: type, prefix: str, defaults: Any) -> list[ParameterSpec]:
    specs = []
    for f in dataclasses.fields(record):
        if 'description' not in f.metadata:
            continue
        low, high = f.metadata['range'] or (None, None)
        specs.append(ParameterSpec(prefix + f.name, getattr(defaults, f.name),
                                   f.metadata['description'], f.metadata['unit'], low, high,
                                   f.metadata['choices']))
    return specs


def _effect_specs() -> list[ParameterSpec]:
    return [ParameterSpec(f'effects.{p.name}', p.default, p.description, p.unit, p.low,
                          p.high, p.choices)
            for kind in ranked() for p in kind.plant_parameters]


def parameter_specs() -> tuple[ParameterSpec, ...]:
    """
    List every plant parameter with its default, unit and range.

    Returns
    -------
    tuple of ParameterSpec
        In a stable order: top-level, the records of :data:`GROUPS`, the effects, then
        the sensors.

    """
    defaults = PlantParams()
    specs = [s for s in _specs_of(PlantParams, '', defaults) if s.name in _TOP]
    for group, record in GROUPS.items():
        specs += _specs_of(record, f'{group}.', getattr(defaults, group))
    specs += _effect_specs()
    for channel in SENSOR_CHANNELS:
        for spec in _specs_of(SensorParams, f'sensors.{channel}.',
                              getattr(defaults.sensors, channel)):
            unit = CHANNEL_UNITS[channel] if spec.unit == 'unit of the channel' else spec.unit
            specs.append(spec._replace(unit=unit))
    return tuple(specs)


def _flat_effect(effect: Effect) -> bool:
    """Return whether the node parameters of its kind give exactly this effect."""
    kind = KINDS[effect.kind]
    return bool(kind.plant_parameters) and kind.from_plant(kind.plant_values(effect)) == effect


def flat_from_params(params: PlantParams) -> dict[str, Any]:
    """
    Flatten a :class:`PlantParams` into dotted names.

    Effects no node parameter can express (e.g. a ``term:``) are left out; they
    are kept from the base by :func:`params_from_flat`.

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
    given = {e.kind: e for e in params.effects if _flat_effect(e)}
    for kind in ranked():
        for key, value in kind.plant_values(given.get(kind.name)).items():
            flat[f'effects.{key}'] = value
    for channel in SENSOR_CHANNELS:
        for key, value in dataclasses.asdict(getattr(params.sensors, channel)).items():
            flat[f'sensors.{channel}.{key}'] = value
    return flat


def _check(spec: ParameterSpec, value: Any) -> None:
    if spec.choices:
        if value not in spec.choices:
            msg = f'{spec.name} = {value!r}: use one of {", ".join(spec.choices)}'
            raise PlantError(msg)
        return
    low = -math.inf if spec.low is None else spec.low
    high = math.inf if spec.high is None else spec.high
    if not (isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value) and low <= value <= high):
        msg = f'{spec.name} = {value!r} is outside [{low:g}, {high:g}]'
        raise PlantError(msg)


def _effects(flat: Mapping[str, Any], base: PlantParams) -> tuple[Effect, ...]:
    for spec in _effect_specs():
        _check(spec, flat[spec.name])
    values = {k.removeprefix('effects.'): v for k, v in flat.items() if k.startswith('effects.')}
    kept = tuple(e for e in base.effects if not _flat_effect(e))
    try:
        made = tuple(kind.from_plant(values) for kind in ranked() if kind.plant_parameters)
    except ConfigError as err:
        raise PlantError(str(err)) from None
    return (*kept, *(e for e in made if e is not None))


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
    base = base if base is not None else PlantParams()
    flat = flat_from_params(base)
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
        return PlantParams(**{name: flat[name] for name in _TOP}, sensors=sensors,
                           effects=_effects(flat, base), **groups)
    except TypeError as err:
        raise PlantError(str(err)) from None
