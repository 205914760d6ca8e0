# SPDX-License-Identifier: Apache-2.0
"""
The health of one recording against its motor's baseline: the one step a fleet run plugs in.

:func:`recording_health` is everything the fleet knows of health. The recording's leakage
factor (DESIGN.md ``health/leakage_factor``) is the least-squares ratio, through the origin,
of the measured volumetric losses to the baseline model's over every usable point of the
recording (the points ``satmotor validate`` uses), with its 95 % interval from the scatter
about that ratio: one figure per recording, whatever its layout (steady points or a time
series). The motor's one ``satmotor monitor`` estimator runs over its time series in
time order apart (:mod:`satmotor_ros.fleet.chain`); where it ran, its figures are the fleet's.
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

ESTIMATOR = 'ratio-v1+monitor-chain-v1'
"""Names the estimator in each done-marker: a new one redoes every recording."""

HEALTH_DIR = 'health'
"""The health step's directory under ``DIR/<motor>/<recording>/``."""


@dataclass(frozen=True)
class Health:
    """What the fleet keeps of one recording's health."""

    leakage_factor: float  # measured Q_vl over the baseline's [-]
    ci95: tuple[float, float]  # its 95 % interval [-]
    n_samples: int  # points or samples the figure is over [-]

    def as_dict(self) -> dict[str, Any]:
        """Return the JSON form kept in the done-marker."""
        return {'leakage_factor': self.leakage_factor, 'ci95': list(self.ci95),
                'n_samples': self.n_samples}


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
    scale = float(predicted @ predicted)
    ratio = float(measured @ predicted) / scale
    n = measured.size
    scatter = float(np.sum((measured - ratio * predicted) ** 2)) / max(n - 1, 1)
    from scipy.stats import t as student
    half = float(student.ppf(0.975, max(n - 1, 1))) * (scatter / scale) ** 0.5
    health = Health(ratio, (ratio - half, ratio + half), int(n))
    with output_dir('--out', out / HEALTH_DIR, 'fleet-health') as tmp:
        summary = {'data': data, 'baseline': baseline.motor_file, 'liquid': baseline.liquid,
                   'estimator': ESTIMATOR, **health.as_dict(),
                   'error_vs_baseline': result.error.as_dict()}
        (tmp / 'health.json').write_text(json.dumps(summary, indent=1) + '\n',
                                         encoding='utf-8')
    return health


__all__ = ['ESTIMATOR', 'HEALTH_DIR', 'Health', 'recording_health']
