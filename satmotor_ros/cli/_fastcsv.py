# SPDX-License-Identifier: Apache-2.0
"""
CSV text from numpy columns without a Python call per number.

Python spends about a microsecond turning one float into text; a replay writes millions.
Here every column is formatted at once with integer arithmetic, as fixed-point decimals
with a given number of decimal places (NaN as an empty field), and the rows are
assembled as one byte array.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

_LIMIT = 2.0 ** 53  # value * 10^decimals below this is an exact integer in a double


def fixed_point(values: npt.ArrayLike, decimals: int) -> npt.NDArray[np.uint8]:
    r"""
    Format numbers with a fixed number of decimal places, as ``'%.{decimals}f'`` does.

    Parameters
    ----------
    values : array_like
        Numbers; NaN and inf give an empty field, [-]
    decimals : int
        Decimal places; fewer where value * 10^decimals would exceed 2^53, [-]

    Returns
    -------
    ndarray of uint8
        One row of ASCII per value, left-padded with NUL bytes, [-]

    Examples
    --------
    >>> fixed_point([1.5, -0.25, float('nan')], 2).tobytes().replace(b'\0', b'|')
    b'|1.50-0.25|||||'

    """
    x = np.asarray(values)
    integer = np.issubdtype(x.dtype, np.integer)
    x = x.astype(np.int64 if integer else np.float64)
    valid = np.ones(len(x), dtype=bool) if integer else np.isfinite(x)
    if integer:
        decimals = 0
        mag, neg = np.abs(x).astype(np.uint64), x < 0
    else:
        decimals = shown_decimals(x, decimals)
        valid &= np.abs(x) * 10.0 ** decimals < _LIMIT
        scaled = np.round(np.where(valid, x, 0.0) * 10.0 ** decimals)
        neg = scaled < 0
        mag = np.abs(scaled).astype(np.uint64)
    whole = mag // np.uint64(10 ** decimals)
    n_int = max(1, len(str(int(whole.max()))) if len(whole) else 1)
    width = 1 + n_int + (1 + decimals if decimals else 0)
    out = np.zeros((len(x), width), dtype=np.uint8)
    rem = mag.copy()
    col = width - 1
    ten = np.uint64(10)
    for k in range(decimals):
        rem, digit = np.divmod(rem, ten)
        out[:, col - k] = 48 + digit.astype(np.uint8)
    if decimals:
        out[:, width - 1 - decimals] = ord('.')
    units = width - 2 - decimals if decimals else width - 1
    used = np.ones(len(x), dtype=np.int64)  # digits of the whole part actually shown
    for j in range(n_int):
        rem, digit = np.divmod(rem, ten)
        show = (whole >= np.uint64(10 ** j)) | (j == 0)
        out[:, units - j] = np.where(show, 48 + digit.astype(np.uint8), 0)
        used += (j > 0) & show
    rows = np.flatnonzero(neg & valid & (mag > 0))
    out[rows, units - used[rows]] = ord('-')
    out[~valid] = 0
    return out


def shown_decimals(values: npt.ArrayLike, decimals: int) -> int:
    """
    Return the decimal places :func:`fixed_point` shows for `values`.

    Parameters
    ----------
    values : array_like
        Numbers, [-]
    decimals : int
        Decimal places asked for, [-]

    Returns
    -------
    int
        `decimals`, fewer where the largest finite value * 10^decimals would exceed 2^53;
        formatting a column in pieces with it gives the digits of the whole column.

    """
    x = np.asarray(values, dtype=np.float64)
    valid = np.isfinite(x)
    biggest = float(np.abs(x[valid]).max()) if valid.any() else 0.0
    while decimals > 0 and biggest * 10.0 ** decimals >= _LIMIT:
        decimals -= 1
    return decimals


def text(values: Sequence[str]) -> npt.NDArray[np.uint8]:
    """
    Turn ASCII strings into NUL-padded rows.

    Parameters
    ----------
    values : sequence of str
        The strings, [-]

    Returns
    -------
    ndarray of uint8
        One row per string, [-]

    """
    arr = np.array(values, dtype=bytes)
    width = max(arr.dtype.itemsize, 1)
    return np.frombuffer(arr.astype(f'S{width}').tobytes(), dtype=np.uint8).reshape(
        len(values), width)


def rows(fields: Sequence[npt.NDArray[np.uint8]]) -> bytes:
    """
    Join formatted columns into CSV lines.

    Parameters
    ----------
    fields : sequence of ndarray of uint8
        Columns from :func:`fixed_point` or :func:`text`, all of the same length, [-]

    Returns
    -------
    bytes
        The lines, comma-separated, each ending in a newline.

    """
    n = len(fields[0])
    parts = []
    for k, field in enumerate(fields):
        parts.append(field)
        parts.append(np.full((n, 1), ord(',') if k < len(fields) - 1 else ord('\n'),
                             dtype=np.uint8))
    block = np.concatenate(parts, axis=1).reshape(-1)
    text: bytes = block[block != 0].tobytes()  # numpy types a masked array as Any
    return text
