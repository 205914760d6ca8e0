# SPDX-License-Identifier: Apache-2.0
"""``flow_sensor_offset``: the flowmeter reads Q + b; the motor absorbs Q."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from satmotor_ros.model.effects._base import (Candidate, CandidateData, Effect, EffectKind,
                                              Modifier, PlantParameter, SensorError)
from satmotor_ros.model.units import LPM


class FlowSensorOffset(EffectKind):
    """A flowmeter zero error."""

    name = 'flow_sensor_offset'
    rank = 10
    sensor = 'flow'
    unit = 'm^3/s'
    source = 'flowmeter zero error'
    evaluation = 'the flowmeter reads Q + b; the motor absorbs Q'
    plant_parameters = (PlantParameter('flow_sensor_offset', 0.0, 'added to the measured flow',
                                       'm^3/s', -1.0e-2, 1.0e-2),)

    def sensor_error(self, effect: Effect) -> SensorError:
        """Add b to the flow reading."""
        return SensorError('flow', 1.0, effect.coefficient)

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer b within +-50 l/min."""
        return [Candidate(self.name, '1', self.unit, self.source, data.parts.flow,
                          lambda b: Modifier(offset=b), LPM, (-50 * LPM, 50 * LPM))], []

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Return the offset the node parameter sets, None at 0."""
        b = values[self.name]
        return Effect(self.name, b, '1') if b else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the offset of `effect`."""
        return {self.name: 0.0 if effect is None else effect.coefficient}


KIND = FlowSensorOffset()
