# SPDX-License-Identifier: Apache-2.0
"""The interface contract in one module: topics, types, fields; and the motor options."""

import ast
import dataclasses
from pathlib import Path
import re
import subprocess
import sys

import pytest

from satmotor_ros.interface import (CHANNELS, JOINT_NAME, LOSS_COMPONENTS, PREDICTION_INPUTS,
                                    TOPIC_TYPES, VALUE_FIELD)
from satmotor_ros.model import COMPONENTS, MotorModel
from satmotor_ros.options import MotorOptions, OptionError

PACKAGE = Path(__file__).resolve().parents[1] / 'satmotor_ros'

DESIGN_TABLE = {  # DESIGN.md's topic table, as written there
    'flow_command': 'std_msgs/msg/Float64', 'inlet_pressure': 'sensor_msgs/msg/FluidPressure',
    'outlet_pressure': 'sensor_msgs/msg/FluidPressure',
    'case_pressure': 'sensor_msgs/msg/FluidPressure',
    'fluid_temperature': 'sensor_msgs/msg/Temperature', 'flow_measured': 'std_msgs/msg/Float64',
    'joint_states': 'sensor_msgs/msg/JointState', 'load_torque': 'std_msgs/msg/Float64',
    'predicted_joint_state': 'sensor_msgs/msg/JointState',
    'speed_residual': 'std_msgs/msg/Float64',
    'health/leakage_factor': 'std_msgs/msg/Float64',
    'health/volumetric_efficiency': 'std_msgs/msg/Float64',
    'health/hours_to_limit': 'std_msgs/msg/Float64',
}


def test_topic_table_is_the_design_table_plus_one_loss_topic_per_component():
    assert LOSS_COMPONENTS == COMPONENTS == (
        'flat_clearance', 'commutation', 'compressibility', 'deformation', 'backlash',
        'inertia', 'external', 'total')
    losses = {f'losses/{c}': 'std_msgs/msg/Float64' for c in LOSS_COMPONENTS}
    assert TOPIC_TYPES == {**DESIGN_TABLE, **losses}
    assert JOINT_NAME == 'motor_shaft'


def test_every_channel_is_a_design_topic_with_a_field_of_its_type():
    fields = {'std_msgs/msg/Float64': 'data', 'sensor_msgs/msg/FluidPressure': 'fluid_pressure',
              'sensor_msgs/msg/Temperature': 'temperature',
              'sensor_msgs/msg/JointState': 'velocity'}
    assert VALUE_FIELD == fields
    for name, channel in CHANNELS.items():
        assert fields[TOPIC_TYPES[channel.topic]] == channel.field, name
    assert set(PREDICTION_INPUTS) <= set(CHANNELS)


def test_default_options_build_the_packaged_oil_model():
    model = MotorOptions().build_model()
    packaged = MotorModel.default('oil')
    assert model.liquid == packaged.liquid and model.displacement_law == 'eq33'
    assert model.speed_point(1e-4, 1e7) == packaged.speed_point(1e-4, 1e7)


def test_user_liquid_overrides_only_the_properties_given():
    model = MotorOptions('water', viscosity=2e-6, bulk_modulus=2.0e9).build_model()
    own = MotorModel.default('water').liquid
    assert model.liquid == dataclasses.replace(own, name='user liquid on the water set',
                                               kinematic_viscosity=2e-6, bulk_modulus=2.0e9)


@pytest.mark.parametrize(('kwargs', 'option', 'text'), [
    ({'liquid': 'glycol'}, 'liquid', "liquid = 'glycol': not a coefficient set of SM-0,75/25"),
    ({'displacement_law': 'eq40'}, 'displacement_law', 'use one of eq33, eq39'),
    ({'viscosity': -1e-6}, 'viscosity', 'viscosity = -1e-06: must be a finite value'),
    ({'density': float('nan')}, 'density', 'density = nan'),
])
def test_bad_option_names_itself(kwargs, option, text):
    with pytest.raises(OptionError, match=text) as caught:
        MotorOptions(**kwargs).build_model()
    assert caught.value.option == option


def test_unreadable_motor_file_is_a_model_error_naming_it(tmp_path):
    with pytest.raises(ValueError, match='missing.yaml'):
        MotorOptions(motor_file=str(tmp_path / 'missing.yaml')).build_model()


@pytest.mark.parametrize('module', ['satmotor_ros.interface', 'satmotor_ros.bags'])
def test_the_contract_and_the_bag_reader_load_no_physics(module):
    code = (f'import sys, {module}; '
            'print(sorted(m for m in sys.modules if m.startswith("satmotor_ros.model")))')
    out = subprocess.run([sys.executable, '-c', code], check=True, capture_output=True,
                         text=True).stdout
    assert out.strip() == '[]'


def test_the_contract_imports_nothing_of_the_package():
    tree = ast.parse((PACKAGE / 'interface.py').read_text(encoding='utf-8'))
    imported = [node.module or '' for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
    imported += [a.name for node in ast.walk(tree) if isinstance(node, ast.Import)
                 for a in node.names]
    assert not [m for m in imported if m.startswith('satmotor_ros')]


def test_no_module_but_the_contract_spells_a_message_type():
    spelled = []
    for path in PACKAGE.rglob('*.py'):
        if path.name == 'interface.py' and path.parent == PACKAGE:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
            if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                    and re.fullmatch(r'\w+_msgs/msg/\w+', node.value)):
                spelled.append(f'{path.relative_to(PACKAGE)}: {node.value}')
    assert not spelled
