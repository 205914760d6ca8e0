# SPDX-License-Identifier: Apache-2.0
"""
The model families on the paper's own characteristics: fit the defaults, draw doc/families.png.

``python doc/families.py`` prints the least-squares defaults of the ``balawender``
and ``paszota`` families (fitted to the paper's own model, ``sliwinski2017``, of
the SM-0,75/25 over its measured range: 2-25 MPa, 100-1500 rpm) and draws
``doc/families.png``: Q_vl against dp_i at n = 100 and 1500 rpm (Figs. 9-10 of
the paper) and the speed n against dp_i at Q = 5 and 40 l/min (Figs. 14-16), for
oil and water, for the three families as packaged.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
from satmotor_ros.model import MotorModel
from satmotor_ros.model.families import balawender_losses as bal
from satmotor_ros.model.families import FAMILY_NAMES
from satmotor_ros.model.families.paszota_losses import REFERENCE_VISCOSITY
from satmotor_ros.model.units import LPM, MPA, RPM
from scipy.optimize import nnls

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402, I100

SPEEDS = np.geomspace(100.0, 1500.0, 15) * RPM
DROPS = np.linspace(2.0, 25.0, 12) * MPA


def _grid(liquid: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, MotorModel]:
    """Return n, dp_i, Q_vl of the paper's own model on its measured range."""
    model = MotorModel.default(liquid)
    n, dp_i = (a.ravel() for a in np.meshgrid(SPEEDS, DROPS))
    return n, dp_i, model.breakdown(n, dp_i).total, model


def fit_balawender() -> dict[str, float]:
    """
    Fit C_vl, C_ol, C_ot (eqs. 17, 20, 21) to the oil and water models, C_ich (eq. 27) to oil.

    Water enters through the low-viscosity variant (eqs. 16, 18, 19, 22-23), which is
    linear in the same oil coefficients; B_h is eq. (2)'s relative clearance change.
    """
    oil = MotorModel.default('oil')
    d, q = oil.derived, oil.geometry.displacement
    mu_o, rho_o, k_o = oil.liquid.dynamic_viscosity, oil.liquid.density, oil.liquid.bulk_modulus
    b_h = -d.compliance / d.h0  # eq. (2): h/h0 = 1 - (compliance/h0) dp_i
    blocks = []
    for liquid in ('oil', 'water'):
        n, dp_i, target, model = _grid(liquid)
        k_s, k_c = 1.0, 1.0
        if liquid == 'water':
            k_s = bal.leakage_ratio(dp_i, mu_o, model.liquid.dynamic_viscosity)
            k_c = bal.compressibility_ratio(k_o, model.liquid.bulk_modulus)
        columns = np.column_stack([
            bal.pressure_speed_loss_low_viscosity(dp_i, n, q, 1.0, k_c),
            k_s * bal.laminar_leakage(dp_i, mu_o, q, 1.0, b_h),
            k_s * bal.turbulent_leakage(dp_i, rho_o, q, 1.0)])
        blocks.append(columns / target[:, None])  # relative error
    coef, _ = nnls(np.vstack(blocks), np.ones(sum(len(b) for b in blocks)))
    flow = np.linspace(5.0, 40.0, 36) * LPM
    drop = oil.equations.channel_drop(flow)
    unit = bal.channel_pressure_drop_oil(flow / q, rho_o, q, 1.0)
    c_ich = float(np.sum(unit / drop) / np.sum((unit / drop) ** 2))
    fitted = dict(zip(('c_vl', 'c_ol', 'c_ot'), map(float, coef)), b_h=b_h, c_ich=c_ich)
    print(f'balawender: {fitted}')
    for liquid, block in zip(('oil', 'water'), blocks):
        rel = block @ coef - 1.0
        print(f'  {liquid}: Q_vl error {100 * np.abs(rel).max():.0f} % at most, '
              f'rms {100 * np.sqrt(np.mean(rel ** 2)):.0f} %')
    return fitted


def fit_paszota() -> dict[str, float]:
    """Fit k_g, a_pv, a_nv, a_vv of eq. (29) to log Q_vl of the oil and water models."""
    p_n, n_t = 25.0 * MPA, 1500.0 * RPM
    rows, logs = [], []
    for liquid in ('oil', 'water'):
        n, dp_i, target, model = _grid(liquid)
        nu = model.liquid.kinematic_viscosity
        rows.append(np.column_stack([np.ones_like(n), np.log(dp_i / p_n), np.log(n / n_t),
                                     np.full_like(n, np.log(nu / REFERENCE_VISCOSITY))]))
        logs.append(np.log(target / (model.geometry.displacement * n_t)))
    a, y = np.vstack(rows), np.concatenate(logs)
    x = np.linalg.lstsq(a, y, rcond=None)[0]
    fitted = {'k_g': float(np.exp(x[0])), 'a_pv': float(x[1]), 'a_nv': float(x[2]),
              'a_vv': float(x[3])}
    rel = np.exp(a @ x - y) - 1.0
    print(f'paszota (oil and water): {fitted}; Q_vl error {100 * np.abs(rel).max():.0f} % '
          f'at most, rms {100 * np.sqrt(np.mean(rel ** 2)):.0f} %')
    return fitted


def draw(path: Path) -> None:
    """Draw the families on the paper's characteristics into `path`."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), constrained_layout=True)
    dp = np.linspace(0.5, 25.0, 60) * MPA
    styles = dict(zip(FAMILY_NAMES, ('-', '--', ':')))
    colours = {'oil': 'tab:brown', 'water': 'tab:blue'}
    for family in FAMILY_NAMES:
        for liquid in ('oil', 'water'):
            model = MotorModel.for_displacement(None, family, liquid)
            label = f'{family}, {liquid}'
            for ax, rpm in zip(axes[0], (100.0, 1500.0)):
                total = model.breakdown(np.full_like(dp, rpm * RPM), dp).total
                ax.plot(dp / MPA, total / LPM, styles[family], color=colours[liquid],
                        label=label)
                ax.set_title(f'Q_vl at n = {rpm:.0f} rpm (Figs. 9-10)')
            for ax, lpm in zip(axes[1], (5.0, 40.0)):
                points = model.speed(lpm * LPM, dp_i=dp, errors='mask')
                ax.plot(dp / MPA, points.speed / RPM, styles[family], color=colours[liquid],
                        label=label)
                ax.set_title(f'speed n at Q = {lpm:.0f} l/min (Figs. 14-16)')
    for ax in axes[0]:
        ax.set_ylabel('Q_vl [l/min]')
    for ax in axes[1]:
        ax.set_ylabel('n [rpm]')
    for ax in axes.ravel():
        ax.set_xlabel('dp_i [MPa]')
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.suptitle('SM-0,75/25: the three model families with their packaged defaults')
    fig.savefig(path, dpi=110)
    print(f'wrote {path}')


if __name__ == '__main__':
    fit_balawender()
    fit_paszota()
    draw(Path(__file__).with_name('families.png'))
