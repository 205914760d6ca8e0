# SPDX-License-Identifier: Apache-2.0
"""Argument parsing for ``satmotor``; each subcommand is a function returning an exit code."""

from __future__ import annotations

import argparse
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
import signal
import sys
import threading

from satmotor_ros import __version__
from satmotor_ros.cli import (_output, calibrate, characteristics, demo, operating_point,
                              replay, validate)
from satmotor_ros.cli._common import add_subcommand, CliError, fail, take_motor_options
from satmotor_ros.limits import BAD_OVERRIDES

SUBCOMMANDS = {'demo': demo, 'operating-point': operating_point,
               'characteristics': characteristics, 'replay': replay, 'calibrate': calibrate,
               'validate': validate}
"""Each ``satmotor`` subcommand and the module that defines it, in the order of ``--help``."""

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


def build_parser() -> argparse.ArgumentParser:
    """
    Build the ``satmotor`` argument parser.

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
    for name, module in SUBCOMMANDS.items():
        add_subcommand(sub, name, module, EXAMPLES[name])
    return parser


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
    args = vars(build_parser().parse_args(argv))
    args.pop('subcommand')
    command = args.pop('command')
    if BAD_OVERRIDES:  # the user meant a cap to change; running on the default would hide that
        return fail('; '.join(map(str, BAD_OVERRIDES)))
    try:
        args = take_motor_options(args)
    except CliError as err:
        return fail(err)
    return command(**args)


if __name__ == '__main__':
    sys.exit(main())
