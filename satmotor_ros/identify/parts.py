# SPDX-License-Identifier: Apache-2.0
"""
The model's loss components at measured operating points, and how an effect modifies them.

The measured volumetric loss is Q_vl = Q - q_t n (eq. 31 read backwards).
The model gives it as the sum of the leakage (eqs. 1, 5, 24) and the
speed-dependent part (eqs. 11-14, 33), evaluated at the measured speed and
at the chamber drop dp_i = dp - dp_ich(Q) of eqs. (34)-(35), where Q is the
measured flow, so no equation has to be solved per point.

Rows may be signed (four quadrants, doc/quadrants.md): each row is taken in
the frame where its loss runs forward, i.e. flow, displacement and drops are
multiplied by s = sign(dp), and the components are the model's at |n| and
|dp_i|, so the fit and every candidate see the loss as in forward motor mode.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from satmotor_ros.identify.errors import IdentificationError
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import Modifier
from satmotor_ros.model.families.sliwinski2017.losses import clearance_height


@dataclass(frozen=True)
class Component:
    """
    One named part of the model's Q_vl that the fit scales by a factor of its own.

    A motor family supplies its Q_vl as a tuple of these (:attr:`LossParts.components`);
    the fitter frees one factor per component, with a weak prior at 1.
    """

    name: str  # the factor's name, e.g. 'leakage_scale'
    pieces: tuple[tuple[str, FloatArray], ...]  # (Modifier fields scaling it, '*'-joined, or
    # '', Q [m^3/s])
    speed_power: float = 0.0  # it grows as n^power at a fixed dp_i (how a speed gain acts) [-]
    floor: float = 0.0  # least factor: a share known otherwise (e.g. C_fc beta_l) [-]
    describes: str = ''  # what the factor multiplies, for the report
    part: str = ''  # the family's linear part it scales (Family.linear_parts), for the YAML

    def flow(self, mod: Modifier) -> FloatArray:
        """Return the component at factor 1 under an effect's modifier, [m^3/s]."""
        factor, total = self.pieces[0]
        total = _scaled(mod, factor, total)
        for factor, column in self.pieces[1:]:
            total = total + _scaled(mod, factor, column)
        return total / mod.speed_gain ** self.speed_power if self.speed_power else total


def _scaled(mod: Modifier, factors: str, column: FloatArray) -> FloatArray:
    """Return `column` times the Modifier fields named in `factors` ('a*b'; '' for none)."""
    if not factors:
        return column
    for name in factors.split('*'):
        factor = getattr(mod, name)
        column = column if _one(factor) else factor * column
    return column


@dataclass(frozen=True)
class LossParts:
    """Model components at the measured points, each for unit scale factors, [m^3/s]."""

    flow: FloatArray  # measured Q, times s [m^3/s]
    speed: FloatArray  # measured |n| [rad/s]
    dp: FloatArray  # port drop |dp| [Pa]
    dp_i: FloatArray  # chamber drop |dp_i|, eqs. (34)-(35) with the signed flow [Pa]
    displacement: FloatArray  # q_t n, times s [m^3/s]
    clearance: FloatArray  # h, eq. (2) [m]
    clearance_satellites: float  # h_S [m]
    h_exponent: float  # Q_Lfg ~ h^(3/(2-beta)), eq. (1) [-]
    hs_exponent: float  # Q_C ~ h_S^C_2, eq. (5) [-]
    nu_exponent_lfg: float  # Q_Lfg ~ nu^(-beta/(2-beta)), eq. (1) [-]
    nu_exponent_c: float  # Q_C ~ nu^(-gamma), eq. (5) [-]
    components: tuple[Component, ...] = ()  # the fitted parts of Q_vl, one factor each
    nuisance: Mapping[str, FloatArray] = field(default_factory=dict)  # name -> x (SI), fitted
    # linearly without a prior in every fit (e.g. dp/dt of a time series)
    sign: FloatArray | float = 1.0  # s = sign(dp): the row's frame, +1 or -1 [-]
    rotation: FloatArray | float = 1.0  # sign of the measured speed, -1, 0 or +1 [-]

    @property
    def reverse(self) -> np.ndarray:
        """Return which rows turn backwards (n < 0): where a direction-keyed effect acts."""
        return np.asarray(self.rotation) < 0.0

    @property
    def loss(self) -> FloatArray:
        """Measured volumetric loss Q_vl = Q - q_t n, [m^3/s]."""
        return self.flow - self.displacement

    def __len__(self) -> int:
        """Return the number of points."""
        return int(self.flow.size)

    @property
    def names(self) -> tuple[str, ...]:
        """Return the components' factor names."""
        return tuple(c.name for c in self.components)

    def with_nuisance(self, nuisance: Mapping[str, FloatArray]) -> LossParts:
        """Return these parts with nuisance regressors (name -> x at the points, SI) added."""
        for name, x in nuisance.items():
            if np.shape(x) != self.flow.shape or not np.all(np.isfinite(x)):
                msg = f'nuisance regressor {name!r}: need {self.flow.size} finite values'
                raise IdentificationError(msg)
        return replace(self, nuisance={**self.nuisance, **nuisance})


NO_EFFECT = Modifier()
"""The model as it is."""


def predict_flow(parts: LossParts, scales: FloatArray, mod: Modifier = NO_EFFECT,
                 nuisance: FloatArray | None = None,
                 flows: Sequence[FloatArray] | None = None) -> FloatArray:
    r"""
    Predict the measured flow from the scaled components and the effects, eq. (36).

    .. math:: Q_m = G_Q\left[\frac{q_t n_m}{G_n} + \sum_j s_j \frac{\sum_k \phi_{jk}
        Q_{jk}}{G_n^{e_j}} + Q_{add} + \sum_l \beta_l x_l\right] + b

    For eqs. (31)-(33) the components are the leakage s_L (Q_Lfg phi_L + Q_C phi_C),
    s_C dQ_C / G_n and s_id dQ_id / sqrt(G_n).

    Parameters
    ----------
    parts : LossParts
        Components at the measured points, [-]
    scales : ndarray
        Factors on the components, in their order, [-]
    mod : Modifier
        The effects' gains, factors and extra terms, [-]
    nuisance : ndarray, optional
        Coefficients beta of the nuisance regressors, in their order, [SI]
    flows : sequence of ndarray, optional
        The components under `mod` (:meth:`Component.flow`), when already known: the sums
        are the same, term for term, [m^3/s]

    Returns
    -------
    ndarray
        Predicted measured flow, [m^3/s]

    """
    # a gain of 1 and an extra loss or offset of 0 leave the sums as they are: skipped
    inner = parts.displacement if _one(mod.speed_gain) else parts.displacement / mod.speed_gain
    if not _zero(mod.additive):
        inner = inner + mod.additive
    if flows is None:
        flows = [component.flow(mod) for component in parts.components]
    for scale, column in zip(scales, flows):
        inner = inner + scale * column
    if nuisance is not None:
        for beta, x in zip(nuisance, parts.nuisance.values()):
            inner = inner + beta * x
    flow = inner if _one(mod.flow_gain) else mod.flow_gain * inner
    if not _zero(mod.offset):
        return flow + mod.offset * parts.sign
    return flow.copy() if flow is parts.displacement else flow  # never the parts' own array


def _one(x: FloatArray | float) -> bool:
    """Tell whether `x` is the number 1 (not an array): a product by it changes nothing."""
    return isinstance(x, float | int) and x == 1.0


def _zero(x: FloatArray | float) -> bool:
    """Tell whether `x` is the number 0 (not an array): a sum with it changes nothing."""
    return isinstance(x, float | int) and x == 0.0


def loss_parts(model: MotorModel, table: BenchTable,
               clamp: bool = False) -> tuple[LossParts, np.ndarray]:
    """
    Evaluate the model's components at the table's points.

    Parameters
    ----------
    model : MotorModel
        The packaged (or user) model for the liquid, [-]
    table : BenchTable
        Steady operating points, [-]
    clamp : bool
        Keep a row whose channels take the whole port drop at the chamber drop 0, as the
        engine runs it (flagged channel-limited), instead of leaving it out: the base's
        profile of the channel drop (:mod:`.base`) so weighs the rows that speak against
        a large drop, [-]

    Returns
    -------
    LossParts
        Components at the usable points.
    ndarray of bool
        Which rows of `table` were usable (finite, a flow the model can give:
        not a shaft turning with the pressure and no flow that way, the
        channels not taking the whole port drop, dp_i within the model's limit).
        A shaft at rest may read a flow of either sign: its leak is small against the
        noise, and keeping the readings of one sign only would bias the rest points by
        the noise's half-mean (a phantom flow offset); a time series' samples are screened
        further (:func:`~satmotor_ros.identify.transient.at_rest`).

    Raises
    ------
    IdentificationError
        If no point is usable.

    """
    with np.errstate(invalid='ignore'):
        s = np.where(table.dp < 0.0, -1.0, np.where((table.dp == 0.0) & (table.flow < 0.0),
                                                    -1.0, 1.0))
        flow, speed, dp = s * table.flow, s * table.speed, s * table.dp  # the loss runs forward
        dp_i = s * model.chamber_drop(table.dp, table.flow)
        if clamp:
            dp_i = np.where(np.isfinite(dp_i), np.maximum(dp_i, 0.0), dp_i)
        usable = (np.isfinite(flow) & np.isfinite(speed) & np.isfinite(dp)
                  & ((flow > 0.0) | (speed <= 0.0)) & (dp_i >= 0.0) & (dp_i < model.dp_limit))
    if not usable.any():
        msg = (f'{table.source}: no usable point (need a flow, with the pressure drop unless '
               'the shaft turns against it, and a chamber pressure drop between 0 and '
               f'{model.dp_limit / 1e6:.1f} MPa)')
        raise IdentificationError(msg)
    n, dpi = speed[usable], dp_i[usable]
    sign, rotation = s[usable], np.sign(table.speed[usable])
    if model.family.name != 'sliwinski2017':
        return _family_parts(model, flow[usable], n, dp[usable], dpi, sign, rotation), usable
    coef = model.coef
    d = model.derived
    magnitude = np.abs(n)
    losses = model.breakdown(magnitude, dpi)
    beta = coef.beta
    pressure_speed = losses.compressibility + losses.deformation + losses.backlash
    components = (
        Component('leakage_scale', (('flat_clearance', losses.flat_clearance),
                                    ('commutation', losses.commutation)), 0.0, 0.0,
                  'A_1 (eq. 1) and C_1 (eq. 5)', 'leakage'),
        Component('c_scale', (('', pressure_speed),), 1.0,
                  model.c_fc_beta / model.c_lumped if model.c_lumped > 0 else 0.0, 'C (eq. 33)',
                  'pressure_speed'),
        Component('c_id_scale', (('', losses.inertia),), 0.5, 0.0, 'C_id (eq. 14)', 'inertia'))
    parts = LossParts(
        flow=flow[usable].copy(), speed=magnitude, dp=dp[usable].copy(), dp_i=dpi.copy(),
        displacement=model.geometry.displacement * n,
        clearance=clearance_height(dpi, d.h0, d.compliance),
        clearance_satellites=model.geometry.clearance_satellites,
        h_exponent=3.0 / (2.0 - beta), hs_exponent=coef.c2,
        nu_exponent_lfg=-beta / (2.0 - beta), nu_exponent_c=-coef.gamma,
        components=components, sign=sign, rotation=rotation)
    return parts, usable


GAP_LEAKAGE = ('leakage', 'laminar')
"""Linear parts of a family that are laminar flow through a gap: the clearance and viscosity
effects scale them as a plane gap would (Q ~ h^3 / nu)."""


def _family_parts(model: MotorModel, flow: FloatArray, n: FloatArray, dp: FloatArray,
                  dp_i: FloatArray, sign: FloatArray, rotation: FloatArray) -> LossParts:
    """
    Components of a family other than eqs. (31)-(33): one factor per linear part of its Q_vl.

    A part that is zero at every point (the external leakage of a set without one) is left
    out: no factor could be fitted on it. `n` is the speed in the row's frame (negative
    for a pump); `sign` and `rotation` are the rows' (:class:`LossParts`).
    """
    magnitude = np.abs(n)
    losses = model.family.linear_losses(model, magnitude, dp_i)
    components = []
    for part in model.family.linear_parts(model.coef):
        q = np.asarray(losses[part.name], dtype=float)
        if not np.any(q):
            continue
        modifier = '*'.join((*(('flat_clearance',) if part.name in GAP_LEAKAGE else ()),
                             *(('leakage',) if part.name in model.family.leakage else ())))
        components.append(Component(f'{part.name}_scale', ((modifier, q),), part.speed_exponent,
                                    0.0, f'{", ".join(part.coefficients)} ({part.source})',
                                    part.name))
    h = model.geometry.clearance_satellites
    return LossParts(flow=flow.copy(), speed=magnitude, dp=dp.copy(), dp_i=dp_i.copy(),
                     displacement=model.geometry.displacement * n,
                     clearance=np.full(n.shape, h), clearance_satellites=h, h_exponent=3.0,
                     hs_exponent=3.0, nu_exponent_lfg=-1.0, nu_exponent_c=-1.0,
                     components=tuple(components), sign=sign, rotation=rotation)
