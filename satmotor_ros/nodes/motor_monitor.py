# SPDX-License-Identifier: Apache-2.0
"""
The ``motor_monitor`` node: the motor's health over time, live, on its topics.

Subscribes ``flow_measured`` (else ``flow_command``), ``inlet_pressure``,
``outlet_pressure``, ``joint_states`` and, when they are published, ``case_pressure``
and ``fluid_temperature`` (names and types from :mod:`satmotor_ros.interface`);
publishes ``health/leakage_factor``, ``health/volumetric_efficiency`` (at the current
operating point), ``health/hours_to_limit`` (std_msgs/Float64; inf when not drifting, NaN
when not known)
and ``/diagnostics``: OK; WARN when the trend reaches the limit within ``warn_hours``
or an input is missing or bad, or most samples of the last ``window_s`` are skipped
(the node sees nothing), but OK "parked, not monitoring" when they are skipped as parked
(standing still with no flow: not a fault); ERROR on a detected change or a crossed limit, until
acknowledged (``acknowledged_alarms``: the alarms stay in the history).

A sample is taken on every ``joint_states`` message (its header stamp is the sample's
time, on the data's own clock), with the latest value of each other topic; a topic not
heard for ``input_timeout`` makes the sample stale (counted and skipped by the
estimator, never folded in). Samples go to the estimator a block per ``update_period``.
The node holds no physics and no statistics: the estimator is
:class:`satmotor_ros.identify.health.HealthMonitor`, the one ``satmotor monitor`` runs.
With ``state_file`` its state is resumed at start and saved every ``save_period`` and at
shutdown, whole or not at all, so hours of history survive a restart; a file that is not
a health state (edited by hand, cut short: the field is named), or a state made with other
settings than the parameters, is ERROR, and never written over: the node runs on afresh and
saves no state until ``state_file`` names a new file; nor is ``state_file`` written over by
a parameter change that starts a new estimator.
"""

from __future__ import annotations

from array import array
from collections import deque
import math
from pathlib import Path
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
import numpy as np
from rcl_interfaces.msg import SetParametersResult
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from rclpy.time import Time
from satmotor_ros.identify.calibrated import Calibrated
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.health import (Baseline, HealthMonitor, HealthSamples,
                                          HealthSettings, HealthSnapshot)
from satmotor_ros.identify.health.records import hours_note, unresolved
from satmotor_ros.identify.health.run import clock_shift, EPOCH_S
from satmotor_ros.interface import CHANNELS, DIAGNOSTICS, HEALTH_TOPICS, JOINT_NAME
from satmotor_ros.model import ModelError
from satmotor_ros.model.units import gauge
from satmotor_ros.nodes import _diagnostics as diag
from satmotor_ros.nodes import _parameters as params
from satmotor_ros.nodes._parameters import ParamSpec, RosParameter
from satmotor_ros.nodes._spin import node_main
from sensor_msgs.msg import FluidPressure, JointState, Temperature
from std_msgs.msg import Float64

INPUTS = ('flow_measured', 'flow', 'p_in', 'p_out', 'p_case', 'temperature')
"""The held channels by their :data:`~satmotor_ros.interface.CHANNELS` name."""

REQUIRED = ('p_in', 'p_out')
"""Held channels a sample cannot do without (and a flow: measured, else commanded)."""

SETTINGS = (
    ParamSpec('false_alarm_hours', 1000.0, 'mean operating hours between false change '
              'alarms; sets the detector threshold', 'h', 1.0, 1.0e9),
    ParamSpec('limit_leakage_factor', 2.0, 'leakage factor at which the motor is worn out',
              '-', 1.0e-3, 1.0e3),
    ParamSpec('limit_volumetric_efficiency', 0.0, 'instead: volumetric efficiency at the '
              'reference point at which it is worn out; 0 uses the leakage factor', '-',
              0.0, 0.999),
    ParamSpec('change_fraction', 0.2, 'relative change of the losses the detector is tuned '
              'to', '-', 1.0e-3, 10.0),
    ParamSpec('learn_hours', 0.25, 'operation that teaches the noise model and the level',
              'h', 1.0e-4, 1.0e4),
    ParamSpec('bin_s', 10.0, 'samples are pooled into bins this long', 's', 0.01, 3600.0),
    ParamSpec('window_s', 300.0, 'window of the windowed leakage factor', 's', 0.01, 1.0e6),
    ParamSpec('trend_hours', 200.0, 'forgetting time constant of the trend', 'h', 1.0e-3,
              1.0e6),
    ParamSpec('min_speed', 0.5, 'below it a sample is stalled', 'rad/s', 0.0, 1.0e4),
)
"""Parameters handed to :class:`HealthSettings` (same names)."""

PARAMETERS = (
    *params.MOTOR_PARAMETERS,
    *SETTINGS,
    ParamSpec('warn_hours', 100.0, 'WARN when the trend reaches the limit within this',
              'h', 0.0, 1.0e9),
    ParamSpec('acknowledged_alarms', 0, 'the first this many alarms are acknowledged (kept, '
              "no longer ERROR); set it to the diagnostics' alarms count; it never goes back",
              '-', 0, 1000000000),
    ParamSpec('joint_name', JOINT_NAME, 'joint whose velocity in joint_states is the speed'),
    ParamSpec('input_timeout', 0.5, 'a held topic older than this makes a sample stale', 's',
              0.001, 3600.0),
    ParamSpec('update_period', 1.0, 'samples go to the estimator (and the health topics '
              'out) this often', 's', 0.01, 3600.0),
    ParamSpec('diagnostics_period', 1.0, 'period of /diagnostics', 's', 0.01, 3600.0),
    ParamSpec('state_file', '', 'estimator state: resumed at start, saved every '
              "save_period and at shutdown; '' keeps no state"),
    ParamSpec('save_period', 60.0, 'how often the state is saved', 's', 1.0, 1.0e6),
    ParamSpec('max_block', 100000, 'most samples held between updates (the oldest dropped '
              'beyond, counted)', '-', 10, 10000000, read_only=True),
)
"""The node's parameters: name, default, description, unit and accepted values."""

SKIPPED_SHARE = 0.5
"""WARN when more than this share of the samples of the last ``window_s`` was skipped."""

_SPECS = {spec.name: spec for spec in PARAMETERS}
_SETTING_NAMES = tuple(s.name for s in SETTINGS)
_REBUILD = {*params.MOTOR_KEYS, *(s.name for s in SETTINGS)}
_QUIET = PublisherEventCallbacks(use_default_callbacks=False)
_QUIET_SUBSCRIPTION = SubscriptionEventCallbacks(use_default_callbacks=False)
_COLUMNS = ('time', 'speed', 'flow', 'p_in', 'p_out', 'p_case', 'temperature', 'stale')


def settings_from(values: dict[str, Any]) -> HealthSettings:
    """
    Build the estimator's settings from the node parameters.

    Parameters
    ----------
    values : dict
        Parameter name -> value (see :data:`PARAMETERS`), [SI, hours]

    Returns
    -------
    HealthSettings
        The settings; a 0 ``limit_volumetric_efficiency`` is none.

    """
    given = {s.name: values[s.name] for s in SETTINGS}
    given['limit_volumetric_efficiency'] = given['limit_volumetric_efficiency'] or None
    return HealthSettings(**given)


def baseline_from(values: dict[str, Any]) -> Baseline:
    """
    Build the healthy motor the parameters name: a motor file, or a family at a displacement.

    Parameters
    ----------
    values : dict
        Parameter name -> value, [-]

    Returns
    -------
    Baseline
        With the envelope a calibrated ``coefficients.yaml`` records.

    Raises
    ------
    ModelError
        If the options do not make a motor (a family the file is not, ...), naming it.

    """
    model = params.motor_options(values).build_model()
    path = values['motor_file']
    if not path:
        return Baseline(model)
    return Baseline(model, Calibrated(path).envelope, path)


class MotorMonitorNode(Node):
    """
    Track the motor's health from its topics.

    Parameters
    ----------
    node_name : str
        Name of the node, [-]
    **kwargs : Any
        Passed to :class:`rclpy.node.Node` (namespace, context, parameter_overrides, ...), [-]

    """

    def __init__(self, node_name: str = 'motor_monitor', **kwargs: Any) -> None:
        """Declare parameters, build or resume the estimator, open the topics."""
        super().__init__(node_name, **kwargs)
        self._problems = params.declare_logged(self, PARAMETERS)
        values = self._values = params.values(self, PARAMETERS)
        self.monitor: HealthMonitor | None = None
        self._error = ''  # why there is no estimator, or why it failed
        self._state_note = ''  # what happened to the state file
        self._may_save = True  # False: the state file is someone else's
        self._mismatch = ''  # the resumed state's settings that differ from the parameters
        self._refused = ''  # why the state file was not resumed (not a health state)
        self._build(values, resume=True)
        self._acknowledge()
        self._held = {name: math.nan for name in INPUTS}
        self._heard = {name: -math.inf for name in INPUTS}  # node clock at reception [s]
        self._block: dict[str, array[float]] = {c: array('d') for c in _COLUMNS}
        self._optional = {'p_case': False, 'temperature': False}  # ever heard
        self._last_time = -math.inf  # of the last sample, on the monitor's clock [s]
        if self.monitor is not None and math.isfinite(self.monitor.t_last):
            self._last_time = self.monitor.t_last  # a resumed state's
        self._resumed = math.isfinite(self._last_time)  # the next sample is the first since
        self._shift = 0.0  # added to the stamps: their clock started again (clock_shift) [s]
        self._recent: deque[tuple[float, int, dict[str, int]]] = deque()  # per update:
        # (last time, samples, skipped by reason) over the last window_s
        self._last_heard_joint = -math.inf  # node clock [s]
        self.taken = self.dropped = self.out_of_order = self.bad = self.no_joint = 0
        self.clock_restarts = 0
        self.received = 0  # messages of the held topics taken
        self.last_bad = ''
        self._alarms_seen = 0
        self._pub = {topic: self.create_publisher(Float64, topic, 10, event_callbacks=_QUIET)
                     for topic in HEALTH_TOPICS}
        self._pub_diag = self.create_publisher(DiagnosticArray, DIAGNOSTICS, 10,
                                               event_callbacks=_QUIET)
        sensor = qos_profile_sensor_data
        for kind, name, callback in (
                (Float64, 'flow_measured', self._on_float('flow_measured')),
                (Float64, 'flow', self._on_float('flow')),
                (FluidPressure, 'p_in', self._on_pressure('p_in')),
                (FluidPressure, 'p_out', self._on_pressure('p_out')),
                (FluidPressure, 'p_case', self._on_pressure('p_case')),
                (Temperature, 'temperature', self._on_temperature),
                (JointState, 'measured_speed', self._on_joint_states)):
            self.create_subscription(kind, CHANNELS[name].topic, callback, sensor,
                                     event_callbacks=_QUIET_SUBSCRIPTION)
        self._update_timer = self.create_timer(values['update_period'], self.update)
        self._diag_timer = self.create_timer(values['diagnostics_period'], self.diagnose)
        self._save_timer = self.create_timer(values['save_period'], self.save)
        self.add_on_set_parameters_callback(self._check_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)

    # -- the estimator ----------------------------------------------------------------------

    def _build(self, values: dict[str, Any], resume: bool) -> None:
        try:
            baseline = baseline_from(values)
            settings = settings_from(values)
        except (ModelError, DataError, OSError, ValueError) as err:
            self.monitor, self._error = None, f'no baseline: {err}'
            self.get_logger().error(self._error)
            return
        self._error = ''
        path = values['state_file']
        if resume and path and Path(path).exists():
            try:
                resumed = HealthMonitor.resume(path, baseline)
                differ = resumed.settings.differences(settings, _SETTING_NAMES)
                if not differ:
                    self.monitor = resumed
                    self._state_note = f'resumed from {path}'
                    self.get_logger().info(self._state_note)
                    return
                self._may_save = False
                self._mismatch = '; '.join(f'{k}: state {was!r}, parameter {now!r}'
                                           for k, (was, now) in differ.items())
                self._state_note = (f'{path} was made with other settings ({self._mismatch}): '
                                    'not resumed, not written over; starting afresh; give '
                                    'the same parameters or a new state_file')
                self.get_logger().error(self._state_note)
            except DataError as err:  # hand-edited, cut short, not ours: refused, kept
                self._may_save = False
                self._refused = self._state_note = (
                    f'{err}; starting afresh and saving no state (the file is kept as it is: '
                    'give a new state_file, or mend or remove this one and restart)')
                self.get_logger().error(self._state_note)
        self.monitor = HealthMonitor(baseline, settings)

    def _check_parameters(self, request: list[RosParameter]) -> SetParametersResult:
        def build(proposed: dict[str, Any], changed: set[str]) -> None:
            settings_from(proposed)
            if changed & set(params.MOTOR_KEYS):
                baseline_from(proposed)
            self._protect_state(proposed, changed)
        return params.check_proposed(_SPECS, request, self._values, build,
                                     (ModelError, DataError, OSError, ValueError))

    def _protect_state(self, proposed: dict[str, Any], changed: set[str]) -> None:
        """
        Refuse a change that would write over a state the node did not start from.

        Raises
        ------
        ValueError
            A new ``state_file`` that exists, or a change that starts a new estimator while
            ``state_file`` holds the history of this one (give a new ``state_file`` with it).

        """
        path, now = proposed['state_file'], self._values['state_file']
        if 'state_file' in changed and path and path != now and Path(path).exists():
            msg = (f'state_file {path!r} exists: the node writes only a state it started '
                   'from; give a new path, or restart the node to resume it')
            raise ValueError(msg)
        rebuild = sorted(changed & _REBUILD)
        if rebuild and path and path == now and self._may_save and self.monitor is not None:
            held = self.monitor.snapshot().n_samples
            if held:
                msg = (f'{", ".join(rebuild)}: a new estimator would write over the history '
                       f'of {held} samples in state_file {path!r}; set a new state_file (or '
                       "'') in the same call")
                raise ValueError(msg)

    def _apply_parameters(self, changed: list[RosParameter]) -> None:
        names = {p.name for p in changed}
        for name in names:
            self._problems.pop(name, None)
        values = self._values = params.values(self, PARAMETERS)
        if names & _REBUILD:  # a new baseline or new settings: the history means another motor
            self.get_logger().warning(f'{", ".join(sorted(names & _REBUILD))} changed: the '
                                      'estimator starts afresh')
            self._build(values, resume=False)
        for timer, key, callback in ((self._update_timer, 'update_period', self.update),
                                     (self._diag_timer, 'diagnostics_period', self.diagnose),
                                     (self._save_timer, 'save_period', self.save)):
            if key in names:
                self.destroy_timer(timer)
                setattr(self, f'_{key.split("_")[0]}_timer',
                        self.create_timer(values[key], callback))
        if 'state_file' in names:
            self._may_save, self._state_note, self._mismatch, self._refused = True, '', '', ''
        if 'acknowledged_alarms' in names:
            self._acknowledge()

    def _acknowledge(self) -> None:
        """Acknowledge the first ``acknowledged_alarms`` alarms (the estimator keeps them)."""
        if self.monitor is not None and self._values['acknowledged_alarms'] > 0:
            count = self.monitor.acknowledge(self._values['acknowledged_alarms'])
            self.get_logger().info(f'{count} of {len(self.monitor.alarms)} alarms acknowledged')

    # -- inputs -----------------------------------------------------------------------------

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1.0e-9

    def _hold(self, name: str, value: float, what: str) -> None:
        if not math.isfinite(value):  # a NaN held would spoil every sample until the next
            self.bad += 1
            self.last_bad = f'{what} = {value!r}: not finite'
            self.get_logger().warning(f'{self.last_bad}; ignored', throttle_duration_sec=5.0)
            return
        self._held[name] = value
        self._heard[name] = self._now()
        self.received += 1

    def _on_float(self, name: str) -> Any:
        topic = CHANNELS[name].topic

        def on_float(msg: Float64) -> None:
            self._hold(name, msg.data, f'{topic}.data')
        return on_float

    def _on_pressure(self, name: str) -> Any:
        topic = CHANNELS[name].topic

        def on_pressure(msg: FluidPressure) -> None:
            if name in self._optional:
                self._optional[name] = True
            self._hold(name, gauge(msg.fluid_pressure), f'{topic}.fluid_pressure')
        return on_pressure

    def _on_temperature(self, msg: Temperature) -> None:
        self._optional['temperature'] = True
        self._hold('temperature', msg.temperature, 'fluid_temperature.temperature')

    def _on_joint_states(self, msg: JointState) -> None:
        try:
            speed = msg.velocity[msg.name.index(self._values['joint_name'])]
        except (ValueError, IndexError):
            self.no_joint += 1  # no such joint, or no velocity for it: not a measurement
            return
        stamp = msg.header.stamp
        now = self._last_heard_joint = self._now()
        t = stamp.sec + 1.0e-9 * stamp.nanosec if (stamp.sec or stamp.nanosec) else now
        self.take(t, speed, now)

    def _in_order(self, t: float) -> float:
        """
        Return a stamp on the monitor's clock, or NaN for a sample out of order.

        A stamp that goes back by more than ``input_timeout`` (or at all, the first after a
        resumed state) on a clock that is not an epoch clock is a clock that started again (a
        simulation restarted, a replay): shifted as ``satmotor monitor`` shifts a recording
        (:func:`~satmotor_ros.identify.health.run.clock_shift`), never skipped as stale.
        """
        shifted = t + self._shift
        resumed, self._resumed = self._resumed, False
        if shifted > self._last_time:
            return shifted
        back = self._last_time - shifted
        if (resumed or back > self._values['input_timeout']) and \
                self._last_time - self._shift <= EPOCH_S:
            shift = clock_shift(self._last_time, t)
            if shift:
                self._shift = shift
                self.clock_restarts += 1
                self.get_logger().warning(f'the stamps went back {back:.1f} s: their clock '
                                          f'started again; shifted by {shift:.1f} s')
                return t + shift
        self.out_of_order += 1  # the estimator takes samples in time order only
        return math.nan

    def take(self, t: float, speed: float, now: float) -> None:
        """
        Add one sample at time `t` with the held values of the other topics.

        Parameters
        ----------
        t : float
            The sample's time on the data's clock (out of order: counted, not taken), [s]
        speed : float
            Shaft speed, [rad/s]
        now : float
            The node clock, for the inputs' ages, [s]

        """
        t = self._in_order(t)
        if math.isnan(t):
            return
        self._last_time = t
        timeout = self._values['input_timeout']
        fresh = {name: now - heard <= timeout for name, heard in self._heard.items()}
        flow = self._flow_source()
        stale = not (fresh[flow] and all(fresh[n] for n in REQUIRED))
        for name, on in self._optional.items():
            stale = stale or (on and not fresh[name])
        block = self._block
        for column, value in (('time', t), ('speed', speed), ('flow', self._held[flow]),
                              ('p_in', self._held['p_in']), ('p_out', self._held['p_out']),
                              ('p_case', self._held['p_case']),
                              ('temperature', self._held['temperature']),
                              ('stale', float(stale))):
            block[column].append(value)
        self.taken += 1
        if len(block['time']) > self._values['max_block']:
            for values in block.values():
                del values[0]
            self.dropped += 1

    # -- the estimate -----------------------------------------------------------------------

    def update(self, publish: bool = True) -> None:
        """
        Hand the samples held to the estimator and, with `publish`, publish the figures.

        Parameters
        ----------
        publish : bool
            False at shutdown: a signal may have invalidated the context already, [-]

        """
        block = self._block
        if not block['time'] or self.monitor is None:
            return
        arrays = {c: np.frombuffer(v, dtype=float).copy() for c, v in block.items()}
        for column in block.values():
            del column[:]
        samples = HealthSamples(
            arrays['time'], arrays['speed'], arrays['flow'], arrays['p_in'], arrays['p_out'],
            arrays['p_case'] if self._optional['p_case'] else None,
            arrays['temperature'] if self._optional['temperature'] else None,
            arrays['stale'] > 0.0)
        skipped = dict(self.monitor.skipped)
        try:
            alarms = self.monitor.update(samples)
        except DataError as err:  # the estimator refused the block: say so, keep running
            self._error = f'estimator: {err}'
            self.get_logger().error(self._error, throttle_duration_sec=5.0)
            return
        self.monitor.pop_points()  # the per-bin series is the CLI's; the node keeps no list
        self._note_skipped(float(arrays['time'][-1]), len(samples),
                           {k: v - skipped[k] for k, v in self.monitor.skipped.items()})
        for alarm in alarms:
            self.get_logger().error(f'{alarm.kind} alarm at {alarm.time_s:.1f} s: '
                                    f'{alarm.what} (statistic {alarm.statistic:.3g})')
        if publish:
            self.publish(self.monitor.snapshot())

    def _note_skipped(self, last: float, n: int, skipped: dict[str, int]) -> None:
        """Keep the counts of the updates of the last ``window_s`` (of the data's time)."""
        recent = self._recent
        recent.append((last, n, skipped))
        while len(recent) > 1 and recent[0][0] < last - self._values['window_s']:
            recent.popleft()

    def recent_skipped(self) -> tuple[int, dict[str, int]]:
        """
        Return the samples of the last ``window_s`` handed to the estimator, and those skipped.

        Returns
        -------
        tuple of (int, dict)
            The samples, and the skipped ones by reason (samples the estimator still holds
            to learn their step count as neither), [-]

        """
        total = sum(n for _, n, _ in self._recent)
        skipped = {k: sum(s[k] for _, _, s in self._recent) for k in self.monitor.skipped} \
            if self.monitor is not None else {}
        return total, skipped

    def publish(self, snap: HealthSnapshot) -> None:
        """
        Publish the health topics of a snapshot.

        The leakage factor and the efficiency are published once they have a value;
        ``hours_to_limit`` always, NaN when it is not known (no trend yet since the first
        sample or the last change: the diagnostics' ``hours_to_limit note`` says why), so
        that no subscriber holds a figure from before a change.

        Parameters
        ----------
        snap : HealthSnapshot
            The estimator's figures, [-]

        """
        for topic, value in zip(HEALTH_TOPICS, (snap.leakage_factor.value,
                                                snap.volumetric_efficiency,
                                                snap.hours_to_limit.value)):
            if math.isfinite(value) or topic == HEALTH_TOPICS[2]:
                self._pub[topic].publish(Float64(data=float(value)))

    def save(self) -> None:
        """Save the estimator's state to ``state_file`` (whole or not at all)."""
        path = self._values['state_file']
        if not path or self.monitor is None or not self._may_save:
            return
        try:
            self.monitor.save(path)
            self._state_note = f'saved to {path}'
        except OSError as err:
            self._state_note = f'cannot save {path}: {err}'
            self.get_logger().error(self._state_note, throttle_duration_sec=60.0)

    def destroy_node(self) -> None:
        """Feed the last samples and save the state before the node goes."""
        self.update(publish=False)
        self.save()
        super().destroy_node()

    # -- diagnostics ------------------------------------------------------------------------

    def level(self, snap: HealthSnapshot | None) -> tuple[int, str]:
        """
        Judge a snapshot and the inputs: OK, WARN or ERROR and why.

        Parameters
        ----------
        snap : HealthSnapshot or None
            The estimator's figures; None without an estimator, [-]

        Returns
        -------
        tuple of (int, str)
            The level (0, 1, 2) and the message.

        """
        if snap is None or self._error:
            return 2, self._error or 'no estimator'
        if self._problems:
            return 2, f'parameter {"; ".join(self._problems.values())}'
        if self._mismatch or self._refused:
            return 2, self._state_note
        new = snap.unacknowledged
        if new and new[-1].kind == 'change':
            last = new[-1]
            return 2, (f'change at {last.change_s:.1f} s (alarm at {last.time_s:.1f} s): '
                       f'{last.what}')
        if snap.in_limit or (new and new[-1].kind == 'limit'):  # the estimator's rule
            trend = f', trend {snap.trend.value:.3g}' if math.isfinite(snap.trend.value) else ''
            return 2, (f'limit crossed: leakage factor {snap.leakage_factor.value:.3g}{trend} '
                       f'(limit {snap.limit_leakage_factor:.3g})')
        if snap.hours_to_limit.value < self._values['warn_hours']:
            return 1, f'limit within {snap.hours_to_limit.value:.3g} h'
        quiet = self.quiet()
        if quiet:
            return 1, f'no recent message on {", ".join(quiet)}'
        total, skipped = self.recent_skipped()
        parked = ''
        if total and skipped.get('parked', 0) > SKIPPED_SHARE * total:
            # standing still with no flow: nothing to judge and nothing wrong (doc/health.md)
            parked = (f'parked, not monitoring: {skipped["parked"]} of the last {total} '
                      'samples at rest (speed below min_speed, no flow but leakage); the '
                      'figures are from before')
        elif total and sum(skipped.values()) > SKIPPED_SHARE * total:
            why = ', '.join(f'{v} {k.replace("_", " ")}' for k, v in skipped.items() if v)
            return 1, (f'not monitoring: {sum(skipped.values())} of the last {total} samples '
                       f'skipped ({why})')
        if self.bad or self.out_of_order or self.no_joint:
            return 1, f'inputs refused: {self.last_bad or "joint_states out of order"}'
        why = unresolved(snap.leakage_factor, self.monitor.settings.change_fraction) \
            if self.monitor is not None else ''
        if why:
            return 1, why
        state = parked or ('learning' if snap.learning else 'healthy')
        return 0, state + (f' ({snap.acknowledged} alarms acknowledged)'
                           if snap.acknowledged else '')

    def _flow_source(self) -> str:
        """
        Return the flow input: the flowmeter once it has spoken, the command before.

        A flowmeter that falls silent makes the samples stale; the command does not stand in
        for it, since the factor would then measure something else from that sample on.
        """
        return 'flow_measured' if self._heard['flow_measured'] > -math.inf else 'flow'

    def quiet(self) -> list[str]:
        """Name the topics a sample needs that were not heard within ``input_timeout``."""
        now, timeout = self._now(), self._values['input_timeout']
        quiet = [CHANNELS[n].topic for n in REQUIRED if now - self._heard[n] > timeout]
        flow = self._flow_source()
        if now - self._heard[flow] > timeout:
            quiet.append(CHANNELS['flow_measured'].topic if flow == 'flow_measured'
                         else 'flow_measured (or flow_command)')
        if now - self._last_heard_joint > timeout:
            quiet.append(CHANNELS['measured_speed'].topic)
        return quiet

    def diagnose(self) -> None:
        """Publish /diagnostics: the figures with intervals, the alarms, the inputs."""
        snap = self.monitor.snapshot() if self.monitor is not None else None
        level, message = self.level(snap)
        values: dict[str, Any] = {}
        if snap is not None:
            values.update(_figures(snap))
        now = self._now()
        for name in INPUTS:
            values[f'{CHANNELS[name].topic} age [s]'] = diag.human(now - self._heard[name],
                                                                   's')[1]
        recent, skipped = self.recent_skipped()
        values.update({'samples taken': self.taken, 'samples dropped': self.dropped,
                       'joint_states out of order': self.out_of_order,
                       'joint_states without joint': self.no_joint,
                       'clock restarts': self.clock_restarts,
                       'inputs refused': self.bad, 'last refused': self.last_bad,
                       'recent samples': recent, 'recent skipped': sum(skipped.values()),
                       'recent skipped share [-]':
                           f'{sum(skipped.values()) / recent:.3g}' if recent else 'none',
                       **{f'recent skipped {k}': v for k, v in skipped.items()},
                       'state_file': self._values['state_file'] or 'none',
                       'state': self._state_note,
                       'state settings differ': self._mismatch or 'none'})
        if snap is not None and self.monitor is not None:
            values['leakage_factor identifiable'] = not unresolved(
                snap.leakage_factor, self.monitor.settings.change_fraction)
        name = f'{self.get_fully_qualified_name()}: motor health'
        hardware = self.monitor.baseline.source if self.monitor is not None else 'motor'
        self._pub_diag.publish(diag.array(Time(nanoseconds=int(now * 1e9)), [diag.status(
            name, hardware, level, message, values)]))


def _interval(e: Any) -> str:
    return f'[{e.low:.4g}, {e.high:.4g}]'


def _figures(snap: HealthSnapshot) -> dict[str, Any]:
    """Return a snapshot's figures as diagnostics key/values (hours where a person reads)."""
    last = snap.alarms[-1] if snap.alarms else None
    return {
        'leakage_factor [-]': f'{snap.leakage_factor.value:.4g}',
        'leakage_factor ci95 [-]': _interval(snap.leakage_factor),
        'trend_per_hour [1/h]': f'{snap.trend_per_hour.value:.4g}',
        'trend_per_hour ci95 [1/h]': _interval(snap.trend_per_hour),
        'hours_to_limit [h]': f'{snap.hours_to_limit.value:.4g}',
        'hours_to_limit ci95 [h]': _interval(snap.hours_to_limit),
        'hours_to_limit note': hours_note(snap.hours_to_limit.value, snap.hours_to_limit_why),
        'limit_leakage_factor [-]': f'{snap.limit_leakage_factor:.4g}',
        'volumetric_efficiency [-]': f'{snap.volumetric_efficiency:.4g}',
        'volumetric_efficiency reference [-]':
            f'{snap.volumetric_efficiency_reference.value:.4g}',
        'volumetric_efficiency reference ci95 [-]':
            _interval(snap.volumetric_efficiency_reference),
        'operating_hours [h]': f'{snap.operating_hours:.4g}',
        'learning': snap.learning, 'statistic [-]': f'{snap.statistic:.4g}',
        'samples': snap.n_samples, 'skipped': snap.n_skipped,
        **{f'skipped {reason}': count for reason, count in snap.skipped.items()},
        'alarms': len(snap.alarms), 'alarms acknowledged': snap.acknowledged,
        'last alarm': 'none' if last is None else f'{last.kind} at {last.time_s:.1f} s',
        'change_time [s]': f'{snap.change_s:.1f}' if math.isfinite(snap.change_s) else 'none',
        'what changed': snap.what_changed or 'none',
    }


main = node_main(MotorMonitorNode, 'motor_monitor')


__all__ = ['HEALTH_TOPICS', 'MotorMonitorNode', 'PARAMETERS', 'main']


if __name__ == '__main__':
    main()
