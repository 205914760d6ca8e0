# SPDX-License-Identifier: Apache-2.0
"""
What a worker does for one recording, and for a motor's baseline.

Each task reads its own recording by path (the client sends a few names and flags), writes
into ``DIR/<motor>/<recording>/`` through the functions ``satmotor calibrate`` and
``satmotor validate`` use, so the outputs are theirs, and returns a small dict. A recording
that cannot be used is refused whole with one line and never raises: the other tasks go on.
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import os
from pathlib import Path
import socket
import time
from typing import Any

from satmotor_ros.fleet.config import MotorRule
from satmotor_ros.fleet.discover import Motor, Recording
from satmotor_ros.fleet.resume import (content_of, is_done, options_key, read_done, stat_of,
                                       write_done)
from satmotor_ros.options import MotorOptions, OptionError

BASELINE = 'baseline.json'
"""Names a motor's baseline in ``DIR/<motor>/`` (which recording, its calibration)."""

CALIBRATE_DIR, VALIDATE_DIR = 'calibrate', 'validate'
"""Where ``--calibrate`` and ``--validate`` write under ``DIR/<motor>/<recording>/``."""

ZERO_PRESSURE = 'every pressure is zero'

EMPTY = 'empty file (0 bytes): no header, no data'

OUTPUTS = {CALIBRATE_DIR: 'calibrate', VALIDATE_DIR: 'validate', 'health': 'fleet-health'}
"""A recording's output directories, each with the command its marker names."""

STEP, STATE, MONITOR_DIR = '.fleet-monitor.json', '.monitor-state.json', 'monitor'
"""The motor's monitor chain's files in a recording's directory (:mod:`~satmotor_ros.fleet.chain`):
its step's marker, the monitor's state after it and ``satmotor monitor``'s output."""


@dataclass(frozen=True)
class RunOptions:
    """What every task of a run is asked (part of each done-marker's options)."""

    out: str  # DIR, absolute
    calibrate: bool = False  # also write calibrate's outputs per recording
    validate: bool = False  # also write validate's outputs against the baseline
    liquid: str = ''  # default liquid for motors fleet.yaml gives none
    alpha: float = 0.05  # calibrate's significance level [-]
    folds: int = 5  # calibrate's cross-validation folds [-]


class Refused(Exception):
    """A recording refused whole: the message is its one-line reason."""


class MotorRefused(Refused):
    """A sound recording refused for a reason of its motor's (the same for each of them)."""


NO_LIQUID = 'the recordings record no liquid: give liquid in fleet.yaml or --liquid'


def motor_options(rule: MotorRule, run: RunOptions, motor_file: str = '') -> MotorOptions:
    """
    Build the options of a motor: its fleet.yaml entry, or a baseline file over it.

    Parameters
    ----------
    rule : MotorRule
        The motor's entry, [-]
    run : RunOptions
        The run's options (the default liquid), [-]
    motor_file : str
        The baseline's coefficients; '' for the entry's own motor file, [-]

    Returns
    -------
    MotorOptions
        The options; the liquid '' when neither says (the data must then record it).

    """
    if motor_file:
        return MotorOptions(liquid=rule.liquid or run.liquid, motor_file=motor_file)
    return MotorOptions(liquid=rule.liquid or run.liquid, motor_file=rule.motor_file,
                        family=rule.family, displacement=rule.displacement)


def columns_of(rule: MotorRule, run: RunOptions) -> str:
    """Return the ``--columns`` of a motor: its entry's, an inline one written to DIR."""
    if rule.columns_inline is None:
        return rule.columns
    path = Path(run.out) / rule.motor / 'columns.yaml'
    text = json.dumps(rule.columns_inline, sort_keys=True)  # JSON is YAML
    if not path.is_file() or path.read_text(encoding='utf-8') != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = path.with_name(f'.columns.yaml.partial-{os.getpid()}')
        temporary.write_text(text, encoding='utf-8')
        os.replace(temporary, path)
    return str(path)


def load_screened(rec: Recording, options: MotorOptions, columns: str) -> tuple[Any, Any]:
    """
    Load a recording as ``satmotor calibrate`` does, and refuse it whole if it is damaged.

    The reader and its row-level handling are calibrate's (:func:`~satmotor_ros.cli._bench.
    load_data`): rows with an impossible value or absurd cells are dropped and said
    (:func:`warnings_of`), not a reason to refuse. Damaged is what no row-level rule reads:
    unreadable or not UTF-8 (garbage), a row with the wrong number of cells, a text file
    cut mid-row, every pressure zero.

    Parameters
    ----------
    rec : Recording
        The recording, [-]
    options : MotorOptions
        The motor (its displacement names impossible losses), [-]
    columns : str
        Its column mapping, '' for a CSV or a bag, [-]

    Returns
    -------
    tuple of (BenchTable, MotorOptions)
        The data and the options with the liquid settled.

    Raises
    ------
    Refused
        One line: unreadable, truncated, garbage, every pressure zero, empty;
        :class:`MotorRefused` (:data:`NO_LIQUID`) for sound data when neither fleet.yaml,
        --liquid nor the data name the liquid.

    """
    from satmotor_ros.bags.errors import BagError
    from satmotor_ros.cli._bench import load_data
    from satmotor_ros.cli._common import CliError
    from satmotor_ros.cli._liquid import settle_liquid
    from satmotor_ros.identify import IdentificationError
    from satmotor_ros.model import ModelError
    import numpy as np
    unsettled = False
    try:
        settled = settle_liquid(options, rec.path, 'fleet').options
    except CliError:  # the motor's; the data are screened first, for their own reason
        if options.liquid:
            raise
        settled, unsettled = options, True
    except BagError as err:  # its metadata unreadable: a damaged bag, refused whole
        raise Refused(_first_line(err)) from None
    try:
        table = load_data(rec.path, columns, _displacement(settled))
    except (BagError, CliError, IdentificationError, ModelError, OptionError) as err:
        if rec.kind != 'bag' and _size(rec.path) == 0:
            raise Refused(EMPTY) from None
        cut = rec.kind != 'bag' and not _ends_a_line(rec.path) and 'UTF-8' not in str(err)
        raise Refused(('truncated mid-row (no end of line at the end): ' if cut else '')
                      + str(err)) from None
    except OSError as err:
        raise Refused(f'{err.strerror or err}') from None
    if rec.kind != 'bag' and not _ends_a_line(rec.path):
        raise Refused('ends without an end of line: truncated mid-row')
    if not np.any(table.p_in) and not np.any(table.p_out):
        raise Refused(ZERO_PRESSURE)
    if unsettled:
        raise MotorRefused(NO_LIQUID)
    return table, settled


def warnings_of(table: Any) -> list[str]:
    """Return what a table's reader dropped or found suspicious: calibrate's warnings."""
    from satmotor_ros.identify.table import BAD_CELLS, IMPOSSIBLE
    from satmotor_ros.identify.textfile import SANITY
    return [note for note in table.notes if note.startswith((IMPOSSIBLE, BAD_CELLS, SANITY))]


def _first_line(err: Exception) -> str:
    """Return an error's first line (its type's name if it says nothing)."""
    text = str(err).strip().splitlines()
    return text[0] if text else type(err).__name__


def _displacement(options: MotorOptions) -> float:
    """Return the motor's displacement, whatever liquid (none yet) the options name."""
    from dataclasses import replace
    from satmotor_ros.fleet.config import LIQUIDS
    for liquid in (options.liquid, *LIQUIDS[:-1]):
        try:
            return float(replace(options, liquid=liquid).spec().geometry.displacement)
        except OptionError as err:
            if err.option != 'liquid':
                raise
    return float(replace(options, liquid=LIQUIDS[-1]).spec().geometry.displacement)


def _size(path: str) -> int:
    """Return a file's size in bytes, -1 when it cannot be read."""
    try:
        return os.path.getsize(path)
    except OSError:
        return -1


def _ends_a_line(path: str) -> bool:
    """Whether a text file's last byte ends a line (a file cut mid-row does not)."""
    try:
        with open(path, 'rb') as file:
            file.seek(-1, os.SEEK_END)
            return file.read(1) in (b'\n', b'\r')
    except OSError:  # empty, or gone
        return False


def input_of(rec: Recording) -> dict[str, Any]:
    """Return the fingerprint of a recording: its files' stat and its content hash."""
    return {'stat': stat_of(rec.path), 'content': content_of(rec.path)}


def calibrate_baseline(motor: Motor, run: RunOptions) -> dict[str, Any]:
    """
    Calibrate a motor's first usable recording: its baseline.

    The calibration is ``DIR/<motor>/<recording>/calibrate`` (what ``satmotor calibrate``
    writes); :data:`BASELINE` names it and the recordings refused before it.

    Parameters
    ----------
    motor : Motor
        The motor and its recordings in time order, [-]
    run : RunOptions
        The run's options, [-]

    Returns
    -------
    dict
        :data:`BASELINE`'s content: ``recording``, ``coefficients``, ``liquid``, ``key``
        (what a recording's health depends on) and ``refused_before``; ``recording``
        None and ``reason`` when no recording calibrates (written too, so a rerun on the
        same recordings and options finds it).

    """
    from satmotor_ros.cli.calibrate import calibrate_into
    from satmotor_ros.cli._common import CliError
    from satmotor_ros.identify import IdentificationError
    from satmotor_ros.model import ModelError
    columns = columns_of(motor.rule, run)
    refused: list[dict[str, Any]] = []
    stats: dict[str, Any] = {}
    for rec in motor.recordings:
        fingerprint = input_of(rec)
        stats[rec.relative] = fingerprint['stat']
        target = Path(run.out) / motor.motor / rec.name / CALIBRATE_DIR
        if output_conflict(target, 'calibrate'):  # the user's: the baseline is not moved on
            return _conflict_baseline(motor, run, rec, fingerprint['content'], target, refused,
                                      stats)
        try:
            table, settled = load_screened(rec, motor_options(motor.rule, run), columns)
            calibrate_into(rec.path, str(target), 'auto', run.alpha, run.folds, settled,
                           columns, False, table)
        except Refused as err:
            refused.append({'recording': rec.relative, 'content': fingerprint['content'],
                            'reason': str(err), 'sound': isinstance(err, MotorRefused)})
            continue
        except (CliError, IdentificationError, ModelError, OSError) as err:
            refused.append({'recording': rec.relative, 'content': fingerprint['content'],
                            'reason': f'cannot be calibrated: {_line(err)}', 'sound': True})
            continue
        found = {'recording': rec.relative, 'name': rec.name, 'date': rec.date,
                 'coefficients': str(target / 'coefficients.yaml'), 'liquid': settled.liquid,
                 'content': fingerprint['content'], 'refused_before': refused,
                 'rule': baseline_rule_key(motor.rule, run)}
        found['key'] = options_key(found)
        found['stats'] = stats  # the stat of each file above, to check them without reading
        _write_baseline(Path(run.out) / motor.motor, found)
        return found
    tried = next((r for r in refused if r['sound']), None)
    reason = (f"no baseline: {tried['recording']} was tried first and {tried['reason']}"
              if tried else 'no baseline: no recording of the motor is sound')
    none: dict[str, Any] = {'recording': None, 'reason': reason, 'refused_before': refused,
                            'rule': baseline_rule_key(motor.rule, run)}
    none['key'] = options_key(none)
    none['stats'] = stats  # kept too: a rerun with the same recordings and options redoes none
    _write_baseline(Path(run.out) / motor.motor, none)
    return none


def output_conflict(target: Path, command: str) -> bool:
    """
    Whether an output directory holds what `command` did not write (so it cannot be written).

    Parameters
    ----------
    target : pathlib.Path
        The directory, [-]
    command : str
        The satmotor command that writes it, [-]

    Returns
    -------
    bool
        True when it exists, is not empty and is not wholly an earlier output of `command`.

    """
    from satmotor_ros.cli._output import written_by
    if not (target.exists() or target.is_symlink()):
        return False
    if target.is_dir() and not target.is_symlink() and not any(target.iterdir()):
        return False
    return not written_by(command)(target)


def _conflict_baseline(motor: Motor, run: RunOptions, rec: Recording, content: str,
                       target: Path, refused: list[dict[str, Any]],
                       stats: dict[str, Any]) -> dict[str, Any]:
    """
    Return (and write) no baseline: the recording that would be it cannot be written.

    Its ``calibrate/`` holds a user's files: the baseline does not move on to the next
    recording (its health figures would be against another calibration); the motor waits,
    said in one line, until that directory is emptied or removed (``conflict``; ``blocked``
    and ``content`` name the recording).
    """
    reason = (f'no baseline: {rec.relative} would be it, but {target} holds files satmotor '
              'calibrate did not write (kept; empty or remove it and run again)')
    none: dict[str, Any] = {'recording': None, 'reason': reason, 'refused_before': refused,
                            'rule': baseline_rule_key(motor.rule, run), 'conflict': str(target),
                            'blocked': rec.relative, 'content': content}
    none['key'] = options_key(none)
    none['stats'] = stats
    _write_baseline(Path(run.out) / motor.motor, none)
    return none


def no_baseline(baseline: dict[str, Any], rec: Recording) -> Refused:
    """Return why a recording of a motor without a baseline is refused: its own damage first."""
    own = next((r for r in baseline.get('refused_before', ())
                if r.get('recording') == rec.relative and not r.get('sound')), None)
    return Refused(own['reason'] if own else baseline.get('reason', 'no baseline'))


def rule_identity(rule: MotorRule) -> list[Any]:
    """
    Return what a motor's fleet.yaml entry puts into a result: its fields and its files.

    A column mapping or motor file edited in place changes every result read through it, so
    the content of each file the entry names is part of it, not only the path.
    """
    files = [file_digest(name) for name in (rule.motor_file, rule.columns)]
    return [rule.pattern, rule.motor, rule.liquid, rule.family, rule.displacement,
            rule.motor_file, rule.columns, rule.columns_inline, *files]


_DIGESTS: dict[tuple[str, int, int], str] = {}
_SETTLED_NS = 2_000_000_000  # a file's digest is kept once its mtime is this old [ns]


def file_digest(name: str) -> str:
    """
    Return :func:`content_of` a motor file or column mapping; '' for none (or a packaged name).

    Hashed once per (path, size, mtime) in a process: a run's keys, one per recording, hash
    each motor's files once, not once per recording (a file written in the last 2 s is
    hashed every time: an edit within the clock's tick keeps the mtime).
    """
    try:
        st = os.stat(name) if name else None
    except OSError:
        st = None
    if st is None or not Path(name).is_file():
        return ''
    key = (name, st.st_size, st.st_mtime_ns)
    if key in _DIGESTS:
        return _DIGESTS[key]
    digest = content_of(name)
    if time.time_ns() - st.st_mtime_ns > _SETTLED_NS:  # an edit within its mtime's tick: hashed
        _DIGESTS[key] = digest
    return digest


def baseline_rule_key(rule: MotorRule, run: RunOptions) -> str:
    """Hash what a calibrated baseline depends on besides its data."""
    return options_key({'rule': rule_identity(rule), 'liquid': run.liquid, 'alpha': run.alpha,
                        'folds': run.folds})


def given_baseline(motor: Motor, run: RunOptions) -> dict[str, Any]:
    """Return the baseline of a motor whose fleet.yaml entry gives its motor file."""
    found: dict[str, Any] = {'recording': None, 'coefficients': motor.rule.motor_file,
                             'liquid': motor.rule.liquid or run.liquid,
                             'content': file_digest(motor.rule.motor_file),
                             'refused_before': []}
    found['key'] = options_key(found)
    return found


def _write_baseline(directory: Path, found: dict[str, Any]) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    temporary = directory / f'.{BASELINE}.partial-{os.getpid()}'
    temporary.write_text(json.dumps(found, indent=1) + '\n', encoding='utf-8')
    os.replace(temporary, directory / BASELINE)


def recording_options(rule: MotorRule, run: RunOptions, baseline_key: str) -> dict[str, Any]:
    """Return what a recording's outputs depend on besides its data (hashed in its marker)."""
    from satmotor_ros.fleet.health import ESTIMATOR
    return {'rule': rule_identity(rule), 'calibrate': run.calibrate, 'validate': run.validate,
            'liquid': run.liquid, 'alpha': run.alpha, 'folds': run.folds, 'baseline': baseline_key,
            'estimator': ESTIMATOR}


def process_recording(rec: Recording, rule: MotorRule, baseline: dict[str, Any],
                      run: RunOptions) -> dict[str, Any]:
    """
    Run every step asked of one recording and write its done-marker last.

    Parameters
    ----------
    rec : Recording
        The recording, [-]
    rule : MotorRule
        Its motor's fleet.yaml entry, [-]
    baseline : dict
        Its motor's baseline (:func:`calibrate_baseline` or :func:`given_baseline`), [-]
    run : RunOptions
        The run's options, [-]

    Returns
    -------
    dict
        The marker: ``status`` ('done' or 'refused'), ``reason``, ``result`` (the health
        figures), the recording's date and how it was found.

    """
    from satmotor_ros.cli.calibrate import calibrate_into
    from satmotor_ros.cli.validate import validate_into
    from satmotor_ros.cli._common import CliError
    from satmotor_ros.fleet.health import HEALTH_DIR, recording_health
    from satmotor_ros.identify import IdentificationError
    from satmotor_ros.model import ModelError
    out = Path(run.out) / rec.motor / rec.name
    options = options_key(recording_options(rule, run, baseline['key']))
    steps = step_keys(rule, run, baseline['key'])
    if rec.relative == baseline.get('recording'):
        steps.pop(CALIBRATE_DIR, None)  # the baseline task's: calibrated once
    marker: dict[str, Any] = {'recording': rec.relative, 'motor': rec.motor, 'date': rec.date,
                              'time': rec.time, 'time_source': rec.time_source,
                              'options': options, 'steps': steps,
                              'worker': f'{socket.gethostname()}:{os.getpid()}',
                              **input_of(rec)}
    done = is_done(out, rec.path, options)
    if done is not None:
        return done
    kept = kept_steps(out, marker, steps)  # the steps whose own input and options held
    columns = columns_of(rule, run)
    written = [CALIBRATE_DIR] if rec.relative == baseline.get('recording') else []
    try:
        if baseline.get('recording') is None and not baseline.get('coefficients'):
            raise no_baseline(baseline, rec)
        wanted = [name for name in steps if name not in kept]
        if wanted:  # only what is not kept reads the data
            table, settled = load_screened(rec, motor_options(rule, run), columns)
            base = MotorOptions(liquid=baseline['liquid'], motor_file=baseline['coefficients'])
        if CALIBRATE_DIR in wanted:
            calibrate_into(rec.path, str(out / CALIBRATE_DIR), 'auto', run.alpha, run.folds,
                           settled, columns, False, table)
        if VALIDATE_DIR in wanted:
            validate_into(rec.path, str(out / VALIDATE_DIR), 'auto', base, columns, False,
                          table)
        if wanted:
            marker['warnings'] = warnings_of(table)
        else:  # nothing read: the earlier run's
            marker['warnings'] = (read_done(out) or {}).get('warnings', [])
        result = (kept[HEALTH_DIR] if HEALTH_DIR in kept
                  else recording_health(rec.relative, table, base, out).as_dict())
        written += [name for name in steps if name not in written]
    except Refused as err:
        marker.update(status='refused', reason=str(err), result=None)
    except (CliError, IdentificationError, ModelError, OptionError, OSError) as err:
        marker.update(status='refused', reason=_line(err), result=None)
    else:
        marker.update(status='done', reason='', result=result)
    drop_stale(out, tuple(written))
    write_done(out, marker, only=tuple(written))
    return marker


def step_keys(rule: MotorRule, run: RunOptions, baseline_key: str) -> dict[str, str]:
    """
    Return the key of each output a recording is asked for: what that output depends on.

    Toggling ``--validate`` redoes ``validate/`` only: ``calibrate/`` depends on the entry,
    the liquid and calibrate's settings, ``health/`` and ``validate/`` on the entry, the
    liquid and the baseline. The baseline recording's ``calibrate/`` is the baseline task's.
    """
    from satmotor_ros.fleet.health import ESTIMATOR, HEALTH_DIR
    common = {'rule': rule_identity(rule), 'liquid': run.liquid}
    keys = {}
    if run.calibrate:
        keys[CALIBRATE_DIR] = options_key({**common, 'alpha': run.alpha, 'folds': run.folds})
    if run.validate:
        keys[VALIDATE_DIR] = options_key({**common, 'baseline': baseline_key})
    keys[HEALTH_DIR] = options_key({**common, 'baseline': baseline_key, 'estimator': ESTIMATOR})
    return keys


def kept_steps(out: Path, marker: dict[str, Any], steps: dict[str, str]) -> dict[str, Any]:
    """
    Return the outputs an earlier run wrote that hold for this one (name -> its result).

    An output holds when the earlier done-marker was for the same recording (the same stat,
    or content), the output's key is the same, it was done (not refused), and every file it
    listed under the output is still there, its command's marker saying it wrote them.
    """
    from satmotor_ros.cli._output import written_by
    from satmotor_ros.fleet.health import HEALTH_DIR
    old = read_done(out)
    if old is None or old.get('status') != 'done' or not isinstance(old.get('steps'), dict):
        return {}
    if old.get('stat') != marker['stat'] and old.get('content') != marker['content']:
        return {}
    listed = [str(name) for name in old.get('outputs', [])]
    kept: dict[str, Any] = {}
    for name, key in steps.items():
        files = [f for f in listed if f.split('/')[0] == name]
        if old['steps'].get(name) != key or not files or not all(
                (out / f).is_file() for f in files) or not written_by(OUTPUTS[name])(out / name):
            continue
        kept[name] = old.get('result') if name == HEALTH_DIR else None
    if HEALTH_DIR in kept and not isinstance(kept[HEALTH_DIR], dict):
        del kept[HEALTH_DIR]
    return kept


def drop_stale(out: Path, keep: tuple[str, ...]) -> None:
    """
    Remove what an earlier run wrote in a recording's directory and this one did not.

    A rerun on other options (``--calibrate`` or ``--validate`` dropped, a recording now
    refused, the baseline moved to another recording) leaves no earlier output behind. Only
    a directory its command's marker names as wholly its own is removed
    (:func:`~satmotor_ros.cli._output.written_by`): never a file the tool did not write.
    """
    import shutil
    from satmotor_ros.cli._output import written_by
    for name, command in OUTPUTS.items():
        target = out / name
        if name not in keep and target.is_dir() and written_by(command)(target):
            shutil.rmtree(target)


def _line(err: BaseException) -> str:
    """Return the first line of an error, or its type when it says nothing."""
    text = str(err).strip()
    return text.splitlines()[0] if text else type(err).__name__


__all__ = ['BASELINE', 'CALIBRATE_DIR', 'EMPTY', 'MONITOR_DIR', 'MotorRefused', 'NO_LIQUID',
           'RunOptions',
           'OUTPUTS', 'Refused', 'STATE', 'STEP', 'VALIDATE_DIR', 'ZERO_PRESSURE',
           'baseline_rule_key', 'drop_stale', 'file_digest',
           'calibrate_baseline', 'columns_of', 'given_baseline', 'input_of', 'load_screened',
           'motor_options', 'no_baseline', 'output_conflict', 'process_recording', 'warnings_of',
           'kept_steps', 'recording_options', 'step_keys']
