# SPDX-License-Identifier: Apache-2.0
"""
Parameter records of the virtual motor: lines, relief valve, shaft, heat, case, effects, fault.

Every record is frozen and checks its fields on construction; an error names the
field and the value. Each field carries its description, unit and closed range as
dataclass field metadata (:func:`parameter`), which the node's parameter
descriptors and ``config/virtual_motor.yaml`` are made from. Defaults describe a
small test rig around the SM-0,75/25 (doc/plant.md); no effect is injected
by default.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
import math
from typing import Any

from satmotor_ros.model.effects import check_effects, Effect, kind_of, PlantParameter, ranked
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA
from satmotor_ros.plant.errors import PlantError


def parameter(default: Any, description: str, unit: str = '-', low: float | None = None,
              high: float | None = None, choices: tuple[str, ...] = ()) -> Any:
    """
    Declare a record field with its description, unit and closed range.

    Parameters
    ----------
    default : Any
        Default value, [unit]
    description : str
        What it is, without the unit, [-]
    unit : str
        SI unit; ``'unit of the channel'`` for a sensor's noise and bias, [-]
    low, high : float, optional
        Closed range a number must lie in, [unit]
    choices : tuple of str
        Values a string may take (checked by its record), [-]

    Returns
    -------
    dataclasses.Field
        The field, with ``description``, ``unit``, ``range`` and ``choices`` in its metadata.

    """
    span = None if low is None else (low, high)
    return field(default=default, metadata={'description': description, 'unit': unit,
                                            'range': span, 'choices': choices})


class Bounded:
    """
    Base of the parameter records: construction checks each field's closed range.

    Every field declared with a ``range`` in its metadata (:func:`parameter`) must
    hold a finite number inside it.

    Raises
    ------
    PlantError
        Naming the first field outside its range and its value.

    """

    def __post_init__(self) -> None:
        """Reject values outside their range, naming the field."""
        for f in fields(self):  # type: ignore[arg-type]
            span = f.metadata.get('range')
            if span is None:
                continue
            low, high = span
            value = getattr(self, f.name)
            ok = (isinstance(value, (int, float)) and not isinstance(value, bool)
                  and math.isfinite(value) and low <= value <= high)
            if not ok:
                msg = (f'{type(self).__name__}.{f.name} = {value!r} is outside '
                       f'[{low:g}, {high:g}]')
                raise PlantError(msg)


@dataclass(frozen=True)
class LineParams(Bounded):
    """Inlet and outlet lines, tank and return line."""

    inlet_volume: float = parameter(
        0.2e-3, 'V_in, liquid volume between pump and motor', 'm^3', 1.0e-7, 1.0)
    outlet_volume: float = parameter(
        0.2e-3, 'V_out, liquid volume between motor and return valve', 'm^3', 1.0e-7, 1.0)
    tank_pressure: float = parameter(ATMOSPHERE, 'p_t, absolute', 'Pa', 1.0e3, 1.0e7)
    back_pressure: float = parameter(
        0.5 * MPA, 'p_b, return-line back pressure above p_t', 'Pa', 0.0, 1.0e7)
    return_conductance: float = parameter(
        40.0 * LPM / MPA, 'G_r, return valve slope', 'm^3/(s*Pa)', 1.0e-13, 1.0e-5)
    vapour_pressure: float = parameter(
        2.0e3, 'absolute floor of both lines (cavitation)', 'Pa', 0.0, 1.0e5)


@dataclass(frozen=True)
class ReliefParams(Bounded):
    """Relief valve from the inlet line to the tank, a proportional characteristic."""

    cracking_pressure: float = parameter(
        27.0 * MPA, 'p_cr, above tank pressure', 'Pa', 1.0e5, 4.5e7)
    conductance: float = parameter(
        40.0 * LPM / (2.0 * MPA), 'k_rv, flow per override', 'm^3/(s*Pa)', 1.0e-13, 1.0e-5)


@dataclass(frozen=True)
class ShaftParams(Bounded):
    """Shaft, its inertia and the hydro-mechanical (torque) losses."""

    inertia: float = parameter(0.01, 'J, motor and coupled load', 'kg*m^2', 1.0e-6, 1.0e3)
    viscous_friction: float = parameter(
        2.0e-3, 'b, torque per speed', 'N*m*s/rad', 0.0, 1.0e3)
    coulomb_friction: float = parameter(0.5, 'T_c, dry friction', 'N*m', 0.0, 1.0e4)
    pressure_friction: float = parameter(
        0.04, 'c_p, share of q_t*dp_i lost to friction', '-', 0.0, 0.9)
    locked: bool = parameter(False, 'shaft blocked by a brake: speed held at 0')


@dataclass(frozen=True)
class ThermalParams(Bounded):
    """Lumped heat balance of the liquid: every watt of loss heats it."""

    heat_capacity: float = parameter(4.0e4, 'C_th, liquid and metal', 'J/K', 1.0, 1.0e9)
    cooling: float = parameter(
        50.0, 'hA, heat loss to the ambient per kelvin', 'W/K', 0.0, 1.0e6)
    ambient: float = parameter(25.0, 'T_a, ambient temperature', 'degC', -50.0, 200.0)
    initial: float = parameter(40.0, 'liquid temperature at t = 0', 'degC', -50.0, 200.0)
    reference: float = parameter(
        40.0, "temperature of the liquid's nominal viscosity", 'degC', -50.0, 200.0)


@dataclass(frozen=True)
class CaseParams(Bounded):
    """Case pressure: the drain's back pressure plus a share of the outlet pressure."""

    offset: float = parameter(
        0.05 * MPA, 'case pressure above tank at zero outlet pressure', 'Pa', 0.0, 1.0e7)
    outlet_share: float = parameter(0.1, 'd p_case / d p_out', '-', 0.0, 1.0)


@dataclass(frozen=True)
class SensorParams(Bounded):
    """One sensor: reading = gain*value + bias + noise, sampled and held at `rate`."""

    noise: float = parameter(
        0.0, 'standard deviation of white noise', 'unit of the channel', 0.0, 1.0e9)
    bias: float = parameter(0.0, 'constant offset', 'unit of the channel', -1.0e9, 1.0e9)
    gain: float = parameter(1.0, 'factor on the true value', '-', 1.0e-3, 10.0)
    rate: float = parameter(
        0.0, 'samples per second; 0 samples at every read', 'Hz', 0.0, 1.0e6)


def fault_parameters() -> dict[str, PlantParameter]:
    """Return the numeric ``effects.<name>`` node parameters a fault may step, by name."""
    return {p.name: p for kind in ranked() for p in kind.plant_parameters if not p.choices}


@dataclass(frozen=True)
class FaultParams(Bounded):
    """
    A step fault: one ``effects.<name>`` parameter steps to `value` at `time` of the plant.

    The plant runs with its configured effects until its clock reaches `time`, then with
    the same effects but that one parameter at `value` (a seal that starts passing:
    ``external_leakage``; a flowmeter knocked: ``flow_sensor_gain``; ...), the state
    carried over. The value is checked against the effect parameter's own range.
    """

    time: float = parameter(0.0, 'plant time at which the fault strikes', 's', 0.0, 1.0e12)
    effect: str = parameter('', "the effects.<name> parameter that steps; '' no fault",
                            choices=('', *fault_parameters()))
    value: float = parameter(0.0, 'what that parameter steps to, in its own unit',
                             'unit of the effect parameter', -1.0e9, 1.0e9)

    def __post_init__(self) -> None:
        """Reject an unknown effect parameter or a value outside its range, naming them."""
        super().__post_init__()
        if not self.effect:
            return
        target = fault_parameters().get(self.effect)
        if target is None:
            msg = (f'FaultParams.effect = {self.effect!r}: use one of '
                   f'{", ".join(fault_parameters())}')
            raise PlantError(msg)
        low = -math.inf if target.low is None else target.low
        high = math.inf if target.high is None else target.high
        if not low <= self.value <= high:
            msg = (f'FaultParams.value = {self.value!r} is outside [{low:g}, {high:g}] '
                   f'{target.unit} of effects.{self.effect}')
            raise PlantError(msg)


SENSOR_CHANNELS = ('inlet_pressure', 'outlet_pressure', 'case_pressure', 'flow', 'speed',
                   'temperature')
"""The sensed channels, in the order of :class:`SensorSet` (SI units; temperature degC)."""


@dataclass(frozen=True)
class SensorSet:
    """The plant's sensors, one record per channel of :data:`SENSOR_CHANNELS`."""

    inlet_pressure: SensorParams = field(default_factory=SensorParams)  # [Pa]
    outlet_pressure: SensorParams = field(default_factory=SensorParams)  # [Pa]
    case_pressure: SensorParams = field(default_factory=SensorParams)  # [Pa]
    flow: SensorParams = field(default_factory=SensorParams)  # [m^3/s]
    speed: SensorParams = field(default_factory=SensorParams)  # [rad/s]
    temperature: SensorParams = field(default_factory=SensorParams)  # [degC]


@dataclass(frozen=True)
class PlantParams(Bounded):
    """
    Everything the plant needs besides the motor model.

    `effects` are registry effects (:mod:`satmotor_ros.model.effects`) that the
    motor_model node does not know about, injected by their kinds; a
    ``viscosity_temperature`` effect without a law takes the liquid's standard
    law, pinned at its viscosity at ``thermal.reference``.
    """

    step: float = parameter(1.0e-3, 'physics step dt', 's', 1.0e-6, 0.1)
    pump_lag: float = parameter(
        0.03, "time constant of the pump's flow response to a command", 's', 0.0, 10.0)
    lines: LineParams = field(default_factory=LineParams)
    relief: ReliefParams = field(default_factory=ReliefParams)
    shaft: ShaftParams = field(default_factory=ShaftParams)
    thermal: ThermalParams = field(default_factory=ThermalParams)
    case: CaseParams = field(default_factory=CaseParams)
    effects: tuple[Effect, ...] = ()  # injected effects, at most one per kind
    fault: FaultParams = field(default_factory=FaultParams)  # a step in one effect at a time
    sensors: SensorSet = field(default_factory=SensorSet)
    active_load: bool = parameter(
        False, 'load torque drives the shaft (True) or brakes it (False)')
    seed: int = parameter(0, 'seed of the sensor noise', '-', 0, 2 ** 63 - 1)
    rebuild_tolerance: float = parameter(
        0.005, 'relative change of nu or h that rebuilds the model', '-', 1.0e-6, 0.5)

    def __post_init__(self) -> None:
        """Reject values outside their range and unknown or repeated effects, naming them."""
        super().__post_init__()
        try:
            for effect in check_effects(self.effects, 'PlantParams.effects'):
                kind_of(effect)
        except (ConfigError, AttributeError) as err:
            msg = f'PlantParams.effects = {self.effects!r}: {err}'
            raise PlantError(msg) from None
