# SPDX-License-Identifier: Apache-2.0
"""
Parameter records of the virtual motor: lines, relief valve, shaft, heat, case and effects.

Every record is frozen and checks its fields on construction; an error names the
field and the value. Defaults describe a small test rig around the SM-0,75/25
(README, "The plant"); every effect is off (magnitude 0) by default.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
import math
from typing import ClassVar, Protocol

from satmotor_ros.model.units import ATMOSPHERE, LPM, MPA
from satmotor_ros.plant.errors import PlantError


class Bounded(Protocol):
    """A parameter record: its class maps numeric field names to closed ranges."""

    bounds: ClassVar[dict[str, tuple[float, float]]]


def check_bounds(record: Bounded) -> None:
    """
    Check every numeric field of a record against its class's ``bounds`` (closed ranges).

    Parameters
    ----------
    record : Bounded
        A parameter record with a ``bounds`` mapping field -> (low, high), [-]

    Raises
    ------
    PlantError
        Naming the first field outside its range and its value.

    """
    for name, (low, high) in record.bounds.items():
        value = getattr(record, name)
        ok = (isinstance(value, (int, float)) and not isinstance(value, bool)
              and math.isfinite(value) and low <= value <= high)
        if not ok:
            msg = f'{type(record).__name__}.{name} = {value!r} is outside [{low:g}, {high:g}]'
            raise PlantError(msg)


@dataclass(frozen=True)
class LineParams:
    """Inlet and outlet lines, tank and return line."""

    inlet_volume: float = 0.2e-3  # V_in, liquid volume between pump and motor [m^3]
    outlet_volume: float = 0.2e-3  # V_out, liquid volume between motor and return valve [m^3]
    tank_pressure: float = ATMOSPHERE  # p_t, absolute [Pa]
    back_pressure: float = 0.5 * MPA  # p_b, return-line back pressure above p_t [Pa]
    return_conductance: float = 40.0 * LPM / MPA  # G_r, return valve slope [m^3/(s*Pa)]
    vapour_pressure: float = 2.0e3  # absolute floor of both lines (cavitation) [Pa]

    bounds: ClassVar[dict[str, tuple[float, float]]] = {
        'inlet_volume': (1.0e-7, 1.0), 'outlet_volume': (1.0e-7, 1.0),
        'tank_pressure': (1.0e3, 1.0e7), 'back_pressure': (0.0, 1.0e7),
        'return_conductance': (1.0e-13, 1.0e-5), 'vapour_pressure': (0.0, 1.0e5)}

    def __post_init__(self) -> None:
        """Reject values outside ``bounds``, naming the field."""
        check_bounds(self)


@dataclass(frozen=True)
class ReliefParams:
    """Relief valve from the inlet line to the tank, a proportional characteristic."""

    cracking_pressure: float = 27.0 * MPA  # p_cr, above tank pressure [Pa]
    conductance: float = 40.0 * LPM / (2.0 * MPA)  # k_rv, flow per override [m^3/(s*Pa)]

    bounds: ClassVar[dict[str, tuple[float, float]]] = {
        'cracking_pressure': (1.0e5, 4.5e7), 'conductance': (1.0e-13, 1.0e-5)}

    def __post_init__(self) -> None:
        """Reject values outside ``bounds``, naming the field."""
        check_bounds(self)


@dataclass(frozen=True)
class ShaftParams:
    """Shaft, its inertia and the hydro-mechanical (torque) losses."""

    inertia: float = 0.01  # J, motor and coupled load [kg*m^2]
    viscous_friction: float = 2.0e-3  # b, torque per speed [N*m*s/rad]
    coulomb_friction: float = 0.5  # T_c, dry friction [N*m]
    pressure_friction: float = 0.04  # c_p, share of q_t*dp_i lost to friction [-]
    locked: bool = False  # shaft blocked by a brake: speed held at 0 [-]

    bounds: ClassVar[dict[str, tuple[float, float]]] = {
        'inertia': (1.0e-6, 1.0e3), 'viscous_friction': (0.0, 1.0e3),
        'coulomb_friction': (0.0, 1.0e4), 'pressure_friction': (0.0, 0.9)}

    def __post_init__(self) -> None:
        """Reject values outside ``bounds``, naming the field."""
        check_bounds(self)


@dataclass(frozen=True)
class ThermalParams:
    """Lumped heat balance of the liquid: every watt of loss heats it."""

    heat_capacity: float = 4.0e4  # C_th, liquid and metal [J/K]
    cooling: float = 50.0  # hA, heat loss to the ambient per kelvin [W/K]
    ambient: float = 25.0  # T_a, ambient temperature [degC]
    initial: float = 40.0  # liquid temperature at t = 0 [degC]
    reference: float = 40.0  # temperature of the liquid's nominal viscosity [degC]

    bounds: ClassVar[dict[str, tuple[float, float]]] = {
        'heat_capacity': (1.0, 1.0e9), 'cooling': (0.0, 1.0e6), 'ambient': (-50.0, 200.0),
        'initial': (-50.0, 200.0), 'reference': (-50.0, 200.0)}

    def __post_init__(self) -> None:
        """Reject values outside ``bounds``, naming the field."""
        check_bounds(self)


@dataclass(frozen=True)
class CaseParams:
    """Case pressure: the drain's back pressure plus a share of the outlet pressure."""

    offset: float = 0.05 * MPA  # case pressure above tank at zero outlet pressure [Pa]
    outlet_share: float = 0.1  # d p_case / d p_out [-]

    bounds: ClassVar[dict[str, tuple[float, float]]] = {
        'offset': (0.0, 1.0e7), 'outlet_share': (0.0, 1.0)}

    def __post_init__(self) -> None:
        """Reject values outside ``bounds``, naming the field."""
        check_bounds(self)


@dataclass(frozen=True)
class EffectParams:
    """
    Effects the motor_model node does not know about; each is off at magnitude 0.

    ``external_leakage`` takes k_x*p_driver (gauge pressure of the case or of the
    outlet line) from the inlet line to the tank; ``viscosity_temperature`` is
    the exponent a of nu = nu_ref exp(-a (T - T_ref)); ``clearance_wear`` grows
    both axial clearances by that much per revolution; the sensor errors act on
    the flowmeter and the speed sensor only.
    """

    external_leakage: float = 0.0  # k_x, leakage to the tank per driving pressure [m^3/(s*Pa)]
    leakage_driver: str = 'case'  # 'case' or 'outlet': pressure that drives k_x [-]
    viscosity_temperature: float = 0.0  # a, viscosity-temperature exponent of eq. (P7) [1/K]
    clearance_wear: float = 0.0  # growth of h_R and h_S [m/rev]
    flow_sensor_offset: float = 0.0  # added to the measured flow [m^3/s]
    flow_sensor_gain: float = 0.0  # relative gain error of the flowmeter [-]
    speed_sensor_gain: float = 0.0  # relative gain error of the speed sensor [-]

    bounds: ClassVar[dict[str, tuple[float, float]]] = {
        'external_leakage': (0.0, 1.0e-8), 'viscosity_temperature': (0.0, 0.2),
        'clearance_wear': (0.0, 1.0e-6), 'flow_sensor_offset': (-1.0e-2, 1.0e-2),
        'flow_sensor_gain': (-0.5, 0.5), 'speed_sensor_gain': (-0.5, 0.5)}

    def __post_init__(self) -> None:
        """Reject values outside ``bounds``, naming the field."""
        check_bounds(self)
        if self.leakage_driver not in ('case', 'outlet'):
            msg = f"EffectParams.leakage_driver = {self.leakage_driver!r}: use 'case' or 'outlet'"
            raise PlantError(msg)


@dataclass(frozen=True)
class SensorParams:
    """One sensor: reading = gain*value + bias + noise, sampled and held at `rate`."""

    noise: float = 0.0  # standard deviation of white noise [unit of the channel]
    bias: float = 0.0  # constant offset [unit of the channel]
    gain: float = 1.0  # factor on the true value [-]
    rate: float = 0.0  # samples per second; 0 samples at every read [Hz]

    bounds: ClassVar[dict[str, tuple[float, float]]] = {
        'noise': (0.0, 1.0e9), 'bias': (-1.0e9, 1.0e9), 'gain': (1.0e-3, 10.0),
        'rate': (0.0, 1.0e6)}

    def __post_init__(self) -> None:
        """Reject values outside ``bounds``, naming the field."""
        check_bounds(self)


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
class PlantParams:
    """Everything the plant needs besides the motor model."""

    step: float = 1.0e-3  # physics step dt [s]
    pump_lag: float = 0.03  # time constant of the pump's flow response to a command [s]
    lines: LineParams = field(default_factory=LineParams)
    relief: ReliefParams = field(default_factory=ReliefParams)
    shaft: ShaftParams = field(default_factory=ShaftParams)
    thermal: ThermalParams = field(default_factory=ThermalParams)
    case: CaseParams = field(default_factory=CaseParams)
    effects: EffectParams = field(default_factory=EffectParams)
    sensors: SensorSet = field(default_factory=SensorSet)
    active_load: bool = False  # load torque drives the shaft (True) or brakes it (False) [-]
    seed: int = 0  # seed of the sensor noise [-]
    rebuild_tolerance: float = 0.005  # relative change of nu or h that rebuilds the model [-]

    bounds: ClassVar[dict[str, tuple[float, float]]] = {
        'step': (1.0e-6, 0.1), 'pump_lag': (0.0, 10.0), 'rebuild_tolerance': (1.0e-6, 0.5)}

    def __post_init__(self) -> None:
        """Reject values outside ``bounds``, naming the field."""
        check_bounds(self)


def record_fields(record: type) -> tuple[str, ...]:
    """
    List the field names of one of the records above.

    Parameters
    ----------
    record : type
        A dataclass type of this module, [-]

    Returns
    -------
    tuple of str
        Field names in declaration order.

    """
    return tuple(f.name for f in fields(record))
