# SPDX-License-Identifier: Apache-2.0
"""
What a model family provides, and the composition shared by the families without a Delta q law.

A family is one loss model of the paper: its equations (a module of kernels),
its coefficient dataclass, and a :class:`Family` object that composes the
kernels for one motor and liquid into the callables the point path and the
array maps use (the interface of :class:`~.sliwinski2017.composition.Equations`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any, NamedTuple, Protocol

from satmotor_ros.model._numeric import maximum, minimum
from satmotor_ros.model._typing import FloatArray, Real
from satmotor_ros.model.coefficients import CoefficientSet, Liquid, MotorGeometry, ValidRange
from satmotor_ros.model.errors import ModelError
from satmotor_ros.model.results import LossBreakdown
from satmotor_ros.model.units import CM3_PER_REV


Residual = Callable[[Real], tuple[Real, Real]]
"""x -> (f(x), df/dx) for :mod:`satmotor_ros.model.engine.solve`."""

_TINY_DROP = 1e-300  # [Pa]; below the resolution of any dp_i but 0

SM_DISPLACEMENT = 32.94 * CM3_PER_REV
"""The SM-0,75/25's q_t, 32.94 cm^3/rev: the motor the defaults were fitted on, [m^3/rad]."""


class FamilyModel(Protocol):
    """What :meth:`Family.linear_losses` reads of a model (``MotorModel``, one layer up)."""

    @property
    def coef(self) -> Any:
        """Return the family's coefficients, [-]."""

    @property
    def equations(self) -> Any:
        """Return the family's composed equations, [-]."""

    def breakdown(self, speed: FloatArray, dp_i: FloatArray,
                  p_ex: FloatArray | float = 0.0) -> LossBreakdown:
        """Return the loss components at (n, dp_i), eq. (31), [m^3/s]."""


class LinearPart(NamedTuple):
    """
    One named component of Q_vl that is linear in the coefficients it names.

    A fitter may scale each part by a free factor: the part's loss times the
    factor is the loss of the coefficients times the factor
    (:meth:`Family.scaled` writes the factors back).
    """

    name: str  # e.g. 'leakage'
    source: str  # the equations, e.g. 'eqs. (20)-(23)'
    coefficients: tuple[str, ...]  # fields of the coefficient dataclass a factor multiplies
    speed_exponent: float  # the part ~ n^e at a fixed dp_i (1: ~n, 0.5, 0: no n) [-]


@dataclass(frozen=True)
class Bounds:
    """The constants every family gives the point path and the maps (``eqs.derived``)."""

    qt: float  # displacement q_t/(2 pi) [m^3/rad]
    dp_limit: float  # chamber drop beyond which the equations stop being physical [Pa]
    dp_max: float  # validated range: largest chamber drop [Pa]
    speed_max: float  # validated range: largest speed [rad/s]
    dp_min: float  # validated range: smallest chamber drop [Pa]
    speed_min: float  # validated range: smallest speed [rad/s]
    liquid_extrapolated: bool  # the liquid's viscosity is outside the fitted span


def bounds(geometry: MotorGeometry, coefficient_set: CoefficientSet, valid_range: ValidRange,
           liquid: Liquid, dp_limit: float) -> Bounds:
    """
    Collect a model's range constants.

    Parameters
    ----------
    geometry : MotorGeometry
        The motor, [-]
    coefficient_set : CoefficientSet
        The coefficients and the viscosity span they were fitted over, [-]
    valid_range : ValidRange
        Range the coefficients were validated over, [-]
    liquid : Liquid
        The working liquid, [-]
    dp_limit : float
        The family's limit of the chamber drop, [Pa]

    Returns
    -------
    Bounds
        The constants.

    """
    low, high = coefficient_set.fitted_viscosity
    nu = liquid.kinematic_viscosity
    return Bounds(geometry.displacement, dp_limit, valid_range.dp_max, valid_range.speed_max,
                  valid_range.dp_min, valid_range.speed_min,
                  not low * (1.0 - 1e-9) <= nu <= high * (1.0 + 1e-9))


class OwnLaw:
    """
    The stand-in for a Delta q law in a family that has none: no floor, no sharing.

    Parameters
    ----------
    name : str
        ``'eqN'``: the equation messages cite, [-]
    closed_form : bool
        Whether n(Q, dp_i) has a closed form, [-]

    """

    has_floor = False
    shares = False
    max_floor = 0.0

    def __init__(self, name: str, closed_form: bool) -> None:
        """Keep the name and whether the speed has a closed form."""
        self.name, self.closed_form = name, closed_form

    def floor(self, dp_i: Real) -> Real:
        """Return the lowest speed the equations are used at: none, [rad/s]."""
        return 0.0 * dp_i


@dataclass(frozen=True)
class Terms:
    """
    A family's loss as a speed-independent leakage plus a speed-dependent part, with slopes.

    Each callable works on Python floats and on arrays alike. The leakage fills
    the ``flat_clearance`` and ``commutation`` slots of the breakdown, the
    speed-dependent part the ``compressibility``, ``deformation``, ``backlash``
    and ``inertia`` slots plus an unlocated rest that only ``total`` shows.
    """

    channel: Callable[[Real], Real]  # Q -> Delta p_ich [Pa]
    channel_slope: Callable[[Real], Real]  # Q -> d Delta p_ich / dQ [Pa*s/m^3]
    leak: Callable[[Real], tuple[Real, Real]]  # dp_i -> the two leakage slots [m^3/s]
    leak_slope: Callable[[Real], Real]  # dp_i -> d(their sum)/d dp_i [m^3/(s*Pa)]
    external: Callable[[Real], Real]  # p_ex -> Q_ex [m^3/s]
    moving: Callable[[Real, Real], tuple[Real, Real, Real, Real, Real]]  # (n, dp_i) -> 5 parts
    moving_slopes: Callable[[Real, Real], tuple[Real, Real]]  # (n, dp_i) -> d/dn, d/d dp_i
    closed_speed: Callable[[Real, Real, Real], Real] | None = None  # (Q, dp_i, leak) -> n


class SplitEquations:
    """
    The callables of :class:`~.sliwinski2017.composition.Equations`, from :class:`Terms`.

    Parameters
    ----------
    derived : object
        The family's constants; has the fields of :class:`Bounds`, [-]
    terms : Terms
        The family's loss, [-]
    law_name : str
        ``'eqN'``, the equation cited in solver messages, [-]
    linear : callable
        (n, dp_i, p_ex) -> the family's linear parts of Q_vl (:meth:`Family.linear_parts`), [-]

    """

    channel_drop: Callable[..., Any]
    chamber_drop: Callable[..., Any]
    leakage: Callable[..., Any]
    breakdown: Callable[..., Any]
    closed_form_speed: Callable[..., Any] | None
    speed_problem: Callable[..., Any]
    flow_problem: Callable[..., Any]
    linear: Callable[..., Any]

    def __init__(self, derived: Any, terms: Terms, law_name: str,
                 linear: Callable[..., tuple[Real, ...]]) -> None:
        """Bind the terms into the compositions, once per model."""
        self.derived, self.terms, self.linear = derived, terms, linear
        self.closed_form = terms.closed_speed is not None
        self.law = OwnLaw(law_name, self.closed_form)
        qt, limit = derived.qt, derived.dp_limit
        channel, channel_slope, leak, leak_slope = (terms.channel, terms.channel_slope,
                                                    terms.leak, terms.leak_slope)
        external, moving, moving_slopes = terms.external, terms.moving, terms.moving_slopes
        self.channel_drop = channel
        self.closed_form_speed = terms.closed_speed

        def chamber_drop(dp: Real, flow: Real) -> Real:
            return dp - channel(flow)

        def leakage(dp_i: Real, p_ex: Real) -> tuple[Real, Real, Real]:
            first, second = leak(dp_i)
            return first, second, external(p_ex)

        def breakdown(speed: Real, dp_i: Real, lost: Real) -> tuple[Real, Real, Real, Real, Real]:
            fc, dch, bl, ine, rest = moving(speed, dp_i)
            return fc, dch, bl, ine, lost + ((fc + dch) + (bl + ine) + rest)

        def speed_problem(flow: Real, dp_i: Real,
                          lost: Real) -> tuple[Real, Real, Residual[Real]]:
            def residual(speed: Real) -> tuple[Real, Real]:
                fc, dch, bl, ine, rest = moving(speed, dp_i)
                return (qt * speed + (lost + ((fc + dch) + (bl + ine) + rest)) - flow,
                        qt + moving_slopes(speed, dp_i)[0])
            return 0.0 * dp_i, maximum(flow - lost, 0.0) / qt, residual

        def flow_problem(speed: Real, dp: Real,
                         p_ex: Real) -> tuple[Real, Callable[[], Real], Residual[Real]]:
            dp_cap = minimum(dp, limit)
            base = qt * speed + external(p_ex)

            def absorbed(dp_i: Real) -> Real:
                first, second = leak(dp_i)
                fc, dch, bl, ine, rest = moving(speed, dp_i)
                out: Real = base + ((first + second) + ((fc + dch) + (bl + ine) + rest))
                return out

            def residual(flow: Real) -> tuple[Real, Real]:
                dp_i = dp_cap - channel(flow)
                dp_i *= dp_i > 0.0  # clipped at 0 where the channels take the whole drop
                slope = leak_slope(dp_i) + moving_slopes(speed, dp_i)[1]
                return (flow - absorbed(dp_i),
                        1.0 + (dp_i > 0.0) * (slope * channel_slope(flow)))
            return qt * speed, lambda: absorbed(dp_cap), residual

        self.chamber_drop, self.leakage, self.breakdown = chamber_drop, leakage, breakdown
        self.speed_problem, self.flow_problem = speed_problem, flow_problem


def inverse_dp(dp_i: Real) -> Real:
    """Return 1/dp_i, and a huge finite number at dp_i = 0 (whose parts are 0 there), [1/Pa]."""
    return 1.0 / (dp_i + _TINY_DROP)


class Family(ABC):
    """
    One loss model: its name, coefficients, composition and linear parts.

    Subclasses set the class attributes and implement :meth:`compose`,
    :meth:`linear_parts` and :meth:`default_coefficients`; :meth:`linear_losses`
    reads the composition's ``linear`` callable unless a family overrides it.
    """

    name = ''
    title = ''  # one line for help texts
    equations = ''  # the equations of the paper it implements, e.g. 'eqs. (29)-(30)'
    coefficients_type: type = object  # the frozen coefficient dataclass
    quantities: Mapping[str, tuple[str, str]] = {}  # YAML field -> (unit kind, SI unit)
    components: Mapping[str, str] = {}  # breakdown component it has -> label with its eq.
    laws: tuple[str, ...] = ('eq33',)  # the displacement_law names it accepts
    channel: tuple[str, ...] = ('c_t', 'c_l')  # coefficients the channel drop is linear in
    leakage: tuple[str, ...] = ('leakage',)  # linear parts that leak through gaps (wear)

    def check_law(self, law: str) -> None:
        """
        Refuse a Delta q law the family does not have.

        Parameters
        ----------
        law : str
            ``displacement_law``, [-]

        Raises
        ------
        ModelError
            Naming the law and the family.

        """
        if law not in self.laws:
            msg = (f'displacement_law = {law!r}: the {self.name} family has '
                   f'{" or ".join(map(repr, self.laws))} (eq. 39 is sliwinski2017 only)')
            raise ModelError(msg)

    @abstractmethod
    def compose(self, geometry: MotorGeometry, coefficient_set: CoefficientSet,
                valid_range: ValidRange, liquid: Liquid, law: str) -> Any:
        """
        Derive the constants and compose the family's equations for one motor and liquid.

        Parameters
        ----------
        geometry : MotorGeometry
            The motor, [-]
        coefficient_set : CoefficientSet
            The coefficients (of this family) and the liquid they were fitted on, [-]
        valid_range : ValidRange
            Range the coefficients were validated over, [-]
        liquid : Liquid
            The working liquid, [-]
        law : str
            Law of Delta q; one of :attr:`laws`, [-]

        Returns
        -------
        object
            The callables of :class:`~.sliwinski2017.composition.Equations`, its
            ``derived`` constants and ``law``.

        """

    @abstractmethod
    def linear_parts(self, coefficients: Any) -> tuple[LinearPart, ...]:
        """
        Return the components of Q_vl that are linear in (named) coefficients.

        Parameters
        ----------
        coefficients : dataclass
            Coefficients of this family (a part's speed exponent may depend on them), [-]

        Returns
        -------
        tuple of LinearPart
            The parts, in the order :meth:`linear_losses` gives them.

        """

    def linear_losses(self, model: FamilyModel, speed: FloatArray, dp_i: FloatArray,
                      p_ex: FloatArray | float = 0.0) -> dict[str, FloatArray]:
        """
        Return Q_vl at given (n, dp_i) as the named :meth:`linear_parts`; their sum is Q_vl.

        Parameters
        ----------
        model : FamilyModel
            A model of this family (without effects), [-]
        speed : ndarray
            Shaft speed n, [rad/s]
        dp_i : ndarray
            Chamber pressure drop, >= 0, [Pa]
        p_ex : float or ndarray
            Pressure driving the external leakage, [Pa]

        Returns
        -------
        dict of str to ndarray
            Each part by name, in :meth:`linear_parts` order, [m^3/s]

        """
        parts = model.equations.linear(speed, dp_i, p_ex)
        return dict(zip((p.name for p in self.linear_parts(model.coef)), parts))

    @abstractmethod
    def default_coefficients(self, packaged: CoefficientSet, displacement: float) -> Any:
        """
        Return the family's documented default coefficients for a motor and liquid.

        Parameters
        ----------
        packaged : CoefficientSet
            The SM-0,75/25's set for the liquid (its Table 1 coefficients, for
            ``sliwinski2017``), [-]
        displacement : float
            The motor's displacement q_t/(2 pi), [m^3/rad]

        Returns
        -------
        dataclass
            The coefficients, to be calibrated.

        """

    def scaled(self, coefficients: Any, factors: Mapping[str, float]) -> Any:
        """
        Scale the coefficients of the named linear parts by factors (what a fit found).

        Parameters
        ----------
        coefficients : dataclass
            Coefficients of this family, [-]
        factors : mapping of str to float
            Part name -> factor; a part not named keeps its coefficients, [-]

        Returns
        -------
        dataclass
            The scaled coefficients.

        Raises
        ------
        ModelError
            For a part the family does not have.

        """
        parts = {p.name: p for p in self.linear_parts(coefficients)}
        changes: dict[str, float] = {}
        for name, factor in factors.items():
            if name not in parts:
                msg = (f'{self.name} has no linear part {name!r} '
                       f'(has: {", ".join(parts)})')
                raise ModelError(msg)
            for field in parts[name].coefficients:
                changes[field] = getattr(coefficients, field) * float(factor)
        return replace(coefficients, **changes)
