# SPDX-License-Identifier: Apache-2.0
"""
A user's own log read through a column mapping: which column is which quantity, in which unit.

The mapping is a small YAML file (doc/columns.md): how the file is laid out, and for each bench
field (time, speed, flow, p_in/p_out or p_a/p_b, temperature, p_case, torque) and each extra
channel the log's column and its unit. A flow may be a cylinder's piston speed times its area;
any speed, flow or torque may have its sign turned. Nothing in it is evaluated as code.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from satmotor_ros.bounded_yaml import read_yaml_or, shown
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.table import BenchTable, column_to_si, KNOWN_KINDS, table_from_columns
from satmotor_ros.identify.textfile import HEADERS, read_cells, SANITY, SEPARATORS, split_unit
from satmotor_ros.limits import CSV_MAX_COLUMNS
from satmotor_ros.model.errors import ConfigError, UnitError
from satmotor_ros.model.io.config import default_config_path
from satmotor_ros.model.units import gauge, parse_quantity, pressure_reference, to_si, units_of

FIELDS = ('time', 'speed', 'flow', 'p_in', 'p_out', 'p_a', 'p_b', 'temperature', 'p_case',
          'torque')
"""Bench fields a mapping may fill (DESIGN.md, "Bench tables")."""

SI_UNITS = {'time': 's', 'speed': 'rad/s', 'flow': 'm^3/s', 'pressure': 'Pa',
            'temperature': 'degC', 'torque': 'N*m'}
"""The unit each kind of field is handed on in."""

_SIGNED = ('speed', 'flow', 'torque')
_KEYS = ('column', 'unit', 'area', 'sign', 'reference', 'optional')
_TOP = ('file', 'columns', 'channels', 'other_columns')
_FILE = {'separator': 'auto', 'comment': '#', 'header': 'auto'}
SUFFIX = '.columns.yaml'
"""Packaged mappings are ``config/<name>.columns.yaml``; ``--columns <name>`` finds them."""


@dataclass(frozen=True)
class Source:
    """Where one bench field or channel comes from and how it becomes SI."""

    column: str | int  # header name (with or without its unit) or 1-based column number
    unit: str = ''  # unit of the column; '' takes the unit in the header
    area: float = 0.0  # piston area for a flow from a piston speed [m^2]; 0 when none
    sign: float = 1.0  # +1 or -1 [-]
    reference: str = ''  # 'gauge' or 'absolute' for a pressure; '' takes the unit's or gauge
    optional: bool = False  # a channel the log may lack (skipped with a note)


@dataclass(frozen=True)
class ColumnMapping:
    """A log's layout and the source of each field (doc/columns.md)."""

    fields: Mapping[str, Source]  # bench field -> source
    channels: Mapping[str, Source] = field(default_factory=dict)  # extra channel -> source
    separator: str = 'auto'  # one of textfile.SEPARATORS, or 'auto'
    comment: str = '#'  # comment line prefix; '' for none
    header: str = 'auto'  # one of textfile.HEADERS
    keep_others: bool = False  # also keep every unmapped column as a channel
    source: str = '<mapping>'  # the mapping file, for messages


def _fail(where: str, text: str) -> DataError:
    return DataError(f'{where}: {text}')


def _source(doc: Any, where: str, name: str) -> Source:
    if isinstance(doc, (str, int)) and not isinstance(doc, bool):
        doc = {'column': doc}
    if not isinstance(doc, Mapping):
        raise _fail(where, 'expected a column name or {column: ..., unit: ...}, got '
                    f'{shown(doc)}')
    unknown = [k for k in doc if k not in _KEYS]
    if unknown:
        raise _fail(where, f'unknown key {unknown[0]!r} (known: {", ".join(_KEYS)})')
    column = doc.get('column')
    if isinstance(column, bool) or not isinstance(column, (str, int)) or column == '':
        raise _fail(f'{where}.column', f'expected a column name or number, got {shown(column)}')
    if isinstance(column, int) and column < 1:
        raise _fail(f'{where}.column', f'column numbers start at 1, got {column}')
    unit = str(doc.get('unit', '') or '')
    area = 0.0
    if 'area' in doc:
        if name != 'flow':
            raise _fail(f'{where}.area', 'only a flow is a piston speed times an area')
        try:
            area = parse_quantity(str(doc['area']), 'area', 'm^2')
        except UnitError as err:
            raise _fail(f'{where}.area', str(err)) from None
        if not area > 0.0:
            raise _fail(f'{where}.area', f'{shown(doc["area"])} must be > 0')
    sign = doc.get('sign', 1)
    if sign not in (1, -1) or isinstance(sign, bool):
        raise _fail(f'{where}.sign', f'{shown(sign)}: use 1 or -1')
    if sign == -1 and name not in _SIGNED:
        raise _fail(f'{where}.sign', f'only {", ".join(_SIGNED)} may have their sign turned')
    reference = str(doc.get('reference', '') or '')
    if reference and (reference not in ('gauge', 'absolute') or _kind(name) != 'pressure'):
        raise _fail(f'{where}.reference', f'{shown(reference)}: a pressure is gauge or absolute')
    implied = pressure_reference(unit) if unit else None
    if reference and implied and implied != reference:
        raise _fail(f'{where}.reference', f'{reference} contradicts the unit {unit!r}')
    optional = doc.get('optional', False)
    if not isinstance(optional, bool):
        raise _fail(f'{where}.optional', f'{shown(optional)}: use true or false')
    return Source(column, unit, area, float(sign), reference, optional)


def _kind(name: str) -> str | None:
    if name in KNOWN_KINDS:
        return KNOWN_KINDS[name]
    return 'pressure' if name.startswith('p_') else None


def _section(doc: Mapping[str, Any], key: str, where: str) -> Mapping[str, Any]:
    value = doc.get(key) or {}
    if not isinstance(value, Mapping):
        raise _fail(f'{where}: {key}', f'expected a mapping, got {shown(value)}')
    return value


def mapping_from_dict(doc: Any, where: str = '<mapping>') -> ColumnMapping:
    """
    Check a parsed mapping and build a :class:`ColumnMapping`.

    Parameters
    ----------
    doc : dict
        The parsed YAML, [-]
    where : str
        The file, for messages, [-]

    Returns
    -------
    ColumnMapping
        The mapping.

    Raises
    ------
    DataError
        One line naming the mapping key and the value that is wrong.

    """
    if not isinstance(doc, Mapping):
        raise _fail(where, 'expected a mapping with columns: (doc/columns.md)')
    unknown = [k for k in doc if k not in _TOP]
    if unknown:
        raise _fail(where, f'unknown key {unknown[0]!r} (known: {", ".join(_TOP)})')
    layout = {**_FILE, **_section(doc, 'file', where)}
    for key in layout:
        if key not in _FILE:
            raise _fail(f'{where}: file', f'unknown key {key!r} (known: {", ".join(_FILE)})')
    if layout['separator'] not in ('auto', *SEPARATORS):
        raise _fail(f'{where}: file.separator',
                    f'{shown(layout["separator"])}: use auto, {", ".join(SEPARATORS)}')
    if layout['header'] not in HEADERS:
        raise _fail(f'{where}: file.header',
                    f'{shown(layout["header"])}: use {", ".join(HEADERS)}')
    columns = _section(doc, 'columns', where)
    for name in columns:
        if name not in FIELDS:
            raise _fail(f'{where}: columns', f'unknown field {name!r} (fields: '
                        f'{", ".join(FIELDS)}; other quantities go under channels:)')
    fields = {name: _source(value, f'{where}: columns.{name}', name)
              for name, value in columns.items()}
    optional = [name for name, source in fields.items() if source.optional]
    if optional:
        raise _fail(f'{where}: columns.{optional[0]}.optional', 'only channels are optional')
    named = _section(doc, 'channels', where)
    if len(named) > CSV_MAX_COLUMNS:
        raise _fail(f'{where}: channels', f'{len(named)} channels, more than the '
                    f'{CSV_MAX_COLUMNS} columns a log may have (the cap SATMOTOR_CSV_MAX_COLUMNS; '
                    'doc/outputs.md)')
    channels = {str(name): _source(value, f'{where}: channels.{name}', str(name))
                for name, value in named.items()}
    clash = [name for name in channels if name in FIELDS]
    if clash:
        raise _fail(f'{where}: channels.{clash[0]}', 'is a bench field: put it under columns:')
    others = doc.get('other_columns', 'drop')
    if others not in ('drop', 'keep'):
        raise _fail(f'{where}: other_columns', f'{shown(others)}: use drop or keep')
    return ColumnMapping(fields, channels, str(layout['separator']), str(layout['comment'] or ''),
                         str(layout['header']), others == 'keep', where)


def load_mapping(name: str | Path) -> ColumnMapping:
    """
    Load a column mapping from a file, or a packaged one by name.

    Parameters
    ----------
    name : str or pathlib.Path
        A YAML file, or the name of a packaged mapping (``mbari_pto`` is
        ``config/mbari_pto.columns.yaml``), [-]

    Returns
    -------
    ColumnMapping
        The mapping.

    Raises
    ------
    DataError
        If the file is missing, not YAML, or not a valid mapping.

    """
    path = Path(name)
    if not (path.exists() or path.is_symlink()) and '/' not in str(name) \
            and not str(name).endswith('.yaml'):
        try:
            path = default_config_path(f'{name}{SUFFIX}')
        except ConfigError:
            msg = f'--columns {str(name)!r}: no such file and no packaged mapping of that name'
            raise DataError(msg) from None
    doc = read_yaml_or(path, DataError, f'--columns {str(name)!r}', str(path))
    # a packaged mapping by its name: its installed path is of this machine, not of the data
    return mapping_from_dict(doc, str(path) if path == Path(name) else f'{name} (packaged)')


def _locate(source: Source, header: tuple[str, ...] | None, width: int,
            where: str) -> tuple[int, str]:
    """Return the column index and the unit the header gives it."""
    if isinstance(source.column, int):
        if source.column > width:
            raise _fail(where, f'column {source.column}: the log has {width} columns')
        index = source.column - 1
        return index, split_unit(header[index])[1] if header else ''
    if header is None:
        raise _fail(where, f'column {source.column!r}: the log has no header; give the column '
                           'by number')
    wanted = source.column.strip()
    for match in (lambda c: c.strip() == wanted, lambda c: split_unit(c)[0] == wanted,
                  lambda c: split_unit(c)[0].lower() == wanted.lower()):
        hits = [i for i, cell in enumerate(header) if match(cell)]
        if len(hits) == 1:
            return hits[0], split_unit(header[hits[0]])[1]
        if len(hits) > 1:
            raise _fail(where, f'column {wanted!r} matches {len(hits)} header cells')
    names = ', '.join(split_unit(c)[0] for c in header)
    raise _fail(where, f'no column {wanted!r} in the log (has: {names})')


def _to_si(values: np.ndarray, source: Source, name: str, unit: str, where: str) -> np.ndarray:
    """Convert one mapped column of known kind to SI (pressures gauge), sign and area applied."""
    kind = 'velocity' if source.area else _kind(name) or ''
    if not unit:
        raise _fail(where, f'column {source.column!r} has no unit in the header: give unit: '
                           f'(accepted: {", ".join(units_of(kind))})')
    if source.area:
        spelled = next((u for u in units_of(kind) if u.lower() == unit.lower()), unit)
        try:
            si = values * to_si(1.0, spelled, kind)
        except UnitError:
            raise _fail(where, f'unit {unit!r} is not a piston speed unit (accepted: '
                               f'{", ".join(units_of(kind))})') from None
        return si * source.area * source.sign
    try:
        si = column_to_si(name, unit, values)
    except DataError:
        raise _fail(where, f'unit {unit!r} is not a {kind} unit (accepted: '
                           f'{", ".join(units_of(kind))})') from None
    if source.reference == 'absolute' and pressure_reference(unit) is None:
        si = gauge(si)
    return si * source.sign


def _describe(name: str, source: Source, label: str, unit: str) -> str:
    text = f'{name} = {"-" if source.sign < 0 else ""}{label} [{unit}]'
    if source.area:
        text += f' x {source.area:.6g} m^2'
    if source.reference == 'absolute' or pressure_reference(unit) == 'absolute':
        text += ' - 1 atm'
    return text


def read_log(path: str | Path, mapping: ColumnMapping) -> BenchTable:
    """
    Read a user's log through a column mapping into a bench table.

    Parameters
    ----------
    path : str or pathlib.Path
        The log, [-]
    mapping : ColumnMapping
        Its layout and column sources, [-]

    Returns
    -------
    BenchTable
        The table in SI, pressures gauge; mapped channels (and, with
        ``other_columns: keep``, every other column) in ``channels``; a note
        says how each field was read.

    Raises
    ------
    DataError
        One line naming the mapping field, the log's column and the value that cannot be read.

    """
    text = read_cells(path, mapping.separator, mapping.comment, mapping.header)
    columns: dict[str, tuple[str, np.ndarray]] = {}
    labels: dict[str, str] = {}
    used: dict[int, str] = {}
    described: list[str] = []
    skipped: list[str] = []
    for section, sources in (('columns', mapping.fields), ('channels', mapping.channels)):
        for name, source in sources.items():
            where = f'{mapping.source}: {section}.{name}'
            try:
                index, header_unit = _locate(source, text.header, text.data.shape[1], where)
            except DataError as err:
                if not source.optional:
                    raise
                skipped.append(f'{SANITY}: {section}.{name} (optional) is absent, its effects '
                               f'are not tested: {str(err).removeprefix(where + ": ")}')
                continue
            label = split_unit(text.header[index])[0] if text.header else f'column {index + 1}'
            if index in used:
                raise _fail(where, f'column {label!r} is already {used[index]}: one column is '
                                   'one quantity')
            unit = _unit(source, name, header_unit, label, where)
            values = text.data[:, index]
            kind = _kind(name)
            if kind is not None:
                columns[name] = (SI_UNITS[kind], _to_si(values, source, name, unit, where))
            else:
                columns[name] = (unit, values * source.sign)
            labels[name] = f'{name} ({label})'
            used[index] = f'{section}.{name}'
            described.append(_describe(name, source, label, unit))
    if mapping.keep_others and text.header:
        for index, cell in enumerate(text.header):
            name, unit = split_unit(cell)
            if index not in used and name not in columns:
                columns[name] = (unit, text.data[:, index])
    note = f'columns mapped by {mapping.source}: {"; ".join(described)}'
    table = table_from_columns(columns, str(path), labels=labels)
    return replace(table, notes=(note, *skipped, *text.notes, *table.notes))


def _unit(source: Source, name: str, header_unit: str, label: str, where: str) -> str:
    """
    Return the unit a mapped column is read in: the mapping's, else the header's.

    A mapping's unit of the field's kind that the header contradicts (another scale, or gauge
    against absolute), or a ``reference:`` the header's unit contradicts, is refused: one of
    the two is wrong and the data cannot say which.
    """
    kind = _kind(name)
    if kind is None or source.area:
        return source.unit or header_unit
    header_is_kind = bool(header_unit) and _is_unit(header_unit, name)
    header_is_kind = header_is_kind and bool(source.unit) and _is_unit(source.unit, name)
    if header_is_kind and not _same_unit(source.unit, header_unit, name, kind):
        raise _fail(f'{where}.unit', f"{source.unit!r} contradicts the unit of the log's "
                    f'column {label!r} ({header_unit}); give the unit the data are in')
    unit = source.unit or header_unit
    if header_is_kind and kind == 'pressure' \
            and pressure_reference(source.unit) is None:
        unit = header_unit  # psi over psia: the header says more (gauge or absolute)
    implied = pressure_reference(unit) if kind == 'pressure' and unit else None
    if source.reference and implied and implied != source.reference:
        raise _fail(f'{where}.reference', f'{source.reference} contradicts the unit '
                    f"{unit!r} of the log's column {label!r}")
    return unit


def _is_unit(unit: str, name: str) -> bool:
    try:
        column_to_si(name, unit, np.zeros(1))
    except DataError:
        return False
    return True


def _same_unit(a: str, b: str, name: str, kind: str) -> bool:
    """Whether two spellings give the same SI values and do not disagree on gauge/absolute."""
    probe = np.array([0.0, 1.0])
    if kind == 'pressure' and None not in (pressure_reference(a), pressure_reference(b)):
        return pressure_reference(a) == pressure_reference(b) \
            and np.allclose(column_to_si(name, a, probe), column_to_si(name, b, probe))
    scale = [column_to_si(name, u, probe) for u in (a, b)]
    if kind == 'pressure':  # psi and psig, bar and barg: the same scale, one says gauge
        scale = [x - x[0] for x in scale]
    return bool(np.allclose(scale[0], scale[1], rtol=1e-9, atol=0.0))


__all__ = ['ColumnMapping', 'FIELDS', 'Source', 'load_mapping', 'mapping_from_dict', 'read_log']
