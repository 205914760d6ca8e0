# SPDX-License-Identifier: Apache-2.0
"""
A calibrated ``coefficients.yaml`` as the bench sees it: motor, effect and instruments.

:class:`~satmotor_ros.model.MotorModel` evaluates the ``effects:`` block
(:mod:`satmotor_ros.model.effects`); :class:`CalibratedModel` adds what the
instruments make of it, so that a calibrated file can be held against the
readings it was fitted on.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from satmotor_ros.identify.errors import DataError
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import flow_reading


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
        self.model = MotorModel.from_spec(load_motor(path), liquid)
        effects = self.model.effects
        if len(effects) > 1:
            msg = f'{path}: effects has {len(effects)} entries; one is supported'
            raise DataError(msg)
        self.effect = effects[0].name if effects else 'none'

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
            Channels (p_case or p_out [Pa], temperature [degC], time [s],
            revolutions [rev], any other); those the effect needs are used, [-]

        Returns
        -------
        ndarray
            Flow (NaN where the model flags the point invalid), [m^3/s]

        """
        needed = {name: channels[name] for name in self.model.channels}
        return self.model.absorbency(np.asarray(speed, dtype=float), dp=dp, errors='mask',
                                     channels=needed).flow

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
        flow = self.absorbency(self.model.true_speed(np.asarray(speed, dtype=float)), dp,
                               channels)
        return flow_reading(self.model.effects, flow)

    def describe(self) -> dict[str, Any]:
        """
        Return the effect as loaded.

        Returns
        -------
        dict
            ``{'effect': id, **fields}``; ``{'effect': 'none'}`` without one.

        """
        if not self.model.effects:
            return {'effect': 'none'}
        effect = self.model.effects[0]
        return {'effect': effect.name, 'regressor': effect.regressor,
                'coefficient': effect.coefficient}
