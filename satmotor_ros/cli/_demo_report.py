# SPDX-License-Identifier: Apache-2.0
"""The demo's bag writer, series decoding, metrics, plots and report.md."""

from __future__ import annotations

from pathlib import Path
from typing import Any, NamedTuple, Sequence

import matplotlib
import numpy as np

from satmotor_ros.bags import OutTopic, read_series, write_bag
from satmotor_ros.identify.plot_tools import robust_limits
from satmotor_ros.interface import (CHANNELS, LOSS_COMPONENTS, LOSSES_PREFIX,
                                    PREDICTED_JOINT_STATE, SPEED_SETPOINT, VALUE_FIELD)
from satmotor_ros.model import MotorModel
from satmotor_ros.model.units import LPM, RPM
from satmotor_ros.plant.scenario import Cycle, step_metrics, StepMetrics

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402, I100


class RunResult(NamedTuple):
    """One run of the cycle: where its bag is and what was recorded."""

    liquid: str
    feedforward: str
    bag: Path
    messages: dict[str, list[tuple[int, bytes]]]  # topic -> (log time [ns], CDR)
    types: dict[str, str]  # topic -> message type
    wall: float  # wall-clock duration of the run [s]
    sim: float  # simulated duration [s]
    unanswered: int  # lockstep periods taken with no flow command (0: a repeatable run)


def write_run_bag(path: Path, messages: dict[str, list[tuple[int, bytes]]],
                  types: dict[str, str], custom: dict[str, str] | None = None) -> int:
    """
    Write the recorded messages to an MCAP rosbag2, in log-time order.

    Parameters
    ----------
    path : pathlib.Path
        Bag directory to create, [-]
    messages : dict
        Topic -> list of (log time [ns], CDR bytes), [-]
    types : dict
        Topic -> message type, [-]
    custom : dict, optional
        What the bag records of its run (:mod:`satmotor_ros.bags.custom`: liquid, motor), [-]

    Returns
    -------
    int
        Messages written.

    """
    path.parent.mkdir(parents=True, exist_ok=True)
    topics = [OutTopic(topic, types[topic], np.array([t for t, _ in items], dtype=np.int64),
                       [data for _, data in items])
              for topic, items in messages.items() if items]
    return write_bag(path, topics, storage='mcap', custom_data=custom)


def hold(t_from: np.ndarray, v_from: np.ndarray, t_to: np.ndarray) -> np.ndarray:
    """
    Resample a stepwise signal by holding its last value.

    Parameters
    ----------
    t_from : ndarray
        Sample times of the signal, [s]
    v_from : ndarray
        Its values, [any]
    t_to : ndarray
        Times wanted, [s]

    Returns
    -------
    ndarray
        The held values (the first value before the first sample), [any]

    """
    if not len(v_from):
        return np.full_like(t_to, np.nan)
    index = np.clip(np.searchsorted(t_from, t_to, side='right') - 1, 0, len(v_from) - 1)
    return v_from[index]


def _topic(name: str) -> str:
    """Return the absolute topic of a channel (interface.CHANNELS) or of another topic."""
    return '/' + (CHANNELS[name].topic if name in CHANNELS else name)


_SPEED, _TORQUE, _FLOW, _P_IN, _P_OUT, _FLOW_MEASURED, _PREDICTED = (_topic(name) for name in (
    'measured_speed', 'torque', 'flow', 'p_in', 'p_out', 'flow_measured', PREDICTED_JOINT_STATE))
_LOSSES = {c: _topic(LOSSES_PREFIX + c) for c in LOSS_COMPONENTS}
_SETPOINT = _topic(SPEED_SETPOINT)
_PLOTTED = (_SPEED, _SETPOINT, _TORQUE, _FLOW, _P_IN, _P_OUT, _FLOW_MEASURED, _PREDICTED,
            *_LOSSES.values())


def read_run(bag: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """
    Read the plotted topics of a run back from its bag.

    Parameters
    ----------
    bag : pathlib.Path
        The run's bag, [-]

    Returns
    -------
    dict
        Topic -> (log time [s], value [SI]) for the topics in the bag.

    """
    found = read_series(bag, _PLOTTED)
    return {name: (s.t_ns * 1e-9, s.fields[VALUE_FIELD[s.msgtype]]) for name, s in found.items()}


class Tracking:
    """The tracking signals of one run on the joint_states time base."""

    def __init__(self, run: RunResult) -> None:
        """Read speed, set-point, load, flow command and pressures back from the bag."""
        self.run = run
        self.data = data = read_run(run.bag)
        empty = (np.zeros(0), np.zeros(0))
        self.t, self.speed = data[_SPEED]
        t_sp, sp = data.get(_SETPOINT, empty)
        keep = self.t >= (t_sp[0] if len(t_sp) else np.inf)
        self.t, self.speed = self.t[keep], self.speed[keep]
        self.setpoint = hold(t_sp, sp, self.t)
        self.load = hold(*data.get(_TORQUE, empty), self.t)
        self.command = hold(*data.get(_FLOW, empty), self.t)
        self.dp = hold(*data[_P_IN], self.t) - hold(*data[_P_OUT], self.t)
        self.flow = hold(*data[_FLOW_MEASURED], self.t)

    def metrics(self) -> list[StepMetrics]:
        """Measure every step of the run."""
        return step_metrics(self.t, self.setpoint, self.speed, self.load)


def summary(metrics: Sequence[StepMetrics]) -> dict[str, float]:
    """
    Reduce per-step metrics to one row.

    Parameters
    ----------
    metrics : sequence of StepMetrics
        Of one run, [-]

    Returns
    -------
    dict
        Mean rise time [s], largest overshoot [%], mean |steady-state error| [rad/s],
        IAE of set-point and of load steps [rad].

    """
    steps = [m for m in metrics if m.start != m.target]
    loads = [m for m in metrics if m.start == m.target]
    return {
        'rise': float(np.nanmean([m.rise_time for m in steps])) if steps else np.nan,
        'overshoot': max((m.overshoot for m in steps), default=np.nan),
        'sse': float(np.mean([abs(m.steady_state_error) for m in metrics])),
        'iae_steps': sum(m.iae for m in steps), 'iae_loads': sum(m.iae for m in loads),
        'iae': sum(m.iae for m in metrics)}


def settled(tr: Tracking, after: float = 1.0) -> np.ndarray:
    """
    Mark the samples at least `after` seconds past the last set-point or load step.

    Parameters
    ----------
    tr : Tracking
        The run, [-]
    after : float
        Settling allowance, [s]

    Returns
    -------
    ndarray of bool
        True where the run is quasi-steady.

    """
    changed = np.r_[True, (np.diff(tr.setpoint) != 0.0) | (np.diff(tr.load) != 0.0)]
    last_change = np.maximum.accumulate(np.where(changed, tr.t, -np.inf))
    return tr.t - last_change >= after


def _plot_tracking(out: Path, liquid: str, runs: dict[str, Tracking]) -> str:
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True,
                                      gridspec_kw={'height_ratios': [2, 1]})
    first = next(iter(runs.values()))
    top.step(first.t, first.setpoint / RPM, 'k--', where='post', lw=1.2, label='set-point')
    styles = {'model': ('C0', 'model feed-forward + PI'), 'none': ('C3', 'PI alone')}
    for ff, tr in runs.items():
        color, label = styles[ff]
        top.plot(tr.t, tr.speed / RPM, color=color, lw=1.0, label=label)
        bottom.plot(tr.t, tr.command / LPM, color=color, lw=1.0, label=f'Q command, {label}')
    top.set_ylabel('speed [rpm]')
    top.set_title(f'Speed tracking on {liquid} (virtual SM-0,75/25, over ROS topics)')
    top.legend(loc='lower right')
    top.grid(alpha=0.3)
    bottom.set_ylabel('flow command [l/min]')
    bottom.set_xlabel('simulated time [s]')
    twin = bottom.twinx()
    twin.step(first.t, first.load, color='0.5', where='post', lw=1.0)
    twin.set_ylabel('load torque [N*m]', color='0.4')
    bottom.grid(alpha=0.3)
    bottom.legend(loc='upper left', fontsize=8)
    name = f'tracking_{liquid}.png'
    fig.tight_layout()
    fig.savefig(out / name, dpi=110)
    plt.close(fig)
    return name


def predicted(tr: Tracking) -> tuple[np.ndarray, dict[str, np.ndarray], str]:
    """
    Give the model's predicted speed and loss breakdown along a run.

    From the motor_model node's topics when they were recorded, else computed from
    the recorded flow and pressures with the model library.

    Parameters
    ----------
    tr : Tracking
        The run, [-]

    Returns
    -------
    tuple
        Predicted speed [rad/s], losses by component [m^3/s], and where they came from.

    """
    data = tr.data
    if _PREDICTED in data:
        losses = {c: np.nan_to_num(hold(*data[topic], tr.t)) if topic in data
                  else np.zeros_like(tr.t) for c, topic in _LOSSES.items()}
        return (hold(*data[_PREDICTED], tr.t), losses,
                'the motor_model node (its recorded topics)')
    model = MotorModel.default(tr.run.liquid)
    op = model.speed(np.maximum(tr.flow, 0.0), np.maximum(tr.dp, 0.0), errors='mask')
    return op.speed, op.losses.as_dict(), 'the model library on the recorded flow and pressures'


RESIDUAL_SPAN = 10.0
"""The prediction plot's residual axis spans this many times the settled samples' RMS (at least
RESIDUAL_FLOOR): the transients at the steps, hundreds of rpm, would hide the steady bias."""

RESIDUAL_FLOOR = 2.0
"""Least half-height of that axis, [rpm]."""


def _residual_limits(residual: np.ndarray, quiet: np.ndarray) -> tuple[float, float]:
    """Give the residual axis: the whole range, or +-RESIDUAL_SPAN x the settled RMS."""
    whole = float(np.nanmin(residual)), float(np.nanmax(residual))
    rms = float(np.sqrt(np.nanmean(residual[quiet] ** 2))) if quiet.any() else np.nan
    half = max(RESIDUAL_SPAN * rms, RESIDUAL_FLOOR) if np.isfinite(rms) else np.inf
    if not (np.all(np.isfinite(whole)) and max(abs(whole[0]), abs(whole[1])) > half):
        return robust_limits(residual)
    return -half, half


def _plot_prediction(out: Path, liquid: str, tr: Tracking,
                     after: float) -> tuple[str, str, str, tuple[float, float]]:
    n_pred, losses, source = predicted(tr)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 6), sharex=True,
                                      gridspec_kw={'height_ratios': [2, 1]})
    top.plot(tr.t, tr.speed / RPM, 'C0', lw=1.0, label='measured (virtual motor)')
    top.plot(tr.t, n_pred / RPM, 'C1--', lw=1.0, label='predicted (model)')
    top.set_ylabel('speed [rpm]')
    top.set_title(f'Predicted against measured speed on {liquid}')
    top.legend(loc='lower right')
    top.grid(alpha=0.3)
    residual = (tr.speed - n_pred) / RPM
    limits = _residual_limits(residual, settled(tr, after))
    bottom.plot(tr.t, np.clip(residual, *limits), 'C2', lw=0.8)
    bottom.set_ylim(*limits)
    beyond = int(np.sum((residual < limits[0]) | (residual > limits[1])))
    if beyond:
        bottom.text(0.99, 0.95, f'{beyond} samples beyond the axis (transients at the steps), '
                    'cut at its edge', transform=bottom.transAxes, ha='right', va='top',
                    fontsize=8, color='0.3')
    bottom.set_ylabel('measured - predicted [rpm]')
    bottom.set_xlabel('simulated time [s]')
    bottom.grid(alpha=0.3)
    fig.tight_layout()
    name = f'prediction_{liquid}.png'
    fig.savefig(out / name, dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(10, 4.5))
    parts = [c for c in LOSS_COMPONENTS if c != 'total']
    stack = [np.nan_to_num(losses[c]) / LPM for c in parts]
    ax.stackplot(tr.t, *stack, labels=parts, alpha=0.85)
    ax.plot(tr.t, np.nan_to_num(losses['total']) / LPM, 'k', lw=0.8, label='total')
    ax.set_ylabel('volumetric loss [l/min]')
    ax.set_xlabel('simulated time [s]')
    ax.set_title(f'Loss breakdown over the cycle on {liquid} (eq. 31)')
    ax.legend(loc='upper left', fontsize=8, ncol=4)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    loss_name = f'losses_{liquid}.png'
    fig.savefig(out / loss_name, dpi=110)
    plt.close(fig)
    quiet = settled(tr, after)
    if quiet.any():
        stats = (float(np.nanmedian(residual[quiet])),
                 float(np.sqrt(np.nanmean(residual[quiet] ** 2))))
    else:
        stats = (np.nan, np.nan)
    return name, loss_name, source, stats


def write_report(out: Path, runs: list[RunResult], cycle: Cycle,
                 effects: dict[str, Any], closing: Sequence[str] = ()) -> Path:
    """
    Write report.md with its PNG plots.

    Parameters
    ----------
    out : pathlib.Path
        Output directory, [-]
    runs : list of RunResult
        The runs, [-]
    cycle : Cycle
        The cycle they ran, [-]
    effects : dict
        Injected effects, [-]
    closing : sequence of str
        The closing-the-loop section, after the runs (none when empty), [-]

    Returns
    -------
    pathlib.Path
        The report.

    """
    lines = ['# satmotor demo', '',
             'The virtual motor (`virtual_motor` node), the speed controller '
             '(`speed_controller`), the motor model (`motor_model`) and the set-point '
             'script ran in one process on one '
             "executor, over real ROS 2 topics, on the virtual motor's `/clock`. Each run "
             'is recorded in full to an MCAP bag under `bags/`.', '',
             '## Cycle', '', '| from [s] | to [s] | set-point [rpm] | load torque [N*m] |',
             '| ---: | ---: | ---: | ---: |']
    t0 = 0.0
    for s in cycle.segments:
        lines.append(f'| {t0:.1f} | {t0 + s.duration:.1f} | {s.setpoint / RPM:.0f} | '
                     f'{s.load:.0f} |')
        t0 += s.duration
    lines += ['', 'Effects injected into the plant: ' + (', '.join(
        f'`{k} = {v}`' for k, v in effects.items()) or 'none') + '.', '']
    table = ['## Metrics', '',
             'Rise time 10-90 % (mean over the set-point steps), largest overshoot, mean '
             '|steady-state error| over the last 20 % of each segment, and the integral of '
             'the absolute speed error (IAE) after set-point steps and after load steps.', '',
             '| liquid | feed-forward | rise time [ms] | overshoot [%] | steady-state error '
             '[rpm] | IAE set-point steps [rad] | IAE load steps [rad] | IAE total [rad] |',
             '| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |']
    sections = []
    for liquid in dict.fromkeys(r.liquid for r in runs):
        tracks = {r.feedforward: Tracking(r) for r in runs if r.liquid == liquid}
        for ff, tr in tracks.items():
            stats = summary(tr.metrics())
            table.append(f'| {liquid} | {"model" if ff == "model" else "none (PI alone)"} | '
                         f'{stats["rise"] * 1e3:.0f} | {stats["overshoot"]:.1f} | '
                         f'{stats["sse"] / RPM:.3f} | {stats["iae_steps"]:.2f} | '
                         f'{stats["iae_loads"]:.2f} | {stats["iae"]:.2f} |')
        tracking = _plot_tracking(out, liquid, tracks)
        main = tracks.get('model') or next(iter(tracks.values()))
        after = min(1.0, 0.5 * min(s.duration for s in cycle.segments))
        pred, losses, source, (bias, rms) = _plot_prediction(out, liquid, main, after)
        sections += [f'## {liquid.capitalize()}', '', f'![tracking]({tracking})', '',
                     f'![predicted against measured]({pred})', '',
                     f'Prediction from {source}. Over the samples at least {after:.2g} s '
                     f'after a step, measured - predicted has a median of {bias:.3f} rpm '
                     f'(RMS {rms:.3f} rpm): an effect the model does not know shows up as '
                     'this bias. The spikes are '
                     'transients: the model is a steady-state map and predicts from the '
                     'commanded flow, while the plant has a pump lag, line compliance '
                     'and shaft inertia.', '',
                     f'![loss breakdown]({losses})', '']
    runs_table = ['## Runs', '', 'The virtual motor ran in lockstep: each publish period waited '
                  "for the controller's flow command, so the runs are repeatable message for "
                  'message (but for the wall times in `/diagnostics`). A period no command '
                  'answered in time is counted as unanswered; a run with one is not '
                  'repeatable.', '',
                  '| run | simulated [s] | wall [s] | real-time factor | messages | '
                  'unanswered periods | bag |', '| --- | ---: | ---: | ---: | ---: | ---: | --- |']
    for r in runs:
        count = sum(len(v) for v in r.messages.values())
        runs_table.append(f'| {r.liquid} / {r.feedforward} | {r.sim:.1f} | {r.wall:.1f} | '
                          f'{r.sim / r.wall:.1f} | {count} | {r.unanswered} | '
                          f'`{r.bag.relative_to(out)}` |')
    path = out / 'report.md'
    text = '\n'.join(lines + table + [''] + sections + runs_table + ['', *closing])
    path.write_text(text.rstrip('\n') + '\n', encoding='utf-8')
    return path


__all__ = ['RunResult', 'Tracking', 'hold', 'read_run', 'summary', 'write_report',
           'write_run_bag']
