"""The sustained value of a recorded signal, written independently of
:func:`sim.analysis.sizing.sustained`: at each sample, the exact integral of the samples'
piecewise-linear interpolant over the centred window (clipped to the record), by the trapezoid
rule on the samples inside it and the interpolated ends, divided by the window's length."""

from __future__ import annotations

import numpy as np


def window_mean(t: np.ndarray, x: np.ndarray, w: float) -> np.ndarray:
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    a = np.maximum(t[0], t - w / 2)
    b = np.minimum(t[-1], t + w / 2)
    # each window's points: its start, the samples strictly inside, its end; the windows are
    # laid out as the rows of one array (padded with the window's end: zero-width pieces)
    first = np.searchsorted(t, a, side="right")
    stop = np.searchsorted(t, b, side="left")
    k = np.arange(max(int((stop - first).max(initial=0)), 0))
    idx = first[:, None] + k[None, :]
    inner = np.where(idx < stop[:, None], t[np.minimum(idx, t.size - 1)], b[:, None])
    pts = np.concatenate([a[:, None], inner, b[:, None]], axis=1)
    vals = np.interp(pts, t, x)
    areas = np.sum(np.diff(pts, axis=1) * (vals[:, 1:] + vals[:, :-1]) / 2, axis=1)
    return areas / (b - a)


def sustained_peak(t: np.ndarray, x: np.ndarray, w: float) -> float:
    """max |window_mean|."""
    return float(np.abs(window_mean(t, x, w)).max())
