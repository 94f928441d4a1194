"""Input checks and the banded linear system shared by the joint-space polynomial planners.

Both planners (4-3-4 after seed 001 eq. 5-17, 5-4-6 after seed 000 eq. 18-24) describe a
phase of ``m`` segments between knot times ``tau_0 < ... < tau_m`` by one polynomial per
segment and joint, in normalized time (seed 001 eq. 6-8)::

    t     = (tau - tau_{i-1}) / t_i  in [0, 1]     segments 1 .. m-1
    t_bar = t - 1 = (tau - tau_i) / t_i  in [-1, 0]  last segment m

with ``t_i = tau_i - tau_{i-1}``. A derivative of order k in real time is the derivative in
the normalized variable divided by ``t_i**k``.

The conditions (boundary values at both ends, knot positions on both sides of every interior
knot, continuity of the derivatives of order 1..K at interior knots) are linear in the
normalized coefficients. Every condition involves the coefficients of at most two adjacent
segments, so with the unknowns ordered segment by segment and the conditions knot by knot the
matrix is banded with a bandwidth that does not depend on the number of knots. One call of
:func:`scipy.linalg.solve_banded` (LAPACK ``gbsv``, LU with partial pivoting) solves it for
all joints at once (one right-hand side per joint): time and memory grow linearly with the
number of knots. No symbolic algebra is involved.

Continuity rows are scaled by ``g**k`` with ``g = min(t_i, t_{i+1})`` so that every row has
coefficients of order one whatever the segment durations.
"""

from __future__ import annotations

from math import factorial

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import solve_banded

from planners.errors import InternalError, InvalidBoundaryError, InvalidKnotsError


def validate_knots(times: ArrayLike, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Check knot times and knot positions and return them as float arrays.

    Args:
        times: Knot times tau_0 .. tau_m, s, shape (m+1,), strictly increasing, m >= 2.
        q: Knot positions, shape (m+1, n_joints); a 1-D array is one joint.

    Returns:
        ``(times, q)`` with shapes (m+1,) and (m+1, n_joints), dtype float64.

    Raises:
        InvalidKnotsError: Fewer than 3 knots, times not strictly increasing, a row of ``q``
            of the wrong length, a row count different from the number of times, or a value
            that is not a finite number. The message names the field and index.
    """
    try:
        t = np.asarray(times, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidKnotsError(f"times: knot times must be numbers in seconds ({exc})") from None
    if t.ndim != 1:
        raise InvalidKnotsError(f"times: expected a 1-D sequence of knot times, got shape {t.shape}")
    if t.size < 3:
        raise InvalidKnotsError(
            f"times: {t.size} knot time(s) given; at least 3 knots (2 segments) are needed")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InvalidKnotsError(f"times[{bad[0]}] is {t[bad[0]]}: knot times must be finite numbers")
    step = np.diff(t)
    bad = np.flatnonzero(step <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InvalidKnotsError(
            f"times[{i}]={float(t[i])!r} s is not greater than times[{i - 1}]={float(t[i - 1])!r} s: "
            "knot times must be strictly increasing")

    if isinstance(q, (list, tuple)) and q and any(isinstance(r, (list, tuple, np.ndarray)) for r in q):
        lengths = [np.size(r) for r in q]
        for i, n in enumerate(lengths):
            if n != lengths[0] or np.ndim(q[i]) != 1:
                raise InvalidKnotsError(
                    f"q: row {i} has {n} value(s), expected {lengths[0]} (one per joint, like row 0)")
    try:
        qa = np.asarray(q, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidKnotsError(f"q: knot positions must be numbers ({exc})") from None
    if qa.ndim == 1:
        qa = qa[:, None]
    if qa.ndim != 2:
        raise InvalidKnotsError(
            f"q: expected shape (n_knots, n_joints) = ({t.size}, n_joints), got shape {qa.shape}")
    if qa.shape[0] != t.size:
        raise InvalidKnotsError(
            f"q: {qa.shape[0]} row(s) of knot positions but times has {t.size} knot(s)")
    if qa.shape[1] == 0:
        raise InvalidKnotsError("q: rows are empty; give one position per joint")
    bad = np.argwhere(~np.isfinite(qa))
    if bad.size:
        i, j = (int(v) for v in bad[0])
        raise InvalidKnotsError(
            f"q[{i}, {j}] (knot {i}, joint {j + 1}) is {qa[i, j]}: knot positions must be finite")
    return t, qa


def per_joint_array(name: str, value: ArrayLike, n_joints: int, what: str) -> NDArray[np.float64]:
    """``value`` as an array of shape (n_joints,): a scalar applies to every joint.

    Args:
        name: Field name used in messages.
        value: A number or one number per joint.
        n_joints: Number of joints.
        what: What the values are, for messages ("boundary values", "limits").

    Raises:
        InvalidBoundaryError: Not numbers, or the wrong shape (one line naming ``name``).
    """
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidBoundaryError(f"{name}: {what} must be numbers ({exc})") from None
    if v.ndim == 0:
        return np.full(n_joints, float(v))
    if v.shape != (n_joints,):
        raise InvalidBoundaryError(
            f"{name}: expected a scalar or shape ({n_joints},) (one value per joint), "
            f"got shape {v.shape}")
    return v


def validate_boundary(name: str, value: ArrayLike | None, n_joints: int) -> NDArray[np.float64]:
    """A boundary value (velocity, acceleration or jerk) as an array of shape (n_joints,).

    Args:
        name: Field name used in messages ("v0", "af", ...).
        value: None (zero), a scalar (same for every joint) or shape (n_joints,).
        n_joints: Number of joints.

    Raises:
        InvalidBoundaryError: Wrong shape or a value that is not a finite number.
    """
    if value is None:
        return np.zeros(n_joints)
    v = per_joint_array(name, value, n_joints, "boundary values")
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        raise InvalidBoundaryError(
            f"{name}[{bad[0]}] (joint {bad[0] + 1}) is {v[bad[0]]}: boundary values must be finite")
    return v


def _deriv_row(deg: NDArray[np.int64], k: int, s: NDArray[np.float64], D: int) -> NDArray[np.float64]:
    """Row weights of the k-th derivative at s: w[r, j] = j!/(j-k)! s^(j-k) for k <= j <= deg[r].

    Shapes: deg (R,), s (R,) -> (R, D+1).
    """
    j = np.arange(D + 1)
    fall = np.array([factorial(jj) // factorial(jj - k) if jj >= k else 0 for jj in j], dtype=float)
    power = np.clip(j - k, 0, None)
    w = fall[None, :] * s[:, None] ** power[None, :]
    w[j[None, :] > deg[:, None]] = 0.0
    return w


def solve_piecewise(times: NDArray[np.float64], q: NDArray[np.float64], degrees: NDArray[np.int64],
                    start: list[NDArray[np.float64]], end: list[NDArray[np.float64]]
                    ) -> NDArray[np.float64]:
    """Normalized coefficients of the piecewise polynomial meeting all conditions.

    Unknowns: the normalized coefficients of every segment, ascending powers of t (of t_bar
    for the last segment). Conditions (K = len(start) = len(end)):

    * at tau_0: the derivatives of order 0..K equal q_0, start[0] .. start[K-1] (real time);
    * at each interior knot tau_i: both adjacent segments pass through q_i, and the
      derivatives of order 1..K of the two segments agree (real time);
    * at tau_m: the derivatives of order 0..K equal q_m, end[0] .. end[K-1].

    Args:
        times: Knot times, s, shape (m+1,), validated.
        q: Knot positions, shape (m+1, n_joints), validated.
        degrees: Degree of each segment, shape (m,). The counts must make the system square:
            sum(degrees + 1) == 2 (K + 1) + (K + 2)(m - 1).
        start: K arrays of shape (n_joints,): velocity, acceleration[, jerk] at tau_0.
        end: K arrays of shape (n_joints,): the same at tau_m.

    Returns:
        Coefficients padded with zeros, shape (m, n_joints, max(degrees)+1).
    """
    m = times.size - 1
    nj = q.shape[1]
    K = len(start)
    h = np.diff(times)
    D = int(degrees.max())
    n_unknown = int(np.sum(degrees + 1))
    n_rows = 2 * (K + 1) + (K + 2) * (m - 1)
    if n_unknown != n_rows:  # a programming error, not a user error
        raise InternalError(f"non-square system: {n_unknown} unknowns, {n_rows} conditions")
    col0 = np.concatenate(([0], np.cumsum(degrees + 1)[:-1]))
    s_lo = np.zeros(m)
    s_hi = np.ones(m)
    s_lo[-1], s_hi[-1] = -1.0, 0.0  # last segment in t_bar

    # Every condition is a list of (segment, derivative order, point, factor) terms; build
    # each family of conditions for all knots at once.
    rows_r, rows_c, rows_v = [], [], []

    def add(row: NDArray[np.int64], seg: NDArray[np.int64], k: int, s: NDArray[np.float64],
            factor: NDArray[np.float64]) -> None:
        w = _deriv_row(degrees[seg], k, s, D) * factor[:, None]
        cols = col0[seg][:, None] + np.arange(D + 1)[None, :]
        keep = np.arange(D + 1)[None, :] <= degrees[seg][:, None]
        keep &= w != 0.0
        rows_r.append(np.broadcast_to(row[:, None], w.shape)[keep])
        rows_c.append(cols[keep])
        rows_v.append(w[keep])

    rhs = np.zeros((n_rows, nj))
    one = np.ones(1)
    # Start: rows 0..K; derivative k of segment 0 at t = 0 equals start[k-1] * t_1^k.
    for k in range(K + 1):
        add(np.array([k]), np.array([0]), k, np.array([s_lo[0]]), one)
        rhs[k] = q[0] if k == 0 else start[k - 1] * h[0] ** k
    # Interior knots i = 1..m-1: block of K+2 rows starting at K+1 + (i-1)(K+2).
    if m > 1:
        i = np.arange(1, m)
        left, right = i - 1, i
        base = K + 1 + (i - 1) * (K + 2)
        add(base, left, 0, s_hi[left], np.ones(m - 1))
        rhs[base] = q[1:m]
        g = np.minimum(h[left], h[right])
        for k in range(1, K + 1):
            add(base + k, left, k, s_hi[left], (g / h[left]) ** k)
            add(base + k, right, k, s_lo[right], -(g / h[right]) ** k)
        add(base + K + 1, right, 0, s_lo[right], np.ones(m - 1))
        rhs[base + K + 1] = q[1:m]
    # End: last K+1 rows; derivative k of the last segment at t_bar = 0.
    for k in range(K + 1):
        r = n_rows - (K + 1) + k
        add(np.array([r]), np.array([m - 1]), k, np.array([s_hi[-1]]), one)
        rhs[r] = q[-1] if k == 0 else end[k - 1] * h[-1] ** k

    r = np.concatenate(rows_r)
    c = np.concatenate(rows_c)
    v = np.concatenate(rows_v)
    lower = int(np.max(r - c, initial=0))
    upper = int(np.max(c - r, initial=0))
    ab = np.zeros((lower + upper + 1, n_unknown))
    ab[upper + r - c, c] = v  # every (row, column) pair occurs once
    try:
        x = solve_banded((lower, upper), ab, rhs, check_finite=False)
    except np.linalg.LinAlgError:
        x = np.full((n_unknown, nj), np.nan)
    if not np.all(np.isfinite(x)):
        raise InvalidKnotsError(
            f"times: the conditions at these {m + 1} knot times have no unique solution "
            "(singular system); change the knot times or the number of knots")

    coef = np.zeros((m, nj, D + 1))
    seg_of_col = np.repeat(np.arange(m), degrees + 1)
    pow_of_col = np.arange(n_unknown) - col0[seg_of_col]
    coef[seg_of_col, :, pow_of_col] = x
    # The coefficients fixed by a single condition (seed 001 section 5, seed 000 after eq. 19
    # and 22: "determined directly") are set exactly, dropping the solve's rounding:
    # a_k = value_k t^k / k! at both ends, a_0 = q_{i-1} for the segments in t.
    for k in range(K + 1):
        v0 = q[0] if k == 0 else start[k - 1]
        vm = q[-1] if k == 0 else end[k - 1]
        coef[0, :, k] = v0 * h[0] ** k / factorial(k)
        coef[-1, :, k] = vm * h[-1] ** k / factorial(k)
    coef[1:m - 1, :, 0] = q[1:m - 1]
    return coef
