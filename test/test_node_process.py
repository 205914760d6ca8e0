# SPDX-License-Identifier: Apache-2.0
"""
The motor_model node as ``ros2 run`` starts it: built by colcon, its own process.

The test holds real publishers and subscribers in its own Context; the node runs from the
colcon install tree, found through the ament index. Every wait has a deadline, and every
node gets a namespace of its own so that parallel test runs never meet.
"""

import math
import os
from pathlib import Path
import time

from ament_index_python.packages import get_package_prefix
from builtin_interfaces.msg import Time
from node_harness import start_node, stop_node, unique_namespace
import pytest
from rosgraph_msgs.msg import Clock
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, MPA
from std_msgs.msg import Float64
from test_package_build import (_copy_source, _executable_path, _find_tool,
                                _sourced_environment, BUILD_TIMEOUT, PACKAGE)

pytestmark = pytest.mark.slow  # each test starts the node as its own process

OIL, WATER = MotorModel.default('oil'), MotorModel.default('water')
FLOW, P_IN, P_OUT = 20 * LPM, 20 * MPA, 0.2 * MPA


@pytest.fixture(scope='module')
def install(tmp_path_factory):
    """Build the package with colcon; return the sourced environment and the executable."""
    import subprocess
    workspace = tmp_path_factory.mktemp('colcon_node_ws')
    source = _copy_source(workspace / 'src' / PACKAGE)
    env = dict(os.environ, COLCON_HOME=str(workspace / 'colcon_home'))
    proc = subprocess.run(
        [_find_tool('colcon'), '--log-base', str(workspace / 'log'), 'build', '--base-paths',
         str(source.parent), '--build-base', str(workspace / 'build'), '--install-base',
         str(workspace / 'install')], cwd=workspace, env=env, capture_output=True, text=True,
        timeout=BUILD_TIMEOUT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    prefix = workspace / 'install' / PACKAGE
    env = _sourced_environment(prefix, os.environ)
    return {'env': env, 'prefix': prefix, 'cwd': workspace,
            'config': prefix / 'share' / PACKAGE / 'config' / 'motor_model.yaml'}


@pytest.fixture()
def executable(install, monkeypatch):
    """Find the motor_model executable as ros2 run finds it."""
    monkeypatch.setenv('AMENT_PREFIX_PATH', install['env']['AMENT_PREFIX_PATH'])
    assert Path(get_package_prefix(PACKAGE)) == install['prefix']
    path = _executable_path(PACKAGE, 'motor_model')
    assert path == install['prefix'] / 'lib' / PACKAGE / 'motor_model'
    return path


def _drive(h, motor, flow=FLOW, settle=0.15, **inputs):
    """
    Publish inputs as a sensor would (a few times), then a flow_command.

    Sensor topics are best effort: a message sent before the node's reader has matched
    the writer is lost, as it would be from a real sensor.
    """
    for _ in range(3 if settle else 1):
        motor.inputs(**inputs)
        h.spin_for(settle / 3)
    before = time.time_ns()
    motor.flow.publish(Float64(data=flow))
    return before


def _drive_until_predicted(h, motor, timeout=8.0, **inputs):
    """
    Drive until a prediction arrives.

    Right after start-up the node's best-effort readers may not have matched our writers
    yet, and what is sent before is lost, as it would be from a sensor.
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        before = _drive(h, motor, **inputs)
        if h.spin_until(lambda: motor.predicted, 0.4):
            return before
    raise AssertionError(f'no prediction from {motor.ns} within {timeout} s')


def _drive_until_diag(h, motor, level, text, timeout=6.0, **inputs):
    """
    Drive good predictions until a report of `level` with `text` arrives.

    A report covers the worst prediction of its 1 s period, so a period that began with
    bad data reports the bad data; the next one reports the recovery.
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        _drive(h, motor, **inputs)
        if h.spin_until(lambda: any(s.level == bytes([level]) and text in s.message
                                    for s in motor.diagnostics), 0.3):
            return
    raise AssertionError([(s.level, s.message[:60]) for s in motor.diagnostics])


def _wait_diag(h, motor, level, text, timeout=4.0):
    """Wait for a diagnostics status of `level` whose message contains `text`."""
    def seen():
        return any(s.level == bytes([level]) and text in s.message for s in motor.diagnostics)
    ok = h.spin_until(seen, timeout)
    assert ok, [(s.level, s.message[:60]) for s in motor.diagnostics]
    return next(s for s in motor.diagnostics if s.level == bytes([level]) and text in s.message)


def test_node_publishes_the_library_prediction_and_recovers_from_bad_input(
        install, executable, harness):
    ns = unique_namespace('motor')
    proc = start_node(executable, ns, install['env'], install['cwd'],
                      '--params-file', str(install['config']))
    try:
        h, motor = harness, harness.motor(ns)
        h.wait_connected(motor)
        before = _drive_until_predicted(h, motor, p_in=P_IN, p_out=P_OUT, speed=50.0)
        assert h.spin_until(lambda: motor.losses['total'] and motor.residual, 5.0)
        after = time.time_ns()
        expected = OIL.speed_point(FLOW, P_IN - P_OUT)
        joint = motor.predicted[-1]
        assert joint.name == ['motor_shaft'] and joint.position.tolist() == []
        assert joint.velocity[0] == pytest.approx(expected.speed, rel=1e-15)
        stamp = joint.header.stamp.sec * 10**9 + joint.header.stamp.nanosec
        assert before <= stamp <= after
        assert h.spin_until(lambda: all(motor.losses.values()), 2.0)
        for name, inbox in motor.losses.items():
            assert inbox[0].data == pytest.approx(getattr(expected, name), rel=1e-15, abs=0.0)
        assert motor.residual[0].data == pytest.approx(50.0 - expected.speed, rel=1e-15)
        ok = _wait_diag(h, motor, 0, 'OK')
        keys = {kv.key: kv.value for kv in ok.values}
        assert float(keys['inlet_pressure.fluid_pressure [MPa]']) == pytest.approx(P_IN / MPA)
        assert keys['model status'] == 'OK'
        assert keys['predictions published'] == str(len(motor.predicted))

        # p_out above p_in and a negative flow are quadrants, not bad input (issue 13)
        cases = [({'p_in': P_IN, 'p_out': -1.0}, FLOW,
                  'outlet_pressure.fluid_pressure = -1.0 Pa: negative'),
                 ({'p_in': math.nan, 'p_out': P_OUT}, FLOW,
                  'inlet_pressure.fluid_pressure = nan Pa: not finite'),
                 ({'p_in': P_IN, 'p_out': P_OUT}, math.inf,
                  'flow_command.data = inf m^3/s: not finite'),
                 ({'p_in': 60 * MPA, 'p_out': P_OUT}, FLOW, 'model status BEYOND_LIMIT')]
        for inputs, flow, text in cases:
            motor.clear()
            _drive(h, motor, flow=flow, **inputs)
            _wait_diag(h, motor, 2, text)
            assert not motor.predicted, f'published a prediction despite: {text}'
            motor.clear()
            _drive(h, motor, p_in=P_IN, p_out=P_OUT)  # recovers by itself
            assert h.spin_until(lambda: motor.predicted, 5.0), f'no recovery after: {text}'
            assert motor.predicted[0].velocity[0] == pytest.approx(expected.speed, rel=1e-15)

        motor.clear()
        h.spin_for(0.7)  # the pressures grow older than input_timeout (0.5 s)
        _drive(h, motor, settle=0.0)
        _wait_diag(h, motor, 2, 'inlet_pressure: last message')
        assert not motor.predicted
        motor.clear()
        _drive(h, motor, flow=0.0, p_in=P_IN, p_out=P_OUT)
        assert h.spin_until(lambda: motor.predicted, 5.0)
        assert motor.predicted[0].velocity[0] == 0.0
        _wait_diag(h, motor, 1, 'STALLED')
    finally:
        code, output = stop_node(proc)
    assert code == 0, output
    assert 'Traceback' not in output, output


def test_node_rejects_bad_parameters_with_a_reason_and_applies_good_ones(
        install, executable, harness, tmp_path):
    bad = tmp_path / 'bad.yaml'
    bad.write_text('/**:\n  ros__parameters:\n    motor_file: /nonexistent/motor.yaml\n'
                   '    input_timeout: -3.0\n')
    ns = unique_namespace('params')
    proc = start_node(executable, ns, install['env'], install['cwd'], '--params-file', str(bad))
    try:
        h, motor = harness, harness.motor(ns)
        h.wait_connected(motor)
        _drive(h, motor, p_in=P_IN, p_out=P_OUT)
        status = _wait_diag(h, motor, 2, 'no model: cannot read motor config '
                                         "'/nonexistent/motor.yaml'")
        assert 'input_timeout' in status.message and 'using the default 0.5' in status.message
        assert not motor.predicted
        node = f'{ns}/motor_model'
        rejected = {
            'input_timeout': (-1.0, 'input_timeout'),
            'displacement_law': ('eq40', "displacement_law = 'eq40': use one of eq33, eq39"),
            'motor_file': ('/nope.yaml', '/nope.yaml'),
            'publish_mode': ('sometimes', 'use one of on_flow, rate'),
            'qos_depth': (5, 'read-only'),
            'joint_name': ('  ', 'must not be empty'),
        }
        for name, (value, reason) in rejected.items():
            (result,) = h.set_parameters(node, **{name: value})
            assert not result.successful and reason in result.reason, (name, result.reason)
        results = h.set_parameters(node, motor_file='', liquid='water', input_timeout=0.5)
        assert all(r.successful for r in results), results
        (result,) = h.set_parameters(node, liquid='glycol')
        assert not result.successful and "liquid = 'glycol': not a coefficient set" \
            in result.reason
        motor.clear()
        _drive_until_predicted(h, motor, p_in=P_IN, p_out=P_OUT)
        water = WATER.speed_point(FLOW, P_IN - P_OUT).speed
        assert motor.predicted[0].velocity[0] == pytest.approx(water, rel=1e-15)
        _drive_until_diag(h, motor, 0, 'OK', p_in=P_IN, p_out=P_OUT)  # start-up problems over

        assert all(r.successful for r in h.set_parameters(node, publish_mode='rate',
                                                          publish_rate=40.0))
        motor.clear()
        _drive(h, motor, p_in=P_IN, p_out=P_OUT, settle=0.0)
        h.spin_for(1.2)  # predictions at 40 Hz while the inputs are fresh (0.5 s)
        assert 12 <= len(motor.predicted) <= 24, len(motor.predicted)
    finally:
        code, output = stop_node(proc)
    assert code == 0 and 'Traceback' not in output, output


def test_two_motors_in_two_namespaces_at_once(install, executable, harness):
    left, right = unique_namespace('left'), unique_namespace('right')
    procs = [start_node(executable, left, install['env'], install['cwd']),
             start_node(executable, right, install['env'], install['cwd'],
                        '-p', 'liquid:=water', '-p', 'joint_name:=shaft_b')]
    try:
        h = harness
        a, b = h.motor(left), h.motor(right, joint='shaft_b')
        h.wait_connected(a)
        h.wait_connected(b)
        _drive_until_predicted(h, a, p_in=P_IN, p_out=P_OUT)
        _drive_until_predicted(h, b, p_in=P_IN, p_out=P_OUT)
        h.spin_for(0.3)
        oil = OIL.speed_point(FLOW, P_IN - P_OUT).speed
        water = WATER.speed_point(FLOW, P_IN - P_OUT).speed
        assert [m.velocity[0] for m in a.predicted] == pytest.approx(
            [oil] * len(a.predicted), rel=1e-15)
        assert [m.velocity[0] for m in b.predicted] == pytest.approx(
            [water] * len(b.predicted), rel=1e-15)  # no cross-talk between the namespaces
        assert {tuple(m.name) for m in b.predicted} == {('shaft_b',)}
    finally:
        results = [stop_node(p) for p in procs]
    assert all(code == 0 for code, _ in results), results


def test_node_runs_on_sim_time_from_clock(install, executable, harness):
    ns = unique_namespace('sim')
    proc = start_node(executable, ns, install['env'], install['cwd'],
                      '-p', 'use_sim_time:=true')
    try:
        h, motor = harness, harness.motor(ns)
        h.wait_connected(motor)
        assert h.spin_until(lambda: h.clock.get_subscription_count() > 0, 10.0)

        def tick(seconds):
            for _ in range(3):
                h.clock.publish(Clock(clock=Time(sec=seconds, nanosec=0)))
                h.spin_for(0.05)

        tick(1000)
        _drive_until_predicted(h, motor, p_in=P_IN, p_out=P_OUT)
        assert motor.predicted[0].header.stamp.sec == 1000
        assert motor.predicted[0].header.stamp.nanosec == 0
        motor.clear()
        tick(1002)  # two simulated seconds later, the pressures are stale
        _drive(h, motor, settle=0.0)
        h.spin_for(0.2)
        tick(1003)  # the 1 Hz report runs on the simulated clock too
        _wait_diag(h, motor, 2, 'inlet_pressure: last message 2 s old')
        assert not motor.predicted
    finally:
        code, output = stop_node(proc)
    assert code == 0 and 'Traceback' not in output, output
