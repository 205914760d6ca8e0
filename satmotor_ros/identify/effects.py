# SPDX-License-Identifier: Apache-2.0
"""
Evaluate a calibrated ``coefficients.yaml`` with its ``effects:`` block.

:class:`~satmotor_ros.model.MotorModel` loads the fitted coefficients but
does not evaluate the ``effects:`` block yet. :class:`CalibratedModel` is
the reference of what it must do, one rule per effect (also written into
each block as ``evaluation``); the tests check that a calibrated file
reproduces the data it was fitted on through this class alone.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from satmotor_ros.identify.candidates import TERMS
from satmotor_ros.identify.errors import DataError
from satmotor_ros.identify.viscosity import vogel_viscosity, walther_viscosity
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model._typing import FloatArray
import yaml

_LEVELS = 400
"""Distinct model instances at most when a liquid or geometry varies per point."""


class CalibratedModel:
    """
    A calibrated motor: the fitted coefficient set plus its effect.

    Parameters
    ----------
    path : str or pathlib.Path
        A ``coefficients.yaml`` written by ``satmotor calibrate``, [-]
    liquid : str
        The coefficient set in it, [-]

    """

    def __init__(self, path: str | Path, liquid: str) -> None:
        """Load the set and its effects block."""
        spec = load_motor(path)
        doc = yaml.safe_load(Path(path).read_text(encoding='utf-8'))
        self.model = MotorModel.from_spec(spec, liquid)
        effects = doc['coefficient_sets'][liquid].get('effects') or {}
        if len(effects) > 1:
            msg = f'{path}: effects has {len(effects)} entries; one is supported'
            raise DataError(msg)
        self.effect, self.block = next(iter(effects.items()), ('none', {}))

    def _grouped(self, models: list[MotorModel], group: np.ndarray, speed: FloatArray,
                 dp: FloatArray) -> tuple[FloatArray, FloatArray]:
        flow, dp_i = np.empty_like(speed), np.empty_like(speed)
        for g, model in enumerate(models):
            at = group == g
            if at.any():
                op = model.absorbency(speed[at], dp=dp[at])
                flow[at], dp_i[at] = op.flow, op.dp_i
        return flow, dp_i

    def _levels(self, value: FloatArray) -> tuple[FloatArray, np.ndarray]:
        lo, hi = float(np.min(value)), float(np.max(value))
        step = (hi - lo) / (_LEVELS - 1) if hi > lo else 1.0
        index = np.round((value - lo) / step).astype(int)
        levels, group = np.unique(index, return_inverse=True)
        return lo + levels * step, group

    def absorbency(self, speed: FloatArray, dp: FloatArray,
                   channels: Mapping[str, FloatArray]) -> FloatArray:
        """
        Compute the flow the motor absorbs, with the physical effect applied.

        Parameters
        ----------
        speed : ndarray
            True shaft speed, [rad/s]
        dp : ndarray
            Port pressure drop, [Pa]
        channels : mapping of str to ndarray
            Channels the effect needs (p_case or p_out [Pa], temperature
            [degC], time [s], revolutions [rev], any other), [-]

        Returns
        -------
        ndarray
            Flow, [m^3/s]

        """
        speed, dp = np.asarray(speed, dtype=float), np.asarray(dp, dtype=float)
        model, block, effect = self.model, self.block, self.effect
        k = float(block.get('coefficient', 0.0))
        if effect == 'external_leakage':
            return model.absorbency(speed, dp=dp, p_ex=channels[block['regressor']]).flow
        if effect == 'viscosity_temperature':
            law = vogel_viscosity if block['law'] == 'vogel' else walther_viscosity
            levels, group = self._levels(np.asarray(channels['temperature'], dtype=float))
            nus = law(levels, block['reference_temperature'], block['reference_viscosity'], k)
            models = [MotorModel(model.geometry, model.coefficient_set, model.valid_range,
                                 replace(model.liquid, kinematic_viscosity=float(nu)))
                      for nu in nus]
            return self._grouped(models, group, speed, dp)[0]
        if effect == 'clearance_wear':
            x = np.asarray(channels[block['regressor']], dtype=float) - block['reference']
            levels, group = self._levels(np.maximum(k * x, 0.0))
            g = model.geometry
            models = [MotorModel(replace(g, clearance_rotor=g.clearance_rotor + d,
                                         clearance_satellites=g.clearance_satellites + d),
                                 model.coefficient_set, model.valid_range, model.liquid)
                      for d in levels]
            return self._grouped(models, group, speed, dp)[0]
        op = model.absorbency(speed, dp=dp)
        if effect.startswith('channel:'):
            x = np.asarray(channels[block['regressor']], dtype=float)
            return op.flow + k * (x - block['reference'])
        if effect.startswith('term:'):
            return op.flow + k * TERMS[block['regressor']][0](speed, op.dp_i)
        return op.flow

    def measured_flow(self, speed: FloatArray, dp: FloatArray,
                      channels: Mapping[str, FloatArray]) -> FloatArray:
        """
        Compute what the flowmeter reads at a measured speed, sensor effects included.

        Parameters
        ----------
        speed : ndarray
            Speed as the speed sensor reads it, [rad/s]
        dp : ndarray
            Port pressure drop, [Pa]
        channels : mapping of str to ndarray
            Channels the effect needs, [-]

        Returns
        -------
        ndarray
            Flowmeter reading, [m^3/s]

        """
        k = float(self.block.get('coefficient', 0.0))
        speed = np.asarray(speed, dtype=float)
        if self.effect == 'speed_sensor_gain':
            speed = speed / (1.0 + k)
        flow = self.absorbency(speed, dp, channels)
        if self.effect == 'flow_sensor_gain':
            return (1.0 + k) * flow
        if self.effect == 'flow_sensor_offset':
            return flow + k
        return flow

    def describe(self) -> dict[str, Any]:
        """
        Return the effect block as loaded.

        Returns
        -------
        dict
            ``{'effect': id, **block}``.

        """
        return {'effect': self.effect, **self.block}
