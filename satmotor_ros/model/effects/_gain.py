# SPDX-License-Identifier: Apache-2.0
"""What the two sensor gain errors share: reading = (1 + g) value, |g| < 0.5."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from satmotor_ros.model.effects._base import (Candidate, CandidateData, Effect, EffectKind,
                                              finite, Modifier, per_unit, PlantParameter,
                                              SensorError)
from satmotor_ros.model.errors import ConfigError


class GainError(EffectKind):
    """A relative gain error g of the instrument on :attr:`sensor` (``flow`` or ``speed``)."""

    unit = '-'

    def __init__(self, name: str, sensor: str, instrument: str, rank: int) -> None:
        """Name the kind, its channel and its instrument (e.g. 'flowmeter')."""
        self.name, self.sensor, self.rank = name, sensor, rank
        self.source = f'{instrument.replace(" ", "-")} calibration error'
        symbol = 'Q' if sensor == 'flow' else 'n'
        self.evaluation = (f'the {instrument} reads (1 + g) {symbol}; the '
                           f'{"motor absorbs Q" if sensor == "flow" else "shaft turns at n"}')
        self.plant_parameters = (PlantParameter(name, 0.0, f'relative gain error of the '
                                                f'{instrument}', '-', -0.5, 0.5),)

    def parse(self, name: str, doc: Mapping[str, Any], where: str) -> Effect:
        """Refuse a gain error outside (-0.5, 0.5)."""
        k = finite(doc['coefficient'], f'{where}.coefficient')
        if not -0.5 < k < 0.5:
            msg = f'{where}.coefficient = {k!r}: a sensor gain error lies in (-0.5, 0.5)'
            raise ConfigError(msg)
        return super().parse(name, doc, where)

    def sensor_error(self, effect: Effect) -> SensorError:
        """Multiply the reading by 1 + g."""
        return SensorError(self.sensor, 1.0 + effect.coefficient, 0.0)

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer g within +-0.5; 1 l/min of typical change at the largest flow (or q_t n)."""
        parts = data.parts
        values = parts.flow if self.sensor == 'flow' else parts.speed
        typical = per_unit(parts.flow if self.sensor == 'flow' else parts.displacement)
        key = f'{self.sensor}_gain'
        return [Candidate(self.name, self.sensor, self.unit, self.source, values,
                          lambda g: Modifier(**{key: 1.0 + g}), typical, (-0.5, 0.5))], []

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Return the gain error the node parameter sets, None at 0."""
        g = values[self.name]
        return Effect(self.name, g, self.sensor) if g else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the gain error of `effect`."""
        return {self.name: 0.0 if effect is None else effect.coefficient}
