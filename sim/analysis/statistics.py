"""Time-signal statistics of a sampled record: time-weighted integrals, RMS, peaks, the
signal sustained over a window, margins.

Owns the signal primitives sizing and selection compute their numbers from. Every integral is
the trapezoidal rule over the samples' own, possibly non-uniform, times (not a plain mean of
samples); ``T`` is the record's duration ``t[-1] - t[0]``.
May import: numpy and :mod:`sim.errors` only.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import CellsimError


def as_time(t: ArrayLike) -> NDArray[np.float64]:
    """``t`` as a float time vector, checked: 1-D, at least 2 samples, finite, strictly
    increasing.

    Raises:
        CellsimError: Otherwise.
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise CellsimError(f"time vector t must be 1-D with at least 2 samples, got shape "
                           f"{t.shape}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise CellsimError("time vector t must be finite and strictly increasing")
    return t


def time_integral(t: ArrayLike, x: ArrayLike) -> NDArray[np.float64] | float:
    """Trapezoidal integral ``int x dt`` over the samples' own times.

    Args:
        t: Sample times, s, shape (N,), strictly increasing (spacing may vary).
        x: Samples, shape (N,) or (N, n).

    Returns:
        The integral, a float or shape (n,).
    """
    t = as_time(t)
    x = np.asarray(x, dtype=float)
    dt = np.diff(t)
    mid = 0.5 * (x[1:] + x[:-1])
    terms = dt.reshape((-1,) + (1,) * (mid.ndim - 1)) * mid
    flat = terms.reshape(terms.shape[0], -1)
    # an exactly rounded sum (exact_sum, math.fsum's result): the same bits whatever BLAS, its
    # thread count or the arrays' alignment (a sweep on Ray, one thread per task, gives the
    # pool's table exactly); numpy's sum where a term is not finite (fsum raises on inf - inf
    # and on overflow)
    out = np.array([_sum(col) for col in flat.T])
    return float(out[0]) if terms.ndim == 1 else out.reshape(terms.shape[1:])


#: Veltkamp's splitter for float64, ``2**27 + 1``: ``x`` is ``hi + lo`` exactly, each half
#: within 26 bits of ``x``'s own exponent.
_SPLIT = 134217729.0

#: Mantissa bits in each of the two halves :func:`_exact_sum_integers` adds separately.
_HALF_BITS = 26

#: Exponent field from which :func:`exact_sum` leaves the sum to ``math.fsum`` (``|x| >=
#: 2**995``: the split, or ``fsum``'s partial sums, could overflow).
_BIG_EXPONENT = 1023 + 995

#: Accumulators per exponent group in :func:`_grouped_sum` (the values' positions modulo 8):
#: a record's values share a few exponents, and one accumulator per group would make each
#: addition wait for the one before (bincount latency-bound, 2.3x slower on a sizing's
#: columns). Each lane's sum is exact as its group's is.
_LANE_BITS = 3

#: The latest lane numbers (positions modulo 2**_LANE_BITS), for one record length.
_LANES: list[NDArray[np.int64]] = []


def exact_sum(x: NDArray[np.float64]) -> float:
    """The exactly rounded sum of finite float64 values ``x`` (1-D): ``math.fsum``'s result,
    bit for bit (both round the exact sum to the nearest double, ties to even), faster on
    long records.

    The values are grouped by their exponent field; each value is split (Veltkamp) into two
    halves of at most 26 and 27 significant bits, whose sums within a group are exact in
    float64 in any order (fewer than 2**25 values). ``math.fsum`` of those exact group sums
    is then the exactly rounded total. ``math.fsum`` itself where the total is zero (its sign
    of zero), the record is longer or a value is so large that the split could overflow;
    subnormal values (where the split is not exact) are summed as integers
    (:func:`_exact_sum_integers`).
    """
    x = np.ascontiguousarray(x, dtype=np.float64).reshape(-1)
    if x.size == 0 or x.size >= (1 << 25):
        return math.fsum(x.tolist())
    ex = x.view(np.int64) >> 52
    ex &= 0x7FF
    return _grouped_sum(x, ex)


def _sum(x: NDArray[np.float64]) -> float:
    """:func:`exact_sum` of a column whose terms are finite, numpy's sum where one is not
    (``fsum`` raises on ``inf - inf``); the finiteness read from the exponent fields."""
    x = np.ascontiguousarray(x, dtype=np.float64).reshape(-1)
    if x.size == 0 or x.size >= (1 << 25):
        return exact_sum(x) if np.all(np.isfinite(x)) else float(np.sum(x))
    ex = x.view(np.int64) >> 52
    ex &= 0x7FF
    if int(ex.max()) == 0x7FF:  # an inf or a NaN
        return float(np.sum(x))
    return _grouped_sum(x, ex)


def _grouped_sum(x: NDArray[np.float64], ex: NDArray[np.int64]) -> float:
    """:func:`exact_sum` of ``x`` (1-D, contiguous, fewer than 2**25 values) given each
    value's exponent field ``ex``."""
    if int(ex.max()) >= _BIG_EXPONENT:
        return math.fsum(x.tolist())
    if int(ex.min()) == 0 and np.any(x[ex == 0]):  # a subnormal value
        return _exact_sum_integers(x)
    # x = hi + lo exactly (Veltkamp: c = (2**27 + 1) x, hi = c - (c - x), lo = x - hi). For x
    # of exponent field e: hi is a multiple of 2**(e - 1048), |hi| <= 2**(e - 1022); lo a
    # multiple of 2**(e - 1075), |lo| <= 2**(e - 1049). Each group's sums are then below
    # 2**53 of their units: exact, in bincount's order too, and split among the lanes (each
    # lane's sums are of fewer values of the same units)
    c = x * _SPLIT
    hi = c - x
    np.subtract(c, hi, out=hi)
    np.subtract(x, hi, out=c)  # c is now lo
    if not _LANES or _LANES[0].size != x.size:
        _LANES[:] = [np.arange(x.size, dtype=np.int64) & ((1 << _LANE_BITS) - 1)]
    group = ex << _LANE_BITS
    group |= _LANES[0]
    bins = 2047 << _LANE_BITS
    sums = np.concatenate([np.bincount(group, weights=hi, minlength=bins),
                           np.bincount(group, weights=c, minlength=bins)])
    total = math.fsum(sums[sums != 0.0].tolist())
    if total == 0.0:
        return math.fsum(x.tolist())
    return total


def _exact_sum_integers(x: NDArray[np.float64]) -> float:
    """:func:`exact_sum` of finite ``x`` (1-D, contiguous, fewer than 2**25 values, below
    2**997) as integers, subnormal values too.

    Each value is ``m 2**(e - 1075)`` with an integer mantissa ``m`` (53 bits, signed) and its
    exponent field ``e``; the mantissas' high and low halves (27 and 26 bits) are summed per
    exponent in float64 (integers below 2**53 for fewer than 2**25 values: exact in any
    order), the sums combined as one Python integer and divided by ``2**1075`` (Python's
    integer division rounds exactly).
    """
    bits = x.view(np.int64)
    ex = (bits >> 52) & 0x7FF
    man = bits & ((1 << 52) - 1)
    man |= (ex > 0).astype(np.int64) << 52  # the implicit bit of a normal value
    ex = np.maximum(ex, 1)  # a subnormal's scale is the smallest normal's
    np.negative(man, out=man, where=bits < 0)
    hi = man >> _HALF_BITS
    lo = man & ((1 << _HALF_BITS) - 1)
    sums_hi = np.bincount(ex, weights=hi, minlength=2047)
    sums_lo = np.bincount(ex, weights=lo, minlength=2047)
    total = 0
    for k in np.flatnonzero((sums_hi != 0) | (sums_lo != 0)).tolist():
        total += ((int(sums_hi[k]) << _HALF_BITS) + int(sums_lo[k])) << k
    if total == 0:
        return math.fsum(x.tolist())
    return total / (1 << 1075)


def rms(t: ArrayLike, x: ArrayLike) -> NDArray[np.float64] | float:
    """Time-weighted RMS ``sqrt(1/T int x^2 dt)`` (trapezoidal), ``T = t[-1] - t[0]``.

    Args:
        t: Sample times, s, shape (N,).
        x: Samples, shape (N,) or (N, n).

    Returns:
        The RMS value(s), same unit as ``x``; a float or shape (n,).
    """
    t = as_time(t)
    x = np.asarray(x, dtype=float)
    return np.sqrt(time_integral(t, x * x) / (t[-1] - t[0]))


def peak_abs(t: ArrayLike, x: ArrayLike) -> tuple[float, float]:
    """Largest ``|x|`` and the (first) time it occurs.

    Args:
        t: Sample times, s, shape (N,).
        x: Samples, shape (N,).

    Returns:
        ``(value, time)``; value >= 0 in the unit of ``x``, time in s.
    """
    x = np.abs(np.asarray(x, dtype=float))
    i = int(np.argmax(x))
    return float(x[i]), float(np.asarray(t, dtype=float)[i])


def sustained(t: ArrayLike, x: ArrayLike, window: float) -> NDArray[np.float64]:
    """The centred sliding mean of ``x`` over ``window`` s at each sample: ``1/w int x dt``
    over ``[t - w/2, t + w/2]`` clipped to the record, the exact integral of the samples'
    piecewise-linear interpolant (the trapezoidal rule on the samples' own times, the window's
    ends interpolated); ``x`` itself when ``window <= 0``.

    Args:
        t: Sample times, s, shape (N,), strictly increasing.
        x: Samples, shape (N,) or (N, n).
        window: Window length, s.

    Returns:
        The sustained signal, shape of ``x``.
    """
    t = as_time(t)
    x = np.asarray(x, dtype=float)
    if window <= 0.0:
        return x
    flat = x.reshape(t.size, -1)
    c = np.concatenate([np.zeros((1, flat.shape[1])),
                        np.cumsum(0.5 * (flat[1:] + flat[:-1]) * np.diff(t)[:, None], axis=0)])
    lo, hi, width, inside, everywhere = _windows(t, window)

    slope = np.diff(flat, axis=0) / np.diff(t)[:, None]

    def integral_to(end: Any) -> NDArray[np.float64]:
        # int from t[0] to s: whole trapezoids up to the sample before s (k), then the part
        # trapezoid from that sample to s (x linear in between; half = (s - t[k]) / 2)
        s, k, half, ds, at_k, at_next = end
        xk = flat[k]
        # x at s: np.interp's value (the same operations, its sample value where s is one)
        xs = slope[k] * ds + xk
        np.copyto(xs, xk, where=at_k)  # (most ends, on a uniform record)
        xs[at_next] = flat[k[at_next] + 1]
        if np.isnan(xs).any():  # a value that is not finite: np.interp's own fallbacks
            xs = np.stack([np.interp(s, t, flat[:, m]) for m in range(flat.shape[1])], axis=1)
        return c[k] + half * (xk + xs)

    mean = integral_to(hi) - integral_to(lo)
    if everywhere:  # every window has a width: the same quotients, without the masks
        return (mean / width[:, None]).reshape(x.shape)
    out = flat.copy()
    out[inside] = mean[inside] / width[inside, None]
    return out.reshape(x.shape)


#: The latest window bounds of :func:`sustained` (times, window, bounds): a sizing takes
#: every signal of a record over the same times and window.
_WINDOWS: list[tuple[NDArray[np.float64], float, Any]] = []


def _same_times(a: NDArray[np.float64], b: NDArray[np.float64]) -> bool:
    """Whether two float64 time vectors hold the same values, bit for bit (0.0 and -0.0
    differ)."""
    return (a.shape == b.shape and a.dtype == b.dtype == np.float64
            and bool(np.array_equal(a.view(np.int64), b.view(np.int64))))


def _windows(t: NDArray[np.float64], window: float) -> Any:
    """The window bounds of each sample for :func:`sustained`: for the low and the high end
    ``(s, k, half, ds, at_k, at_next)`` (the end, clipped to the record; the sample at or
    before it; the time from that sample to the end, halved and whole, (N, 1); whether the end
    is that sample, (N, 1), and the rows where it is the next one), the width, where it is
    positive and whether it is everywhere. Kept for the latest times and window (the same
    times, compared value by value, give the same bounds)."""
    for tt, w, got in _WINDOWS:
        if w == window and _same_times(tt, t):
            return got
    lo = np.maximum(t - 0.5 * window, t[0])
    hi = np.minimum(t + 0.5 * window, t[-1])
    ends = []
    for s in (lo, hi):
        k = np.clip(np.searchsorted(t, s, side="right") - 1, 0, t.size - 2)
        ds = (s - t[k])[:, None]
        # s on a sample: k's (s == t[k]), or the last (s == t[-1], k = N - 2)
        ends.append((s, k, ds * 0.5, ds, (s == t[k])[:, None],
                     np.flatnonzero(s == t[k + 1])))
    width = hi - lo
    inside = width > 0.0  # else a window below the times' resolution: the sample itself
    got = (*ends, width, inside, bool(np.all(inside)))
    for v in (width, inside, *ends[0], *ends[1]):
        v.setflags(write=False)
    _WINDOWS[:] = [(t.copy(), float(window), got)]
    return got


def margin_pct(limit: float, used: float) -> float:
    """Margin in percent, ``(limit - used) / limit * 100`` (NaN when there is no finite limit)."""
    if not np.isfinite(limit) or limit <= 0:
        return float("nan")
    return float((limit - used) / limit * 100.0)
