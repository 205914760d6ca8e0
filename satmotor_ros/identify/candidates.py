# SPDX-License-Identifier: Apache-2.0
"""
The library of candidate effects: every registered effect kind's candidates at the data.

Each kind (:mod:`satmotor_ros.model.effects`) builds its own candidates: the
vocabulary name, the regressor, the unit and source of the coefficient, and
a function from the coefficient to a :class:`Modifier` of the model's
prediction. A coefficient of 0 is always the model without the effect, so
every candidate nests the baseline. The library only builds candidates;
fitting and selection live in :mod:`.fit` and :mod:`.selection`.
"""

from __future__ import annotations

from collections.abc import Mapping

from satmotor_ros.identify.parts import LossParts
from satmotor_ros.model._typing import FloatArray
from satmotor_ros.model.effects import build_candidates, Candidate, CandidateData, Sampled
from satmotor_ros.model.viscosity import ViscosityLaw


def build_library(parts: LossParts, channels: Mapping[str, FloatArray], law: ViscosityLaw,
                  family: str = '', samples: Sampled | None = None
                  ) -> tuple[list[Candidate], list[str]]:
    """
    Build every candidate the data can test, kind by kind in the registry's order.

    Parameters
    ----------
    parts : LossParts
        Components at the points, [-]
    channels : mapping of str to ndarray
        Extra channels at the same points (SI; temperature in degC), [-]
    law : ViscosityLaw
        Viscosity law of the liquid, [-]
    family : str
        The model family of `parts`: kinds that do not apply to it are not offered;
        '' offers every kind, [-]
    samples : Sampled, optional
        The samples whose bins the points are (a time series' every sample): a kind
        nonlinear in the port drop is evaluated at them and averaged, [-]

    Returns
    -------
    list of Candidate
        The candidates, in a fixed order.
    list of str
        Why other candidates were not offered (missing or constant channel).

    """
    return build_candidates(CandidateData(parts, channels, law, frozenset(), family, samples))


__all__ = ['Candidate', 'Sampled', 'build_library']
