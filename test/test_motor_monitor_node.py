# SPDX-License-Identifier: Apache-2.0
"""
The motor_monitor node in-process over real topics: a bag replayed, restarts, bad input.

The bag is a synthetic recording of the packaged motor (a leak to the case steps in
half-way), written as rosbag2 and read back as ``satmotor monitor`` reads it. Its samples
go through the node's topics one by one (the held topics, then ``joint_states``, each
waited for), so the node sees exactly the recording's samples, and reach the estimator in
the node's blocks (every 0.2 s of feeding); its figures must be the estimator's on the same
samples as one block, and ``satmotor monitor``'s on the bag.
"""

import dataclasses
import json
import math
import os
import time

from diagnostic_msgs.msg import DiagnosticArray
from node_harness import monitor_node, spin_until
import numpy as np
import pytest
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from satmotor_ros.cli.monitor import command
from satmotor_ros.identify.bag import read_bag
from satmotor_ros.identify.health import Baseline, Estimate, HealthMonitor, HealthSamples
from satmotor_ros.identify.health.records import NEVER_HOURS
from satmotor_ros.identify.synthetic import generate_series, Injection, Plan, write_bag_of
from satmotor_ros.interface import CHANNELS, HEALTH_TOPICS, JOINT_NAME
from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA
from satmotor_ros.nodes.motor_monitor import PARAMETERS
from satmotor_ros.options import MotorOptions
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64

NAMESPACE = f'/monitor_node_test_{os.getpid()}'
PACKAGED = os.path.join(os.path.dirname(__file__), '..', 'config', 'sm075_25.yaml')
ONSET = 1800.0  # [s]
EPOCH_NS = 1_700_000_000_000_000_000  # the stamps' origin, as a recording's [ns]


def _stamp_ns(time_s):
    return EPOCH_NS + np.round(np.asarray(time_s) * 1e9).astype(np.int64)


@pytest.fixture(scope='module')
def recording(tmp_path_factory):
    """
    Write the bag and read it back as the CLI does: (bag path, samples).

    The sample times jitter by up to 0.3 s, as a real logger's: no sample sits on a bin's
    edge, where the node's epoch stamps (float seconds, 0.24 us apart) and the bag's time from
    its first message could put it in different bins.
    """
    table = generate_series(Plan(), [Injection('external_leakage', 0.4 * LPM / MPA, 'p_case',
                                               onset=ONSET)],
                            seed=2, samples=2700, rate=1.0, hold_s=20.0)
    jitter = np.random.default_rng(5).uniform(-0.3, 0.3, len(table))
    jitter[0] = 0.0
    table = dataclasses.replace(table, channels={**table.channels,
                                                 'time': table.channels['time'] + jitter})
    path = tmp_path_factory.mktemp('monitor') / 'leak.bag'
    write_bag_of(path, table)
    return path, HealthSamples.from_table(read_bag(path))


def _monitor(context, executor, **overrides):
    return monitor_node(context, executor, NAMESPACE, {
        'motor_file': PACKAGED, 'update_period': 0.2,
        'input_timeout': 60.0,  # the feed is the test's pace
        'diagnostics_period': 3600.0, **overrides})


class Feeder:
    """Publish samples on the motor's topics, one at a time, each waited for by the node."""

    def __init__(self, probe, executor):
        """Open the publishers."""
        self.executor = executor
        sensor = qos_profile_sensor_data
        self.pressure = {name: probe.create_publisher(FluidPressure, CHANNELS[name].topic,
                                                      sensor)
                         for name in ('p_in', 'p_out', 'p_case')}
        self.flow = probe.create_publisher(Float64, CHANNELS['flow_measured'].topic, sensor)
        self.temperature = probe.create_publisher(Temperature, CHANNELS['temperature'].topic,
                                                  sensor)
        self.joint = probe.create_publisher(JointState, CHANNELS['measured_speed'].topic,
                                            sensor)

    def wait_for(self, node):
        """Wait until `node` subscribes every topic."""
        pubs = [*self.pressure.values(), self.flow, self.temperature, self.joint]
        assert spin_until(self.executor, lambda: all(
            p.get_subscription_count() > 0 for p in pubs))
        time.sleep(0.2)  # discovery is not instant on both sides

    def feed(self, node, samples, rows):
        """Send the samples `rows`: the held topics, then joint_states stamped with the time."""
        for i in rows:
            received, taken = node.received, node.taken
            for name, values in (('p_in', samples.p_in), ('p_out', samples.p_out),
                                 ('p_case', samples.p_case)):
                self.pressure[name].publish(FluidPressure(
                    fluid_pressure=float(values[i]) + ATMOSPHERE))
            self.flow.publish(Float64(data=float(samples.flow[i])))
            self.temperature.publish(Temperature(temperature=float(samples.temperature[i])))
            assert spin_until(self.executor, lambda: node.received == received + 5), i
            msg = JointState(name=[JOINT_NAME], velocity=[float(samples.speed[i])])
            sec, nanosec = divmod(int(_stamp_ns(samples.time[i])), 1_000_000_000)
            msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
            self.joint.publish(msg)
            assert spin_until(self.executor, lambda: node.taken == taken + 1), i


def _as_sent(samples):
    """Return the samples as the node receives them: times by the ns, pressures via absolute."""
    t = _stamp_ns(samples.time)
    time_s = (t // 1_000_000_000) + 1e-9 * (t % 1_000_000_000)
    pressures = [(p + ATMOSPHERE) - ATMOSPHERE for p in (samples.p_in, samples.p_out,
                                                         samples.p_case)]
    return HealthSamples(time_s, samples.speed, samples.flow, *pressures[:2], pressures[2],
                         samples.temperature)


def _numbers(snap):
    estimates = (snap.leakage_factor, snap.trend_per_hour, snap.hours_to_limit)
    return [x for e in estimates for x in (e.value, e.low, e.high)] + [
        snap.volumetric_efficiency, snap.n_samples, snap.n_skipped,
        *(a.time_s for a in snap.alarms)]


def _cli_numbers(doc):
    """Return monitor.json's figures in the order of :func:`_numbers` (None as NaN)."""
    def number(x):
        return math.nan if x is None else math.inf if x == NEVER_HOURS else x
    now = doc['leakage_factor_now']
    return [number(x) for x in (
        now['value'], *now['ci95'], doc['trend_per_hour'], *doc['trend_per_hour_ci95'],
        doc['hours_to_limit'], *doc['hours_to_limit_ci95'], doc['volumetric_efficiency_now'],
        doc['n_samples'], doc['n_skipped'], *(a['time_s'] for a in doc['alarms']))]


def _same(got, want):
    assert [(a.kind, a.what) for a in got.alarms] == [(a.kind, a.what) for a in want.alarms]
    assert _numbers(got) == pytest.approx(_numbers(want), rel=1e-9, nan_ok=True)


@pytest.mark.slow
def test_replayed_bag_gives_the_node_the_figures_of_satmotor_monitor(ros, recording, tmp_path):
    """Every sample over the topics: the node's figures are the CLI's, and published."""
    context, executor, probe = ros
    path, samples = recording
    node = _monitor(context, executor)
    published = {topic: [] for topic in HEALTH_TOPICS}
    for topic, got in published.items():
        probe.create_subscription(Float64, topic, got.append, 10)
    diagnostics = []
    probe.create_subscription(DiagnosticArray, '/diagnostics', diagnostics.append, 10)
    feeder = Feeder(probe, executor)
    feeder.wait_for(node)
    feeder.feed(node, samples, range(len(samples)))
    node.update()
    reference = HealthMonitor(Baseline.load(PACKAGED, 'oil'))
    reference.update(_as_sent(samples))
    want = reference.snapshot()
    got = node.monitor.snapshot()
    _same(got, want)
    assert want.alarms and math.isfinite(want.leakage_factor.value)  # the test means something
    assert command([str(path)], str(tmp_path / 'cli'),
                   MotorOptions(motor_file=PACKAGED, liquid='oil')) == 0
    cli = json.loads((tmp_path / 'cli' / 'monitor.json').read_text())
    assert [(a['kind'], a['what']) for a in cli['alarms']] == \
        [(a.kind, a.what) for a in got.alarms]
    assert _numbers(got) == pytest.approx(_cli_numbers(cli), rel=1e-5, nan_ok=True)  # 6 digits
    factor = published[HEALTH_TOPICS[0]]  # the last figure published reaches the probe last:
    # wait for it, not for any (hours_to_limit goes out from the first update, NaN or not)
    assert spin_until(executor, lambda: all(published.values()) and factor[-1].data
                      == pytest.approx(want.leakage_factor.value))
    node.diagnose()
    assert spin_until(executor, lambda: diagnostics)
    (status,) = diagnostics[-1].status
    values = {kv.key: kv.value for kv in status.values}
    assert status.level == b'\x02' and 'change' in status.message
    assert values['alarms'] == str(len(want.alarms))
    assert values['samples'] == str(len(samples))
    assert values['last alarm'].startswith('change at')
    assert '[' in values['leakage_factor ci95 [-]']


@pytest.mark.slow
def test_state_file_carries_the_history_over_a_restart(ros, recording, tmp_path):
    """Half the samples, the node shut down, a new one resumes: as if it had run on."""
    context, executor, probe = ros
    _, samples = recording
    state = tmp_path / 'health.json'
    feeder = Feeder(probe, executor)
    half = len(samples) // 2
    first = _monitor(context, executor, state_file=str(state))
    feeder.wait_for(first)
    feeder.feed(first, samples, range(half))
    executor.remove_node(first)
    first.destroy_node()
    assert state.is_file()
    second = _monitor(context, executor, state_file=str(state))
    assert second.monitor.snapshot().n_samples == half
    feeder.wait_for(second)
    feeder.feed(second, samples, range(half, len(samples)))
    second.update()
    reference = HealthMonitor(Baseline.load(PACKAGED, 'oil'))
    sent = _as_sent(samples)
    reference.update(sent.take(slice(0, half)))
    reference.update(sent.take(slice(half, None)))
    _same(second.monitor.snapshot(), reference.snapshot())


def test_a_state_file_that_is_not_ours_is_reported_and_never_written_over(ros, tmp_path):
    """A foreign file at state_file: the node starts afresh, says so, leaves the file alone."""
    context, executor, _ = ros
    foreign = tmp_path / 'notes.json'
    foreign.write_text('{"mine": true}')
    node = _monitor(context, executor, state_file=str(foreign))
    node.save()
    executor.remove_node(node)
    node.destroy_node()
    assert foreign.read_text() == '{"mine": true}'
    assert node.level(node.monitor.snapshot())[0] == 2


def test_bad_input_and_missing_topics_are_counted_reported_and_survived(ros, recording):
    """Bad flows, a joint_states of another joint, samples out of order, silent topics."""
    context, executor, probe = ros
    _, samples = recording
    node = _monitor(context, executor, input_timeout=0.3)
    level, message = node.level(node.monitor.snapshot())
    assert level == 1 and 'joint_states' in message and 'inlet_pressure' in message
    feeder = Feeder(probe, executor)
    feeder.wait_for(node)
    feeder.feed(node, samples, range(5))
    feeder.flow.publish(Float64(data=math.nan))
    feeder.joint.publish(JointState(name=['other'], velocity=[1.0]))
    old = JointState(name=[JOINT_NAME], velocity=[10.0])  # stamped 1 s: before the last
    old.header.stamp.sec = 1
    feeder.joint.publish(old)
    assert spin_until(executor, lambda: node.bad and node.no_joint and node.out_of_order)
    assert node.taken == 5 and 'not finite' in node.last_bad
    time.sleep(0.4)  # every topic falls silent: a sample now is stale
    node.take(EPOCH_NS * 1e-9 + 100.0, float(samples.speed[4]),
              node.get_clock().now().nanoseconds * 1e-9)
    node.update()
    assert node.monitor.snapshot().n_samples == 6  # held: too few to know their step yet
    node.monitor.flush()  # judged with the steps they have
    snap = node.monitor.snapshot()
    assert snap.n_samples == 6, snap.skipped
    assert snap.skipped['stale'] == 1
    assert node.level(snap)[0] >= 1


def test_a_flowmeter_that_falls_silent_is_not_replaced_by_the_command(ros):
    """Once the flowmeter has spoken, a sample without it is stale and the node says so."""
    context, executor, _ = ros
    node = _monitor(context, executor, input_timeout=1.0)
    now = node._now()
    node._held.update(flow_measured=30.0 * LPM, flow=25.0 * LPM, p_in=10.0 * MPA, p_out=0.5 * MPA)
    node._heard.update(flow_measured=now - 10.0, flow=now, p_in=now, p_out=now)
    node._last_heard_joint = now
    node.take(1.0, 50.0, now)
    assert node._block['stale'][-1] == 1.0
    assert CHANNELS['flow_measured'].topic in node.quiet()
    assert node.level(node.monitor.snapshot())[0] == 1
    node._heard['flow_measured'] = -math.inf  # no flowmeter at all: the command is the flow
    node.take(2.0, 50.0, now)
    assert node._block['stale'][-1] == 0.0 and node._block['flow'][-1] == 25.0 * LPM
    executor.remove_node(node)
    node.destroy_node()


def test_parameters_have_units_ranges_and_the_shipped_file_lists_them_all():
    """config/motor_monitor.yaml cannot drift from the declared parameters."""
    from pathlib import Path

    import yaml
    path = Path(__file__).resolve().parent.parent / 'config' / 'motor_monitor.yaml'
    doc = yaml.safe_load(path.read_text())['/**/motor_monitor']['ros__parameters']
    assert doc == {spec.name: spec.default for spec in PARAMETERS}
    for spec in PARAMETERS:
        if isinstance(spec.default, float):
            assert spec.low is not None and spec.high is not None, spec.name


def test_a_bad_parameter_change_is_refused_and_a_good_one_restarts_the_estimator(ros):
    """A family the file is not, refused with its reason; a new limit: a fresh estimator."""
    context, executor, _ = ros
    node = _monitor(context, executor)
    before = node.monitor
    refused = node.set_parameters([Parameter('family', value='paszota')])[0]
    assert not refused.successful and 'family' in refused.reason
    assert node.monitor is before
    assert node.set_parameters([Parameter('limit_leakage_factor', value=3.0)])[0].successful
    assert node.monitor is not before and node.monitor.settings.limit_leakage_factor == 3.0


def test_after_a_change_hours_to_limit_is_published_as_nan_with_the_reason(ros):
    """
    Wear, then a step below the limit (review F4): the topic goes NaN, never holds the old one.

    Before the change the node published a figure (inf: not drifting significantly); with no
    trend since the change it published nothing, so a subscriber kept that figure.
    """
    from health_data import blocks, recording
    context, executor, probe = ros
    node = _monitor(context, executor)
    got, diagnostics = [], []
    probe.create_subscription(Float64, HEALTH_TOPICS[2], got.append, 10)
    probe.create_subscription(DiagnosticArray, '/diagnostics', diagnostics.append, 10)
    samples = recording(1.6, seed=1, rate_hz=1.0, baseline=node.monitor.baseline,
                        scale=lambda t: np.where(t >= 4320.0, 1.4, 1.0 + 0.1 * t / 3600.0))
    held = math.nan
    for block in blocks(samples, 300):
        node.monitor.update(block)
        if node.monitor.alarms:
            break
        node.publish(node.monitor.snapshot())
        held = node.monitor.snapshot().hours_to_limit.value
    assert not math.isnan(held)  # a figure before the change
    assert spin_until(executor, lambda: got and got[-1].data == held)
    count = len(got)
    node.publish(node.monitor.snapshot())
    assert spin_until(executor, lambda: len(got) > count) and math.isnan(got[-1].data)
    ours = [d for d in diagnostics if d.status[0].name.startswith(NAMESPACE)]
    node.diagnose()
    assert spin_until(executor, lambda: ours or ours.extend(
        d for d in diagnostics if d.status[0].name.startswith(NAMESPACE)))
    values = {kv.key: kv.value for kv in ours[-1].status[0].values}
    change = node.monitor.alarms[0].change_s
    assert values['hours_to_limit [h]'] == 'nan'
    assert f'since the change at {change:.0f} s' in values['hours_to_limit note'], values
    executor.remove_node(node)
    node.destroy_node()


def test_the_node_judges_the_limit_by_the_estimator_s_rule(ros):
    """
    ERROR on the estimator's crossing, not on the window's value alone (review F6).

    A window whose value is above the limit but whose interval reaches below it is no
    crossing; a trend above it is one, even with the window below and the alarm acknowledged.
    """
    context, executor, _ = ros
    node = _monitor(context, executor)
    fresh = node.monitor.snapshot()
    noisy = dataclasses.replace(fresh, learning=False,
                                leakage_factor=Estimate(2.05, 1.8, 2.3), in_limit=False)
    assert node.level(noisy)[0] < 2, node.level(noisy)
    crossed = dataclasses.replace(noisy, leakage_factor=Estimate(1.95, 1.7, 2.2),
                                  trend=Estimate(2.1, 2.0, 2.2), in_limit=True)
    level, message = node.level(crossed)
    assert level == 2 and message.startswith('limit crossed') and 'trend 2.1' in message
    executor.remove_node(node)
    node.destroy_node()
