# SPDX-License-Identifier: Apache-2.0
"""
One motor on one liquid without its effects: constants, equations and the single-point path.

Both :class:`~satmotor_ros.model.MotorModel` and the effects
(:mod:`.conditioned`, which builds a variant of the motor per temperature or
wear) build their motors here, so neither needs the other.
"""

from __future__ import annotations

from satmotor_ros.model.coefficients import CoefficientSet, Liquid, MotorGeometry, ValidRange
from satmotor_ros.model.engine.point import PointEvaluator
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.families import family_of


class ModelCore:
    """
    The constants, equations and point evaluator of one motor, coefficient set and liquid.

    The family (:mod:`.families`) is the one the set's coefficients belong to;
    it derives the constants and composes the equations.

    Parameters
    ----------
    geometry : MotorGeometry
        Motor geometry, [-]
    coefficient_set : CoefficientSet
        Loss coefficients and the liquid they were fitted on (its effects are ignored), [-]
    valid_range : ValidRange
        Range the coefficients were validated over, [-]
    liquid : Liquid
        Working liquid, [-]
    law : {'eq33', 'eq39'}
        Law of Delta q (eq. 39 for the ``sliwinski2017`` family only), [-]

    """

    def __init__(self, geometry: MotorGeometry, coefficient_set: CoefficientSet,
                 valid_range: ValidRange, liquid: Liquid, law: str) -> None:
        """Derive the constants and compose the equations."""
        self.geometry, self.coefficient_set = geometry, coefficient_set
        self.valid_range, self.liquid, self.law_name = valid_range, liquid, law
        self.family = family_of(coefficient_set.coefficients)
        try:
            self.eqs = self.family.compose(geometry, coefficient_set, valid_range, liquid, law)
        except (OverflowError, ZeroDivisionError) as err:  # a safety net behind the range checks
            raise ConfigError(f'the {self.family.name} constants of this motor and liquid '
                              f'cannot be computed ({err})') from None
        self.derived = self.eqs.derived
        self.point = PointEvaluator(self.eqs)
