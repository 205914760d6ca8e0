# SPDX-License-Identifier: Apache-2.0
"""
A motor with no YAML: the SM-0,75/25 in any family, or a family's defaults for a displacement.

The liquids (oil and water sets) are the packaged SM-0,75/25's. A displacement
alone gives a geometrically similar motor: module, height and commutation
diameter scaled by (q/q_SM)^(1/3), clearances kept; the coefficients are the
family's documented defaults for that displacement
(:meth:`~satmotor_ros.model.families.Family.default_coefficients`), to be
calibrated; its validated range is the SM-0,75/25's carried over by similarity
(:func:`similar_range`), so points outside it are flagged EXTRAPOLATED.
"""

from __future__ import annotations

from dataclasses import replace

from satmotor_ros.model.coefficients import displacement_problem, MotorGeometry, ValidRange
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.families import DEFAULT_FAMILY, family_named
from satmotor_ros.model.io.config import load_motor, MotorSpec
from satmotor_ros.model.units import CM3_PER_REV


DEFAULTS_NOTE = ' (default coefficients, to be calibrated)'
"""What the name of a motor built from its displacement alone ends with."""


def similar_geometry(base: MotorGeometry, displacement: float) -> MotorGeometry:
    """
    Scale a satellite motor's geometry to another displacement, lengths ~ q^(1/3).

    Parameters
    ----------
    base : MotorGeometry
        The motor to scale, [-]
    displacement : float
        The new displacement q_t/(2 pi), [m^3/rad]

    Returns
    -------
    MotorGeometry
        Module, height and commutation diameter scaled; clearances kept.

    """
    s = (displacement / base.displacement) ** (1.0 / 3.0)
    return replace(base, displacement=displacement, module=base.module * s,
                   height=base.height * s, commutation_diameter=base.commutation_diameter * s)


def similar_range(base: ValidRange, scale: float) -> ValidRange:
    """
    Carry a motor's validated range over to a geometrically similar one, lengths times `scale`.

    The pressure drops stay: at one pressure the stresses, the clearance deformation of
    eq. (2) and the pressure-driven leakage per gap height are those of the measured motor.
    The speeds scale by 1/`scale`: the velocities in the machine (the teeth's, and the flow
    in the commutation channels, Q/A ~ scale^3 n / scale^2) are ~ scale n, and the inertia,
    channel and commutation losses were measured over a span of those velocities. The flow
    range therefore grows as scale^2 ~ q^(2/3) rather than staying that of the measured motor
    (which would ask a large motor to crawl at a speed ~ 1/q).

    Parameters
    ----------
    base : ValidRange
        The measured motor's range, [-]
    scale : float
        Ratio of the lengths, (q/q_base)^(1/3), [-]

    Returns
    -------
    ValidRange
        The drops of `base`, its speeds divided by `scale`.

    """
    return replace(base, speed_max=base.speed_max / scale, speed_min=base.speed_min / scale)


def default_motor(family: str = DEFAULT_FAMILY, displacement: float | None = None) -> MotorSpec:
    """
    Build a motor without a YAML: the SM-0,75/25, or a motor known by its displacement.

    Parameters
    ----------
    family : str
        ``'sliwinski2017'``, ``'balawender'`` or ``'paszota'``, [-]
    displacement : float, optional
        Displacement q_t/(2 pi); the SM-0,75/25's when omitted, [m^3/rad]

    Returns
    -------
    MotorSpec
        Sets ``oil`` and ``water`` with the family's default coefficients.

    Raises
    ------
    ConfigError
        For an unknown family or a displacement outside
        :data:`~satmotor_ros.model.coefficients.DISPLACEMENT_RANGE`.

    Examples
    --------
    >>> spec = default_motor('paszota', 4.9e-6 / 6.283185307179586)
    >>> spec.family, sorted(spec.sets)
    ('paszota', ['oil', 'water'])

    """
    fam = family_named(family)
    packaged = load_motor()
    if displacement is None:
        if fam.name == DEFAULT_FAMILY:
            return packaged
        displacement, name = packaged.geometry.displacement, f'{packaged.name} ({fam.name})'
    elif (problem := displacement_problem(displacement)) is not None:
        raise ConfigError(f'displacement = {displacement!r} m^3/rad is {problem}')
    else:
        name = f'{fam.name} motor of {displacement / CM3_PER_REV:.4g} cm^3/rev{DEFAULTS_NOTE}'
    try:
        sets = {key: replace(s, coefficients=fam.default_coefficients(s, displacement),
                             effects=()) for key, s in packaged.sets.items()}
    except (OverflowError, ZeroDivisionError) as err:  # a safety net behind the range check
        raise ConfigError(f'displacement = {displacement!r} m^3/rad: the default coefficients '
                          f'of {fam.name} cannot be scaled to it ({err})') from None
    scale = (displacement / packaged.geometry.displacement) ** (1.0 / 3.0)
    return MotorSpec(name, similar_geometry(packaged.geometry, displacement),
                     similar_range(packaged.valid_range, scale), sets, f'<{fam.name} defaults>',
                     fam.name)
