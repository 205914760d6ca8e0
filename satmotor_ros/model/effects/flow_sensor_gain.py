# SPDX-License-Identifier: Apache-2.0
"""``flow_sensor_gain``: the flowmeter reads (1 + g) Q; the motor absorbs Q."""

from satmotor_ros.model.effects._gain import GainError

KIND = GainError('flow_sensor_gain', 'flow', 'flowmeter', 20)
