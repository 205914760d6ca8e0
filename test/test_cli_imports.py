# SPDX-License-Identifier: Apache-2.0
"""``satmotor`` imports a subcommand only when it runs it: one command needs no other's library."""

import subprocess
import sys

from satmotor_ros.cli.main import main

BLOCKED = ('rosbags', 'mcap', 'matplotlib', 'scipy', 'rclpy')
BLOCKER = f"""
import importlib.abc, sys

class Blocked(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.partition('.')[0] in {BLOCKED!r}:
            raise ModuleNotFoundError(f'No module named {{name!r}}', name=name)
        return None

sys.meta_path.insert(0, Blocked())
"""


def _satmotor(*args):
    code = BLOCKER + f'from satmotor_ros.cli.main import main; sys.exit(main({list(args)!r}))'
    return subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          timeout=120)


def test_operating_point_runs_without_the_bag_plot_fit_and_ros_libraries():
    run = _satmotor('operating-point', '--flow', '10', '--dp', '100bar')
    assert run.returncode == 0, run.stderr
    assert 'speed n' in run.stdout and 'rpm' in run.stdout


def test_help_lists_every_subcommand_without_importing_one():
    run = _satmotor('--help')
    assert run.returncode == 0, run.stderr
    for name in ('demo', 'operating-point', 'characteristics', 'replay', 'calibrate',
                 'validate'):
        assert name in run.stdout


def test_running_one_subcommand_imports_no_other():
    code = ('import sys; from satmotor_ros.cli.main import main, SUBCOMMANDS; '
            "main(['operating-point', '--flow', '10', '--dp', '100bar']); "
            'print(sorted(s.module for s in SUBCOMMANDS.values() if s.module in sys.modules))')
    run = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         timeout=120, check=True)
    assert run.stdout.splitlines()[-1] == "['satmotor_ros.cli.operating_point']"


def test_an_unknown_subcommand_is_still_a_usage_error(capsys):
    try:
        main(['operating-points'])
    except SystemExit as stop:
        assert stop.code == 2
    assert "invalid choice: 'operating-points'" in capsys.readouterr().err
