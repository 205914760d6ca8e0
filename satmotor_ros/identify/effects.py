# SPDX-License-Identifier: Apache-2.0
"""
A calibrated ``coefficients.yaml`` as the bench sees it: motor, effects and instruments.

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
from satmotor_ros.model import load_motor, MotorModel
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import effect_name, flow_reading, kind_of
from satmotor_ros.model.engine.screening import Status
from satmotor_ros.model.results import OperatingPoints


class CalibratedModel:
    """
    A calibrated motor: the fitted coefficient set plus its effects.

    Parameters
    ----------
    model : MotorModel
        The model of a coefficient set, its ``effects:`` block included, [-]

    """

    def __init__(self, model: MotorModel) -> None:
        """Hold the model and name its effects."""
        self.model = model
        self.effect = ', '.join(e.name for e in model.effects) or 'none'

    @classmethod
    def load(cls, path: str | Path, liquid: str) -> CalibratedModel:
        """
        Load a ``coefficients.yaml`` written by ``satmotor calibrate``.

        Parameters
        ----------
        path : str or pathlib.Path
            The file, [-]
        liquid : str
            The coefficient set in it, [-]

        Returns
        -------
        CalibratedModel
            The set with its effects.

        """
        return cls(MotorModel.from_spec(load_motor(path), liquid))

    def points(self, speed: FloatArray, channels: Mapping[str, FloatArray], *,
               dp: FloatArray | None = None, dp_i: FloatArray | None = None) -> OperatingPoints:
        """
        Compute the flow the motor absorbs, with the physical effects applied.

        Parameters
        ----------
        speed : ndarray
            True shaft speed, [rad/s]
        channels : mapping of str to ndarray
            Channels (p_case or p_out [Pa], temperature [degC], time [s],
            revolutions [rev], any other); those the effects need are used, [-]
        dp : ndarray, optional
            Port pressure drop (eqs. 34-36 solved together), [Pa]
        dp_i : ndarray, optional
            Chamber pressure drop instead of `dp` (eq. 36 directly), [Pa]

        Returns
        -------
        OperatingPoints
            The points (``errors='mask'``: NaN where the model flags a point invalid).

        """
        needed = {name: channels[name] for name in self.model.channels}
        return self.model.absorbency(np.asarray(speed, dtype=float), dp=dp, dp_i=dp_i,
                                     errors='mask', channels=needed)

    def measured_flow(self, speed: FloatArray, channels: Mapping[str, FloatArray], *,
                      dp: FloatArray | None = None,
                      dp_i: FloatArray | None = None) -> tuple[FloatArray, Status]:
        """
        Compute what the flowmeter reads at a measured speed, sensor effects included.

        With `dp_i` from the measured flow (:func:`~satmotor_ros.identify.parts.loss_parts`)
        this is the prediction the calibration fitted, eq. (36) of
        :func:`~satmotor_ros.identify.parts.predict_flow`.

        Parameters
        ----------
        speed : ndarray
            Speed as the speed sensor reads it, [rad/s]
        channels : mapping of str to ndarray
            Channels the effects need, [-]
        dp : ndarray, optional
            Port pressure drop, [Pa]
        dp_i : ndarray, optional
            Chamber pressure drop instead of `dp`, [Pa]

        Returns
        -------
        reading : ndarray
            Flowmeter reading (NaN where the point is invalid), [m^3/s]
        status : ndarray of uint8
            The model's PointStatus flags per point (EXTRAPOLATED: outside the
            validated range or an effect's fitted range), [-]

        """
        at = self.points(self.model.true_speed(np.asarray(speed, dtype=float)), channels,
                         dp=dp, dp_i=dp_i)
        return flow_reading(self.model.effects, at.flow), at.status

    def describe(self) -> list[dict[str, Any]]:
        """
        Return the effects as loaded.

        Returns
        -------
        list of dict
            ``{'effect': id, 'name': ..., 'direction': ..., 'regressor': ...,
            'coefficient': ...}`` per effect (a valve's ``threshold`` and ``exponent`` too),
            in the file's order; empty without one.

        """
        return [{'effect': e.name, 'name': effect_name(e), 'direction': e.direction,
                 'regressor': e.regressor, 'coefficient': e.coefficient,
                 **({'threshold': {'regressor': 'dp', 'value': e.reference, 'unit': 'Pa'},
                     'exponent': e.option('exponent', 1.0)} if kind_of(e).bypass else {})}
                for e in self.model.effects]
