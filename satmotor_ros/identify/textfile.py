# SPDX-License-Identifier: Apache-2.0
"""
Numbers and header cells out of a text log: separators, comments and the header line.

A bench CSV and a user's own log (doc/columns.md) are both read here; what the cells mean is
decided elsewhere (:mod:`.table` for ``name [unit]`` headers, :mod:`.columns` for a mapping).
"""

from __future__ import annotations

from collections.abc import Iterator
import csv
from dataclasses import dataclass
import io
from pathlib import Path
import re

import numpy as np

from satmotor_ros.identify.errors import DataError
from satmotor_ros.limits import (CSV_MAX_COLUMNS, LimitError, read_capped, TEXT_MAX_BYTES,
                                 TEXT_MAX_ROWS)

SEPARATORS = {'comma': ',', 'semicolon': ';', 'tab': '\t', 'whitespace': None}
"""Separator names a mapping may give (``auto`` too); ``None`` is any run of blanks."""

SANITY = 'sanity check'
"""How the notes on a suspicious setup begin (time that restarts, lines a comment rule left
out, an optional channel absent, a displacement that makes most losses negative); each is said
on stderr and in the report."""

HEADERS = ('auto', 'first', 'comment', 'none')
"""Where the header is: decided from the file, the first non-comment line, the last comment
line before the data (as in ``#time(s),RPM,...``), or nowhere (columns by number)."""


_UNIT = re.compile(r'^\s*(.*?)\s*(?:\[\s*([^\[\]]*?)\s*\]|\(\s*([^()]*?)\s*\))?\s*$')


def shorten(text: str, most: int = 40) -> str:
    """
    Return `text` cut to `most` characters, for a message quoting a file's cell.

    Examples
    --------
    >>> shorten('x' * 50, 8)
    'xxxxxxxx...'

    """
    return text if len(text) <= most else text[:most] + '...'


def split_unit(cell: str) -> tuple[str, str]:
    """
    Split a header cell into its name and the unit in brackets or parentheses.

    Parameters
    ----------
    cell : str
        A header cell such as ``'flow [l/min]'`` or ``'Spd(in/s)'``, [-]

    Returns
    -------
    (str, str)
        Name and unit ('' when none).

    Examples
    --------
    >>> split_unit('Spd(in/s)'), split_unit('p_in [MPa]'), split_unit('RPM')
    (('Spd', 'in/s'), ('p_in', 'MPa'), ('RPM', ''))

    """
    match = _UNIT.match(cell)
    if match is None:  # pragma: no cover - the pattern matches any text
        return cell.strip(), ''
    name, bracket, paren = match.groups()
    return name, bracket or paren or ''


@dataclass(frozen=True)
class TextTable:
    """The cells of a text log: header cells (if any) and the data as floats (NaN if empty)."""

    header: tuple[str, ...] | None  # header cells, None when the file has no header
    data: np.ndarray  # rows x columns, float; empty cells and 'nan' are NaN
    lines: np.ndarray  # 1-based line number in the file of each data row
    notes: tuple[str, ...] = ()  # what the reading left out, e.g. comment lines among the data


def _split(line: str, sep: str | None) -> list[str]:
    if sep is None:
        return line.split()
    return next(csv.reader([line], delimiter=sep))


def _numeric(cells: list[str]) -> bool:
    for cell in cells:
        text = cell.strip()
        if text and text.lower() not in ('nan', 'na'):
            try:
                float(text.replace(',', '.'))
            except ValueError:
                return False
    return True


def _detect(line: str) -> str | None:
    for sep in (';', '\t', ','):
        if sep in line:
            return sep
    return None


def _header_cells(text: str, sep: str | None, width: int) -> list[str] | None:
    """Split `text` by `sep` or, failing that, by whichever separator gives `width` cells."""
    for candidate in (sep, ',', ';', '\t', None):
        cells = [c.strip() for c in _split(text, candidate)]
        if len(cells) == width:
            return cells
    return None


def _read_lines(file: Path) -> Iterator[str]:
    """
    Yield the lines of a capped text file one by one (universal newlines, BOM dropped).

    Line by line, never a list of every line: a file of many short lines costs no more than
    its bytes until the row cap stops it.
    """
    try:
        data = read_capped(file, TEXT_MAX_BYTES, 'SATMOTOR_TEXT_MAX_BYTES')
    except OSError as err:
        msg = f'cannot read {str(file)!r}: {err.strerror}'
        raise DataError(msg) from None
    except LimitError as err:
        msg = f'{str(file)!r}: {err}; doc/outputs.md'
        raise DataError(msg) from None
    first = True
    for raw in io.BytesIO(data):  # splits at b'\n' lazily, sharing the bytes
        try:
            text = raw.decode('utf-8-sig' if first else 'utf-8')
        except UnicodeDecodeError:
            msg = f'{str(file)!r} is not a UTF-8 text file'
            raise DataError(msg) from None
        first = False
        yield from text.splitlines() or ('',)


def _numbers(rows: list[list[str]], lines: list[int], names: list[str]) -> np.ndarray:
    data = np.full((len(rows), len(names)), np.nan)
    for r, row in enumerate(rows):
        if len(row) != len(names):
            msg = f'row {lines[r]}: {len(row)} cells, the header has {len(names)}'
            raise DataError(msg)
        for c, cell in enumerate(row):
            text = cell.strip()
            if not text or text.lower() in ('nan', 'na'):
                continue
            try:
                data[r, c] = float(text)
            except ValueError:
                msg = (f"column '{shorten(names[c])}' row {lines[r]}: {shorten(text)!r} is not "
                       'a number')
                raise DataError(msg) from None
    return data


def read_cells(path: str | Path, separator: str = 'auto', comment: str = '#',
               header: str = 'auto') -> TextTable:
    """
    Read a text log's header cells and numbers.

    Parameters
    ----------
    path : str or pathlib.Path
        The file, UTF-8, [-]
    separator : {'auto', 'comma', 'semicolon', 'tab', 'whitespace'}
        Between cells of a data row. ``auto`` takes the first of ``;``, tab, ``,`` found in
        the first data row, else blanks; semicolons mean decimal commas. The header is split
        by the same separator or, if that does not give one cell per data column, by
        another one that does, [-]
    comment : str
        Lines starting with it (after blanks) are comments; ``''`` for none, [-]
    header : {'auto', 'first', 'comment', 'none'}
        Where the header is (:data:`HEADERS`). ``auto``: the first non-comment line if it is
        not all numbers, else the last comment line before the data if it splits into one
        cell per column, else none, [-]

    Returns
    -------
    TextTable
        Header cells and data.

    Raises
    ------
    DataError
        One line naming the file, row or column that cannot be read.

    """
    if separator != 'auto' and separator not in SEPARATORS:
        msg = f'separator {separator!r}: use auto, {", ".join(SEPARATORS)}'
        raise DataError(msg)
    if header not in HEADERS:
        msg = f'header {header!r}: use {", ".join(HEADERS)}'
        raise DataError(msg)
    file = Path(path)
    content: list[tuple[int, str]] = []
    last_comment = None
    skipped: list[int] = []  # comment lines after the first data line
    for number, line in enumerate(_read_lines(file), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if comment and stripped.startswith(comment):
            if not content:
                last_comment = stripped[len(comment):].strip()
            else:
                skipped.append(number)
            continue
        content.append((number, line))
        if len(content) > TEXT_MAX_ROWS + 1:  # the header and the rows the cap allows
            msg = (f'{str(file)!r}: more than {TEXT_MAX_ROWS} data rows (the cap '
                   'SATMOTOR_TEXT_MAX_ROWS; doc/outputs.md)')
            raise DataError(msg)
    if not content:
        msg = f'{str(file)!r} is empty: expected a header row and data rows'
        raise DataError(msg)
    first = 1 if header == 'first' else 0
    if header == 'auto':
        sep0 = SEPARATORS.get(separator, _detect(content[0][1]))
        first = 0 if _numeric(_split(content[0][1], sep0)) else 1
    if first >= len(content):
        msg = f'{str(file)!r} has a header but no data rows'
        raise DataError(msg)
    sep = SEPARATORS[separator] if separator != 'auto' else _detect(content[first][1])
    body = [line for _, line in content[first:]]
    lines = [number for number, _ in content[first:]]
    width = len(_split(body[0], sep))
    if width > CSV_MAX_COLUMNS:
        msg = (f'{str(file)!r}: {width} columns, more than the {CSV_MAX_COLUMNS} read (the cap '
               'SATMOTOR_CSV_MAX_COLUMNS; doc/outputs.md)')
        raise DataError(msg)
    cells: list[str] | None = None
    if first:
        cells = _header_cells(content[0][1], sep, width)
    elif header in ('auto', 'comment') and last_comment is not None:
        cells = _header_cells(last_comment, sep, width)
        if cells is None and header == 'comment':
            msg = (f'{str(file)!r}: the header comment {last_comment[:60]!r} does not split into '
                   f'the {width} cells of a data row')
            raise DataError(msg)
    if cells is None and first:
        msg = (f'{str(file)!r}: the header has {len(_split(content[0][1], sep))} cells, the '
               f'first data row {width}')
        raise DataError(msg)
    if sep == ';':  # a European CSV: decimal commas
        body = [line.replace(',', '.') for line in body]
    names = [split_unit(c)[0] for c in cells] if cells else [str(i + 1) for i in range(width)]
    try:
        data = np.loadtxt(io.StringIO('\n'.join(body)), delimiter=sep, ndmin=2,
                          comments=None)
    except ValueError:
        data = _numbers([_split(line, sep) for line in body], lines, names)
    if data.shape[1] != len(names):
        msg = f'{str(file)!r}: rows have {data.shape[1]} cells, the header has {len(names)}'
        raise DataError(msg)
    return TextTable(tuple(cells) if cells is not None else None, data, np.asarray(lines),
                     _comment_note(skipped, comment, data.shape[0]))


def _comment_note(skipped: list[int], comment: str, rows: int) -> tuple[str, ...]:
    """Say how many lines among the data the comment rule left out, and which."""
    if not skipped:
        return ()
    shown = ', '.join(map(str, skipped[:5])) + (f' and {len(skipped) - 5} more'
                                                if len(skipped) > 5 else '')
    return (f'{SANITY}: the comment rule {comment!r} left out {len(skipped)} lines among the '
            f'{rows} data rows read (lines {shown}); if they are data, change file.comment',)
