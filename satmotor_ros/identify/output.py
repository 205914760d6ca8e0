# SPDX-License-Identifier: Apache-2.0
"""
Calibration files: ``calibration.json`` and ``coefficients.yaml``.

``coefficients.yaml`` has the layout of ``config/sm075_25.yaml`` (it loads with
:func:`satmotor_ros.model.load_motor`) and holds one coefficient set, named
after the liquid, with the fitted coefficients and, when an effect was
found, an ``effects:`` block that describes it as data::

    effects:
      <effect id>:
        regressor: <channel or expression>
        coefficient: <value>        # SI, in `unit`
        unit: <unit>
        ci95: [<low>, <high>]
        ...                         # what the effect needs to be evaluated

Plain numbers are SI (temperature in degC).
"""

from __future__ import annotations

from dataclasses import fields, replace
import json
from pathlib import Path
from typing import Any

import numpy as np
from satmotor_ros.identify.pipeline import Calibration
from satmotor_ros.model import LossCoefficients
from satmotor_ros.model.effects import effect_to_mapping, kind_of
import yaml


def write_json(cal: Calibration, path: str | Path) -> dict[str, Any]:
    """
    Write ``calibration.json`` (DESIGN.md, "Calibration output").

    Parameters
    ----------
    cal : Calibration
        The result; its ``summary()`` is what is written, [-]
    path : str or pathlib.Path
        File to write, [-]

    Returns
    -------
    dict
        The object written.

    """
    summary = cal.summary()
    Path(path).write_text(json.dumps(summary, indent=2) + '\n', encoding='utf-8')
    return summary


def fitted_coefficients(cal: Calibration) -> LossCoefficients:
    """
    Apply the fitted factors (and what the effects set, e.g. k_ex) to the packaged coefficients.

    Parameters
    ----------
    cal : Calibration
        Its final fit holds s_L, s_C and s_id first, then the effects, [-]

    Returns
    -------
    LossCoefficients
        a1 and c1 times s_L, c times s_C, c_id times s_id, and each effect's
        numbers (:meth:`~satmotor_ros.model.effects.EffectKind.coefficients`).

    """
    coef = cal.model.coef
    s_l, s_c, s_id = (float(v) for v in cal.final.values[:3])
    coef = replace(coef, a1=coef.a1 * s_l, c1=coef.c1 * s_l, c=coef.c * s_c,
                   c_id=coef.c_id * s_id)
    for effect in cal.effects():
        coef = kind_of(effect).coefficients(effect, coef)
    return coef


def effect_block(cal: Calibration) -> dict[str, Any]:
    """
    Describe the effects found as data for the ``effects:`` block, in the order found.

    Parameters
    ----------
    cal : Calibration
        The result; nothing to describe when it found no effect, [-]

    Returns
    -------
    dict
        ``{effect id: {...}}``; empty when no effect was found.

    """
    block = {}
    for effect, row, score in zip(cal.effects(), cal.effect_rows(), cal.found):
        entry = effect_to_mapping(effect)
        entry.update(unit=row['unit'], ci95=row['ci95'], source=score.added.source)
        entry['evaluation'] = entry.pop('evaluation')
        block[effect.name] = entry
    return block


def _document(cal: Calibration) -> dict[str, Any]:
    """Build the ``coefficients.yaml`` motor document: one coefficient set, plain SI numbers."""
    spec = cal.spec
    coef = fitted_coefficients(cal)
    liquid = cal.model.liquid
    entry: dict[str, Any] = {
        'liquid': {'name': liquid.name,
                   'kinematic_viscosity': liquid.kinematic_viscosity,
                   'density': liquid.density, 'bulk_modulus': liquid.bulk_modulus},
        'coefficients': {f.name: float(getattr(coef, f.name)) for f in fields(coef)},
    }
    span = _viscosity_span(cal)
    if span is not None:
        entry['viscosity_range'] = span
    effects = effect_block(cal)
    if effects:
        entry['effects'] = effects
    g = spec.geometry
    return {
        'motor': f'{spec.name} (calibrated)',
        'geometry': {f.name: float(getattr(g, f.name)) for f in fields(g)},
        'valid_range': {f.name: float(getattr(spec.valid_range, f.name))
                        for f in fields(spec.valid_range)},
        'coefficient_sets': {cal.liquid: entry},
    }


def _viscosity_span(cal: Calibration) -> list[float] | None:
    """Return the viscosity span the fit covers: the law over the data's temperatures."""
    packaged = cal.model.coefficient_set.viscosity_range
    slope = [e.coefficient for e in cal.effects() if e.kind == 'viscosity_temperature']
    if not slope:
        return None if packaged is None else [float(v) for v in packaged]
    temperature = cal.table.channels['temperature']
    law = cal.law
    nu = law.viscosity(np.array([np.min(temperature), np.max(temperature)]), slope[0])
    low, high = sorted(float(v) for v in nu)
    return [min(low, law.reference_viscosity), max(high, law.reference_viscosity)]


def write_yaml(cal: Calibration, path: str | Path) -> None:
    """
    Write ``coefficients.yaml``.

    Parameters
    ----------
    cal : Calibration
        The result, [-]
    path : str or pathlib.Path
        File to write, [-]

    """
    s_l, s_c, s_id = cal.final.values[:3]
    head = (f'# {cal.spec.name} calibrated on {cal.table.source} ({len(cal.parts)} points), '
            f'liquid {cal.liquid}.\n'
            f'# Fitted factors on the packaged values: leakage (a1, c1) x{s_l:.4g}, '
            f'c x{s_c:.4g}, c_id x{s_id:.4g}.\n'
            "# Plain numbers are SI (temperature degC); loss coefficients in the paper's "
            'fitting units.\n')
    body = yaml.safe_dump(_document(cal), sort_keys=False, allow_unicode=True,
                          width=99)
    Path(path).write_text(head + body, encoding='utf-8')
