# SPDX-License-Identifier: Apache-2.0
"""A lockstep plant says at once that nobody answers it, and notices two controllers (issue 25)."""

import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from node_harness import unique_namespace
from rclpy.parameter import Parameter
from satmotor_ros.nodes.speed_controller import SpeedControllerNode
from satmotor_ros.nodes.virtual_motor import VirtualMotorNode


def _statuses(harness, ns):
    seen = []

    def take(msg):
        seen.extend(s for s in msg.status if s.name.startswith(ns + '/'))
    harness.node.create_subscription(DiagnosticArray, '/diagnostics', take, 100)
    return seen


def _plant(harness, ns, **overrides):
    values = {'clock_mode': 'lockstep', 'lockstep_wait': 0.5, 'paused': True, **overrides}
    node = VirtualMotorNode(context=harness.context, namespace=ns, parameter_overrides=[
        Parameter(k, value=v) for k, v in values.items()])
    harness.executor.add_node(node)
    return node


def test_lockstep_with_no_controller_reports_within_seconds_of_wall_time(harness):
    ns = unique_namespace('alone')
    seen = _statuses(harness, ns)
    plant = _plant(harness, ns)
    try:
        harness.spin_until(lambda: harness.node.count_subscribers('/diagnostics') > 1, 5.0)
        harness.spin_for(0.3)
        start = time.monotonic()
        assert plant.set_parameters([Parameter('paused', value=False)])[0].successful
        assert harness.spin_until(lambda: any(
            s.level == DiagnosticStatus.WARN and 'no flow_command' in s.message for s in seen),
            10.0), [s.message for s in seen]
        assert time.monotonic() - start < 3.0  # was 61 s: one sim second of 0.5 s waits
        assert plant.plant.state.time < 0.1  # simulated time crawls, the report does not
    finally:
        harness.executor.remove_node(plant)
        plant.destroy_node()


def test_two_controllers_on_one_lockstep_plant_are_named(harness):
    ns = unique_namespace('two')
    seen = _statuses(harness, ns)
    plant = _plant(harness, ns, diagnostics_period=0.2)
    controllers = [SpeedControllerNode(name, context=harness.context, namespace=ns,
                                       parameter_overrides=[Parameter('use_sim_time', value=True)])
                   for name in ('speed_controller', 'second_controller')]
    for node in controllers:
        harness.executor.add_node(node)
    try:
        assert harness.spin_until(lambda: plant.count_publishers(f'{ns}/flow_command') == 2, 10)
        assert plant.set_parameters([Parameter('paused', value=False)])[0].successful
        assert harness.spin_until(lambda: any(
            '2 publishers on flow_command' in s.message for s in seen), 10.0), \
            [s.message for s in seen]
        warned = next(s for s in seen if '2 publishers on flow_command' in s.message)
        assert warned.level == DiagnosticStatus.WARN
        assert {kv.key: kv.value for kv in warned.values}['flow_command publishers'] == '2'
    finally:
        for node in (plant, *controllers):
            harness.executor.remove_node(node)
            node.destroy_node()


def test_one_controller_on_a_lockstep_plant_is_not_warned_about(harness):
    ns = unique_namespace('one')
    seen = _statuses(harness, ns)
    plant = _plant(harness, ns, diagnostics_period=0.2)
    controller = SpeedControllerNode(context=harness.context, namespace=ns, parameter_overrides=[
        Parameter('use_sim_time', value=True)])
    harness.executor.add_node(controller)
    try:
        assert harness.spin_until(lambda: plant.count_publishers(f'{ns}/flow_command') == 1, 10)
        assert plant.set_parameters([Parameter('paused', value=False)])[0].successful
        assert harness.spin_until(lambda: len([s for s in seen if 'plant' in s.name]) >= 5, 10)
        assert not [s.message for s in seen if 'publishers on flow_command' in s.message]
    finally:
        for node in (plant, controller):
            harness.executor.remove_node(node)
            node.destroy_node()
