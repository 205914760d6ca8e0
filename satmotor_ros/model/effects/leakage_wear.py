# SPDX-License-Identifier: Apache-2.0
"""
``leakage_wear``: the leakage of a motor without modelled clearances grows with use.

The ``balawender`` and ``paszota`` families have no axial clearances h_R, h_S to
grow (``clearance_wear``), yet such motors wear too: their leakage grows. The
effect multiplies the family's leakage parts (:attr:`Family.leakage`: the laminar
and turbulent leakage of eqs. (20)-(23), the whole loss of eq. (29)) by
1 + max(0, w (x - reference)), x the time [s] or the shaft revolutions [rev].
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from satmotor_ros.model.effects._base import (Candidate, CandidateData, Conditions, Effect,
                                              EffectKind, maker, Modifier, PlantParameter,
                                              Synthetic, varies, why_not)

GROWTH = 0.5
"""Growth of the leakage over the data's span a typical rate stands for, [-]."""


class LeakageWear(EffectKind):
    """The leakage of a clearance-free family grows with time or revolutions."""

    name = 'leakage_wear'
    families = frozenset({'balawender', 'paszota'})  # sliwinski2017 wears its clearances
    rank = 61
    keys = ('regressor', 'coefficient', 'reference')
    required = ('coefficient', 'regressor', 'reference')
    regressors = ('time', 'revolutions')
    reads_channel = True
    drifts = True
    unit = '1/s or 1/rev'
    source = "the family's leakage times 1 + w x (wear)"
    evaluation = ("the family's leakage parts (balawender: laminar and turbulent, eqs. 20-23; "
                  'paszota: eq. 29) times 1 + max(0, w (x - reference)), x = time [s] or '
                  'cumulative revolutions [rev]')
    plant_parameters = (PlantParameter('leakage_wear', 0.0, 'relative growth of the leakage '
                                       'per shaft revolution (balawender, paszota)', '1/rev',
                                       0.0, 1.0e-2),)

    def condition(self, effect: Effect, x: float, now: Conditions) -> Conditions:
        """Multiply the leakage by 1 + max(0, w (x - reference))."""
        return now._replace(leakage=now.leakage
                            * (1.0 + max(effect.coefficient * (x - effect.reference), 0.0)))

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer a rate w >= 0 per exposure channel (time, revolutions) that varies."""
        out, skipped = [], []
        for name in self.regressors:
            exposure = data.channels.get(name)
            if exposure is None or not varies(exposure):
                skipped.append(f'{self.name}({name}): {why_not(exposure)}')
                continue
            start = float(np.min(exposure))
            x = exposure - start

            def modify(rate: float, x: np.ndarray = x) -> Modifier:
                return Modifier(leakage=1.0 + rate * x)

            typical = GROWTH / max(float(np.max(x)), 1e-300)
            out.append(Candidate(self.name, name, '1/s' if name == 'time' else '1/rev',
                                 self.source, exposure, modify, typical, (0.0, np.inf),
                                 make=maker(self.name, name, start)))
        return out, skipped

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Wear per revolution of the plant's shaft since its start; None at 0."""
        k = values['leakage_wear']
        return Effect(self.name, k, 'revolutions') if k else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the wear rate of `effect`."""
        return {'leakage_wear': 0.0 if effect is None else effect.coefficient}

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """Grow the leakage by the share `magnitude` [-] over the span of the regressor."""
        x = data.channels[regressor or self.regressors[0]]
        return Effect(name, magnitude / max(float(np.ptp(x)), 1e-300),
                      regressor or self.regressors[0], reference=float(np.min(x)))


KIND = LeakageWear()
