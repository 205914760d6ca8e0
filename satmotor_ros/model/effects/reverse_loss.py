# SPDX-License-Identifier: Apache-2.0
"""``reverse_loss``: an extra loss k |dp_i| |n| in Q_vl while the shaft turns backwards."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from satmotor_ros.model._typing import Real
from satmotor_ros.model.effects._base import (additive, Candidate, CandidateData, Effect,
                                              EffectKind, Loss, maker, PlantParameter,
                                              Synthetic)

MIN_POINTS = 3
"""Points the data must hold in each direction of rotation for the candidate to be offered."""


class ReverseLoss(EffectKind):
    """
    A loss that differs between the two directions of rotation.

    The paper's eq. (33) has one C for the loss per revolution that grows with the
    chamber drop (compressibility, deformation, backlash: eqs. 11-13). A motor whose
    commutation or clearances are not symmetric loses more (k > 0) or less (k < 0) per
    revolution when it turns backwards. The term k |dp_i| |n| is 0 at rest, where the
    direction is undefined, so the model stays continuous through zero speed.
    """

    name = 'reverse_loss'
    rank = 75
    directional = True
    reverse = True
    unit = 'm^3/(Pa*rad)'
    source = 'direction of rotation: C of eq. (33) differs when n < 0'
    evaluation = ('extra loss k |dp_i| |n| added to Q_vl (eq. 31) while the shaft turns '
                  'backwards (n < 0), running with the other losses from the high- to the '
                  'low-pressure port')
    plant_parameters = (PlantParameter(
        'reverse_loss', 0.0, 'extra loss k |dp_i| |n| while the shaft turns backwards',
        'm^3/(Pa*rad)', -1e-12, 1e-12),)

    def loss(self, effect: Effect) -> Loss | None:
        """Return k dp_i n at the magnitudes (the model calls it only when n < 0)."""
        k = effect.coefficient

        def loss(n: Real, dp_i: Real) -> Real:
            return k * dp_i * n
        return loss

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer k where the data hold both directions of rotation."""
        parts = data.parts
        rotation = np.broadcast_to(np.asarray(getattr(parts, 'rotation', 1.0)),
                                   parts.speed.shape)
        counts = int((rotation > 0.0).sum()), int((rotation < 0.0).sum())
        if min(counts) < MIN_POINTS:
            return [], [f'{self.name}: the data turn one way only ({counts[0]} points '
                        f'forward, {counts[1]} backwards; {MIN_POINTS} each needed)']
        x = np.where(rotation < 0.0, parts.dp_i * parts.speed, 0.0)
        return [additive(self.name, '', self.unit, self.source, x, make=maker(self.name))], []

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Return the effect the node parameter sets, None at 0."""
        k = values[self.name]
        return Effect(self.name, k) if k else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the coefficient of `effect`."""
        return {self.name: 0.0 if effect is None else effect.coefficient}

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """Make the largest extra loss over the backward points `magnitude` [m^3/s]."""
        rotation = np.broadcast_to(np.asarray(data.rotation), np.shape(data.speed))
        x = np.where(rotation < 0.0, np.abs(data.dp_i * data.speed), 0.0)
        return Effect(name, magnitude / max(float(np.max(x, initial=0.0)), 1e-300))


KIND = ReverseLoss()
