# SPDX-License-Identifier: Apache-2.0
"""
Calibration against measured data: load, fit, find the missing effects one by one, add them.

No ROS here (scipy is allowed). The pieces are kept apart as PySINDy keeps
library, optimizer and model apart: :mod:`.table` and :mod:`.steady` bring
data in, :mod:`.parts` evaluates the model at the measured points,
:mod:`.candidates` is the library of candidate effects, :mod:`.fit` the
bounded, weighted and robust least-squares fitter, :mod:`.noise` the noise
model and outliers, :mod:`.selection` the cross-validated forward selector,
and :mod:`.pipeline` composes them; :mod:`.output` and
:mod:`.report` write the results, :mod:`.synthetic` makes test data.
"""

from satmotor_ros.identify.candidates import build_library, Candidate
from satmotor_ros.identify.errors import DataError, IdentificationError
from satmotor_ros.identify.fit import check_identifiable, FitReport, LossFit
from satmotor_ros.identify.parts import Component, loss_parts, LossParts, predict_flow
from satmotor_ros.identify.pipeline import calibrate, Calibration, Options, steady_points
from satmotor_ros.identify.selection import CrossValidatedSelector, Errors, Forward, Selection
from satmotor_ros.identify.steady import extract_steady, SteadyTolerance
from satmotor_ros.identify.table import BenchTable, read_csv, REQUIRED, write_csv
from satmotor_ros.model.effects import Modifier
from satmotor_ros.model.viscosity import standard_law, ViscosityLaw

__all__ = [
    'BenchTable', 'Calibration', 'Candidate', 'Component', 'CrossValidatedSelector',
    'DataError', 'Errors', 'FitReport', 'Forward', 'IdentificationError', 'LossFit',
    'LossParts', 'Modifier', 'Options', 'REQUIRED', 'Selection', 'SteadyTolerance',
    'ViscosityLaw', 'build_library',
    'calibrate', 'check_identifiable', 'extract_steady', 'loss_parts', 'predict_flow',
    'read_csv', 'standard_law', 'steady_points', 'write_csv',
]
