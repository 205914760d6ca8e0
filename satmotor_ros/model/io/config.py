# SPDX-License-Identifier: Apache-2.0
"""
Motor specifications from YAML: geometry, validated range and coefficient sets.

The packaged default is ``config/sm075_25.yaml`` (the SM-0,75/25 for oil and
water). A file names its model family with ``family:`` (default
``sliwinski2017``; see :mod:`.families`): the coefficients are that family's,
and a family other than ``sliwinski2017`` needs only the ``displacement`` of the
geometry. It is found as package data when satmotor_ros is pip-installed and in
``share/satmotor_ros/config`` when it is built by colcon; any user file can be
given by path. Every value is checked on load, and an error names the key
path and the value (``coefficient_sets.oil.coefficients.beta = 2.5 ...``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, TypeVar

from satmotor_ros.bounded_yaml import read_yaml_or
from satmotor_ros.model.coefficients import (CoefficientSet, field_names, FieldError, Liquid,
                                             MotorGeometry, ValidRange)
from satmotor_ros.model.effects import (check_coefficients, check_effects, Effect,
                                        effect_from_mapping)
from satmotor_ros.model.errors import ConfigError, UnitError
from satmotor_ros.model.families import DEFAULT_FAMILY, Family, family_named
from satmotor_ros.model.families.sliwinski2017.losses import compressibility_coefficient
from satmotor_ros.model.units import parse_quantity

_T = TypeVar('_T')

DEFAULT_MOTOR = 'sm075_25.yaml'
"""File name of the packaged SM-0,75/25 specification."""

_GEOMETRY_KINDS = {
    'displacement': ('displacement', 'm^3/rad'), 'module': ('length', 'm'),
    'height': ('length', 'm'), 'clearance_rotor': ('length', 'm'),
    'clearance_satellites': ('length', 'm'), 'commutation_diameter': ('length', 'm'),
}
_RANGE_KINDS = {'dp_max': ('pressure', 'Pa'), 'speed_max': ('speed', 'rad/s'),
                'dp_min': ('pressure', 'Pa'), 'speed_min': ('speed', 'rad/s')}
_LIQUID_KINDS = {
    'kinematic_viscosity': ('viscosity', 'm^2/s'), 'density': ('density', 'kg/m^3'),
    'bulk_modulus': ('pressure', 'Pa'),
}
_COEFFICIENT_KINDS = {'external_leakage': ('leakage_coefficient', 'm^3/(s*Pa)')}


@dataclass(frozen=True)
class MotorSpec:
    """A motor: its geometry, its validated range and its coefficient sets by liquid."""

    name: str
    geometry: MotorGeometry
    valid_range: ValidRange
    sets: Mapping[str, CoefficientSet]
    source: str  # file the spec was read from
    family: str = DEFAULT_FAMILY  # the model family of the sets' coefficients


def default_config_path(name: str = DEFAULT_MOTOR) -> Path:
    """
    Locate a packaged configuration file.

    Parameters
    ----------
    name : str
        File name inside the package's ``config`` directory, [-]

    Returns
    -------
    pathlib.Path
        Path to the file: package data first, then the colcon share directory,
        then the source tree.

    Raises
    ------
    ConfigError
        If no copy of the file can be found.

    """
    candidates = []
    try:
        candidates.append(Path(str(resources.files('satmotor_ros.config') / name)))
    except ModuleNotFoundError:
        pass
    try:
        from ament_index_python.packages import (get_package_share_directory,
                                                 PackageNotFoundError)
        try:
            candidates.append(Path(get_package_share_directory('satmotor_ros')) / 'config' / name)
        except (PackageNotFoundError, OSError):  # OSError: AMENT_PREFIX_PATH not set
            pass
    except ImportError:
        pass
    candidates.append(Path(__file__).resolve().parents[3] / 'config' / name)
    for path in candidates:
        if path.is_file():
            return path
    msg = f'packaged config {name!r} not found (looked in: {", ".join(map(str, candidates))})'
    raise ConfigError(msg)


def load_motor(path: str | Path | None = None) -> MotorSpec:
    """
    Load and validate a motor specification.

    Parameters
    ----------
    path : str or pathlib.Path, optional
        YAML file; the packaged SM-0,75/25 when omitted, [-]

    Returns
    -------
    MotorSpec
        The validated specification.

    Raises
    ------
    ConfigError
        If the file is missing or malformed; the message names the key and value.

    Examples
    --------
    >>> spec = load_motor()
    >>> sorted(spec.sets)
    ['oil', 'water']

    """
    file = Path(path) if path is not None else default_config_path()
    doc = read_yaml_or(file, ConfigError, f'cannot read motor config {str(file)!r}',
                       f'motor config {str(file)!r}')
    return motor_from_mapping(doc, source=str(file))


def motor_from_mapping(doc: Any, source: str = '<mapping>') -> MotorSpec:
    """
    Build a validated :class:`MotorSpec` from a parsed YAML document.

    Parameters
    ----------
    doc : Any
        The parsed document, [-]
    source : str
        Where it came from, quoted in errors, [-]

    Returns
    -------
    MotorSpec
        The validated specification.

    """
    doc = _mapping(doc, source, {'motor', 'geometry', 'valid_range', 'coefficient_sets'})
    family = family_named(doc.get('family', DEFAULT_FAMILY), 'family')
    geometry = _geometry(doc['geometry'], family)
    valid_range = _record(ValidRange, doc['valid_range'], 'valid_range', _RANGE_KINDS)
    sets_doc = _mapping(doc['coefficient_sets'], 'coefficient_sets', None)
    if not sets_doc:
        raise ConfigError('coefficient_sets is empty: give at least one liquid')
    sets = {str(name): coefficient_set_from_mapping(entry, str(name), geometry, family)
            for name, entry in sets_doc.items()}
    return MotorSpec(str(doc['motor']), geometry, valid_range, sets, source, family.name)


def _geometry(doc: Any, family: Family) -> MotorGeometry:
    """Read the geometry; a family other than the default needs only the displacement."""
    if family.name == DEFAULT_FAMILY:
        return _record(MotorGeometry, doc, 'geometry', _GEOMETRY_KINDS)
    doc = _mapping(doc, 'geometry', {'displacement'})
    given = _values(doc, 'geometry', field_names(MotorGeometry), _GEOMETRY_KINDS)
    packaged = load_motor().geometry  # the satellite dimensions this family does not use
    s = (given['displacement'] / packaged.displacement) ** (1.0 / 3.0)
    similar = {'module': packaged.module * s, 'height': packaged.height * s,
               'clearance_rotor': packaged.clearance_rotor,
               'clearance_satellites': packaged.clearance_satellites,
               'commutation_diameter': packaged.commutation_diameter * s}
    return _construct(MotorGeometry, 'geometry', **{**similar, **given})


def coefficient_set_from_mapping(doc: Any, name: str, geometry: MotorGeometry,
                                 family: Family | None = None) -> CoefficientSet:
    """
    Build one validated coefficient set (liquid plus coefficients of a family).

    Parameters
    ----------
    doc : Any
        Mapping with ``liquid`` and ``coefficients``, [-]
    name : str
        Name of the set, e.g. ``'oil'``, [-]
    geometry : MotorGeometry
        Geometry the set belongs to (checks the split of C), [-]
    family : Family, optional
        The model family of the coefficients; ``sliwinski2017`` when omitted, [-]

    Returns
    -------
    CoefficientSet
        The validated set.

    """
    family = family if family is not None else family_named(DEFAULT_FAMILY)
    where = f'coefficient_sets.{name}'
    doc = _mapping(doc, where, {'liquid', 'coefficients'})
    unknown = sorted(set(doc) - {'liquid', 'coefficients', 'viscosity_range', 'effects'})
    if unknown:
        msg = (f'{where} has unknown key(s): {", ".join(map(str, unknown))} '
               '(known: liquid, coefficients, viscosity_range, effects)')
        raise ConfigError(msg)
    liquid = liquid_from_mapping(doc['liquid'], f'{where}.liquid', default_name=name)
    span = _viscosity_range(doc.get('viscosity_range'), f'{where}.viscosity_range')
    coef: Any = _record(family.coefficients_type, doc['coefficients'], f'{where}.coefficients',
                        {**_COEFFICIENT_KINDS, **family.quantities})
    if family.name != DEFAULT_FAMILY:
        effects = check_effects(_effects(doc.get('effects'), f'{where}.effects', coef),
                                f'{where}.effects', family.name)
        return _construct(CoefficientSet, where, name=name, liquid=liquid, coefficients=coef,
                          viscosity_range=span, effects=effects)
    c_fc = compressibility_coefficient(liquid.bulk_modulus, geometry, coef)
    if c_fc > coef.c:
        msg = (f'{where}.coefficients.compressed_volume_fraction = '
               f'{coef.compressed_volume_fraction!r} gives C_fc*beta_l = {c_fc:.4g} > '
               f'c = {coef.c!r}: the compressibility share cannot exceed the lumped C')
        raise ConfigError(msg)
    effects = _effects(doc.get('effects'), f'{where}.effects', coef)
    return _construct(CoefficientSet, where, name=name, liquid=liquid, coefficients=coef,
                      viscosity_range=span, effects=effects)


def _effects(doc: Any, where: str, coef: Any) -> tuple[Effect, ...]:
    if not doc:
        return ()
    effects = tuple(effect_from_mapping(name, block, where)
                    for name, block in _mapping(doc, where, None).items())
    check_effects(effects, where)
    check_coefficients(effects, coef, where)
    return effects


def _viscosity_range(doc: Any, where: str) -> tuple[float, float] | None:
    if doc is None:
        return None
    if not isinstance(doc, (list, tuple)) or len(doc) != 2:
        msg = f'{where} = {doc!r}: expected [low, high]'
        raise ConfigError(msg)
    low, high = (_number(v, f'{where}[{i}]', _LIQUID_KINDS['kinematic_viscosity'])
                 for i, v in enumerate(doc))
    return low, high


def liquid_from_mapping(doc: Any, where: str = 'liquid', default_name: str = 'liquid') -> Liquid:
    """
    Build a validated :class:`Liquid` from a mapping.

    Parameters
    ----------
    doc : Any
        Mapping with ``kinematic_viscosity``, ``density``, ``bulk_modulus`` and
        optionally ``name``, [-]
    where : str
        Key path quoted in errors, [-]
    default_name : str
        Name used when the mapping gives none, [-]

    Returns
    -------
    Liquid
        The validated liquid.

    """
    doc = dict(_mapping(doc, where, None))
    name = str(doc.pop('name', default_name))
    values = _values(doc, where, field_names(Liquid)[1:], _LIQUID_KINDS)
    return _construct(Liquid, where, name=name, **values)


def _mapping(doc: Any, where: str, required: set[str] | None) -> Mapping[str, Any]:
    if not isinstance(doc, Mapping):
        msg = f'{where} must be a mapping, got {type(doc).__name__}: {doc!r}'
        raise ConfigError(msg)
    if required is not None:
        missing = sorted(required - set(doc))
        if missing:
            msg = f'{where} is missing key(s): {", ".join(missing)}'
            raise ConfigError(msg)
    return doc


def _record(record: type[_T], doc: Any, where: str,
            kinds: Mapping[str, tuple[str, str]]) -> _T:
    doc = _mapping(doc, where, None)
    names = field_names(record)
    return _construct(record, where, **_values(doc, where, names, kinds))


def _values(doc: Mapping[str, Any], where: str, names: tuple[str, ...],
            kinds: Mapping[str, tuple[str, str]]) -> dict[str, float]:
    unknown = sorted(set(doc) - set(names))
    if unknown:
        msg = (f'{where} has unknown key(s): {", ".join(map(str, unknown))} '
               f'(known: {", ".join(names)})')
        raise ConfigError(msg)
    return {key: _number(value, f'{where}.{key}', kinds.get(key))
            for key, value in doc.items()}


def _number(value: Any, where: str, kind: tuple[str, str] | None) -> float:
    if isinstance(value, bool):
        msg = f'{where} = {value!r}: expected a number'
        raise ConfigError(msg)
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, str):
        if kind is None:
            try:
                return float(value)
            except ValueError:
                msg = f'{where} = {value!r}: expected a number (this key takes no unit)'
                raise ConfigError(msg) from None
        try:
            return parse_quantity(value, kind[0], kind[1])
        except UnitError as err:
            msg = f'{where} = {value!r}: {err}'
            raise ConfigError(msg) from None
    msg = f'{where} = {value!r}: expected a number, got {type(value).__name__}'
    raise ConfigError(msg)


def _construct(record: type[_T], where: str, **values: Any) -> _T:
    try:
        return record(**values)
    except TypeError as err:
        missing = sorted(set(field_names(record)) - set(values))
        msg = f'{where} is missing key(s): {", ".join(missing)}' if missing else f'{where}: {err}'
        raise ConfigError(msg) from None
    except FieldError as err:
        msg = f'{where}.{err.field} = {err.detail}'
        raise ConfigError(msg) from None
