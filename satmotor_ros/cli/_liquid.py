# SPDX-License-Identifier: Apache-2.0
"""
Which liquid a command on recorded data uses: the one the data record, or the user's.

No guess: a bag of the demo or of ``replay --out-bag`` records its liquid and motor
(:mod:`satmotor_ros.bags.custom`); where neither the data nor ``--liquid`` says, the command
refuses with one line. An explicit ``--liquid`` that differs from the recorded one is
followed (a set of a user's ``--motor`` may have any name, and predicting a recording with
another liquid is a fair question) but said loudly on stderr and in the output.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
import sys
from typing import NamedTuple

from satmotor_ros.bags.custom import custom_data, LIQUID_KEY, MOTOR_KEY
from satmotor_ros.cli._common import CliError
from satmotor_ros.model import ModelError
from satmotor_ros.options import MotorOptions


class Liquid(NamedTuple):
    """The options with their liquid settled, and where it came from."""

    options: MotorOptions
    source: str  # one phrase for the output, e.g. 'recorded in the bag'
    warning: str  # '' or the disagreement with the recording, said on stderr and in the output


def settle_liquid(options: MotorOptions, data: str, command: str) -> Liquid:
    """
    Take the liquid from ``--liquid`` or from what the data record; refuse where neither says.

    Parameters
    ----------
    options : MotorOptions
        As parsed; ``liquid == ''`` when ``--liquid`` was not given, [-]
    data : str
        The recording (bag directory, storage file or CSV) as typed, [-]
    command : str
        The subcommand, for the warning, [-]

    Returns
    -------
    Liquid
        The options to use and where the liquid came from.

    Raises
    ------
    CliError
        If neither the data nor ``--liquid`` gives the liquid.

    """
    recorded = custom_data(data) if Path(data).exists() else {}
    theirs = recorded.get(LIQUID_KEY, '')
    motor = recorded.get(MOTOR_KEY, '')
    if not options.liquid:
        if not theirs:
            raise CliError(f'{data}: the data do not record their liquid: name it with '
                           "--liquid ('oil' or 'water', or a set of --motor)")
        options = replace(options, liquid=theirs)
        settled = Liquid(options, f'{theirs} (recorded in the bag'
                         + (f', motor {motor})' if motor else ')'), '')
    elif theirs and theirs != options.liquid:
        settled = Liquid(options, f'{options.liquid} (--liquid; the bag records {theirs})',
                         f'--liquid {options.liquid} differs from the liquid recorded in {data} '
                         f'({theirs}): {command} uses {options.liquid} as told')
    else:
        settled = Liquid(options, f'{options.liquid} (--liquid'
                         + (', as recorded)' if theirs else ')'), '')
    warnings = [w for w in (settled.warning, _other_motor(options, motor, data, command)) if w]
    for warning in warnings:
        print(f'satmotor {command}: WARNING: {warning}', file=sys.stderr)
    return settled._replace(warning='; '.join(warnings))


def _other_motor(options: MotorOptions, recorded: str, data: str, command: str) -> str:
    """Say that the recording names a motor other than the packaged one used for want of one."""
    if not recorded or options.motor_file or options.family or options.displacement:
        return ''
    try:
        used = options.build_model().name
    except ModelError:
        return ''  # the command itself says what is wrong with the options, in one line
    if used == recorded:
        return ''
    return (f'{data} records the motor {recorded!r}; {command} uses the packaged {used} for '
            'want of --motor (give the file of the recorded motor with --motor)')


__all__ = ['Liquid', 'settle_liquid']
