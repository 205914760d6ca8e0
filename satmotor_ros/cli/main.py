# SPDX-License-Identifier: Apache-2.0
"""Argument parsing for ``satmotor``; each subcommand is a function returning an exit code."""

from __future__ import annotations

import argparse
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
import importlib
import signal
import sys
import threading
from types import ModuleType
from typing import NamedTuple

from satmotor_ros import __version__
from satmotor_ros.cli import _output
from satmotor_ros.cli._common import add_subcommand, CliError, fail, take_motor_options
from satmotor_ros.limits import BAD_OVERRIDES


class Subcommand(NamedTuple):
    """Where a subcommand is defined, and what it does in a line."""

    module: str  # defines DESCRIPTION, add_arguments(parser) and command(**options)
    summary: str  # its line in `satmotor --help`


SUBCOMMANDS = {
    'demo': Subcommand('satmotor_ros.cli.demo',
                       'run virtual motor, model and controller over ROS; bag + report'),
    'operating-point': Subcommand('satmotor_ros.cli.operating_point',
                                  'speed and losses at one flow and pressure drop'),
    'characteristics': Subcommand('satmotor_ros.cli.characteristics',
                                  'write characteristic plots (PNG) and their data (CSV)'),
    'replay': Subcommand('satmotor_ros.cli.replay',
                         "run the motor_model node's prediction over a recorded bag"),
    'calibrate': Subcommand('satmotor_ros.cli.calibrate',
                            'fit the model to bench data and find the effect it lacks'),
    'validate': Subcommand('satmotor_ros.cli.validate',
                           'error of a given (calibrated) model on new data'),
    'synthetic': Subcommand('satmotor_ros.cli.synthetic',
                            'write a bench table or recording generated from the model'),
    'monitor': Subcommand('satmotor_ros.cli.monitor',
                          'motor health over recordings: leakage factor, trend, alarms'),
    'fleet': Subcommand('satmotor_ros.cli.fleet',
                        'health of every recording of every motor, on a Dask cluster'),
}
"""
Each ``satmotor`` subcommand, in the order of ``--help``.

Its module is imported only when the subcommand runs (or shows its own help): a command
never needs the libraries of another (``operating-point`` runs without the bag library).
"""

EXAMPLES = {
    'demo': ['satmotor demo    # both liquids, 24 s simulated each, into out/demo',
             'satmotor demo --liquid water --duration 12 --out out/short',
             'satmotor demo --effect clearance_wear=1e-9 --no-loop --out out/worn'],
    'operating-point': ['satmotor operating-point --liquid water --flow 5 --dp-i 25',
                        'satmotor operating-point --flow 10 --dp 100bar --json',
                        'satmotor operating-point --flow 10 --dp 100bar --family paszota '
                        '--displacement 0.30in^3/rev'],
    'characteristics': ['satmotor characteristics --liquid oil --out out/oil',
                        'satmotor characteristics --liquid water --law eq39 --out out/water39'],
    'replay': ['satmotor replay out/demo/bags/water_model --liquid water --out out/water.csv',
               'satmotor replay rig_bag --topic-map /rig/q:=flow_command --out-bag '
               'out/rig_predicted --no-plot'],
    'calibrate': ['satmotor calibrate bench.csv --liquid water --out out/cal',
                  'satmotor calibrate log.exp --columns mbari_pto --liquid oil '
                  "--displacement '0.30 in^3/rev' --out out/cal_log"],
    'validate': ['satmotor validate today.csv --motor out/cal/coefficients.yaml --liquid water '
                 '--out out/val'],
    'monitor': ['satmotor monitor day1.csv day2.csv --motor out/cal/coefficients.yaml '
                '--liquid oil --out out/health',
                'satmotor monitor run.exp --columns mbari_pto --liquid oil --family paszota '
                "--displacement '0.30 in^3/rev' --out out/health_log"],
    'synthetic': ['satmotor synthetic --liquid water --effect external_leakage --seed 4 '
                  '--out out/leak.csv',
                  'satmotor synthetic --liquid water --effect external_leakage --transient 90 '
                  '--bag mcap --out out/run_transient'],
    'fleet': ['satmotor fleet recordings/ --out out/fleet    # local cluster, a worker per core',
              'satmotor fleet recordings/ --fleet fleet.yaml --calibrate --workers 2 '
              '--out out/fleet',
              'satmotor fleet recordings/ --scheduler tcp://10.0.0.5:8786 --out out/fleet'],
}
"""Example command lines of each subcommand, shown at the end of its ``--help``."""

INTERRUPTED = 130
"""Exit code after SIGINT or SIGTERM (128 + SIGINT, as a shell reports Ctrl-C), [-]."""


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised as Ctrl-C is so that every output's with-block removes its temporary."""


def _terminate(signum: int, frame: object) -> None:
    raise _Terminated


@contextmanager
def _sigterm_as_interrupt() -> Iterator[None]:
    if threading.current_thread() is not threading.main_thread():  # only it may set one
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _interrupted(err: KeyboardInterrupt) -> int:
    """Say in one line that the run was interrupted and what became of its outputs."""
    how = 'terminated (SIGTERM)' if isinstance(err, _Terminated) else 'interrupted'
    done = _output.COMMITTED
    left = ('; ' + ', '.join(map(str, done)) + ' written before it') if done else ''
    print(f'satmotor: {how}; outputs not yet written are left as they were{left}',
          file=sys.stderr)
    return INTERRUPTED


def subcommand_module(name: str) -> ModuleType:
    """
    Import the module that defines a subcommand.

    Parameters
    ----------
    name : str
        A key of :data:`SUBCOMMANDS`, [-]

    Returns
    -------
    module
        Its module.

    """
    return importlib.import_module(SUBCOMMANDS[name].module)


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """
    Build the ``satmotor`` argument parser.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments it will parse: only the subcommand they name is imported and given
        its options (the others are listed by name and help); None: every subcommand, [-]

    Returns
    -------
    argparse.ArgumentParser
        Parser with one subparser per subcommand.

    """
    parser = argparse.ArgumentParser(
        prog='satmotor',
        description='Volumetric losses and speed of the hydraulic satellite motor '
                    '(Śliwiński 2017 model).')
    parser.add_argument('--version', action='version', version=f'%(prog)s {__version__}')
    sub = parser.add_subparsers(dest='subcommand', required=True, metavar='COMMAND')
    named = SUBCOMMANDS.keys() if argv is None else _named(argv)
    for name, (_, short) in SUBCOMMANDS.items():
        if name in named:
            add_subcommand(sub, name, subcommand_module(name), short, EXAMPLES[name])
        else:
            sub.add_parser(name, help=short)
    return parser


def _named(argv: Sequence[str]) -> set[str]:
    """Return the subcommand `argv` names: its first word (before it, options take no value)."""
    first = next((arg for arg in argv if not arg.startswith('-')), None)
    return {first} if first in SUBCOMMANDS else set()


def main(argv: Sequence[str] | None = None) -> int:
    """
    Run ``satmotor``.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when omitted, [-]

    Returns
    -------
    int
        Exit code: 0 on success, 1 on an error the command reports (also a SATMOTOR_*
        cap variable that changes nothing, or memory running out), 2 on bad usage, 130
        after SIGINT (Ctrl-C) or SIGTERM (one line; no output is left half-written).

    """
    with _sigterm_as_interrupt():
        try:
            return _run(argv)
        except KeyboardInterrupt as err:
            return _interrupted(err)
        except MemoryError:
            return fail('out of memory; ask for less (fewer points, a lower --rate, a '
                        'shorter bag)')


def _run(argv: Sequence[str] | None) -> int:
    if argv is None:
        argv = sys.argv[1:]
    args = vars(build_parser(argv).parse_args(argv))
    args.pop('subcommand')
    command = args.pop('command')
    if BAD_OVERRIDES:  # the user meant a cap to change; running on the default would hide that
        return fail('; '.join(map(str, BAD_OVERRIDES)))
    try:
        args = take_motor_options(args)
    except CliError as err:
        return fail(err)
    code: int = command(**args)  # argparse's defaults are Any
    return code


if __name__ == '__main__':
    sys.exit(main())
