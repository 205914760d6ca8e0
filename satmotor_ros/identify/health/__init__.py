# SPDX-License-Identifier: Apache-2.0
"""
Motor health over time: the leakage factor against a baseline, its trend, changes and limits.

No ROS here. :class:`HealthMonitor` takes :class:`HealthSamples` a block at a time against a
:class:`Baseline` (a calibrated ``coefficients.yaml`` or a family at a displacement) and
keeps, at constant cost and memory, what :class:`HealthSnapshot` reports; the ``motor_monitor``
node, ``satmotor monitor`` and ``satmotor fleet`` are its doors (doc/health.md).
"""

from satmotor_ros.identify.health.baseline import Baseline, Losses
from satmotor_ros.identify.health.monitor import Explainer, HealthMonitor
from satmotor_ros.identify.health.records import (Alarm, Estimate, HealthPoint, HealthSamples,
                                                  HealthSettings, HealthSnapshot, SKIP_REASONS)

__all__ = ['Alarm', 'Baseline', 'Estimate', 'Explainer', 'HealthMonitor', 'HealthPoint',
           'HealthSamples', 'HealthSettings', 'HealthSnapshot', 'Losses', 'SKIP_REASONS']
