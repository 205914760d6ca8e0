# SPDX-License-Identifier: Apache-2.0
"""
The motor and liquid options every node and ``satmotor`` command builds its model from.

The same options are node parameters (same names, declared once in
``nodes/_parameters.py``) and ``satmotor`` options; :meth:`MotorOptions.build_model` is
the only place a model is built from options.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math

from satmotor_ros.model import load_motor, ModelError, MotorModel
from satmotor_ros.model.coefficients import displacement_problem
from satmotor_ros.model.families import DEFAULT_FAMILY, FAMILY_NAMES
from satmotor_ros.model.families.defaults import default_motor
from satmotor_ros.model.io.config import MotorSpec
from satmotor_ros.model.motor import DisplacementLaw

DISPLACEMENT_LAWS = ('eq33', 'eq39')
"""Laws of the change of displacement: physical eq. (33) or empirical eq. (39)."""

LIQUID_PROPERTIES = {'viscosity': 'kinematic_viscosity', 'density': 'density',
                     'bulk_modulus': 'bulk_modulus'}
"""User-liquid option -> :class:`~satmotor_ros.model.Liquid` field it overrides."""


class OptionError(ModelError):
    """
    A motor or liquid option is not acceptable; names the option and the value.

    Parameters
    ----------
    option : str
        Field of :class:`MotorOptions`, [-]
    value : object
        Its value, [-]
    reason : str
        What is wrong, [-]

    """

    def __init__(self, option: str, value: object, reason: str) -> None:
        """Keep the parts, so that each front end can spell the option its own way."""
        super().__init__(f'{option} = {value!r}: {reason}')
        self.option, self.value, self.reason = option, value, reason


@dataclass(frozen=True)
class MotorOptions:
    """
    Which motor, model family, coefficient set, liquid and Delta q law a model is built from.

    The same options are node parameters (same names) and ``satmotor`` options
    (``--liquid``, ``--motor``, ``--family``, ``--displacement``, ``--law``,
    ``--viscosity``, ``--density``, ``--bulk-modulus``).

    Parameters
    ----------
    liquid : str
        Coefficient set and its liquid: ``'oil'`` or ``'water'`` for the packaged
        SM-0,75/25, or any set of `motor_file`, [-]
    motor_file : str
        Motor specification or calibrated coefficients YAML; empty: the packaged
        SM-0,75/25, [-]
    displacement_law : {'eq33', 'eq39'}
        Change of displacement law, [-]
    viscosity : float
        Kinematic viscosity of a user liquid run on the set; 0: the set's own, [m^2/s]
    density : float
        Density of a user liquid; 0: the set's own, [kg/m^3]
    bulk_modulus : float
        Bulk modulus of a user liquid; 0: the set's own, [Pa]
    family : str
        Model family: ``'sliwinski2017'``, ``'balawender'`` or ``'paszota'``; empty:
        the motor file's own (``sliwinski2017`` without a file). Without a motor
        file, the SM-0,75/25 (or a motor of `displacement`) with the family's
        default coefficients, [-]
    displacement : float
        Displacement of a motor that has no YAML (the family's default
        coefficients, to be calibrated); 0: the motor file's, [m^3/rad]

    """

    liquid: str = 'oil'
    motor_file: str = ''
    displacement_law: DisplacementLaw = 'eq33'
    viscosity: float = 0.0  # [m^2/s]; 0: the set's own
    density: float = 0.0  # [kg/m^3]; 0: the set's own
    bulk_modulus: float = 0.0  # [Pa]; 0: the set's own
    family: str = ''  # '': the motor file's own
    displacement: float = 0.0  # [m^3/rad]; 0: the motor file's

    def __post_init__(self) -> None:
        """Reject a family, law, displacement or liquid property that cannot be, naming it."""
        if self.family not in ('', *FAMILY_NAMES):
            raise OptionError('family', self.family, f'use one of {", ".join(FAMILY_NAMES)}')
        problem = displacement_problem(self.displacement) if self.displacement != 0.0 else None
        if problem is not None:
            raise OptionError('displacement', self.displacement,
                              f"{problem}; 0: the motor file's")
        if self.displacement and self.motor_file:
            raise OptionError('displacement', self.displacement, 'a motor file has its own: '
                              'give the file or the displacement, not both')
        if self.displacement_law not in DISPLACEMENT_LAWS:
            raise OptionError('displacement_law', self.displacement_law,
                              f'use one of {", ".join(DISPLACEMENT_LAWS)}')
        for name in LIQUID_PROPERTIES:
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise OptionError(name, value, "must be a finite value > 0 (0: the set's own)")

    def spec(self) -> MotorSpec:
        """
        Load the motor file, or build a motor of the family, and check that it has the set.

        Returns
        -------
        MotorSpec
            The motor.

        Raises
        ------
        ModelError
            If the file cannot be read (the message names it), is of another family
            than `family` (:class:`OptionError` on ``family``) or lacks the set
            (:class:`OptionError` on ``liquid``).

        """
        if self.motor_file:
            spec = load_motor(self.motor_file)
            if self.family and self.family != spec.family:
                raise OptionError('family', self.family, f'{self.motor_file} is a '
                                  f'{spec.family} motor (omit the family, or convert the file)')
        else:
            spec = default_motor(self.family or DEFAULT_FAMILY, self.displacement or None)
        if self.liquid not in spec.sets:
            raise OptionError('liquid', self.liquid, f'not a coefficient set of {spec.name} '
                              f'(has: {", ".join(spec.sets)})')
        return spec

    def build_model(self) -> MotorModel:
        """
        Build the motor model the options describe.

        Returns
        -------
        MotorModel
            The model, with the user liquid when a property is overridden.

        Raises
        ------
        ModelError
            If the motor file, the set or the user liquid is invalid; the message names it.

        """
        spec = self.spec()
        overrides = {field: float(getattr(self, option))
                     for option, field in LIQUID_PROPERTIES.items() if getattr(self, option)}
        liquid = None
        if overrides:
            liquid = replace(spec.sets[self.liquid].liquid,
                             name=f'user liquid on the {self.liquid} set', **overrides)
        return MotorModel.from_spec(spec, self.liquid, liquid, self.displacement_law)


__all__ = ['DISPLACEMENT_LAWS', 'LIQUID_PROPERTIES', 'MotorOptions', 'OptionError']
