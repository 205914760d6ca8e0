# SPDX-License-Identifier: Apache-2.0
"""``satmotor characteristics``: the paper's Figs. 8-16 kind of curves as PNG plots and CSV."""

from __future__ import annotations

import argparse
import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from satmotor_ros.cli._common import add_motor_options, CliError, fail
from satmotor_ros.cli._output import add_out_dir, output_dir
from satmotor_ros.limits import CURVE_MAX_POINTS
from satmotor_ros.model import ModelError, MotorModel
from satmotor_ros.model.families import DEFAULT_FAMILY
from satmotor_ros.model.families.sliwinski2017.losses import (displacement_change,
                                                              displacement_change_empirical,
                                                              empirical_drop)
from satmotor_ros.model.units import CM3_PER_REV, LPM, MPA, RPM
from satmotor_ros.options import MotorOptions

FLOWS_LPM = (5.0, 10.0, 20.0, 40.0)
"""Constant flows of the paper's Figs. 8, 13 and 16, [l/min]."""

SPEEDS_RPM = (100.0, 500.0, 1000.0, 1500.0)
"""Constant speeds of the paper's Figs. 9-12, [rpm]."""


@dataclass(frozen=True)
class Figure:
    """One characteristic: its curves over dp_i and how to label them."""

    name: str
    title: str
    ylabel: str
    parameter: str  # column header of the curve parameter, with unit
    values: tuple[float, ...]  # curve parameter values
    columns: dict[str, np.ndarray]  # header with unit -> array (curves x points)
    plotted: tuple[str, ...]  # which columns are drawn; line styles in order


DESCRIPTION = ("Characteristics of the paper's Figs. 8-16 kind over the chamber pressure drop: "
               'losses at constant flow and at constant speed, change of displacement, speed '
               'loss, and water against oil.')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``satmotor characteristics``."""
    add_out_dir(parser)
    parser.add_argument('--points', type=int, default=60,
                        help='points per curve (default 60; at most 100000, '
                             'SATMOTOR_CURVE_MAX_POINTS)')
    add_motor_options(parser)


def command(out: str, points: int, options: MotorOptions, force: bool = False) -> int:
    """
    Write the characteristics of one liquid, plus water against oil.

    Parameters
    ----------
    out : str
        Output directory (created), [-]
    points : int
        Points per curve, [-]
    options : MotorOptions
        Motor, liquid and Delta q law, [-]
    force : bool
        Replace an existing ``--out`` that characteristics did not write, [-]

    Returns
    -------
    int
        0 once every figure is written (PNG and CSV), 1 on an error (one line on stderr).

    """
    try:
        if points < 2:
            raise CliError(f'--points {points}: need at least 2')
        if points > CURVE_MAX_POINTS:
            raise CliError(f'--points {points}: more than {CURVE_MAX_POINTS} points per curve '
                           '(the cap SATMOTOR_CURVE_MAX_POINTS)')
        model = options.build_model()
        dp_i = np.linspace(0.5 * MPA, model.valid_range.dp_max, points)
        figures = [*constant_flow(model, dp_i), constant_speed(model, dp_i)]
        if model.family.name == DEFAULT_FAMILY:  # eqs. (33) and (39) are that family's
            figures.append(displacement(model, dp_i))
        others = {name: MotorOptions(name, options.motor_file, options.displacement_law,
                                     family=options.family,
                                     displacement=options.displacement).build_model()
                  for name in ('oil', 'water')} if _has_both(options) else None
        if others is not None:
            figures.append(water_against_oil(others['water'], others['oil'], dp_i))
        label = f'{model.name}, {model.liquid.name}, {model.displacement_law}'
        inputs = [options.motor_file] if options.motor_file else []
        with output_dir('--out', out, 'characteristics', inputs, force) as directory:
            for figure in figures:
                _write_csv(directory / f'{figure.name}.csv', figure, dp_i)
                _plot(directory / f'{figure.name}.png', figure, dp_i, label)
    except (CliError, ModelError) as err:
        return fail(err)
    except OSError as err:
        return fail(CliError(f'--out {out!r}: {err.strerror}'))
    for figure in figures:
        print(Path(out) / f'{figure.name}.png')
    return 0


def _has_both(options: MotorOptions) -> bool:
    return {'oil', 'water'} <= set(options.spec().sets)


def constant_flow(model: MotorModel, dp_i: np.ndarray) -> tuple[Figure, Figure]:
    """Compute Q_vl (Fig. 8 kind) and n_i (eq. 41) over `dp_i` [Pa] at each of FLOWS_LPM."""
    op = model.speed(np.array(FLOWS_LPM)[:, None] * LPM, dp_i=dp_i[None, :], errors='mask')
    speed = op.speed / RPM
    return (Figure('constant_flow', 'Volumetric losses at constant flow (Fig. 8 kind)',
                   'Q_vl [l/min]', 'Q [l/min]', FLOWS_LPM,
                   {'Q_vl [l/min]': op.losses.total / LPM, 'n [rpm]': speed},
                   ('Q_vl [l/min]',)),
            Figure('speed_loss', 'Speed loss at constant flow, eq. (41)', 'n_i [rpm]',
                   'Q [l/min]', FLOWS_LPM,
                   {'n_i [rpm]': op.speed_loss / RPM, 'n [rpm]': speed}, ('n_i [rpm]',)))


def constant_speed(model: MotorModel, dp_i: np.ndarray) -> Figure:
    """Compute Q_vl and its parts over `dp_i` [Pa] at each of SPEEDS_RPM (Figs. 9-10 kind)."""
    op = model.absorbency(np.array(SPEEDS_RPM)[:, None] * RPM, dp_i=dp_i[None, :],
                          errors='mask')
    losses = op.losses
    leak = losses.flat_clearance + losses.commutation
    return Figure('constant_speed', 'Volumetric losses at constant speed (Figs. 9-10 kind)',
                  'flow [l/min]', 'n [rpm]', SPEEDS_RPM,
                  {'Q_vl [l/min]': losses.total / LPM,
                   'Q_Lfg+Q_C [l/min]': leak / LPM,
                   'dQ_vl [l/min]': (losses.total - leak - losses.external) / LPM,
                   'Q [l/min]': op.flow / LPM},
                  ('Q_vl [l/min]', 'Q_Lfg+Q_C [l/min]', 'dQ_vl [l/min]'))


def displacement(model: MotorModel, dp_i: np.ndarray) -> Figure:
    """Compute dq of eqs. (33) and (39) over `dp_i` [Pa] at each of SPEEDS_RPM (Figs. 11-12)."""
    n = np.array(SPEEDS_RPM)[:, None] * RPM
    to_cm3 = 1.0 / CM3_PER_REV
    d = model.derived
    dq33 = displacement_change(dp_i[None, :], n, d.k_p, d.k_i)
    dq39 = displacement_change_empirical(empirical_drop(dp_i[None, :]), n,
                                         d.c1_39, d.c2_39)
    return Figure('displacement_change', 'Change of displacement (Figs. 11-12 kind)',
                  'dq [cm^3/rev]', 'n [rpm]', SPEEDS_RPM,
                  {'dq eq.33 [cm^3/rev]': dq33 * to_cm3, 'dq eq.39 [cm^3/rev]': dq39 * to_cm3},
                  ('dq eq.33 [cm^3/rev]', 'dq eq.39 [cm^3/rev]'))


def water_against_oil(water: MotorModel, oil: MotorModel, dp_i: np.ndarray) -> Figure:
    """
    Compare water with oil at constant flow (Figs. 13 and 16 kind).

    Parameters
    ----------
    water, oil : MotorModel
        The two models, [-]
    dp_i : ndarray
        Chamber pressure drops, [Pa]

    Returns
    -------
    Figure
        Ratios of losses and of speeds, one curve per flow of :data:`FLOWS_LPM`.

    """
    q = np.array(FLOWS_LPM)[:, None] * LPM
    w = water.speed(q, dp_i=dp_i[None, :], errors='mask')
    o = oil.speed(q, dp_i=dp_i[None, :], errors='mask')
    return Figure('water_oil_ratio', 'Water against oil at constant flow (Figs. 13, 16 kind)',
                  'ratio [-]', 'Q [l/min]', FLOWS_LPM,
                  {'Q_vl_w/Q_vl_o [-]': w.losses.total / o.losses.total,
                   'n_w/n_o [-]': w.speed / o.speed},
                  ('Q_vl_w/Q_vl_o [-]', 'n_w/n_o [-]'))


def _write_csv(path: Path, figure: Figure, dp_i: np.ndarray) -> None:
    headers = list(figure.columns)
    with path.open('w', newline='', encoding='utf-8') as stream:
        writer = csv.writer(stream)
        writer.writerow([figure.parameter, 'dp_i [MPa]', *headers])
        for k, value in enumerate(figure.values):
            for j, p in enumerate(dp_i):
                writer.writerow([f'{value:g}', f'{p / MPA:.6g}',
                                 *(f'{figure.columns[h][k, j]:.8g}' for h in headers)])


def _plot(path: Path, figure: Figure, dp_i: np.ndarray, label: str) -> None:
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot

    fig, ax = pyplot.subplots(figsize=(7.0, 4.8), dpi=110)
    styles = ('-', '--', ':', '-.')
    colors = pyplot.rcParams['axes.prop_cycle'].by_key()['color']
    for k, value in enumerate(figure.values):
        for style, column in zip(styles, figure.plotted):
            symbol, unit = figure.parameter.rstrip(']').split(' [')
            ax.plot(dp_i / MPA, figure.columns[column][k], style, color=colors[k % len(colors)],
                    label=f'{column.split(" [")[0]}, {symbol} = {value:g} {unit}')
    ax.set_xlabel('pressure drop in the chambers dp_i [MPa]')
    ax.set_ylabel(figure.ylabel)
    ax.set_title(f'{figure.title}\n{label}', fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2 if len(figure.plotted) > 1 else 1)
    fig.tight_layout()
    fig.savefig(path)
    pyplot.close(fig)
