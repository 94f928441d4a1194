"""The sustained value of a recorded signal, written independently of
:func:`sim.analysis.sizing.sustained`: at each sample, the exact integral of the samples'
piecewise-linear interpolant over the centred window (clipped to the record), by the trapezoid
rule on the samples inside it and the interpolated ends, divided by the window's length."""

from __future__ import annotations

import numpy as np


def window_mean(t: np.ndarray, x: np.ndarray, w: float) -> np.ndarray:
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    out = np.empty(t.size)
    for i, ti in enumerate(t):
        a, b = max(t[0], ti - w / 2), min(t[-1], ti + w / 2)
        pts = np.concatenate([[a], t[(t > a) & (t < b)], [b]])
        out[i] = np.trapezoid(np.interp(pts, t, x), pts) / (b - a)
    return out


def sustained_peak(t: np.ndarray, x: np.ndarray, w: float) -> float:
    """max |window_mean|."""
    return float(np.abs(window_mean(t, x, w)).max())
