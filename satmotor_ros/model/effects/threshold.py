# SPDX-License-Identifier: Apache-2.0
"""
``threshold:dp``: a valve across the ports passing k max(0, |dp| - x_c)^e, dp the port drop.

A relief, bypass or anti-cavitation valve opens on the drop between the ports, and its flow
runs beside the motor's chambers and channels (:mod:`satmotor_ros.model.engine.valves`); it may
open for one sign of dp = p_a - p_b only (``direction``).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray, Real
from satmotor_ros.model.effects._base import (Candidate, CandidateData, DIRECTIONS, Effect,
                                              EffectKind, finite, Loss, Modifier, negative_rows,
                                              PlantParameter, Sampled, Shape, SHAPES_KEPT,
                                              Synthetic, two_sided)
from satmotor_ros.model.effects.term import MAX_EXPONENT
from satmotor_ros.model.errors import ConfigError
from satmotor_ros.model.units import LPM, MPA

MIN_ABOVE = {'both': (0.15, 4), 'positive': (0.01, 8), 'negative': (0.01, 8)}
"""Least share of the points, and least number, above a fitted threshold, [-]: a one-sided
valve opens near the top of its side's range, in one or a few per cent of a recording."""

STARTS = {'both': (0.3, 0.7), 'positive': (0.6, 0.9, 0.98), 'negative': (0.6, 0.9, 0.98)}
"""Starts of the fitted threshold: shares of the range it may take (both sides), quantiles of
the side's drops (one side: a valve cracks near the top of its side's range), [-]."""

RESPONSE_TIMES = (0.0, 1.0)
"""Range of the fitted response time of a valve read at every sample of a time series, [s]: 0
is the static law; a relief valve opens within a few tens to hundreds of milliseconds, so
a pressure peak shorter than that passes little of what the law gives at its top."""

STATIC = 1e-3
"""A valve's response time under this share of the sample step is the static law, [-]: a fit
left on the floor ends just above 0, where no sampling tells the lag from none."""

EXPONENTS = (0.05, 3.0)
"""Range of the fitted exponent e, [-]: below 1 down to a near step, a relief valve at its
pressure override, whose drop hardly rises while the flow it passes (set by the demand) does."""


class Threshold(EffectKind):
    """A flow that starts above a pressure drop: a relief or bypass valve cracking open."""

    name = 'threshold'
    suffixed = True
    rank = 85
    directional = True
    bypass = True
    keys = ('regressor', 'coefficient', 'reference', 'exponent', 'response_time')
    required = ('coefficient', 'reference')
    unit = 'm^3/s per Pa^e'
    source = 'a valve that cracks open (relief, bypass)'
    evaluation = ('a valve across the ports: flow k max(0, |dp| - reference)^exponent from the '
                  'high- to the low-pressure port, beside the chambers and channels, added to '
                  'Q and to Q_vl; dp [Pa] the port drop p_a - p_b, reference the cracking '
                  'drop [Pa]; only where dp has the sign direction names; response_time '
                  '[s]: read at every sample of a time series (calibrate, validate), the '
                  'flow follows the law through a first-order lag of that time constant; a '
                  'point is evaluated at the steady state, the law itself')

    plant_parameters = (
        PlantParameter('valve_conductance', 0.0, 'flow per Pa of port drop above the crack '
                       'pressure through a valve across the ports (threshold:dp, exponent 1)',
                       'm^3/(s*Pa)', 0.0, 1.0e-8),
        PlantParameter('valve_crack', 20.0e6, 'port drop where that valve cracks open',
                       'Pa', 0.0, 1.0e9),
        PlantParameter('valve_direction', 'both', 'sign of dp = p_a - p_b where it opens',
                       choices=DIRECTIONS),
    )

    def from_plant(self, values: Mapping[str, Any]) -> Effect | None:
        """Return the valve the node parameters set (exponent 1), None at k = 0."""
        k, direction = values['valve_conductance'], values['valve_direction']
        if direction not in DIRECTIONS:
            msg = f'effects.valve_direction = {direction!r}: use {", ".join(DIRECTIONS)}'
            raise ConfigError(msg)
        return Effect(f'{self.name}:dp', k, 'dp', values['valve_crack'],
                      options=(('exponent', 1.0),), direction=direction) if k else None

    def plant_values(self, effect: Effect | None) -> dict[str, Any]:
        """Return k, the crack pressure and the direction of `effect`."""
        if effect is None:
            return super().plant_values(None)
        return {'valve_conductance': effect.coefficient, 'valve_crack': effect.reference,
                'valve_direction': effect.direction}

    def named(self, effect: Effect) -> str:
        """Return ``threshold:dp@negative cracking at 19.87 MPa``: side and crack pressure."""
        return f'{effect.key} cracking at {effect.reference / MPA:.4g} MPa'

    def regressor(self, suffix: str, value: Any, where: str) -> str:
        """Read the regressor of the id's suffix: ``dp``."""
        if suffix != 'dp' or value not in (None, 'dp'):
            msg = f'{where}: a threshold reads the pressure drop: use threshold:dp'
            raise ConfigError(msg)
        return suffix

    def parse(self, name: str, doc: Mapping[str, Any], where: str) -> Effect:
        """Read k >= 0, the cracking drop >= 0, the exponent (default 1, > 0), the response."""
        regressor = self.regressor(name.partition(':')[2], doc.get('regressor'), where)
        exponent = finite(doc.get('exponent', 1.0), f'{where}.exponent')
        if not 0.0 < exponent <= MAX_EXPONENT:  # past it the flow overflows at bench drops
            msg = f'{where}.exponent = {exponent!r}: must be > 0 and at most {MAX_EXPONENT:g}'
            raise ConfigError(msg)
        coefficient = finite(doc['coefficient'], f'{where}.coefficient')
        reference = finite(doc['reference'], f'{where}.reference')
        for key, value in (('coefficient', coefficient), ('reference', reference)):
            if value < 0.0:  # a valve passes flow from the high- to the low-pressure port
                msg = f'{where}.{key} = {value!r}: must be >= 0 (a valve that cracks open)'
                raise ConfigError(msg)
        response = finite(doc.get('response_time', 0.0), f'{where}.response_time')
        if not RESPONSE_TIMES[0] <= response <= RESPONSE_TIMES[1]:
            msg = (f'{where}.response_time = {response!r}: must be within '
                   f'{RESPONSE_TIMES[0]:g}-{RESPONSE_TIMES[1]:g} s')
            raise ConfigError(msg)
        lag = (('response_time', response),) if response > 0.0 else ()
        return Effect(name, coefficient, regressor, reference,
                      options=(('exponent', exponent), *lag))

    def to_mapping(self, effect: Effect) -> dict[str, Any]:
        """Write k, the cracking drop, the exponent and a response time (when not 0)."""
        out = {'regressor': effect.regressor, 'coefficient': effect.coefficient,
               'reference': effect.reference, 'exponent': effect.option('exponent', 1.0)}
        response = effect.option('response_time', 0.0)
        return {**out, 'response_time': response} if response > 0.0 else out

    def loss(self, effect: Effect) -> Loss | None:
        """Return (n, dp) -> k max(0, |dp| - x_c)^e, dp the port drop (a bypass kind)."""
        k, x_c, e = effect.coefficient, effect.reference, effect.option('exponent', 1.0)

        def loss(n: Real, dp: Real) -> Real:
            if type(dp) is float:  # the point path: Python floats, no numpy scalar
                over = abs(dp) - x_c
                return k * over ** e if over > 0.0 else 0.0
            out: Real = k * np.maximum(abs(dp) - x_c, 0.0) ** e
            return out
        return loss

    def reads(self, effect: Effect) -> tuple[str, ...]:
        """Read the port drop only."""
        return ('dp',)

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """
        Offer a threshold within the data, k >= 0: on |dp| and, with both signs, each side.

        A relief, bypass or anti-cavitation valve usually opens for one sign of
        dp only; the one-sided candidates (``direction`` positive or negative)
        place the threshold among that side's points.
        """
        dp = np.abs(data.parts.dp)
        negative = negative_rows(data.parts)
        sides = [('both', np.ones(dp.shape, dtype=bool))]
        both = two_sided(data.parts)
        if both:
            sides += [('positive', ~negative), ('negative', negative)]
        out, skipped = [], []
        tops = _side_tops(dp, negative, data.samples)
        for direction, at in sides:
            # data of one sign are one side: the threshold may also sit near its top
            candidate = self._candidate(dp, at, direction, both, data.samples, tops)
            if candidate is None:
                skipped.append(f'{self.name}:dp ({direction}): too few points to place a '
                               'threshold')
            else:
                out.append(candidate)
        return out, skipped

    def _candidate(self, dp: FloatArray, at: np.ndarray, direction: str,
                   two: bool = True, samples: Sampled | None = None,
                   tops: tuple[float, float] = (np.inf, np.inf)) -> Candidate | None:
        """
        Return the candidate acting at `at` only, the threshold among those points.

        On data of one sign of dp (`two` false) the candidate on both sides is a one-sided
        valve too: its threshold may sit as near the top as a side's, and starts both
        within the range and at the side's quantiles. When the points are bins of a time
        series' `samples`, the valve's flow is computed at every sample and averaged over
        each bin, as the model evaluates it: the flow of a bin whose drop crosses the crack
        is not the flow at the bin's mean drop. A valve on both sides whose crack lies
        beyond every drop of one side (`tops`: the largest drop of each, positive then
        negative) acts on the other side only, and is written as that side's: the data
        cannot say whether it opens both ways.
        """
        ordered = np.sort(dp[at])
        share, least = MIN_ABOVE[direction if two else 'negative']
        above = max(least, int(np.ceil(share * ordered.size)))
        if ordered.size < 2 * above:
            return None
        low, high = float(ordered[above // 2]), float(ordered[-above])
        top = float(ordered[-1])
        if not top > high > low:
            return None
        acts = at.astype(float)
        step = samples.step if samples is not None else 0.0
        if samples is not None:
            over = _at_samples(samples, direction)
            known = ~np.isnan(over)
            order = np.flatnonzero(known)[np.argsort(over[known])]  # by drop, rising
            rising = over[order]
            shapes: dict[tuple[float, ...], FloatArray] = {}  # (x_c, e, tau) -> bins' flow
            lag = samples.lag

            def modify(k: float, x_c: float, e: float, tau: float = 0.0) -> Modifier:
                # a fit's finite differences in k and the other coefficients keep the
                # shape: its flow, the costly part (every sample), is computed once
                flow = shapes.get((x_c, e, tau))
                if flow is None:
                    if tau > 0.0 and lag is not None:  # the static law through the response
                        at = np.sort(order[np.searchsorted(rising, x_c, side='right'):])
                        reach, lagged = lag(at, ((over[at] - x_c) / (top - x_c)) ** e, tau)
                        held = known[reach]
                        flow = (samples.sparse(reach[held], lagged[held]) if samples.sparse
                                else samples.mean(_spread(reach[held], lagged[held], over)))
                    elif samples.sparse is not None and x_c < top:  # 0 at or below the crack
                        at = order[np.searchsorted(rising, x_c, side='right'):]
                        flow = samples.sparse(at, (np.maximum(over[at] - x_c, 0.0)
                                                   / (top - x_c)) ** e)
                    else:
                        flow = samples.mean((np.maximum(over - x_c, 0.0) / (top - x_c)) ** e)
                    if len(shapes) >= SHAPES_KEPT:
                        shapes.pop(next(iter(shapes)))
                    shapes[(x_c, e, tau)] = flow
                return Modifier(additive=acts * k * flow)
        else:
            def modify(k: float, x_c: float, e: float, tau: float = 0.0) -> Modifier:
                return Modifier(additive=acts * k * (np.maximum(dp - x_c, 0.0)
                                                     / (top - x_c)) ** e)

        def make(k: float, x_c: float, e: float, tau: float = 0.0) -> Effect:
            response = (('response_time', tau),) if tau > STATIC * step else ()
            return Effect(f'{self.name}:dp', k / (top - x_c) ** e, 'dp', x_c,
                          options=(('exponent', e), *response),
                          direction=supported(direction, x_c, tops))

        quantiles = tuple(float(np.clip((np.quantile(ordered, q) - low) / (high - low), 0.0,
                                        1.0)) for q in STARTS[direction if two else 'negative'])
        starts = (STARTS['both'] if direction == 'both' else ()) + (
            quantiles if direction != 'both' or not two else ())
        crack = Shape('threshold', starts, (0.0, 1.0), 'Pa', (low, high - low))
        shape: tuple[Shape, ...] = (crack, Shape('exponent', (1.0,), EXPONENTS))
        if samples is not None and samples.lag is not None and samples.step > 0.0:
            # read in time, it may lag its law (0: the law itself, a value, not a range's end)
            shape += (Shape('response time', (0.0,), RESPONSE_TIMES, 's',
                            floor_is_value=True),)
        return Candidate(f'{self.name}:dp', 'dp', self.unit, self.source, dp, modify,
                         LPM, (0.0, np.inf), 0.1 * LPM, make, shape, direction)

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """Inject `magnitude` [m^3/s] at the largest drop; ``reference``, ``exponent`` in shape."""
        shape = dict(data.shape)
        x_c, e = shape['reference'], shape.get('exponent', 1.0)
        drop = data.dp if data.dp is not None else data.dp_i  # the valve reads the port drop
        peak = float(np.max(np.maximum(np.abs(drop) - x_c, 0.0) ** e))
        return Effect(name, magnitude / max(peak, 1e-300), 'dp', x_c, options=(('exponent', e),))


def _spread(at: np.ndarray, values: FloatArray, over: FloatArray) -> FloatArray:
    """Return `values` at `at`, 0 at the other samples and NaN where `over` is NaN."""
    out = np.where(np.isnan(over), np.nan, 0.0)
    out[at] = values
    return out


def supported(direction: str, crack: float, tops: tuple[float, float]) -> str:
    """
    Return the side a valve acts on in the data: one side when the other holds no drop past it.

    Parameters
    ----------
    direction : str
        The candidate's direction (DIRECTIONS), [-]
    crack : float
        The fitted cracking drop, [Pa]
    tops : tuple of float
        The largest drop on the positive and on the negative side of dp, [Pa]

    Returns
    -------
    str
        `direction`, or for ``'both'`` the one side with drops past the crack when the other
        has none.

    """
    positive, negative = (top > crack for top in tops)
    if direction != 'both' or positive == negative:
        return direction
    return 'positive' if positive else 'negative'


def _side_tops(dp: FloatArray, negative: np.ndarray,
               samples: Sampled | None) -> tuple[float, float]:
    """Return the largest drop of each side, positive then negative (0 for none), [Pa]."""
    if samples is not None:  # the valve reads the drop at every sample
        signed = samples.dp[np.isfinite(samples.dp)]
        return (float(np.max(signed, initial=0.0)), float(np.max(-signed, initial=0.0)))
    return (float(np.max(dp[~negative], initial=0.0)), float(np.max(dp[negative], initial=0.0)))


def _at_samples(samples: Sampled, direction: str) -> FloatArray:
    """Return |dp| at the samples where a valve of `direction` may open (0 elsewhere), [Pa]."""
    dp = samples.dp
    if direction == 'both':
        return np.abs(dp)
    side = 1.0 if direction == 'positive' else -1.0
    return np.where(np.isnan(dp), np.nan, np.maximum(side * dp, 0.0))


KIND = Threshold()
