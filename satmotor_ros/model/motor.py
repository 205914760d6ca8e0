# SPDX-License-Identifier: Apache-2.0
"""
The motor model: loss breakdown, forward map Q(n, dp) and inverse map n(Q, dp).

:class:`MotorModel` is a façade over one motor, one coefficient set and one
liquid, in the model family its coefficients belong to (:mod:`.families`;
the other families compose their own equations into the same callables). In
the ``sliwinski2017`` family :mod:`.derived` holds the constants of the
equations, :mod:`.laws` the two laws of Delta q, :mod:`.composition` composes
the equation functions,
:mod:`.inverse` and :mod:`.forward` are the array maps (screened by
:mod:`.screening`, evaluated by :mod:`.batch`), and :mod:`.point` the
single-point path. Every array map screens its inputs element by element:
with ``errors='raise'`` (the default) the first bad element raises
:class:`InvalidInputError` naming the argument, index and value; with
``errors='mask'`` bad elements come back as NaN and are flagged in
``status`` (see :class:`PointStatus`) while the rest of the batch is computed.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import replace
from typing import Any, Literal

import numpy as np

from satmotor_ros.model._typing import ArrayLike, FloatArray, Real
from satmotor_ros.model.coefficients import CoefficientSet, Liquid, MotorGeometry, ValidRange
from satmotor_ros.model.effects import check_effects, Effect, kind_of, true_flow, true_speed
from satmotor_ros.model.engine.conditioned import ConditionedModel, map_points
from satmotor_ros.model.engine.core import ModelCore
from satmotor_ros.model.engine.forward import absorbency_map
from satmotor_ros.model.engine.inverse import speed_map
from satmotor_ros.model.engine.point import as_float, invalid_point
from satmotor_ros.model.engine.quadrants import chamber_drop, Channels, Quadrants, signed_map
from satmotor_ros.model.engine.screening import Errors
from satmotor_ros.model.engine.valves import Valves
from satmotor_ros.model.errors import ModelError
from satmotor_ros.model.families import DEFAULT_FAMILY, Family
from satmotor_ros.model.families.defaults import default_motor
from satmotor_ros.model.io.config import load_motor, MotorSpec
from satmotor_ros.model.results import LossBreakdown, OperatingPoints, Point, PointStatus

DisplacementLaw = Literal['eq33', 'eq39']


def _derived(name: str, doc: str) -> property:
    """Return a read-only property that reads `name` off the model's derived constants."""
    return property(lambda model: getattr(model.derived, name), doc=doc)


def _point_args(name: str, value: object, dp: object, dp_i: object,
                p_ex: object) -> tuple[float, bool, float, float]:
    """
    Check one point's arguments, as floats: `value` (flow or speed), port, drop and p_ex.

    The drop is `dp` between the ports (port True) or `dp_i` in the chambers;
    exactly one of them is given.
    """
    if dp_i is None and dp is not None:
        port, drop = True, dp if type(dp) is float else as_float('dp', dp)
    elif dp is None and dp_i is not None:
        port, drop = False, dp_i if type(dp_i) is float else as_float('dp_i', dp_i)
    else:
        raise ModelError('give exactly one of dp (between the ports) and dp_i (chambers)')
    value = value if type(value) is float else as_float(name, value)
    return value, port, drop, p_ex if type(p_ex) is float else as_float('p_ex', p_ex)


class _Magnitudes:
    """The model's single-point path at magnitudes, for :class:`Quadrants`."""

    def __init__(self, core: ModelCore, conditioned: ConditionedModel | None) -> None:
        self.qt = core.geometry.displacement
        self._point, self._conditioned = core.point, conditioned
        self._drop: Callable[[float], float] = core.eqs.channel_drop

    def speed(self, flow: float, dp: float, port: bool, p_ex: float, channels: Channels,
              reverse: bool, negative: bool) -> Point:
        if self._conditioned is not None:
            return self._conditioned.speed_point(flow, dp, port, p_ex, channels, reverse,
                                                 negative)
        return self._point.speed(flow, dp, port, p_ex)

    def absorbency(self, speed: float, dp: float, port: bool, p_ex: float,
                   flow_guess: float | None, channels: Channels, reverse: bool,
                   negative: bool) -> Point:
        if self._conditioned is not None:
            return self._conditioned.absorbency_point(speed, dp, port, p_ex, flow_guess,
                                                      channels, reverse, negative)
        return self._point.absorbency(speed, dp, port, p_ex, flow_guess)

    def channel_drop(self, p_ex: float, channels: Channels) -> Callable[[float], float]:
        if self._conditioned is not None:
            return self._conditioned.channel_drop(p_ex, channels)
        return self._drop


class MotorModel:
    """
    The volumetric-loss and speed model of one motor on one liquid, in one model family.

    The family is the one the coefficients belong to (:attr:`family`); every
    family gives the same results, statuses and guarantees.

    Every map takes signed flow, speed and pressure drops (four quadrants, see
    :mod:`.quadrants`): positive flow enters port A, dp = p_a - p_b, and the
    losses run from the higher- to the lower-pressure port.

    Parameters
    ----------
    geometry : MotorGeometry
        Motor geometry, [-]
    coefficient_set : CoefficientSet
        Loss coefficients and the liquid they were fitted on, [-]
    valid_range : ValidRange
        Range the coefficients were validated over, [-]
    liquid : Liquid, optional
        Working liquid; the set's own liquid when omitted. Another liquid keeps
        the set's fitted coefficients and changes nu, rho and the
        compressibility share of C (eqs. 9-11), [-]
    displacement_law : {'eq33', 'eq39'}
        Delta q from the physical eq. (33) (default) or the empirical eq. (39); the
        other families have their own equations and accept the default only, [-]
    name : str
        Name of the motor, for reports, [-]

    Examples
    --------
    >>> from satmotor_ros.model.units import LPM, MPA, RPM
    >>> oil = MotorModel.default('oil')
    >>> op = oil.speed(5 * LPM, dp_i=25 * MPA)
    >>> round(float(op.speed) / RPM, 1)
    133.2

    """

    def __init__(self, geometry: MotorGeometry, coefficient_set: CoefficientSet,
                 valid_range: ValidRange, liquid: Liquid | None = None,
                 displacement_law: DisplacementLaw = 'eq33', name: str = 'motor') -> None:
        """Derive the liquid-dependent coefficients once."""
        self.name = name
        self.geometry = geometry
        self.coefficient_set = coefficient_set
        self.valid_range = valid_range
        self.liquid = liquid if liquid is not None else coefficient_set.liquid
        self.coef = coefficient_set.coefficients
        self.displacement_law = displacement_law
        core = ModelCore(geometry, coefficient_set, valid_range, self.liquid, displacement_law)
        self.family: Family = core.family
        self.derived, self.law = core.derived, core.eqs.law
        self._equations, self._point = core.eqs, core.point
        self.effects = coefficient_set.effects
        self._valves = Valves(self.effects)
        inside = any(not kind_of(e).bypass for e in self.effects)  # not only port valves
        self._conditioned = ConditionedModel(core) if inside else None
        self.channels = self._conditioned.channels if self._conditioned else ()
        self._quadrants = Quadrants(_Magnitudes(core, self._conditioned))

    # constants of the equations for this liquid, read from :attr:`derived`
    c_fc_beta = _derived('c_fc_beta', 'C_fc*beta_l of eq. (11) for this liquid, [1/(MPa*rev)].')
    c_dch = _derived('c_dch', 'C_dch of eq. (12), [1/(MPa*rev)].')
    c_b = _derived('c_b', 'C_b of eq. (13), [1/(MPa*rev)].')
    c_lumped = _derived('c_lumped', 'C of eq. (33) for this liquid (``coef.c`` is the fitted '
                        'one), [1/(MPa*rev)].')
    dp_limit = _derived('dp_limit', 'Chamber drop where eq. (1) would start to fall with '
                        'pressure, [Pa].')

    @property
    def equations(self) -> Any:
        """Return the composed equations of the model's family (as ``Equations`` has them)."""
        return self._equations

    @classmethod
    def from_spec(cls, spec: MotorSpec, coefficients: str = 'oil', liquid: Liquid | None = None,
                  displacement_law: DisplacementLaw = 'eq33') -> MotorModel:
        """
        Build a model from a loaded :class:`MotorSpec`.

        Parameters
        ----------
        spec : MotorSpec
            The motor, [-]
        coefficients : str
            Name of the coefficient set, e.g. ``'oil'`` or ``'water'``, [-]
        liquid : Liquid, optional
            A user liquid run on that set, [-]
        displacement_law : {'eq33', 'eq39'}
            Law for Delta q, [-]

        Returns
        -------
        MotorModel
            The model.

        """
        if coefficients not in spec.sets:
            msg = (f'coefficient set {coefficients!r} is not in {spec.source} '
                   f'(has: {", ".join(spec.sets)})')
            raise ModelError(msg)
        return cls(spec.geometry, spec.sets[coefficients], spec.valid_range, liquid,
                   displacement_law, spec.name)

    @classmethod
    def default(cls, coefficients: str = 'oil',
                displacement_law: DisplacementLaw = 'eq33') -> MotorModel:
        """
        Build the packaged SM-0,75/25 model for oil or water.

        Parameters
        ----------
        coefficients : str
            ``'oil'`` or ``'water'``, [-]
        displacement_law : {'eq33', 'eq39'}
            Law for Delta q, [-]

        Returns
        -------
        MotorModel
            The SM-0,75/25 on that set.

        """
        return cls.from_spec(load_motor(), coefficients, None, displacement_law)

    @classmethod
    def for_displacement(cls, displacement: float | None = None, family: str = DEFAULT_FAMILY,
                         coefficients: str = 'oil') -> MotorModel:
        """
        Build a motor with no YAML: a family's documented defaults, to be calibrated.

        Parameters
        ----------
        displacement : float, optional
            Displacement q_t/(2 pi); the SM-0,75/25's when omitted, [m^3/rad]
        family : {'sliwinski2017', 'balawender', 'paszota'}
            The model family, [-]
        coefficients : {'oil', 'water'}
            The liquid (the packaged SM-0,75/25's), [-]

        Returns
        -------
        MotorModel
            The model (:func:`~satmotor_ros.model.families.defaults.default_motor`).

        Examples
        --------
        >>> from satmotor_ros.model.units import CM3_PER_REV, LPM, MPA, RPM
        >>> f11 = MotorModel.for_displacement(4.92 * CM3_PER_REV, 'paszota')
        >>> op = f11.speed_point(10 * LPM, dp_i=10 * MPA)
        >>> 1900 < op.speed / RPM < 2032
        True

        """
        return cls.from_spec(default_motor(family, displacement), coefficients)

    # -- public maps -----------------------------------------------------------------------

    def speed(self, flow: ArrayLike, dp: ArrayLike | None = None, *,
              dp_i: ArrayLike | None = None, p_ex: ArrayLike = 0.0, errors: Errors = 'raise',
              method: Literal['auto', 'iterative'] = 'auto',
              channels: Mapping[str, ArrayLike] | None = None) -> OperatingPoints:
        """
        Compute the effective speed and losses from flow and pressure (inverse map).

        With eq. (33) this is the closed form of eq. (40); with eq. (39), or
        with ``method='iterative'``, eq. (36) is solved for n numerically.

        Parameters
        ----------
        flow : float or ndarray
            Flow into the motor Q, [m^3/s]
        dp, dp_i : float or ndarray, optional
            Pressure drop between the ports (eqs. (34)-(35) give dp_i) or in the
            working chambers: exactly one of them, [Pa]
        p_ex : float or ndarray
            Pressure driving the external leakage, eq. (24), [Pa]
        errors : {'raise', 'mask'}
            Raise on the first invalid element, or return it as NaN, [-]
        method : {'auto', 'iterative'}
            Force the numerical solver even where eq. (40) applies, [-]
        channels : mapping of str to float or ndarray, optional
            Measured channels the coefficient set's effects need (see
            :attr:`channels`; gauge Pa, degC, s, rev), [-]

        Returns
        -------
        OperatingPoints
            Speed, speed loss, losses and status per element.

        """
        dp_name, dp_value = self._which_dp(dp, dp_i)
        if method not in ('auto', 'iterative'):
            msg = f"method = {method!r}: use 'auto' or 'iterative'"
            raise ModelError(msg)
        if self.effects:  # the single-point path, element by element
            return map_points(
                lambda q, d, p, c: self.speed_point(q, **{dp_name: d}, p_ex=p, channels=c),
                ('flow', flow), (dp_name, dp_value), p_ex, channels, self.geometry, errors)
        closed_form = self.law.closed_form and method == 'auto'
        port = dp_name == 'dp'
        return signed_map(
            lambda q, d, p: self._quadrants.speed(q, d, port, p, None),
            lambda q, d, p, err: speed_map(self._equations, self.geometry, q, dp_name, d, p,
                                           err, closed_form),
            ('flow', flow), (dp_name, dp_value), p_ex, self.geometry, errors)

    def absorbency(self, speed: ArrayLike, dp: ArrayLike | None = None, *,
                   dp_i: ArrayLike | None = None, p_ex: ArrayLike = 0.0,
                   errors: Errors = 'raise',
                   channels: Mapping[str, ArrayLike] | None = None) -> OperatingPoints:
        """
        Compute the flow the motor absorbs at a speed and pressure (forward map).

        With `dp_i` this is eq. (36) directly. With port `dp`, the channel drop
        of eq. (35) depends on the very flow being computed, so eq. (36) and
        eq. (34) are solved together numerically.

        Parameters
        ----------
        speed : float or ndarray
            Shaft speed n, [rad/s]
        dp, dp_i : float or ndarray, optional
            Pressure drop between the ports or in the working chambers: exactly one, [Pa]
        p_ex : float or ndarray
            Pressure driving the external leakage, eq. (24), [Pa]
        errors : {'raise', 'mask'}
            Raise on the first invalid element, or return it as NaN, [-]
        channels : mapping of str to float or ndarray, optional
            Measured channels the coefficient set's effects need, [-]

        Returns
        -------
        OperatingPoints
            Absorbency, losses and status per element.

        """
        dp_name, dp_value = self._which_dp(dp, dp_i)
        if self.effects:  # the single-point path, element by element
            return map_points(
                lambda n, d, p, c: self.absorbency_point(n, **{dp_name: d}, p_ex=p, channels=c),
                ('speed', speed), (dp_name, dp_value), p_ex, channels, self.geometry, errors)
        port = dp_name == 'dp'
        return signed_map(
            lambda n, d, p: self._quadrants.absorbency(n, d, port, p, None, None),
            lambda n, d, p, err: absorbency_map(self._equations, self.geometry, n, dp_name, d,
                                                p, err),
            ('speed', speed), (dp_name, dp_value), p_ex, self.geometry, errors)

    @staticmethod
    def _which_dp(dp: ArrayLike | None, dp_i: ArrayLike | None) -> tuple[str, ArrayLike]:
        if dp is not None and dp_i is None:
            return 'dp', dp
        if dp_i is not None and dp is None:
            return 'dp_i', dp_i
        raise ModelError('give exactly one of dp (between the ports) and dp_i (chambers)')

    def breakdown(self, speed: ArrayLike, dp_i: ArrayLike, p_ex: ArrayLike = 0.0,
                  errors: Errors = 'raise',
                  channels: Mapping[str, ArrayLike] | None = None) -> LossBreakdown:
        """
        Compute the loss components at given speed and chamber pressure drop, eq. (31).

        Parameters
        ----------
        speed : float or ndarray
            Shaft speed n, [rad/s]
        dp_i : float or ndarray
            Pressure drop in the working chambers, [Pa]
        p_ex : float or ndarray
            Pressure driving the external leakage, eq. (24), [Pa]
        errors : {'raise', 'mask'}
            Raise on the first invalid element, or return it as NaN, [-]
        channels : mapping of str to float or ndarray, optional
            The effects' measured channels, as :meth:`absorbency` reads them, [-]

        Returns
        -------
        LossBreakdown
            Every component of eq. (31) and their total (with any extra loss of
            an effect), [m^3/s]

        """
        return self.absorbency(speed, dp_i=dp_i, p_ex=p_ex, errors=errors,
                               channels=channels).losses

    # -- single points ---------------------------------------------------------------------

    def speed_point(self, flow: float, dp: float | None = None, *, dp_i: float | None = None,
                    p_ex: float = 0.0, channels: Mapping[str, float] | None = None) -> Point:
        """
        Compute the inverse map n(Q, dp) at one operating point, on Python floats.

        Equal to :meth:`speed` with ``errors='mask'`` to 1e-12, at a few
        microseconds a call. Bad values never raise: the point comes back NaN
        with its :class:`PointStatus` flags.

        Parameters
        ----------
        flow : float
            Flow into the motor Q, [m^3/s]
        dp, dp_i : float, optional
            Pressure drop between the ports or in the working chambers: exactly one, [Pa]
        p_ex : float
            Pressure driving the external leakage, eq. (24), [Pa]
        channels : mapping of str to float, optional
            Measured channels the coefficient set's effects need, [-]

        Returns
        -------
        Point
            The speed n at the flow Q, with its losses and status.

        Raises
        ------
        ModelError
            If not exactly one of `dp` and `dp_i` is given, an argument is not a
            number, or an effect's channel is missing.

        """
        if dp_i is None and type(dp) is float and type(flow) is float and type(p_ex) is float:
            port, value = True, dp  # the usual call: skip the checks
        else:
            flow, port, value, p_ex = _point_args('flow', flow, dp, dp_i, p_ex)
        if self._valves:  # the motor's map at the flow the valves leave it
            return self._valves.speed(self._speed_at, flow, port, value, p_ex, channels)
        return self._speed_at(flow, port, value, p_ex, channels)

    def _speed_at(self, flow: float, port: bool, value: float, p_ex: float,
                  channels: Mapping[str, float] | None) -> Point:
        """Return the motor's n(Q, dp) at one point, without the port valves."""
        try:
            if not (flow >= 0.0 and value >= 0.0):  # any other quadrant, or NaN
                return self._quadrants.speed(flow, value, port, p_ex, channels)
            if self._conditioned is not None:
                return self._conditioned.speed_point(flow, value, port, p_ex, channels)
            return self._point.speed(flow, value, port, p_ex)
        except (OverflowError, ZeroDivisionError):  # float arithmetic past its range
            return invalid_point(int(PointStatus.BEYOND_LIMIT))

    def absorbency_point(self, speed: float, dp: float | None = None, *,
                         dp_i: float | None = None, p_ex: float = 0.0,
                         flow_guess: float | None = None,
                         channels: Mapping[str, float] | None = None) -> Point:
        """
        Compute the forward map Q(n, dp) at one operating point, on Python floats.

        Equal to :meth:`absorbency` with ``errors='mask'`` to 1e-12. With a port
        `dp`, eqs. (34)-(36) are solved together; `flow_guess` (for instance
        the previous step's flow) starts that solve near its root.

        Parameters
        ----------
        speed : float
            Shaft speed n, [rad/s]
        dp, dp_i : float, optional
            Pressure drop between the ports or in the working chambers: exactly one, [Pa]
        p_ex : float
            Pressure driving the external leakage, eq. (24), [Pa]
        flow_guess : float, optional
            Starting estimate of Q for the coupled solve; ignored unless it is
            finite and above q_t*n, [m^3/s]
        channels : mapping of str to float, optional
            Measured channels the coefficient set's effects need, [-]

        Returns
        -------
        Point
            Q at n: the flow, the losses and the status flags.

        Raises
        ------
        ModelError
            If not exactly one of `dp` and `dp_i` is given, or an argument is not a number.

        """
        if dp_i is None and type(dp) is float and type(speed) is float and type(p_ex) is float:
            port, value = True, dp  # the usual call: skip the checks
        else:
            speed, port, value, p_ex = _point_args('speed', speed, dp, dp_i, p_ex)
        if flow_guess is not None and type(flow_guess) is not float:
            flow_guess = as_float('flow_guess', flow_guess)
        if self._valves:  # the motor's flow plus the valves'
            return self._valves.absorbency(self._absorbency_at, speed, port, value, p_ex,
                                           flow_guess, channels)
        return self._absorbency_at(speed, port, value, p_ex, flow_guess, channels)

    def _absorbency_at(self, speed: float, port: bool, value: float, p_ex: float,
                       flow_guess: float | None,
                       channels: Mapping[str, float] | None) -> Point:
        """Return the motor's Q(n, dp) at one point, without the port valves."""
        try:
            if not (speed >= 0.0 and value >= 0.0):  # any other quadrant, or NaN
                return self._quadrants.absorbency(speed, value, port, p_ex, flow_guess, channels)
            if self._conditioned is not None:
                return self._conditioned.absorbency_point(speed, value, port, p_ex, flow_guess,
                                                          channels)
            return self._point.absorbency(speed, value, port, p_ex, flow_guess)
        except (OverflowError, ZeroDivisionError):  # float arithmetic past its range
            return invalid_point(int(PointStatus.BEYOND_LIMIT))

    def breakdown_point(self, speed: float, dp_i: float, p_ex: float = 0.0,
                        channels: Mapping[str, float] | None = None) -> Point:
        """
        Compute the loss components at one speed and chamber pressure drop, eq. (31).

        Parameters
        ----------
        speed : float
            Shaft speed n, [rad/s]
        dp_i : float
            Pressure drop in the working chambers, [Pa]
        p_ex : float
            Pressure driving the external leakage, eq. (24), [Pa]
        channels : mapping of str to float, optional
            The effects' measured channels, as :meth:`absorbency_point` reads them, [-]

        Returns
        -------
        Point
            The operating point (its flow is the absorbency of eq. 36).

        """
        if not (type(speed) is float and type(dp_i) is float and type(p_ex) is float):
            speed, _, dp_i, p_ex = _point_args('speed', speed, None, dp_i, p_ex)
        if self._valves:
            return self._valves.absorbency(self._absorbency_at, speed, False, dp_i, p_ex, None,
                                           channels)
        return self._absorbency_at(speed, False, dp_i, p_ex, None, channels)

    def chamber_drop(self, dp: ArrayLike, flow: ArrayLike) -> FloatArray:
        """
        Compute the chamber drop of eqs. (34)-(35) for flows of either sign.

        The channel drop of eq. (35) runs with the flow: dp_i = dp - sign(Q)
        dp_ich(|Q|), so in pump mode the chambers deliver more than the ports.

        Parameters
        ----------
        dp : float or ndarray
            p_a - p_b at the ports, [Pa]
        flow : float or ndarray
            Flow entering port A, [m^3/s]

        Returns
        -------
        ndarray
            dp_i, unclipped (of the other sign where the channels take more than dp), [Pa]

        """
        return chamber_drop(self._equations.channel_drop, np.asarray(dp, dtype=float),
                            np.asarray(flow, dtype=float))

    # -- instruments -----------------------------------------------------------------------

    def true_flow(self, reading: Real) -> Real:
        """
        Return the flow through the motor from a flowmeter reading (sensor effects).

        Parameters
        ----------
        reading : float or ndarray
            What the flowmeter reads, [m^3/s]

        Returns
        -------
        float or ndarray
            The flow; the reading itself when the set has no flowmeter effect, [m^3/s]

        """
        return true_flow(self.effects, reading)

    def true_speed(self, reading: Real) -> Real:
        """
        Return the shaft speed from a speed-sensor reading (sensor effects).

        Parameters
        ----------
        reading : float or ndarray
            What the speed sensor reads, [rad/s]

        Returns
        -------
        float or ndarray
            The speed; the reading itself without a speed-sensor effect, [rad/s]

        """
        return true_speed(self.effects, reading)


def with_effects(model: MotorModel, effects: Iterable[Effect]) -> MotorModel:
    """
    Return the model with `effects` added to its coefficient set.

    Parameters
    ----------
    model : MotorModel
        The motor, [-]
    effects : iterable of Effect
        Motor effects to add, [-]

    Returns
    -------
    MotorModel
        The same motor, liquid and law, evaluating the effects (`model` when there are none).

    """
    effects = tuple(effects)
    if not effects:
        return model
    spec = model.coefficient_set
    coef = spec.coefficients
    for effect in effects:
        coef = kind_of(effect).coefficients(effect, coef)
    combined = check_effects((*spec.effects, *effects), 'effects', model.family.name)
    return type(model)(model.geometry, replace(spec, coefficients=coef, effects=combined),
                       model.valid_range, model.liquid, model.displacement_law, model.name)
