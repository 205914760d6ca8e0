# SPDX-License-Identifier: Apache-2.0
"""What the reports share: axes one outlier cannot squash, marks, one legend each, paths."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from satmotor_ros.model._typing import FloatArray

FAR = 5.0
"""Interquartile ranges beyond the quartiles where a plot's axis ends: a point beyond is drawn
at the edge and marked, so one outlier does not squash the others into a line."""


def robust_limits(values: FloatArray) -> tuple[float, float]:
    """
    Give axis limits that hold every value but the far outliers, and 0.

    Parameters
    ----------
    values : ndarray
        What the axis shows (non-finite values are ignored), [any]

    Returns
    -------
    tuple of float
        Lower and upper limit: the data's range cut at :data:`FAR` interquartile ranges
        beyond the quartiles, widened by 5 % on each side, [unit of values]

    """
    v = values[np.isfinite(values)]
    if not v.size:
        return -1.0, 1.0
    q1, q3 = np.percentile(v, [25.0, 75.0])
    spread = q3 - q1
    lo, hi = float(v.min()), float(v.max())
    if spread > 0.0:
        lo, hi = max(lo, q1 - FAR * spread), min(hi, q3 + FAR * spread)
    lo, hi = min(lo, 0.0), max(hi, 0.0)
    pad = 0.05 * (hi - lo) if hi > lo else max(abs(hi), 1e-12)
    return lo - pad, hi + pad


def draw_beyond(ax: Any, x: FloatArray, y: FloatArray, limits: tuple[float, float],
                color: str) -> np.ndarray:
    """
    Draw the points beyond the y limits at the edge as outward triangles.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes, [-]
    x, y : ndarray
        The points, [any]
    limits : tuple of float
        The y axis' limits (:func:`robust_limits`), [unit of y]
    color : str
        The points' colour, [-]

    Returns
    -------
    ndarray of bool
        Which points are beyond.

    """
    lo, hi = limits
    for beyond, edge, marker in ((y > hi, hi, '^'), (y < lo, lo, 'v')):
        if beyond.any():
            ax.plot(x[beyond], np.full(int(beyond.sum()), edge), marker, ms=7, color=color,
                    mec='k', mew=0.6, clip_on=False, zorder=5)
    return np.asarray((y > hi) | (y < lo))


def unique_legend(ax: Any, **kwargs: Any) -> None:
    """
    Draw an axes' legend with each label once (the first artist of that label).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes, [-]
    **kwargs
        Passed to ``ax.legend``, [-]

    """
    handles, labels = ax.get_legend_handles_labels()
    first = dict(zip(reversed(labels), reversed(handles)))
    ax.legend([first[label] for label in dict.fromkeys(labels)], list(dict.fromkeys(labels)),
              **kwargs)


MARK_STYLES = ({'marker': 'o', 'mfc': 'none', 'mec': 'red', 'ms': 9, 'mew': 1.3},
               {'marker': 's', 'mfc': 'none', 'mec': 'darkorange', 'ms': 8, 'mew': 1.1})
"""How :func:`plot_residual_grid` rings the marked points (outliers, EXTRAPOLATED, ...)."""


def portable(source: str) -> str:
    """
    Show a data path in a report without the machine's directories.

    Parameters
    ----------
    source : str
        The path as read, [-]

    Returns
    -------
    str
        A relative path as it is; an absolute one relative to the working directory when
        under it, else its name alone, [-]

    """
    path = Path(source)
    if not path.is_absolute():
        return source
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return path.name


BEFORE_COLOR = '0.6'
"""Grey: the residual before any effect, drawn under the others so that what changed shows."""


def residual_colors(count: int) -> list[str]:
    """
    Colour residual series: the first (before) grey when there are several, then C0, C1, ...

    Parameters
    ----------
    count : int
        Number of series, [-]

    Returns
    -------
    list of str
        A matplotlib colour per series, [-]

    """
    several = count > 1
    return [BEFORE_COLOR] * several + [f'C{k}' for k in range(count - several)]


__all__ = ['BEFORE_COLOR', 'FAR', 'MARK_STYLES', 'draw_beyond', 'portable', 'residual_colors',
           'robust_limits', 'unique_legend']
