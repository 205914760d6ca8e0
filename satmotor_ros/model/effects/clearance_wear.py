# SPDX-License-Identifier: Apache-2.0
"""``clearance_wear``: h_R and h_S grow by k (x - reference) >= 0 in eqs. (1), (2) and (5)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects._base import Conditions, Effect, Modifier, Parts, PlantParameter
from satmotor_ros.model.effects._wear import Wear


class ClearanceWear(Wear):
    """Both axial clearances grow with time [s] or shaft revolutions [rev]."""

    name = 'clearance_wear'
    families = frozenset({'sliwinski2017'})  # the others have no axial clearances h_R, h_S
    rank = 60
    unit = 'm/s or m/rev'
    per = 'm'
    source = 'eqs. (1), (2), (5) with h + w x'
    evaluation = ('h_R and h_S grow by w (x - reference), x = time [s] or cumulative '
                  'revolutions [rev], in eqs. (1), (2) and (5)')
    plant_parameters = (PlantParameter('clearance_wear', 0.0, 'growth of h_R and h_S per '
                                       'shaft revolution', 'm/rev', 0.0, 1.0e-6),
                        PlantParameter('clearance_wear_rate', 0.0, 'growth of h_R and h_S per '
                                       "second of the plant's running time (operating hours); "
                                       'not with clearance_wear', 'm/s', 0.0, 1.0e-6))

    def condition(self, effect: Effect, x: float, now: Conditions) -> Conditions:
        """Grow the clearances by k (x - reference), never below 0."""
        return now._replace(growth=now.growth
                            + max(effect.coefficient * (x - effect.reference), 0.0))

    def modifier(self, parts: Parts, x: FloatArray) -> Callable[[float], Modifier]:
        """Return rate -> the factors on Q_Lfg and Q_C of clearances grown by rate * x."""
        def modify(rate: float) -> Modifier:
            grow = rate * x
            return Modifier(flat_clearance=(1.0 + grow / parts.clearance) ** parts.h_exponent,
                            commutation=(1.0 + grow / parts.clearance_satellites)
                            ** parts.hs_exponent)
        return modify

    def typical(self, parts: Parts, span: float) -> float:
        """Return the rate that grows the clearances by 5 % over `span`."""
        return float(np.mean(parts.clearance)) * 0.05 / span


KIND = ClearanceWear()
