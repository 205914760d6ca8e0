# SPDX-License-Identifier: Apache-2.0
"""``satmotor monitor``: the motor's health over recordings, against a baseline model."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from satmotor_ros.cli._bench import load_data, run_bench_command
from satmotor_ros.cli._common import add_motor_options, CliError
from satmotor_ros.cli._liquid import settle_liquid
from satmotor_ros.cli._output import add_out_dir, check_target, output_dir, written_by
from satmotor_ros.identify.calibrated import Calibrated
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.health import Baseline, HealthMonitor, HealthSettings
from satmotor_ros.identify.health.report import write_monitor
from satmotor_ros.identify.health.run import monitor_recordings
from satmotor_ros.options import MotorOptions

DESCRIPTION = ("Track a motor's health over one or more recordings in time order (bench CSVs, "
               'rosbag2 bags, logs read with --columns) against a baseline (--motor: typically '
               'the coefficients.yaml `satmotor calibrate` wrote on the first half hour of the '
               'same machine): the leakage factor with its interval, its trend and the hours to '
               'a limit, change alarms at a stated false-alarm interval and what changed. '
               'Writes monitor.json, health.csv, report.md and plots into --out.')

SETTING_FLAGS = {'false_alarm_hours': '--false-alarm-hours',
                 'limit_leakage_factor': '--limit-leakage-factor',
                 'limit_volumetric_efficiency': '--limit-volumetric-efficiency',
                 'change_fraction': '--change-fraction', 'learn_hours': '--learn-hours'}
"""Each setting the command line sets, and its flag (named in an error)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor monitor``."""
    parser.add_argument('data', nargs='+', metavar='DATA',
                        help='bench CSVs, rosbag2 directories or logs, in time order')
    add_out_dir(parser)
    parser.add_argument('--columns', default='', metavar='MAPPING',
                        help='read logs through a column mapping (doc/columns.md)')
    group = parser.add_argument_group('health')
    group.add_argument('--false-alarm-hours', type=float, default=1000.0, metavar='H',
                       help='mean hours of operation between false change alarms (default '
                            '1000); the threshold follows from it and the noise the data show')
    group.add_argument('--limit-leakage-factor', type=float, default=2.0, metavar='K',
                       help='leakage factor at which the motor is worn out (default 2)')
    group.add_argument('--limit-volumetric-efficiency', type=float, default=None,
                       metavar='ETA', help='instead: the volumetric efficiency at the '
                                           'reference point at which it is worn out (0-1)')
    group.add_argument('--change-fraction', type=float, default=0.2, metavar='F',
                       help='change of the losses the detector is tuned to (default 0.2)')
    group.add_argument('--learn-hours', type=float, default=0.25, metavar='H',
                       help='operation that teaches the noise model and the level (default '
                            '0.25)')
    group.add_argument('--no-explain', dest='explain', action='store_false',
                       help="do not run the calibration's candidates on a change")
    group.add_argument('--state', default='', metavar='FILE',
                       help='resume from this state file if it exists, and save the state '
                            'there after the last sample (a later run continues the history)')
    group.add_argument('--acknowledge', action='store_true',
                       help="acknowledge the --state's alarms (those the last run reported): "
                            'they stay in the history, marked acknowledged; alarms the new '
                            'data raise are new')
    add_motor_options(parser, liquid_from_data=True)


def command(data: list[str], out: str, options: MotorOptions, columns: str = '',
            force: bool = False, false_alarm_hours: float = 1000.0,
            limit_leakage_factor: float = 2.0,
            limit_volumetric_efficiency: float | None = None, change_fraction: float = 0.2,
            learn_hours: float = 0.25, explain: bool = True, state: str = '',
            acknowledge: bool = False) -> int:
    """
    Run the health monitor over the recordings and write its outputs.

    Parameters
    ----------
    data : list of str
        The recordings, in time order, [-]
    out, columns : str
        ``--out`` and ``--columns``, [-]
    options : MotorOptions
        The baseline model (``--motor``, ``--liquid``, ``--family``, ...), [-]
    force : bool
        Replace an ``--out`` this command did not write, [-]
    false_alarm_hours, limit_leakage_factor, limit_volumetric_efficiency : float
        As :class:`HealthSettings`, [h], [-], [-]
    change_fraction, learn_hours : float
        As :class:`HealthSettings`, [-], [h]
    explain : bool
        Name what changed on a change, [-]
    state : str
        State file to resume from and save to; '' for none, [-]
    acknowledge : bool
        Acknowledge the alarms of the resumed `state` before the data, [-]

    Returns
    -------
    int
        0 with the figures on stdout; 1 with one line on stderr for unusable data or options.

    """
    values = {'false_alarm_hours': false_alarm_hours,
              'limit_leakage_factor': limit_leakage_factor,
              'limit_volumetric_efficiency': limit_volumetric_efficiency,
              'change_fraction': change_fraction, 'learn_hours': learn_hours}
    return run_bench_command(out, lambda: _monitor(data, out, options, columns, force, values,
                                                   explain, state, acknowledge))


def _settings(values: dict[str, float | None], explain: bool) -> HealthSettings:
    """Build the settings; a meaningless value is named by its flag."""
    try:
        return HealthSettings(**values, explain=explain)  # type: ignore[arg-type]
    except DataError as err:
        text = str(err)
        field = text.split(' ', 1)[0]
        raise CliError(SETTING_FLAGS.get(field, field) + text[len(field):]) from None


def _same_settings(saved: HealthSettings, given: HealthSettings, state: str) -> None:
    """Refuse settings that differ from those a resumed state was judged with."""
    for field, (was, now) in saved.differences(given, SETTING_FLAGS).items():
        raise CliError(f'{SETTING_FLAGS[field]} {now!r}: the state {state} was made with '
                       f'{was!r}; give the same, or start a new --state')


def _monitor(data: list[str], out: str, options: MotorOptions, columns: str, force: bool,
             values: dict[str, float | None], explain: bool, state: str,
             acknowledge: bool) -> str:
    settings = _settings(values, explain)
    if acknowledge and not (state and Path(state).is_file()):
        raise CliError(f'--acknowledge: no alarms to acknowledge without a --state file '
                       f'({state or "none given"}): the alarms are those of a previous run')
    inputs = [name for name in (*data, options.motor_file, columns) if name]
    check_target('--out', Path(out), inputs, force, written_by('monitor'), 'monitor')
    if state and not Path(state).parent.is_dir():  # found out only after --out was written
        raise CliError(f'--state {state!r}: {Path(state).parent} is not a directory')
    settled = settle_liquid(options, data[0], 'monitor')
    options = settled.options
    model = options.build_model()
    motor_file = options.motor_file
    baseline = Baseline(model, Calibrated(motor_file).envelope if motor_file else None,
                        motor_file or model.name)
    # a resumed monitor keeps the settings it was started with: its history was judged so
    monitor = (HealthMonitor.resume(state, baseline) if state and Path(state).exists()
               else HealthMonitor(baseline, settings))
    _same_settings(monitor.settings, settings, state)
    if acknowledge:
        monitor.acknowledge()
    tables = [load_data(path, columns, model.geometry.displacement) for path in data]
    run = monitor_recordings(tables, baseline, monitor=monitor)
    snap = run.snapshot
    if snap.n_skipped >= snap.n_samples:
        msg = (f'DATA: none of the {snap.n_samples} samples is usable (' + ', '.join(
            f'{v} {k.replace("_", " ")}' for k, v in snap.skipped.items() if v)
            + '): check --motor, --displacement and the units')
        raise DataError(msg)
    with output_dir('--out', out, 'monitor', inputs, force) as tmp:
        content = write_monitor(run, tmp)
    if state:
        monitor.save(state)
    alarms = ', '.join(f'{a.kind} at {a.time_s / 3600:.3g} h ({a.what})'
                       + (' acknowledged' if n < snap.acknowledged else '')
                       for n, a in enumerate(snap.alarms))
    flags = ''.join(f'; WARNING: {flag}' for flag in content['flags'])
    notes = ''.join(f'; {note}' for note in run.notes)
    if snap.learning and not snap.alarms:
        figures = (f'still learning the noise model and the level ({snap.operating_hours:.2g} '
                   f'of {settings.learn_hours:g} h of operation): no figure yet')
    else:
        figures = (f'leakage factor {snap.leakage_factor.value:.4g} '
                   f'[{snap.leakage_factor.low:.4g}, {snap.leakage_factor.high:.4g}], trend '
                   f'{snap.trend_per_hour.value:+.3g}/h, hours to limit '
                   + _hours_text(snap.hours_to_limit.value))
    return ((f'WARNING: {settled.warning}; ' if settled.warning else '')
            + f'{figures}; alarms: {alarms or "none"}{flags}{notes}; '
            f'{snap.n_samples} samples, {snap.n_skipped} skipped; wrote {out}/monitor.json, '
            'health.csv, report.md, leakage_factor.png, detector.png')


def _hours_text(hours: float) -> str:
    if math.isfinite(hours):
        return f'{hours:.3g}'
    if math.isinf(hours):
        return 'never (the trend does not rise significantly towards the limit)'
    return 'none yet (not enough operation for a trend)'


__all__ = ['add_arguments', 'command', 'DESCRIPTION']
