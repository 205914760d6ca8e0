# SPDX-License-Identifier: Apache-2.0
"""
``satmotor replay``: the motor_model node's predictions over a recorded bag, fast.

The bag's input topics are combined in log-time order by the node's own rule
(:mod:`satmotor_ros.prediction`) and predicted in one vectorised model call; the result is
written as CSV (hydraulic units in the header) and, with ``--out-bag``, as a new bag that
holds the recorded and the predicted topics side by side.
"""

from __future__ import annotations

import argparse
from contextlib import ExitStack
from pathlib import Path
import time

import numpy as np

from satmotor_ros.bags import (BagError, describe_topics, encode_many, list_topics,
                               missing_topics, OutTopic, parse_topic_map, read_series, Series,
                               write_bag)
from satmotor_ros.bags.custom import LIQUID_KEY, MOTOR_KEY
from satmotor_ros.cli import _fastcsv as fastcsv
from satmotor_ros.cli._common import add_motor_options, CliError, fail
from satmotor_ros.cli._liquid import settle_liquid
from satmotor_ros.cli._output import (check_target, output_file, png_by, png_metadata,
                                      resolve, write_marker, written_by)
from satmotor_ros.interface import (CHANNELS, FLOAT64, JOINT_NAME, JOINT_STATE, LOSS_COMPONENTS,
                                    LOSSES_PREFIX, PREDICTED_JOINT_STATE, SPEED_RESIDUAL)
from satmotor_ros.model import describe_status, ModelError, MotorModel
from satmotor_ros.model.units import LPM, MPA, RPM
from satmotor_ros.options import MotorOptions
from satmotor_ros.prediction import (combine_batch, driving_times, INPUTS, InputState, Level,
                                     MODES, predict, PredictionBatch, Progress, REQUIRED, Rule,
                                     TOPICS)
from satmotor_ros.prediction.rule import input_level

# (name, CSV header, unit in SI, decimal places written)
_INPUT_COLUMNS = (('flow', 'flow [l/min]', LPM, 12), ('p_in', 'p_in [MPa]', MPA, 9),
                  ('p_out', 'p_out [MPa]', MPA, 9), ('p_case', 'p_case [MPa]', MPA, 9),
                  ('temperature', 'temperature [degC]', 1.0, 6),
                  ('measured_speed', 'measured_speed [rpm]', RPM, 9))
_OUTPUT_COLUMNS = (('dp', 'dp [MPa]', MPA, 9), ('dp_i', 'dp_i [MPa]', MPA, 9),
                   ('speed', 'speed [rpm]', RPM, 9), ('speed', 'speed [rad/s]', 1.0, 12),
                   *((c, f'{c} [l/min]', LPM, 15) for c in LOSS_COMPONENTS),
                   ('residual', 'residual [rpm]', RPM, 9))


COMMAND = 'replay'
_CSV_START = b'log_time [ns],time [s]'
CSV_CHUNK_ROWS = 65536
"""Rows formatted at once; the text of a CSV row takes about 1.5 KB while it is built, [-]."""

DESCRIPTION = ("Replay a rosbag2 bag (sqlite3 or MCAP) through the motor_model node's "
               'prediction, as fast as it can: the inputs are combined in log-time order by the '
               "node's rule. With a measured speed (joint_states) it prints residual statistics "
               'and plots predicted against measured speed.')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor replay``."""
    parser.add_argument('bag', help='bag directory, or a single .db3/.mcap file')
    parser.add_argument('--out', default=None, metavar='FILE.csv',
                        help='write one row per driving message (units in the header)')
    parser.add_argument('--out-bag', default=None, metavar='DIR',
                        help='write a new MCAP bag with the recorded and predicted topics')
    parser.add_argument('--plot', default=None, metavar='FILE.png',
                        help='plot of predicted and measured speed (default: beside --out, '
                             'else <bag>_speed.png here; only with a measured speed)')
    parser.add_argument('--no-plot', action='store_true', help='do not plot')
    parser.add_argument('--force', action='store_true',
                        help='replace existing outputs that replay did not write')
    parser.add_argument('--topic-map', action='append', default=[], metavar='OLD:=NEW',
                        help='match bag topic OLD as NEW (repeatable), e.g. '
                             '/rig/p1:=inlet_pressure')
    parser.add_argument('--timeout', type=float, default=0.5, metavar='S',
                        help='input timeout of the rule, as the node parameter '
                             'input_timeout (default 0.5 s)')
    parser.add_argument('--mode', choices=MODES, default='on_flow',
                        help='predict on every flow_command (default) or at --rate')
    parser.add_argument('--rate', type=float, default=50.0, metavar='HZ',
                        help='prediction rate with --mode rate (default 50 Hz)')
    parser.add_argument('--joint', default=JOINT_NAME, metavar='NAME',
                        help='joint of the measured speed in joint_states (default '
                             f'{JOINT_NAME})')
    add_motor_options(parser, liquid_from_data=True)


def command(bag: str, out: str | None, out_bag: str | None, plot: str | None, no_plot: bool,
            topic_map: list[str], timeout: float, mode: str, rate: float, joint: str,
            options: MotorOptions, force: bool = False) -> int:
    """
    Replay a bag through the prediction and report.

    Parameters
    ----------
    bag : str
        Bag directory or storage file, [-]
    out : str or None
        CSV file to write, [-]
    out_bag : str or None
        Bag directory to write (MCAP), [-]
    plot : str or None
        PNG file for predicted against measured speed, [-]
    no_plot : bool
        Skip the plot, [-]
    topic_map : list of str
        ``OLD:=NEW`` renames, [-]
    timeout : float
        Input timeout of the rule, [s]
    mode : str
        ``'on_flow'`` or ``'rate'``, [-]
    rate : float
        Prediction rate in ``'rate'`` mode, [Hz]
    joint : str
        Joint of the measured speed, [-]
    options : MotorOptions
        Motor, liquid and Delta q law, as the node's parameters, [-]
    force : bool
        Replace existing outputs that replay did not write (never the bag), [-]

    Returns
    -------
    int
        0 when predictions were made, 1 on an error (one line on stderr).

    """
    started = time.perf_counter()
    try:
        rule = Rule(timeout=timeout, mode=mode, rate=rate)
    except ValueError as err:
        return fail(CliError(f'--{str(err).split(" ", 1)[0]} {err}'))
    inputs = [bag, options.motor_file] if options.motor_file else [bag]
    targets = {'--out': (out, _csv_by_replay), '--out-bag': (out_bag, written_by(COMMAND)),
               '--plot': (plot if not no_plot else None, png_by(COMMAND))}
    try:
        if plot is not None and not no_plot and Path(plot).suffix.lower() != '.png':
            raise CliError(f'--plot {plot!r}: a plot is written as PNG; name it *.png')
        for option, (target, ours) in targets.items():
            if target is not None:
                check_target(option, Path(target), inputs, force, ours, COMMAND)
        figure = _plot_path(bag, out, plot, no_plot)
        written = {'--out-bag': out_bag, '--out': out, '--plot': figure}
        _refuse_clashes({option: Path(p) for option, p in written.items() if p is not None})
        renames = parse_topic_map(topic_map)
        series = read_series(bag, [TOPICS[name] for name in INPUTS], renames, joint,
                             keep_raw=out_bag is not None)
        _require(bag, series, renames)
        settled = settle_liquid(options, bag, COMMAND)
        options = settled.options
        model = options.build_model()
        batch = _predict(model, rule, series)
        if not batch.valid.any():
            raise CliError(f'{bag}: none of {len(batch)} predictions could be made; the '
                           f'first: {batch.message(0)}')
        measured = series.get(TOPICS['measured_speed'])
        picture = figure if measured is not None and len(measured) else None
        with ExitStack() as outputs:  # every output renamed into place only once all are made
            if out_bag is not None:
                tmp = outputs.enter_context(output_file('--out-bag', out_bag, COMMAND,
                                                        written_by(COMMAND), inputs, force))
                _write_bag(tmp, series, batch, joint, Path(out_bag).name,
                           {LIQUID_KEY: options.liquid, MOTOR_KEY: model.name})
                write_marker(tmp, COMMAND)
            if out is not None:
                tmp = outputs.enter_context(output_file('--out', out, COMMAND, _csv_by_replay,
                                                        inputs, force))
                write_csv(tmp, batch)
            if picture is not None:
                tmp = outputs.enter_context(output_file('--plot', picture, COMMAND,
                                                        png_by(COMMAND), inputs, force))
                plot_speed(tmp, batch, f'{Path(bag).name}: {model.liquid.name}, '
                                       f'{model.displacement_law}'
                                       + (' (WARNING: not the recorded liquid)'
                                          if settled.warning else ''))
    except (BagError, CliError, ModelError) as err:
        return fail(err)
    except OSError as err:
        return fail(CliError(f'{err.filename}: {err.strerror}'))
    print(summary(bag, batch, time.perf_counter() - started))
    print(f'  liquid {settled.source}'
          + (f'; WARNING: {settled.warning}' if settled.warning else ''))
    for path in (out, out_bag, picture):
        if path is not None:
            print(f'wrote {path}')
    return 0


def _refuse_clashes(targets: dict[str, Path]) -> None:
    """Refuse two outputs on one path, or one inside another (an output directory)."""
    resolved = {option: resolve(option, path) for option, path in targets.items()}
    for first, (option, path) in enumerate(resolved.items()):
        for other, there in list(resolved.items())[first + 1:]:
            if path == there or path.is_relative_to(there) or there.is_relative_to(path):
                raise CliError(f'{option} {str(targets[option])!r} and {other} '
                               f'{str(targets[other])!r} are one path or one holds the other; '
                               'choose different paths')


def _require(bag: str, series: dict[str, Series], renames: dict[str, str]) -> None:
    missing = missing_topics(series, [TOPICS[name] for name in REQUIRED])
    if missing:
        have = describe_topics(list_topics(bag))
        hint = '' if renames else '; rename with --topic-map OLD:=NEW'
        raise CliError(f'{bag}: no messages on {", ".join(missing)} (the bag has: {have})'
                       f'{hint}')


def inputs_of(series: dict[str, Series]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """
    Take the rule's inputs from the series that :func:`read_series` returned.

    Parameters
    ----------
    series : dict
        Topic name -> Series, [-]

    Returns
    -------
    dict
        Input name -> (log times [ns], values [SI]).

    """
    inputs = {}
    for name in INPUTS:
        found = series.get(TOPICS[name])
        if found is not None and len(found):
            inputs[name] = (found.t_ns, found.fields[CHANNELS[name].field])
    return inputs


def _predict(model: MotorModel, rule: Rule, series: dict[str, Series]) -> PredictionBatch:
    inputs = inputs_of(series)
    first = min(int(t[0]) for t, _ in inputs.values())
    last = max(int(t[-1]) for t, _ in inputs.values())
    try:
        stamps = driving_times(rule, inputs['flow'][0], first, last)
    except ValueError as err:
        raise CliError(f'--mode rate: {err}') from None
    snaps = combine_batch(rule, stamps, inputs)
    return predict(model, snaps, rule.timeout, Progress().advance(snaps))


def summary(bag: str, batch: PredictionBatch, seconds: float) -> str:
    """
    Describe a replay in a few lines: counts, the first problem, residual statistics.

    Parameters
    ----------
    bag : str
        The bag, [-]
    batch : PredictionBatch
        The predictions, [-]
    seconds : float
        Wall time of the replay, [s]

    Returns
    -------
    str
        The text.

    """
    n = len(batch)
    valid = batch.valid
    warn = int((batch.level == Level.WARN).sum())
    lines = [f'{bag}: {n} driving messages, {int(valid.sum())} predictions ({warn} with a '
             f'warning), {n - int(valid.sum())} rejected, in {seconds:.2f} s']
    t0 = int(batch.snapshots.stamp_ns[0]) if n else 0
    for level in (Level.ERROR, Level.WARN):
        hits = np.flatnonzero(batch.level == level)
        if len(hits):
            i = int(hits[0])
            lines.append(f'  first {level.name} at {(batch.snapshots.stamp_ns[i] - t0) / 1e9:.3f} '
                         f's: {batch.message(i)}')
    stats = residual_stats(batch)
    if stats is None:
        lines.append('  no measured speed (joint_states): no residual')
    else:
        lines.append(f'  residual measured - predicted speed over {stats["n"]} points: mean '
                     f'{stats["mean"]:.3g} rpm, std {stats["std"]:.3g} rpm, RMS '
                     f'{stats["rms"]:.3g} rpm, max |r| {stats["max_abs"]:.3g} rpm '
                     f'({stats["rms_pct"]:.3g} % RMS of the mean measured speed)')
    return '\n'.join(lines)


def residual_stats(batch: PredictionBatch) -> dict[str, float] | None:
    """
    Summarise the residual of measured against predicted speed.

    Parameters
    ----------
    batch : PredictionBatch
        The predictions, [-]

    Returns
    -------
    dict or None
        ``n``, ``mean``, ``std``, ``rms``, ``max_abs`` [rpm] and ``rms_pct`` [%];
        None when no prediction had a measured speed.

    """
    residual = batch.output('residual')
    ok = np.isfinite(residual)
    if not ok.any():
        return None
    r = residual[ok] / RPM
    measured = batch.snapshots.values[INPUTS.index('measured_speed')][ok] / RPM
    rms = float(np.sqrt(np.mean(r * r)))
    scale = float(np.mean(np.abs(measured)))
    return {'n': int(ok.sum()), 'mean': float(r.mean()), 'std': float(r.std()), 'rms': rms,
            'max_abs': float(np.abs(r).max()),
            'rms_pct': 100.0 * rms / scale if scale > 0 else float('nan')}


def _state_notes(batch: PredictionBatch) -> list[str]:
    """Name, per prediction, the inputs that are not usable (e.g. 'p_out:NEGATIVE')."""
    states = batch.snapshots.states.astype(np.int64)
    key = np.zeros(states.shape[1], dtype=np.int64)
    for row in states:  # one small integer per combination of input states
        key = key * 8 + row
    codes, inverse = np.unique(key, return_inverse=True)
    texts = []
    for code in codes.tolist():
        column = [(code >> (3 * (len(INPUTS) - 1 - i))) & 7 for i in range(len(INPUTS))]
        texts.append(';'.join(f'{TOPICS[name]}:{InputState(s).name}'
                              for name, s in zip(INPUTS, column) if input_level(name, s)))
    return [texts[i] for i in inverse.reshape(-1).tolist()]


def _status_names(batch: PredictionBatch) -> list[str]:
    codes, inverse = np.unique(batch.status, return_inverse=True)
    names = [describe_status(int(c)) for c in codes]
    return [names[i] for i in inverse.reshape(-1).tolist()]


def _csv_by_replay(path: Path) -> bool:
    """Whether `path` is a CSV that replay wrote (its header)."""
    try:
        with path.open('rb') as file:
            return file.read(len(_CSV_START)) == _CSV_START
    except OSError:
        return False


def write_csv(path: Path, batch: PredictionBatch) -> None:
    """
    Write one row per driving message, hydraulic units in the header.

    Columns: ``log_time [ns]``, ``time [s]`` (from the first), the inputs (optional ones
    only when the bag has them), the outputs (``residual`` only with a measured speed),
    ``level`` (OK, WARN, ERROR: ERROR rows are what the node would not publish, their
    outputs empty), ``model_status`` and ``inputs`` (the unusable ones and why). Numbers
    are fixed-point with 9 to 15 decimal places (at least 12 significant digits at the
    model's scales).

    Parameters
    ----------
    path : pathlib.Path
        The file, [-]
    batch : PredictionBatch
        The predictions, [-]

    """
    snaps = batch.snapshots
    t_ns = snaps.stamp_ns
    t0 = int(t_ns[0]) if len(t_ns) else 0
    header = _CSV_START.decode('ascii').split(',')
    numbers = [(t_ns, 0), ((t_ns - t0) / 1e9, 9)]  # each column in SI and its decimals
    for name, title, unit, decimals in _INPUT_COLUMNS:
        values = snaps.values[INPUTS.index(name)]
        if name in REQUIRED or not np.isnan(values).all():  # absent optional inputs: no column
            numbers.append((values / unit, decimals))
            header.append(title)
    for name, title, unit, decimals in _OUTPUT_COLUMNS:
        values = batch.output(name)
        if name != 'residual' or not np.isnan(values).all():
            numbers.append((values / unit, decimals))
            header.append(title)
    numbers = [(v, d if np.issubdtype(v.dtype, np.integer) else fastcsv.shown_decimals(v, d))
               for v, d in numbers]
    levels = [Level(k).name for k in range(3)]
    texts = [[levels[k] for k in batch.level.tolist()], _status_names(batch),
             _state_notes(batch)]
    header += ['level', 'model_status', 'inputs']
    with path.open('wb') as stream:
        stream.write((','.join(header) + '\n').encode('ascii'))
        for start in range(0, len(t_ns), CSV_CHUNK_ROWS):  # bounded memory: rows in pieces
            part = slice(start, start + CSV_CHUNK_ROWS)
            stream.write(fastcsv.rows([fastcsv.fixed_point(v[part], d) for v, d in numbers]
                                      + [fastcsv.text(t[part]) for t in texts]))


def _write_bag(path: Path, series: dict[str, Series], batch: PredictionBatch,
               joint: str, name: str, custom: dict[str, str]) -> None:
    """
    Write the recorded inputs and the predictions (what the node publishes) to a bag.

    `path` is the hidden temporary directory renamed to the bag once every output is made;
    its storage file is named after the bag's final name `name` (``NAME.mcap``), so that
    ls, globs and clean-up scripts see an ordinary file. The bag records `custom`
    (:mod:`satmotor_ros.bags.custom`: the liquid and motor of the prediction).
    """
    flow_topic = series[TOPICS['flow']].topic
    flow = CHANNELS['flow'].topic
    prefix = flow_topic[:-len(flow)] if flow_topic.endswith(flow) else '/'
    prefix = prefix if prefix.startswith('/') else '/' + prefix
    topics = [OutTopic(s.topic if s.topic.startswith('/') else '/' + s.topic, s.msgtype,
                       s.t_ns, s.raw) for s in series.values() if len(s) and s.raw is not None]
    valid = batch.valid
    t_ns = batch.snapshots.stamp_ns[valid]
    topics.append(OutTopic(prefix + PREDICTED_JOINT_STATE, JOINT_STATE, t_ns, encode_many(
        JOINT_STATE, {'velocity': batch.output('speed')[valid]}, t_ns, joint=joint)))
    for c in LOSS_COMPONENTS:
        topics.append(OutTopic(prefix + LOSSES_PREFIX + c, FLOAT64, t_ns,
                               encode_many(FLOAT64, {'data': batch.output(c)[valid]})))
    residual = batch.output('residual')
    has = valid & np.isfinite(residual)
    if has.any():
        topics.append(OutTopic(prefix + SPEED_RESIDUAL, FLOAT64,
                               batch.snapshots.stamp_ns[has],
                               encode_many(FLOAT64, {'data': residual[has]})))
    write_bag(path, topics, name=name, custom_data=custom)


def _plot_path(bag: str, out: str | None, plot: str | None, no_plot: bool) -> Path | None:
    """Where the plot goes when the bag has a measured speed."""
    if no_plot:
        return None
    if plot is not None:
        return Path(plot)
    if out is not None:
        return Path(out).with_name(Path(out).stem + '_speed.png')
    return Path(f'{resolve("BAG", Path(bag)).name}_speed.png')


def plot_speed(path: Path, batch: PredictionBatch, label: str, max_points: int = 20000) -> None:
    """
    Plot predicted and measured speed over time, and their residual.

    Parameters
    ----------
    path : pathlib.Path
        The PNG to write, [-]
    batch : PredictionBatch
        The predictions, [-]
    label : str
        Title line, [-]
    max_points : int
        Most points drawn per curve (evenly thinned), [-]

    """
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot

    t_ns = batch.snapshots.stamp_ns
    step = max(1, len(t_ns) // max_points)
    t = (t_ns[::step] - t_ns[0]) / 1e9
    predicted = batch.output('speed')[::step] / RPM
    measured = batch.snapshots.values[INPUTS.index('measured_speed')][::step] / RPM
    residual = batch.output('residual')[::step] / RPM
    fig, (top, bottom) = pyplot.subplots(2, 1, figsize=(8.0, 5.6), dpi=110, sharex=True,
                                         gridspec_kw={'height_ratios': [2, 1]})
    top.plot(t, measured, '-', lw=0.8, color='0.35', label='measured (joint_states)')
    top.plot(t, predicted, '-', lw=0.8, color='tab:blue', label='predicted (motor model)')
    top.set_ylabel('shaft speed [rpm]')
    top.legend(fontsize=8)
    top.grid(True, alpha=0.3)
    top.set_title(f'Predicted against measured speed\n{label}', fontsize=10)
    bottom.plot(t, residual, '-', lw=0.8, color='tab:red')
    bottom.axhline(0.0, color='0.5', lw=0.6)
    bottom.set_ylabel('measured - predicted [rpm]')
    bottom.set_xlabel('time from the first driving message [s]')
    bottom.grid(True, alpha=0.3)
    stale = ~batch.valid[::step]
    if stale.any():
        top.plot(t[stale], np.zeros(int(stale.sum())), '|', color='tab:orange',
                 label='no prediction (ERROR)')
        top.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, format='png', metadata=png_metadata(COMMAND))
    pyplot.close(fig)
