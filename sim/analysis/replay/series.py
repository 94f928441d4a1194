"""The replay's charts and tool paths, decimated to what a screen shows.

Chart series keep their peaks: the samples are cut into one bin per pixel column and each bin
gives its minimum and its maximum (at the bin's first and last time), so a spike one sample
wide is still drawn at its height. Tool paths keep one point per display step.

May import: numpy only.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: Pixel columns a chart is decimated to (two points each: min and max).
CHART_COLUMNS = 1200

#: Most points of one tool path.
PATH_POINTS = 8000


def minmax_bins(t: NDArray[np.float64], ys: NDArray[np.float64],
                columns: int = CHART_COLUMNS) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(x, y)`` with ``x`` (2*B,) and ``y`` (k, 2*B): per bin its min at the bin's first time
    and its max at its last time, for every column of ``ys`` (n, k). Fewer samples than
    ``2*columns`` are returned as they are."""
    t = np.asarray(t, np.float64)
    ys = np.asarray(ys, np.float64).reshape(t.size, -1)
    if t.size <= 2 * columns:
        return t.copy(), ys.T.copy()
    starts = np.unique(np.linspace(0, t.size, columns, endpoint=False).astype(np.int64))
    ends = np.append(starts[1:], t.size) - 1
    lo = np.minimum.reduceat(ys, starts, axis=0)
    hi = np.maximum.reduceat(ys, starts, axis=0)
    x = np.empty(2 * starts.size)
    x[0::2], x[1::2] = t[starts], t[ends]
    y = np.empty((ys.shape[1], 2 * starts.size))
    y[:, 0::2], y[:, 1::2] = lo.T, hi.T
    return x, y


def path_indices(n: int, points: int = PATH_POINTS) -> NDArray[np.int64]:
    """Evenly spaced sample indices (first and last included) for a path of ``n`` samples."""
    if n <= points:
        return np.arange(n, dtype=np.int64)
    return np.unique(np.linspace(0, n - 1, points).round().astype(np.int64))
