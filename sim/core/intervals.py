"""Runs of True in a boolean series, as index ranges (saturation intervals, arc-on stretches,
phase bands)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike


def true_runs(mask: ArrayLike) -> list[tuple[int, int]]:
    """``[start, stop)`` index ranges where the 1-D ``mask`` is true, in order."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(m))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))
