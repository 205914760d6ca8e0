# SPDX-License-Identifier: Apache-2.0
"""
The motor_monitor node never says OK while it sees nothing (review of issue 23, F2).

A resumed state followed by stamps whose clock starts again at 0 (a simulation restarted,
a replay) is shifted as ``satmotor monitor`` shifts a recording, so a +50 % leak is seen;
samples the estimator skips (a dead speed sensor: speed 0 while the flow passes) make the
status WARN with the skipped share, not OK "healthy"; so does a leakage factor the data
cannot identify (review F1, :func:`~satmotor_ros.identify.health.records.unresolved`).
"""

import os

from health_data import recording
from node_harness import monitor_node
import numpy as np
from satmotor_ros.identify.health import HealthMonitor, HealthSamples
from satmotor_ros.identify.health.run import clock_shift, GAP_S
from satmotor_ros.nodes.motor_monitor import baseline_from, PARAMETERS

NAMESPACE = f'/monitor_blind_test_{os.getpid()}'
PACKAGED = os.path.join(os.path.dirname(__file__), '..', 'config', 'sm075_25.yaml')
VALUES = {**{s.name: s.default for s in PARAMETERS}, 'motor_file': PACKAGED, 'liquid': 'oil'}


def _node(context, executor, **overrides):
    return monitor_node(context, executor, NAMESPACE, {'motor_file': PACKAGED, 'liquid': 'oil',
                                                       'input_timeout': 3600.0,
                                                       'diagnostics_period': 3600.0,
                                                       **overrides})


def _feed(node, samples):
    """Hand the samples to the node as its topics would, every input fresh."""
    now = node._now()
    for i in range(len(samples)):
        node._held.update(flow_measured=float(samples.flow[i]), p_in=float(samples.p_in[i]),
                          p_out=float(samples.p_out[i]))
        for name in ('flow_measured', 'p_in', 'p_out'):
            node._heard[name] = now
        node._last_heard_joint = now
        node.take(float(samples.time[i]), float(samples.speed[i]), now)
        if i % 1000 == 999:
            node.update(publish=False)
    node.update(publish=False)


def test_clock_shift_places_a_restarted_clock_after_the_last_sample():
    """The one rule the CLI and the node share: epoch clocks are never moved."""
    assert clock_shift(3600.0, 0.0) == 3600.0 + GAP_S
    assert clock_shift(3600.0, 3601.0) == 0.0
    assert clock_shift(float('nan'), 0.0) == 0.0
    assert clock_shift(1.7e9, 1.6e9) == 0.0


def test_a_clock_that_starts_again_after_a_resume_is_shifted_and_the_leak_is_seen(ros, tmp_path):
    """0.5 h saved, then a +50 % leak on stamps from 0 s: not stale, a change alarm."""
    context, executor, _ = ros
    baseline = baseline_from(VALUES)
    state = tmp_path / 'health.json'
    before = HealthMonitor(baseline)
    before.update(recording(0.5, seed=3, rate_hz=2, baseline=baseline))
    before.save(state)
    node = _node(context, executor, state_file=str(state))
    _feed(node, recording(0.25, seed=8, rate_hz=2, baseline=baseline,
                          scale=lambda t: np.full_like(t, 1.5)))
    snap = node.monitor.snapshot()
    assert snap.skipped['stale'] == 0 and node.clock_restarts == 1 and not node.out_of_order
    assert snap.alarms and snap.alarms[0].kind == 'change'
    assert snap.alarms[0].change_s >= 1800.0 + GAP_S - 5.0
    assert node.level(snap)[0] == 2
    executor.remove_node(node)
    node.destroy_node()


def test_a_dead_speed_sensor_warns_with_the_skipped_share(ros):
    """Healthy, OK; then speed 0 while the flow passes: WARN 'not monitoring', counts given."""
    context, executor, _ = ros
    baseline = baseline_from(VALUES)
    node = _node(context, executor)
    good = recording(0.4, seed=7, rate_hz=2, baseline=baseline)
    _feed(node, good)
    assert node.level(node.monitor.snapshot()) == (0, 'healthy')
    dead = recording(0.2, seed=8, rate_hz=2, baseline=baseline, t0=float(good.time[-1]) + 0.5)
    _feed(node, HealthSamples(dead.time, 0.0 * dead.speed, dead.flow, dead.p_in, dead.p_out))
    level, message = node.level(node.monitor.snapshot())
    assert level == 1 and 'not monitoring' in message and 'stalled' in message
    total, skipped = node.recent_skipped()
    assert total >= VALUES['window_s'] * 2 * 0.9 and skipped['stalled'] == total
    executor.remove_node(node)
    node.destroy_node()


def test_a_factor_lost_in_the_noise_warns_not_identifiable(ros):
    """A flowmeter whose noise swamps the baseline's losses: WARN, not OK 'healthy'."""
    context, executor, _ = ros
    baseline = baseline_from(VALUES)
    for noise_lpm, level in ((0.05, 0), (3.0, 1)):
        node = _node(context, executor)
        _feed(node, recording(0.4, seed=7, rate_hz=2, baseline=baseline, noise_lpm=noise_lpm))
        snap = node.monitor.snapshot()
        assert not snap.learning
        got, message = node.level(snap)
        assert got == level and ('not identifiable' in message) is bool(level), message
        executor.remove_node(node)
        node.destroy_node()


def test_a_parked_motor_is_ok_parked_not_monitoring(ros):
    """
    Healthy, then standing still with no flow (review F9): OK 'parked, not monitoring'.

    A parked motor is not a fault: a drive engineer reads WARN as something to look at. Its
    samples are counted 'parked', not 'stalled' (speed 0 while the flow passes: WARN above).
    The status holds for as long as it stands (the share is of the last window_s).
    """
    context, executor, _ = ros
    baseline = baseline_from(VALUES)
    node = _node(context, executor)
    good = recording(0.4, seed=7, rate_hz=2, baseline=baseline)
    _feed(node, good)
    rest = recording(0.2, seed=8, rate_hz=2, baseline=baseline, t0=float(good.time[-1]) + 0.5)
    leak = np.full(len(rest), 1e-3 * baseline.displacement * 100.0)  # a trickle, held pressure
    _feed(node, HealthSamples(rest.time, 0.0 * rest.speed, leak, rest.p_in, rest.p_out))
    snap = node.monitor.snapshot()
    assert snap.skipped['parked'] == len(rest) and snap.skipped['stalled'] == 0
    level, message = node.level(snap)
    assert level == 0 and message.startswith('parked, not monitoring'), message
    executor.remove_node(node)
    node.destroy_node()
