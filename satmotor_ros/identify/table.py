# SPDX-License-Identifier: Apache-2.0
"""Bench tables: CSV with ``name [unit]`` headers read into SI arrays (DESIGN.md)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.textfile import read_cells, SANITY, shorten, split_unit
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.errors import UnitError
from satmotor_ros.model.units import (ATMOSPHERE, gauge, kinds, pressure_reference, RPM, to_si,
                                      units_of)

REQUIRED = ('speed', 'flow', 'p_in', 'p_out')
"""Columns every bench table must have (DESIGN.md, "Bench tables")."""

PORTS = {'p_a': 'p_in', 'p_b': 'p_out'}
"""Port pressures A and B, the alternative to p_in and p_out for signed speed and flow: port A
is the inlet when the flow is positive, so p_a is read as p_in and p_b as p_out."""

KNOWN_KINDS = {'speed': 'speed', 'flow': 'flow', 'p_in': 'pressure', 'p_out': 'pressure',
               'p_a': 'pressure', 'p_b': 'pressure', 'p_case': 'pressure',
               'temperature': 'temperature', 'time': 'time', 'torque': 'torque'}
"""Kind of quantity of the named columns; any other ``p_*`` column is a pressure too."""

IMPOSSIBLE = 'impossible values'
"""How the notes on rows dropped for a physically impossible value begin."""

_FLOORS = {'pressure': (-ATMOSPHERE, 1.0e3, 'kPa', 'a gauge pressure below vacuum'),
           'temperature': (-273.15, 1.0, 'degC', 'a temperature below absolute zero')}
"""Kind -> (least possible SI value, display scale, display unit, what a lower value is)."""

BAD_CELLS = 'bad cells'
"""How the notes on absurd or missing cells begin (rows dropped or cells ignored)."""

_NEGATIVE_LOSS = 0.02
"""Median loss, as a share of q n, below which most rows' negative losses are named: a
sensor gain of a per cent is an effect calibrate finds, not a wrong setup, [-]."""

_RESTART_SHARE = 0.01
"""Most share of time steps that may go backwards for the time to be read as restarts (more:
the rows are not in time order, and time is one more channel)."""

_RESTART_JITTER = 10.0
"""A step back of more than this many median time steps is a restart, not a late sample."""

_RESTART_GAP = 1000.0
"""A restarted recording is moved to begin this many median time steps after the one before:
far beyond any gap that cuts a steady window or a transient stretch."""

_CEILINGS = {'pressure': 1.0e9, 'temperature': 1.0e4, 'speed': 1.0e5, 'flow': 10.0,
             'torque': 1.0e7}
"""Kind -> magnitude in SI no bench reaches (1 GPa, 10^4 degC, about 10^6 rpm, 10 m^3/s,
10^7 N m): a cell beyond it is a broken cell or a wrong unit, not a measurement. 1 GPa is
beyond every hydraulic pressure: displacement motors are rated to some 70 MPa, intensifiers
reach 600 MPa, and the pressure transducers of the highest range end near 1 GPa."""

_ABSURD_RATIO = 1.0e6
"""A cell this many times larger in magnitude than 90 % of its column's cells is absurd."""

_MOST_MISSING = 0.1
"""Share of rows a channel may miss and still be tested on the others (its rows dropped)."""

_NOT_CHANNEL_KINDS = ('velocity', 'area')
"""Kinds that only describe a derived flow's inputs (doc/columns.md): a channel in mm/s stays
as given rather than being read as a velocity."""

_EXTRA_UNITS = {('pressure', 'mbar'): 100.0,
                ('temperature', '°C'): 1.0, ('temperature', 'C'): 1.0,
                ('flow', 'm3/s'): 1.0, ('flow', 'm³/s'): 1.0, ('flow', 'l/h'): 1.0e-3 / 3600.0,
                ('speed', '1/min'): RPM, ('speed', 'min^-1'): RPM, ('time', 'h'): 3600.0}
"""Spellings accepted beyond :mod:`satmotor_ros.model.units` (scale to SI)."""


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


@np.errstate(over='ignore', invalid='ignore')  # 1e308 rpm is inf in rad/s: a bad cell, dropped
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
        Values in SI (degC for temperature; a pressure in an absolute unit such as
        psia made gauge); unchanged for a column of no known kind whose unit is not a
        known one.

    Raises
    ------
    DataError
        If a column of known kind has no unit or a unit not of that kind.

    """
    kind = _kind_of(name)
    if kind is None:
        for other in kinds():
            if unit and unit in units_of(other) and other not in _NOT_CHANNEL_KINDS:
                scale, offset = _affine(unit, other)
                return values * scale + offset
        return values
    unit = _known_spelling(kind, unit)
    if kind == 'pressure' and pressure_reference(unit) == 'absolute':
        return gauge(values * _affine(unit, kind)[0])
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
        If a header is malformed, empty or repeated, a required column is missing, or
        both p_in/p_out and p_a/p_b are given.

    """
    columns = []
    for i, cell in enumerate(header):
        name, unit = split_unit(cell)
        if not name or '[' in name or ']' in name:
            msg = f'column {i + 1} header {shorten(cell)!r}: expected "name [unit]"'
            raise DataError(msg)
        columns.append((name.lower() if name.lower() in KNOWN_KINDS else name, unit))
    names = [name for name, _ in columns]
    for name in names:
        if names.count(name) > 1:
            msg = f"column '{shorten(name)}' appears {names.count(name)} times"
            raise DataError(msg)
    ports = [name for name in (*PORTS, *PORTS.values()) if name in names]
    if set(ports) & set(PORTS) and set(ports) & set(PORTS.values()):
        msg = f'columns {", ".join(ports)}: give either p_in, p_out or p_a, p_b, not both'
        raise DataError(msg)
    need = ('speed', 'flow', *(PORTS if set(ports) & set(PORTS) else PORTS.values()))
    missing = [name for name in need if name not in names]
    if missing:
        have = ', '.join(shorten(name) for name in names[:20]) + (', ...' if names[20:] else '')
        msg = (f"missing required column '{missing[0]}' (have: {have}; need "
               'speed, flow and p_in, p_out (or p_a, p_b) with units, e.g. "speed [rpm]"; '
               'a log with other column names is read through --columns, doc/columns.md)')
        raise DataError(msg)
    return columns


def _impossible(si: Mapping[str, FloatArray], labels: Mapping[str, str],
                source: str) -> tuple[np.ndarray, tuple[str, ...]]:
    """
    Flag the rows where a pressure or temperature column holds a physically impossible value.

    Returns the row mask and one note per column naming it; refuses the file (DataError)
    when most rows are impossible, which points at a wrong unit or reference, not at noise.
    """
    n = len(next(iter(si.values())))
    bad = np.zeros(n, dtype=bool)
    notes = []
    worst = ('', 0)
    for name, values in si.items():
        kind = _kind_of(name)
        if kind not in _FLOORS:
            continue
        floor, scale, unit, what = _FLOORS[kind]
        low = values < floor
        count = int(low.sum())
        if not count:
            continue
        label = labels.get(name, name)
        lowest = float(values[low].min()) / scale
        notes.append(f"{IMPOSSIBLE}: column '{label}': dropped {count} rows with {what} "
                     f'(< {floor / scale:.6g} {unit}; lowest {lowest:.4g} {unit})')
        bad |= low
        if count > worst[1]:
            worst = (f"column '{label}': {count} of {n} values are {what} (lowest {lowest:.4g} "
                     f'{unit})', count)
    if 2 * int(bad.sum()) > n:
        msg = (f'{source}: {worst[0]}; most rows are impossible: check the unit and whether '
               'the pressure is gauge or absolute')
        raise DataError(msg)
    return bad, tuple(notes)


def _absurd(values: FloatArray, kind: str | None) -> np.ndarray:
    """Flag the finite cells beyond the kind's ceiling or far beyond the column's own scale."""
    finite = np.isfinite(values)
    magnitude = np.where(finite, np.abs(values), 0.0)
    out = magnitude > _CEILINGS.get(kind or '', np.inf)
    typical = float(np.percentile(magnitude[finite], 90)) if finite.any() else 0.0
    if typical > 0.0:
        out |= magnitude > _ABSURD_RATIO * typical
    return out


def _rows(mask: np.ndarray) -> str:
    """Name the 1-based data rows of `mask`, the first five of them."""
    rows = np.flatnonzero(mask) + 1
    more = f' and {rows.size - 5} more' if rows.size > 5 else ''
    return ', '.join(str(r) for r in rows[:5]) + more


def _bad_cells(si: dict[str, FloatArray], labels: Mapping[str, str],
               time_series: bool) -> tuple[np.ndarray, tuple[str, ...]]:
    """
    Find absurd cells in every column and the rows a channel misses, and say what is done.

    An absurd cell (:func:`_absurd`) of a required column drops its row; one of another
    channel is made missing (NaN) in `si`. In a table of operating points, a channel
    missing in a few rows (at most :data:`_MOST_MISSING` of them) drops those rows, so
    that its effects are tested on the others rather than not at all; missing in more (or
    in a recording), it is kept and its effects are not tested, which the note says.
    Returns the rows to drop and one note per column naming it and the rows.
    """
    n = len(si['speed'])
    drop = np.zeros(n, dtype=bool)
    notes = []
    for name, values in si.items():
        label = labels.get(name, name)
        absurd = _absurd(values, _kind_of(name))
        largest = f' (up to {float(np.abs(values[absurd]).max()):.3g} in SI)' \
            if absurd.any() else ''
        if name in REQUIRED:
            drop |= absurd
        else:
            si[name] = values = np.where(absurd, np.nan, values)
        missing = ~np.isfinite(values)
        if name not in REQUIRED and missing.any():
            what = f'missing{" or absurd" if largest else ""}{largest}'
            if not time_series and missing.sum() <= _MOST_MISSING * n:
                drop |= missing
                notes.append(f"{BAD_CELLS}: column '{label}': dropped {int(missing.sum())} "
                             f'rows where it is {what} (data rows {_rows(missing)}), '
                             'so that its effects are tested on the others')
            else:
                notes.append(f"{BAD_CELLS}: column '{label}': {what} in "
                             f'{int(missing.sum())} of {n} rows (data rows {_rows(missing)}): '
                             'too many to drop, so its effects are not tested')
        elif absurd.any():
            action = 'dropped the rows of' if name in REQUIRED else 'ignored'
            notes.append(f"{BAD_CELLS}: column '{label}': {action} {int(absurd.sum())} absurd "
                         f'values{largest} at data rows {_rows(absurd)}')
    return drop, tuple(notes)


def _restarts(time: FloatArray) -> tuple[FloatArray, tuple[str, ...]]:
    """
    Find where the time starts again (logs joined in one file) and keep the pieces apart.

    Each later piece is shifted to begin :data:`_RESTART_GAP` median steps after the end of
    the one before, so that the rows stay in file order when sorted by time and nothing that
    reads a time series joins two recordings; the note says so.
    """
    finite = np.isfinite(time)
    t = time[finite]
    step = np.diff(t)
    forward = step[step > 0.0]
    typical = float(np.median(forward)) if forward.size else 1.0
    # a timestamp a step or two late is jitter, left to the sort; a restart goes far back
    back = np.flatnonzero(step < -_RESTART_JITTER * typical)
    if back.size == 0 or np.count_nonzero(step < 0.0) > _RESTART_SHARE * step.size:
        return time, ()
    gap = _RESTART_GAP * typical
    shift = np.zeros(t.size)
    for i in back:
        shift[i + 1:] += gap - step[i]  # piece i+1 begins `gap` after piece i ends
    shifted = time.copy()
    shifted[finite] = t + shift
    rows = np.flatnonzero(finite)[back + 1]
    where = '; '.join(f'data row {r + 1}: {t[i]:.6g} s -> {t[i + 1]:.6g} s'
                      for r, i in zip(rows[:5], back[:5]))
    more = f' and {rows.size - 5} more' if rows.size > 5 else ''
    return shifted, (f'{SANITY}: the time restarts {rows.size} time(s) ({where}{more}): '
                     f'read as {rows.size + 1} separate recordings, each later one moved to '
                     f'begin {gap:.6g} s after the one before, so that no steady window or '
                     'transient stretch joins two (two logs in one file?)',)


def table_from_columns(columns: Mapping[str, tuple[str, np.ndarray]], source: str,
                       time_series: bool = False,
                       labels: Mapping[str, str] | None = None) -> BenchTable:
    """
    Build a :class:`BenchTable` from named columns with units.

    Rows with a missing or non-finite value in a required column are dropped
    (and counted in the notes); so are rows with a physically impossible value
    (a gauge pressure below vacuum, -101.325 kPa, or a temperature below
    absolute zero), with a note naming the column, unless they are most rows:
    then the table is refused. Port pressures ``p_a``, ``p_b`` become
    ``p_in``, ``p_out`` (:data:`PORTS`).

    Parameters
    ----------
    columns : mapping of str to (str, ndarray)
        Column name -> (unit as written, values in that unit), [-]
    source : str
        Where the data came from, for messages, [-]
    time_series : bool
        Whether the rows are raw samples in time order, [-]
    labels : mapping of str to str, optional
        Column name -> how messages name it (e.g. the log's own column), [-]

    Returns
    -------
    BenchTable
        The table in SI.

    Raises
    ------
    DataError
        If a required column is missing, a unit is wrong, no row is usable, or
        most rows hold an impossible value.

    """
    parse_header([f'{name} [{unit}]' if unit else name for name, (unit, _) in columns.items()])
    labels = labels or {}
    si = {PORTS.get(name, name): column_to_si(name, unit, np.asarray(values, dtype=float))
          for name, (unit, values) in columns.items()}
    labels = {PORTS.get(name, name): labels.get(name, name) for name in columns}
    restarted: tuple[str, ...] = ()
    if 'time' in si:
        si['time'], restarted = _restarts(si['time'])
    dropped, cells = _bad_cells(si, labels, time_series)
    good = ~dropped
    for name in REQUIRED:
        good &= np.isfinite(si[name])
    if not good.any():
        msg = f'{source}: no row has finite values in all of {", ".join(REQUIRED)}'
        raise DataError(msg)
    notes: tuple[str, ...] = ()
    missing = ~good & ~dropped
    if missing.any():
        notes = (f'dropped {int(missing.sum())} rows with a missing or non-finite value in '
                 f'{", ".join(REQUIRED)}',)
    notes += cells
    bad, flagged = _impossible(si, labels, source)
    good &= ~bad
    units = {PORTS.get(name, name): unit for name, (unit, _) in columns.items()}
    extra = {name: values[good].copy() for name, values in si.items() if name not in REQUIRED}
    speed, flow, p_in, p_out = (si[name][good].copy() for name in REQUIRED)
    return BenchTable(speed, flow, p_in, p_out, extra, units, source, time_series,
                      restarted + notes + flagged)


def read_csv(path: str | Path) -> BenchTable:
    r"""
    Read a bench table (DESIGN.md, "Bench tables").

    Parameters
    ----------
    path : str or pathlib.Path
        CSV file with one header row of ``name [unit]`` cells, separated by
        commas (or semicolons with decimal commas, tabs or blanks); lines
        starting with ``#`` are comments, [-]

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
    text = read_cells(path)
    if text.header is None:
        msg = (f'{str(path)!r} has no header row of "name [unit]" cells (e.g. "speed [rpm]"); '
               'a log with its own columns is read through --columns, doc/columns.md')
        raise DataError(msg)
    columns = parse_header(list(text.header))
    named = {name: (unit, text.data[:, i]) for i, (name, unit) in enumerate(columns)}
    table = table_from_columns(named, str(path))
    return replace(table, notes=text.notes + table.notes)


def negative_losses(table: BenchTable, displacement: float) -> BenchTable:
    """
    Name a displacement that makes most of the table's volumetric losses negative.

    The loss is Q_vl = sign(dp) (Q - q n) (eq. 36 in four quadrants, doc/quadrants.md) and
    is never negative; noise makes some rows so, a wrong displacement or a flow or speed in
    another unit than said makes most of them so.

    Parameters
    ----------
    table : BenchTable
        The data as read, [-]
    displacement : float
        The motor's displacement q, [m^3/rad]

    Returns
    -------
    BenchTable
        `table`, with a note beginning :data:`SANITY` when more than half of the rows that
        turn under a pressure drop have a negative loss and the median loss is below
        -:data:`_NEGATIVE_LOSS` of q n.

    """
    with np.errstate(invalid='ignore', over='ignore', divide='ignore'):
        ideal = np.abs(displacement * table.speed)
        loss = np.sign(table.dp) * (table.flow - displacement * table.speed)
        share = loss / ideal
    rows = np.isfinite(share) & (table.speed != 0.0) & (table.dp != 0.0)
    negative = int((loss[rows] < 0.0).sum())
    if not rows.any() or 2 * negative <= int(rows.sum()) \
            or np.median(share[rows]) >= -_NEGATIVE_LOSS:
        return table
    note = (f'{SANITY}: the displacement {displacement * 2e6 * np.pi:.4g} cm^3/rev makes the '
            f'volumetric loss sign(dp) (Q - q n) negative in {negative} of {int(rows.sum())} '
            f'rows (median {float(np.median(share[rows])):.1%} of q n): the displacement '
            '(--displacement, the motor file), or the unit of the flow or the speed, is wrong')
    return replace(table, notes=table.notes + (note,))


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
    # time in epoch seconds needs 15 digits for its hundredths; 9 rounded it to 10 s
    fmt = ['%.15g' if name == 'time' else '%.9g' for name in columns]
    np.savetxt(path, data, delimiter=',', header=header, comments='', fmt=fmt)
