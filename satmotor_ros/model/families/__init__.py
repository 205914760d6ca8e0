# SPDX-License-Identifier: Apache-2.0
"""
The paper's three loss models behind one interface: the model families.

- ``sliwinski2017``: the paper's own model, eqs. (31)-(41) (the default);
- ``balawender``: the earlier literature's model, eqs. (15)-(28), with its
  variant for low-viscosity liquids;
- ``paszota``: Paszota and Mączyszyn's model of any constant-displacement
  motor, eqs. (29)-(30).

A motor YAML names its family (``family:``); the family is also known from
the type of a coefficient set's coefficients, which is how
:class:`~satmotor_ros.model.MotorModel` dispatches. Each :class:`Family`
composes its equations into the callables the point path and the array maps
use, and exposes Q_vl as named linear parts for a fitter
(:meth:`Family.linear_parts`, :meth:`Family.linear_losses`, :meth:`Family.scaled`).
"""

from __future__ import annotations

from typing import Any

from satmotor_ros.model.errors import ConfigError, ModelError
from satmotor_ros.model.families._base import Family, LinearPart, SM_DISPLACEMENT
from satmotor_ros.model.families.balawender import Balawender, BalawenderCoefficients
from satmotor_ros.model.families.paszota import Paszota, PaszotaCoefficients
from satmotor_ros.model.families.sliwinski2017 import Sliwinski2017

FAMILIES: dict[str, Family] = {f.name: f for f in (Sliwinski2017(), Balawender(), Paszota())}
"""The families by name."""

FAMILY_NAMES = tuple(FAMILIES)
"""Their names, the default first."""

DEFAULT_FAMILY = 'sliwinski2017'
"""The family of a motor YAML without ``family:``."""


def family_named(name: Any, where: str = 'family') -> Family:
    """
    Return the family of a given name.

    Parameters
    ----------
    name : str
        ``'sliwinski2017'``, ``'balawender'`` or ``'paszota'``, [-]
    where : str
        The key or option quoted in the error, [-]

    Returns
    -------
    Family
        The family.

    Raises
    ------
    ConfigError
        For any other name; the message names `where` and the value.

    """
    family = FAMILIES.get(name) if isinstance(name, str) else None
    if family is None:
        msg = f'{where} = {name!r}: unknown model family (use {", ".join(FAMILY_NAMES)})'
        raise ConfigError(msg)
    return family


def family_of(coefficients: Any) -> Family:
    """
    Return the family a coefficient dataclass belongs to.

    Parameters
    ----------
    coefficients : dataclass
        ``LossCoefficients``, ``BalawenderCoefficients`` or ``PaszotaCoefficients``, [-]

    Returns
    -------
    Family
        Its family.

    Raises
    ------
    ModelError
        For coefficients of no family.

    """
    for family in FAMILIES.values():
        if type(coefficients) is family.coefficients_type:
            return family
    msg = f'coefficients of type {type(coefficients).__name__} belong to no model family'
    raise ModelError(msg)


__all__ = ['BalawenderCoefficients', 'DEFAULT_FAMILY', 'FAMILIES', 'FAMILY_NAMES', 'Family',
           'LinearPart', 'PaszotaCoefficients', 'SM_DISPLACEMENT', 'family_named', 'family_of']
