# SPDX-License-Identifier: Apache-2.0
"""
External load torque on the shaft: constant, step, ramp or speed-proportional.

A load gives, at a time, the affine torque law T_L(omega) = t0 + slope*omega
as ``(t0, slope)``, so the integrator can treat a speed-proportional load
implicitly. Positive torque opposes positive rotation.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
import math
from typing import Protocol

from satmotor_ros.plant.errors import PlantError


class LoadProfile(Protocol):
    """Anything that gives the load law at a time."""

    def at(self, time: float) -> tuple[float, float]:
        """
        Give the load law at `time`.

        Parameters
        ----------
        time : float
            Simulation time, [s]

        Returns
        -------
        tuple of float
            Torque at zero speed [N*m] and its slope over speed [N*m*s/rad].

        """


def _finite(owner: object, *names: str) -> None:
    for name in names:
        value = getattr(owner, name)
        if not (isinstance(value, (int, float)) and math.isfinite(value)):
            msg = f'{type(owner).__name__}.{name} = {value!r}: must be a finite number'
            raise PlantError(msg)


@dataclass(frozen=True)
class ConstantLoad:
    """A constant torque."""

    torque: float = 0.0  # [N*m]

    def __post_init__(self) -> None:
        """Reject a non-finite torque."""
        _finite(self, 'torque')

    def at(self, time: float) -> tuple[float, float]:
        """Return (torque [N*m], slope 0) at `time` [s], as :meth:`LoadProfile.at`."""
        return self.torque, 0.0


@dataclass(frozen=True)
class StepLoad:
    """A torque that steps from `before` to `after` at `time`."""

    before: float = 0.0  # [N*m]
    after: float = 0.0  # [N*m]
    time: float = 0.0  # [s]

    def __post_init__(self) -> None:
        """Reject non-finite values."""
        _finite(self, 'before', 'after', 'time')

    def at(self, time: float) -> tuple[float, float]:
        """Return (torque [N*m], slope 0) at `time` [s], as :meth:`LoadProfile.at`."""
        return (self.after if time >= self.time else self.before), 0.0


@dataclass(frozen=True)
class RampLoad:
    """A torque ramping linearly from `start` at `t_start` to `end` at `t_end`."""

    start: float = 0.0  # [N*m]
    end: float = 0.0  # [N*m]
    t_start: float = 0.0  # [s]
    t_end: float = 1.0  # [s]

    def __post_init__(self) -> None:
        """Reject non-finite values and an empty ramp."""
        _finite(self, 'start', 'end', 't_start', 't_end')
        if self.t_end <= self.t_start:
            msg = f'RampLoad.t_end = {self.t_end!r}: must be after t_start = {self.t_start!r}'
            raise PlantError(msg)

    def at(self, time: float) -> tuple[float, float]:
        """Return (torque [N*m], slope 0) at `time` [s], as :meth:`LoadProfile.at`."""
        share = min(max((time - self.t_start) / (self.t_end - self.t_start), 0.0), 1.0)
        return self.start + share * (self.end - self.start), 0.0


@dataclass(frozen=True)
class SpeedProportionalLoad:
    """A torque offset + coefficient*omega, e.g. a pump or a fan linearised."""

    coefficient: float = 0.0  # [N*m*s/rad]
    offset: float = 0.0  # [N*m]

    def __post_init__(self) -> None:
        """Reject non-finite and negative (energy-producing) slopes."""
        _finite(self, 'coefficient', 'offset')
        if self.coefficient < 0.0:
            msg = f'SpeedProportionalLoad.coefficient = {self.coefficient!r}: must be >= 0'
            raise PlantError(msg)

    def at(self, time: float) -> tuple[float, float]:
        """Return (offset [N*m], slope [N*m*s/rad]) at any `time`, as :meth:`LoadProfile.at`."""
        return self.offset, self.coefficient


LOAD_KINDS: dict[str, Callable[..., LoadProfile]] = {
    'constant': ConstantLoad, 'step': StepLoad, 'ramp': RampLoad, 'speed': SpeedProportionalLoad}
"""Load profile by the name the node's ``load.kind`` parameter uses."""


def make_load(kind: str, **values: float) -> LoadProfile:
    """
    Build a load profile by name.

    Parameters
    ----------
    kind : str
        One of :data:`LOAD_KINDS`, [-]
    **values : float
        The profile's fields, [N*m, s or N*m*s/rad]

    Returns
    -------
    LoadProfile
        The profile.

    Raises
    ------
    PlantError
        If the kind is unknown or a value is invalid.

    """
    if kind not in LOAD_KINDS:
        msg = f'load kind {kind!r}: use one of {", ".join(LOAD_KINDS)}'
        raise PlantError(msg)
    try:
        return LOAD_KINDS[kind](**values)
    except TypeError as err:
        msg = f'load kind {kind!r}: {err}'
        raise PlantError(msg) from None
