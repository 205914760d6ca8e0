# SPDX-License-Identifier: Apache-2.0
"""``speed_sensor_gain``: the speed sensor reads (1 + g) n; the shaft turns at n."""

from __future__ import annotations

from satmotor_ros.model.effects._base import (Candidate, CandidateData, Modifier, per_unit,
                                              PlantParameter)
from satmotor_ros.model.effects._gain import GainError


class SpeedSensorGain(GainError):
    """A speed-sensor calibration error."""

    name = 'speed_sensor_gain'
    rank = 30
    sensor = 'speed'
    source = 'speed-sensor calibration error'
    evaluation = 'the speed sensor reads (1 + g) n; the shaft turns at n'
    plant_parameters = (PlantParameter('speed_sensor_gain', 0.0, 'relative gain error of the '
                                       'speed sensor', '-', -0.5, 0.5),)

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer g within +-0.5."""
        parts = data.parts
        return [Candidate(self.name, 'speed', self.unit, self.source, parts.speed,
                          lambda g: Modifier(speed_gain=1.0 + g), per_unit(parts.displacement),
                          (-0.5, 0.5))], []


KIND = SpeedSensorGain()
