# SPDX-License-Identifier: Apache-2.0
"""Sensors: gain, bias, seeded white noise, sample-and-hold at a rate."""

from __future__ import annotations

import math

import numpy as np

from satmotor_ros.plant.params import SensorParams


class Sensor:
    """
    One sensed channel: reading = gain*g_e*value + bias + o_e + noise, (g_e, o_e) the effects.

    Parameters
    ----------
    params : SensorParams
        Noise, bias, gain and rate, [channel unit]
    rng : numpy.random.Generator
        Source of the noise (seeded by the plant), [-]
    error : tuple of float
        Gain g_e [-] and offset o_e [channel unit] of the injected effects
        (:func:`satmotor_ros.model.effects.sensor_error`), [-]

    """

    __slots__ = ('_gain', '_bias', '_noise', '_rate', '_index', '_held', '_rng')

    def __init__(self, params: SensorParams, rng: np.random.Generator,
                 error: tuple[float, float] = (1.0, 0.0)) -> None:
        """Fold the effects into one gain and one bias."""
        self._gain = params.gain * error[0]
        self._bias = params.bias + error[1]
        self._noise = params.noise
        self._rate = params.rate
        self._index = -1
        self._held = math.nan
        self._rng = rng

    def read(self, time: float, value: float) -> float:
        """
        Read the sensor at `time` while the true value is `value`.

        Parameters
        ----------
        time : float
            Simulation time, [s]
        value : float
            True value of the channel, [channel unit]

        Returns
        -------
        float
            The reading; held since the last sample when a rate is set, [channel unit]

        """
        if self._rate > 0.0:  # sample on the grid t = k / rate
            index = math.floor(time * self._rate + 1e-9)
            if index == self._index:
                return self._held
            self._index = index
        reading = self._gain * value + self._bias
        if self._noise > 0.0:
            reading += self._noise * float(self._rng.standard_normal())
        self._held = reading
        return reading
