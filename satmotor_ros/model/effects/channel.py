# SPDX-License-Identifier: Apache-2.0
"""``channel:<name>``: an extra loss k (x - reference) in Q_vl, x the measured channel <name>."""

from __future__ import annotations

from typing import Any

import numpy as np

from satmotor_ros.model.effects._base import (additive, Candidate, CandidateData, Conditions,
                                              Effect, EffectKind, maker, Synthetic, varies,
                                              why_not)
from satmotor_ros.model.errors import ConfigError


class Channel(EffectKind):
    """A generic linear effect of a channel no named kind explains."""

    name = 'channel'
    suffixed = True
    rank = 70
    directional = True
    keys = ('regressor', 'coefficient', 'reference')
    required = ('coefficient', 'reference')
    reads_channel = True
    unit = 'm^3/s per channel unit'
    source = 'measured channel (no physical model)'
    evaluation = 'extra loss k (x - reference) added to Q_vl (eq. 31), x the channel'

    def regressor(self, suffix: str, value: Any, where: str) -> str:
        """Read its own channel, the name's suffix."""
        if value is not None and str(value) != suffix:
            msg = f'{where}.regressor = {value!r}: a channel effect reads its own channel'
            raise ConfigError(msg)
        return suffix

    def condition(self, effect: Effect, x: float, now: Conditions) -> Conditions:
        """Add k (x - reference) to the loss."""
        return now._replace(extra=now.extra + effect.coefficient * (x - effect.reference))

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer k for every extra channel that varies and no named kind reads."""
        out, skipped = [], []
        for name, values in data.channels.items():
            if name in data.covered:
                continue
            if values is None or not varies(values):
                skipped.append(f'{self.name}:{name}: {why_not(values)}')
                continue
            mean = float(np.mean(values))
            out.append(additive(f'{self.name}:{name}', name, f'm^3/s per {name} unit',
                                self.source, values - mean, values=values,
                                make=maker(f'{self.name}:{name}', name, mean)))
        return out, skipped

    def scaled(self, name: str, magnitude: float, regressor: str, data: Synthetic) -> Effect:
        """Change the loss by `magnitude` [m^3/s] peak to peak, zero at the channel's mean."""
        x = data.channels[name.partition(':')[2]]
        return Effect(name, magnitude / max(float(np.ptp(x)), 1e-300), name.partition(':')[2],
                      reference=float(np.mean(x)))


KIND = Channel()
