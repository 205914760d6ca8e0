# SPDX-License-Identifier: Apache-2.0
"""
Node parameters from a table: declared with descriptors, checked with a reason.

A node lists its parameters as :class:`ParamSpec` rows. :func:`declare` declares them
with a description that carries the unit and a range or a set of choices; a value from
a parameter file that violates its descriptor does not kill the node: the default is
used and the problem returned, for the node to report. :func:`check` rejects a set
request with a reason that names the parameter and the value; an on-set callback
returns its result, so that rclpy keeps the old value.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
import math
from typing import Any, TypeAlias

from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                SetParametersResult)
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.node import Node
from rclpy.parameter import AllowableParameterValue, Parameter
from satmotor_ros.model.coefficients import displacement_problem, DISPLACEMENT_RANGE
from satmotor_ros.model.families import FAMILY_NAMES
from satmotor_ros.options import DISPLACEMENT_LAWS, MotorOptions

RosParameter: TypeAlias = Parameter[AllowableParameterValue]
"""A parameter as rclpy hands it to the set-parameter callbacks."""


@dataclass(frozen=True)
class ParamSpec:
    """One parameter: default, meaning with unit, and what values it accepts."""

    name: str
    default: Any  # float, int, str or bool; sets the type
    description: str  # what it is, without the unit
    unit: str = '-'  # SI unit, shown as '[unit]'
    low: float | None = None  # inclusive range (numbers)
    high: float | None = None
    choices: tuple[str, ...] = ()  # allowed strings
    read_only: bool = False  # fixed after start
    check: Callable[[Any], str | None] | None = None  # extra test: a reason, or None

    def descriptor(self) -> ParameterDescriptor:
        """
        Build the parameter's descriptor.

        Returns
        -------
        ParameterDescriptor
            Description with unit, range or choices, read-only flag.

        """
        text = f'{self.description} [{self.unit}]'
        extra = f'one of: {", ".join(self.choices)}' if self.choices else ''
        # dynamic typing: a value of the wrong type reaches reason(), which names it
        desc = ParameterDescriptor(description=text, additional_constraints=extra,
                                   read_only=self.read_only, dynamic_typing=True)
        if isinstance(self.default, float) and self.low is not None and self.high is not None:
            desc.floating_point_range = [FloatingPointRange(
                from_value=float(self.low), to_value=float(self.high), step=0.0)]
        elif isinstance(self.default, int) and not isinstance(self.default, bool) \
                and self.low is not None and self.high is not None:
            desc.integer_range = [IntegerRange(from_value=int(self.low),
                                               to_value=int(self.high), step=1)]
        return desc

    def reason(self, value: Any) -> str | None:
        """
        Say why a value is not acceptable.

        Parameters
        ----------
        value : Any
            Proposed value, [unit of the parameter]

        Returns
        -------
        str or None
            The reason, naming the parameter and the value; None when it is acceptable.

        """
        kind = type(self.default)
        if kind is float:
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                return f'{self.name} = {value!r}: must be a number [{self.unit}]'
        elif not isinstance(value, kind) or isinstance(value, bool) != (kind is bool):
            return f'{self.name} = {value!r}: must be of type {kind.__name__}'
        if kind in (float, int) and self.low is not None and not (
                math.isfinite(value) and self.low <= value <= self.high):
            return (f'{self.name} = {value!r} {self.unit}: must be within '
                    f'[{self.low:g}, {self.high:g}]')
        if self.choices and value not in self.choices:
            return f'{self.name} = {value!r}: use one of {", ".join(self.choices)}'
        return self.check(value) if self.check is not None else None


def declare(node: Node, specs: Iterable[ParamSpec]) -> dict[str, str]:
    """
    Declare every parameter; an invalid override falls back to the default.

    Parameters
    ----------
    node : rclpy.node.Node
        The node, [-]
    specs : iterable of ParamSpec
        The table, [-]

    Returns
    -------
    dict
        Parameter name -> problem with its override (parameter file, command line), one
        line each.

    """
    problems = {}
    for spec in specs:
        try:
            node.declare_parameter(spec.name, spec.default, spec.descriptor())
            reason = spec.reason(node.get_parameter(spec.name).value)
        except (InvalidParameterValueException, InvalidParameterTypeException) as err:
            reason = f'{spec.name}: {str(err).splitlines()[0]}'
            node.declare_parameter(spec.name, spec.default, spec.descriptor(),
                                   ignore_override=True)
        if reason is not None:
            problems[spec.name] = f'{reason}; using the default {spec.default!r}'
            node.set_parameters([Parameter(spec.name, value=spec.default)])
    return problems


def declare_logged(node: Node, specs: Iterable[ParamSpec]) -> dict[str, str]:
    """Declare every parameter as :func:`declare` does, and log each problem as an error."""
    problems = declare(node, specs)
    for problem in problems.values():
        node.get_logger().error(f'parameter {problem}')
    return problems


def check(specs: Mapping[str, ParamSpec], params: Iterable[RosParameter]) -> SetParametersResult:
    """
    Check a set request against the table (for an on-set callback).

    Parameters
    ----------
    specs : mapping
        Name -> ParamSpec, [-]
    params : iterable of rclpy.parameter.Parameter
        The request, [-]

    Returns
    -------
    SetParametersResult
        Unsuccessful, with the first reason, if any value is not acceptable.

    """
    for param in params:
        spec = specs.get(param.name)
        reason = spec.reason(param.value) if spec is not None else None
        if reason is not None:
            return SetParametersResult(successful=False, reason=reason)
    return SetParametersResult(successful=True)


def check_proposed(specs: Mapping[str, ParamSpec], request: list[RosParameter],
                   current: Mapping[str, Any],
                   build: Callable[[dict[str, Any], set[str]], object],
                   errors: tuple[type[Exception], ...]) -> SetParametersResult:
    """
    Check a set request value by value (:func:`check`), then as the whole set it would make.

    Parameters
    ----------
    specs : mapping
        The table, name -> ParamSpec, [-]
    request : list of rclpy.parameter.Parameter
        The parameters the request sets, [-]
    current : mapping
        The node's values now, by name, [-]
    build : callable
        ``build(proposed, changed)``: raises one of `errors` where the values
        proposed (the names `changed` among them) would not make a working node, [-]
    errors : tuple of type
        What `build` raises on a bad set, [-]

    Returns
    -------
    SetParametersResult
        Unsuccessful, with the reason, where a value or the whole set is refused.

    """
    result = check(specs, request)
    if not result.successful:
        return result
    changed = {p.name: p.value for p in request if p.name in specs}
    try:
        build({**current, **changed}, set(changed))
    except errors as err:
        return SetParametersResult(successful=False, reason=str(err))
    return SetParametersResult(successful=True)


def values(node: Node, specs: Iterable[ParamSpec]) -> dict[str, Any]:
    """Return the current value of each parameter of the table `specs` on `node`, by name."""
    return {spec.name: node.get_parameter(spec.name).value for spec in specs}


def _displacement_reason(value: float) -> str | None:
    """Refuse a displacement no motor has (0 keeps meaning the motor file's)."""
    problem = displacement_problem(value) if value != 0.0 else None
    return None if problem is None else (f'displacement = {value!r} m^3/rad: {problem}; '
                                         "0: the motor file's")


MOTOR_PARAMETERS = (
    ParamSpec('liquid', MotorOptions.liquid, "coefficient set and its liquid: 'oil' or 'water' "
              'for the packaged SM-0,75/25, or any set of motor_file'),
    ParamSpec('viscosity', MotorOptions.viscosity, 'kinematic viscosity of a user liquid run '
              "on the set; 0: the set's own liquid", 'm^2/s', 0.0, 1.0e-2),
    ParamSpec('density', MotorOptions.density, "density of a user liquid; 0: the set's own",
              'kg/m^3', 0.0, 1.0e5),
    ParamSpec('bulk_modulus', MotorOptions.bulk_modulus,
              "bulk modulus of a user liquid; 0: the set's own", 'Pa', 0.0, 1.0e12),
    ParamSpec('motor_file', MotorOptions.motor_file, 'motor specification or calibrated '
              'coefficients YAML; empty: the packaged SM-0,75/25'),
    ParamSpec('family', MotorOptions.family, "model family; empty: the motor file's own "
              '(sliwinski2017 without one); without motor_file, the SM-0,75/25 or a motor of '
              "displacement with the family's default coefficients",
              choices=('', *FAMILY_NAMES)),
    ParamSpec('displacement', MotorOptions.displacement, 'displacement of a motor with no '
              "motor_file (the family's default coefficients, to be calibrated); 0: the "
              "motor file's", 'm^3/rad', 0.0, DISPLACEMENT_RANGE[1], check=_displacement_reason),
    ParamSpec('displacement_law', MotorOptions.displacement_law, 'change of displacement: '
              'physical eq. (33) or empirical eq. (39)', choices=DISPLACEMENT_LAWS),
)
"""The motor and liquid parameters every node declares (:class:`MotorOptions`, same names)."""

MOTOR_KEYS = tuple(spec.name for spec in MOTOR_PARAMETERS)
"""Their names: a change to any of them rebuilds the model."""


def motor_options(values: Mapping[str, Any]) -> MotorOptions:
    """
    Collect the motor and liquid parameters into options.

    Parameters
    ----------
    values : mapping
        Parameter name -> value (at least :data:`MOTOR_KEYS`), [SI]

    Returns
    -------
    MotorOptions
        The options; ``build_model()`` builds the model.

    """
    return MotorOptions(**{name: values[name] for name in MOTOR_KEYS})


def liquid_source(node: Node) -> str:
    """
    Say where the node's liquid came from, and log it once at start-up.

    A liquid left at its default is a guess about the user's rig: the INFO line says so
    and how to set it (issue 21).

    Parameters
    ----------
    node : rclpy.node.Node
        A node that declared the :data:`MOTOR_PARAMETERS`, [-]

    Returns
    -------
    str
        ``'parameter'`` when ``liquid`` was given (command line, parameter file, overrides),
        ``'default'`` otherwise.

    """
    liquid = node.get_parameter('liquid').value
    if 'liquid' in node._parameter_overrides:  # what the command line and files set
        node.get_logger().info(f'liquid: {liquid}')
        return 'parameter'
    node.get_logger().info(f'liquid: {liquid} (the default; set the liquid parameter)')
    return 'default'
