# SPDX-License-Identifier: Apache-2.0
"""Every subcommand's --help shows no internal names and ends in examples that parse."""

import re
import shlex

import pytest
from satmotor_ros.cli.main import build_parser, EXAMPLES, main, SUBCOMMANDS


@pytest.mark.parametrize('name', list(SUBCOMMANDS))
def test_help_has_no_internal_names_and_shows_examples(name, capsys):
    with pytest.raises(SystemExit) as stop:
        main([name, '--help'])
    assert stop.value.code == 0
    text = capsys.readouterr().out
    assert not re.search(r'--[\w-]+ [A-Z_]+\.[A-Z_]+', text), text  # MOTOR_OPTIONS.LIQUID
    assert 'MOTOR_OPTIONS' not in text and 'motor_options' not in text, text
    examples = text.split('\nexamples:\n', 1)[1].rstrip().splitlines()
    assert examples and examples == [f'  {line}' for line in EXAMPLES[name]][:len(examples)]


@pytest.mark.parametrize('line', [line for lines in EXAMPLES.values() for line in lines])
def test_every_example_is_a_valid_command_line(line):
    argv = shlex.split(line, comments=True)
    assert argv[0] == 'satmotor'
    args = build_parser().parse_args(argv[1:])  # exits 2 on an unknown option
    assert args.subcommand == argv[1]
    for option in re.findall(r'--[\w-]+', line):  # outputs under out/, never the repo root
        if option in ('--out', '--out-bag'):
            assert argv[argv.index(option) + 1].startswith('out/'), line
