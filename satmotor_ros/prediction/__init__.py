# SPDX-License-Identifier: Apache-2.0
"""
Predictions of the motor model from its input topics, shared by the node and bag replay.

No ROS here: :mod:`.rule` holds the combination rule (latest value of each input, a
timeout, value checks naming the field), :mod:`.predict` the model call and its status;
each is written once for one message (floats) and a whole recording (arrays).
"""

from satmotor_ros.prediction.predict import (CHANNELS, describe, OUTPUTS, pick, predict,
                                             Prediction, PredictionBatch, Progress)
from satmotor_ros.prediction.rule import (combine_batch, Combiner, describe_input,
                                          driving_times, FIELDS, input_state, input_states,
                                          INPUTS, InputState, Level, MODES, REQUIRED, Rule,
                                          Snapshot, SnapshotBatch, TOPICS, UNITS)

__all__ = [
    'CHANNELS', 'Combiner', 'FIELDS', 'INPUTS', 'InputState', 'Level', 'MODES', 'OUTPUTS',
    'Prediction', 'PredictionBatch', 'Progress', 'REQUIRED', 'Rule', 'Snapshot',
    'SnapshotBatch', 'TOPICS', 'UNITS',
    'combine_batch', 'describe', 'describe_input', 'driving_times', 'input_state',
    'input_states', 'pick', 'predict',
]
