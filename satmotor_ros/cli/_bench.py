# SPDX-License-Identifier: Apache-2.0
"""What the commands that read bench DATA and write into ``--out`` share."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from satmotor_ros.cli._common import fail
from satmotor_ros.identify import BenchTable, DataError, IdentificationError, read_csv
from satmotor_ros.model import ModelError


def add_data_arguments(parser: argparse.ArgumentParser) -> None:
    """
    Add DATA, ``--out`` and ``--mode``: what the commands that read bench data share.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser, [-]

    """
    parser.add_argument('data', metavar='DATA', help='bench CSV or rosbag2 directory')
    parser.add_argument('--out', required=True, metavar='DIR', help='output directory')
    parser.add_argument('--mode', choices=('auto', 'points', 'series'), default='auto',
                        help='rows are steady points, a time series, or decide from the data '
                             '(default: auto)')


def load_data(data: str) -> BenchTable:
    """
    Load a bench CSV, or a rosbag2 directory through :mod:`satmotor_ros.bags`.

    Parameters
    ----------
    data : str
        Path as typed, [-]

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
    if not path.exists():
        msg = f'DATA {data!r}: no such file or directory'
        raise DataError(msg)
    if path.is_dir():
        from satmotor_ros.identify.bag import read_bag
        return read_bag(path)
    return read_csv(path)


def output_dir(out: str) -> Path:
    """Create ``--out`` (and its parents) if it does not exist, and return it."""
    target = Path(out)
    target.mkdir(parents=True, exist_ok=True)
    return target


def run_bench_command(out: str, run: Callable[[], str]) -> int:
    """
    Run a bench command and print its summary line, or fail with one line on stderr.

    Parameters
    ----------
    out : str
        Output directory as typed, named in an error writing it, [-]
    run : callable
        Loads the data, builds the model, writes the outputs and returns the line to print;
        raises :class:`IdentificationError`, :class:`ModelError` or :class:`OSError`, [-]

    Returns
    -------
    int
        0 on success; 1 for unusable data, options or ``--out``.

    """
    try:
        line = run()
    except (IdentificationError, ModelError) as err:
        return fail(err)
    except OSError as err:
        return fail(f'--out {out!r}: {err.strerror}')
    print(line)
    return 0


__all__ = ['add_data_arguments', 'load_data', 'output_dir', 'run_bench_command']
