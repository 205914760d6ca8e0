# SPDX-License-Identifier: Apache-2.0
"""The shared run and error handling of the commands that read DATA and write into --out."""

import argparse
import errno

import pytest

from satmotor_ros.cli._bench import load_data, run_bench_command
from satmotor_ros.cli.main import build_parser, subcommand_module, SUBCOMMANDS
from satmotor_ros.identify import DataError
from satmotor_ros.model import ModelError


def test_success_prints_the_line(capsys):
    assert run_bench_command('out', lambda: 'the summary') == 0
    captured = capsys.readouterr()
    assert captured.out == 'the summary\n'
    assert captured.err == ''


@pytest.mark.parametrize('err', [DataError('bad row'), ModelError('bad model')])
def test_data_and_model_errors_are_one_line(capsys, err):
    def run():
        raise err
    assert run_bench_command('out', run) == 1
    captured = capsys.readouterr()
    assert captured.out == ''
    assert captured.err == f'satmotor: error: {err}\n'


def test_os_error_names_out(capsys):
    def run():
        raise PermissionError(errno.EACCES, 'Permission denied', 'x')
    assert run_bench_command('/ro/dir', run) == 1
    assert capsys.readouterr().err == "satmotor: error: --out '/ro/dir': Permission denied\n"


def test_other_errors_propagate():
    def run():
        raise KeyError('bug')
    with pytest.raises(KeyError):
        run_bench_command('out', run)


def test_missing_data_is_a_data_error(tmp_path):
    with pytest.raises(DataError, match='no such file or directory'):
        load_data(str(tmp_path / 'missing.csv'))


def test_every_subcommand_is_registered_with_its_command():
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert list(sub.choices) == list(SUBCOMMANDS)
    for name in SUBCOMMANDS:
        module = subcommand_module(name)
        assert sub.choices[name].get_default('command') is module.command
        assert sub.choices[name].description == module.DESCRIPTION
