# SPDX-License-Identifier: Apache-2.0
"""
The virtual motor plant: the model's motor on a test rig, stepped in fixed time steps.

No ROS here: the ``virtual_motor`` node is a thin adapter over :class:`Plant`.
"""

from satmotor_ros.plant.errors import PlantError
from satmotor_ros.plant.load import (ConstantLoad, LOAD_KINDS, LoadProfile, make_load,
                                     RampLoad, SpeedProportionalLoad, StepLoad)
from satmotor_ros.plant.motor import MotorCache
from satmotor_ros.plant.params import (CaseParams, LineParams, PlantParams,
                                       ReliefParams, SENSOR_CHANNELS, SensorParams, SensorSet,
                                       ShaftParams, ThermalParams)
from satmotor_ros.plant.plant import (MAX_FLOW_COMMAND, Measurement, Plant, PlantState,
                                      StepFlows)

__all__ = [
    'CaseParams', 'ConstantLoad', 'LOAD_KINDS', 'LineParams', 'LoadProfile',
    'MAX_FLOW_COMMAND', 'Measurement', 'MotorCache', 'Plant', 'PlantError', 'PlantParams',
    'PlantState', 'RampLoad', 'ReliefParams', 'SENSOR_CHANNELS', 'SensorParams', 'SensorSet',
    'ShaftParams', 'SpeedProportionalLoad', 'StepFlows', 'StepLoad', 'ThermalParams',
    'make_load',
]
