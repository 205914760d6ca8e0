# SPDX-License-Identifier: Apache-2.0
"""
Effects the paper's model lacks, one kind per file, and the registry that finds them.

A coefficient set's ``effects:`` block (written by ``satmotor calibrate``) is a
mapping of effect ids to blocks; :func:`effect_from_mapping` reads one into an
:class:`Effect` through its kind, :func:`effect_to_mapping` writes it back.
The model (:mod:`..conditioned`), the virtual motor (:mod:`satmotor_ros.plant`),
synthetic data and the calibration's candidate library all reach an effect
through its kind in :data:`KINDS`, so a new kind is one new file here that
defines ``KIND = MyKind()`` (doc/effects.md). The kinds shipped:

=========================  ============================================================
``external_leakage``       Q_ex = k_ex p (eq. 24), p the gauge pressure named by
                           ``regressor`` (``p_case`` or ``p_out``)
``viscosity_temperature``  nu(T) of a Walther or Vogel law replaces the liquid's
                           viscosity in eqs. (1), (5) and (35)
``clearance_wear``         h_R and h_S grow by k (x - reference) >= 0, x = ``time`` [s]
                           or ``revolutions`` [rev], in eqs. (1), (2) and (5)
``leakage_wear``           the leakage of a balawender or paszota motor grows by the factor
                           1 + max(0, k (x - reference)), x = ``time`` or ``revolutions``
``channel:<name>``         extra loss k (x - reference) in Q_vl, x the channel <name>
``reverse_loss``           extra loss k |dp_i| |n| in Q_vl while the shaft turns backwards
``term:<expression>``      extra loss k dp_i^a n^b in Q_vl, the exponents fitted
``threshold:dp``           a valve across the ports passing k max(0, |dp| - x_c)^e, dp the
                           port drop, beside the chambers (a relief valve cracking open)
``flow_sensor_offset``     the flowmeter reads Q + k
``flow_sensor_gain``       the flowmeter reads (1 + k) Q
``speed_sensor_gain``      the speed sensor reads (1 + k) n
=========================  ============================================================

Sensor effects describe the instruments, not the motor: the model's maps take
the true flow and return the true speed, and :func:`true_flow` and
:func:`true_speed` convert readings.

An effect that a calibration fitted carries ``fitted_range``: the least and
largest value of each quantity its law reads (:meth:`EffectKind.reads`) over
the data it was fitted on (:func:`measured_range`). The model flags a point
EXTRAPOLATED where it evaluates the effect outside that range
(:func:`satmotor_ros.model.engine.screening.outside_fitted`); an effect without one (a
hand-written file) is never flagged for it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import fields, replace
import importlib
import math
import pkgutil
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray, Real
from satmotor_ros.model.effects._base import (Candidate, CandidateData, Conditions, CORE_CHANNELS,
                                              DIRECTIONS, DOCUMENTARY, Effect, EffectKind, finite,
                                              KINDS, Modifier, PlantInjection, PlantParameter,
                                              Sampled, SensorError, Shape, Synthetic)
from satmotor_ros.model.errors import ConfigError


def register(kind: EffectKind) -> EffectKind:
    """
    Add a kind to :data:`KINDS` (every module of this package is registered on import).

    Parameters
    ----------
    kind : EffectKind
        The kind; its ``name`` must be new, [-]

    Returns
    -------
    EffectKind
        `kind`.

    Raises
    ------
    ConfigError
        If the name is empty, has a colon or is taken.

    """
    if not kind.name or ':' in kind.name or kind.name in KINDS:
        msg = f'effect kind {kind.name!r}: the name is empty, has a colon or is taken'
        raise ConfigError(msg)
    KINDS[kind.name] = kind
    return kind


def unregister(name: str) -> None:
    """
    Remove a kind from :data:`KINDS` (for tests that register one of their own).

    Parameters
    ----------
    name : str
        The kind's name, [-]

    """
    KINDS.pop(name, None)


def _discover() -> None:
    for module in pkgutil.iter_modules(__path__):
        if not module.name.startswith('_'):
            kind = getattr(importlib.import_module(f'{__name__}.{module.name}'), 'KIND', None)
            if kind is not None and kind.name not in KINDS:
                register(kind)


_discover()


def ranked() -> list[EffectKind]:
    """
    List the registered kinds in their order of :attr:`EffectKind.rank`.

    Returns
    -------
    list of EffectKind
        The kinds; equal ranks by name.

    """
    return sorted(KINDS.values(), key=lambda k: (k.rank, k.name))


def kind_of(effect: Effect) -> EffectKind:
    """
    Return the kind of an effect.

    Parameters
    ----------
    effect : Effect
        The effect, [-]

    Returns
    -------
    EffectKind
        Its kind.

    Raises
    ------
    ConfigError
        If no kind of that name is registered.

    """
    kind = KINDS.get(effect.kind)
    if kind is None:
        msg = f'effect {effect.name!r}: no such kind (known: {", ".join(KINDS)})'
        raise ConfigError(msg)
    return kind


def effect_name(effect: Effect) -> str:
    """
    Return the one name of an effect that every output gives (:meth:`EffectKind.named`).

    Parameters
    ----------
    effect : Effect
        The effect, [-]

    Returns
    -------
    str
        Its id with its direction, and what places it (a valve's crack pressure), e.g.
        ``threshold:dp@negative cracking at 19.87 MPa`` or ``external_leakage``.

    """
    return kind_of(effect).named(effect)


FITTED_RANGE = 'fitted_range'
"""The YAML key of an effect's fitted range: ``{quantity: [min, max]}``, SI (degC)."""

DIRECTION = 'direction'
"""The YAML key of where an effect acts (:data:`DIRECTIONS`); a one-sided effect's id in the
``effects:`` block is ``<id>@<direction>`` (:attr:`Effect.key`), so both sides may differ."""


def _known() -> str:
    return ', '.join(f'{k.name}:<name>' if k.suffixed else k.name for k in ranked())


def effect_from_mapping(name: Any, doc: Any, where: str) -> Effect:
    """
    Build one validated :class:`Effect` from its YAML block.

    Parameters
    ----------
    name : Any
        The block's key, e.g. ``'external_leakage'`` or ``'term:dp^2*n'``, [-]
    doc : Any
        The block: ``coefficient`` and what the kind needs, [-]
    where : str
        Key path quoted in errors, [-]

    Returns
    -------
    Effect
        The effect.

    Raises
    ------
    ConfigError
        Naming the key and the value for an unknown kind, key, regressor or law,
        a missing key, a value that is not a finite number, or a ``fitted_range``
        that does not give [min, max] with min <= max for exactly the quantities
        the effect reads.

    """
    key = str(name)
    name, at, qualifier = key.partition('@')
    kind_name, _, suffix = name.partition(':')
    where = f'{where}.{key}'
    kind = KINDS.get(kind_name)
    if kind is None or kind.suffixed != bool(suffix):
        msg = f'{where}: unknown effect {name!r} (known: {_known()})'
        raise ConfigError(msg)
    if not isinstance(doc, Mapping):
        msg = f'{where} must be a mapping, got {type(doc).__name__}: {doc!r}'
        raise ConfigError(msg)
    known = (*kind.keys, *((DIRECTION,) if kind.directional else ()), FITTED_RANGE)
    unknown = sorted(set(map(str, doc)) - set(known) - set(DOCUMENTARY))
    missing = [k for k in kind.required if k not in doc]
    if unknown or missing:
        what = (f'unknown key(s) {", ".join(unknown)}' if unknown
                else f'missing key(s) {", ".join(missing)}')
        msg = f'{where} has {what} (known: {", ".join(known)})'
        raise ConfigError(msg)
    effect = kind.parse(name, {k: v for k, v in doc.items() if k in kind.keys}, where)
    direction = _direction(doc.get(DIRECTION, qualifier or 'both'), qualifier if at else None,
                           kind, where)
    if direction != 'both':
        effect = replace(effect, direction=direction)
    if FITTED_RANGE not in doc:
        return effect
    return replace(effect, fitted_range=_fitted_range(doc[FITTED_RANGE], kind.reads(effect),
                                                      f'{where}.{FITTED_RANGE}'))


def _direction(value: Any, qualifier: str | None, kind: EffectKind, where: str) -> str:
    """Read ``direction`` (or the id's ``@<direction>``): one of DIRECTIONS, agreeing."""
    if not isinstance(value, str) or value not in DIRECTIONS:
        msg = f'{where}.{DIRECTION} = {value!r}: use {", ".join(DIRECTIONS)}'
        raise ConfigError(msg)
    if qualifier is not None and (qualifier != value or qualifier == 'both'):
        msg = (f'{where}: the id says @{qualifier}, the block says {DIRECTION} = {value!r} '
               '(write @positive or @negative, as the block)')
        raise ConfigError(msg)
    if value != 'both' and not kind.directional:
        msg = (f'{where}.{DIRECTION} = {value!r}: {kind.name} acts in both directions '
               '(a one-sided effect is a threshold, term, channel or reverse_loss)')
        raise ConfigError(msg)
    return value


def _fitted_range(doc: Any, quantities: tuple[str, ...],
                  where: str) -> tuple[tuple[str, float, float], ...]:
    """Read ``{quantity: [min, max]}``: exactly the quantities the law reads, min <= max."""
    if not isinstance(doc, Mapping):
        msg = f'{where} must be a mapping of quantity to [min, max], got {type(doc).__name__}'
        raise ConfigError(msg)
    given = set(map(str, doc))
    if given != set(quantities):
        extra, lacking = sorted(given - set(quantities)), sorted(set(quantities) - given)
        what = (f'unknown quantity {", ".join(extra)}' if extra
                else f'no range for {", ".join(lacking)}')
        msg = f'{where} has {what} (the effect reads: {", ".join(quantities) or "nothing"})'
        raise ConfigError(msg)
    out = []
    for quantity in quantities:
        value = doc[quantity]
        pair = list(value) if isinstance(value, (list, tuple)) else []
        low, high = (finite(v, f'{where}.{quantity}') for v in pair) if len(pair) == 2 else (
            math.nan, math.nan)
        if not low <= high:
            msg = (f'{where}.{quantity} = {value!r}: expected [min, max], two finite numbers '
                   'with min <= max')
            raise ConfigError(msg)
        out.append((quantity, low, high))
    return tuple(out)


def measured_range(effect: Effect, data: Mapping[str, FloatArray]) -> Effect:
    """
    Return `effect` with the range of the data it was fitted on.

    Parameters
    ----------
    effect : Effect
        A fitted effect, [-]
    data : mapping of str to ndarray
        The fitted points: ``dp_i``, ``speed`` and ``flow`` (magnitudes, SI) and the
        channels by name (gauge Pa, degC, s, rev), [-]

    Returns
    -------
    Effect
        `effect` with ``fitted_range`` over the finite values of every quantity
        :meth:`EffectKind.reads` names (`effect` itself when one has none).

    """
    out = []
    for quantity in kind_of(effect).reads(effect):
        values = np.asarray(data.get(quantity, ()), dtype=float)
        values = values[np.isfinite(values)]
        if not values.size:
            return effect
        out.append((quantity, float(values.min()), float(values.max())))
    return replace(effect, fitted_range=tuple(out))


def effect_to_mapping(effect: Effect) -> dict[str, Any]:
    """
    Write an effect as its YAML block (what :func:`effect_from_mapping` reads back).

    Parameters
    ----------
    effect : Effect
        The effect to write, [-]

    Returns
    -------
    dict
        The block, plain SI numbers and strings, with its ``fitted_range`` when it has
        one and the kind's ``evaluation``.

    """
    kind = kind_of(effect)
    block = kind.to_mapping(effect)
    if kind.directional:
        block[DIRECTION] = effect.direction
    if effect.fitted_range:
        block[FITTED_RANGE] = {q: [low, high] for q, low, high in effect.fitted_range}
    return {**block, 'evaluation': kind.evaluation}


def check_effects(effects: Iterable[Effect], where: str,
                  family: str | None = None) -> tuple[Effect, ...]:
    """
    Refuse two effects of one kind (only suffixed kinds may repeat, with other suffixes).

    Parameters
    ----------
    effects : iterable of Effect
        The effects, [-]
    where : str
        Key path quoted in errors, [-]
    family : str, optional
        Model family the effects act on: a kind that does not apply to it is refused, [-]

    Returns
    -------
    tuple of Effect
        The effects.

    Raises
    ------
    ConfigError
        Naming the kind given twice, unknown, or not applying to `family`.

    """
    effects = tuple(effects)
    seen: set[tuple[str, str]] = set()
    for effect in effects:
        kind = kind_of(effect)
        if family is not None and kind.families is not None and family not in kind.families:
            msg = (f'{where}.{effect.name}: {effect.kind} applies to the '
                   f'{" and ".join(sorted(kind.families))} family, not {family}')
            raise ConfigError(msg)
        key = effect.name if kind.suffixed else effect.kind
        sides = ('positive', 'negative') if effect.direction == 'both' else (effect.direction,)
        if any((key, side) in seen for side in sides):
            msg = f'{where} has more than one {key} effect acting where dp is {sides[0]}'
            raise ConfigError(msg)
        seen.update((key, side) for side in sides)
    return effects


def coefficients_without(effects: Iterable[Effect], coef: Any) -> Any:
    """
    Return a set's coefficients without what its effects set in them (e.g. eq. (24)'s k_ex).

    Each kind's :meth:`EffectKind.coefficients` applied at a coefficient of 0: the
    coefficients the set would hold without those effects.

    Parameters
    ----------
    effects : iterable of Effect
        The effects to take out, [-]
    coef : dataclass
        The family's coefficients, [-]

    Returns
    -------
    dataclass
        The coefficients, of the same type.

    """
    for effect in effects:
        coef = kind_of(effect).coefficients(replace(effect, coefficient=0.0), coef)
    return coef


def check_coefficients(effects: Iterable[Effect], coef: Any, where: str) -> None:
    """
    Refuse a set whose coefficients hold another value than an effect sets in them.

    Parameters
    ----------
    effects : iterable of Effect
        The set's effects, [-]
    coef : dataclass
        The set's coefficients, [-]
    where : str
        Key path of the effects for the message, [-]

    Raises
    ------
    ConfigError
        Naming the effect, the coefficient and both values.

    """
    for effect in effects:
        applied = kind_of(effect).coefficients(effect, coef)
        for field in fields(coef):
            held, set_ = getattr(coef, field.name), getattr(applied, field.name)
            if held != set_ and not math.isclose(held, set_, rel_tol=1e-9):
                msg = (f'{where}.{effect.name}.coefficient = {effect.coefficient!r} differs from '
                       f'coefficients.{field.name} = {held!r}: the set holds one value of it')
                raise ConfigError(msg)


def plant_injection(effects: Iterable[Effect]) -> PlantInjection:
    """
    Sort effects by what the virtual motor does with them (:meth:`EffectKind.inject`).

    Parameters
    ----------
    effects : iterable of Effect
        The injected effects, [-]

    Returns
    -------
    PlantInjection
        Motor, drifting, bypass and sensor effects.

    """
    into = PlantInjection()
    for effect in effects:
        into = kind_of(effect).inject(effect, into)
    return into


def sensor_error(effects: Iterable[Effect], channel: str) -> tuple[float, float]:
    """
    Compose the instrument errors on one channel into reading = gain * value + offset.

    The last effect acts first (a coefficient set lists the instrument's errors
    from the reading back to the truth).

    Parameters
    ----------
    effects : iterable of Effect
        A coefficient set's (or the plant's) effects, [-]
    channel : str
        ``'flow'`` or ``'speed'``, [-]

    Returns
    -------
    tuple of float
        Gain [-] and offset [unit of the channel].

    """
    gain, offset = 1.0, 0.0
    for effect in reversed(tuple(effects)):
        error = kind_of(effect).sensor_error(effect)
        if error is not None and error.channel == channel:
            gain, offset = error.gain * gain, error.gain * offset + error.offset
    return gain, offset


def flow_reading(effects: tuple[Effect, ...], flow: Real) -> Real:
    """Return what the flowmeter reads [m^3/s] at a flow through the motor (see true_flow)."""
    gain, offset = sensor_error(effects, 'flow')
    return flow if (gain, offset) == (1.0, 0.0) else gain * flow + offset


def true_flow(effects: tuple[Effect, ...], reading: Real) -> Real:
    """
    Return the flow through the motor from a flowmeter reading.

    Parameters
    ----------
    effects : tuple of Effect
        The coefficient set's effects, [-]
    reading : float or ndarray
        What the flowmeter reads, [m^3/s]

    Returns
    -------
    float or ndarray
        ``(reading - offset) / gain``, the reading itself without a flowmeter error, [m^3/s]

    """
    gain, offset = sensor_error(effects, 'flow')
    return reading if (gain, offset) == (1.0, 0.0) else (reading - offset) / gain


def true_speed(effects: tuple[Effect, ...], reading: Real) -> Real:
    """Return the shaft speed [rad/s] from a speed-sensor reading, as :func:`true_flow`."""
    gain, offset = sensor_error(effects, 'speed')
    return reading if (gain, offset) == (1.0, 0.0) else (reading - offset) / gain


def build_candidates(data: CandidateData) -> tuple[list[Candidate], list[str]]:
    """
    Build every kind's candidates, in the order of :func:`ranked`.

    Parameters
    ----------
    data : CandidateData
        Components, channels and law at the points (``covered`` is filled in here), [-]

    Returns
    -------
    list of Candidate
        The candidates.
    list of str
        Why other candidates were not offered.

    """
    covered = frozenset(CORE_CHANNELS).union(*(k.regressors for k in KINDS.values()))
    data = data._replace(covered=covered)
    out: list[Candidate] = []
    skipped: list[str] = []
    for kind in ranked():
        if data.family and kind.families is not None and data.family not in kind.families:
            continue  # e.g. clearance_wear of a family without clearances
        offered, why = kind.candidates(data)
        out += offered
        skipped += why
    return out, skipped


SENSOR_KINDS = tuple(k.name for k in ranked() if k.sensor)
"""Kinds shipped that describe an instrument, not the motor (:attr:`EffectKind.sensor`)."""

__all__ = ['Candidate', 'CandidateData', 'Conditions', 'DIRECTION', 'DIRECTIONS', 'Effect',
           'EffectKind', 'KINDS',
           'Modifier', 'PlantInjection', 'PlantParameter', 'Sampled', 'SENSOR_KINDS',
           'SensorError',
           'Shape', 'Synthetic', 'build_candidates', 'check_effects', 'effect_from_mapping',
           'effect_name', 'effect_to_mapping', 'FITTED_RANGE', 'flow_reading', 'kind_of',
           'measured_range',
           'plant_injection', 'ranked', 'register', 'sensor_error', 'true_flow', 'true_speed',
           'unregister', 'check_coefficients', 'coefficients_without']
