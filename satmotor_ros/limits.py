# SPDX-License-Identifier: Apache-2.0
"""
The caps on the work a small input may ask for, in one place.

A hostile or broken file must not take unbounded memory or time: each cap
below bounds one kind of work, is documented in ``doc/outputs.md`` and can be
raised through the environment variable named beside it. Hitting a cap is an
error of one line naming the file and the cap, never a traceback. A variable that
changes nothing (not a whole number from 1 to 2**63 - 1, or a misspelt name) is
found here, once, and listed in :data:`BAD_OVERRIDES` for the entry points to say.
"""

from __future__ import annotations

from dataclasses import dataclass
import difflib
import os
from pathlib import Path
import re
import stat

CAP_MAX = (1 << 63) - 1
"""Largest value a cap may be given (the 64-bit sizes and counts it is compared with), [-]."""


@dataclass(frozen=True)
class BadOverride:
    """A SATMOTOR_* variable that was set to change a cap and changes nothing."""

    name: str
    """The variable, e.g. ``'SATMOTOR_YAML_MAX_BYTES'``, [-]"""
    text: str
    """Its value as set, [-]"""
    reason: str
    """Why it changes nothing, [-]"""
    instead: str
    """What a node does instead of refusing, e.g. ``'the default 1048576 is used'``, [-]"""

    def __str__(self) -> str:
        """Return the line that names the variable, its value and the reason."""
        return f'{self.name}={self.text!r}: {self.reason}'


_CAPS: dict[str, int] = {}  # each overridable cap's variable and its default
_bad: list[BadOverride] = []


def _cap(name: str, default: int) -> int:
    _CAPS[name] = default
    text = os.environ.get(name, '')
    if not text.strip():  # unset, or set to nothing as `export NAME=` does: the default
        return default
    digits = re.fullmatch(r'\s*([0-9]{1,30})\s*', text)
    if digits and 1 <= int(digits[1]) <= CAP_MAX:
        return int(digits[1])
    _bad.append(BadOverride(name, text, f'a cap is a whole number from 1 to {CAP_MAX}',
                            f'the default {default} is used'))
    return default


YAML_MAX_BYTES = _cap('SATMOTOR_YAML_MAX_BYTES', 1 << 20)
"""Largest YAML file read, [byte]."""

YAML_MAX_DEPTH = _cap('SATMOTOR_YAML_MAX_DEPTH', 64)
"""Deepest nesting of YAML mappings and sequences, [-]."""

YAML_MAX_NODES = _cap('SATMOTOR_YAML_MAX_NODES', 100_000)
"""Most nodes of a YAML document with every alias expanded, [-]."""

YAML_MAX_DIGITS = 40
"""Most digits of a YAML integer; no physical quantity needs more, [-]."""

BAG_MAX_BYTES = _cap('SATMOTOR_BAG_MAX_BYTES', 16 << 30)
"""Most bytes a bag may decompress to, whatever its size, [byte]."""

BAG_MAX_RATIO = _cap('SATMOTOR_BAG_MAX_RATIO', 200)
"""Most bytes a bag may decompress to per byte stored, above :data:`BAG_FLOOR_BYTES`, [-]."""

BAG_FLOOR_BYTES = 64 << 20
"""Bytes any bag may decompress to, however small it is, [byte]."""

RATE_MAX_PREDICTIONS = _cap('SATMOTOR_RATE_MAX_PREDICTIONS', 4_000_000)
"""Most predictions ``replay --mode rate`` makes (66 min at 1 kHz; replay peaks at about 2 GB,
0.5 KB a prediction), [-]."""

CSV_MAX_COLUMNS = _cap('SATMOTOR_CSV_MAX_COLUMNS', 256)
"""Most columns of a CSV or text log read; calibration's work grows with each, [-]."""

TEXT_MAX_BYTES = _cap('SATMOTOR_TEXT_MAX_BYTES', 128 << 20)
"""Largest text log (CSV, ``.exp``) read as DATA: about a million rows of 18 columns, [byte]."""

TEXT_MAX_ROWS = _cap('SATMOTOR_TEXT_MAX_ROWS', 500_000)
"""Most data rows of a text log (a points table of 500 000 rows calibrates in 121 s and
1.07 GB; 2.8 h of a 50 Hz log), [-]."""

TEXT_MAX_CHANNELS = _cap('SATMOTOR_TEXT_MAX_CHANNELS', 256)
"""Most channels a column mapping may name (each is a set of candidate effects, as a
column is), [-]."""

CURVE_MAX_POINTS = _cap('SATMOTOR_CURVE_MAX_POINTS', 100_000)
"""Most points per curve of ``satmotor characteristics --points`` (about 40 MB), [-]."""

PLOT_MAX_PANELS = _cap('SATMOTOR_PLOT_MAX_PANELS', 24)
"""Most panels of a report's residual grid (24: 960 x 1920 pixels), [-]."""


def _misspelt() -> list[BadOverride]:
    """Name each SATMOTOR_*_MAX_* variable that is no cap: a misspelt cap changes nothing."""
    bad = []
    for name in sorted(os.environ):
        if name.startswith('SATMOTOR_') and '_MAX_' in name and name not in _CAPS:
            near = difflib.get_close_matches(name, _CAPS, n=1, cutoff=0.8)
            known = f'did you mean {near[0]}?' if near else 'the caps: ' + ', '.join(_CAPS)
            bad.append(BadOverride(name, os.environ[name], f'no such cap ({known})',
                                   'it is ignored'))
    return bad


BAD_OVERRIDES = tuple(_bad + _misspelt())
"""Each SATMOTOR_* cap variable that is set and changes nothing, found once, at import: the
CLI refuses to run with one (one line), a node logs each as an ERROR and runs on the
defaults."""


class LimitError(ValueError):
    """A file is not a regular file or is larger than its cap; the message is one line."""


def read_capped(path: str | Path, most: int, variable: str) -> bytes:
    """
    Read a regular file of at most `most` bytes, reading no more than that.

    Parameters
    ----------
    path : str or pathlib.Path
        The file, [-]
    most : int
        Largest size read, [byte]
    variable : str
        The cap's variable, named when it is hit, [-]

    Returns
    -------
    bytes
        The file's content.

    Raises
    ------
    OSError
        If the file cannot be opened or read (a symbolic link loop among them).
    LimitError
        If it is not a regular file (a FIFO would block, ``/dev/zero`` never end) or is
        larger than `most`.

    """
    # O_NONBLOCK: opening a FIFO does not wait for a writer, so fstat can refuse it
    with open(os.open(path, os.O_RDONLY | os.O_NONBLOCK), 'rb') as file:
        if not stat.S_ISREG(os.fstat(file.fileno()).st_mode):
            raise LimitError('not a regular file (a FIFO, device or directory)')
        data = file.read(most + 1)
    if len(data) > most:
        raise LimitError(f'larger than {most} bytes (the cap {variable})')
    return data


def bag_budget(stored_bytes: int) -> int:
    """
    Return how many bytes a bag of `stored_bytes` may decompress to.

    Parameters
    ----------
    stored_bytes : int
        Size of the bag's storage files on disk, [byte]

    Returns
    -------
    int
        ``min(BAG_MAX_BYTES, max(BAG_FLOOR_BYTES, BAG_MAX_RATIO * stored_bytes))``, [byte]

    """
    return min(BAG_MAX_BYTES, max(BAG_FLOOR_BYTES, BAG_MAX_RATIO * stored_bytes))


__all__ = ['BAD_OVERRIDES', 'BadOverride', 'BAG_FLOOR_BYTES', 'BAG_MAX_BYTES', 'BAG_MAX_RATIO',
           'CAP_MAX', 'CSV_MAX_COLUMNS', 'CURVE_MAX_POINTS', 'LimitError',
           'PLOT_MAX_PANELS', 'RATE_MAX_PREDICTIONS', 'TEXT_MAX_BYTES', 'TEXT_MAX_CHANNELS',
           'TEXT_MAX_ROWS', 'YAML_MAX_BYTES', 'YAML_MAX_DEPTH', 'YAML_MAX_DIGITS',
           'YAML_MAX_NODES', 'bag_budget', 'read_capped']
