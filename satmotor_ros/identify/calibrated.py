# SPDX-License-Identifier: Apache-2.0
"""
What a calibration wrote into a ``coefficients.yaml`` beside the model, read back once.

``satmotor calibrate`` writes the envelope its fit used (``coverage.envelope``,
:func:`~satmotor_ros.identify.coverage.envelope`) and, on a time series read with every
sample, the transient terms it fitted (``dynamics``,
:data:`~satmotor_ros.identify.transient.DYNAMIC_TERMS`) and the delay of the speed reading
(``speed_delay``, :mod:`~satmotor_ros.identify.delay`). ``validate`` reads both, the
health monitor the envelope; each block is checked when it is asked for, so a monitor is
not refused for a malformed block it does not use.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.bounded_yaml import read_yaml_or
from satmotor_ros.identify.coverage import DIRECTIONS
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.transient import DYNAMIC_TERMS


class Calibrated:
    """
    The blocks a calibration wrote into a motor file (``coverage``, ``dynamics``, ...).

    Parameters
    ----------
    path : str or pathlib.Path
        A motor file, [-]

    Raises
    ------
    DataError
        If the file cannot be read.

    """

    def __init__(self, path: str | Path) -> None:
        """Read the file's top-level blocks; a file that is no mapping has none."""
        self.path = path
        doc = read_yaml_or(path, DataError, str(path), str(path))
        self.blocks: dict[str, Any] = doc if isinstance(doc, dict) else {}

    @property
    def envelope(self) -> dict[str, Any] | None:
        """
        Return the envelope the model was fitted on, as :func:`~.coverage.envelope` gives it.

        None when the file holds none (a motor file that no calibration wrote); DataError
        naming the field when ``coverage.envelope`` is malformed.
        """
        if 'coverage' not in self.blocks:
            return None
        block = self.blocks['coverage']
        env = block.get('envelope') if isinstance(block, dict) else None
        if not isinstance(env, dict) or not set(env) <= {name for name, _ in DIRECTIONS}:
            msg = f'{self.path}: coverage.envelope = {env!r}: need a mapping of positive/negative'
            raise DataError(msg)
        for name, side in env.items():
            for key in ('dp_mpa', 'speed_rpm'):
                span = side.get(key) if isinstance(side, dict) else None
                if not (isinstance(span, list) and len(span) == 2
                        and all(isinstance(v, (int, float)) and np.isfinite(v) for v in span)
                        and span[0] <= span[1]):
                    msg = (f'{self.path}: coverage.envelope.{name}.{key} = {span!r}: '
                           'need [min, max]')
                    raise DataError(msg)
        return env

    @property
    def dynamics(self) -> dict[str, float] | None:
        """
        Return the transient terms: term name -> coefficient (SI).

        None when the file holds none (a motor file no calibration on every sample wrote);
        DataError naming the field when ``dynamics`` is malformed.
        """
        if 'dynamics' not in self.blocks:
            return None
        terms = self.blocks['dynamics']
        known = {term.name for term in DYNAMIC_TERMS}
        if not isinstance(terms, dict) or not set(terms) <= known:
            msg = (f'{self.path}: dynamics = {terms!r}: '
                   f'need a mapping of {", ".join(sorted(known))}')
            raise DataError(msg)
        for name, value in terms.items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not np.isfinite(value):
                msg = f'{self.path}: dynamics.{name} = {value!r}: need a finite number'
                raise DataError(msg)
        return {name: float(value) for name, value in terms.items()}

    @property
    def speed_delay(self) -> float | None:
        """
        Return the delay of the speed reading behind the flow reading, [s].

        None when the file holds none (no calibration on a time series wrote it); DataError
        naming the field when ``speed_delay.seconds`` is no finite number.
        """
        if 'speed_delay' not in self.blocks:
            return None
        block = self.blocks['speed_delay']
        value = block.get('seconds') if isinstance(block, dict) else None
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not np.isfinite(value):
            msg = f'{self.path}: speed_delay.seconds = {value!r}: need a finite number [s]'
            raise DataError(msg)
        return float(value)


__all__ = ['Calibrated']
