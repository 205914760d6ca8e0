# SPDX-License-Identifier: Apache-2.0
"""``flow_sensor_gain``: the flowmeter reads (1 + g) Q; the motor absorbs Q."""

from __future__ import annotations

from satmotor_ros.model.effects._base import (Candidate, CandidateData, Modifier, per_unit,
                                              PlantParameter)
from satmotor_ros.model.effects._gain import GainError


class FlowSensorGain(GainError):
    """A flowmeter calibration error."""

    name = 'flow_sensor_gain'
    rank = 20
    sensor = 'flow'
    source = 'flowmeter calibration error'
    evaluation = 'the flowmeter reads (1 + g) Q; the motor absorbs Q'
    plant_parameters = (PlantParameter('flow_sensor_gain', 0.0, 'relative gain error of the '
                                       'flowmeter', '-', -0.5, 0.5),)

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer g within +-0.5."""
        flow = data.parts.flow
        return [Candidate(self.name, 'flow', self.unit, self.source, flow,
                          lambda g: Modifier(flow_gain=1.0 + g), per_unit(flow),
                          (-0.5, 0.5))], []


KIND = FlowSensorGain()
