"""Blended Cartesian moves: one tool path through several moves, rounding each corner.

A move that ends with a blend radius ``r`` (FANUC's CNT, ABB's zone) does not stop at its end
point: the tool point leaves the move ``r`` before the corner (arc length) and joins the next
move ``r`` after it on a smooth curve, keeping its speed. The pieces are:

* :class:`SubPath`: a path (line, arc) trimmed to part of its length;
* :class:`BlendCurve`: the corner curve, a quintic Bezier from the leaving point to the joining
  point with the tangents of the two moves there and zero curvature at both ends (its first and
  last three control points are collinear), so the tool's acceleration is continuous where the
  blend starts and ends. For two lines meeting at a corner ``C`` its control points are
  ``C - r t1, C - 3r/4 t1, C - r/2 t1, C + r/2 t2, C + 3r/4 t2, C + r t2``: the curve stays
  inside the triangle of the corner, at most ``r/2`` from ``C``;
* :class:`CompositePath`: the pieces end to end by arc length;
* :class:`CompositeOrientation`: each piece's orientation law over its own stretch;
* :class:`PiecewiseProfile`: the time law: speed ramps from rest at the start, constant
  speeds, smooth speed changes inside the blends (where the moves' speeds differ), a ramp to
  rest at the end; each change a quintic smoothstep in time.

:class:`planners.adnia.CartesianTrajectory` takes these like its own path, law and profile.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from planners.errors import InvalidMoveError
from planners.profiles import ConstantSpeedShare, quintic_smoothstep
from planners.rotations import GeodesicOrientation, axis_angle_matrix


class SubPath:
    """``base`` between arc lengths ``s0`` and ``s1`` (m), re-parametrised from 0."""

    def __init__(self, base, s0: float, s1: float) -> None:
        if not 0.0 <= s0 < s1 <= base.length + 1e-12:
            raise InvalidMoveError(f"sub-path [{s0:g}, {s1:g}] m outside the move's length "
                                   f"{base.length:g} m")
        self.base, self.s0 = base, float(s0)
        self.length = float(s1 - s0)
        self.kind = base.kind

    def evaluate(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        return self.base.evaluate(np.asarray(s, dtype=float) + self.s0)


def _bernstein(n: int, u: NDArray[np.float64]) -> NDArray[np.float64]:
    k = np.arange(n + 1)
    return (np.array([math.comb(n, i) for i in k]) * u[..., None] ** k
            * (1.0 - u[..., None]) ** (n - k))


class BlendCurve:
    """Quintic Bezier corner blend (module docstring), by arc length.

    Args:
        p_a, t_a: Where the blend leaves the first move and the move's unit tangent there.
        p_b, t_b: Where it joins the next move and that move's unit tangent there.
        handle: Distance of the second control point from each end along its tangent, m (the
            third is at twice that).
    """

    kind = "blend"

    def __init__(self, p_a: ArrayLike, t_a: ArrayLike, p_b: ArrayLike, t_b: ArrayLike,
                 handle: float) -> None:
        pa, ta, pb, tb = (np.asarray(v, dtype=float) for v in (p_a, t_a, p_b, t_b))
        h = float(handle)
        self.P = np.array([pa, pa + h * ta, pa + 2 * h * ta, pb - 2 * h * tb, pb - h * tb, pb])
        # arc length table by Gauss-Legendre on fine intervals
        self._u = np.linspace(0.0, 1.0, 2049)
        x, w = np.polynomial.legendre.leggauss(6)
        lo, hi = self._u[:-1], self._u[1:]
        mid, half = (lo + hi) / 2, (hi - lo) / 2
        uu = mid[:, None] + half[:, None] * x[None, :]
        speed = np.linalg.norm(self._d(uu.ravel(), 1), axis=-1).reshape(uu.shape)
        seg = (speed * w[None, :]).sum(axis=1) * half
        self._s = np.r_[0.0, np.cumsum(seg)]
        self.length = float(self._s[-1])
        if not self.length > 0:
            raise InvalidMoveError("blend: zero-length corner curve")

    def _d(self, u: NDArray[np.float64], order: int) -> NDArray[np.float64]:
        """Derivative of the given order of B(u), (..., 3)."""
        P = self.P
        n = 5
        for _ in range(order):
            P = n * (P[1:] - P[:-1])
            n -= 1
        return _bernstein(n, np.asarray(u, dtype=float)) @ P

    def _u_of_s(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        u = np.interp(s, self._s, self._u)
        for _ in range(3):  # Newton on s(u) = s
            i = np.clip(np.searchsorted(self._u, u) - 1, 0, len(self._u) - 2)
            # arc length from the table's knot to u (Simpson)
            u0 = self._u[i]
            m = (u0 + u) / 2
            sp = [np.linalg.norm(self._d(v, 1), axis=-1) for v in (u0, m, u)]
            s_u = self._s[i] + (u - u0) / 6 * (sp[0] + 4 * sp[1] + sp[2])
            u = np.clip(u - (s_u - s) / np.maximum(sp[2], 1e-300), 0.0, 1.0)
        return u

    def _tangent(self, u: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """Unit tangent and its arc-length derivative at parameters ``u`` (d/ds = d/du / |B'|)."""
        b1, b2 = self._d(u, 1), self._d(u, 2)
        sp = np.linalg.norm(b1, axis=-1, keepdims=True)
        T = b1 / sp
        return T, (b2 - np.sum(b2 * T, axis=-1, keepdims=True) * T) / sp**2

    def evaluate(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        s = np.asarray(s, dtype=float)
        u = self._u_of_s(s)
        T, dT = self._tangent(u)
        # third derivative: the tangent's second derivative by central differences of dT
        h = 1e-6 * max(self.length, 1e-9)
        span = (np.clip(s + h, 0, self.length) - np.clip(s - h, 0, self.length))[..., None]
        d3 = ((self._tangent(self._u_of_s(s + h))[1] - self._tangent(self._u_of_s(s - h))[1])
              / np.maximum(span, 1e-300))
        return self._d(u, 0), T, dT, d3


class CompositePath:
    """Paths end to end by arc length (each piece starts where the previous one ends)."""

    kind = "composite"

    def __init__(self, pieces: list) -> None:
        self.pieces = list(pieces)
        self.starts = np.r_[0.0, np.cumsum([p.length for p in self.pieces])]
        self.length = float(self.starts[-1])

    def piece_at(self, s: NDArray[np.float64]) -> NDArray[np.int64]:
        idx = np.searchsorted(self.starts, np.asarray(s, dtype=float), side="right") - 1
        return np.clip(idx, 0, len(self.pieces) - 1)

    def evaluate(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        out = [np.zeros(s.shape + (3,)) for _ in range(4)]
        idx = self.piece_at(s)
        for k, piece in enumerate(self.pieces):
            sel = idx == k
            if np.any(sel):
                vals = piece.evaluate(np.clip(s[sel] - self.starts[k], 0.0, piece.length))
                for o, v in zip(out, vals, strict=True):
                    o[sel] = v
        return tuple(out)


class CompositeOrientation:
    """Orientation laws over consecutive stretches of a path (each law in its own 0..1)."""

    def __init__(self, laws: list, starts: ArrayLike, lengths: ArrayLike) -> None:
        self.laws = list(laws)
        self.starts = np.asarray(starts, dtype=float)
        self.lengths = np.asarray(lengths, dtype=float)
        self.total = float(self.starts[-1] + self.lengths[-1])

    def evaluate(self, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        s = np.clip(np.asarray(u, dtype=float), 0.0, 1.0) * self.total
        idx = np.clip(np.searchsorted(self.starts, s, side="right") - 1, 0, len(self.laws) - 1)
        R = np.zeros(s.shape + (3, 3))
        dR = np.zeros(s.shape + (3, 3))
        for k, law in enumerate(self.laws):
            sel = idx == k
            if np.any(sel):
                L = max(self.lengths[k], 1e-300)
                r, dr = law.evaluate(np.clip((s[sel] - self.starts[k]) / L, 0.0, 1.0))
                R[sel] = r
                dR[sel] = dr * (self.total / L)
        return R, dR


class SubOrientation:
    """An orientation law between its parameters ``a`` and ``b``, re-parametrised to 0..1."""

    def __init__(self, law, a: float, b: float) -> None:
        self.law, self.a, self.b = law, float(a), float(b)

    def evaluate(self, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        R, dR = self.law.evaluate(self.a + np.asarray(u, dtype=float) * (self.b - self.a))
        return R, dR * (self.b - self.a)


class CornerOrientation:
    """The tool turning from one move's orientation to the next inside a corner blend.

    Without rates: the shortest rotation from ``start`` to ``end``, its angle a quintic
    smoothstep of the corner's own parameter ``u`` (0..1 by arc length along the corner
    curve); the turn's rate and acceleration are zero where the corner meets the moves.

    With the moves' own turning rates at the corner's ends (``rate_start``, ``rate_end``:
    angular velocity per metre of path, world frame; a TP linear move turns its tool evenly
    from one point to the next), each move's orientation is carried on at its rate through
    the corner and the two are blended as a controller blends them: ``R = R_a exp(h(u)
    log(R_a^T R_b))`` with ``R_a`` the first move continued, ``R_b`` the next one begun early
    and ``h`` the smoothstep. The tool's angular velocity and acceleration then stay
    continuous where the corner meets the moves (a smoothstep from rest would jump the rate
    a turning move has there; so would a uniform slerp).

    Args:
        start, end: Tool frames where the corner leaves the first move and joins the next,
            (3, 3).
        rate_start, rate_end: The moves' angular velocities there, rad per metre of path, (3,)
            (default: not turning).
        length: The corner curve's arc length, m (needed with rates).
    """

    name = "corner"

    def __init__(self, start: ArrayLike, end: ArrayLike, rate_start: ArrayLike | None = None,
                 rate_end: ArrayLike | None = None, length: float = 0.0) -> None:
        self._geo = GeodesicOrientation(start, end)
        self.start, self.end, self.angle = self._geo.start, self._geo.end, self._geo.angle
        wa = np.zeros(3) if rate_start is None else np.asarray(rate_start, dtype=float)
        wb = np.zeros(3) if rate_end is None else np.asarray(rate_end, dtype=float)
        self.length = float(length)
        #: The turn each move carries into the corner, rad per unit of u (world frame).
        self._wa, self._wb = wa * self.length, wb * self.length
        # a turn under a micro-radian over the corner is none (a straight seam leg's law)
        self._turning = bool(max(np.linalg.norm(self._wa), np.linalg.norm(self._wb)) > 1e-9)

    def _blended(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        def carried(R0: NDArray[np.float64], w: NDArray[np.float64],
                    x: NDArray[np.float64]) -> NDArray[np.float64]:
            n = float(np.linalg.norm(w))
            if n == 0.0:
                return np.broadcast_to(R0, x.shape + (3, 3))
            return axis_angle_matrix(w / n, x * n) @ R0

        Ra = carried(self.start, self._wa, u)
        Rb = carried(self.end, self._wb, u - 1.0)
        v = Rotation.from_matrix(np.swapaxes(Ra, -1, -2) @ Rb).as_rotvec()
        h = quintic_smoothstep(u)[0]
        return Ra @ Rotation.from_rotvec(v * h[..., None]).as_matrix()

    def evaluate(self, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        u = np.asarray(u, dtype=float)
        if not self._turning:
            h, h1 = quintic_smoothstep(u)[:2]
            R, dR = self._geo.evaluate(h)
            return R, dR * h1[..., None, None]
        e = 1e-6  # dR/du by central differences (the carried rotations are smooth past 0, 1)
        R = self._blended(u)
        dR = (self._blended(u + e) - self._blended(u - e)) / (2.0 * e)
        return R, dR


@dataclass(frozen=True)
class _Piece:
    t0: float
    s0: float
    T: float
    va: float
    vb: float


class PiecewiseProfile:
    """Arc-length time law through speed changes (module docstring).

    Args:
        changes: ``(s_mid, v_before, v_after, duration)`` per speed change in path order: rest to
            speed at the start (``v_before = 0``), between moves, and to rest at the end
            (``v_after = 0``). Each change runs a quintic smoothstep of the speed over
            ``duration`` s, centred (in arc length) on ``s_mid``; the speed is constant between.
        length: Total path length, m.

    Raises:
        InvalidMoveError: Changes overlap (a move too short for its ramps or blends).
    """

    def __init__(self, changes: list[tuple[float, float, float, float]], length: float) -> None:
        self.length = float(length)
        pieces: list[_Piece] = []
        t = s = 0.0
        for s_mid, va, vb, T in changes:
            d = 0.5 * (va + vb) * T  # distance covered during the change
            s_start = s_mid - d / 2 if va > 0 and vb > 0 else (0.0 if va == 0 else self.length - d)
            gap = s_start - s
            if gap < -1e-9 * max(self.length, 1.0):
                raise InvalidMoveError(
                    f"the moves are too short for their ramps and blends: a speed change needs "
                    f"{d * 1e3:.3g} mm, {-gap * 1e3:.3g} mm more than there is")
            if gap > 1e-15:
                pieces.append(_Piece(t, s, gap / va, va, va))
                t += gap / va
                s = s_start
            pieces.append(_Piece(t, s, T, va, vb))
            t += T
            s += d
        if abs(s - self.length) > 1e-9 * max(self.length, 1.0):
            raise InvalidMoveError(f"profile covers {s:.9g} m of a {self.length:.9g} m path")
        self.pieces = pieces
        self.duration = t
        self.speed = max(max(p.va, p.vb) for p in pieces)
        self.ramp_time = pieces[0].T if pieces else 0.0
        self._t0 = np.array([p.t0 for p in pieces])

    def evaluate(self, t: ArrayLike) -> tuple[NDArray[np.float64], ...]:
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        idx = np.clip(np.searchsorted(self._t0, t, side="right") - 1, 0, len(self.pieces) - 1)
        out = [np.zeros(t.shape) for _ in range(4)]
        for k, p in enumerate(self.pieces):
            sel = idx == k
            if not np.any(sel):
                continue
            tau = t[sel] - p.t0
            if p.T <= 0:
                continue
            x = tau / p.T
            h, h1, h2, H = quintic_smoothstep(x)
            dv = p.vb - p.va
            out[0][sel] = p.s0 + p.va * tau + dv * p.T * H
            out[1][sel] = p.va + dv * h
            out[2][sel] = dv * h1 / p.T
            out[3][sel] = dv * h2 / p.T**2
        out[0] = np.minimum(out[0], self.length)
        return tuple(out)

    def time_at(self, s: float) -> float:
        """The time at which the law reaches arc length ``s`` (m), s (bisection)."""
        lo, hi = 0.0, self.duration
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            if float(self.evaluate(np.array([mid]))[0][0]) < s:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    @property
    def constant_speed_length(self) -> float:
        return float(sum(p.va * p.T for p in self.pieces if p.va == p.vb))

    @property
    def constant_speed_fraction(self):
        tc = sum(p.T for p in self.pieces if p.va == p.vb)
        return ConstantSpeedShare(time=tc / self.duration if self.duration else 0.0,
                                  length=self.constant_speed_length / self.length
                                  if self.length else 0.0)


class _WindowProfile:
    def __init__(self, ramp_time: float, speed: float) -> None:
        self.ramp_time = ramp_time
        self.speed = speed


class TimeWindow:
    """The part ``[t0, t1]`` (s) of a trajectory, on its own clock from 0: one phase of a
    blended path. ``at`` gives the whole path's states (``path_length`` is the whole path's arc
    length); ``length`` is the window's arc length.

    Args:
        base: The blended trajectory. t0, t1: The window, s. speed: The phase's set speed,
        m/s. ramp_in, ramp_out: Its start and stop ramps (0 where it blends), s. steady: The
        part of the window at the set speed (after the start ramp or incoming corner, before
        the stop ramp or outgoing corner), on the window's clock, s.
    """

    kind = "blended"

    def __init__(self, base, t0: float, t1: float, speed: float, ramp_in: float,
                 ramp_out: float, steady: tuple[float, float] | None = None) -> None:
        self.base, self.t0, self.t1 = base, float(t0), float(t1)
        #: The window's part at its set speed, on its own clock, s.
        self.steady = (0.0, self.t1 - self.t0) if steady is None else tuple(map(float, steady))
        self._speed = float(speed)
        self.ramp_in, self.ramp_out = float(ramp_in), float(ramp_out)
        s = base.profile.evaluate(np.array([self.t0, self.t1]))[0]
        self.s0 = float(s[0])
        self.length = float(s[1] - s[0])
        self.profile = _WindowProfile(max(self.ramp_in, self.ramp_out), self._speed)

    @property
    def duration(self) -> float:
        return self.t1 - self.t0

    @property
    def speed(self) -> float:
        return self._speed

    @property
    def path(self):
        return self.base.path

    @property
    def constant_speed_fraction(self):
        tc = max(self.steady[1] - self.steady[0], 0.0)
        return ConstantSpeedShare(time=tc / self.duration if self.duration else 0.0,
                                  length=min(1.0, tc * self._speed / self.length)
                                  if self.length else 0.0)

    def at(self, t: ArrayLike):
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        return self.base.at(self.t0 + t)


__all__ = [
    "BlendCurve",
    "CompositeOrientation",
    "CompositePath",
    "CornerOrientation",
    "PiecewiseProfile",
    "SubOrientation",
    "SubPath",
    "TimeWindow",
]
