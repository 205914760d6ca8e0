# SPDX-License-Identifier: Apache-2.0
"""
The motor_monitor node writes only a state it started from (review of issue 23, F3).

A state resumed under other parameters is not carried on (the rule ``satmotor monitor``
applies, :meth:`HealthSettings.differences`): reported as ERROR with the settings that differ,
and the file is never written over. At run time a parameter that starts a new estimator is
refused while ``state_file`` holds this one's history, unless a new ``state_file`` comes with
it; a new ``state_file`` that exists is refused.
"""

import json
import os

from diagnostic_msgs.msg import DiagnosticArray
from health_data import recording
from node_harness import monitor_node, spin_until
from rclpy.parameter import Parameter
from satmotor_ros.identify.health import HealthMonitor, HealthSettings
from satmotor_ros.nodes.motor_monitor import baseline_from, PARAMETERS

NAMESPACE = f'/monitor_state_test_{os.getpid()}'
PACKAGED = os.path.join(os.path.dirname(__file__), '..', 'config', 'sm075_25.yaml')
VALUES = {**{s.name: s.default for s in PARAMETERS}, 'motor_file': PACKAGED, 'liquid': 'oil'}


def _node(context, executor, **overrides):
    return monitor_node(context, executor, NAMESPACE, {'motor_file': PACKAGED, 'liquid': 'oil',
                                                       'diagnostics_period': 3600.0,
                                                       **overrides})


def _state(path, hours=0.3):
    """Save a state of `hours` of healthy samples with the default settings."""
    baseline = baseline_from(VALUES)
    monitor = HealthMonitor(baseline, HealthSettings())
    monitor.update(recording(hours, seed=3, rate_hz=2, baseline=baseline))
    monitor.save(path)
    return monitor.snapshot().n_samples


def test_a_state_made_with_other_settings_is_reported_not_used_and_kept(ros, tmp_path):
    """State: limit 2, 1 000 h; node: limit 1.5, 10 h: ERROR naming both, file untouched."""
    context, executor, probe = ros
    path = tmp_path / 'health.json'
    _state(path)
    before = path.read_bytes()
    node = _node(context, executor, state_file=str(path), limit_leakage_factor=1.5,
                 false_alarm_hours=10.0)
    assert node.monitor.settings.limit_leakage_factor == 1.5
    assert node.monitor.settings.false_alarm_hours == 10.0
    assert node.monitor.snapshot().n_samples == 0
    level, message = node.level(node.monitor.snapshot())
    assert level == 2 and 'limit_leakage_factor' in message and 'false_alarm_hours' in message
    got = []
    probe.create_subscription(DiagnosticArray, '/diagnostics', got.append, 10)
    assert spin_until(executor, lambda: node.diagnose() or got)
    values = {kv.key: kv.value for kv in got[-1].status[0].values}
    assert 'limit_leakage_factor: state 2.0, parameter 1.5' in values['state settings differ']
    node.save()
    executor.remove_node(node)
    node.destroy_node()
    assert path.read_bytes() == before
    same = _node(context, executor, state_file=str(path))  # the same settings: resumed
    assert same.monitor.snapshot().n_samples == json.loads(before)['n_samples'] > 0
    assert same.level(same.monitor.snapshot())[0] < 2  # WARN only: no topic is published
    executor.remove_node(same)
    same.destroy_node()


def test_a_change_that_needs_a_new_estimator_keeps_the_state_file(ros, tmp_path):
    """trend_hours alone: refused with the reason; with a new state_file: the old one kept."""
    context, executor, _ = ros
    path, other = tmp_path / 'health.json', tmp_path / 'other.json'
    n = _state(path)
    node = _node(context, executor, state_file=str(path))
    before = node.monitor
    assert before.snapshot().n_samples == n
    refused = node.set_parameters([Parameter('trend_hours', value=100.0)])[0]
    assert not refused.successful and 'state_file' in refused.reason, refused.reason
    assert node.monitor is before and node.get_parameter('trend_hours').value == 200.0
    _state(other)
    taken = node.set_parameters([Parameter('state_file', value=str(other))])[0]
    assert not taken.successful and 'exists' in taken.reason, taken.reason
    new = tmp_path / 'new.json'
    assert node.set_parameters_atomically([Parameter('trend_hours', value=100.0),
                                           Parameter('state_file', value=str(new))]).successful
    assert node.monitor is not before and node.monitor.settings.trend_hours == 100.0
    node.save()
    assert json.loads(path.read_text())['n_samples'] == n
    assert json.loads(new.read_text())['settings']['trend_hours'] == 100.0
    executor.remove_node(node)
    node.destroy_node()


def test_a_hand_edited_state_is_error_naming_the_field_and_kept(ros, tmp_path):
    """
    n_samples edited to text (review F7): ERROR naming it, a fresh estimator, the file kept.

    It used to crash the node with a TypeError; the node now refuses to save any state over a
    file it did not start from (doc/nodes.md), and runs on afresh.
    """
    context, executor, probe = ros
    path = tmp_path / 'health.json'
    _state(path)
    doc = json.loads(path.read_text())
    doc['n_samples'] = 'twelve'
    path.write_text(json.dumps(doc))
    before = path.read_bytes()
    node = _node(context, executor, state_file=str(path))
    assert node.monitor.snapshot().n_samples == 0
    level, message = node.level(node.monitor.snapshot())
    assert level == 2 and "n_samples = 'twelve'" in message and '\n' not in message, message
    got = []
    probe.create_subscription(DiagnosticArray, '/diagnostics', got.append, 10)
    assert spin_until(executor, lambda: node.diagnose() or got)
    assert got[-1].status[0].level == b'\x02' and 'n_samples' in got[-1].status[0].message
    node.monitor.update(recording(0.01, seed=4, rate_hz=2, baseline=node.monitor.baseline))
    node.save()
    executor.remove_node(node)
    node.destroy_node()  # saves at shutdown too
    assert path.read_bytes() == before
