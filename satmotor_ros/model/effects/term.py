# SPDX-License-Identifier: Apache-2.0
"""``term:<expression>``: an extra loss k f(n, dp_i) in Q_vl, f one of :data:`TERMS`."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from satmotor_ros.model._typing import Real
from satmotor_ros.model.effects._base import (additive, Candidate, CandidateData, Effect,
                                              EffectKind, Loss, maker)
from satmotor_ros.model.errors import ConfigError

TERMS: Mapping[str, tuple[Loss, str]] = {
    'n^2': (lambda n, dp: n ** 2, 'm^3/s/(rad/s)^2'),
    'n^1.5': (lambda n, dp: n ** 1.5, 'm^3/s/(rad/s)^1.5'),
    'dp^2': (lambda n, dp: dp ** 2, 'm^3/s/Pa^2'),
    'dp^0.5': (lambda n, dp: dp ** 0.5, 'm^3/s/Pa^0.5'),
    'dp^2*n': (lambda n, dp: dp ** 2 * n, 'm^3/s/(Pa^2*rad/s)'),
    'dp*n^2': (lambda n, dp: dp * n ** 2, 'm^3/s/(Pa*(rad/s)^2)'),
    'dp*n^0.5': (lambda n, dp: dp * n ** 0.5, 'm^3/s/(Pa*(rad/s)^0.5)'),
    'dp^0.5*n': (lambda n, dp: dp ** 0.5 * n, 'm^3/s/(Pa^0.5*rad/s)'),
}
"""
Functions of speed n [rad/s] and chamber drop dp = dp_i [Pa] that eqs. (31)-(33) lack.

Left out on purpose, as the model or a named effect already has them: 1
(flowmeter offset), n (sensor gains), n^0.5 (C_id, eq. 14), dp*n (C, eq. 33)
and dp (the leakage of eqs. 1 and 5 is close to linear in dp).
"""


class Term(EffectKind):
    """A loss term the paper's eqs. (31)-(33) lack."""

    name = 'term'
    suffixed = True
    rank = 80
    source = 'not in eqs. (31)-(33)'
    evaluation = ('extra loss k f(n [rad/s], dp [Pa]) added to Q_vl (eq. 31), dp the chamber '
                  'drop dp_i of eq. (34)')

    def regressor(self, suffix: str, value: Any, where: str) -> str:
        """Read the expression of the name's suffix, one of :data:`TERMS`."""
        if suffix not in TERMS:
            msg = f'{where}: unknown term {suffix!r} (known: {", ".join(TERMS)})'
            raise ConfigError(msg)
        return suffix

    def loss(self, effect: Effect) -> Loss | None:
        """Return k f(n, dp_i)."""
        f, k = TERMS[effect.suffix][0], effect.coefficient

        def loss(n: Real, dp_i: Real) -> Real:
            return k * f(n, dp_i)
        return loss

    def candidates(self, data: CandidateData) -> tuple[list[Candidate], list[str]]:
        """Offer every expression of :data:`TERMS`."""
        out = []
        for expression, (f, unit) in TERMS.items():
            x = np.asarray(f(data.parts.speed, data.parts.dp_i), dtype=float)
            name = f'{self.name}:{expression}'
            out.append(additive(name, expression, unit, self.source, x,
                                make=maker(name, expression)))
        return out, []


KIND = Term()
