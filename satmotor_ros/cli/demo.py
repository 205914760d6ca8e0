# SPDX-License-Identifier: Apache-2.0
"""
``satmotor demo``: virtual motor, controller and model over real ROS topics, recorded.

For each liquid, the scripted cycle of speed and load steps runs twice, with the
controller's model-based feed-forward and with the PI alone, in one process: the
nodes share a single-threaded executor, talk over DDS topics in a namespace of their
own and run on the virtual motor's ``/clock``, faster than real time. Every topic goes
into an MCAP rosbag2 per run; ``report.md`` gets the plots and the metrics table.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import sys
import time
from typing import Any

from satmotor_ros.cli._common import CliError, fail
from satmotor_ros.cli._output import add_out_dir, output_dir
from satmotor_ros.model.units import LPM, MPA, RPM
from satmotor_ros.plant.config import parameter_specs, params_from_flat
from satmotor_ros.plant.scenario import default_cycle, identification_cycle
from satmotor_ros.ros_runtime import MISSING_ROS, ros_problem

LIQUIDS = ('water', 'oil')
FEEDFORWARDS = ('model', 'none')
LOOP_EFFECT = 'external_leakage=2e-11'
"""The default effect of the closing-the-loop run: a leak to the case, k * p_case [m^3/(s*Pa)]."""

LOOP_SCALE = 1.5
"""The loop run's length per second of --duration: its nine points hold 1.5 * duration / 9 s."""

BENCH_SENSORS = {'sensors.flow.noise': 0.05 * LPM, 'sensors.speed.noise': 0.5 * RPM,
                 'sensors.inlet_pressure.noise': 0.01 * MPA,
                 'sensors.outlet_pressure.noise': 0.01 * MPA,
                 'sensors.case_pressure.noise': 0.005 * MPA}
"""The loop run's sensor noise (SI), as on a bench: the other runs have ideal sensors."""


DESCRIPTION = ('Runs the virtual motor, the motor_model node and the speed controller together '
               'over real ROS topics through a cycle of speed and load steps, with and without '
               'feed-forward, faster than real time; records every topic to an MCAP bag per run '
               'and writes report.md with plots.')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor demo``."""
    parser.add_argument('--liquid', choices=(*LIQUIDS, 'both'), default='both',
                        help='liquid(s) to run (default: both)')
    parser.add_argument('--duration', default='24', metavar='SECONDS',
                        help='length of the cycle per run in seconds of simulated time '
                             '(default 24; the steps scale with it)')
    parser.add_argument('--effect', action='append', default=[], metavar='NAME=VALUE',
                        help='inject a plant effect the model does not know (an effects.* '
                             'parameter of virtual_motor), SI value, e.g. '
                             'external_leakage=2e-12, viscosity_temperature=247.8 (Vogel B '
                             'of water [K]; Walther B of oil: 3.68), clearance_wear=1e-9, '
                             'flow_sensor_gain=0.03 (repeatable)')
    parser.add_argument('--loop-effect', action='append', default=None, metavar='NAME=VALUE',
                        help='the effect of the closing-the-loop run, which the model does '
                             f'not know and the calibration must find (default {LOOP_EFFECT}; '
                             'repeatable)')
    parser.add_argument('--no-loop', action='store_true',
                        help='skip the closing-the-loop run and its calibration')
    add_out_dir(parser, 'the demo', 'out/demo')
    parser.add_argument('--quiet', action='store_true', help='no progress bar')


def parse_effects(items: list[str]) -> dict[str, Any]:
    """
    Parse ``NAME=VALUE`` effect options into plant parameter values.

    Parameters
    ----------
    items : list of str
        As typed, [-]

    Returns
    -------
    dict
        ``effects.<name>`` -> value, validated by :func:`params_from_flat`.

    Raises
    ------
    CliError
        Naming the option and the value.

    """
    specs = {s.name.removeprefix('effects.'): s for s in parameter_specs()
             if s.name.startswith('effects.')}
    values: dict[str, Any] = {}
    for item in items:
        name, sep, text = item.partition('=')
        if not sep or name not in specs:
            msg = f'--effect {item!r}: use NAME=VALUE with NAME one of {", ".join(specs)}'
            raise CliError(msg)
        if specs[name].choices:
            values[name] = text
            continue
        try:
            values[name] = float(text)
        except ValueError:
            raise CliError(f'--effect {item!r}: {text!r} is not a number') from None
    try:
        params_from_flat({f'effects.{k}': v for k, v in values.items()})
    except ValueError as err:
        raise CliError(f'--effect: {err}') from None
    return {f'effects.{k}': v for k, v in values.items()}


def command(liquid: str, duration: str, effect: list[str], out: str, quiet: bool,
            force: bool = False, loop_effect: list[str] | None = None,
            no_loop: bool = False) -> int:
    """
    Run the demo.

    Parameters
    ----------
    liquid : str
        ``'water'``, ``'oil'`` or ``'both'``, [-]
    duration : str
        Cycle length as typed, [s]
    effect : list of str
        ``NAME=VALUE`` effects to inject, [-]
    out : str
        Output directory, [-]
    quiet : bool
        Suppress the progress bar, [-]
    force : bool
        Replace an existing ``--out`` that the demo did not write, [-]
    loop_effect : list of str, optional
        ``NAME=VALUE`` effects of the closing-the-loop run; :data:`LOOP_EFFECT` when None, [-]
    no_loop : bool
        Skip the closing-the-loop run, [-]

    Returns
    -------
    int
        0 on success, 1 on an error (one line on stderr).

    """
    try:
        try:
            seconds = float(duration)
        except ValueError:
            raise CliError(f'--duration {duration!r}: not a number of seconds') from None
        if not 2.0 <= seconds <= 3600.0:
            raise CliError(f'--duration {duration!r}: must be within 2..3600 s')
        effects = parse_effects(effect)
        loop = None if no_loop else {**BENCH_SENSORS, **effects,
                                     **parse_effects(loop_effect or [LOOP_EFFECT])}
        liquids = LIQUIDS if liquid == 'both' else (liquid,)
        cycle = default_cycle().scaled(seconds)
        os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
        problem = ros_problem()
        if problem is not None:
            raise CliError(f'demo {MISSING_ROS} (cannot import {problem})')
        from satmotor_ros.cli import _demo_report as report
        from satmotor_ros.cli._demo_ros import run_cycle
        runs: list[report.RunResult] = []
        loop_runs: list[report.RunResult] = []
        steps = (len(liquids) * len(FEEDFORWARDS) + LOOP_SCALE * (loop is not None)) * seconds
        progress = None if quiet else Progress(steps)
        with output_dir('--out', out, 'demo', (), force) as out_dir:
            for q in liquids:
                for ff in FEEDFORWARDS:
                    runs.append(run_cycle(q, ff, cycle, effects, out_dir / 'bags' / f'{q}_{ff}',
                                          progress))
            section: list[str] = []
            if loop is not None:
                from satmotor_ros.cli._demo_loop import close_loop
                bag = out_dir / 'bags' / f'{liquids[0]}_model_loop'
                loop_cycle = identification_cycle().scaled(LOOP_SCALE * seconds)
                loop_runs.append(run_cycle(liquids[0], 'model', loop_cycle, loop, bag,
                                           progress))
                section = close_loop(bag, liquids[0], loop, out_dir, loop_cycle)
                from satmotor_ros.cli._demo_health import health_section
                section += health_section(out_dir, liquids[0],
                                          [out_dir / 'bags' / f'{liquids[0]}_model', bag], loop)
            if progress is not None:
                progress.done()
            report.write_report(out_dir, runs, cycle, effects, section)
    except (CliError, OSError) as err:
        return fail(err)
    timed = runs + loop_runs
    late = [f'{r.liquid}/{r.feedforward}' for r in timed if r.unanswered]
    if late:
        print(f'satmotor demo: warning: the controller missed periods in {", ".join(late)} '
              '(a busy machine): those runs are not repeatable; see report.md',
              file=sys.stderr)
    path, bags = Path(out) / 'report.md', Path(out) / 'bags'
    wall = sum(r.wall for r in timed)
    sim = sum(r.sim for r in timed)
    loop_note = '' if no_loop else f' and the loop run, calibrated into {Path(out) / "loop"}'
    print(f'satmotor demo: {len(runs)} runs{loop_note}, {sim:.0f} s simulated in {wall:.1f} s '
          f'({sim / wall:.1f}x real time); report: {path}; bags: {bags}')
    return 0


class Progress:
    """
    A one-line progress bar on stderr.

    Parameters
    ----------
    total : float
        Simulated seconds of all runs, [s]

    """

    def __init__(self, total: float) -> None:
        """Start the clock."""
        self.total = total
        self.finished = 0.0
        self.start = time.monotonic()
        self._shown = 0.0

    def show(self, label: str, sim: float) -> None:
        """
        Redraw at most five times a second.

        Parameters
        ----------
        label : str
            Current run, [-]
        sim : float
            Simulated seconds of the current run, [s]

        """
        now = time.monotonic()
        if now - self._shown < 0.2:
            return
        self._shown = now
        done = min((self.finished + sim) / self.total, 1.0)
        bar = '#' * int(30 * done)
        speed = (self.finished + sim) / max(now - self.start, 1e-9)
        sys.stderr.write(f'\r[{bar:<30}] {done * 100:5.1f} % {label:<14} '
                         f'{speed:5.1f}x real time ')
        sys.stderr.flush()

    def run_done(self, sim: float) -> None:
        """
        Count a finished run.

        Parameters
        ----------
        sim : float
            Its simulated seconds, [s]

        """
        self.finished += sim

    def done(self) -> None:
        """End the line."""
        sys.stderr.write('\n')


__all__ = ['add_arguments', 'command', 'parse_effects']
