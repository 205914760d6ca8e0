# SPDX-License-Identifier: Apache-2.0
"""
What every effect kind provides, and the records they exchange with the layers.

An effect kind is one subclass of :class:`EffectKind` in one file of this
package. It owns four things, each a method with a working default:

- its YAML schema: :meth:`EffectKind.parse` and :meth:`EffectKind.to_mapping`;
- what it does to the model: :meth:`EffectKind.condition` (a motor built for
  the channel's value), :meth:`EffectKind.loss` (an extra loss in Q_vl) or
  :meth:`EffectKind.sensor_error` (what an instrument makes of the truth);
- its calibration candidate: :meth:`EffectKind.candidates`;
- its plant injection: :meth:`EffectKind.inject`, with the node parameters
  :attr:`EffectKind.plant_parameters` and :meth:`EffectKind.from_plant`.

Pure numpy: nothing here imports the plant, identify or ROS.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
import math
from typing import Any, NamedTuple, Protocol

import numpy as np

from satmotor_ros.model._typing import FloatArray, Real
from satmotor_ros.model.coefficients import Effect, LossCoefficients
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.units import LPM
from satmotor_ros.model.viscosity import ViscosityLaw


class Loss(Protocol):
    """An extra loss f(n [rad/s], dp_i [Pa]) -> Q [m^3/s]: floats in, float out; arrays alike."""

    def __call__(self, n: Real, dp_i: Real, /) -> Real:
        """Evaluate the loss."""


KINDS: dict[str, EffectKind] = {}
"""The registry: kind name -> kind, filled by :func:`satmotor_ros.model.effects.register`."""

DOCUMENTARY = ('unit', 'ci95', 'source', 'evaluation')

DIRECTIONS = ('both', 'positive', 'negative')
"""Where an effect acts: both signs of dp = p_a - p_b, dp >= 0 only or dp < 0 only."""
"""Keys written for the reader of a ``coefficients.yaml``; the model does not use them."""

MIN_SPREAD = 1.0e-3
"""A regressor must vary by this share of its largest magnitude to be offered, [-]."""

CORE_CHANNELS = ('p_in', 'speed', 'flow')
"""Columns of every bench table, never a regressor of their own effect."""


class Conditions(NamedTuple):
    """The motor an effect asks for at a channel's value (what :meth:`condition` returns)."""

    viscosity: float  # kinematic viscosity of the liquid [m^2/s]
    growth: float  # growth of both axial clearances h_R, h_S [m]
    p_ex: float  # pressure that drives the external leakage Q_ex of eq. (24) [Pa]
    extra: float  # extra loss in Q_vl that does not depend on n or dp_i [m^3/s]
    leakage: float = 1.0  # factor on the family's leakage parts (Family.leakage) [-]


class SensorError(NamedTuple):
    """What an instrument makes of the truth: reading = gain * value + offset."""

    channel: str  # 'flow' or 'speed'
    gain: float  # factor on the true value [-]
    offset: float  # added to it [unit of the channel]


@dataclass(frozen=True)
class Modifier:
    """How a candidate effect changes the model's prediction of the measured flow."""

    flow_gain: float = 1.0  # measured / true flow [-]
    speed_gain: float = 1.0  # measured / true speed [-]
    flat_clearance: FloatArray | float = 1.0  # factor on Q_Lfg [-]
    commutation: FloatArray | float = 1.0  # factor on Q_C [-]
    additive: FloatArray | float = 0.0  # extra loss [m^3/s]
    offset: float = 0.0  # flowmeter offset [m^3/s]
    leakage: FloatArray | float = 1.0  # factor on a family's leakage parts (wear) [-]

    def __add__(self, other: Modifier) -> Modifier:
        """Compose two effects: gains and factors multiply, extra losses and offsets add."""
        return Modifier(self.flow_gain * other.flow_gain, self.speed_gain * other.speed_gain,
                        self.flat_clearance * other.flat_clearance,
                        self.commutation * other.commutation, self.additive + other.additive,
                        self.offset + other.offset, self.leakage * other.leakage)


@dataclass(frozen=True)
class Shape:
    """A parameter of a candidate's form fitted with its coefficient (an exponent, a threshold)."""

    name: str  # e.g. 'dp exponent'
    starts: tuple[float, ...]  # initial values the fit tries
    bounds: tuple[float, float]  # range, in the fitted units
    unit: str = '-'  # of the physical value
    to_unit: tuple[float, float] = (0.0, 1.0)  # physical value = [0] + [1] * fitted value
    floor_is_value: bool = False  # the lower bound is a value of the physics (no delay),
    # not the end of a range the data might ask to pass: a fit may end on it


@dataclass(frozen=True)
class Candidate:
    """One candidate effect bound to the data it will be fitted on."""

    effect: str  # vocabulary id, e.g. 'external_leakage' or 'term:dp^2*n'
    regressor: str  # the channel or expression the effect uses
    unit: str  # unit of the coefficient
    source: str  # the physics or standard the term comes from
    values: FloatArray  # the regressor at each point (SI), for plots
    modify: Callable[..., Modifier]  # (coefficient, *shape) -> modified prediction
    typical: float  # coefficient magnitude that changes the loss by ~1 l/min
    bounds: tuple[float, float] = (-np.inf, np.inf)  # physical range of the coefficient
    start: float = 0.0  # initial coefficient of the fit
    make: Callable[..., Effect] | None = None  # (coefficient, *shape) -> the effect (YAML)
    shape: tuple[Shape, ...] = ()  # parameters of the form fitted with the coefficient
    direction: str = 'both'  # the sign of dp where it acts (DIRECTIONS)

    @property
    def label(self) -> str:
        """Return the effect with its regressor, e.g. ``external_leakage(p_case)``."""
        where = '' if self.direction == 'both' else f'@{self.direction}'
        if ':' in self.effect or self.regressor in ('', '1'):
            return self.effect + where
        return f'{self.effect}({self.regressor}){where}'

    @property
    def description(self) -> str:
        """Return ``label [unit] (source)``, one line for reports."""
        return f'{self.label} [{self.unit}] ({self.source})'

    def as_effect(self, coefficient: float, *shape: float) -> Effect:
        """Return the effect this candidate stands for at a fitted coefficient (and shape)."""
        if self.make is not None:  # a form on both sides may say which side its data hold
            made = self.make(coefficient, *shape)
            return made if self.direction == 'both' else replace(made,
                                                                 direction=self.direction)
        return Effect(self.effect, coefficient, self.regressor, direction=self.direction)


class Parts(Protocol):
    """The model's loss components at measured points (``identify.parts.LossParts``)."""

    @property
    def flow(self) -> FloatArray:
        """Measured Q [m^3/s]."""

    @property
    def speed(self) -> FloatArray:
        """Measured n [rad/s]."""

    @property
    def dp(self) -> FloatArray:
        """Port drop |dp| [Pa]."""

    @property
    def dp_i(self) -> FloatArray:
        """Chamber drop, eq. (34) [Pa]."""

    @property
    def displacement(self) -> FloatArray:
        """q_t n [m^3/s]."""

    @property
    def sign(self) -> FloatArray | float:
        """Sign of dp (the row's frame): -1 where dp < 0 [-]."""

    @property
    def clearance(self) -> FloatArray:
        """h, eq. (2) [m]."""

    @property
    def clearance_satellites(self) -> float:
        """h_S [m]."""

    @property
    def h_exponent(self) -> float:
        """Q_Lfg ~ h^(3/(2-beta)) [-]."""

    @property
    def hs_exponent(self) -> float:
        """Q_C ~ h_S^C_2 [-]."""

    @property
    def nu_exponent_lfg(self) -> float:
        """Q_Lfg ~ nu^(-beta/(2-beta)) [-]."""

    @property
    def nu_exponent_c(self) -> float:
        """Q_C ~ nu^(-gamma) [-]."""


class CandidateData(NamedTuple):
    """What the candidate library offers every kind."""

    parts: Parts  # components at the points
    channels: Mapping[str, FloatArray]  # extra channels (SI; temperature in degC)
    law: ViscosityLaw  # the liquid's viscosity law, pinned at its viscosity
    covered: frozenset[str]  # channels a named kind reads (no generic channel: candidate)
    family: str = ''  # the model family of the parts; '' offers every kind
    samples: Sampled | None = None  # the points are bins of a time series' samples: the
    # samples' own port drop, so a kind nonlinear in it is averaged as the model will be


SHAPES_KEPT = 4
"""Shapes (a crack, exponents) whose form a candidate keeps computed, [-]: a fit's finite
differences in the coefficients keep the shape (the form is reused), and a step, its
differences in the shape and a rejected step's retry each need one."""


class Sampled(NamedTuple):
    """The samples each point (a bin of a time series) averages, for kinds that read dp."""

    dp: FloatArray  # signed port drop p_a - p_b at every sample (NaN where unusable) [Pa]
    mean: Callable[[FloatArray], FloatArray]  # a quantity at every sample -> its bin means
    sparse: Callable[[np.ndarray, FloatArray], FloatArray] | None = None  # (the samples
    # where a quantity may differ from 0, each once, none where dp is NaN; its values there)
    # -> its bin means, NaN where dp is: `mean`'s, at a cost that grows with those samples
    lag: Callable[[np.ndarray, FloatArray, float], tuple[np.ndarray, FloatArray]] | None = None
    # (the samples where a quantity may differ from 0, its values there, a time constant tau
    # [s]) -> the samples its first-order lag of tau reaches and the lagged values there
    step: float = 0.0  # the median sample step [s]


class Synthetic(NamedTuple):
    """Operating points a synthetic injection scales its coefficient on."""

    speed: FloatArray  # true speed |n| [rad/s]
    dp_i: FloatArray  # chamber drop |dp_i| of the model without the effect [Pa]
    channels: Mapping[str, FloatArray]  # time [s], temperature [degC], p_case [Pa], ...
    law: ViscosityLaw  # the liquid's standard viscosity law
    shape: tuple[tuple[str, float], ...] = ()  # kind-specific numbers (a threshold, ...)
    rotation: FloatArray | float = 1.0  # sign of the true speed, -1, 0 or +1 [-]
    dp: FloatArray | None = None  # port drop |dp| [Pa]; None: not known (dp_i stands in)


@dataclass(frozen=True)
class PlantParameter:
    """One node parameter of the virtual motor that sets an effect (``effects.<name>``)."""

    name: str  # without the 'effects.' prefix
    default: Any  # float or str; the default leaves the effect off
    description: str  # what it is, without the unit
    unit: str = '-'  # SI unit
    low: float | None = None  # closed range (numbers)
    high: float | None = None
    choices: tuple[str, ...] = ()  # allowed strings


@dataclass(frozen=True)
class PlantInjection:
    """What the virtual motor does with a tuple of effects, sorted by :meth:`EffectKind.inject`."""

    motor: tuple[Effect, ...] = ()  # evaluated by the plant's motor model at its channels
    drift: tuple[Effect, ...] = ()  # change the motor itself: rebuilt within a tolerance
    bypass: tuple[tuple[str, float], ...] = ()  # (gauge pressure channel, k): inlet -> tank
    sensors: tuple[Effect, ...] = ()  # act on the readings only

    def add(self, slot: str, item: Any) -> PlantInjection:
        """Return a copy with `item` appended to the tuple `slot`."""
        return replace(self, **{slot: (*getattr(self, slot), item)})


def one_sided(candidate: Candidate, negative: np.ndarray, direction: str) -> Candidate:
    """
    Return `candidate` acting only where dp < 0 (`direction` 'negative') or dp >= 0.

    Parameters
    ----------
    candidate : Candidate
        A two-sided candidate whose modifier adds a loss, [-]
    negative : ndarray of bool
        Rows where dp = p_a - p_b < 0, [-]
    direction : {'positive', 'negative'}
        Where it acts, [-]

    Returns
    -------
    Candidate
        The same form with its extra loss zero on the other side.

    """
    acts = negative if direction == 'negative' else ~negative

    def modify(*args: float) -> Modifier:
        mod = candidate.modify(*args)
        return replace(mod, additive=np.where(acts, mod.additive, 0.0))
    return replace(candidate, modify=modify, direction=direction)


def negative_rows(parts: Parts) -> np.ndarray:
    """Return which rows have dp = p_a - p_b < 0 (their frame's sign is -1)."""
    return np.broadcast_to(np.asarray(parts.sign, dtype=float) < 0.0, parts.flow.shape)


MIN_SIDE = 0.05
"""Least share of the points (and at least 8) on each side of dp for a one-sided candidate."""


def two_sided(parts: Parts) -> bool:
    """Return whether the data hold both signs of dp, each with enough points to tell them."""
    negative = negative_rows(parts)
    least = max(8, int(np.ceil(MIN_SIDE * negative.size)))
    return bool(min(int(negative.sum()), int((~negative).sum())) >= least)


def maker(name: str, regressor: str = '', reference: float = 0.0) -> Callable[[float], Effect]:
    """Return coefficient -> ``Effect(name, coefficient, regressor, reference)``."""
    def make(coefficient: float) -> Effect:
        return Effect(name, coefficient, regressor, reference)
    return make


def finite(value: Any, where: str) -> float:
    """Return `value` as a float, or raise ConfigError naming `where` if it is no finite number."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        msg = f'{where} = {value!r}: expected a finite number'
        raise ConfigError(msg)
    return float(value)


def varies(x: FloatArray | None) -> bool:
    """Return whether a regressor is finite and varies enough to be fitted."""
    return bool(x is not None and np.all(np.isfinite(x))
                and np.ptp(x) > MIN_SPREAD * np.max(np.abs(x)) > 0.0)


def why_not(x: FloatArray | None) -> str:
    """Say why a regressor was not offered."""
    if x is None:
        return 'not measured'
    if not np.all(np.isfinite(x)):
        return 'has missing values'
    return 'does not vary enough'


def per_unit(x: FloatArray) -> float:
    """Return the coefficient that makes `x` contribute 1 l/min at its largest magnitude."""
    return float(LPM / max(np.max(np.abs(x)), 1e-300))


class EffectKind:
    """
    One kind of effect; subclass it in a new file of this package (see doc/effects.md).

    The defaults describe an additive loss k f(n, dp_i) that reads no channel:
    a kind overrides what differs.
    """

    name: str = ''  # YAML id; a suffixed kind is written '<name>:<suffix>'
    suffixed: bool = False  # the id carries ':<suffix>'
    rank: int = 100  # place in the candidate library and in messages
    keys: tuple[str, ...] = ('regressor', 'coefficient')  # YAML keys it reads
    required: tuple[str, ...] = ('coefficient',)  # of which these must be there
    regressors: tuple[str, ...] = ()  # channels it may read, the default first
    reads_channel: bool = False  # the model needs its regressor's value
    drives_leakage: bool = False  # its channel is the pressure p_ex of eq. (24)'s leakage
    drifts: bool = False  # it changes the motor itself (a rebuilt model)
    sensor: str = ''  # the channel of an instrument error ('flow', 'speed')
    reverse: bool = False  # its loss() applies only while the shaft turns backwards (n < 0)
    directional: bool = False  # it may act for one sign of dp only (Effect.direction)
    bypass: bool = False  # its loss() is a valve across the ports: f(n, port dp), beside the
    # motor's chambers and channels (satmotor_ros.model.engine.valves)
    unit: str = '-'  # unit of the coefficient
    source: str = ''  # the physics or standard the term comes from
    evaluation: str = ''  # what the model does with it (written into the YAML)
    plant_parameters: tuple[PlantParameter, ...] = ()  # node parameters
    families: frozenset[str] | None = None  # model families it applies to; None: every one

    # -- YAML --------------------------------------------------------------------------

    def parse(self, name: str, doc: Mapping[str, Any], where: str) -> Effect:
        """Build the effect of YAML block `doc` (known keys only) named `name` at `where`."""
        values: dict[str, Any] = {k: finite(doc[k], f'{where}.{k}') for k in self.keys
                                  if k in doc and k not in ('regressor', 'law')}
        suffix = name.partition(':')[2]
        return Effect(name=name, regressor=self.regressor(suffix, doc.get('regressor'), where),
                      **values)

    def regressor(self, suffix: str, value: Any, where: str) -> str:
        """Return the regressor a YAML block names (or the kind's default), checked."""
        if not self.regressors:
            return '' if value is None else str(value)
        value = self.regressors[0] if value is None else value
        if value not in self.regressors:
            msg = f'{where}.regressor = {value!r}: use {" or ".join(self.regressors)}'
            raise ConfigError(msg)
        return str(value)

    def to_mapping(self, effect: Effect) -> dict[str, Any]:
        """Return the YAML block of an effect (the inverse of :meth:`parse`)."""
        block: dict[str, Any] = {}
        for key in self.keys:
            value = getattr(effect, key) if hasattr(effect, key) else effect.option(key)
            if key == 'regressor' and not value:
                continue
            block[key] = value
        return block

    def named(self, effect: Effect) -> str:
        """
        Return the effect's one name for people: its id with its direction (:attr:`Effect.key`).

        Every output that names a calibrated or loaded effect (the command's summary line,
        the reports, ``calibration.json``'s and ``validation.json``'s ``name``) takes it from
        here, through :func:`satmotor_ros.model.effects.effect_name`; a kind whose law has a
        place of its own (a valve's crack pressure) adds it.
        """
        return effect.key

    # -- the model -----------------------------------------------------------------------

    def coefficients(self, effect: Effect, coef: LossCoefficients) -> LossCoefficients:
        """Return the coefficient set's numbers for a model that carries `effect`."""
        return coef

    def condition(self, effect: Effect, x: float, now: Conditions) -> Conditions:
        """Return the motor the effect asks for at its channel's value `x`."""
        return now

    def loss(self, effect: Effect) -> Loss | None:
        """Return f(n [rad/s], dp_i [Pa]) -> extra loss in Q_vl [m^3/s], or None."""
        return None

    def reads(self, effect: Effect) -> tuple[str, ...]:
        """
        Name the quantities the effect's law reads: the keys of its ``fitted_range``.

        ``dp_i`` [Pa] and ``speed`` [rad/s] (magnitudes) for a loss f(n, dp_i),
        the instrument's channel (``flow`` [m^3/s] or ``speed``) for a sensor
        error, the regressor's channel (gauge Pa, degC, s, rev) for a kind that
        reads one.
        """
        if self.sensor:
            return (self.sensor,)
        if self.reads_channel:
            return (effect.regressor,)
        return ('dp_i', 'speed') if self.loss(effect) is not None else ()

    def channels(self, effect: Effect) -> tuple[str, ...]:
        """Name the measured channels the model needs for `effect` (its regressor's, or none)."""
        return (effect.regressor,) if self.reads_channel else ()

    def channel_at(self, effect: Effect, reverse: bool) -> str:
        """Name the channel :meth:`condition` reads while the flow runs forward or `reverse`."""
        return effect.regressor

    def sensor_error(self, effect: Effect) -> SensorError | None:
        """Return what the effect does to an instrument, or None for a motor effect."""
        return None

    # -- calibration ---------------------------------------------------------------------

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """
        Build the candidates of this kind the data can test.

        Parameters
        ----------
        data : CandidateData
            Components, channels and the viscosity law at the points, [-]

        Returns
        -------
        list of Candidate
            The candidates.
        list of str
            Why others were not offered.

        """
        unit_loss = self.loss(Effect(self.name, 1.0))
        if unit_loss is None:
            return [], []
        x = np.asarray(unit_loss(data.parts.speed, data.parts.dp_i), dtype=float)
        return [additive(self.name, '', self.unit, self.source, x)], []

    # -- the plant and synthetic data ----------------------------------------------------

    def inject(self, effect: Effect, into: PlantInjection) -> PlantInjection:
        """Return `into` with what the virtual motor does with `effect` added."""
        if self.sensor:
            return into.add('sensors', effect)
        return into.add('drift' if self.drifts else 'motor', effect)

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Return the effect the node parameters ask for, or None when it is off."""
        return None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return the node parameter values (without prefix) that give `effect`."""
        return {p.name: p.default for p in self.plant_parameters}

    def bind(self, effect: Effect, law: ViscosityLaw, reference_temperature: float) -> Effect:
        """Return `effect` with what it left to the plant's liquid filled in."""
        return effect

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """
        Build the effect a synthetic injection of `magnitude` stands for.

        Parameters
        ----------
        name : str
            Effect id, [-]
        magnitude : float
            By default the largest extra loss it causes at the points, [m^3/s]
        regressor : str
            Channel or expression, '' for the kind's default, [-]
        data : Synthetic
            The operating points, [-]

        Returns
        -------
        Effect
            The effect to inject.

        """
        regressor = regressor or (self.regressors or (name.partition(':')[2],))[0]
        unit_loss = self.loss(Effect(name, 1.0, regressor))
        if unit_loss is None:
            return Effect(name, magnitude, regressor)
        x = np.asarray(unit_loss(data.speed, data.dp_i), dtype=float)
        return Effect(name, magnitude / max(float(np.max(np.abs(x))), 1e-300), regressor)


def additive(effect: str, regressor: str, unit: str, source: str, x: FloatArray,
             bounds: tuple[float, float] = (-np.inf, np.inf),
             values: FloatArray | None = None,
             make: Callable[[float], Effect] | None = None) -> Candidate:
    """
    Build a candidate that adds k x to the loss.

    Parameters
    ----------
    effect : str
        Effect id, [-]
    regressor : str
        Its regressor, [-]
    unit : str
        Unit of k, [-]
    source : str
        Where the term comes from, [-]
    x : ndarray
        The design column, [m^3/s per unit of k]
    bounds : tuple of float
        Physical range of k, [unit]
    values : ndarray, optional
        The regressor to plot; `x` when omitted, [-]
    make : callable, optional
        k -> the effect, [-]

    Returns
    -------
    Candidate
        The candidate.

    """
    return Candidate(effect, regressor, unit, source, x if values is None else values,
                     lambda k: Modifier(additive=k * x), per_unit(x), bounds, make=make)


__all__ = ['Candidate', 'CandidateData', 'Conditions', 'Effect', 'EffectKind', 'KINDS',
           'Modifier', 'PlantInjection', 'PlantParameter', 'SensorError', 'Shape', 'Synthetic',
           'additive', 'DIRECTIONS', 'finite', 'maker', 'negative_rows', 'one_sided', 'per_unit',
           'two_sided', 'varies', 'why_not']
