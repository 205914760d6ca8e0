# SPDX-License-Identifier: Apache-2.0
"""
Predictions of the motor model from its input topics, shared by the node and bag replay.

No ROS here: :mod:`.rule` holds the combination rule (latest value of each input, a
timeout, value checks naming the field), :mod:`.predict` the model call and its status.
"""

from satmotor_ros.prediction.predict import (CHANNELS, OUTPUTS, predict_batch, predict_point,
                                             Prediction, PredictionBatch, Progress)
from satmotor_ros.prediction.rule import (check_value, check_values, combine_batch, Combiner,
                                          describe_input, driving_times, FIELDS, INPUTS,
                                          InputState, Level, MODES, REQUIRED, Rule, Snapshot,
                                          SnapshotBatch, TOPICS, UNITS)

__all__ = [
    'CHANNELS', 'Combiner', 'FIELDS', 'INPUTS', 'InputState', 'Level', 'MODES', 'OUTPUTS',
    'Prediction', 'PredictionBatch', 'Progress', 'REQUIRED', 'Rule', 'Snapshot',
    'SnapshotBatch', 'TOPICS', 'UNITS',
    'check_value', 'check_values', 'combine_batch', 'describe_input', 'driving_times',
    'predict_batch', 'predict_point',
]
