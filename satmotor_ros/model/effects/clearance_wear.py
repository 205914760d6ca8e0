# SPDX-License-Identifier: Apache-2.0
"""``clearance_wear``: h_R and h_S grow by k (x - reference) >= 0 in eqs. (1), (2) and (5)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects._base import (Candidate, CandidateData, Conditions, Effect,
                                              EffectKind, maker, Modifier, Parts,
                                              PlantParameter, Synthetic, varies, why_not)


class ClearanceWear(EffectKind):
    """Both axial clearances grow with time [s] or shaft revolutions [rev]."""

    name = 'clearance_wear'
    families = frozenset({'sliwinski2017'})  # the others have no axial clearances h_R, h_S
    rank = 60
    keys = ('regressor', 'coefficient', 'reference')
    required = ('coefficient', 'regressor', 'reference')
    regressors = ('time', 'revolutions')
    reads_channel = True
    drifts = True
    unit = 'm/s or m/rev'
    source = 'eqs. (1), (2), (5) with h + w x'
    evaluation = ('h_R and h_S grow by w (x - reference), x = time [s] or cumulative '
                  'revolutions [rev], in eqs. (1), (2) and (5)')
    plant_parameters = (PlantParameter('clearance_wear', 0.0, 'growth of h_R and h_S per '
                                       'shaft revolution', 'm/rev', 0.0, 1.0e-6),)

    def condition(self, effect: Effect, x: float, now: Conditions) -> Conditions:
        """Grow the clearances by k (x - reference), never below 0."""
        return now._replace(growth=now.growth
                            + max(effect.coefficient * (x - effect.reference), 0.0))

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer a wear rate w >= 0 per exposure channel (time, revolutions) that varies."""
        out, skipped = [], []
        parts = data.parts
        for name in self.regressors:
            exposure = data.channels.get(name)
            if exposure is None or not varies(exposure):
                skipped.append(f'{self.name}({name}): {why_not(exposure)}')
                continue
            start = float(np.min(exposure))
            x = exposure - start

            modify = _wear_modifier(parts, x)

            typical = float(np.mean(parts.clearance)) * 0.05 / max(float(np.max(x)), 1e-300)
            unit = 'm/s' if name == 'time' else 'm/rev'
            out.append(Candidate(
                self.name, name, unit, self.source, exposure, modify, typical, (0.0, np.inf),
                make=maker(self.name, name, start)))
        return out, skipped

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Wear per revolution of the plant's shaft since its start; None at 0."""
        k = values['clearance_wear']
        return Effect(self.name, k, 'revolutions') if k else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the wear rate of `effect`."""
        return {'clearance_wear': 0.0 if effect is None else effect.coefficient}

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """Grow the clearances by `magnitude` [m] over the span of the regressor."""
        x = data.channels[regressor or self.regressors[0]]
        return Effect(name, magnitude / max(float(np.ptp(x)), 1e-300),
                      regressor or self.regressors[0], reference=float(np.min(x)))


def _wear_modifier(parts: Parts, x: FloatArray) -> Callable[[float], Modifier]:
    """Return rate -> the factors on Q_Lfg and Q_C of clearances grown by rate * x."""
    def modify(rate: float) -> Modifier:
        grow = rate * x
        return Modifier(flat_clearance=(1.0 + grow / parts.clearance) ** parts.h_exponent,
                        commutation=(1.0 + grow / parts.clearance_satellites)
                        ** parts.hs_exponent)
    return modify


KIND = ClearanceWear()
