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

from collections.abc import Callable

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects._base import Conditions, Effect, Modifier, Parts, PlantParameter
from satmotor_ros.model.effects._wear import Wear

GROWTH = 0.5
"""Growth of the leakage over the data's span a typical rate stands for, [-]."""


class LeakageWear(Wear):
    """The leakage of a clearance-free family grows with time or revolutions."""

    name = 'leakage_wear'
    families = frozenset({'balawender', 'paszota'})  # sliwinski2017 wears its clearances
    rank = 61
    unit = '1/s or 1/rev'
    per = '1'
    source = "the family's leakage times 1 + w x (wear)"
    evaluation = ("the family's leakage parts (balawender: laminar and turbulent, eqs. 20-23; "
                  'paszota: eq. 29) times 1 + max(0, w (x - reference)), x = time [s] or '
                  'cumulative revolutions [rev]')
    plant_parameters = (PlantParameter('leakage_wear', 0.0, 'relative growth of the leakage '
                                       'per shaft revolution (balawender, paszota)', '1/rev',
                                       0.0, 1.0e-2),
                        PlantParameter('leakage_wear_rate', 0.0, 'relative growth of the '
                                       "leakage per second of the plant's running time "
                                       '(operating hours; balawender, paszota); not with '
                                       'leakage_wear', '1/s', 0.0, 1.0e-2))

    def condition(self, effect: Effect, x: float, now: Conditions) -> Conditions:
        """Multiply the leakage by 1 + max(0, w (x - reference))."""
        return now._replace(leakage=now.leakage
                            * (1.0 + max(effect.coefficient * (x - effect.reference), 0.0)))

    def modifier(self, parts: Parts, x: FloatArray) -> Callable[[float], Modifier]:
        """Return rate -> the leakage grown by 1 + rate * x."""
        def modify(rate: float) -> Modifier:
            return Modifier(leakage=1.0 + rate * x)
        return modify

    def typical(self, parts: Parts, span: float) -> float:
        """Return the rate that grows the leakage by :data:`GROWTH` over `span`."""
        return GROWTH / span


KIND = LeakageWear()
