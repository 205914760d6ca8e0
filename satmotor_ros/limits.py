# SPDX-License-Identifier: Apache-2.0
"""
The caps on the work a small input may ask for, in one place.

A hostile or broken file must not take unbounded memory or time: each cap
below bounds one kind of work, is documented in ``doc/outputs.md`` and can be
raised through the environment variable named beside it. Hitting a cap is an
error of one line naming the file and the cap, never a traceback.
"""

from __future__ import annotations

import os


def _cap(name: str, default: int) -> int:
    text = os.environ.get(name, '').strip()
    return int(text) if text.isdigit() and int(text) > 0 else default


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

RATE_MAX_PREDICTIONS = _cap('SATMOTOR_RATE_MAX_PREDICTIONS', 20_000_000)
"""Most predictions ``replay --mode rate`` makes (5.5 h at 1 kHz; about 5 GB of results), [-]."""

CSV_MAX_COLUMNS = _cap('SATMOTOR_CSV_MAX_COLUMNS', 256)
"""Most columns of a CSV or text log read; calibration's work grows with each, [-]."""

PLOT_MAX_PANELS = _cap('SATMOTOR_PLOT_MAX_PANELS', 24)
"""Most panels of a report's residual grid (24: 960 x 1920 pixels), [-]."""


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


__all__ = ['BAG_FLOOR_BYTES', 'BAG_MAX_BYTES', 'BAG_MAX_RATIO', 'CSV_MAX_COLUMNS',
           'PLOT_MAX_PANELS', 'RATE_MAX_PREDICTIONS', 'YAML_MAX_BYTES',
           'YAML_MAX_DEPTH', 'YAML_MAX_DIGITS', 'YAML_MAX_NODES', 'bag_budget']
