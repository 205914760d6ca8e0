# SPDX-License-Identifier: Apache-2.0
"""
The baseline the monitor measures against: the model's volumetric losses at every sample.

The measured loss is Q_vl = Q - q_t n and the baseline's is the model's, both taken in the
frame where the loss runs forward, exactly as calibration and validation take them
(:func:`~satmotor_ros.identify.parts.loss_parts`, the prediction of
:class:`~satmotor_ros.identify.effects.CalibratedModel` with its effects and instruments):
nothing physical is written here.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import hashlib
from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.identify.calibrated import Calibrated
from satmotor_ros.identify.coverage import outside
from satmotor_ros.identify.effects import CalibratedModel
from satmotor_ros.identify.health.records import HealthSamples
from satmotor_ros.identify.parts import loss_parts
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.viscosity import standard_law

NU_EXPONENTS = (0.0, -0.25, -0.5, -1.0)
"""Powers of nu/nu_ref spanning the baseline's loss between nodes: the families' losses are
sums of such powers (laminar gaps -1, eqs. (1) and (5) -beta/(2-beta) and -gamma, eq. (29)
a_vv) and a constant; over 0.2-5 times the viscosity the span holds them within 3e-4 (1e-5
within +-20 K of the reference), from the reading and three more evaluations of the model."""

NU_NODES = (0.25, 0.5, 1.0, 2.0)
"""Viscosity factors the model is evaluated at (1: the reading itself), [-]."""

OK, STALLED, OUTSIDE_ENVELOPE, OUTSIDE_MODEL, STALE, NON_FINITE, IMPLAUSIBLE, PARKED = range(8)
"""Codes of :attr:`Losses.reason`, in the order of :data:`.records.SKIP_REASONS` plus OK."""

GROSS = 10.0
"""The physical envelope, in multiples of the model's validated range: a speed beyond GROSS
times its ``speed_max``, a gauge pressure beyond GROSS times its ``dp_max``, a flow beyond
the displacement flow at GROSS times ``speed_max`` is no reading of this motor (a broken
message, a logger's 1e30 fill value): counted and skipped as ``implausible``, like a
non-finite one. Real logs run to twice the range (the MBARI logs: 2x ``speed_max``), [-]."""

PARKED_FLOW = 0.05
"""A sample below ``min_speed`` whose flow is below this share of the displacement flow at the
model's ``speed_max`` is ``parked``: the motor stands still and nothing passes it but
leakage, nothing to judge and nothing wrong. With more flow it is ``stalled``: a speed
sensor that reads 0 on a running motor, or a shaft held against a load, [-]."""

TEMPERATURE_RANGE = (-100.0, 400.0)
"""Oil temperatures a hydraulic liquid can have; a reading outside is implausible, [degC]."""


@dataclass(frozen=True)
class Losses:
    """The losses at every sample of a block (NaN where not usable)."""

    measured: FloatArray  # Q - q_t n, in the loss's forward frame [m^3/s]
    baseline: FloatArray  # the model's Q_vl there [m^3/s]
    displacement: FloatArray  # |q_t n| [m^3/s]
    speed: FloatArray  # |n| [rad/s]
    dp: FloatArray  # |dp| [Pa]
    reason: np.ndarray  # int: OK or why the sample is skipped


class Baseline:
    """
    A motor model held as the healthy motor.

    Parameters
    ----------
    model : MotorModel
        The model, effects included (a calibrated ``coefficients.yaml``'s), [-]
    envelope : dict, optional
        The envelope it was calibrated on
        (:attr:`~satmotor_ros.identify.calibrated.Calibrated.envelope`); samples outside
        are skipped, [-]
    source : str
        Where it came from, for reports, [-]
    reference_temperature : float, optional
        The temperature at which the liquid has the model's viscosity; by default where
        the liquid's standard law (:func:`~satmotor_ros.model.viscosity.standard_law`)
        gives it, [degC]

    """

    def __init__(self, model: MotorModel, envelope: dict[str, Any] | None = None,
                 source: str = '', reference_temperature: float | None = None) -> None:
        """Hold the model, its bare copy (which places the points) and the envelope."""
        self.model = model
        self.envelope = envelope
        self.source = source or model.name
        self.calibrated = CalibratedModel(model)
        self._bare = MotorModel(model.geometry, replace(model.coefficient_set, effects=()),
                                model.valid_range, model.liquid, model.displacement_law,
                                model.name)
        self.law = standard_law(model.liquid, model.coefficient_set.name)
        self.uses_temperature = 'temperature' in model.channels
        self.reference_temperature = float(self.law.reference_temperature
                                           if reference_temperature is None
                                           else reference_temperature)
        self._thinned: dict[float, CalibratedModel] = {}
        nodes = np.asarray(NU_NODES)
        self._spread = np.linalg.inv(nodes[:, None] ** np.asarray(NU_EXPONENTS)[None, :])

    @classmethod
    def load(cls, path: str | Path, liquid: str) -> Baseline:
        """
        Load a motor file (a calibrated ``coefficients.yaml`` or a motor YAML).

        Parameters
        ----------
        path : str or pathlib.Path
            The file, [-]
        liquid : str
            Its coefficient set, [-]

        Returns
        -------
        Baseline
            The model with the envelope the file records (if any).

        """
        model = MotorModel.from_spec(load_motor(path), liquid)
        return cls(model, Calibrated(path).envelope, str(path))

    @classmethod
    def for_family(cls, family: str, displacement: float, liquid: str = 'oil') -> Baseline:
        """
        Use a family's documented defaults at a displacement.

        Parameters
        ----------
        family : str
            The model family, [-]
        displacement : float
            q_t/(2 pi), [m^3/rad]
        liquid : str
            ``'oil'`` or ``'water'``, [-]

        Returns
        -------
        Baseline
            The model, without an envelope.

        """
        model = MotorModel.for_displacement(displacement, family, liquid)
        return cls(model, None, f'{family} defaults at {displacement:.4g} m^3/rad')

    @property
    def fingerprint(self) -> str:
        """
        Return a short digest of the model: a state made against another one is refused.

        The family, geometry, coefficient set (effects included) and liquid as the model
        holds them, not the path they were read from.
        """
        model = self.model
        text = repr((model.name, model.family.name, model.geometry, model.coefficient_set,
                     model.liquid, model.displacement_law, self.envelope))
        return f'{model.name}#{hashlib.sha256(text.encode()).hexdigest()[:12]}'

    @property
    def displacement(self) -> float:
        """Return q_t/(2 pi), [m^3/rad]."""
        return float(self.model.geometry.displacement)

    def _at_viscosity(self, factor: float) -> CalibratedModel:
        """Return the model with its liquid's viscosity times `factor` (built once)."""
        if factor not in self._thinned:
            model = self.model
            liquid = replace(model.liquid,
                             kinematic_viscosity=model.liquid.kinematic_viscosity * factor)
            self._thinned[factor] = CalibratedModel(MotorModel(
                model.geometry, model.coefficient_set, model.valid_range, liquid,
                model.displacement_law, model.name))
        return self._thinned[factor]

    def _warm(self, reading: FloatArray, speed: FloatArray, channels: dict[str, FloatArray],
              dp_i: FloatArray, temperature: FloatArray) -> FloatArray:
        """
        Return the flow reading at the oil's temperature, for a model that does not read it.

        The liquid's standard law (:func:`~satmotor_ros.model.viscosity.standard_law`) gives
        r = nu(T)/nu(reference) with the reference :attr:`reference_temperature`. The model
        itself is evaluated at the viscosity times each of :data:`NU_NODES` (vectorised, as at
        its own) and the reading taken as the sum of the powers r^e of :data:`NU_EXPONENTS`
        through those nodes: each loss of the families is such a power of nu (eqs. (1), (5),
        (29)), so this is the model at nu(T) (within 3e-4 of its loss from 0.2 to 5 times
        the viscosity, ``test_baseline_follows_the_model_at_the_oil_s_viscosity``) at a
        bounded cost per sample; nothing about the losses is assumed here.
        """
        law = self.law
        ratio = (law.viscosity(temperature, law.standard_slope)
                 / law.viscosity(self.reference_temperature, law.standard_slope))
        r = np.where(np.isfinite(ratio) & (ratio > 0), ratio, 1.0)
        at = [reading if f == 1.0 else self._at_viscosity(f).measured_flow(
            speed, channels, dp_i=dp_i)[0] for f in NU_NODES]
        weights = (r[:, None] ** np.asarray(NU_EXPONENTS)[None, :]) @ self._spread
        warm: FloatArray = np.einsum('ij,ji->i', weights, np.asarray(at))
        return warm

    def physical(self, block: HealthSamples) -> np.ndarray:
        """
        Flag the samples inside the physical envelope (:data:`GROSS`), whatever their finiteness.

        Parameters
        ----------
        block : HealthSamples
            The samples, [-]

        Returns
        -------
        ndarray of bool
            False where a speed, a pressure, the flow or the temperature is gross.

        """
        valid = self.model.valid_range
        speed_max, p_max = GROSS * valid.speed_max, GROSS * valid.dp_max
        flow_max = speed_max * self.displacement
        with np.errstate(invalid='ignore'):
            inside = ((np.abs(block.speed) <= speed_max) & (np.abs(block.flow) <= flow_max)
                      & (np.abs(block.p_in) <= p_max) & (np.abs(block.p_out) <= p_max))
            if block.p_case is not None:
                inside &= ~(np.abs(block.p_case) > p_max)  # a NaN case pressure: not gross
            if block.temperature is not None:
                low, high = TEMPERATURE_RANGE
                inside &= ~((block.temperature < low) | (block.temperature > high))
        result: np.ndarray = inside
        return result

    def losses(self, block: HealthSamples, min_speed: float = 0.0) -> Losses:
        """
        Evaluate the measured and the baseline losses at every sample.

        Parameters
        ----------
        block : HealthSamples
            The samples, [-]
        min_speed : float
            Below this |n| a sample is stalled, [rad/s]

        Returns
        -------
        Losses
            Arrays as long as the block, with the reason a sample is skipped.

        """
        n = len(block)
        reason = np.full(n, OK, dtype=np.int8)
        finite = (np.isfinite(block.time) & np.isfinite(block.speed) & np.isfinite(block.flow)
                  & np.isfinite(block.p_in) & np.isfinite(block.p_out))
        channels: dict[str, FloatArray] = {'time': block.time}
        needs = set(self.model.channels)
        if 'p_case' in needs:
            # no case pressure measured: the case drains to the outlet, whose pressure drives
            channels['p_case'] = block.p_out if block.p_case is None else block.p_case
            finite &= np.isfinite(channels['p_case'])
        if block.temperature is not None:
            channels['temperature'] = block.temperature
            if self.uses_temperature:
                finite &= np.isfinite(block.temperature)
        reason[~finite] = NON_FINITE
        reason[finite & ~self.physical(block)] = IMPLAUSIBLE
        with np.errstate(invalid='ignore'):
            still = (reason == OK) & (np.abs(block.speed) < min_speed)
            quiet = np.abs(block.flow) <= PARKED_FLOW * self.model.valid_range.speed_max \
                * self.displacement
            reason[still & quiet] = PARKED
            reason[still & ~quiet] = STALLED
        if self.envelope is not None:
            out = outside(self.envelope, block.p_in - block.p_out, block.speed)
            reason[(reason == OK) & out] = OUTSIDE_ENVELOPE
        measured = np.full(n, np.nan)
        base, disp, speed, dp = measured.copy(), measured.copy(), measured.copy(), measured.copy()
        ok = reason == OK
        if ok.any():
            table = BenchTable(block.speed[ok], block.flow[ok], block.p_in[ok], block.p_out[ok],
                               {k: v[ok] for k, v in channels.items()}, time_series=True)
            try:
                parts, usable = loss_parts(self._bare, table)
            except ValueError:
                usable = np.zeros(int(ok.sum()), dtype=bool)
            idx = np.flatnonzero(ok)
            reason[idx[~usable]] = OUTSIDE_MODEL
            if usable.any():
                kept = table.select(usable)
                channels_kept = {**kept.channels, 'p_in': kept.p_in, 'p_out': kept.p_out}
                speed_signed, dp_i = parts.rotation * parts.speed, parts.sign * parts.dp_i
                reading, _ = self.calibrated.measured_flow(speed_signed, channels_kept,
                                                           dp_i=dp_i)
                if block.temperature is not None and not self.uses_temperature:
                    reading = self._warm(reading, speed_signed, channels_kept, dp_i,
                                         kept.channels['temperature'])
                at = idx[usable]
                good = np.isfinite(reading)
                reason[at[~good]] = OUTSIDE_MODEL
                at = at[good]
                sign = np.broadcast_to(parts.sign, reading.shape)[good]
                measured[at] = parts.loss[good]
                base[at] = sign * reading[good] - parts.displacement[good]
                disp[at] = np.abs(parts.displacement[good])
                speed[at], dp[at] = parts.speed[good], parts.dp[good]
        if block.stale is not None:
            reason[(reason == OK) & block.stale] = STALE
        return Losses(measured, base, disp, speed, dp, reason)


__all__ = ['Baseline', 'Losses']
