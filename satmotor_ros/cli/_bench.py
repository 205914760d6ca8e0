# SPDX-License-Identifier: Apache-2.0
"""What the commands that read bench DATA and write into ``--out`` share."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
import sys
from typing import Any

from satmotor_ros.cli._common import CliError, fail
from satmotor_ros.cli._liquid import Liquid, settle_liquid
from satmotor_ros.cli._output import add_out_dir, check_target, written_by
from satmotor_ros.identify import BenchTable, DataError, IdentificationError, read_csv
from satmotor_ros.identify.columns import load_mapping, read_log
from satmotor_ros.identify.table import BAD_CELLS, IMPOSSIBLE, negative_losses
from satmotor_ros.identify.textfile import SANITY
from satmotor_ros.model import ModelError
from satmotor_ros.options import MotorOptions


def add_data_arguments(parser: argparse.ArgumentParser,
                       modes: tuple[str, ...] = ('auto', 'points', 'series')) -> None:
    """
    Add DATA, ``--out``, ``--mode`` and ``--columns``, shared by the bench-data commands.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser, [-]
    modes : tuple of str
        The ``--mode`` choices the command takes, [-]

    """
    parser.add_argument('data', metavar='DATA', help='bench CSV or rosbag2 directory')
    add_out_dir(parser)
    transient = (', transient: a time series, every sample with the transient terms'
                 if 'transient' in modes else '')
    parser.add_argument('--mode', choices=modes, default='auto',
                        help='points: rows are steady points; series: a time series, its '
                             f'steady windows{transient}; auto: decide from the data '
                             '(default)')
    parser.add_argument('--columns', default='', metavar='MAPPING',
                        help='read a log with its own column names and units through a column '
                             'mapping: a YAML file or a packaged name such as mbari_pto '
                             '(doc/columns.md)')


def open_bench(command: str, data: str, out: str, options: MotorOptions, columns: str,
               force: bool, table: BenchTable | None) -> tuple[list[str], Liquid, BenchTable]:
    """
    Refuse an ``--out`` that may not be replaced, settle the liquid and load the data.

    Parameters
    ----------
    command : str
        The subcommand, [-]
    data, out, options, columns, force
        As the subcommand's ``command`` takes them, [-]
    table : BenchTable or None
        `data` already loaded by :func:`load_data`; read here when None, [-]

    Returns
    -------
    tuple
        (the inputs, never replaced; the liquid settled, :func:`settle_liquid`; the table,
        whose notes say where the liquid came from).

    """
    inputs = [name for name in (data, options.motor_file, columns) if name]
    check_target('--out', Path(out), inputs, force, written_by(command), command)
    settled = settle_liquid(options, data, command)
    if table is None:
        table = load_data(data, columns, settled.options.spec().geometry.displacement)
    table = replace(table, notes=table.notes + (f'liquid: {settled.source}',)
                    + ((f'WARNING: {settled.warning}',) if settled.warning else ()))
    return inputs, settled, table


def load_data(data: str, columns: str = '', displacement: float | None = None) -> BenchTable:
    """
    Load a bench CSV, a log through a column mapping, or a rosbag2 directory.

    Rows dropped for a physically impossible value, absurd or missing cells are named on
    stderr too.

    Parameters
    ----------
    data : str
        Path as typed, [-]
    columns : str
        ``--columns``: a mapping file or packaged name; '' for a bench CSV or a bag, [-]
    displacement : float, optional
        The motor's displacement, to name one that makes most losses negative, [m^3/rad]

    Returns
    -------
    BenchTable
        The data in SI.

    Raises
    ------
    DataError
        If the path is missing or cannot be read.

    """
    path = Path(data)
    try:
        path.stat()
    except FileNotFoundError:
        msg = f'DATA {data!r}: no such file or directory'
        raise DataError(msg) from None
    except OSError as err:  # a loop of symbolic links, a directory we may not enter
        msg = f'DATA {data!r}: {err.strerror}'
        raise DataError(msg) from None
    if path.is_dir():
        if columns:
            msg = f'--columns {columns!r}: a column mapping reads text logs, not a rosbag2'
            raise DataError(msg)
        from satmotor_ros.identify.bag import read_bag
        table = read_bag(path)
        said: tuple[str, ...] = ()  # a bag's notes are in its report only
    else:
        table = read_log(path, load_mapping(columns)) if columns else read_csv(path)
        said = table.notes
    if displacement is not None:
        checked = negative_losses(table, displacement)
        said, table = said + checked.notes[len(table.notes):], checked
    for note in said:
        if note.startswith((IMPOSSIBLE, BAD_CELLS, SANITY)):
            print(f'warning: {data}: {note}', file=sys.stderr)
    return table


def run_bench_command(out: str, run: Callable[[], str]) -> int:
    """
    Run a bench command and print its summary line, or fail with one line on stderr.

    Parameters
    ----------
    out : str
        Output directory as typed, named in an error writing it, [-]
    run : callable
        Loads the data, builds the model, writes the outputs and returns the line to print;
        raises :class:`CliError`, :class:`IdentificationError`, :class:`ModelError` or
        :class:`OSError`, [-]

    Returns
    -------
    int
        0 on success; 1 for unusable data, options or ``--out``.

    """
    try:
        line = run()
    except (CliError, IdentificationError, ModelError) as err:
        return fail(err)
    except OSError as err:
        return fail(f'--out {out!r}: {err.strerror}')
    print(line)
    return 0


def samples_left_out(coverage: dict[str, Any]) -> str:
    """
    Say how many of the data's samples no figure of the summary line is over, or ''.

    The errors are over the samples the model could be evaluated at; the others (no flow
    the model can give, a chamber drop out of range, too few for a bin) are where it may
    miss most, so the line says they were left out.
    """
    used, total = coverage['samples_used'], coverage['samples_total']
    if used >= total:
        return ''
    return (f'; {total - used} of {total} samples left out, the error is not over them '
            '(why: report.md)')


__all__ = ['add_data_arguments', 'load_data', 'run_bench_command', 'samples_left_out']
