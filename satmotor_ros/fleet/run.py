# SPDX-License-Identifier: Apache-2.0
"""One fleet run: discover, plan what is left, run it on Dask, write the fleet's view."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
import json
from pathlib import Path
import time
from typing import Any

from satmotor_ros.cli._output import check_target, MARKER, written_by
from satmotor_ros.fleet.config import FLEET_FILE, FleetConfig, load_fleet, RESERVED
from satmotor_ros.fleet.discover import discover
from satmotor_ros.fleet.engine import check_address, execute, plan, settle_without_baseline
from satmotor_ros.fleet.errors import FleetError
from satmotor_ros.fleet.explain import explain_alarms
from satmotor_ros.fleet.health import ESTIMATOR
from satmotor_ros.fleet.prune import check_root, prune
from satmotor_ros.fleet.report import not_ours, write_report
from satmotor_ros.fleet.resume import read_marker
from satmotor_ros.fleet.summary import iso_now, LIMIT, motor_view, rank
from satmotor_ros.fleet.tasks import BASELINE, RunOptions


@dataclass(frozen=True)
class Outcome:
    """What a run did, for the summary line and the tests."""

    recordings: int  # found under ROOT [-]
    ran: int  # processed by this run [-]
    reused: int  # already done [-]
    refused: int  # refused or failed [-]
    cluster: str  # where it ran; '' when nothing was left to do
    seconds: float  # wall time [s]
    motors: tuple[str, ...]  # ranked, soonest to the limit first


def run_fleet(root: str, out: str, fleet: str = '', workers: int = 0, scheduler: str = '',
              calibrate: bool = False, validate: bool = False, liquid: str = '',
              limit: float = LIMIT, force: bool = False, show_progress: bool = True,
              say: Callable[[str], None] = print) -> Outcome:
    """
    Run every recording of a fleet that is not done yet and write the fleet's view.

    Parameters
    ----------
    root : str
        The fleet's tree, [-]
    out : str
        DIR: per-recording outputs, fleet.json, fleet.md, plots/, [-]
    fleet : str
        fleet.yaml; '' for ROOT/fleet.yaml when there is one, [-]
    workers : int
        Local workers; 0 sizes the cluster to the machine, [-]
    scheduler : str
        Address of a running Dask scheduler; '' starts a local cluster, [-]
    calibrate, validate : bool
        Also calibrate every recording, validate it against the baseline, [-]
    liquid : str
        Liquid of motors fleet.yaml gives none to ('' the data's own), [-]
    limit : float
        Limit of the leakage factor, [-]
    force : bool
        Use an existing DIR that a fleet run did not write, or one whose last report was of
        another ROOT (taking it over: that ROOT's outputs go), [-]
    show_progress : bool
        Draw the progress bar, [-]
    say : callable
        Where progress lines go, [-]

    Returns
    -------
    Outcome
        Counts, where it ran and the ranking.

    Raises
    ------
    FleetError
        ROOT missing or empty of recordings, fleet.yaml invalid, DIR not ours or (without
        `force`) last reported of another ROOT, the cluster
        unreachable (one line naming the field and value).

    """
    started = time.monotonic()
    base = Path(root)
    if not base.is_dir():
        raise FleetError(f'ROOT {root!r}: not a directory')
    target = Path(out).resolve()
    from satmotor_ros.cli._common import CliError
    try:
        check_target('--out', target, [str(base)], force, written_by('fleet'), 'fleet')
    except CliError as err:
        raise FleetError(str(err)) from None
    taken = check_root(target, base, force)  # before any work: a DIR of another ROOT
    check_address(scheduler)
    config = _config(base, fleet)
    motors = discover(base, config)
    if not motors:
        raise FleetError(f'ROOT {root!r}: no recordings (rosbag2 directories, *.csv, or logs '
                         'of a motor with columns in fleet.yaml)')
    theirs = not_ours(target, [m.motor for m in motors])
    if theirs:  # --force or not: a file we did not write is never replaced
        raise FleetError(f"--out {out!r}: {', '.join(theirs)} not written by satmotor fleet "
                         '(never replaced, even with --force: move it away)')
    target.mkdir(parents=True, exist_ok=True)
    if (read_marker(target / MARKER) or {}).get('command') != 'fleet':  # keep its digests
        (target / MARKER).write_text(json.dumps({'command': 'fleet'}) + '\n', encoding='utf-8')
    options = RunOptions(str(target), calibrate, validate, liquid)
    work = plan(motors, options)
    settle_without_baseline(work, options)  # steps that read nothing: no cluster for them
    markers = dict(work.done)
    where = ''
    if not work.idle:
        ran, cluster = execute(work, options, workers, scheduler, show_progress, say)
        markers.update({m['recording']: m for m in ran})
        where = cluster.address
    else:
        say(f'fleet: all {len(markers)} recordings already done for these inputs and options; '
            'no cluster started')
    if taken is not None:
        say(f'fleet: --out {out!r} taken over from ROOT {taken!r} (--force)')
    gone = prune(target, base, motors, RESERVED)  # recordings and motors no longer under ROOT
    if gone:
        more = ' ...' if len(gone) > 5 else ''
        say(f'fleet: removed the outputs of {len(gone)} recording(s) or motor(s) no longer '
            f"under ROOT: {', '.join(gone[:5])}{more}")
    views = []
    for motor in motors:
        baseline = work.baselines.get(motor.motor) or _read_baseline(target / motor.motor)
        view = motor_view(motor.motor, motor.rule.liquid or liquid,
                          [markers[r.relative] for r in motor.recordings if r.relative
                           in markers], baseline, limit,
                          [work.steps[r.relative] for r in motor.recordings
                           if r.relative in work.steps])
        explain_alarms(view, motor, baseline, markers, options)
        views.append(view)
    ranked = rank(views)
    refused = sum(len(v['refused']) for v in views)
    total = sum(len(m.recordings) for m in motors)
    header = {'root': str(base.resolve()), 'written': iso_now(), 'recordings': total,
              'refused': refused, 'ran': len(work.todo), 'reused': len(work.done),
              'estimator': ESTIMATOR, 'limit': limit, 'cluster': where,
              'fleet_file': config.source}
    write_report(target, ranked, header)
    return Outcome(total, len(work.todo), len(work.done), refused, where,
                   time.monotonic() - started, tuple(v['motor'] for v in ranked))


def _config(base: Path, fleet: str) -> FleetConfig:
    if fleet:
        return load_fleet(fleet)
    local = base / FLEET_FILE
    return load_fleet(local) if local.is_file() else FleetConfig()


def _read_baseline(directory: Path) -> dict[str, Any] | None:
    return read_marker(directory / BASELINE)


__all__ = ['Outcome', 'run_fleet']
