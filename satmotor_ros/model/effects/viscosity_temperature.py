# SPDX-License-Identifier: Apache-2.0
"""
``viscosity_temperature``: nu(T) of a Walther or Vogel law replaces the liquid's viscosity.

The law is one of :data:`satmotor_ros.model.viscosity.LAWS`, evaluated in
eqs. (1), (5) and (35). In the plant the law is the liquid's standard one
(:func:`~satmotor_ros.model.viscosity.standard_law`), pinned at the liquid's
viscosity at ``thermal.reference``; the node parameter is its slope B.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from satmotor_ros.model.coefficients import LIQUID_RANGES
from satmotor_ros.model.effects._base import (Candidate, CandidateData, Conditions, Effect,
                                              EffectKind, finite, Modifier, PlantParameter,
                                              Synthetic)
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.viscosity import LAWS, ViscosityLaw

MIN_SPAN = 1.0
"""Temperature span the data must cover for the effect to be offered, [K]."""


_RANGES = {'reference_temperature': (-273.0, 1.0e4),
           'reference_viscosity': LIQUID_RANGES['kinematic_viscosity']}
"""The reference a law is pinned at: a temperature above absolute zero [degC] and a liquid's
viscosity [m^2/s]."""


def law_of(effect: Effect) -> ViscosityLaw:
    """Return the law an effect names, pinned at its reference."""
    return ViscosityLaw(effect.law, effect.reference_temperature, effect.reference_viscosity,
                        vogel_c=effect.vogel_c)


class ViscosityTemperature(EffectKind):
    """The liquid's viscosity follows its temperature."""

    name = 'viscosity_temperature'
    rank = 50
    keys = ('regressor', 'coefficient', 'law', 'reference_temperature', 'reference_viscosity',
            'vogel_c')
    required = ('coefficient', 'law', 'reference_temperature', 'reference_viscosity')
    regressors = ('temperature',)
    reads_channel = True
    drifts = True
    evaluation = ('nu(T) from the law (walther: log10(log10(nu_cSt + 0.7)) = '
                  'log10(log10(nu_ref_cSt + 0.7)) - B (log10 T_K - log10 T_ref_K); '
                  'vogel: nu = nu_ref 10^(B (1/(T_K - C) - 1/(T_ref_K - C)))) '
                  'replaces the liquid viscosity in eqs. (1), (5) and (35)')
    plant_parameters = (PlantParameter(
        'viscosity_temperature', 0.0, "slope B of the liquid's standard viscosity law "
        '(Walther for oil [-], Vogel for water [K]); 0: constant viscosity', '- or K',
        0.0, 2000.0),)

    def parse(self, name: str, doc: Mapping[str, Any], where: str) -> Effect:
        """Read the law and its reference as well."""
        law = str(doc.get('law', ''))
        if law not in LAWS:
            msg = f"{where}.law = {doc.get('law')!r}: use {' or '.join(map(repr, LAWS))}"
            raise ConfigError(msg)
        values: dict[str, Any] = {k: finite(doc[k], f'{where}.{k}') for k in self.keys
                                  if k in doc and k not in ('regressor', 'law')}
        for key, (low, high) in _RANGES.items():  # past them the law's logarithms fail
            if key in values and not low <= values[key] <= high:
                msg = f'{where}.{key} = {values[key]!r}: must be from {low:g} to {high:g}'
                raise ConfigError(msg)
        return Effect(name, regressor=self.regressor('', doc.get('regressor'), where), law=law,
                      **values)

    def to_mapping(self, effect: Effect) -> dict[str, Any]:
        """Write the law; ``vogel_c`` only for Vogel."""
        block = super().to_mapping(effect)
        if effect.law != 'vogel':
            del block['vogel_c']
        return block

    def condition(self, effect: Effect, x: float, now: Conditions) -> Conditions:
        """Take the law's viscosity at the temperature `x` [degC] (NaN past its pole)."""
        return now._replace(viscosity=float(law_of(effect).viscosity(x, effect.coefficient)))

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer the slope of the liquid's law, pinned at the set's viscosity."""
        temperature, law, parts = data.channels.get('temperature'), data.law, data.parts
        if (temperature is None or not np.all(np.isfinite(temperature))
                or np.ptp(temperature) < MIN_SPAN
                or not np.ptp(temperature) > 1e-3 * np.max(np.abs(temperature))):
            why = ('not measured' if temperature is None else 'has missing values'
                   if not np.all(np.isfinite(temperature)) else 'does not vary enough')
            return [], [f'{self.name}: {why}']

        def modify(slope: float) -> Modifier:
            ratio = law.viscosity(temperature, slope) / law.reference_viscosity
            return Modifier(flat_clearance=ratio ** parts.nu_exponent_lfg,
                            commutation=ratio ** parts.nu_exponent_c)

        def make(slope: float) -> Effect:
            return Effect(self.name, slope, 'temperature', law=law.law,
                          reference_temperature=float(law.reference_temperature),
                          reference_viscosity=float(law.reference_viscosity),
                          vogel_c=law.vogel_c)

        source = 'Walther, ASTM D341' if law.law == 'walther' else 'Vogel (water)'
        return [Candidate(self.name, 'temperature', law.unit, source, temperature, modify,
                          law.standard_slope, (0.0, 20.0 * law.standard_slope),
                          law.standard_slope, make)], []

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Return the slope the node parameter sets, the law left to the plant's liquid."""
        b = values['viscosity_temperature']
        return Effect(self.name, b, 'temperature') if b else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the slope of `effect`."""
        return {'viscosity_temperature': 0.0 if effect is None else effect.coefficient}

    def bind(self, effect: Effect, law: ViscosityLaw, reference_temperature: float) -> Effect:
        """Fill in the liquid's law, pinned at its viscosity at `reference_temperature`."""
        if effect.law:
            return effect
        return Effect(effect.name, effect.coefficient, effect.regressor, law=law.law,
                      reference_temperature=reference_temperature,
                      reference_viscosity=law.reference_viscosity, vogel_c=law.vogel_c)

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """Give the liquid its standard law, pinned at the mean temperature of the data."""
        law = data.law
        return Effect(name, law.standard_slope, 'temperature', law=law.law,
                      reference_temperature=float(np.mean(data.channels['temperature'])),
                      reference_viscosity=law.reference_viscosity, vogel_c=law.vogel_c)


KIND = ViscosityTemperature()
