# SPDX-License-Identifier: Apache-2.0
r"""
The health of one recording against its motor's baseline: the one step a fleet run plugs in.

:func:`recording_health` is everything the fleet knows of health. The recording's leakage
factor (DESIGN.md ``health/leakage_factor``) is the least-squares ratio, through the origin,
of the measured volumetric losses to the baseline model's over every usable point of the
recording (the points ``satmotor validate`` uses), eq. (1) below, with its 95 % interval from
the scatter about that ratio: one figure per recording, whatever its layout (steady points or
a time series). The points of a recording are not independent (a bench sweep's residuals
about the ratio run in long same-signed stretches where the model misses a little), so the
interval counts them as the effective number the residuals' own autocorrelation leaves
(:func:`~satmotor_ros.identify.transient.variance_inflation`, in row order), eq. (2):

.. math:: k = \frac{\sum_i m_i p_i}{\sum_i p_i^2} \quad (1) \qquad
          k \pm t_{0.975,\,n_e-1}\sqrt{\frac{\phi\,s^2}{\sum_i p_i^2}},\;
          n_e = n/\phi \quad (2)

with :math:`s^2` the residuals' variance and :math:`\phi \ge 1` the inflation (1 below 20
points, too few to see a correlation in). The motor's one ``satmotor monitor`` estimator runs
over its time series in time order apart (:mod:`satmotor_ros.fleet.chain`); where it ran,
its figures are the fleet's.
"""

from __future__ import annotations

from dataclasses import dataclass
import json
from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.cli._output import output_dir
from satmotor_ros.identify import BenchTable
from satmotor_ros.identify.validate import validate
from satmotor_ros.options import MotorOptions

ESTIMATOR = 'ratio-v2+monitor-chain-v1'
"""Names the estimator in each done-marker: a new one redoes every recording."""

RATIO = 'ratio-v2 (interval widened for correlated residuals)'
"""Names the per-recording ratio estimator in fleet.json and fleet.md."""

HEALTH_DIR = 'health'
"""The health step's directory under ``DIR/<motor>/<recording>/``."""


@dataclass(frozen=True)
class Health:
    """What the fleet keeps of one recording's health."""

    leakage_factor: float  # measured Q_vl over the baseline's [-]
    ci95: tuple[float, float]  # its 95 % interval [-]
    n_samples: int  # points or samples the figure is over [-]
    inflation: float = 1.0  # variance inflation of the correlated residuals, >= 1 [-]

    @property
    def n_effective(self) -> float:
        """Return the number of independent points the interval counts, [-]."""
        return self.n_samples / self.inflation

    def as_dict(self) -> dict[str, Any]:
        """Return the JSON form kept in the done-marker."""
        return {'leakage_factor': self.leakage_factor, 'ci95': list(self.ci95),
                'n_samples': self.n_samples, 'inflation': self.inflation,
                'n_effective': self.n_effective, 'estimator': RATIO}


def ratio_health(measured: np.ndarray, predicted: np.ndarray) -> Health:
    """
    Return the ratio of measured to predicted losses and its interval, eqs. (1)-(2).

    Parameters
    ----------
    measured : ndarray
        Measured volumetric losses in time (row) order, [m^3/s]
    predicted : ndarray
        The baseline's at the same points, [m^3/s]

    Returns
    -------
    Health
        The ratio, its 95 % interval widened for the residuals' correlation, the points
        and the inflation.

    """
    from scipy.stats import t as student
    from satmotor_ros.identify.transient import variance_inflation
    scale = float(predicted @ predicted)
    ratio = float(measured @ predicted) / scale
    n = int(measured.size)
    residual = measured - ratio * predicted
    scatter = float(np.sum(residual ** 2)) / max(n - 1, 1)
    inflation = max(float(variance_inflation(residual)), 1.0)
    dof = max(n / inflation - 1.0, 1.0)
    half = float(student.ppf(0.975, dof)) * (inflation * scatter / scale) ** 0.5
    return Health(ratio, (ratio - half, ratio + half), n, inflation)


def recording_health(data: str, table: BenchTable, baseline: MotorOptions, out: Path) -> Health:
    """
    Estimate a recording's health against the baseline and write its output.

    Parameters
    ----------
    data : str
        The recording, as named in the output, [-]
    table : BenchTable
        Its data, already loaded and screened, [-]
    baseline : MotorOptions
        The motor's baseline (its calibrated coefficients.yaml, or the motor file given), [-]
    out : pathlib.Path
        The recording's output directory; the health output goes to ``out/health``, [-]

    Returns
    -------
    Health
        The leakage factor and its interval.

    Raises
    ------
    IdentificationError
        If no point of the recording is usable against the baseline.

    """
    model = baseline.build_model()
    result = validate(table, model, baseline.liquid)
    measured = result.parts.flow - result.parts.displacement
    predicted = measured - result.residual
    health = ratio_health(measured, predicted)
    with output_dir('--out', out / HEALTH_DIR, 'fleet-health') as tmp:
        summary = {'data': data, 'baseline': baseline.motor_file, 'liquid': baseline.liquid,
                   'estimator': ESTIMATOR, **health.as_dict(),
                   'error_vs_baseline': result.error.as_dict()}
        (tmp / 'health.json').write_text(json.dumps(summary, indent=1) + '\n',
                                         encoding='utf-8')
    return health


__all__ = ['ESTIMATOR', 'HEALTH_DIR', 'Health', 'RATIO', 'ratio_health', 'recording_health']
