"""Geometric paths of a Cartesian move, parametrized by arc length.

Owns :class:`Path` (what a move's path offers: ``length`` and ``evaluate(s)``, the point and
its first three derivatives by arc length), :class:`LinePath`, :class:`CirclePath` (an arc
through three points, or about an axis) and :class:`SphericalPath` (seed 003's spherical
curve at constant speed), and the seed's spherical coordinates (eq. 16-18).
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.errors import (
    CoincidentPointsError,
    CollinearPointsError,
    InvalidMoveError,
)
from planners.move_inputs import _COINCIDENT_TOL, _COLLINEAR_TOL, _distinct, _point
from planners.rotations import spherical_angles, spherical_versor


class Path(Protocol):
    """A curve p(s) by arc length s in [0, length]."""

    length: float

    def evaluate(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """``(p, dp/ds, d2p/ds2, d3p/ds3)`` at ``s`` of shape (M,), each of shape (M, 3)."""
        ...


class LinePath:
    """Straight segment from ``start`` to ``end``.

    Attributes:
        start, end: End points, m, (3,).
        length: m.
        direction: Unit tangent, (3,).
    """

    kind = "line"

    def __init__(self, start: ArrayLike, end: ArrayLike) -> None:
        self.start = _point(start, "start")
        self.end = _point(end, "end")
        self.length = _distinct(self.start, self.end, "start and end")
        self._chord = self.end - self.start
        self.direction = self._chord / self.length

    def evaluate(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        s = np.asarray(s, dtype=float)[..., None]
        p = self.start + (s / self.length) * self._chord
        d1 = np.broadcast_to(self.direction, p.shape).copy()
        zero = np.zeros_like(p)
        return p, d1, zero, zero.copy()


class CirclePath:
    """Arc of a circle: ``p = c + R (cos(theta) e1 + sin(theta) e2)``, theta = s / R in [0, sweep].

    ``e2 = normal x e1``, so the tool turns right-handedly about ``normal``.

    Attributes:
        centre: m, (3,).
        radius: m.
        normal: Unit axis of the circle, (3,).
        e1: Unit vector from the centre to the start point, (3,).
        e2: ``normal x e1``, (3,).
        sweep: Swept angle, rad, > 0 (may exceed 2 pi for several turns).
        length: ``radius * sweep``, m.
    """

    kind = "arc"

    def __init__(self, centre: ArrayLike, radius: float, e1: ArrayLike, normal: ArrayLike,
                 sweep: float) -> None:
        self.centre = np.asarray(centre, dtype=float)
        self.radius = float(radius)
        self.normal = np.asarray(normal, dtype=float)
        self.e1 = np.asarray(e1, dtype=float)
        self.e2 = np.cross(self.normal, self.e1)
        self.sweep = float(sweep)
        self.length = self.radius * self.sweep

    @classmethod
    def through(cls, start: ArrayLike, via: ArrayLike, end: ArrayLike) -> CirclePath:
        """The arc from ``start`` through ``via`` to ``end`` (any plane, sweeps up to < 360 deg).

        Raises:
            CoincidentPointsError: two of the points coincide.
            CollinearPointsError: the points lie on one line.
        """
        A, B, C = _point(start, "start"), _point(via, "via"), _point(end, "end")
        _distinct(A, B, "start and via")
        _distinct(B, C, "via and end")
        _distinct(A, C, "start and end")
        a, b = A - C, B - C
        axb = np.cross(a, b)
        nrm = float(np.linalg.norm(axb))
        if nrm <= _COLLINEAR_TOL * float(np.linalg.norm(a)) * float(np.linalg.norm(b)):
            raise CollinearPointsError(
                f"via: start, via and end are collinear ({A.tolist()}, {B.tolist()}, {C.tolist()});"
                " an arc needs three points not on one line (use a linear move)")
        # circumcentre of the triangle A, B, C
        centre = C + np.cross(np.dot(a, a) * b - np.dot(b, b) * a, axb) / (2.0 * nrm**2)
        normal = np.cross(B - A, C - B)
        normal /= np.linalg.norm(normal)
        rA = A - centre
        radius = float(np.linalg.norm(rA))
        e1 = rA / radius
        e2 = np.cross(normal, e1)
        rC = C - centre
        sweep = float(np.arctan2(np.dot(rC, e2), np.dot(rC, e1))) % (2.0 * np.pi)
        return cls(centre, radius, e1, normal, sweep)

    @classmethod
    def about_axis(cls, centre: ArrayLike, axis: ArrayLike, start: ArrayLike, sweep: float
                   ) -> CirclePath:
        """Circle round the line through ``centre`` along ``axis``, from ``start``, by ``sweep``.

        The circle's plane is the one through ``start`` normal to ``axis``; its centre is the
        foot of ``start`` on the axis. A negative ``sweep`` turns the other way (left-handed
        about ``axis``); |sweep| may exceed 2 pi.

        Raises:
            InvalidMoveError: zero/NaN axis or sweep.
            CoincidentPointsError: ``start`` lies on the axis (radius 0).
        """
        c = _point(centre, "centre")
        k = _point(axis, "axis")
        p = _point(start, "start")
        kn = float(np.linalg.norm(k))
        if kn == 0.0:
            raise InvalidMoveError("axis: must be a non-zero vector")
        k = k / kn
        try:
            sw = float(sweep)
        except (TypeError, ValueError):
            raise InvalidMoveError(f"sweep: expected an angle in rad, got {sweep!r}") from None
        if not math.isfinite(sw) or sw == 0.0:
            raise InvalidMoveError(f"sweep: must be a non-zero finite angle in rad, got {sweep!r}")
        foot = c + np.dot(p - c, k) * k
        r = p - foot
        radius = float(np.linalg.norm(r))
        scale = max(1.0, float(np.max(np.abs(p))))
        if radius <= _COINCIDENT_TOL * scale:
            raise CoincidentPointsError(
                f"start: point {p.tolist()} lies on the circle's axis (radius 0)")
        normal = k if sw > 0 else -k
        return cls(foot, radius, r / radius, normal, abs(sw))

    def point_at_angle(self, theta: ArrayLike) -> NDArray[np.float64]:
        """Points at angles ``theta`` (rad, shape (...)) from the start, shape (..., 3)."""
        th = np.asarray(theta, dtype=float)[..., None]
        return self.centre + self.radius * (np.cos(th) * self.e1 + np.sin(th) * self.e2)

    def evaluate(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        th = np.asarray(s, dtype=float)[..., None] / self.radius
        c, sn = np.cos(th), np.sin(th)
        radial = c * self.e1 + sn * self.e2
        tangent = -sn * self.e1 + c * self.e2
        p = self.centre + self.radius * radial
        return p, tangent, -radial / self.radius, -tangent / self.radius**2


def _spherical_coordinates(value: ArrayLike, field: str) -> tuple[float, float, float]:
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidMoveError(f"{field}: expected (R, varphi, phi), got {value!r}") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InvalidMoveError(f"{field}: expected finite (R, varphi, phi) (m, rad, rad), got {value!r}")
    if v[0] <= 0:
        raise InvalidMoveError(f"{field}: radius R must be positive, got {v[0]!r}")
    return float(v[0]), float(v[1]), float(v[2])


def spherical_to_cartesian(coords: ArrayLike, centre: ArrayLike = (0.0, 0.0, 0.0)
                           ) -> NDArray[np.float64]:
    """Point of seed 003 eq. (16)-(18) from ``(R, varphi, phi)`` (..., 3), shape (..., 3)."""
    c = np.asarray(coords, dtype=float)
    return np.asarray(centre, dtype=float) + c[..., 0:1] * spherical_versor(c[..., 1], c[..., 2])


def cartesian_to_spherical(point: ArrayLike, centre: ArrayLike = (0.0, 0.0, 0.0)
                           ) -> NDArray[np.float64]:
    """``(R, varphi, phi)`` (seed 003 angles, rad) of point(s) (..., 3) about ``centre``."""
    d = np.asarray(point, dtype=float) - np.asarray(centre, dtype=float)
    r = np.linalg.norm(d, axis=-1)
    f, p = spherical_angles(d / r[..., None])
    return np.stack([r, f, p], axis=-1)


# Gauss-Legendre rule for the arc length of the spherical curve
_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)


class SphericalPath:
    """Seed 003's spherical curve at constant speed: angles linear in u, then arc-length reparametrized.

    ``p(u) = c + R (sin phi cos varphi, sin phi sin varphi, cos phi)`` with
    ``varphi = varphi0 + u dvarphi`` and ``phi = phi0 + u dphi``, u in [0, 1]. The length
    ``s(u) = integral |p'(u)| du`` is computed by composite 16-point Gauss-Legendre quadrature
    (64 panels) and inverted by Newton's method, to ~1e-14 relative.

    Args:
        start, end: ``(R, varphi, phi)`` (m, rad, rad), same R.
        centre: Sphere centre, m, (3,).
    """

    kind = "spherical"
    _PANELS = 64

    def __init__(self, start: ArrayLike, end: ArrayLike, centre: ArrayLike = (0.0, 0.0, 0.0)) -> None:
        r0, f0, p0 = _spherical_coordinates(start, "start")
        r1, f1, p1 = _spherical_coordinates(end, "end")
        if abs(r1 - r0) > 1e-12 * max(r0, r1):
            raise InvalidMoveError(
                f"end: radius R = {r1!r} differs from the start's R = {r0!r}; a spherical move keeps R")
        self.centre = _point(centre, "centre")
        self.radius = r0
        self.varphi0, self.phi0 = f0, p0
        self.delta_varphi, self.delta_phi = f1 - f0, p1 - p0
        self.start = self.point_at_parameter(0.0)
        self.end = self.point_at_parameter(1.0)
        if self.delta_phi == 0.0 and (self.delta_varphi == 0.0 or abs(math.sin(p0)) < 1e-12):
            raise CoincidentPointsError(
                f"start and end coincide on the sphere ({self.start.tolist()}); a move needs distinct points")
        edges = np.linspace(0.0, 1.0, self._PANELS + 1)
        self._edges = edges
        panel = self._integrate(edges[:-1], edges[1:])
        self._cum = np.concatenate([[0.0], np.cumsum(panel)])
        self.length = float(self._cum[-1])
        # table for the initial guess of u(s)
        self._u_tab = np.linspace(0.0, 1.0, 4097)
        self._s_tab = self.arc_length(self._u_tab)

    # --- curve in the angle parameter u ----------------------------------------------------
    def point_at_parameter(self, u: ArrayLike) -> NDArray[np.float64]:
        """``p(u)`` (u in [0, 1], shape (...)), shape (..., 3): the seed's point at u = l / N."""
        u = np.asarray(u, dtype=float)
        return self.centre + self.radius * spherical_versor(self.varphi0 + u * self.delta_varphi,
                                                            self.phi0 + u * self.delta_phi)

    def _derivative_u(self, u: NDArray[np.float64], k: int) -> NDArray[np.float64]:
        """k-th derivative of p with respect to u (k >= 1), shape (..., 3).

        With alpha = phi + varphi and beta = phi - varphi, x = (sin alpha + sin beta) / 2,
        y = (cos beta - cos alpha) / 2, z = cos phi; each term's k-th derivative is a phase shift.
        """
        f = self.varphi0 + u * self.delta_varphi
        p = self.phi0 + u * self.delta_phi
        da = self.delta_phi + self.delta_varphi
        db = self.delta_phi - self.delta_varphi
        sh = 0.5 * k * np.pi
        x = 0.5 * (da**k * np.sin(p + f + sh) + db**k * np.sin(p - f + sh))
        y = 0.5 * (db**k * np.cos(p - f + sh) - da**k * np.cos(p + f + sh))
        z = self.delta_phi**k * np.cos(p + sh)
        return self.radius * np.stack([x, y, z], axis=-1)

    def _speed_u(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """|dp/du|, m."""
        p = self.phi0 + u * self.delta_phi
        return self.radius * np.sqrt(self.delta_phi**2 + (np.sin(p) * self.delta_varphi) ** 2)

    def _integrate(self, a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
        half = 0.5 * (b - a)
        mid = 0.5 * (b + a)
        nodes = mid[..., None] + half[..., None] * _GL_X
        return half * np.sum(_GL_W * self._speed_u(nodes), axis=-1)

    def arc_length(self, u: ArrayLike) -> NDArray[np.float64]:
        """s(u), m, for u in [0, 1] (shape (...))."""
        u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
        k = np.minimum((u * self._PANELS).astype(int), self._PANELS - 1)
        return self._cum[k] + self._integrate(self._edges[k], u)

    def parameter(self, s: ArrayLike) -> NDArray[np.float64]:
        """u(s) for arc length(s) s in [0, length], the inverse of :meth:`arc_length`."""
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        u = np.interp(s, self._s_tab, self._u_tab)        # error ~1e-9 from the 4097-point table
        for _ in range(8):
            # Newton: the error after a step is ~ |g'/2g| du^2, so |du| < 1e-8 leaves ~1e-16
            du = (self.arc_length(u) - s) / self._speed_u(u)
            u = np.clip(u - du, 0.0, 1.0)
            if np.all(np.abs(du) < 1e-8):
                break
        return u

    def evaluate(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        u = self.parameter(s)
        p = self.point_at_parameter(u)
        p1, p2, p3 = (self._derivative_u(u, k) for k in (1, 2, 3))
        g = np.linalg.norm(p1, axis=-1)
        g1 = np.sum(p1 * p2, axis=-1) / g
        g2 = (np.sum(p2 * p2, axis=-1) + np.sum(p1 * p3, axis=-1)) / g - g1**2 / g
        u1 = 1.0 / g
        u2 = -g1 / g**3
        u3 = -g2 / g**4 + 3.0 * g1**2 / g**5
        u1, u2, u3 = u1[..., None], u2[..., None], u3[..., None]
        d1 = p1 * u1
        d2 = p2 * u1**2 + p1 * u2
        d3 = p3 * u1**3 + 3.0 * p2 * u1 * u2 + p1 * u3
        return p, d1, d2, d3
