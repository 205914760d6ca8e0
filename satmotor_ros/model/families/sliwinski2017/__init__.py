# SPDX-License-Identifier: Apache-2.0
"""
The ``sliwinski2017`` family: the paper's own model, eqs. (1)-(41), as the model package has it.

Its equations are :mod:`satmotor_ros.model.families.sliwinski2017.losses` and
:mod:`satmotor_ros.model.families.sliwinski2017.speed`, composed by
:class:`~.composition.Equations`; this module only adds what
every family offers: the linear parts of Q_vl for a fitter, and the defaults
for a motor known by its displacement alone.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.coefficients import (CoefficientSet, Liquid, LossCoefficients,
                                             MotorGeometry, ValidRange)
from satmotor_ros.model.families._base import Family, FamilyModel, LinearPart, SM_DISPLACEMENT
from satmotor_ros.model.families.sliwinski2017.composition import Equations
from satmotor_ros.model.families.sliwinski2017.derived import derive
from satmotor_ros.model.families.sliwinski2017.laws import displacement_law


class Sliwinski2017(Family):
    """
    The paper's model: eqs. (31)-(41) over the components of eqs. (1)-(14) and (24).

    Breakdown: every component of eq. (31); the split of C among eqs. (11)-(13)
    follows the coefficient set's documented assumption.
    """

    name = 'sliwinski2017'
    title = "the paper's own model, eqs. (31)-(41) (default)"
    equations = 'eqs. (31)-(41)'
    coefficients_type = LossCoefficients
    components = {'flat_clearance': 'flat clearances Q_Lfg, eq. (1)',
                  'commutation': 'commutation unit Q_C, eq. (5)',
                  'compressibility': 'compressibility dQ_fc, eq. (11)',
                  'deformation': 'deformation dQ_dch, eq. (12)',
                  'backlash': 'backlash dQ_b, eq. (13)', 'inertia': 'inertia dQ_id, eq. (14)',
                  'external': 'external Q_ex, eq. (24)', 'total': 'total Q_vl, eq. (31)'}
    laws = ('eq33', 'eq39')

    def compose(self, geometry: MotorGeometry, coefficient_set: CoefficientSet,
                valid_range: ValidRange, liquid: Liquid, law: str) -> Equations:
        """Derive the constants and compose eqs. (1)-(40): see :meth:`Family.compose`."""
        derived = derive(geometry, coefficient_set, valid_range, liquid)
        return Equations(derived, displacement_law(law, derived))

    def linear_parts(self, coefficients: Any) -> tuple[LinearPart, ...]:
        """Return ``leakage`` (a1, c1), ``pressure_speed`` (c), ``inertia`` (c_id), external."""
        return (LinearPart('leakage', 'eqs. (1), (5)', ('a1', 'c1'), 0.0),
                LinearPart('pressure_speed', 'eqs. (11)-(13), (33)', ('c',), 1.0),
                LinearPart('inertia', 'eqs. (14), (33)', ('c_id',), 0.5),
                LinearPart('external', 'eq. (24), lumped', ('external_leakage',), 0.0))

    def linear_losses(self, model: FamilyModel, speed: FloatArray, dp_i: FloatArray,
                      p_ex: FloatArray | float = 0.0) -> dict[str, FloatArray]:
        """Return Q_vl as the named linear parts: see :meth:`Family.linear_losses`."""
        b = model.breakdown(speed, dp_i, p_ex)
        return {'leakage': b.flat_clearance + b.commutation,
                'pressure_speed': b.compressibility + b.deformation + b.backlash,
                'inertia': b.inertia, 'external': b.external}

    def default_coefficients(self, packaged: CoefficientSet,
                             displacement: float) -> LossCoefficients:
        """Return Table 1's set for the liquid, eq. (35) scaled: c_t ~ q^(-4/3), c_l ~ q^(-1)."""
        coef = packaged.coefficients
        ratio = displacement / SM_DISPLACEMENT
        return replace(coef, c_t=coef.c_t * ratio ** (-4.0 / 3.0), c_l=coef.c_l / ratio)
