# SPDX-License-Identifier: Apache-2.0
"""
``external_leakage``: Q_ex = k_ex p (eq. 24), p the gauge pressure of the case or the outlet.

A gauge pressure below atmosphere drives no leakage out of the motor: p is floored at 0, as
the nodes (``prediction``) and the plant read their pressures.

In a coefficient set the effect names the pressure that drives eq. (24); its
coefficient is ``coefficients.external_leakage``. The virtual motor takes the
same k_ex p from the inlet line to the tank (solved implicitly with the lines),
and the flowmeter sees it, as it sees the model's Q_ex.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.coefficients import LossCoefficients
from satmotor_ros.model.effects._base import (additive, Candidate, CandidateData, Conditions,
                                              Effect, EffectKind, maker, PlantInjection,
                                              PlantParameter, varies, why_not)
from satmotor_ros.model.errors import ConfigError


_DRIVERS = {'case': 'p_case', 'outlet': 'p_out'}

OUTFLOW = {False: 'p_out', True: 'p_in'}
"""The channel of the port the flow leaves by (B, or A while it runs backwards), gauge Pa: the
``p_out`` regressor names the outflow port, which is port B only while the flow is positive."""


def outflow(data: CandidateData) -> FloatArray | None:
    """Return the outflow port's gauge pressure at the points: p_out, p_in where n < 0."""
    p_out, p_in = data.channels.get('p_out'), data.channels.get('p_in')
    backwards = np.asarray(getattr(data.parts, 'rotation', 1.0)) < 0.0
    if p_out is None or not np.any(backwards):
        return p_out
    if p_in is None:
        return None
    return np.where(backwards, p_in, p_out)


class ExternalLeakage(EffectKind):
    """Q_ex = k_ex p, eq. (24), p the gauge case or outlet pressure."""

    name = 'external_leakage'
    rank = 40
    regressors = ('p_case', 'p_out')
    reads_channel = True
    drives_leakage = True
    unit = 'm^3/(s*Pa)'
    source = 'eq. (24), lumped'
    evaluation = ('Q_ex = k_ex * p (eq. 24) with p the gauge pressure named by regressor; '
                  'k_ex is also coefficients.external_leakage')
    plant_parameters = (
        PlantParameter('external_leakage', 0.0, 'k_ex, leakage to the tank per driving pressure '
                       '(eq. 24)', 'm^3/(s*Pa)', 0.0, 1.0e-8),
        PlantParameter('leakage_driver', 'case', "pressure that drives k_ex: 'case' or 'outlet'",
                       choices=tuple(_DRIVERS)),
    )

    def coefficients(self, effect: Effect, coef: LossCoefficients) -> LossCoefficients:
        """Return `coef` with eq. (24)'s k_ex set to the effect's coefficient."""
        return replace(coef, external_leakage=effect.coefficient)

    def channels(self, effect: Effect) -> tuple[str, ...]:
        """Read the case pressure, or both ports: the flow leaves by B, or by A in reverse."""
        return ('p_in', 'p_out') if effect.regressor == 'p_out' else (effect.regressor,)

    def channel_at(self, effect: Effect, reverse: bool) -> str:
        """Read the port the flow leaves by: ``p_out`` (B), ``p_in`` (A) while it runs back."""
        return OUTFLOW[reverse] if effect.regressor == 'p_out' else effect.regressor

    def condition(self, effect: Effect, x: float, now: Conditions) -> Conditions:
        """Drive eq. (24) by the channel's gauge pressure `x` [Pa], floored at 0."""
        return now._replace(p_ex=max(x, 0.0))  # below atmosphere nothing leaks out (NaN kept)

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer k_ex >= 0 for each driving pressure that was measured and varies."""
        out, skipped = [], []
        for name in self.regressors:
            p = data.channels.get(name) if name != 'p_out' else outflow(data)
            if p is not None:
                p = np.maximum(p, 0.0)  # as the model: no leak out below atmosphere
            if p is None or not varies(p):
                skipped.append(f'{self.name}({name}): {why_not(p)}')
                continue
            out.append(additive(self.name, name, self.unit, self.source, p, (0.0, np.inf),
                                make=maker(self.name, name)))
        return out, skipped

    def inject(self, effect: Effect, into: PlantInjection) -> PlantInjection:
        """Let k_ex p leave the plant's inlet line for the tank."""
        return into.add('bypass', (effect.regressor, effect.coefficient))

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Return the leakage the node parameters set, None at k = 0."""
        driver = values['leakage_driver']
        if driver not in _DRIVERS:
            msg = f"effects.leakage_driver = {driver!r}: use 'case' or 'outlet'"
            raise ConfigError(msg)
        k = values['external_leakage']
        return Effect(self.name, k, _DRIVERS[driver]) if k else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return k and the driver of `effect`."""
        if effect is None:
            return super().plant_values(None)
        driver = next(d for d, r in _DRIVERS.items() if r == effect.regressor)
        return {'external_leakage': effect.coefficient, 'leakage_driver': driver}


KIND = ExternalLeakage()
