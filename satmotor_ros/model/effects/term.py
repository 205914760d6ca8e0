# SPDX-License-Identifier: Apache-2.0
"""``term:<expression>``: an extra loss k dp_i^a n^b in Q_vl, the exponents fitted."""

from __future__ import annotations

from collections.abc import Mapping
import math
import re
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray, Real
from satmotor_ros.model.effects._base import (Candidate, CandidateData, Effect, EffectKind,
                                              finite, Loss, Modifier, Shape, SHAPES_KEPT)
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.units import LPM

FORMS = (('dp',), ('n',), ('dp', 'n'))
"""The candidates offered: dp_i^a, n^b and dp_i^a n^b, each with its exponents fitted."""

BOUNDS = {'dp': (0.05, 4.0), 'n': (0.05, 3.0)}
"""Range of each fitted exponent, [-]."""

MAX_EXPONENT = 10.0
"""Largest exponent a ``term:`` id may give (k dp_i^a overflows past it), [-]."""

_FACTOR = re.compile(r'(dp|n)(?:\^([0-9]+(?:\.[0-9]*)?|\.[0-9]+))?')


def expression(a: float, b: float) -> str:
    """
    Write dp^a n^b as an id suffix: 2 significant digits, a power of 1 bare, of 0 left out.

    Parameters
    ----------
    a, b : float
        Exponents of dp_i and n, [-]

    Returns
    -------
    str
        E.g. ``'dp^0.76'``, ``'dp^3*n'``, ``'n^0.7'``.

    """
    parts = []
    for name, power in (('dp', a), ('n', b)):
        text = f'{power:.2g}'
        if text not in ('0', '-0'):
            parts.append(name if text == '1' else f'{name}^{text}')
    return '*'.join(parts) or '1'


def exponents(suffix: str, where: str) -> tuple[float, float]:
    """
    Read the exponents of dp and n from an expression such as ``'dp^2*n'``.

    Parameters
    ----------
    suffix : str
        The expression, [-]
    where : str
        Key path quoted in errors, [-]

    Returns
    -------
    tuple of float
        a (of dp_i) and b (of n), [-]

    Raises
    ------
    ConfigError
        If the expression is not a product of powers of dp and n.

    """
    powers = {'dp': 0.0, 'n': 0.0}
    for factor in suffix.split('*'):
        match = _FACTOR.fullmatch(factor.strip())
        power = float(match.group(2) or 1.0) if match else math.nan
        if match is None or powers[match.group(1)] != 0.0 or not 0.0 < power <= MAX_EXPONENT:
            msg = (f'{where}: term {suffix!r} is not a product of powers of dp and n, each '
                   f"power above 0 and at most {MAX_EXPONENT:g} (e.g. 'dp^0.76', 'dp^2*n', "
                   "'n^0.7')")
            raise ConfigError(msg)
        powers[match.group(1)] = power
    return powers['dp'], powers['n']


def _variables(a: float, b: float) -> str:
    return '*'.join(name for name, p in (('dp', a), ('n', b)) if p)


def power_of(effect: Effect) -> tuple[float, float]:
    """Return an effect's exponents (a of dp_i, b of n): its options, or read from its id."""
    if effect.option('dp') is not None:
        return float(effect.option('dp')), float(effect.option('n', 0.0))
    return exponents(effect.suffix, effect.name)


class Term(EffectKind):
    """A loss k dp_i^a n^b that the paper's eqs. (31)-(33) lack, the exponents fitted."""

    name = 'term'
    suffixed = True
    rank = 80
    directional = True
    keys = ('regressor', 'coefficient', 'exponents')
    unit = 'm^3/s per Pa^a (rad/s)^b'
    source = 'not in eqs. (31)-(33), exponents fitted'
    evaluation = ('extra loss k |dp|^a |n|^b added to Q_vl (eq. 31): n [rad/s], dp [Pa] the '
                  'chamber drop dp_i of eq. (34), a and b the exponents')

    def parse(self, name: str, doc: Mapping[str, Any], where: str) -> Effect:
        """Read the coefficient and the exponents (``exponents:``, or the id's expression)."""
        a, b = exponents(name.partition(':')[2], where)
        given = doc.get('exponents')
        if given is not None:
            if not isinstance(given, Mapping) or set(map(str, given)) - {'dp', 'n'}:
                msg = f'{where}.exponents = {given!r}: expected a mapping with dp and n'
                raise ConfigError(msg)
            a = finite(given.get('dp', 0.0), f'{where}.exponents.dp')
            b = finite(given.get('n', 0.0), f'{where}.exponents.n')
            if expression(a, b) != name.partition(':')[2]:
                msg = (f'{where}.exponents = {dict(given)!r}: the id says '
                       f'{name.partition(":")[2]!r}, these give {expression(a, b)!r}')
                raise ConfigError(msg)
        k = finite(doc['coefficient'], f'{where}.coefficient')
        return Effect(name, k, _variables(a, b), options=(('dp', a), ('n', b)))

    def to_mapping(self, effect: Effect) -> dict[str, Any]:
        """Write the coefficient and the exponents."""
        a, b = power_of(effect)
        return {'regressor': _variables(a, b), 'coefficient': effect.coefficient,
                'exponents': {'dp': a, 'n': b}}

    def loss(self, effect: Effect) -> Loss | None:
        """Return k |dp_i|^a |n|^b."""
        a, b = power_of(effect)
        k = effect.coefficient

        def loss(n: Real, dp_i: Real) -> Real:
            out: Real = k * abs(dp_i) ** a * abs(n) ** b
            return out
        return loss

    def reads(self, effect: Effect) -> tuple[str, ...]:
        """Read dp_i, n or both, as the exponents say."""
        return tuple(q for q, p in zip(('dp_i', 'speed'), power_of(effect)) if p)

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer dp_i^a, n^b and dp_i^a n^b, k the extra loss at the largest dp_i and n."""
        dp = np.abs(data.parts.dp_i) / max(float(np.max(np.abs(data.parts.dp_i))), 1e-300)
        n = np.abs(data.parts.speed) / max(float(np.max(np.abs(data.parts.speed))), 1e-300)
        ref = {'dp': float(np.max(np.abs(data.parts.dp_i))),
               'n': float(np.max(np.abs(data.parts.speed)))}
        columns = {'dp': dp, 'n': n}
        return [self._candidate(form, columns, ref) for form in FORMS], []

    def _candidate(self, form: tuple[str, ...], columns: Mapping[str, FloatArray],
                   ref: Mapping[str, float]) -> Candidate:
        def powers(theta: tuple[float, ...]) -> dict[str, float]:
            return {'dp': 0.0, 'n': 0.0, **dict(zip(form, theta))}

        shapes: dict[tuple[float, ...], FloatArray | float] = {}  # exponents -> the form

        def modify(k: float, *theta: float) -> Modifier:
            # a fit's finite differences in k and the other coefficients keep the exponents
            x = shapes.get(theta)
            if x is None:
                x = 1.0
                for name, p in zip(form, theta):
                    x = x * columns[name] ** p
                if len(shapes) >= SHAPES_KEPT:
                    shapes.pop(next(iter(shapes)))
                shapes[theta] = x
            return Modifier(additive=k * x)

        def make(k: float, *theta: float) -> Effect:
            p = powers(theta)
            coefficient = k / ref['dp'] ** p['dp'] / ref['n'] ** p['n']
            return Effect(f'{self.name}:{expression(p["dp"], p["n"])}', coefficient,
                          _variables(p['dp'], p['n']), options=(('dp', p['dp']), ('n', p['n'])))

        shape = tuple(Shape(f'{name} exponent', (0.5, 2.0), BOUNDS[name]) for name in form)
        label = '*'.join(f'{name}^{"ab"[("dp", "n").index(name)]}' for name in form)
        return Candidate(f'{self.name}:{label}', '*'.join(form), self.unit, self.source,
                         columns[form[0]], modify, LPM, make=make, shape=shape)


KIND = Term()
