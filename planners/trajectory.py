"""Piecewise polynomial joint trajectory shared by the 4-3-4 and 5-4-6 planners.

A trajectory of ``m`` segments holds, per segment and joint, the polynomial in normalized
time printed by the seeds (seed 001 eq. 5-9, seed 000 eq. 19-22)::

    segments 1 .. m-1:  q(t)     = sum_k a_k t^k,      t     = (tau - tau_{i-1}) / t_i in [0, 1]
    last segment m:     q(t_bar) = sum_k a_k t_bar^k,  t_bar = (tau - tau_m) / t_m   in [-1, 0]

with ``t_i = tau_i - tau_{i-1}``; derivatives in real time divide the normalized ones by
``t_i**k``. :meth:`PiecewisePolynomialTrajectory.at` always evaluates this normalized form
(well conditioned whatever the clock). The real-time form of seed 000 Table 5 (ascending
powers of the absolute time tau, s) is produced on request by exact binomial re-expansion;
its coefficients of high powers grow like ``(tau / t_i)**k`` and cancel each other, so it is
meant for display and export, not for evaluation far from tau = 0.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from math import comb, factorial
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.base import JointState, sample_times
from planners.errors import PlannerError, UsageError

#: Slack on the time range accepted by :meth:`PiecewisePolynomialTrajectory.at`, s.
TIME_TOLERANCE = 1e-9


@dataclass(frozen=True)
class TrajectoryExtrema:
    """Exact per-joint extremes of a trajectory (each array has shape (n_joints,)).

    Found from the real roots of the next derivative inside every segment plus the segment
    ends, so they are the true extremes of the polynomials, not of a sampling. Units follow
    the knots (rad, rad/s, rad/s^2, rad/s^3 for radians); times in s on the knot clock.

    Attributes:
        q_min, q_min_time: Lowest position and when it occurs.
        q_max, q_max_time: Highest position and when it occurs.
        qd_peak, qd_time: Largest |velocity| and when.
        qdd_peak, qdd_time: Largest |acceleration| and when.
        qddd_peak, qddd_time: Largest |jerk| and when (for 4-3-4 the jerk jumps at knots;
            both sides are considered).
    """

    q_min: NDArray[np.float64]
    q_min_time: NDArray[np.float64]
    q_max: NDArray[np.float64]
    q_max_time: NDArray[np.float64]
    qd_peak: NDArray[np.float64]
    qd_time: NDArray[np.float64]
    qdd_peak: NDArray[np.float64]
    qdd_time: NDArray[np.float64]
    qddd_peak: NDArray[np.float64]
    qddd_time: NDArray[np.float64]


def _horner(coef: NDArray[np.float64], s: NDArray[np.float64]) -> NDArray[np.float64]:
    """Evaluate polynomials with ascending coefficients ``coef`` (..., d+1) at ``s`` (...)."""
    acc = np.zeros(np.broadcast_shapes(coef.shape[:-1], np.shape(s)))
    acc += coef[..., -1]
    for p in range(coef.shape[-1] - 2, -1, -1):
        acc *= s
        acc += coef[..., p]
    return acc


def _real_roots_in(poly: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64]
                   ) -> NDArray[np.float64]:
    """Real roots of many polynomials inside their own intervals.

    Args:
        poly: Ascending coefficients, shape (M, d+1).
        lo, hi: Interval of each polynomial, shape (M,).

    Returns:
        Shape (M, max(d, 1)): the roots found in [lo, hi] (clipped into it), NaN elsewhere.
        Nearly real roots (|imag| < 1e-6) are kept: they only add candidate points.
    """
    M, n = poly.shape
    d = n - 1
    out = np.full((M, max(d, 1)), np.nan)
    if d < 1:
        return out
    scale = np.max(np.abs(poly), axis=1)
    significant = np.abs(poly) > 1e-13 * scale[:, None]
    eff = np.where(significant.any(axis=1), d - np.argmax(significant[:, ::-1], axis=1), 0)
    for de in np.unique(eff):
        if de < 1:
            continue
        rows = np.flatnonzero(eff == de)
        c = poly[rows, :de] / poly[rows, de][:, None]
        comp = np.zeros((rows.size, de, de))
        if de > 1:
            comp[:, np.arange(1, de), np.arange(de - 1)] = 1.0
        comp[:, :, -1] = -c
        z = np.linalg.eigvals(comp)
        ok = (np.abs(z.imag) < 1e-6 * np.maximum(1.0, np.abs(z))) \
            & (z.real >= lo[rows, None] - 1e-9) & (z.real <= hi[rows, None] + 1e-9)
        r = np.clip(z.real, lo[rows, None], hi[rows, None])
        out[rows, :de] = np.where(ok, r, np.nan)
    return out


class PiecewisePolynomialTrajectory:
    """Joint trajectory made of one polynomial per segment and joint, in normalized time.

    Conforms to :class:`planners.base.Trajectory`. Units follow the knot values (radians in
    cellsim) and the knot clock (seconds).

    Args:
        knots: Knot times tau_0 < ... < tau_m, s, shape (m+1,).
        coefficients: Normalized coefficients, shape (m, n_joints, D+1), ascending powers of
            t (of t_bar for the last segment), zero-padded above each segment's degree.
        degrees: Degree of each segment, shape (m,).
        planner: Name of the planner that made it ("434", "546").
    """

    def __init__(self, knots: ArrayLike, coefficients: ArrayLike, degrees: Sequence[int],
                 planner: str) -> None:
        self._knots = np.array(knots, dtype=float)
        self._coef = np.array(coefficients, dtype=float)
        self._degrees = tuple(int(d) for d in degrees)
        m = self._knots.size - 1
        if self._coef.ndim != 3 or self._coef.shape[0] != m or len(self._degrees) != m:
            raise UsageError("coefficients must have shape (n_segments, n_joints, D+1) with one "
                             "degree per segment")
        self._planner = str(planner)
        self._h = np.diff(self._knots)
        # Origin of each segment's normalized variable: tau_{i-1} for t, tau_i for t_bar.
        self._ref = self._knots[:-1].copy()
        self._ref[-1] = self._knots[-1]
        self._s_lo = np.zeros(m)
        self._s_hi = np.ones(m)
        self._s_lo[-1], self._s_hi[-1] = -1.0, 0.0
        self._knots.setflags(write=False)
        self._coef.setflags(write=False)
        # Real-time derivative coefficients in the normalized variable, per order 0..3:
        # shape (D+1-k, m, n_joints), powers first so Horner gathers contiguous rows.
        D = self._coef.shape[2] - 1
        self._deriv: list[NDArray[np.float64]] = []
        for k in range(4):
            if k > D:
                self._deriv.append(np.zeros((1, m, self.n_joints)))
                continue
            p = np.arange(k, D + 1)
            fall = np.array([factorial(j) / factorial(j - k) for j in p])
            c = self._coef[:, :, k:] * fall / self._h[:, None, None] ** k
            self._deriv.append(np.ascontiguousarray(np.moveaxis(c, 2, 0)))

    # ------------------------------------------------------------------ basic facts
    @property
    def knots(self) -> NDArray[np.float64]:
        """Knot times, s, shape (n_segments+1,) (read-only)."""
        return self._knots

    @property
    def start(self) -> float:
        """First knot time, s."""
        return float(self._knots[0])

    @property
    def end(self) -> float:
        """Last knot time, s."""
        return float(self._knots[-1])

    @property
    def duration(self) -> float:
        """end - start, s."""
        return float(self._knots[-1] - self._knots[0])

    @property
    def n_joints(self) -> int:
        """Number of joints."""
        return int(self._coef.shape[1])

    @property
    def n_segments(self) -> int:
        """Number of segments (knots - 1)."""
        return int(self._coef.shape[0])

    @property
    def planner(self) -> str:
        """Name of the planner that produced the trajectory ("434" or "546")."""
        return self._planner

    @property
    def degrees(self) -> tuple[int, ...]:
        """Polynomial degree of each segment."""
        return self._degrees

    def segment_variable(self, i: int) -> str:
        """Name of segment ``i``'s normalized variable: ``"t"``, or ``"t_bar"`` for the last.

        Raises:
            IndexError: ``i`` is not a segment index (negative indices count from the end).
        """
        m = self.n_segments
        if not -m <= i < m:
            raise IndexError(f"segment index {i} out of range for {m} segments")
        return "t_bar" if i % m == m - 1 else "t"

    def __repr__(self) -> str:
        return (f"PiecewisePolynomialTrajectory(planner={self._planner!r}, "
                f"n_segments={self.n_segments}, n_joints={self.n_joints}, "
                f"start={self.start:g}, end={self.end:g})")

    # ------------------------------------------------------------------ coefficients
    @cached_property
    def normalized_coefficients(self) -> list[NDArray[np.float64]]:
        """Per segment, shape (n_joints, degree+1): ascending powers of t (t_bar for the last).

        Exactly the form of seed 001 eq. 18-20 and seed 000 Table 4 (read right to left).
        """
        return [self._coef[i, :, : d + 1].copy() for i, d in enumerate(self._degrees)]

    @cached_property
    def real_coefficients(self) -> list[NDArray[np.float64]]:
        """Per segment, shape (n_joints, degree+1): ascending powers of absolute time tau, s.

        The form of seed 000 Table 5. Obtained by exact binomial re-expansion of
        ``sum_j a_j ((tau - r) / t_i)**j`` (r = tau_{i-1}, or tau_i for the last segment):
        ``b_k = sum_{j>=k} a_j C(j, k) (-r)**(j-k) / t_i**j``. For tau far from 0 relative to
        t_i these coefficients are large and cancel when summed: evaluate with :meth:`at`.
        """
        D = self._coef.shape[2] - 1
        j = np.arange(D + 1)
        binom = np.array([[comb(jj, kk) for kk in range(D + 1)] for jj in range(D + 1)], dtype=float)
        expo = np.clip(j[:, None] - j[None, :], 0, None)
        # M[i, j, k] = C(j, k) (-r_i)^(j-k) / h_i^j
        Mx = binom[None] * (-self._ref[:, None, None]) ** expo[None] \
            / self._h[:, None, None] ** j[None, :, None]
        real = np.einsum("inj,ijk->ink", self._coef, Mx)
        return [real[i, :, : d + 1].copy() for i, d in enumerate(self._degrees)]

    # ------------------------------------------------------------------ evaluation
    def _locate(self, t: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Segment index and normalized variable of each time (already in range)."""
        idx = np.searchsorted(self._knots, t, side="right") - 1
        np.clip(idx, 0, self.n_segments - 1, out=idx)
        s = (t - self._ref[idx]) / self._h[idx]
        return idx, s

    def _check_times(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        lo, hi = self._knots[0], self._knots[-1]
        bad = ~((t >= lo - TIME_TOLERANCE) & (t <= hi + TIME_TOLERANCE))
        if np.any(bad):
            tb = float(t[np.argmax(bad)])
            raise PlannerError(f"t={tb!r} s is outside the trajectory's time range "
                               f"[{lo:g}, {hi:g}] s")
        return np.clip(t, lo, hi)

    def at(self, t: ArrayLike) -> JointState:
        """State at time(s) ``t`` (s, on the knot clock).

        At an interior knot the segment on the right is used (position, velocity and
        acceleration are continuous there; for 4-3-4 the jerk is not).

        Args:
            t: Scalar or array of times in [start, end] (1e-9 s of slack).

        Returns:
            JointState with arrays of shape (n_joints,) for a scalar ``t``, else
            t.shape + (n_joints,).

        Raises:
            PlannerError: A time outside [start, end] (or NaN); the message names it and the
                valid range.
        """
        ta = np.asarray(t, dtype=float)
        shape = ta.shape
        flat = self._check_times(ta.reshape(-1))
        idx, s = self._locate(flat)
        s = s[:, None]
        out = []
        for k in range(4):
            c = self._deriv[k]
            acc = c[-1][idx]
            for p in range(c.shape[0] - 2, -1, -1):
                acc *= s
                acc += c[p][idx]
            out.append(acc.reshape(shape + (self.n_joints,)))
        return JointState(q=out[0], qd=out[1], qdd=out[2], qddd=out[3])

    def sample(self, dt: float) -> tuple[NDArray[np.float64], JointState]:
        """``(times, states)`` every ``dt`` seconds from start to end (end included).

        Raises:
            PlannerError: ``dt`` is not a positive finite number.
        """
        try:
            times = sample_times(self.start, self.end, float(dt))
        except (TypeError, ValueError) as exc:
            raise PlannerError(f"dt: {exc}") from None
        return times, self.at(times)

    # ------------------------------------------------------------------ extremes
    def extrema(self) -> TrajectoryExtrema:
        """Exact per-joint extremes of position, |velocity|, |acceleration| and |jerk|."""
        m, nj = self.n_segments, self.n_joints
        lo = np.repeat(self._s_lo, nj)
        hi = np.repeat(self._s_hi, nj)

        def best(k: int, mode: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
            f = np.moveaxis(self._deriv[k], 0, 2).reshape(m * nj, -1)  # (M, d+1) in s
            df = np.moveaxis(self._deriv[k + 1], 0, 2).reshape(m * nj, -1) if k < 3 else \
                f[:, 1:] * np.arange(1, f.shape[1])
            roots = _real_roots_in(df, lo, hi)
            cand = np.concatenate([lo[:, None], hi[:, None], roots], axis=1)
            cand = np.where(np.isnan(cand), lo[:, None], cand)
            val = _horner(f[:, None, :], cand)  # (M, C)
            if mode == "max":
                score = val
            elif mode == "min":
                score = -val
            else:
                val = np.abs(val)
                score = val
            C = cand.shape[1]
            score = score.reshape(m, nj, C).transpose(1, 0, 2).reshape(nj, m * C)
            pick = np.argmax(score, axis=1)
            jj = np.arange(nj)
            vals = val.reshape(m, nj, C).transpose(1, 0, 2).reshape(nj, m * C)[jj, pick]
            sg = pick // C
            sv = cand.reshape(m, nj, C).transpose(1, 0, 2).reshape(nj, m * C)[jj, pick]
            times = self._ref[sg] + sv * self._h[sg]
            return vals, times

        qmin, tmin = best(0, "min")
        qmax, tmax = best(0, "max")
        v, tv = best(1, "abs")
        a, ta = best(2, "abs")
        j, tj = best(3, "abs")
        return TrajectoryExtrema(q_min=qmin, q_min_time=tmin, q_max=qmax, q_max_time=tmax,
                                 qd_peak=v, qd_time=tv, qdd_peak=a, qdd_time=ta,
                                 qddd_peak=j, qddd_time=tj)
