# SPDX-License-Identifier: Apache-2.0
"""Bench tables: CSV with ``name [unit]`` headers read into SI arrays (DESIGN.md)."""

from __future__ import annotations

from collections.abc import Mapping
import csv
from dataclasses import dataclass, field
import io
from pathlib import Path
import re

import numpy as np

from satmotor_ros.identify.errors import DataError
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.errors import UnitError
from satmotor_ros.model.units import kinds, RPM, to_si, units_of

REQUIRED = ('speed', 'flow', 'p_in', 'p_out')
"""Columns every bench table must have (DESIGN.md, "Bench tables")."""

KNOWN_KINDS = {'speed': 'speed', 'flow': 'flow', 'p_in': 'pressure', 'p_out': 'pressure',
               'p_case': 'pressure', 'temperature': 'temperature', 'time': 'time',
               'torque': 'torque'}
"""Kind of quantity of the named columns; any other ``p_*`` column is a pressure too."""

_EXTRA_UNITS = {('pressure', 'psi'): 6894.757293168, ('pressure', 'mbar'): 100.0,
                ('temperature', '°C'): 1.0, ('temperature', 'C'): 1.0,
                ('flow', 'm3/s'): 1.0, ('flow', 'm³/s'): 1.0, ('flow', 'l/h'): 1.0e-3 / 3600.0,
                ('speed', '1/min'): RPM, ('speed', 'min^-1'): RPM, ('time', 'h'): 3600.0}
"""Spellings accepted beyond :mod:`satmotor_ros.model.units` (scale to SI)."""

_HEADER = re.compile(r'^\s*([^\[\]]*?)\s*(?:\[\s*([^\[\]]*?)\s*\])?\s*$')


@dataclass(frozen=True)
class BenchTable:
    """
    Operating points (or samples) of a bench test, all SI.

    Temperature is in degC, as sensor_msgs/Temperature defines it. Every
    column beyond the required four is kept in `channels` by its name
    without unit: SI when its unit is known, as given otherwise.
    """

    speed: FloatArray  # shaft speed n [rad/s]
    flow: FloatArray  # flow into the motor Q [m^3/s]
    p_in: FloatArray  # inlet pressure [Pa]
    p_out: FloatArray  # outlet pressure [Pa]
    channels: Mapping[str, FloatArray] = field(default_factory=dict)  # name -> values
    units: Mapping[str, str] = field(default_factory=dict)  # name -> unit as written
    source: str = '<table>'  # file or recording the data came from
    time_series: bool = False  # rows are raw samples in time order
    notes: tuple[str, ...] = ()  # what loading dropped or assumed, for the report

    @property
    def dp(self) -> FloatArray:
        """Pressure drop between the ports p_in - p_out, [Pa]."""
        return self.p_in - self.p_out

    def __len__(self) -> int:
        """Return the number of rows."""
        return int(self.speed.size)

    def select(self, keep: np.ndarray, note: str | None = None) -> BenchTable:
        """
        Return the rows where `keep` is true.

        Parameters
        ----------
        keep : ndarray of bool
            Row mask, [-]
        note : str, optional
            What the selection did, appended to `notes`, [-]

        Returns
        -------
        BenchTable
            A new table with copies of the kept rows.

        """
        notes = self.notes + ((note,) if note else ())
        return BenchTable(self.speed[keep], self.flow[keep], self.p_in[keep], self.p_out[keep],
                          {k: v[keep] for k, v in self.channels.items()}, dict(self.units),
                          self.source, self.time_series, notes)


def _kind_of(name: str) -> str | None:
    if name in KNOWN_KINDS:
        return KNOWN_KINDS[name]
    return 'pressure' if name.startswith('p_') else None


def column_to_si(name: str, unit: str, values: FloatArray) -> FloatArray:
    """
    Convert one column to SI, checking its unit against the column's kind.

    Parameters
    ----------
    name : str
        Column name without unit, [-]
    unit : str
        Unit as written in the header, [-]
    values : ndarray
        Values in `unit`, [unit]

    Returns
    -------
    ndarray
        Values in SI (degC for temperature); unchanged for a column of no known
        kind whose unit is not a known one.

    Raises
    ------
    DataError
        If a column of known kind has no unit or a unit not of that kind.

    """
    kind = _kind_of(name)
    if kind is None:
        for other in kinds():
            if unit and unit in units_of(other):
                scale, offset = _affine(unit, other)
                return values * scale + offset
        return values
    unit = _known_spelling(kind, unit)
    if (kind, unit) in _EXTRA_UNITS:
        return values * _EXTRA_UNITS[(kind, unit)]
    if not unit:
        msg = (f"column '{name}' has no unit: write '{name} [{units_of(kind)[0]}]' "
               f'(accepted: {", ".join(units_of(kind))})')
        raise DataError(msg)
    try:
        scale, offset = _affine(unit, kind)
    except UnitError:
        msg = (f"column '{name} [{unit}]': unknown {kind} unit {unit!r} "
               f'(accepted: {", ".join(units_of(kind))})')
        raise DataError(msg) from None
    return values * scale + offset


def _known_spelling(kind: str, unit: str) -> str:
    """Return the accepted spelling of `unit` if it differs only in case (RPM, MPA)."""
    known = (*units_of(kind), *(u for k, u in _EXTRA_UNITS if k == kind))
    if unit in known:
        return unit
    folded = [u for u in known if u.lower() == unit.lower()]
    return folded[0] if len(folded) == 1 else unit


def _affine(unit: str, kind: str) -> tuple[float, float]:
    offset = to_si(0.0, unit, kind)
    return to_si(1.0, unit, kind) - offset, offset


def parse_header(header: list[str]) -> list[tuple[str, str]]:
    """
    Split ``name [unit]`` headers into names and units.

    Parameters
    ----------
    header : list of str
        The header cells, [-]

    Returns
    -------
    list of (str, str)
        Name and unit ('' when none) per column.

    Raises
    ------
    DataError
        If a header is malformed, empty or repeated, or a required column is missing.

    """
    columns = []
    for i, cell in enumerate(header):
        match = _HEADER.match(cell)
        if match is None or not match.group(1):
            msg = f'column {i + 1} header {cell!r}: expected "name [unit]"'
            raise DataError(msg)
        name = match.group(1)
        columns.append((name.lower() if name.lower() in KNOWN_KINDS else name,
                        match.group(2) or ''))
    names = [name for name, _ in columns]
    for name in names:
        if names.count(name) > 1:
            msg = f"column '{name}' appears {names.count(name)} times"
            raise DataError(msg)
    missing = [name for name in REQUIRED if name not in names]
    if missing:
        msg = (f"missing required column '{missing[0]}' (have: {', '.join(names)}; need "
               f'{", ".join(REQUIRED)} with units, e.g. "speed [rpm]")')
        raise DataError(msg)
    return columns


def _numbers(rows: list[list[str]], columns: list[tuple[str, str]]) -> np.ndarray:
    data = np.full((len(rows), len(columns)), np.nan)
    for r, row in enumerate(rows):
        if len(row) != len(columns):
            msg = f'row {r + 2}: {len(row)} cells, header has {len(columns)}'
            raise DataError(msg)
        for c, cell in enumerate(row):
            text = cell.strip()
            if not text or text.lower() in ('nan', 'na'):
                continue
            try:
                data[r, c] = float(text)
            except ValueError:
                msg = f"column '{columns[c][0]}' row {r + 2}: {text!r} is not a number"
                raise DataError(msg) from None
    return data


def table_from_columns(columns: Mapping[str, tuple[str, np.ndarray]], source: str,
                       time_series: bool = False) -> BenchTable:
    """
    Build a :class:`BenchTable` from named columns with units.

    Rows with a missing or non-finite value in a required column are dropped
    (and counted in the notes).

    Parameters
    ----------
    columns : mapping of str to (str, ndarray)
        Column name -> (unit as written, values in that unit), [-]
    source : str
        Where the data came from, for messages, [-]
    time_series : bool
        Whether the rows are raw samples in time order, [-]

    Returns
    -------
    BenchTable
        The table in SI.

    Raises
    ------
    DataError
        If a required column is missing, a unit is wrong, or no row is usable.

    """
    parse_header([f'{name} [{unit}]' if unit else name for name, (unit, _) in columns.items()])
    si = {name: column_to_si(name, unit, np.asarray(values, dtype=float))
          for name, (unit, values) in columns.items()}
    good = np.ones(len(si['speed']), dtype=bool)
    for name in REQUIRED:
        good &= np.isfinite(si[name])
    notes: tuple[str, ...] = ()
    if not good.any():
        msg = f'{source}: no row has finite values in all of {", ".join(REQUIRED)}'
        raise DataError(msg)
    if not good.all():
        notes = (f'dropped {int((~good).sum())} rows with a missing or non-finite value in '
                 f'{", ".join(REQUIRED)}',)
    units = {name: unit for name, (unit, _) in columns.items()}
    extra = {name: values[good].copy() for name, values in si.items() if name not in REQUIRED}
    speed, flow, p_in, p_out = (si[name][good].copy() for name in REQUIRED)
    return BenchTable(speed, flow, p_in, p_out, extra, units, source, time_series, notes)


def read_csv(path: str | Path) -> BenchTable:
    r"""
    Read a bench table (DESIGN.md, "Bench tables").

    Parameters
    ----------
    path : str or pathlib.Path
        CSV file with one header row of ``name [unit]`` cells, separated by
        commas (or semicolons with decimal commas, or tabs), [-]

    Returns
    -------
    BenchTable
        The table in SI; every extra column kept in ``channels``.

    Raises
    ------
    DataError
        One line naming the column (or row) that cannot be read.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / 't.csv'
    >>> _ = f.write_text('speed [rpm],flow [l/min],p_in [MPa],p_out [bar]\n600,20,10,5\n')
    >>> t = read_csv(f)
    >>> round(float(t.dp[0]) / 1e6, 2)
    9.5

    """
    file = Path(path)
    try:
        text = file.read_text(encoding='utf-8-sig')
    except OSError as err:
        msg = f'cannot read {str(file)!r}: {err.strerror}'
        raise DataError(msg) from None
    except UnicodeDecodeError:
        msg = f'{str(file)!r} is not a UTF-8 text file'
        raise DataError(msg) from None
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith('#')]
    if not lines:
        msg = f'{str(file)!r} is empty: expected a header row and data rows'
        raise DataError(msg)
    delimiter = ','
    for other in (';', '\t'):
        if other in lines[0] and ',' not in lines[0]:
            delimiter = other
    body = lines[1:]
    if delimiter == ';':  # a European CSV: decimal commas
        body = [line.replace(',', '.') for line in body]
    columns = parse_header(next(csv.reader([lines[0]], delimiter=delimiter)))
    try:
        data = np.loadtxt(io.StringIO('\n'.join(body)), delimiter=delimiter, ndmin=2)
    except ValueError:
        data = _numbers(list(csv.reader(body, delimiter=delimiter)), columns)
    if data.shape[0] == 0:
        msg = f'{str(file)!r} has a header but no data rows'
        raise DataError(msg)
    if data.shape[1] != len(columns):
        msg = f'{str(file)!r}: rows have {data.shape[1]} cells, the header has {len(columns)}'
        raise DataError(msg)
    named = {name: (unit, data[:, i]) for i, (name, unit) in enumerate(columns)}
    return table_from_columns(named, str(file))


def write_csv(path: str | Path, columns: Mapping[str, tuple[str, np.ndarray]]) -> None:
    """
    Write a bench table with ``name [unit]`` headers.

    Parameters
    ----------
    path : str or pathlib.Path
        File to write, [-]
    columns : mapping of str to (str, ndarray)
        Column name -> (unit, values already in that unit), [-]

    """
    header = ','.join(f'{name} [{unit}]' for name, (unit, _) in columns.items())
    data = np.column_stack([np.asarray(v, dtype=float) for _, v in columns.values()])
    np.savetxt(path, data, delimiter=',', header=header, comments='', fmt='%.9g')
