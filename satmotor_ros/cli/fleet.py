# SPDX-License-Identifier: Apache-2.0
"""``satmotor fleet``: every recording of every motor, on Dask, and the fleet's view."""

from __future__ import annotations

import argparse

from satmotor_ros.cli._common import fail, number_option
from satmotor_ros.fleet.errors import FleetError
from satmotor_ros.fleet.summary import LIMIT

DESCRIPTION = ('Find the recordings under ROOT (rosbag2 directories, bench CSVs, logs read '
               'through a column mapping), group them by motor (fleet.yaml patterns, else the '
               'first directory level) and order them in time; estimate the health of each '
               "against its motor's baseline (its first usable recording, calibrated, unless "
               'fleet.yaml gives a motor file), and calibrate or validate each when asked, as '
               'tasks on a local Dask cluster or on --scheduler. Outputs go to '
               'DIR/<motor>/<recording>/ as the single commands write them, and DIR/fleet.json, '
               'fleet.md and plots/ rank the motors soonest to the limit. A rerun redoes only '
               'what changed.')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor fleet``."""
    parser.add_argument('root', metavar='ROOT', help="directory holding the fleet's recordings")
    parser.add_argument('--out', required=True, metavar='DIR',
                        help='output directory (outside ROOT); an existing one is used only '
                             'if a fleet run wrote it')
    parser.add_argument('--force', action='store_true',
                        help='use an existing --out that a fleet run did not write, or take '
                             'over one whose last report was of another ROOT (the outputs of '
                             'that ROOT go)')
    parser.add_argument('--fleet', default='', metavar='FILE',
                        help='fleet description (default: ROOT/fleet.yaml when present)')
    parser.add_argument('--workers', type=_workers, default=0, metavar='N',
                        help='local Dask workers, one task each at a time (default: one per '
                             'core of this machine)')
    parser.add_argument('--scheduler', default='', metavar='ADDRESS',
                        help='run on an existing Dask cluster, e.g. tcp://host:8786 (started '
                             'with `dask scheduler` and `dask worker`; see doc/fleet.md)')
    parser.add_argument('--calibrate', action='store_true',
                        help='also calibrate every recording (DIR/<motor>/<recording>/calibrate)')
    parser.add_argument('--validate', action='store_true',
                        help="also validate every recording against its motor's baseline "
                             '(DIR/<motor>/<recording>/validate)')
    parser.add_argument('--liquid', choices=('oil', 'water'), default='',
                        help='liquid of the motors fleet.yaml gives none (default: what each '
                             'recording records; a recording that records none is refused)')
    parser.add_argument('--limit', type=_limit, default=LIMIT, metavar='FACTOR',
                        help=f'limit of the leakage factor (default {LIMIT:g})')
    parser.add_argument('--no-progress', dest='progress', action='store_false',
                        help='no progress bar')


_workers = number_option(int, lambda value: 1 <= value <= 1024, 'must be from 1 to 1024')
_limit = number_option(float, lambda value: 1.0 < value < float('inf'),
                       'must be a finite factor above 1')


def command(root: str, out: str, force: bool = False, fleet: str = '', workers: int = 0,
            scheduler: str = '', calibrate: bool = False, validate: bool = False,
            liquid: str = '', limit: float = LIMIT, progress: bool = True) -> int:
    """
    Run the fleet and print one summary line.

    Parameters
    ----------
    root, out, fleet, scheduler, liquid : str
        As parsed, [-]
    force, calibrate, validate, progress : bool
        As parsed, [-]
    workers : int
        Local workers; 0 one per core, [-]
    limit : float
        Limit of the leakage factor, [-]

    Returns
    -------
    int
        0 when the fleet's view is written (refused recordings are in it); 1 with one line
        on stderr when the run cannot start (ROOT, --out, fleet.yaml, the cluster).

    """
    from satmotor_ros.fleet.run import run_fleet  # dask and the fleet's engine: only when run
    try:
        done = run_fleet(root, out, fleet, workers, scheduler, calibrate, validate, liquid,
                         limit, force, progress)
    except FleetError as err:
        return fail(err)
    except OSError as err:
        return fail(f'--out {out!r}: {err.strerror or err}')
    first = f'; soonest to the limit: {done.motors[0]}' if done.motors else ''
    print(f'fleet: {done.recordings} recordings, {done.ran} processed, {done.reused} already '
          f'done, {done.refused} refused{first}; {done.seconds:.1f} s; wrote {out}/fleet.json, '
          'fleet.md, plots/')
    return 0
