# SPDX-License-Identifier: Apache-2.0
"""
Volumetric losses and effective speed of the hydraulic satellite motor.

Pure numpy, SI at every interface. Implements the model of P. Śliwiński,
"The influence of water and mineral oil on volumetric losses in a hydraulic
motor", Polish Maritime Research 24 (2017): one function per equation in
:mod:`.losses` and :mod:`.speed`, composed by :class:`MotorModel`.
"""

from satmotor_ros.model.coefficients import (CoefficientSet, Liquid, LossCoefficients,
                                             MotorGeometry, ValidRange)
from satmotor_ros.model.errors import ConfigError, InvalidInputError, ModelError, UnitError
from satmotor_ros.model.io.config import (default_config_path, liquid_from_mapping, load_motor,
                                          MotorSpec)
from satmotor_ros.model.motor import MotorModel
from satmotor_ros.model.results import (COMPONENTS, describe_status, INVALID, LossBreakdown,
                                        OperatingPoints, Point, PointStatus)

__all__ = [
    'COMPONENTS', 'CoefficientSet', 'ConfigError', 'INVALID', 'InvalidInputError', 'Liquid',
    'LossBreakdown', 'LossCoefficients', 'ModelError', 'MotorGeometry', 'MotorModel',
    'MotorSpec', 'OperatingPoints', 'Point', 'PointStatus', 'UnitError', 'ValidRange',
    'default_config_path', 'describe_status', 'liquid_from_mapping', 'load_motor',
]
