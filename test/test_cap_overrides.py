# SPDX-License-Identifier: Apache-2.0
"""A SATMOTOR_* cap variable that changes nothing is said: the CLI refuses, a node runs on."""

import os
from pathlib import Path
import signal
import subprocess
import sys
import time

from node_harness import unique_namespace
import pytest

ROOT = Path(__file__).resolve().parents[1]
LIMIT = 'a cap is a whole number from 1 to 9223372036854775807'


def _env(**caps):
    env = {k: v for k, v in os.environ.items() if not k.startswith('SATMOTOR_')}
    return {**env, 'PYTHONPATH': str(ROOT), **caps}


def _satmotor(env, *args):
    return subprocess.run([sys.executable, '-m', 'satmotor_ros.cli', *args], env=env,
                          capture_output=True, text=True, timeout=120)


POINT = ('operating-point', '--flow', '10', '--dp', '100bar')


@pytest.mark.parametrize('text', ['abc', '-5', '1e400', '0', '2.5', '9223372036854775808',
                                  '1' * 400])
def test_a_bad_cap_value_is_one_line_and_the_cli_refuses(text):
    proc = _satmotor(_env(SATMOTOR_YAML_MAX_BYTES=text), *POINT)
    assert proc.returncode == 1 and proc.stdout == ''
    assert proc.stderr == f'satmotor: error: SATMOTOR_YAML_MAX_BYTES={text!r}: {LIMIT}\n'


def test_a_misspelt_cap_is_named_with_the_cap_it_resembles():
    proc = _satmotor(_env(SATMOTOR_YAML_MAX_BYTE='4096', SATMOTOR_BAG_MAX_RATIO='x'), *POINT)
    assert proc.returncode == 1
    assert proc.stderr == (f"satmotor: error: SATMOTOR_BAG_MAX_RATIO='x': {LIMIT}; "
                           "SATMOTOR_YAML_MAX_BYTE='4096': no such cap (did you mean "
                           'SATMOTOR_YAML_MAX_BYTES?)\n')


def test_a_good_cap_value_takes_effect_and_an_empty_one_is_the_default():
    proc = _satmotor(_env(SATMOTOR_YAML_MAX_BYTES=' 12 '), *POINT)
    assert proc.returncode == 1
    assert proc.stderr.endswith(': larger than 12 bytes (the cap SATMOTOR_YAML_MAX_BYTES)\n')
    assert _satmotor(_env(SATMOTOR_YAML_MAX_BYTES=''), *POINT).returncode == 0


@pytest.mark.ros
def test_a_node_logs_a_bad_cap_as_an_error_and_runs_on_the_default():
    code = 'from satmotor_ros.nodes.launch import motor_model; motor_model()'
    proc = subprocess.Popen(
        [sys.executable, '-c', code, '--ros-args', '-r',
         f'__ns:={unique_namespace("caps")}'], stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT, text=True, env=_env(SATMOTOR_YAML_MAX_BYTES='-5',
                                                      PYTHONUNBUFFERED='1'))
    try:
        line = proc.stdout.readline()  # the node's first words, before it loads its motor
        assert f"SATMOTOR_YAML_MAX_BYTES='-5': {LIMIT}; the default 1048576 is used" in line
        assert '[ERROR]' in line and '[motor_model]' in line
        time.sleep(2.0)  # it loads the packaged motor YAML with the default cap and runs on
        assert proc.poll() is None
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0 and 'Traceback' not in out, out
