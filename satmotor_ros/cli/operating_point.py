# SPDX-License-Identifier: Apache-2.0
"""``satmotor operating-point``: speed, speed loss and loss breakdown at one flow and pressure."""

from __future__ import annotations

import argparse
from dataclasses import replace
import json
import math
from typing import Any, TypedDict

from satmotor_ros.cli._common import add_motor_options, CliError, fail, quantity
from satmotor_ros.model import (COMPONENTS, describe_status, ModelError, MotorModel,
                                OperatingPoints, PointStatus)
from satmotor_ros.model.errors import UnitError
from satmotor_ros.model.families import DEFAULT_FAMILY, FAMILIES
from satmotor_ros.model.units import channel_gauge, LPM, MPA, parse_quantity, RPM
from satmotor_ros.options import MotorOptions

ABSOLUTE_UNITS = ('bara', 'psia')
"""Pressure units that say absolute; a channel's pressure is gauge, one atmosphere less."""

CHANNEL_KINDS = {'p_case': ('pressure', 'MPa'), 'p_out': ('pressure', 'MPa'),
                 'p_in': ('pressure', 'MPa'), 'temperature': ('temperature', 'degC'),
                 'time': ('time', 's')}
"""Kind and default unit of each channel with a unit; any other channel (revolutions, a
``channel:<name>`` effect's) is a plain number in the unit it was calibrated in."""


class PointReport(TypedDict):
    """The operating point as ``--json`` prints it, in hydraulic units."""

    motor: str
    family: str
    coefficients: str
    liquid: str
    displacement_law: str
    flow_lpm: float
    dp_MPa: float
    dp_i_MPa: float
    speed_rpm: float
    speed_rad_s: float
    speed_loss_rpm: float
    losses_lpm: dict[str, float]
    effects: list[str]
    effects_lpm: float
    channels: dict[str, float]
    status: str
    warnings: list[str]


DESCRIPTION = ('Effective speed (eq. 40), speed loss (eq. 41) and the volumetric-loss breakdown '
               '(eq. 31, or the components of the chosen --family) at one operating point. '
               'Quantities take an optional unit: --flow '
               '8.3e-5m^3/s, --dp 250bar.')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor operating-point``."""
    parser.add_argument('--flow', required=True, help='flow into the motor (default l/min)')
    drop = parser.add_mutually_exclusive_group(required=True)
    drop.add_argument('--dp', help='pressure drop between the ports (default MPa); the '
                                   'internal-channel drop of eqs. (34)-(35) is subtracted')
    drop.add_argument('--dp-i', help='pressure drop in the working chambers (default MPa), '
                                     "as in the paper's figures")
    parser.add_argument('--p-ex', default='0', help='pressure driving the external leakage, '
                                                    'eq. (24) (default MPa; default 0)')
    parser.add_argument('--channel', action='append', default=[], dest='channels',
                        metavar='NAME=VALUE',
                        help="a channel a calibrated file's effects read, e.g. p_case=0.3MPa "
                             '(gauge pressure, default MPa; temperature degC; time s; '
                             'revolutions rev); repeatable')
    parser.add_argument('--json', action='store_true', dest='as_json',
                        help='print one JSON object')
    add_motor_options(parser)


def command(flow: str, dp: str | None, dp_i: str | None, p_ex: str, channels: list[str],
            as_json: bool, options: MotorOptions) -> int:
    """
    Print the operating point.

    Parameters
    ----------
    flow : str
        Flow as typed, [l/min by default]
    dp, dp_i : str or None
        Port or chamber pressure drop as typed (exactly one), [MPa by default]
    p_ex : str
        Pressure driving the external leakage as typed, [MPa by default]
    channels : list of str
        ``NAME=VALUE`` for each channel the motor file's effects read, as typed, [-]
    as_json : bool
        Print JSON instead of a table, [-]
    options : MotorOptions
        Motor, liquid and Delta q law, [-]

    Returns
    -------
    int
        0 once the point is printed, flagged or not; 1 on an error (one line on stderr).

    """
    try:
        model = options.build_model()
        q = quantity('--flow', flow, 'flow', 'l/min', signed=True)
        pex = quantity('--p-ex', p_ex, 'pressure', 'MPa')
        given = read_channels(channels, model.channels)
        if dp is not None:
            op = model.speed(q, quantity('--dp', dp, 'pressure', 'MPa', signed=True), p_ex=pex,
                             channels=given or None)
        elif dp_i is not None:
            op = model.speed(q, dp_i=quantity('--dp-i', dp_i, 'pressure', 'MPa', signed=True),
                             p_ex=pex, channels=given or None)
        else:
            raise CliError('give --dp or --dp-i')
    except (CliError, ModelError) as err:
        return fail(err)
    result = _result(model, op, given, pex)
    print(json.dumps(_json_safe(result), indent=2, allow_nan=False) if as_json
          else _table(result))
    return 0


def read_channels(texts: list[str], needed: tuple[str, ...]) -> dict[str, float]:
    """
    Read ``--channel NAME=VALUE`` options: exactly the channels the model's effects read.

    Parameters
    ----------
    texts : list of str
        Each option as typed, e.g. ``'p_case=0.3MPa'``, [-]
    needed : tuple of str
        The channels the model reads (``MotorModel.channels``), [-]

    Returns
    -------
    dict of str to float
        Each channel in the model's units: gauge pressure [Pa] (an absolute unit, ``bara``
        or ``psia``, less one atmosphere), temperature [degC], time [s], others as given.

    Raises
    ------
    CliError
        One line naming the option: malformed, repeated, not read by the model, missing.

    """
    values: dict[str, float] = {}
    for text in texts:
        name, sep, value = (part.strip() for part in text.partition('='))
        if not sep or not name or not value:
            raise CliError(f'--channel {text!r}: use NAME=VALUE, e.g. p_case=0.3MPa')
        if name not in needed:
            reads = ', '.join(needed) or 'no channel'
            raise CliError(f"--channel {text!r}: the motor file's effects read {reads}, "
                           f'not {name!r}')
        if name in values:
            raise CliError(f'--channel {text!r}: {name} is given twice')
        values[name] = _channel_value(text, name, value)
    missing = [name for name in needed if name not in values]
    if missing:
        raise CliError(f"--channel: the motor file's effects read {', '.join(missing)}; "
                       f'give --channel {missing[0]}=VALUE')
    return values


def _channel_value(text: str, name: str, value: str) -> float:
    kind = CHANNEL_KINDS.get(name)
    try:
        if kind is None:
            number = float(value)
        else:
            number = parse_quantity(value, *kind)
            if kind[0] == 'pressure' and number < 0.0:
                raise CliError(f'--channel {text!r}: a pressure must be >= 0')
            if kind[0] == 'pressure' and value.rstrip().endswith(ABSOLUTE_UNITS):
                number = channel_gauge(number)  # bara, psia: the effects read gauge
    except (UnitError, ValueError) as err:
        raise CliError(f'--channel {text!r}: {err}') from None
    if not math.isfinite(number):
        raise CliError(f'--channel {text!r}: must be a finite value')
    return number


def _json_safe(value: Any) -> Any:
    """Return `value` with NaN and inf as None: JSON has no such numbers (the status says why)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    return value


def _effects_share(model: MotorModel, op: OperatingPoints, total_lpm: float, p_ex: float) -> float:
    """Return how much of Q_vl the file's effects make: the total less the model's without."""
    if not model.effects:
        return 0.0
    plain = MotorModel(model.geometry, replace(model.coefficient_set, effects=()),
                       model.valid_range, model.liquid, model.displacement_law, model.name)
    base = plain.breakdown(float(op.speed), float(op.dp_i), p_ex, errors='mask')
    return total_lpm - float(base.total) / LPM


def _result(model: MotorModel, op: OperatingPoints, channels: dict[str, float],
            pex: float) -> PointReport:
    status = int(op.status)
    losses = {name: float(getattr(op.losses, name)) / LPM for name in COMPONENTS}
    return {
        'motor': model.name,
        'family': model.family.name,
        'coefficients': model.coefficient_set.name,
        'liquid': model.liquid.name,
        'displacement_law': model.displacement_law,
        'flow_lpm': float(op.flow) / LPM,
        'dp_MPa': float(op.dp) / MPA,
        'dp_i_MPa': float(op.dp_i) / MPA,
        'speed_rpm': float(op.speed) / RPM,
        'speed_rad_s': float(op.speed),
        'speed_loss_rpm': float(op.speed_loss) / RPM,
        'losses_lpm': losses,
        'effects': [effect.name for effect in model.effects],
        'effects_lpm': _effects_share(model, op, losses['total'], pex),
        'channels': channels,
        'status': describe_status(status),
        'warnings': _warnings(status),
    }


def _warnings(status: int) -> list[str]:
    notes = []
    if status & PointStatus.STALLED:
        notes.append('the leakage takes all the flow: the shaft does not turn (n = 0)')
    if status & PointStatus.CHANNEL_LIMITED:
        notes.append('the internal channels take the whole pressure drop: dp_i set to 0')
    if status & PointStatus.EXTRAPOLATED:
        notes.append('outside the range the coefficients were measured over (extrapolated)')
    return notes


def _table(r: PointReport) -> str:
    lines = [
        f'{r["motor"]} on {r["liquid"]} ({r["coefficients"]} coefficients), '
        + (f'displacement law {r["displacement_law"]}' if r['family'] == DEFAULT_FAMILY
           else f'{r["family"]} family'),
        f'  flow Q               {r["flow_lpm"]:10.3f} l/min',
        f'  dp between ports     {r["dp_MPa"]:10.3f} MPa',
        f'  dp_i in chambers     {r["dp_i_MPa"]:10.3f} MPa',
        f'  speed n              {r["speed_rpm"]:10.2f} rpm  ({r["speed_rad_s"]:.3f} rad/s)',
        f'  speed loss n_i       {r["speed_loss_rpm"]:10.2f} rpm  (eq. 41)',
        '  volumetric losses [l/min]',
    ]
    labels = FAMILIES[r['family']].components  # the components the family has
    rows = [(labels[name], value) for name, value in r['losses_lpm'].items() if name in labels]
    if r['effects']:
        rows.append((f'  of it from {", ".join(r["effects"])}', r['effects_lpm']))
    lines += [f'    {label:38s} {value:10.4f}' for label, value in rows]
    lines.append(f'  status: {r["status"]}')
    lines += [f'  warning: {note}' for note in r['warnings']]
    return '\n'.join(lines)
