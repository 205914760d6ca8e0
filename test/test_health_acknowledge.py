# SPDX-License-Identifier: Apache-2.0
"""Acknowledging alarms: the estimator keeps them, the CLI and the node stop calling them new."""

from __future__ import annotations

from dataclasses import replace
import json
import os
from pathlib import Path

from health_data import DISPLACEMENT, recording
import numpy as np
import pytest

from satmotor_ros.cli.main import main
from satmotor_ros.identify.health import Alarm, Baseline, HealthMonitor, HealthSettings
from satmotor_ros.identify.table import write_csv

NAMESPACE = f'/acknowledge_test_{os.getpid()}'
MOTOR = ['--liquid', 'oil', '--family', 'paszota', '--displacement',
         f'{DISPLACEMENT * 2 * np.pi * 1e6:.9g}', '--no-explain']


def _monitor_with_alarms(kinds: tuple[str, ...]) -> HealthMonitor:
    monitor = HealthMonitor(Baseline.for_family('paszota', DISPLACEMENT),
                            HealthSettings(explain=False))
    monitor.alarms = [Alarm(100.0 * (n + 1), kind, 'leak', 1.2, 90.0 * (n + 1), 1.0, 1.3)
                      for n, kind in enumerate(kinds)]
    return monitor


def test_acknowledging_keeps_the_alarms_only_grows_and_survives_a_restart(
        tmp_path: Path) -> None:
    """All so far by default, at most those raised, never fewer; saved with the state."""
    monitor = _monitor_with_alarms(('change', 'change'))
    assert monitor.acknowledge(1) == 1 and monitor.snapshot().unacknowledged == (
        monitor.alarms[1],)
    assert monitor.acknowledge(0) == 1  # never goes back
    assert monitor.acknowledge(99) == 2  # not beyond the alarms raised
    monitor.alarms.append(Alarm(500.0, 'limit', 'leakage factor 2 >= limit 2', 2.0))
    snap = monitor.snapshot()
    assert len(snap.alarms) == 3 and snap.acknowledged == 2
    assert [a.kind for a in snap.unacknowledged] == ['limit']  # raised later: new
    monitor.save(tmp_path / 'state.json')
    resumed = HealthMonitor.resume(tmp_path / 'state.json', monitor.baseline)
    assert resumed.snapshot().acknowledged == 2
    assert resumed.acknowledge() == 3


def _csv(path: Path, samples, shift: float = 0.0) -> Path:
    write_csv(path, {'time': ('s', samples.time - shift), 'speed': ('rad/s', samples.speed),
                     'flow': ('m^3/s', samples.flow), 'p_in': ('Pa', samples.p_in),
                     'p_out': ('Pa', samples.p_out)})
    return path


def test_the_cli_acknowledges_the_states_alarms_and_keeps_them(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A change reported by one run, acknowledged by the next: kept, marked, figures the same."""
    samples = recording(1.6, seed=2, rate_hz=2.0,
                        scale=lambda t: np.where(t >= 3000.0, 1.3, 1.0))
    first = _csv(tmp_path / 'a.csv', samples.take(samples.time < 5000.0))
    second = _csv(tmp_path / 'b.csv', samples.take(samples.time >= 5000.0), 5000.0)
    state = tmp_path / 'state.json'
    assert main(['monitor', str(first), '--out', str(tmp_path / 'o1'), '--state', str(state),
                 *MOTOR]) == 0
    saved = state.read_bytes()
    docs = {}
    for flags, out in (([], 'plain'), (['--acknowledge'], 'acked')):
        state.write_bytes(saved)
        assert main(['monitor', str(second), '--out', str(tmp_path / out), '--state',
                     str(state), *flags, *MOTOR]) == 0
        docs[out] = json.loads((tmp_path / out / 'monitor.json').read_text())
    assert [a['kind'] for a in docs['acked']['alarms']] == ['change']
    assert docs['plain']['alarms'][0]['acknowledged'] is False
    assert docs['acked']['alarms'][0]['acknowledged'] is True
    assert docs['acked']['leakage_factor'] == docs['plain']['leakage_factor']
    assert '| change (acknowledged) |' in (tmp_path / 'acked' / 'report.md').read_text()
    assert ') acknowledged' in capsys.readouterr().out


def test_acknowledge_without_a_state_is_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """No --state: there are no alarms of a previous run; refused before anything is written."""
    data = _csv(tmp_path / 'run.csv', recording(0.05, seed=1))
    assert main(['monitor', str(data), '--out', str(tmp_path / 'out'), '--acknowledge',
                 *MOTOR]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and '--acknowledge' in err[0] and '--state' in err[0]
    assert not (tmp_path / 'out').exists()


def test_the_node_is_ok_again_once_its_alarms_are_acknowledged(ros) -> None:
    """ERROR on a change; acknowledged_alarms 1: OK, the alarm kept; a later alarm: ERROR."""
    pytest.importorskip('rclpy')
    from rclpy.parameter import Parameter

    from satmotor_ros.nodes.motor_monitor import _figures, MotorMonitorNode
    context, _, _ = ros
    node = MotorMonitorNode(context=context, namespace=NAMESPACE, parameter_overrides=[
        Parameter('family', value='paszota'), Parameter('displacement', value=DISPLACEMENT),
        Parameter('input_timeout', value=3600.0), Parameter('diagnostics_period',
                                                            value=3600.0)])
    node._heard.update(flow=node._now(), p_in=node._now(), p_out=node._now())
    node._last_heard_joint = node._now()
    node.monitor = _monitor_with_alarms(('change',))
    assert node.level(node.monitor.snapshot())[0] == 2
    assert node.set_parameters([Parameter('acknowledged_alarms', value=1)])[0].successful
    snap = node.monitor.snapshot()
    level, message = node.level(snap)
    assert level == 0 and 'acknowledged' in message and len(snap.alarms) == 1
    assert _figures(snap)['alarms acknowledged'] == 1
    node.monitor.alarms.append(replace(node.monitor.alarms[0], time_s=900.0))
    assert node.level(node.monitor.snapshot())[0] == 2
    limit = replace(node.monitor.snapshot(), acknowledged=2, in_limit=True,  # the estimator's
                    leakage_factor=replace(snap.leakage_factor, value=2.5))  # rule (F6)
    assert node.level(limit)[0] == 2 and 'limit' in node.level(limit)[1]  # still past it
    node.destroy_node()
