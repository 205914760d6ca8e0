# SPDX-License-Identifier: Apache-2.0
"""
A model's prediction of the flow reading at measured points, as calibration and validation see it.

The motor is evaluated at the chamber drop the calibration uses
(:func:`~satmotor_ros.identify.parts.loss_parts`), a valve across the ports at the measured
port drop, and the flowmeter's effects are applied
(:func:`~satmotor_ros.model.effects.flow_reading`): the prediction that
:func:`~satmotor_ros.identify.parts.predict_flow` fits, made by the model itself.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from satmotor_ros.identify.effects import CalibratedModel
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.parts import LossParts
from satmotor_ros.identify.table import BenchTable
from satmotor_ros.model import MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import Effect, flow_reading, kind_of
from satmotor_ros.model.engine.valves import Valves
from satmotor_ros.model.results import PointStatus


def bare(model: MotorModel) -> MotorModel:
    """Return `model` without its effects: it only places the points (dp_i, usable rows)."""
    return with_only(model, ())


def with_only(model: MotorModel, effects: tuple[Effect, ...]) -> MotorModel:
    """Return `model` with only `effects`."""
    coefficient_set = replace(model.coefficient_set, effects=effects)
    return MotorModel(model.geometry, coefficient_set, model.valid_range, model.liquid,
                      model.displacement_law, model.name)


def responds(model: MotorModel) -> bool:
    """Return whether a valve of `model` has a response time (its flow depends on the past)."""
    return any(kind_of(e).bypass and e.option('response_time', 0.0) > 0.0 for e in model.effects)


def predicted(calibrated: CalibratedModel, points: BenchTable, parts: LossParts,
              lag: Callable[[FloatArray, float], FloatArray] | None = None
              ) -> tuple[FloatArray, np.ndarray]:
    """
    Predict the flow reading in each row's frame (as ``parts.flow``); which are EXTRAPOLATED.

    The motor is evaluated at the chamber drop the calibration uses; a valve across the
    ports (:mod:`~satmotor_ros.model.engine.valves`) at the measured port drop, as the
    calibration fitted it: through the chamber drop the model would place the valve at the
    port drop of the motor's own flow, lower than the one measured by the channel drop of the
    valve's flow, where a relief valve's steep law passes a fraction of what it passes.

    Parameters
    ----------
    calibrated : CalibratedModel
        The model, effects included, [-]
    points : BenchTable
        The points (their channels feed the effects), [-]
    parts : LossParts
        The components of the model without effects at them (speed, drops, frame), [-]
    lag : callable, optional
        (a quantity at each of the points, tau [s]) -> it through a first-order lag of tau:
        the points are a time series' samples in order, and a valve with a
        ``response_time`` passes its law's flow through it; without, the law itself, [-]

    Returns
    -------
    ndarray
        The flow reading predicted, times the row's frame sign (NaN where invalid), [m^3/s]
    ndarray of bool
        Which points the model flags EXTRAPOLATED.

    Raises
    ------
    DataError
        If the effects need a channel the points lack.

    """
    channels = {**points.channels, 'p_in': points.p_in, 'p_out': points.p_out}
    model = calibrated.model
    missing = [name for name in model.channels if name not in channels]
    if missing:
        msg = (f'{points.source}: no {", ".join(missing)} column, which the effects of '
               f'{model.name} need')
        raise DataError(msg)
    valves = Valves(model.effects)
    if valves:
        kept = tuple(e for e in model.effects if not kind_of(e).bypass)
        calibrated = CalibratedModel(with_only(model, kept))
    # the model takes the signed row; the parts hold it where its loss runs forward
    at = calibrated.points(model.true_speed(parts.rotation * parts.speed), channels,
                           dp_i=parts.sign * parts.dp_i)
    flow, extrapolated = at.flow, (at.status & int(PointStatus.EXTRAPOLATED)) != 0
    port = parts.sign * parts.dp
    for effect in (e for e in model.effects if kind_of(e).bypass):
        valve_of = Valves((effect,))
        opened = [valve_of.flow(float(x)) for x in port]
        valve = np.array([v for v, _ in opened])
        tau = effect.option('response_time', 0.0)
        flow = flow + (lag(valve, tau) if tau > 0.0 and lag is not None else valve)
        extrapolated = extrapolated | np.array([f for _, f in opened], dtype=bool)
    return parts.sign * flow_reading(model.effects, flow), extrapolated


__all__ = ['bare', 'predicted', 'responds', 'with_only']
