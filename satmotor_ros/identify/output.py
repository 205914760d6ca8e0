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
        fitted_range:               # the data it was fitted on, per quantity it reads
          <quantity>: [<min>, <max>]
        ci95: [<low>, <high>]
        ...                         # what the effect needs to be evaluated

Plain numbers are SI (temperature in degC). Where the model evaluates an
effect outside its ``fitted_range`` (by more than 5 % of the span) the point
is flagged EXTRAPOLATED (doc/effects.md).
"""

from __future__ import annotations

from dataclasses import fields
import json
from pathlib import Path
from typing import Any

import numpy as np
from satmotor_ros.identify.pipeline import Calibration
from satmotor_ros.identify.plot_tools import portable
from satmotor_ros.model.effects import effect_to_mapping, kind_of
from satmotor_ros.model.families.defaults import DEFAULTS_NOTE
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


def fitted_coefficients(cal: Calibration) -> Any:
    """
    Apply the fitted factors (and what the effects set, e.g. k_ex) to the packaged coefficients.

    Parameters
    ----------
    cal : Calibration
        Its final fit holds one factor per component first, then the effects, [-]

    Returns
    -------
    dataclass
        The family's coefficients, each linear part's times its factor (for eqs. (31)-(33):
        a1 and c1 times s_L, c times s_C, c_id times s_id), and each effect's numbers
        (:meth:`~satmotor_ros.model.effects.EffectKind.coefficients`).

    """
    components = cal.parts.components
    factors = {c.part: float(v) for c, v in zip(components, cal.final.values[:len(components)])}
    coef = cal.model.family.scaled(cal.model.coef, factors)
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
        block[effect.key] = entry
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
        'motor': f'{spec.name.removesuffix(DEFAULTS_NOTE)} (calibrated)',
        'family': cal.model.family.name,
        'geometry': {f.name: float(getattr(g, f.name)) for f in fields(g)},
        'valid_range': {f.name: float(getattr(spec.valid_range, f.name))
                        for f in fields(spec.valid_range)},
        'coefficient_sets': {cal.liquid: entry},
        # where the fit's data lie; `satmotor validate` counts the samples outside it
        'coverage': cal.coverage,
        **_dynamics(cal),
        **_delay(cal),
    }


def _delay(cal: Calibration) -> dict[str, Any]:
    """
    Return the delay of the speed reading behind the flow reading, [s], on a time series.

    Same rig, same sensors: `satmotor validate` reads the speed that much later, as the
    calibration did (:func:`~satmotor_ros.identify.delay.shifted`).
    """
    if cal.delay is None:
        return {}
    return {'speed_delay': {'seconds': cal.delay.as_dict()['seconds'],
                            'fitted': cal.delay.fitted}}


def _dynamics(cal: Calibration) -> dict[str, Any]:
    """
    Return the fitted transient terms (name -> SI coefficient) when the rows were samples.

    `satmotor validate` applies them unchanged, so its error on a time series stays out of
    sample; a term the calibration left out is not written (it is zero in the fit).
    """
    terms = cal.mode_fields().get('dynamics', [])
    fitted = {d['term']: float(d['coefficient']) for d in terms if 'coefficient' in d}
    return {'dynamics': fitted} if terms else {}


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
    factors = ', '.join(f'{c.part} ({c.describes}) x{v:.4g}' for c, v in
                        zip(cal.parts.components, cal.final.values))
    head = (f'# {cal.spec.name} calibrated on {portable(cal.table.source)} '
            f'({len(cal.parts)} points), liquid {cal.liquid}.\n'
            f'# Fitted factors on the packaged values: {factors}.\n'
            "# Plain numbers are SI (temperature degC); loss coefficients in the paper's "
            'fitting units.\n')
    if cal.found:
        head += ('# fitted_range: least and largest value of each quantity an effect reads '
                 'over the points it was\n# fitted on (dp_i, speed, flow as magnitudes); '
                 'outside it the model flags EXTRAPOLATED.\n')
    doc = _document(cal)
    if 'dynamics' in doc:
        head += ('# dynamics: the transient terms fitted beside the model (the bench, not the '
                 'motor; SI,\n# doc/calibration.md); `satmotor validate` applies them '
                 'unchanged.\n')
    if 'speed_delay' in doc:
        head += ("# speed_delay: seconds the speed reading lags the flow reading (the bench's "
                 'sensors, eq. D1 of\n# satmotor_ros.identify.delay; 0 when kept); '
                 '`satmotor validate` reads the speed that much later.\n')
    body = yaml.safe_dump(doc, sort_keys=False, allow_unicode=True,
                          width=99)
    Path(path).write_text(head + body, encoding='utf-8')
