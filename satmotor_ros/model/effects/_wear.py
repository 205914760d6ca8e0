# SPDX-License-Identifier: Apache-2.0
"""What the two wear kinds share: a growth w (x - reference) >= 0, x the time or revolutions."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects._base import (Candidate, CandidateData, Effect, EffectKind,
                                              maker, Modifier, Parts, Synthetic, varies,
                                              why_not)


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
            if exposure is None or not varies(exposure):
                skipped.append(f'{self.name}({name}): {why_not(exposure)}')
                continue
            start = float(np.min(exposure))
            x = exposure - start
            typical = self.typical(data.parts, max(float(np.max(x)), 1e-300))
            unit = f'{self.per}/s' if name == 'time' else f'{self.per}/rev'
            out.append(Candidate(self.name, name, unit, self.source, exposure,
                                 self.modifier(data.parts, x), typical, (0.0, np.inf),
                                 make=maker(self.name, name, start)))
        return out, skipped

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Wear per revolution of the plant's shaft since its start; None at 0."""
        k = values[self.name]
        return Effect(self.name, k, 'revolutions') if k else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the wear rate of `effect`."""
        return {self.name: 0.0 if effect is None else effect.coefficient}

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """Grow the part by `magnitude` over the span of the regressor."""
        x = data.channels[regressor or self.regressors[0]]
        return Effect(name, magnitude / max(float(np.ptp(x)), 1e-300),
                      regressor or self.regressors[0], reference=float(np.min(x)))
