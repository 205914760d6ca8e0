# SPDX-License-Identifier: Apache-2.0
"""
A displacement no motor has is refused with one line, wherever it comes from (issue 14).

A node also outlives a motor_file that is a FIFO or holds a hex-integer bomb.
"""

import os
import subprocess
import sys

from node_harness import unique_namespace
import pytest
from satmotor_ros.bounded_yaml import read_yaml
from satmotor_ros.cli.main import main
from satmotor_ros.model import ConfigError, load_motor, MotorModel
from satmotor_ros.model.coefficients import displacement_problem, DISPLACEMENT_RANGE
from satmotor_ros.model.engine.core import ModelCore
from satmotor_ros.model.io.config import default_config_path
from satmotor_ros.model.units import CM3_PER_REV
from satmotor_ros.options import MotorOptions, OptionError
import yaml

TINY = [1e-300, 5e-324, 1e-18, 1e-234]
"""Inside the old advertised range [0, 1e-2] m^3/rad; 1e-300 overflowed c_t ~ q^(-4/3)."""


def test_the_range_spans_every_displacement_machine_and_nothing_else():
    low, high = DISPLACEMENT_RANGE
    assert low == pytest.approx(0.01 * CM3_PER_REV) and high == pytest.approx(1e6 * CM3_PER_REV)
    for q in (0.02, 4.92, 100.0, 250_000.0):
        assert displacement_problem(q * CM3_PER_REV) is None
    for q in (*TINY, 0.0, -1e-6, 1.0, float('nan'), float('inf')):
        assert displacement_problem(q).startswith('outside (1.592e-09, 0.1592) m^3/rad')


@pytest.mark.parametrize('family', ['sliwinski2017', 'balawender', 'paszota'])
@pytest.mark.parametrize('value', TINY)
def test_every_way_in_refuses_a_tiny_displacement(family, value):
    with pytest.raises(OptionError, match=r'^displacement = .*: outside \(1.592e-09'):
        MotorOptions(displacement=value, family=family)
    with pytest.raises(ConfigError, match=r'^displacement = .* m\^3/rad is outside'):
        MotorModel.for_displacement(value, family)


def test_a_motor_file_with_a_tiny_displacement_is_refused(tmp_path):
    path = tmp_path / 'tiny.yaml'
    for family in ('paszota', 'sliwinski2017'):
        doc = read_yaml(default_config_path())
        doc['family'], doc['geometry']['displacement'] = family, 1e-300
        path.write_text(yaml.safe_dump(doc))
        with pytest.raises(ConfigError, match=r'^geometry.displacement = 1e-300 is '
                                              r'outside \(1.592e-09'):
            load_motor(path)
        with pytest.raises(ConfigError, match='geometry.displacement = 1e-300'):
            MotorOptions(motor_file=str(path)).build_model()


def test_an_overflow_while_building_the_constants_is_a_config_error(monkeypatch):
    spec = load_motor()
    coefficient_set = spec.sets['oil']
    family = ModelCore(spec.geometry, coefficient_set, spec.valid_range,
                       coefficient_set.liquid, 'eq33').family

    def overflow(*args):
        return 10.0 ** 400

    monkeypatch.setattr(type(family), 'compose', overflow)
    with pytest.raises(ConfigError, match='constants of this motor and liquid cannot be '
                                          r'computed \(.*range'):
        ModelCore(spec.geometry, coefficient_set, spec.valid_range, coefficient_set.liquid,
                  'eq33')


CLI = [
    ['operating-point', '--flow', '30', '--dp-i', '10'],
    ['operating-point', '--flow', '30', '--dp-i', '10', '--family', 'paszota'],
    ['operating-point', '--flow', '10', '--dp', '100bar', '--family', 'paszota'],
]


@pytest.mark.parametrize('argv', CLI)
@pytest.mark.parametrize('value', ['1e-300', '5e-324', '1e-18m^3/rad', '1e7'])
def test_the_cli_refuses_it_with_one_line_naming_the_option(argv, value, capsys):
    code = main([*argv, '--displacement', value])  # in this process: a traceback fails it
    out, err = capsys.readouterr()
    assert code != 0 and not out
    assert err.count('\n') == 1 and 'Traceback' not in err, err
    assert err.startswith('satmotor: error: --displacement ') and (
        'outside (1.592e-09, 0.1592) m^3/rad' in err  # 5e-324 cm^3/rev is 0 m^3/rad
        or 'must be a finite value > 0' in err), err


def _start(node, *params):
    code = f'from satmotor_ros.nodes.launch import {node}; {node}()'
    ns = unique_namespace(node)
    proc = subprocess.Popen([sys.executable, '-c', code, '--ros-args', '-r', f'__ns:={ns}',
                             *params], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, env=os.environ.copy())
    return proc, f'{ns}/{node}'


def _stop(proc):
    if proc.poll() is None:
        proc.send_signal(2)
    try:
        out, _ = proc.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, _ = proc.communicate()
    return proc.returncode, out


@pytest.mark.parametrize('node', ['motor_model', 'virtual_motor', 'speed_controller'])
def test_a_node_refuses_a_tiny_displacement_and_a_hostile_motor_file_and_lives(
        node, harness, tmp_path):
    fifo, bomb = tmp_path / 'fifo.yaml', tmp_path / 'bomb.yaml'
    os.mkfifo(fifo)
    hex_a1 = 'a1: 0x' + 'f' * 400 + ' #'
    bomb.write_text(default_config_path().read_text().replace('a1:', hex_a1, 1))
    start_up = ('-p', 'displacement:=1e-300')
    if node == 'virtual_motor':  # a plant refuses any bad start-up override (doc/nodes.md)
        refused, _ = _start(node, *start_up)
        code, out = refused.wait(timeout=60), refused.stdout.read()
        refused.stdout.close()
        lines = [line for line in out.splitlines() if line.startswith('virtual_motor: ')]
        assert code == 1 and 'Traceback' not in out, out
        assert len(lines) == 1 and 'displacement = 1e-300 m^3/rad: outside' in lines[0], out
        start_up = ()
    proc, name = _start(node, *start_up)
    try:
        for path, reason in ((fifo, 'not a regular file'), (bomb, 'an integer of 402 digits')):
            (result,) = harness.set_parameters(name, motor_file=str(path))
            assert not result.successful and reason in result.reason, result.reason
            assert proc.poll() is None, _stop(proc)
        for value in (1e-300, 5e-324, 1e-18):
            (result,) = harness.set_parameters(name, displacement=value)
            assert not result.successful, (value, result.reason)
            assert f'displacement = {value!r} m^3/rad: outside (1.592e-09' in result.reason
            assert proc.poll() is None, _stop(proc)
        (result,) = harness.set_parameters(name, displacement=5 * CM3_PER_REV)
        assert result.successful, result.reason
        assert proc.poll() is None
    finally:
        code, out = _stop(proc)
    assert 'Traceback' not in out and 'OverflowError' not in out, out
    if start_up:  # the start-up value: reported, and the node ran on the default
        assert 'displacement = 1e-300 m^3/rad: outside' in out, out
    assert code == 0, out
