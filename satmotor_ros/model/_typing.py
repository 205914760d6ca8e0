# SPDX-License-Identifier: Apache-2.0
"""Array type aliases shared by the model."""

from __future__ import annotations

from typing import TypeAlias, TypeVar, Union

import numpy as np
import numpy.typing as npt

FloatArray: TypeAlias = npt.NDArray[np.float64]
ArrayLike: TypeAlias = Union[float, FloatArray]

Real = TypeVar('Real', float, FloatArray)
"""A Python float or a float array: an equation returns the kind it is given."""
