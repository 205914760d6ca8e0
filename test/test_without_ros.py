# SPDX-License-Identifier: Apache-2.0
"""
Without ROS 2 (a pip install alone), every console script that needs it ends in one line.

Each script of setup.py runs in a subprocess whose sitecustomize makes the ROS 2 Python
packages unimportable, as they are where nothing but the wheel is installed (the wheel in a
clean venv is also tried, in test_package_build).
"""

from pathlib import Path
import re
import subprocess
import sys

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCKER = """
import importlib.abc, sys
ROS = {'rclpy', 'rpyutils', 'rcl_interfaces', 'builtin_interfaces', 'rosgraph_msgs',
       'ament_index_python'}

class NoRos(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        top = name.partition('.')[0]
        if top in ROS or top.endswith('_msgs'):
            raise ModuleNotFoundError(f'No module named {name!r}', name=name)
        return None

sys.meta_path.insert(0, NoRos())
"""


def _console_scripts():
    """Return setup.py's console scripts as (name, module, function)."""
    text = (ROOT / 'setup.py').read_text(encoding='utf-8')
    return re.findall(r"'(\w+) = ([\w.]+):(\w+)'", text)


SCRIPTS = _console_scripts()
NEED_ROS = {'motor_model': [], 'virtual_motor': [], 'speed_controller': [], 'motor_monitor': [],
            'satmotor': ['demo', '--quiet', '--no-loop', '--duration', '2']}
"""Every script that needs ROS, with the arguments that make it need it."""


@pytest.fixture
def no_ros(tmp_path):
    site = tmp_path / 'site'
    site.mkdir()
    (site / 'sitecustomize.py').write_text(BLOCKER, encoding='utf-8')
    return site


def _run(site, cwd, module, function, name, *args):
    code = (f'import sys; from {module} import {function}; sys.argv = {[name, *args]!r}; '
            f'sys.exit({function}())')
    env = {'PYTHONPATH': f'{site}:{ROOT}', 'PATH': '/usr/bin:/bin', 'HOME': str(cwd)}
    return subprocess.run([sys.executable, '-c', code], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=120)


def test_every_console_script_that_needs_ros_is_listed():
    assert {name for name, _, _ in SCRIPTS} == set(NEED_ROS)


@pytest.mark.parametrize(('name', 'module', 'function'), SCRIPTS, ids=[s[0] for s in SCRIPTS])
def test_without_ros_a_script_says_what_it_needs_in_one_line(no_ros, tmp_path, name, module,
                                                             function):
    proc = _run(no_ros, tmp_path, module, function, name, *NEED_ROS[name],
                *(['--out', str(tmp_path / 'demo')] if name == 'satmotor' else []))
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert proc.stderr.count('\n') == 1 and 'Traceback' not in proc.stderr, proc.stderr
    line = proc.stderr
    assert 'ROS 2 Kilted' in line and 'pip install ros-kilted-rclpy' in line, line
    assert 'cannot import' in line, line
    assert not (tmp_path / 'demo').exists()


def test_without_ros_the_commands_that_do_not_need_it_run(no_ros, tmp_path):
    proc = _run(no_ros, tmp_path, 'satmotor_ros.cli', 'main', 'satmotor', 'operating-point',
                '--liquid', 'oil', '--flow', '5', '--dp-i', '25')
    assert proc.returncode == 0, proc.stderr
    proc = _run(no_ros, tmp_path, 'satmotor_ros.cli', 'main', 'satmotor', 'demo', '--help')
    assert proc.returncode == 0 and 'usage' in proc.stdout, proc.stderr
