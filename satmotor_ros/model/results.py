# SPDX-License-Identifier: Apache-2.0
"""What the model returns: operating points, their loss breakdown and a status per element."""

from __future__ import annotations

from dataclasses import dataclass, fields
import enum
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from satmotor_ros.model._typing import FloatArray, Real
from satmotor_ros.model.coefficients import MotorGeometry


def speed_loss(flow: Real, speed: Real, qt: float) -> Real:
    r"""
    Compute the loss of speed against the theoretical speed, eq. (41).

    .. math:: n_i = \frac{Q}{q_t} - n

    Parameters
    ----------
    flow : float or ndarray
        Flow into the motor Q, [m^3/s]
    speed : float or ndarray
        Effective shaft speed n, [rad/s]
    qt : float
        Theoretical displacement q_t, [m^3/rad]

    Returns
    -------
    float or ndarray
        Speed loss n_i, [rad/s]

    """
    return flow / qt - speed


class PointStatus(enum.IntFlag):
    """Per-element outcome of a model evaluation; flags combine."""

    OK = 0
    STALLED = 1  # the leakage takes all the flow: n = 0 (a physical result)
    CHANNEL_LIMITED = 2  # dp_ich >= dp: the chamber drop dp_i is clipped to 0
    EXTRAPOLATED = 4  # beyond the coefficient set's validated range (computed)
    NOT_FINITE = 8  # NaN or inf input (invalid: output NaN)
    NEGATIVE = 16  # a negative p_ex (flow, speed and drops are signed) (invalid: output NaN)
    BEYOND_LIMIT = 32  # where the equations stop being physical (invalid: output NaN)
    NOT_CONVERGED = 64  # an iterative solve ran out of iterations (invalid: output NaN)
    NO_ROOT = 128  # the equations have no solution at this point (invalid: output NaN)


INVALID = (PointStatus.NOT_FINITE | PointStatus.NEGATIVE | PointStatus.BEYOND_LIMIT
           | PointStatus.NOT_CONVERGED | PointStatus.NO_ROOT)
"""The flags that make an element invalid (its outputs are NaN)."""

COMPONENTS = ('flat_clearance', 'commutation', 'compressibility', 'deformation', 'backlash',
              'inertia', 'external', 'total')
"""Loss component names, as on the ``losses/<component>`` topics."""


@dataclass(frozen=True)
class LossBreakdown:
    """The volumetric losses of eq. (31), by component, [m^3/s]."""

    flat_clearance: FloatArray  # Q_Lfg, eq. (1)
    commutation: FloatArray  # Q_C, eq. (5)
    compressibility: FloatArray  # Delta Q_fc, eq. (11)
    deformation: FloatArray  # Delta Q_dch, eq. (12)
    backlash: FloatArray  # Delta Q_b, eq. (13)
    inertia: FloatArray  # Delta Q_id, eq. (14)
    external: FloatArray  # Q_ex, eq. (24)
    total: FloatArray  # Q_vl, eq. (31)

    def as_dict(self) -> dict[str, FloatArray]:
        """Return the components by name, in :data:`COMPONENTS` order."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True)
class OperatingPoints:
    """
    Operating points of the motor and their losses, all SI.

    Every array is the result's own (the inputs of the call come back broadcast,
    as copies) and read-only; where an element is invalid every field holds NaN.
    """

    flow: FloatArray  # absorbency Q [m^3/s]
    speed: FloatArray  # effective shaft speed n [rad/s]
    dp: FloatArray  # pressure drop between the ports [Pa]
    dp_i: FloatArray  # pressure drop in the working chambers [Pa]
    losses: LossBreakdown
    status: npt.NDArray[np.uint8]  # PointStatus flags per element
    geometry: MotorGeometry  # the motor the points belong to

    @property
    def speed_loss(self) -> FloatArray:
        """Speed loss n_i against the theoretical speed Q/q_t, eq. (41), [rad/s]."""
        return speed_loss(self.flow, self.speed, self.geometry.displacement)

    @property
    def invalid(self) -> npt.NDArray[np.bool_]:
        """Mask of the elements whose outputs are NaN."""
        mask: npt.NDArray[np.bool_] = (self.status & int(INVALID)) != 0
        return mask


class Point(NamedTuple):
    """
    One operating point as Python floats, SI; same meaning as :class:`OperatingPoints`.

    Returned by ``MotorModel.speed_point``, ``absorbency_point`` and
    ``breakdown_point``. The loss fields are the :data:`COMPONENTS`, in order;
    an invalid point has NaN in every float field.
    """

    flow: float  # Q [m^3/s]
    speed: float  # n [rad/s]
    dp: float  # port pressure drop [Pa]
    dp_i: float  # chamber pressure drop [Pa]
    flat_clearance: float  # Q_Lfg, eq. (1) [m^3/s]
    commutation: float  # Q_C, eq. (5) [m^3/s]
    compressibility: float  # Delta Q_fc, eq. (11) [m^3/s]
    deformation: float  # Delta Q_dch, eq. (12) [m^3/s]
    backlash: float  # Delta Q_b, eq. (13) [m^3/s]
    inertia: float  # Delta Q_id, eq. (14) [m^3/s]
    external: float  # Q_ex, eq. (24) [m^3/s]
    total: float  # Q_vl, eq. (31) [m^3/s]
    status: int  # PointStatus flags


def describe_status(code: int) -> str:
    """
    Spell out a status code.

    Parameters
    ----------
    code : int
        A :class:`PointStatus` value, [-]

    Returns
    -------
    str
        Flag names joined by ``|``, or ``'OK'``.

    Examples
    --------
    >>> describe_status(PointStatus.STALLED | PointStatus.EXTRAPOLATED)
    'STALLED|EXTRAPOLATED'

    """
    names = [flag.name for flag in PointStatus if flag and code & flag]
    return '|'.join(n for n in names if n) or 'OK'


def from_table(table: FloatArray, status: npt.NDArray[np.uint8], shape: tuple[int, ...],
               geometry: MotorGeometry) -> OperatingPoints:
    """
    Return points as read-only :class:`OperatingPoints` of `shape`, each field its own copy.

    Parameters
    ----------
    table : ndarray
        One row a point: flow, speed, dp, dp_i and the :data:`COMPONENTS`, [SI]
    status : ndarray of uint8
        The points' flags, [-]
    shape : tuple of int
        The shape of the result (``()`` for one point), [-]
    geometry : MotorGeometry
        The motor the points belong to, [-]

    Returns
    -------
    OperatingPoints
        The points.

    """
    rows = table.reshape(-1, 12)
    columns = [rows[:, j].reshape(shape).copy() for j in range(12)]
    flags = status.reshape(shape).copy()
    for column in (*columns, flags):
        column.setflags(write=False)
    return OperatingPoints(columns[0], columns[1], columns[2], columns[3],
                           LossBreakdown(**dict(zip(COMPONENTS, columns[4:]))), flags, geometry)
