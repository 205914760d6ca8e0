# SPDX-License-Identifier: Apache-2.0
"""``fleet.yaml``: which recordings belong to which motor, and what each motor is."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
import re
from typing import Any

from satmotor_ros.bounded_yaml import read_yaml_or, shown
from satmotor_ros.fleet.errors import FleetError
from satmotor_ros.model.errors import UnitError
from satmotor_ros.model.units import parse_quantity

FLEET_FILE = 'fleet.yaml'
"""The fleet description looked for in ROOT when ``--fleet`` is not given."""

REPORT_JSON, REPORT_MD, PLOTS, FLEET_PLOT = 'fleet.json', 'fleet.md', 'plots', 'fleet'
"""The fleet's own files in DIR: its report, the plots' directory and the fleet's plot
(``plots/fleet.png``) beside each motor's (``plots/<motor>.png``)."""

RESERVED = (REPORT_JSON, REPORT_MD, PLOTS, FLEET_PLOT)
"""Names no motor id may take (in any case): its directory or plot would be a report file."""

LIQUIDS = ('oil', 'water')
"""The liquids a fleet.yaml entry may name (the packaged coefficient sets)."""

_KEYS = ('pattern', 'motor', 'liquid', 'family', 'displacement', 'motor_file', 'columns')
_MOTOR_ID = re.compile(r'[A-Za-z0-9][A-Za-z0-9._-]{0,99}')


@dataclass(frozen=True)
class MotorRule:
    """One ``motors:`` entry of fleet.yaml; the empty defaults mean 'not given'."""

    pattern: str  # glob relative to ROOT ('**' spans directories)
    motor: str  # motor id, also its directory name under --out
    liquid: str = ''  # 'oil' | 'water'; '' the data's own, else water
    family: str = ''  # model family; '' the motor file's or the default
    displacement: float = 0.0  # [m^3/rad]; 0: the motor file's or the packaged motor's
    motor_file: str = ''  # absolute path of the motor or coefficients YAML; '' none
    columns: str = ''  # absolute path or packaged name of a column mapping; '' none
    columns_inline: dict[str, Any] | None = None  # a mapping written in fleet.yaml itself

    def matches(self, relative: str) -> bool:
        """Whether the recording at `relative` (POSIX, from ROOT) or a parent matches."""
        regex = glob_regex(self.pattern)
        parts = relative.split('/')
        return any(regex.fullmatch('/'.join(parts[:n])) for n in range(len(parts), 0, -1))


@dataclass(frozen=True)
class FleetConfig:
    """The parsed fleet.yaml: its rules in order (the first match wins) and where it is."""

    rules: tuple[MotorRule, ...] = ()
    source: str = ''  # the file read; '' without one

    def rule_for(self, relative: str) -> MotorRule | None:
        """Return the first rule matching a recording, or None."""
        return next((rule for rule in self.rules if rule.matches(relative)), None)


def glob_regex(pattern: str) -> re.Pattern[str]:
    """
    Translate a glob relative to ROOT into a regular expression over POSIX paths.

    ``**`` matches any number of whole directories, ``*`` and ``?`` stay within one
    name, ``[...]`` is a character class.

    Parameters
    ----------
    pattern : str
        The glob, e.g. ``'vessels/*/pump_a/**'``, [-]

    Returns
    -------
    re.Pattern
        The expression, to be used with ``fullmatch``.

    Examples
    --------
    >>> bool(glob_regex('a/**/b*.csv').fullmatch('a/x/y/b1.csv'))
    True
    >>> bool(glob_regex('a/*.csv').fullmatch('a/x/b.csv'))
    False

    """
    out, i = [], 0
    text = pattern.strip('/')
    while i < len(text):
        if text.startswith('**/', i):
            out.append('(?:[^/]+/)*')
            i += 3
        elif text.startswith('**', i):
            out.append('.*')
            i += 2
        elif text[i] == '*':
            out.append('[^/]*')
            i += 1
        elif text[i] == '?':
            out.append('[^/]')
            i += 1
        elif text[i] == '[' and ']' in text[i + 1:]:
            end = text.index(']', i + 1)
            body = text[i + 1:end].replace('\\', '\\\\')
            out.append('[' + ('^' + body[1:] if body.startswith('!') else body) + ']')
            i = end + 1
        else:
            out.append(re.escape(text[i]))
            i += 1
    return re.compile(''.join(out))


def load_fleet(path: str | Path) -> FleetConfig:
    """
    Read fleet.yaml strictly: an unknown key or a bad value is one line naming both.

    Parameters
    ----------
    path : str or pathlib.Path
        The fleet.yaml, [-]

    Returns
    -------
    FleetConfig
        The rules, paths made absolute against the file's directory.

    Raises
    ------
    FleetError
        If the file cannot be read, is not YAML, or an entry is invalid.

    """
    path = Path(path)
    doc = read_yaml_or(path, FleetError, str(path), str(path))
    if not isinstance(doc, dict) or set(doc) != {'motors'} \
            or not isinstance(doc['motors'], list):
        raise FleetError(f'{path}: need one key, motors: a list of {{pattern, motor, ...}} '
                         f'entries (got {shown(doc)})')
    rules = tuple(_rule(entry, f'{path}: motors[{i}]', path.parent)
                  for i, entry in enumerate(doc['motors']))
    _agree(rules, path)
    return FleetConfig(rules, str(path))


_SAME = ('liquid', 'family', 'displacement', 'motor_file', 'columns', 'columns_inline')
"""What every entry of one motor id must give alike (it is one motor, with one baseline)."""


def _agree(rules: tuple[MotorRule, ...], path: Path) -> None:
    """Refuse two entries of one motor id that say different things of it."""
    first: dict[str, tuple[int, MotorRule]] = {}
    for i, rule in enumerate(rules):
        j, earlier = first.setdefault(rule.motor, (i, rule))
        for key in _SAME:
            if getattr(rule, key) != getattr(earlier, key):
                name = 'columns' if key == 'columns_inline' else key
                raise FleetError(f'{path}: motors[{i}].{name} = {shown(getattr(rule, key))}: '
                                 f'motors[{j}] gives motor {rule.motor!r} '
                                 f'{shown(getattr(earlier, key))} (one motor, one {name})')


def _check_motor(where: str, entry: dict[str, Any], liquid: str, family: str,
                 displacement: float, motor_file: str) -> None:
    """Build the motor the entry names, so a contradiction is refused here, not per recording."""
    from satmotor_ros.model.errors import ModelError
    from satmotor_ros.options import MotorOptions, OptionError
    try:
        options = MotorOptions(liquid=liquid, family=family, displacement=displacement,
                               motor_file=motor_file)
        try:
            options.spec()
        except OptionError as err:
            if liquid or err.option != 'liquid':  # no liquid given: the data name it later
                raise
    except OptionError as err:
        key = 'motor_file' if err.option == 'family' and motor_file else err.option
        raise FleetError(f'{where}: {key} = {shown(entry.get(key, err.value))}: '
                         f'{err.reason}') from None
    except ModelError as err:
        key = 'motor_file' if motor_file else 'displacement'
        text = str(err).strip().splitlines()
        raise FleetError(f'{where}: {key} = {shown(entry.get(key))}: '
                         + (text[0] if text else type(err).__name__)) from None


def _rule(entry: Any, where: str, base: Path) -> MotorRule:
    if not isinstance(entry, dict):
        raise FleetError(f'{where}: need a mapping with pattern and motor (got {shown(entry)})')
    for key in entry:
        if key not in _KEYS:
            raise FleetError(f'{where}: unknown key {shown(key)} (known: {", ".join(_KEYS)})')
    for key in ('pattern', 'motor'):
        if key not in entry:
            raise FleetError(f'{where}: {key} is missing')
    text = {k: v for k, v in entry.items() if k != 'columns'}
    for key, value in text.items():
        if not isinstance(value, str) or not value.strip():
            raise FleetError(f'{where}: {key} = {shown(value)}: need a non-empty string')
    if not _MOTOR_ID.fullmatch(entry['motor']):
        raise FleetError(f"{where}: motor = {shown(entry['motor'])}: need letters, digits, "
                         "'.', '_' or '-' (it names a directory), at most 100")
    if entry['motor'].lower() in RESERVED:
        raise FleetError(f"{where}: motor = {shown(entry['motor'])}: the name of the report's "
                         f"own {', '.join(RESERVED)} (in DIR): name the motor otherwise")
    liquid = entry.get('liquid', '')
    if liquid and liquid not in LIQUIDS:
        raise FleetError(f'{where}: liquid = {shown(liquid)}: need one of {", ".join(LIQUIDS)}')
    family = entry.get('family', '')
    if family:
        from satmotor_ros.model.families import FAMILIES
        if family not in FAMILIES:
            raise FleetError(f'{where}: family = {shown(family)}: need one of '
                             f'{", ".join(FAMILIES)}')
    displacement = 0.0
    if 'displacement' in entry:
        try:
            displacement = parse_quantity(entry['displacement'], 'displacement', 'cm^3/rev')
        except UnitError as err:
            raise FleetError(f"{where}: displacement = {shown(entry['displacement'])}: {err}") \
                from None
        if not displacement > 0.0 or displacement == float('inf'):
            raise FleetError(f"{where}: displacement = {shown(entry['displacement'])}: need a "
                             'finite value > 0')
    motor_file = ''
    if 'motor_file' in entry:
        motor_file = str((base / entry['motor_file']).resolve())
        if not Path(motor_file).is_file():
            raise FleetError(f"{where}: motor_file = {shown(entry['motor_file'])}: no such file")
    _check_motor(where, entry, liquid, family, displacement, motor_file)
    columns, inline = _columns(entry.get('columns'), where, base)
    return MotorRule(entry['pattern'], entry['motor'], liquid, family, displacement,
                     motor_file, columns, inline)


def _columns(value: Any, where: str, base: Path) -> tuple[str, dict[str, Any] | None]:
    """Read ``columns``: a mapping file (relative to fleet.yaml), a packaged name, or inline."""
    if value is None:
        return '', None
    if isinstance(value, dict):
        from satmotor_ros.identify import DataError
        from satmotor_ros.identify.columns import mapping_from_dict
        try:
            mapping_from_dict(value, f'{where}: columns')
        except DataError as err:
            raise FleetError(str(err)) from None
        return '', value
    if not isinstance(value, str) or not value.strip():
        raise FleetError(f'{where}: columns = {shown(value)}: need a mapping, a mapping file '
                         'or a packaged mapping name')
    local = base / value
    return (str(local.resolve()) if local.exists() else value), None


__all__ = ['FLEET_FILE', 'FLEET_PLOT', 'FleetConfig', 'LIQUIDS', 'MotorRule', 'PLOTS',
           'REPORT_JSON', 'REPORT_MD', 'RESERVED', 'glob_regex', 'load_fleet']
