# SPDX-License-Identifier: Apache-2.0
"""
Find a fleet's recordings under ROOT, name their motor and order them in time.

A recording is a rosbag2 directory (one with ``metadata.yaml`` or a storage file; not
entered), a bench CSV, or, for a motor whose fleet.yaml entry gives ``columns``, any other
text log. Its motor is the first fleet.yaml pattern that matches it (or a parent directory), else
the first directory level under ROOT. Its time is the bag's start time, else the first
value of a ``time`` column when it holds epoch seconds (a log's read through its motor's
column mapping), else a date (and time) in its path below ROOT, else -- said as such -- the
file's modification time. Only what these need is read here (a bag's metadata, a CSV's first
two lines, a log's first 64 kB), nothing more of the data.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime, timezone
import hashlib
import os
from pathlib import Path
import re
from typing import Any

from satmotor_ros.bounded_yaml import read_yaml, YamlLimitError
from satmotor_ros.fleet.config import FLEET_FILE, FleetConfig, MotorRule, RESERVED

BAG_START = 'bag start time'
TIME_COLUMN = 'time column (epoch s)'
PATH_DATE = 'date in the path'
MTIME = 'file modification time (no time in the data or the path)'
"""How a recording's time was found, in the order they are tried (as the report says it)."""

LOG_SUFFIXES = ('.csv', '.tsv', '.txt', '.log', '.dat', '.exp')
"""Text logs read through a motor's column mapping; without one, only ``.csv``."""

EPOCH_RANGE = (9.0e8, 4.2e9)
"""A ``time`` value in this range is epoch seconds (1998 to 2103), [s]."""

BAG_FILES = ('.mcap', '.db3')
"""A directory holding one of these is a bag (one without metadata.yaml is refused by its
reader, with the reason, not passed over)."""

_HEAD_BYTES = 1 << 16
_DATE = re.compile(r'(?<![0-9])(?P<y>(?:19|20)[0-9]{2})(?P<ds>[-.]?)(?P<m>[01][0-9])(?P=ds)'
                   r'(?P<d>[0-3][0-9])(?:[T_ -]?(?P<H>[0-2][0-9])(?P<ts>[:.-]?)(?P<M>[0-5][0-9])'
                   r'(?:(?P=ts)(?P<S>[0-5][0-9]))?)?(?![0-9])')
"""A date, its parts apart by '-', '.' or nothing (the same between all three), and a time
(':', '-', '.' or nothing between its parts): 2026-03-01, 2021.07.26T10.51.44, 20260301T0830."""


@dataclass(frozen=True)
class Recording:
    """One recording of the fleet, placed."""

    path: str  # absolute path of the file or bag directory
    relative: str  # POSIX path from ROOT
    motor: str  # motor id
    kind: str  # 'bag' | 'csv' | 'log'
    time: float  # start, epoch [s] (UTC)
    time_source: str  # one of BAG_START, TIME_COLUMN, PATH_DATE, MTIME
    name: str  # its directory under DIR/<motor>/

    @property
    def date(self) -> str:
        """Return the start as an ISO 8601 UTC timestamp."""
        return datetime.fromtimestamp(self.time, timezone.utc).isoformat(timespec='seconds')


@dataclass(frozen=True)
class Motor:
    """A motor of the fleet: its rule (what fleet.yaml says) and its recordings in time."""

    motor: str
    rule: MotorRule
    recordings: tuple[Recording, ...]


def discover(root: str | Path, config: FleetConfig, skip: tuple[Path, ...] = ()) -> list[Motor]:
    """
    Find and place every recording under `root`.

    Parameters
    ----------
    root : str or pathlib.Path
        The fleet's tree, [-]
    config : FleetConfig
        fleet.yaml (empty rules: every motor is its first directory level), [-]
    skip : tuple of pathlib.Path
        Directories not to enter (the output directory when it is under `root`), [-]

    Returns
    -------
    list of Motor
        The motors by id, each with its recordings ordered in time (then by path).

    """
    base = Path(root).resolve()
    skipped = {p.resolve() for p in skip}
    placed: list[tuple[Path, str, str, MotorRule | None, str]] = []
    for path, kind in _walk(base, skipped):
        relative = path.relative_to(base).as_posix()
        rule = config.rule_for(relative)
        top = relative.split('/')[0] if '/' in relative else '/' + base.name  # ROOT's files
        columns = rule is not None and bool(rule.columns or rule.columns_inline)
        if kind == 'text':
            if path.suffix.lower() != '.csv' and not columns:
                continue
            kind = 'log' if columns else 'csv'
        placed.append((path, relative, kind, rule, top))
    ids = derived_ids({top for *_, rule, top in placed if rule is None},
                      {rule.motor for rule in config.rules})
    found: dict[str, list[Recording]] = {}
    rules: dict[str, MotorRule] = {}
    mappings: dict[str, Any] = {}
    for path, relative, kind, given, top in placed:
        rule = given if given is not None else MotorRule('', ids[top])
        rules.setdefault(rule.motor, rule)
        if kind == 'log' and rule.motor not in mappings:
            mappings[rule.motor] = _mapping(rule)
        time, source = recording_time(path, kind, relative, mappings.get(rule.motor))
        found.setdefault(rule.motor, []).append(
            Recording(str(path), relative, rule.motor, kind, time, source,
                      _name(relative, rule)))
    motors = []
    for motor in sorted(found):
        ordered = tuple(sorted(found[motor], key=lambda r: (r.time, r.relative)))
        motors.append(Motor(motor, rules[motor], _unique(ordered)))
    return motors


def derived_ids(tops: set[str], given: set[str]) -> dict[str, str]:
    """
    Name the motors no fleet.yaml pattern matched, each directory its own id.

    A directory's id is its name made safe (:func:`_motor_id`). Where that id is another
    directory's too (``a b`` and ``a_b``), a motor fleet.yaml names, or a name of the report
    (:data:`~satmotor_ros.fleet.config.RESERVED`), it gets ``~`` and six hexadecimal digits
    of its name's hash: the same whatever else is in the tree. A directory whose name is its
    id already keeps it when only altered names collide with it (``a_b`` above).

    Parameters
    ----------
    tops : set of str
        First-level directory names under ROOT; ``'/'`` and ROOT's name for its own files
        (their motor is named after ROOT, apart from a directory of that name), [-]
    given : set of str
        The motor ids fleet.yaml names, [-]

    Returns
    -------
    dict
        Each name's motor id, all distinct and none of `given` or of the report's.

    Examples
    --------
    >>> ids = derived_ids({'a b', 'a_b', 'plots', 'm1'}, {'m1'})
    >>> ids['a_b'], ids['a b'] != 'a_b', ids['plots'] != 'plots', ids['m1'] != 'm1'
    ('a_b', True, True, True)

    """
    safe = {top: _motor_id(top.lstrip('/')) for top in tops}
    taken = {id_.lower() for id_ in given} | set(RESERVED)
    out = {}
    for top, id_ in safe.items():
        rivals = [t for t, other in safe.items() if other.lower() == id_.lower() and t != top]
        yields = top != id_ or any(t == safe[t] for t in rivals)  # to a name that is its id
        clash = id_.lower() in taken or bool(rivals) and yields
        if clash:
            digest = hashlib.blake2b(top.encode('utf-8', 'surrogateescape'),
                                     digest_size=3).hexdigest()
            id_ = f'{id_}~{digest}'
        out[top] = id_
    return out


def _walk(base: Path, skipped: set[Path]) -> list[tuple[Path, str]]:
    out: list[tuple[Path, str]] = []
    for directory, dirs, files in os.walk(base):
        here = Path(directory)
        storage = any(f.endswith(BAG_FILES) for f in files)
        if here != base and ((here / 'metadata.yaml').is_file() or storage):
            out.append((here, 'bag'))
            dirs[:] = []
            continue
        dirs[:] = sorted(d for d in dirs if not d.startswith('.')
                         and (here / d).resolve() not in skipped)
        for name in sorted(files):
            if name.startswith('.') or name == FLEET_FILE:
                continue
            if Path(name).suffix.lower() in LOG_SUFFIXES:
                out.append((here / name, 'text'))
    return out


def _motor_id(text: str) -> str:
    """Make a name safe as a motor id (it names a directory under --out)."""
    return re.sub(r'[^A-Za-z0-9._-]', '_', text).lstrip('.') or 'motor'


def _name(relative: str, rule: MotorRule) -> str:
    """Name the recording's directory under DIR/<motor>/: its path below the motor's own."""
    parts = relative.split('/')
    if not rule.pattern:
        fixed = 1
    else:  # the pattern's directories up to its first wildcard: the motor's own directory
        literal = rule.pattern.strip('/').split('/')
        fixed = next((i for i, p in enumerate(literal) if any(c in p for c in '*?[')),
                     len(literal))
        if parts[:fixed] != literal[:fixed]:
            fixed = 0
    parts = parts[min(fixed, len(parts) - 1):]
    return _motor_id('__'.join(parts))


def _unique(recordings: tuple[Recording, ...]) -> tuple[Recording, ...]:
    seen: dict[str, int] = {}
    out = []
    for rec in recordings:
        n = seen.get(rec.name, 0)
        seen[rec.name] = n + 1
        if n:
            rec = Recording(rec.path, rec.relative, rec.motor, rec.kind, rec.time,
                            rec.time_source, f'{rec.name}~{n}')
        out.append(rec)
    return tuple(out)


def recording_time(path: Path, kind: str, relative: str = '',
                   mapping: Any = None) -> tuple[float, str]:
    """
    Find when a recording started, and how.

    Parameters
    ----------
    path : pathlib.Path
        The file or bag directory, [-]
    kind : str
        ``'bag'``, ``'csv'`` or ``'log'``, [-]
    relative : str
        Its path below ROOT, where a date counts (one in ROOT's own path is not the
        recording's); '' for the file's name only, [-]
    mapping : ColumnMapping or None
        A log's column mapping (its ``time`` column is read through it); None for none, [-]

    Returns
    -------
    tuple of (float, str)
        Epoch seconds (UTC) and how it was found (:data:`BAG_START` ... :data:`MTIME`).

    """
    if kind == 'bag':
        found = _bag_start(path)
        if found is not None:
            return found, BAG_START
    elif kind == 'csv':
        found = _time_column(path)
        if found is not None:
            return found, TIME_COLUMN
    elif kind == 'log' and mapping is not None:
        found = _mapped_time(path, mapping)
        if found is not None:
            return found, TIME_COLUMN
    found = path_date(relative or path.name)
    if found is not None:
        return found, PATH_DATE
    try:
        return path.stat().st_mtime, MTIME
    except OSError:
        return 0.0, MTIME


def _mapping(rule: MotorRule) -> Any:
    """Return a motor's column mapping, or None when it cannot be read (its runs say why)."""
    from satmotor_ros.identify import DataError
    from satmotor_ros.identify.columns import load_mapping, mapping_from_dict
    try:
        if rule.columns_inline is not None:
            return mapping_from_dict(rule.columns_inline)
        return load_mapping(rule.columns) if rule.columns else None
    except DataError:
        return None


def _mapped_time(path: Path, mapping: Any) -> float | None:
    """
    Return a log's first ``time`` value through its mapping when it is epoch seconds.

    Only the log's head is read (its first 64 kB, to the last whole line), through the
    mapping as the run reads the whole (units converted: a time in ms is seconds here too).
    """
    import tempfile
    from satmotor_ros.identify.columns import read_log
    if 'time' not in mapping.fields:
        return None
    try:
        with path.open('rb') as file:
            head = file.read(_HEAD_BYTES)
        head = head[:head.rfind(b'\n') + 1]
        if not head:
            return None
        with tempfile.TemporaryDirectory(prefix='satmotor-fleet-') as scratch:
            part = Path(scratch) / path.name
            part.write_bytes(head)
            table = read_log(part, mapping)
        value = float(table.channels['time'][0])
    except Exception:  # noqa: B902 - a log the mapping cannot read is timed otherwise
        return None
    return value if EPOCH_RANGE[0] <= value <= EPOCH_RANGE[1] else None


def _bag_start(path: Path) -> float | None:
    try:
        info = read_yaml(path / 'metadata.yaml')['rosbag2_bagfile_information']
        ns = info['starting_time']['nanoseconds_since_epoch']
    except (OSError, YamlLimitError, KeyError, TypeError):
        return None
    if isinstance(ns, bool) or not isinstance(ns, int) or ns <= 0:
        return None
    return ns / 1e9


def _time_column(path: Path) -> float | None:
    """
    Return the first ``time`` value of a CSV in seconds when it is an epoch, else None.

    The value is read in the column's unit and converted as the bench table reads it
    (``time [ms]`` is milliseconds: 1.77e12 ms is 1.77e9 s).
    """
    from satmotor_ros.identify import DataError
    from satmotor_ros.identify.table import column_to_si
    from satmotor_ros.identify.textfile import split_unit
    import numpy as np
    try:
        with path.open('rb') as file:
            head = file.read(_HEAD_BYTES).decode('utf-8', errors='replace')
    except OSError:
        return None
    lines = [line for line in head.splitlines() if line.strip()]
    if len(lines) < 2:
        return None
    header = [split_unit(cell.strip()) for cell in lines[0].split(',')]
    names = [name.strip().lower() for name, _ in header]
    if 'time' not in names:
        return None
    column = names.index('time')
    cells = lines[1].split(',')
    try:
        value = float(column_to_si('time', header[column][1] or 's',  # none: s, as before
                                   np.array([float(cells[column])]))[0])
    except (ValueError, IndexError, DataError):
        return None
    return value if EPOCH_RANGE[0] <= value <= EPOCH_RANGE[1] else None


def path_date(text: str) -> float | None:
    """
    Read the last date (and time) written in a path, as epoch seconds (UTC).

    Parameters
    ----------
    text : str
        The path, [-]

    Returns
    -------
    float or None
        The epoch, or None when the path holds no valid date.

    Examples
    --------
    >>> path_date('rig/2026-03-01/run_20260302T0830.csv') - path_date('x/2026-03-02')
    30600.0
    >>> path_date('rig/run7.csv') is None
    True

    """
    for found in reversed(list(_DATE.finditer(text))):
        try:
            when = datetime(int(found['y']), int(found['m']), int(found['d']),
                            int(found['H'] or 0), int(found['M'] or 0), int(found['S'] or 0),
                            tzinfo=timezone.utc)
        except ValueError:
            continue
        return when.timestamp()
    return None


__all__ = ['BAG_FILES', 'BAG_START', 'EPOCH_RANGE', 'LOG_SUFFIXES', 'MTIME', 'Motor', 'PATH_DATE',
           'Recording', 'TIME_COLUMN', 'derived_ids', 'discover', 'path_date', 'recording_time']
