# SPDX-License-Identifier: Apache-2.0
"""
Run a fleet's tasks on Dask: what is done is checked first, then only the rest is sent.

The client plans on its own (discovery, baselines and done-markers already on disk) and
starts or joins a cluster only when something is left to do. Each motor without a motor
file gets one baseline task; each recording one task that depends on it, so motors run in
parallel and a motor's recordings wait only for its own baseline. The motor's health
monitor is a chain of tasks beside them, one per recording in time order, each resuming
the state the one before saved (:mod:`~satmotor_ros.fleet.chain`). Workers get one thread
each: one task at a time, so a worker's memory limit is a task's.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
import json
import logging
import os
from pathlib import Path
import sys
from typing import Any

from satmotor_ros.fleet.chain import monitor_step, valid_steps
from satmotor_ros.fleet.discover import Motor, Recording
from satmotor_ros.fleet.errors import FleetError
from satmotor_ros.fleet.resume import HashCache, is_done, options_key, stat_of
from satmotor_ros.fleet.tasks import (BASELINE, baseline_rule_key, calibrate_baseline,
                                      given_baseline, output_conflict, process_recording,
                                      recording_options, RunOptions)

MEMORY_FRACTION = 0.8
"""Share of the machine's memory the local workers may hold together, [-]."""

MEMORY_CAP = 4 << 30
"""Most memory one local worker (one task) may hold before Dask stops it, [byte]."""

WORKER_WAIT = 60.0
"""How long a run on --scheduler waits for the cluster's first worker, [s]."""

CONNECT_WAIT = 20.0
"""How long a run on --scheduler tries to reach the scheduler before it gives up, [s]."""


@dataclass
class Plan:
    """What a run has to do: per motor its baseline (if still valid) and its recordings."""

    motors: list[Motor]
    baselines: dict[str, dict[str, Any]] = field(default_factory=dict)  # motor -> baseline
    done: dict[str, dict[str, Any]] = field(default_factory=dict)  # relative -> marker
    todo: list[Recording] = field(default_factory=list)
    steps: dict[str, dict[str, Any]] = field(default_factory=dict)  # relative -> chain step
    chain_from: dict[str, int] = field(default_factory=dict)  # motor -> first step to redo

    @property
    def idle(self) -> bool:
        """Whether nothing is left to do (no recording, no monitor step)."""
        return not self.todo and not self.chain_from

    def motors_to_calibrate(self) -> list[Motor]:
        """Return the motors whose baseline must be (re)calibrated."""
        wanted = {rec.motor for rec in self.todo} | set(self.chain_from)
        return [m for m in self.motors if m.motor in wanted and m.motor not in self.baselines]


@dataclass
class Cluster:
    """How the run was placed: for the report's first lines."""

    address: str
    workers: int
    memory_per_task: int  # the smallest worker memory limit, [byte]; 0 unbounded
    started: bool  # a local cluster started by the run (else an existing one)


def plan(motors: list[Motor], run: RunOptions) -> Plan:
    """
    Find what is done already, reading markers and stats only (no data, no cluster).

    Parameters
    ----------
    motors : list of Motor
        The discovered fleet, [-]
    run : RunOptions
        The run's options, [-]

    Returns
    -------
    Plan
        The valid baselines, the done recordings' markers and the recordings left.

    """
    result = Plan(motors)
    hashes = HashCache(run.out)
    for motor in motors:
        baseline = _valid_baseline(motor, run, hashes)
        if baseline is None:
            result.todo.extend(motor.recordings)
            result.chain_from[motor.motor] = 0
            continue
        result.baselines[motor.motor] = baseline
        held = valid_steps(motor, run, baseline['key'], hashes)
        result.steps.update({m['recording']: m for m in held})
        if len(held) < len(motor.recordings):
            result.chain_from[motor.motor] = len(held)
        key = options_key(recording_options(motor.rule, run, baseline['key']))  # per motor
        for rec in motor.recordings:
            marker = is_done(Path(run.out) / motor.motor / rec.name, rec.path, key, hashes)
            if marker is None:
                result.todo.append(rec)
            else:
                result.done[rec.relative] = marker
    hashes.save()
    return result


def settle_without_baseline(work: Plan, run: RunOptions) -> int:
    """
    Write the monitor steps left of motors without a baseline here, not on a cluster.

    Such a step reads no data: it is refused with the baseline's reason and passes the state
    on (:func:`~satmotor_ros.fleet.chain.monitor_step`), so a rerun left only those (a
    scheduler lost before them) starts no cluster.

    Parameters
    ----------
    work : Plan
        From :func:`plan`; its steps and ``chain_from`` are updated, [-]
    run : RunOptions
        The run's options, [-]

    Returns
    -------
    int
        The steps written.

    """
    written = 0
    for motor in work.motors:
        baseline = work.baselines.get(motor.motor)
        start = work.chain_from.get(motor.motor)
        if start is None or baseline is None or baseline.get('coefficients'):
            continue
        step = work.steps[motor.recordings[start - 1].relative] if start else None
        for rec in motor.recordings[start:]:
            step = work.steps[rec.relative] = monitor_step(rec, motor.rule, baseline, run, step)
            written += 1
        del work.chain_from[motor.motor]
    return written


def _valid_baseline(motor: Motor, run: RunOptions,
                    hashes: HashCache) -> dict[str, Any] | None:
    """Return the motor's baseline when it still holds for the recordings as they are now."""
    if motor.rule.motor_file:
        return given_baseline(motor, run)
    try:
        found = json.loads((Path(run.out) / motor.motor / BASELINE).read_text(encoding='utf-8'))
    except (OSError, ValueError):
        return None
    if not isinstance(found, dict) or found.get('rule') != baseline_rule_key(motor.rule, run):
        return None
    conflict = found.get('conflict')  # the baseline's calibrate/ held a user's files
    if conflict and not output_conflict(Path(conflict), 'calibrate'):
        return None  # they went: it can be calibrated now
    before = [entry.get('recording') for entry in found.get('refused_before', [])]
    head = found.get('recording') or found.get('blocked')  # the baseline, or the one blocked
    calibrated = found.get('recording') is not None  # else every recording was refused
    n = len(before) + (head is not None)
    names = [rec.relative for rec in motor.recordings[:n]]
    if names != [*before, head][:n] or head is None and len(motor.recordings) != len(before):
        return None  # an earlier recording appeared, or one went away
    contents = [e.get('content') for e in found['refused_before']] + [found.get('content')]
    stats = found.get('stats', {})
    for rec, content in zip(motor.recordings, contents):
        try:
            if stats.get(rec.relative) != stat_of(rec.path) and hashes.content(rec.path) \
                    != content:
                return None
        except OSError:
            return None
    return found if not calibrated or Path(found.get('coefficients', '')).is_file() else None


def machine_workers() -> int:
    """Return the cores this process may use: the default number of local workers."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return max(os.cpu_count() or 1, 1)


def memory_per_worker(workers: int) -> int:
    """Return the local workers' memory limit: a share of the machine's, capped, [byte]."""
    from distributed.system import MEMORY_LIMIT  # the machine's, or its cgroup's if lower
    total = int(MEMORY_LIMIT * MEMORY_FRACTION)
    return max(min(total // max(workers, 1), MEMORY_CAP), 256 << 20)


def execute(work: Plan, run: RunOptions, workers: int = 0, scheduler: str = '',
            show_progress: bool = True,
            say: Callable[[str], None] = print) -> tuple[list[dict[str, Any]], Cluster]:
    """
    Run the recordings left on a cluster and return every recording's marker.

    Parameters
    ----------
    work : Plan
        From :func:`plan`, [-]
    run : RunOptions
        The run's options, [-]
    workers : int
        Local workers; 0 sizes the cluster to the machine (ignored with `scheduler`), [-]
    scheduler : str
        Address of a running Dask scheduler (``tcp://host:8786``); '' starts a local
        cluster, [-]
    show_progress : bool
        Draw Dask's progress bar when the output is a terminal, [-]
    say : callable
        Where the line saying the cluster and the memory per task goes, [-]

    Returns
    -------
    tuple of (list of dict, Cluster)
        A marker per recording (``status`` 'done', 'refused' or 'failed' with ``reason``)
        and where it ran.

    Raises
    ------
    FleetError
        If the scheduler cannot be reached or the cluster cannot start.

    """
    with connect(workers, scheduler) as (client, placed):
        steps = sum(len(m.recordings) - work.chain_from[m.motor] for m in work.motors
                    if m.motor in work.chain_from)
        say(f'fleet: {len(work.todo)} recording(s) and {steps} monitor step(s) to do on '
            f'{placed.workers} worker(s) '
            f'at {placed.address}, one task per worker at a time, '
            f'memory per task {_size(placed.memory_per_task)}')
        return run_on(client, work, run, show_progress), placed


@contextmanager
def connect(workers: int = 0, scheduler: str = '') -> Iterator[tuple[Any, Cluster]]:
    """
    Start a local cluster, or join the one at `scheduler`, for the block; close it after.

    Parameters
    ----------
    workers : int
        Local workers (one thread each); 0 one per core, [-]
    scheduler : str
        Address of a running scheduler; '' for a local cluster, [-]

    Yields
    ------
    tuple of (distributed.Client, Cluster)
        The client and where it runs.

    Raises
    ------
    FleetError
        If the scheduler cannot be reached, no worker joins, or the cluster cannot start.

    """
    import dask
    from distributed import Client, LocalCluster
    # Dask's housekeeping runs on a clock, not per task: its statistical profiler samples every
    # task's stack each 10 ms, the event loop ticks each 20 ms and the memory monitor reads
    # the process each 100 ms. Our tasks take a second or more, so the profiler is off and
    # the clocks slower (bench/bench_fleet.py: 13 % of a worker's CPU on a loaded machine
    # before, doc/fleet.md).
    with dask.config.set({'distributed.scheduler.allowed-failures': 1,
                          'distributed.worker.profile.enabled': False,
                          'distributed.admin.tick.interval': '500ms',
                          'distributed.worker.memory.monitor-interval': '500ms',
                          'distributed.worker.daemon': False,
                          'distributed.admin.tick.limit': '1h',
                          'logging.distributed': 'error'}):
        cluster = None
        try:
            if scheduler:
                client = Client(scheduler, timeout=CONNECT_WAIT)
                _wait_for_a_worker(client, scheduler)
            else:
                n = workers or machine_workers()
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                       memory_limit=memory_per_worker(n),
                                       dashboard_address=':0', silence_logs=40)
                client = Client(cluster)
        except (OSError, TimeoutError, ValueError, TypeError) as err:  # TypeError: tls://
            # without a TLS configuration; ValueError: an address distributed cannot use
            where = f'--scheduler {scheduler!r}' if scheduler else 'the local cluster'
            raise FleetError(f'{where}: cannot connect ({_first_line(err)})') from None
        quiet = logging.getLogger('distributed.client')  # a lost scheduler is our one line,
        level = quiet.level  # not its reconnect traceback
        quiet.setLevel(logging.CRITICAL)
        try:
            yield client, _describe(client, scheduler, cluster is not None)
        finally:
            try:
                client.close()
                if cluster is not None:
                    cluster.close()
            finally:
                quiet.setLevel(level)


def run_on(client: Any, work: Plan, run: RunOptions,
           show_progress: bool = False) -> list[dict[str, Any]]:
    """
    Submit the plan's tasks to `client`, wait for them, and return every recording's marker.

    Parameters
    ----------
    client : distributed.Client
        A connected client, [-]
    work : Plan
        From :func:`plan`, [-]
    run : RunOptions
        The run's options, [-]
    show_progress : bool
        Draw Dask's progress bar when the output is a terminal, [-]

    Returns
    -------
    list of dict
        A marker per recording left to do; the monitor steps run go to ``work.steps``.

    """
    from distributed.diagnostics.progressbar import progress
    futures, steps = _submit(client, work, run)
    if show_progress and (futures or steps) and sys.stdout.isatty():
        progress([*futures.values(), *steps.values()])
    for rec, future in steps.items():
        work.steps[rec.relative] = _outcome(rec, future)
    markers = [_outcome(rec, f) for rec, f in futures.items()]
    lost = [m for m in [*markers, *work.steps.values()] if m.get('status') == LOST]
    if lost:  # cancelled by no one: the cluster went away; what finished is kept on disk
        raise FleetError(f'{where_of(client)}: lost mid-run ({lost[0]["reason"]}); what '
                         'finished is kept: run again to resume')
    return markers


LOST = 'lost'
"""A task's status when the cluster cancelled it (the scheduler gone): the run stops."""


def where_of(client: Any) -> str:
    """Name the cluster a client is on, for a one-line message."""
    address = getattr(getattr(client, 'scheduler', None), 'address', '') or ''
    return f'the cluster at {address}' if address else 'the cluster'


def check_address(scheduler: str) -> None:
    """
    Refuse a --scheduler address Dask cannot parse, before any work is planned.

    Parameters
    ----------
    scheduler : str
        The address, e.g. ``tcp://host:8786``; '' passes, [-]

    Raises
    ------
    FleetError
        One line naming the address and what is wrong with it.

    """
    if not scheduler:
        return
    from distributed.comm.addressing import get_address_host_port
    try:
        get_address_host_port(scheduler)
    except (ValueError, TypeError) as err:
        raise FleetError(f'--scheduler {scheduler!r}: not an address such as '
                         f'tcp://host:8786 ({_first_line(err)})') from None


def _first_line(err: BaseException) -> str:
    text = str(err).strip()
    return text.splitlines()[0] if text else type(err).__name__


def _wait_for_a_worker(client: Any, scheduler: str) -> None:
    """Wait for the cluster's first worker, or say in one line that none joined."""
    try:
        client.wait_for_workers(1, timeout=WORKER_WAIT)
    except TimeoutError:
        client.close()
        raise FleetError(f'--scheduler {scheduler!r}: no worker joined in {WORKER_WAIT:g} s '
                         '(start one with `dask worker ADDRESS`)') from None


def _describe(client: Any, scheduler: str, started: bool) -> Cluster:
    info = client.scheduler_info()
    limits = [int(w.get('memory_limit') or 0) for w in info.get('workers', {}).values()]
    threads = [int(w.get('nthreads') or 1) for w in info.get('workers', {}).values()]
    per_task = min((lim // t for lim, t in zip(limits, threads) if lim), default=0)
    return Cluster(info.get('address', scheduler), len(limits), per_task, started)


def _size(n: int) -> str:
    return 'unbounded (the workers have no memory limit)' if not n else f'{n / 2 ** 30:.2f} GiB'


def _submit(client: Any, work: Plan,
            run: RunOptions) -> tuple[dict[Recording, Any], dict[Recording, Any]]:
    baselines: dict[str, Any] = dict(work.baselines)
    for motor in work.motors_to_calibrate():
        baselines[motor.motor] = client.submit(calibrate_baseline, motor, run, pure=False,
                                               key=f'baseline-{motor.motor}-{os.urandom(4).hex()}')
    rules = {m.motor: m.rule for m in work.motors}
    futures = {}
    for rec in work.todo:
        futures[rec] = client.submit(process_recording, rec, rules[rec.motor],
                                     baselines[rec.motor], run, pure=False,
                                     key=f'recording-{rec.motor}-{os.urandom(6).hex()}')
    steps = {}
    for motor in work.motors:
        if motor.motor not in work.chain_from:
            continue
        start = work.chain_from[motor.motor]
        before: Any = work.steps[motor.recordings[start - 1].relative] if start else None
        for rec in motor.recordings[start:]:  # each waits for the one before: one monitor
            before = steps[rec] = client.submit(
                monitor_step, rec, motor.rule, baselines[motor.motor], run, before, pure=False,
                key=f'monitor-{rec.motor}-{os.urandom(6).hex()}')
    return futures, steps


def _outcome(rec: Recording, future: Any) -> dict[str, Any]:
    """Return the marker a task returned, or a 'failed' one naming what stopped it."""
    from asyncio import CancelledError
    try:
        return dict(future.result())
    except (Exception, CancelledError) as err:  # noqa: B902 - a task's error is its own
        text = str(err).strip().splitlines()
        reason = f'{type(err).__name__}: {text[0]}' if text else type(err).__name__
        return {'recording': rec.relative, 'motor': rec.motor, 'date': rec.date,
                'time': rec.time, 'time_source': rec.time_source,
                'status': LOST if _cancelled(err) else 'failed', 'reason': reason,
                'result': None}


def _cancelled(err: BaseException) -> bool:
    """Whether a task was cancelled (we cancel none: the scheduler or the cluster went)."""
    from asyncio import CancelledError
    from distributed.client import FutureCancelledError
    return isinstance(err, (CancelledError, FutureCancelledError))


__all__ = ['Cluster', 'MEMORY_CAP', 'MEMORY_FRACTION', 'Plan', 'WORKER_WAIT', 'check_address',
           'connect', 'execute', 'machine_workers', 'memory_per_worker', 'plan', 'run_on',
           'settle_without_baseline']
