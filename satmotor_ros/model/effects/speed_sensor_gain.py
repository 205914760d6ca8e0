# SPDX-License-Identifier: Apache-2.0
"""``speed_sensor_gain``: the speed sensor reads (1 + g) n; the shaft turns at n."""

from satmotor_ros.model.effects._gain import GainError

KIND = GainError('speed_sensor_gain', 'speed', 'speed sensor', 30)
