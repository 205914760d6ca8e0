# SPDX-License-Identifier: Apache-2.0
"""What the subcommands share: registration, the motor options, quantities, errors."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
import math
import sys
from types import ModuleType
from typing import Any, TypeVar

from satmotor_ros.model.errors import UnitError
from satmotor_ros.model.families import FAMILIES
from satmotor_ros.model.units import parse_quantity
from satmotor_ros.options import DISPLACEMENT_LAWS, MotorOptions, OptionError


class CliError(Exception):
    """A user-facing error: printed as one line, exit code 1."""


Number = TypeVar('Number', int, float)


def number_option(kind: Callable[[str], Number], acceptable: Callable[[Number], bool],
                  need: str) -> Callable[[str], Number]:
    """
    Make the argparse ``type`` of a numeric option: a usage error names the text and the need.

    Parameters
    ----------
    kind : {int, float}
        What the text must be, [-]
    acceptable : callable
        Whether a value is in range, [-]
    need : str
        What an out-of-range value is told, e.g. ``'must be at least 2'``, [-]

    Returns
    -------
    callable
        Text -> value, raising :class:`argparse.ArgumentTypeError`.

    """
    what = 'a whole number' if kind is int else 'a number'

    def read(text: str) -> Number:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f'{text!r}: not {what}') from None
        if not acceptable(value):
            raise argparse.ArgumentTypeError(f'{text!r}: {need}')
        return value
    return read


MOTOR_FLAGS = {'liquid': '--liquid', 'motor_file': '--motor', 'family': '--family',
               'displacement': '--displacement', 'displacement_law': '--law',
               'viscosity': '--viscosity', 'density': '--density',
               'bulk_modulus': '--bulk-modulus'}
"""Each :class:`MotorOptions` field and its ``satmotor`` option."""

_QUANTITIES = {'viscosity': ('viscosity', 'cSt'), 'density': ('density', 'kg/m^3'),
               'bulk_modulus': ('pressure', 'MPa'),
               'displacement': ('displacement', 'cm^3/rev')}  # option -> (kind, default unit)
_PREFIX = 'motor_options.'  # the argparse dest of a motor option: prefix + field


def add_subcommand(sub: argparse._SubParsersAction[argparse.ArgumentParser], name: str,
                   module: ModuleType, short: str, examples: Sequence[str] = ()) -> None:
    """
    Add the subcommand a module defines; its parsed options go to ``command`` as keywords.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``satmotor`` subparsers, [-]
    name : str
        The subcommand, [-]
    module : module
        Defines ``DESCRIPTION`` (its long help), ``add_arguments(parser)`` and ``command``
        (runs it and returns the exit code), [-]
    short : str
        Its line in ``satmotor --help``, [-]
    examples : sequence of str
        Command lines shown under "examples:" at the end of its ``--help``, [-]

    """
    epilog = 'examples:\n' + '\n'.join(f'  {line}' for line in examples) if examples else None
    parser = sub.add_parser(name, help=short, description=module.DESCRIPTION,
                            epilog=epilog, formatter_class=_ExamplesFormatter)
    parser.set_defaults(command=module.command)
    module.add_arguments(parser)


class _ExamplesFormatter(argparse.HelpFormatter):
    """Wrap the description as usual but keep the examples' lines as they are written."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        if text.startswith('examples:'):
            return ''.join(indent + line for line in text.splitlines(keepends=True))
        return super()._fill_text(text, width, indent)


def add_motor_options(parser: argparse.ArgumentParser, *, liquid_from_data: bool = False,
                      model_options: bool = True) -> None:
    """
    Add the motor options; the command receives them as one ``options`` :class:`MotorOptions`.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser, [-]
    liquid_from_data : bool
        ``--liquid`` has no default: '' when not given, and the command takes the liquid
        the data record or refuses (:func:`satmotor_ros.cli._liquid.settle_liquid`), [-]
    model_options : bool
        Also ``--law`` and the user-liquid properties (not for a calibration, which fits
        the set's own liquid), [-]

    """
    group = parser.add_argument_group('motor and liquid')
    group.add_argument('--liquid', dest=_PREFIX + 'liquid',
                       default='' if liquid_from_data else MotorOptions.liquid,
                       metavar='NAME',
                       help="coefficient set and its liquid: 'oil' or 'water' for the packaged "
                            'SM-0,75/25, or any set in --motor'
                            + (' (default: the liquid the bag records; data that record none '
                               'need it)' if liquid_from_data else ' (default: oil)'))
    group.add_argument('--motor', dest=_PREFIX + 'motor_file', default='', metavar='YAML',
                       help='motor specification or calibrated coefficients file (default: '
                            'the packaged SM-0,75/25)')
    group.add_argument('--family', dest=_PREFIX + 'family', default=MotorOptions.family,
                       choices=tuple(FAMILIES), metavar='NAME',
                       help='model family: ' + '; '.join(f'{name}: {f.title}'
                                                         for name, f in FAMILIES.items())
                       + ". Default: the motor file's own; without --motor, the SM-0,75/25 "
                         "(or a motor of --displacement) with the family's defaults")
    group.add_argument('--displacement', dest=_PREFIX + 'displacement', default=None,
                       metavar='Q', help='displacement of a motor with no YAML (default '
                                         "cm^3/rev; e.g. 0.30in^3/rev): the family's default "
                                         'coefficients, to be calibrated')
    if not model_options:
        return
    group.add_argument('--law', dest=_PREFIX + 'displacement_law', choices=DISPLACEMENT_LAWS,
                       default=MotorOptions.displacement_law,
                       help='change of displacement: physical eq. (33) or empirical eq. (39)')
    group.add_argument('--viscosity', dest=_PREFIX + 'viscosity', default=None, metavar='NU',
                       help='run a user liquid on the set: kinematic viscosity (default cSt)')
    group.add_argument('--density', dest=_PREFIX + 'density', default=None, metavar='RHO',
                       help='user liquid density (default kg/m^3)')
    group.add_argument('--bulk-modulus', dest=_PREFIX + 'bulk_modulus', default=None,
                       metavar='K', help='user liquid bulk modulus (default MPa)')


def take_motor_options(args: dict[str, Any]) -> dict[str, Any]:
    """
    Replace the parsed motor options by one ``options`` :class:`MotorOptions` (SI).

    Parameters
    ----------
    args : dict
        Parsed arguments; left as they are when the subcommand has no motor options, [-]

    Returns
    -------
    dict
        The arguments for the command.

    Raises
    ------
    CliError
        If a quantity (user-liquid property, displacement) cannot be parsed or is not > 0,
        naming the option.

    """
    typed = {k[len(_PREFIX):]: args.pop(k) for k in list(args) if k.startswith(_PREFIX)}
    if not typed:
        return args
    for name, (kind, unit) in _QUANTITIES.items():
        text = typed.pop(name, None)
        if text is not None:
            typed[name] = quantity(MOTOR_FLAGS[name], text, kind, unit, positive=True)
    try:
        return {**args, 'options': MotorOptions(**typed)}
    except OptionError as err:
        raise CliError(f'{MOTOR_FLAGS[err.option]} {err.value!r}: {err.reason}') from None


def quantity(flag: str, text: str, kind: str, default_unit: str, *,
             positive: bool = False, signed: bool = False) -> float:
    """
    Parse a command-line quantity into SI, naming the flag on error.

    Returns the value in SI; raises a :class:`CliError` naming `flag` if `text` cannot be
    parsed or is negative (unless `signed`), NaN or infinite.

    Parameters
    ----------
    flag : str
        The option, e.g. ``'--flow'``, quoted in errors, [-]
    text : str
        What the user typed, e.g. ``'250bar'``, [-]
    kind : str
        Kind of quantity (see :mod:`satmotor_ros.model.units`), [-]
    default_unit : str
        Unit when `text` has none, [-]
    positive : bool
        Require a value > 0 rather than >= 0, [-]
    signed : bool
        Accept any finite value (a flow or drop of a four-quadrant point), [-]

    """
    try:
        value = parse_quantity(text, kind, default_unit)
    except UnitError as err:
        raise CliError(f'{flag} {text!r}: {err}') from None
    if not math.isfinite(value) or (not signed and value < 0.0) or (positive and value == 0.0):
        need = '' if signed else ' > 0' if positive else ' >= 0'
        raise CliError(f'{flag} {text!r}: must be a finite value{need}')
    return value


def fail(err: Exception | str) -> int:
    """
    Print one error line to stderr.

    Parameters
    ----------
    err : Exception or str
        The error (or its message) to report; an :class:`OptionError` names the
        ``satmotor`` option, [-]

    Returns
    -------
    int
        The exit code 1.

    """
    if isinstance(err, OptionError):
        err = CliError(f'{MOTOR_FLAGS[err.option]} {err.value!r}: {err.reason}')
    print(f'satmotor: error: {err}', file=sys.stderr)
    return 1
