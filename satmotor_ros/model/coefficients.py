# SPDX-License-Identifier: Apache-2.0
"""
Liquids, motor geometry and loss coefficients as frozen, validated records.

Geometry and liquids are SI. The loss coefficients are the empirical fits of
Śliwiński (2017), Table 1, and only mean something in the unit system they
were fitted in; each field states that system (doc/PAPER_MODEL.md, "Units"). The
equation functions in :mod:`satmotor_ros.model.families.sliwinski2017.losses` take SI arrays and do
the conversion, so no caller ever sees the paper's units.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import math
from typing import Any

from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.units import CM3_PER_REV


class FieldError(ConfigError):
    """One field of a record holds a value outside its range."""

    def __init__(self, owner: str, field: str, detail: str) -> None:
        """Keep the field and the detail apart so a loader can re-prefix the key path."""
        super().__init__(f'{owner}.{field} = {detail}')
        self.field = field
        self.detail = detail


def _check(owner: str, name: str, value: float, low: float, high: float,
           closed_low: bool = False) -> None:
    ok = math.isfinite(value) and value < high and (value >= low if closed_low else value > low)
    if not ok:
        bracket = '[' if closed_low else '('
        raise FieldError(owner, name, f'{value!r} is outside {bracket}{low}, {high})')


DISPLACEMENT_RANGE = (0.01 * CM3_PER_REV, 1.0e6 * CM3_PER_REV)
"""
Open range of a motor's displacement q_t/(2 pi), [m^3/rad]: 0.01 to 1e6 cm^3/rev.

Wider than any displacement machine built (micro gear pumps have about 0.02 cm^3/rev,
the largest low-speed radial-piston motors about 250 000 cm^3/rev), narrow enough that
the scaling of a family's default coefficients (c_t ~ q^(-4/3)) and of the validated
speeds (~ q^(-1/3)) stays finite: a displacement of 1e-300 m^3/rad overflows them.
Every displacement (motor file, node parameter, CLI option) is checked here.
"""


def displacement_problem(value: float) -> str | None:
    """
    Say why a displacement is not one a motor can have.

    Parameters
    ----------
    value : float
        Displacement q_t/(2 pi), [m^3/rad]

    Returns
    -------
    str or None
        ``'outside (low, high) m^3/rad (...)'``, or None when it is inside
        :data:`DISPLACEMENT_RANGE`.

    """
    low, high = DISPLACEMENT_RANGE
    if isinstance(value, (int, float)) and math.isfinite(value) and low < value < high:
        return None
    return (f'outside ({low:.4g}, {high:.4g}) m^3/rad '
            '(0.01 to 1e6 cm^3/rev, wider than any displacement machine)')


LIQUID_RANGES = {'kinematic_viscosity': (1.0e-8, 1.0), 'density': (10.0, 1.0e5),
                 'bulk_modulus': (1.0e5, 1.0e12)}
"""
Open ranges of a liquid's properties, [SI].

Wide enough for any liquid a motor runs on (water at 100 degC has 2.9e-7 m^2/s;
oil with entrained air a bulk modulus of about 1e8 Pa), narrow enough that no
property turns a loss into inf or NaN (a bulk modulus of 5e-324 Pa would).
"""


@dataclass(frozen=True)
class Liquid:
    """A working liquid, described by the three properties the model uses."""

    name: str
    kinematic_viscosity: float  # nu [m^2/s]
    density: float  # rho [kg/m^3]
    bulk_modulus: float  # K, isothermal secant bulk modulus [Pa]; beta_l = 1/K, eq. (6)

    def __post_init__(self) -> None:
        """Reject non-physical properties, naming the field."""
        for name, (low, high) in LIQUID_RANGES.items():
            _check(self.name, name, getattr(self, name), low, high)

    @property
    def dynamic_viscosity(self) -> float:
        """Dynamic viscosity mu = rho * nu, [Pa*s]."""
        return self.density * self.kinematic_viscosity


@dataclass(frozen=True)
class MotorGeometry:
    """Geometry of a satellite motor (SM-0,75/25 by default)."""

    displacement: float  # q_t, theoretical displacement [m^3/rad]
    module: float  # m, tooth module [m]
    height: float  # H, height of the working mechanism [m]
    clearance_rotor: float  # h_R, axial clearance of the rotor [m]
    clearance_satellites: float  # h_S, axial clearance of the satellites [m]
    commutation_diameter: float  # D_o of eq. (5) [m]; assumed, not given in the paper

    def __post_init__(self) -> None:
        """Reject non-physical dimensions, naming the field."""
        problem = displacement_problem(self.displacement)
        if problem is not None:
            raise FieldError('geometry', 'displacement', f'{self.displacement!r} is {problem}')
        for name, high in (('module', 0.1), ('height', 1.0),
                           ('clearance_rotor', 1.0e-3), ('clearance_satellites', 1.0e-3),
                           ('commutation_diameter', 1.0)):
            _check('geometry', name, getattr(self, name), 0.0, high)

    @property
    def m2h(self) -> float:
        """
        Return m^2*H as the paper uses it in eqs. (11)-(14), (33) and (40).

        The paper evaluates m^2*H with m and H in mm and reads the number as
        cm^3 (0.75^2 * 25 = 14.0625 "cm^3"); the fitted C and C_id only
        reproduce its results that way (doc/PAPER_MODEL.md, "Units").
        """
        return (self.module * 1.0e3) ** 2 * (self.height * 1.0e3)

    @property
    def displacement_cm3_per_rev(self) -> float:
        """Theoretical displacement q_t in the paper's unit, [cm^3/rev]."""
        return self.displacement / CM3_PER_REV


@dataclass(frozen=True)
class LossCoefficients:
    """
    Coefficients of the volumetric-loss model for one motor and one liquid.

    Units are the paper's fitting units (doc/PAPER_MODEL.md): pressure in MPa,
    speed in rpm, flow in l/min, lengths in mm and um, viscosity in cSt.
    """

    a1: float  # A_1 of eq. (1) [-]
    a2: float  # A_2 of eq. (1) [-]
    k: float  # K of eq. (1) [-]
    beta: float  # laminarity of the clearance flow, eq. (1) [-]
    d_c: float  # D_C of eq. (2), stator compliance [um/(MPa*mm)]
    d_k: float  # D_K of eq. (2), compensation-unit compliance [um/MPa]
    c1: float  # C_1 of eq. (5) [-]
    c2: float  # C_2 of eq. (5), exponent [-]
    c3: float  # C_3 of eq. (5) [-]
    gamma: float  # exponent of eq. (5) [-]
    c: float  # C = C_fc*beta_l + C_dch + C_b of eq. (33) [1/(MPa*rev)]
    c_id: float  # C_id of eqs. (14), (33) [1/(rev*min)^0.5]
    c_t: float  # turbulent channel coefficient of eq. (35), Q in l/min -> Pa
    c_l: float  # laminar channel coefficient of eq. (35), mu in mPa*s, Q in l/min -> Pa
    c1_39: float  # C_1 of the empirical eq. (39), dq in cm^3/rev
    c2_39: float  # C_2 of the empirical eq. (39) [-]
    compressed_volume_fraction: float  # C'_fc of eq. (9): share of q_t compressed per rev [-]
    deformation_share: float  # share of C - C_fc*beta_l given to C_dch (rest: C_b) [-]
    external_leakage: float = 0.0  # lumped C_ex of eq. (24): Q_ex = k * p [m^3/(s*Pa)]

    def __post_init__(self) -> None:
        """Reject coefficients the equations cannot use, naming the field."""
        owner = 'coefficients'
        for name in ('a1', 'a2', 'k', 'c1', 'c3', 'gamma', 'c1_39'):
            _check(owner, name, getattr(self, name), 0.0, 1.0e12)
        _check(owner, 'beta', self.beta, 0.0, 2.0)
        for name in ('c', 'c_id', 'c_t', 'c_l', 'c2_39', 'compressed_volume_fraction',
                     'external_leakage'):
            _check(owner, name, getattr(self, name), 0.0, 1.0e12, closed_low=True)
        for name in ('d_c', 'd_k', 'c2'):
            _check(owner, name, getattr(self, name), -1.0e12, 1.0e12)
        _check(owner, 'deformation_share', self.deformation_share, 0.0, 1.0 + 1e-12,
               closed_low=True)


@dataclass(frozen=True)
class ValidRange:
    """Operating range over which a coefficient set was validated by measurement."""

    dp_max: float  # largest chamber pressure drop measured [Pa]
    speed_max: float  # largest shaft speed measured [rad/s]
    dp_min: float = 0.0  # smallest chamber pressure drop measured [Pa]
    speed_min: float = 0.0  # smallest shaft speed measured [rad/s]

    def __post_init__(self) -> None:
        """Reject an empty or non-finite range."""
        _check('valid_range', 'dp_max', self.dp_max, 0.0, 1.0e10)
        _check('valid_range', 'speed_max', self.speed_max, 0.0, 1.0e6)
        _check('valid_range', 'dp_min', self.dp_min, 0.0, self.dp_max, closed_low=True)
        _check('valid_range', 'speed_min', self.speed_min, 0.0, self.speed_max, closed_low=True)


@dataclass(frozen=True)
class Effect:
    """One effect of a coefficient set (or injected into the plant), SI (temperature in degC)."""

    name: str  # id as in the YAML: a kind, or '<kind>:<suffix>' ('channel:aux', 'term:dp^2')
    coefficient: float  # k, in the unit the kind implies (m^3/(s*Pa), m/s, -, ...)
    regressor: str = ''  # channel or expression the effect reads
    reference: float = 0.0  # x where the effect is zero (wear, channel) [unit of x]
    law: str = ''  # viscosity_temperature: 'walther' or 'vogel'; '' the liquid's own
    reference_temperature: float = math.nan  # where the viscosity is the liquid's [degC]
    reference_viscosity: float = math.nan  # the viscosity there; NaN the liquid's [m^2/s]
    vogel_c: float = 140.0  # Vogel C [K]
    options: tuple[tuple[str, Any], ...] = ()  # further parameters of a new kind, by name
    fitted_range: tuple[tuple[str, float, float], ...] = ()  # (quantity, min, max) of the data
    # it was fitted on, SI, one per quantity of EffectKind.reads; () when not known (no flag)
    direction: str = 'both'  # sign of dp = p_a - p_b where it acts: 'positive', 'negative'

    @property
    def kind(self) -> str:
        """Return the kind, without a ``:<suffix>``."""
        return self.name.split(':', 1)[0]

    @property
    def key(self) -> str:
        """Return the id with its direction, ``threshold:dp@negative``: unique in a set."""
        return self.name if self.direction == 'both' else f'{self.name}@{self.direction}'

    def acts(self, negative: bool) -> bool:
        """Return whether the effect acts where dp < 0 (`negative`) or dp >= 0."""
        return self.direction == 'both' or (self.direction == 'negative') == negative

    @property
    def suffix(self) -> str:
        """Return what follows ``<kind>:`` in the name, or ''."""
        return self.name.partition(':')[2]

    def option(self, key: str, default: Any = None) -> Any:
        """Return the kind-specific parameter `key` of :attr:`options`, or `default`."""
        return dict(self.options).get(key, default)


@dataclass(frozen=True)
class CoefficientSet:
    """
    Loss coefficients together with the liquid they were fitted on.

    ``viscosity_range`` is the span of kinematic viscosity the fit covers; by
    default only the fitted liquid's own. A model run on a liquid outside it
    flags every point EXTRAPOLATED.
    """

    name: str
    liquid: Liquid
    coefficients: LossCoefficients
    viscosity_range: tuple[float, float] | None = None  # (nu_min, nu_max) [m^2/s]
    effects: tuple[Effect, ...] = ()  # effects a calibration added, see .effects

    def __post_init__(self) -> None:
        """Reject an empty or non-physical viscosity range."""
        if self.viscosity_range is not None:
            low, high = self.viscosity_range
            _check(self.name, 'viscosity_range[0]', low, 0.0, 1.0)
            _check(self.name, 'viscosity_range[1]', high, low, 1.0, closed_low=True)

    @property
    def fitted_viscosity(self) -> tuple[float, float]:
        """Return the span of kinematic viscosity the fit covers, [m^2/s]."""
        if self.viscosity_range is None:
            nu = self.liquid.kinematic_viscosity
            return nu, nu
        return self.viscosity_range


def field_names(record: type) -> tuple[str, ...]:
    """
    List the field names of one of the records above.

    Parameters
    ----------
    record : type
        A dataclass type from this module, [-]

    Returns
    -------
    tuple of str
        Field names in declaration order.

    """
    return tuple(f.name for f in fields(record))
