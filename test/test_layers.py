# SPDX-License-Identifier: Apache-2.0
"""The physics layers never pull in ROS, and every equation function documents itself."""

import inspect
import re
import subprocess
import sys

import pytest

from satmotor_ros.model.families import balawender_losses, paszota_losses
from satmotor_ros.model.families.sliwinski2017 import losses, speed


@pytest.mark.parametrize('module', ['satmotor_ros.model', 'satmotor_ros.plant',
                                    'satmotor_ros.identify', 'satmotor_ros.prediction',
                                    'satmotor_ros.bags', 'satmotor_ros.cli',
                                    'satmotor_ros.fleet'])
def test_layer_imports_without_rclpy(module):
    code = f'import sys, {module}; assert "rclpy" not in sys.modules, "rclpy imported"'
    subprocess.run([sys.executable, '-c', code], check=True)


EQUATION_MODULES = [losses, speed, balawender_losses, paszota_losses]


def _public_functions():
    for module in EQUATION_MODULES:
        for name, fn in inspect.getmembers(module, inspect.isfunction):
            if not name.startswith('_') and fn.__module__ == module.__name__:
                yield f'{module.__name__}.{name}', fn


@pytest.mark.parametrize(('name', 'fn'), list(_public_functions()))
def test_equation_function_cites_its_equation_and_units(name, fn):
    doc = inspect.getdoc(fn)
    assert re.search(r'eqs?\. \(\d+\)', doc), f'{name} cites no equation'
    params = list(inspect.signature(fn).parameters)
    section = doc.split('Parameters\n----------\n', 1)[1].split('\n\n', 1)[0]
    for param in params:
        line = re.search(rf'^(\w+, )*{param}\b.*\n\s+.*\[.*\]\s*$', section,
                         re.MULTILINE)  # numpydoc: `a, b : float` documents both
        assert line, f'{name}: parameter {param!r} lacks a [unit]'
