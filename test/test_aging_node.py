# SPDX-License-Identifier: Apache-2.0
"""The virtual_motor node ages on its sim clock: wear and a step fault from its parameters."""

import os

from diagnostic_msgs.msg import DiagnosticArray
from node_harness import spin_until
from rclpy.parameter import Parameter
from satmotor_ros.model.effects import Effect
from satmotor_ros.model.units import LPM
from satmotor_ros.nodes.virtual_motor import VirtualMotorNode
from std_msgs.msg import Float64

NAMESPACE = f'/aging_node_test_{os.getpid()}'


def _fault_reports(messages, name):
    for msg in messages:
        for status in msg.status:
            if status.name.startswith(name):
                yield {kv.key: kv.value for kv in status.values}['fault']


def test_node_wears_and_reports_the_fault_striking_on_its_sim_clock(ros):
    """fault.* and effects.clearance_wear_rate as parameters: /diagnostics says when it struck."""
    context, executor, probe = ros
    overrides = {'clock_mode': 'sim', 'diagnostics_period': 0.25, 'fault.time': 1.0,
                 'fault.effect': 'external_leakage', 'fault.value': 1.0e-12,
                 'effects.clearance_wear_rate': 1.0e-9, 'load.torque': 40.0}
    node = VirtualMotorNode(context=context, namespace=NAMESPACE, parameter_overrides=[
        Parameter(k, value=v) for k, v in overrides.items()])
    executor.add_node(node)
    try:
        assert node.plant.params.effects == (Effect('clearance_wear', 1.0e-9, 'time'),)
        diagnostics = []
        probe.create_subscription(DiagnosticArray, '/diagnostics', diagnostics.append, 10)
        command = probe.create_publisher(Float64, f'{NAMESPACE}/flow_command', 10)
        spin_until(executor, lambda: command.get_subscription_count() > 0, 5.0)
        command.publish(Float64(data=20.0 * LPM))
        assert spin_until(executor, lambda: node.plant.state.time > 2.0)
        assert node.plant.fault_struck and node.plant.flows.leakage > 0.0
        spin_until(executor, lambda: any('struck' in f for f in _fault_reports(
            diagnostics, node.get_fully_qualified_name())), 5.0)
        reports = list(_fault_reports(diagnostics, node.get_fully_qualified_name()))
        assert any(r == 'effects.external_leakage = 1e-12: strikes at 1 s' for r in reports)
        assert reports[-1] == 'effects.external_leakage = 1e-12: struck at 1 s'
        refused = node.set_parameters([Parameter('fault.value', value=1.0)])[0]
        assert not refused.successful and 'FaultParams.value' in refused.reason
        both = node.set_parameters([Parameter('effects.clearance_wear', value=1.0e-9)])[0]
        assert not both.successful and 'clearance_wear_rate' in both.reason
    finally:
        executor.remove_node(node)
        node.destroy_node()
