# SPDX-License-Identifier: Apache-2.0
"""Options shared by the subcommands: which motor, which liquid, which Delta q law."""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys

from satmotor_ros.model import Liquid, load_motor, ModelError, MotorModel
from satmotor_ros.model.units import parse_quantity, UnitError


class CliError(Exception):
    """A user-facing error: printed as one line, exit code 1."""


def add_model_options(parser: argparse.ArgumentParser) -> None:
    """
    Add ``--liquid``, ``--motor``, ``--law`` and the liquid-property overrides.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The subcommand's parser, [-]

    """
    group = parser.add_argument_group('motor and liquid')
    group.add_argument('--liquid', default='oil',
                       help="coefficient set and its liquid: 'oil' or 'water' for the packaged "
                            'SM-0,75/25, or any set in --motor (default: oil)')
    group.add_argument('--motor', default=None, metavar='YAML',
                       help='motor specification file (default: the packaged SM-0,75/25)')
    group.add_argument('--law', choices=('eq33', 'eq39'), default='eq33',
                       help='change of displacement: physical eq. (33) or empirical eq. (39)')
    group.add_argument('--viscosity', default=None, metavar='NU',
                       help='run a user liquid on the set: kinematic viscosity (default cSt)')
    group.add_argument('--density', default=None, metavar='RHO',
                       help='user liquid density (default kg/m^3)')
    group.add_argument('--bulk-modulus', default=None, metavar='K',
                       help='user liquid bulk modulus (default MPa)')


def quantity(flag: str, text: str, kind: str, default_unit: str, *,
             positive: bool = False) -> float:
    """
    Parse a command-line quantity into SI, naming the flag on error.

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

    Returns
    -------
    float
        The value in SI.

    Raises
    ------
    CliError
        If `text` cannot be parsed or is negative, NaN or infinite.

    """
    try:
        value = parse_quantity(text, kind, default_unit)
    except UnitError as err:
        raise CliError(f'{flag} {text!r}: {err}') from None
    if not math.isfinite(value) or value < 0.0 or (positive and value == 0.0):
        need = '> 0' if positive else '>= 0'
        raise CliError(f'{flag} {text!r}: must be a finite value {need}')
    return value


def build_model(liquid: str, motor: str | None, law: str, viscosity: str | None,
                density: str | None, bulk_modulus: str | None) -> MotorModel:
    """
    Build the model the options describe.

    Parameters
    ----------
    liquid : str
        Name of the coefficient set, [-]
    motor : str or None
        Motor YAML path, [-]
    law : str
        ``'eq33'`` or ``'eq39'``, [-]
    viscosity, density, bulk_modulus : str or None
        Overrides of the set's liquid, as typed, [-]

    Returns
    -------
    MotorModel
        The model.

    Raises
    ------
    CliError
        If the motor file, the set or a liquid property is invalid.

    """
    try:
        spec = load_motor(motor)
        if liquid not in spec.sets:
            raise CliError(f'--liquid {liquid!r}: not a coefficient set of {spec.name} '
                           f'(has: {", ".join(spec.sets)})')
        base = spec.sets[liquid].liquid
        overrides = {}
        if viscosity is not None:
            overrides['kinematic_viscosity'] = quantity('--viscosity', viscosity, 'viscosity',
                                                        'cSt', positive=True)
        if density is not None:
            overrides['density'] = quantity('--density', density, 'density', 'kg/m^3',
                                            positive=True)
        if bulk_modulus is not None:
            overrides['bulk_modulus'] = quantity('--bulk-modulus', bulk_modulus, 'pressure',
                                                 'MPa', positive=True)
        user: Liquid | None = None
        if overrides:
            user = dataclasses.replace(base, name=f'user liquid on the {liquid} set',
                                       **overrides)
        return MotorModel.from_spec(spec, liquid, user, law)
    except ModelError as err:
        raise CliError(str(err)) from None


def fail(err: Exception) -> int:
    """
    Print one error line to stderr.

    Parameters
    ----------
    err : Exception
        The error to report, [-]

    Returns
    -------
    int
        The exit code 1.

    """
    print(f'satmotor: error: {err}', file=sys.stderr)
    return 1
