# SPDX-License-Identifier: Apache-2.0
"""
What the two wear kinds share: a growth w (x - reference) >= 0, x the time or revolutions.

In the virtual motor a wear grows with the shaft's revolutions (``effects.<name>``) or with
the plant's running time, its operating hours (``effects.<name>_rate``, per second): one of
the two.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects._base import (Candidate, CandidateData, Effect, EffectKind,
                                              maker, Modifier, Parts, Synthetic, varies,
                                              why_not)
from satmotor_ros.model.errors import ConfigError


class Wear(EffectKind):
    """A part of the motor grows with its exposure: time [s] or shaft revolutions [rev]."""

    keys = ('regressor', 'coefficient', 'reference')
    required = ('coefficient', 'regressor', 'reference')
    regressors = ('time', 'revolutions')
    reads_channel = True
    drifts = True
    per = ''
    """Unit of the grown quantity per unit of exposure, before '/s' or '/rev'."""

    def modifier(self, parts: Parts, x: FloatArray) -> Callable[[float], Modifier]:
        """Return rate -> the modifier of the parts grown by rate * x."""
        raise NotImplementedError

    def typical(self, parts: Parts, span: float) -> float:
        """Return a typical rate over an exposure of `span`."""
        raise NotImplementedError

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer a wear rate w >= 0 per exposure channel (time, revolutions) that varies."""
        out, skipped = [], []
        for name in self.regressors:
            exposure = data.channels.get(name)
            # the exposure counts from its start: a clock's epoch (1.6e9 s) is no spread
            start = float(np.min(exposure)) if exposure is not None and exposure.size else 0.0
            if exposure is None or not varies(exposure - start):
                skipped.append(f'{self.name}({name}): {why_not(exposure)}')
                continue
            x = exposure - start
            typical = self.typical(data.parts, max(float(np.max(x)), 1e-300))
            unit = f'{self.per}/s' if name == 'time' else f'{self.per}/rev'
            out.append(Candidate(self.name, name, unit, self.source, exposure,
                                 self.modifier(data.parts, x), typical, (0.0, np.inf),
                                 make=maker(self.name, name, start)))
        return out, skipped

    @property
    def rate_parameter(self) -> str:
        """Name the node parameter of the growth per second of running time."""
        return f'{self.name}_rate'

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """
        Wear per revolution of the plant's shaft, or per second of its time; None at 0.

        Raises
        ------
        ConfigError
            If both are set: a wear grows with one exposure.

        """
        per_rev, per_s = values[self.name], values[self.rate_parameter]
        if per_rev and per_s:
            msg = (f'effects.{self.name} = {per_rev!r} and effects.{self.rate_parameter} = '
                   f'{per_s!r}: a wear grows with revolutions or with time, set one')
            raise ConfigError(msg)
        if per_s:
            return Effect(self.name, per_s, 'time')
        return Effect(self.name, per_rev, 'revolutions') if per_rev else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the wear rate of `effect`, per revolution or per second."""
        values: dict[str, Any] = {self.name: 0.0, self.rate_parameter: 0.0}
        if effect is not None:
            key = self.rate_parameter if effect.regressor == 'time' else self.name
            values[key] = effect.coefficient
        return values

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """Grow the part by `magnitude` over the span of the regressor."""
        x = data.channels[regressor or self.regressors[0]]
        return Effect(name, magnitude / max(float(np.ptp(x)), 1e-300),
                      regressor or self.regressors[0], reference=float(np.min(x)))
