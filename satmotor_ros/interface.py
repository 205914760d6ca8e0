# SPDX-License-Identifier: Apache-2.0
"""
The DESIGN.md topic contract in one place: topic names, message types and fields.

Nodes, ``satmotor replay``, ``calibrate`` and ``demo``, the bag code and the tests import
their topic names, message types, message fields, loss components and default joint name
from here; nothing else spells a message type. No ROS and no physics: this module imports
nothing of the package, so reading a bag loads no model; message types are named by their
type strings (``'sensor_msgs/msg/FluidPressure'``) and the nodes map them to classes.

Beyond DESIGN.md (documented here and in doc/interface.md): ``motor_model`` may also
publish the loss breakdown as one ``std_msgs/Float64MultiArray`` on ``losses``
(:data:`LOSSES_ARRAY`), its layout naming the components (:data:`LOSS_COMPONENTS` order);
``speed_controller`` reads its set-point on :data:`SPEED_SETPOINT`; every node reports on
:data:`DIAGNOSTICS`. The motor and liquid options are :mod:`satmotor_ros.options`.
"""

from __future__ import annotations

from typing import NamedTuple

FLOAT64 = 'std_msgs/msg/Float64'
FLOAT64_ARRAY = 'std_msgs/msg/Float64MultiArray'
FLUID_PRESSURE = 'sensor_msgs/msg/FluidPressure'
TEMPERATURE = 'sensor_msgs/msg/Temperature'
JOINT_STATE = 'sensor_msgs/msg/JointState'
DIAGNOSTIC_ARRAY = 'diagnostic_msgs/msg/DiagnosticArray'
CLOCK = 'rosgraph_msgs/msg/Clock'

LOSS_COMPONENTS = ('flat_clearance', 'commutation', 'compressibility', 'deformation',
                   'backlash', 'inertia', 'external', 'total')
"""The ``<component>`` of ``losses/<component>``: the model's loss breakdown fields."""

JOINT_NAME = 'motor_shaft'
"""Default joint name of every JointState the nodes read or write."""

PREDICTED_JOINT_STATE = 'predicted_joint_state'
SPEED_RESIDUAL = 'speed_residual'
LOSSES_PREFIX = 'losses/'
LOSSES_ARRAY = 'losses'
"""One Float64MultiArray with every component (an addition to DESIGN.md, optional)."""

SPEED_SETPOINT = 'speed_setpoint'
"""The speed controller's set-point (std_msgs/Float64, rad/s), relative to its namespace."""

DIAGNOSTICS = '/diagnostics'
"""Where every node reports its state (diagnostic_msgs/DiagnosticArray), absolute."""

CLOCK_TOPIC = '/clock'
"""Simulated time (rosgraph_msgs/Clock), absolute."""

HEALTH_TOPICS = ('health/leakage_factor', 'health/volumetric_efficiency',
                 'health/hours_to_limit')
"""What ``motor_monitor`` publishes (std_msgs/Float64): the factor, eta_v and the hours [h]."""

TOPIC_TYPES = {
    'flow_command': FLOAT64, 'inlet_pressure': FLUID_PRESSURE,
    'outlet_pressure': FLUID_PRESSURE, 'case_pressure': FLUID_PRESSURE,
    'fluid_temperature': TEMPERATURE, 'flow_measured': FLOAT64, 'joint_states': JOINT_STATE,
    'load_torque': FLOAT64, PREDICTED_JOINT_STATE: JOINT_STATE, SPEED_RESIDUAL: FLOAT64,
    **{LOSSES_PREFIX + c: FLOAT64 for c in LOSS_COMPONENTS},
    **dict.fromkeys(HEALTH_TOPICS, FLOAT64),
}
"""Each DESIGN.md topic (relative name) and its message type."""

VALUE_FIELD = {FLOAT64: 'data', FLUID_PRESSURE: 'fluid_pressure', TEMPERATURE: 'temperature',
               JOINT_STATE: 'velocity'}
"""The number a message of each single-value type carries (JointState: the joint's velocity)."""

MODEL_OUTPUTS = (PREDICTED_JOINT_STATE, SPEED_RESIDUAL, LOSSES_PREFIX, LOSSES_ARRAY)
"""What ``motor_model`` publishes (``losses/`` as a prefix): predictions, not measurements."""


class Channel(NamedTuple):
    """Where a measured quantity travels: topic, message field and unit."""

    topic: str  # relative topic name
    field: str  # message field (JointState: of the joint named by the joint parameter)
    unit: str  # SI unit on the topic


CHANNELS = {
    'flow': Channel('flow_command', 'data', 'm^3/s'),
    'p_in': Channel('inlet_pressure', 'fluid_pressure', 'Pa'),
    'p_out': Channel('outlet_pressure', 'fluid_pressure', 'Pa'),
    'p_case': Channel('case_pressure', 'fluid_pressure', 'Pa'),
    'temperature': Channel('fluid_temperature', 'temperature', 'degC'),
    'measured_speed': Channel('joint_states', 'velocity', 'rad/s'),
    'flow_measured': Channel('flow_measured', 'data', 'm^3/s'),
    'torque': Channel('load_torque', 'data', 'N*m'),
}
"""
Each measured quantity by its short name (the bench-table column where there is one).

Signs (doc/quadrants.md): ``p_in`` and ``p_out`` are the pressures at ports A and B, the
flow is positive entering port A, and every flow and JointState velocity keeps its sign.
"""

PREDICTION_INPUTS = ('flow', 'p_in', 'p_out', 'p_case', 'temperature', 'measured_speed')
"""The :data:`CHANNELS` a ``motor_model`` prediction reads, in its order."""

PRESSURE_TOPICS = ('inlet_pressure', 'outlet_pressure', 'case_pressure')
"""The FluidPressure topics, in the order the plant reads them."""

__all__ = [
    'CHANNELS', 'CLOCK', 'CLOCK_TOPIC', 'Channel', 'DIAGNOSTICS', 'DIAGNOSTIC_ARRAY', 'FLOAT64',
    'FLOAT64_ARRAY', 'FLUID_PRESSURE', 'HEALTH_TOPICS', 'JOINT_NAME', 'JOINT_STATE',
    'LOSSES_ARRAY', 'LOSSES_PREFIX', 'LOSS_COMPONENTS', 'MODEL_OUTPUTS', 'PREDICTED_JOINT_STATE',
    'PREDICTION_INPUTS', 'PRESSURE_TOPICS', 'SPEED_RESIDUAL', 'SPEED_SETPOINT', 'TEMPERATURE',
    'TOPIC_TYPES', 'VALUE_FIELD',
]
