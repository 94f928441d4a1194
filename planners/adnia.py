"""ADNIA: Cartesian interpolation of the tool point (seed 003), discrete and continuous.

Seed 003 (Matica et al.) computes the tool point of a robot at a fixed controller sampling period
``dt`` while it moves at a constant speed ``v``:

* **linear ADNIA** (eq. 1-7): ``N = round(L / (v dt))`` sampling periods (eq. 5), constant axis
  steps ``delta = (P_F - P_O) / N`` and points ``P_l = P_O + l delta``, ``l = 0..N`` (eq. 1-2);
* **circular/spherical ADNIA** (eq. 11-18): constant angle steps on the two spherical angles and
  ``x = R sin(phi) cos(varphi)``, ``y = R sin(phi) sin(varphi)``, ``z = R cos(phi)``;
* **versor form** (eq. 19-24): the same angle stepping applied to the tool frame's versors
  ``n``, ``o``, ``a`` (the columns of the position matrix G, eq. 8).

Angle names follow the seed, which swaps the usual (ISO 80000-2) words: ``varphi`` (the seed's
"polar angle") is measured in the xy-plane from +x, ``phi`` (its "azimuthal angle") from +z.

This module gives both

1. the seed's discrete algorithms, literal: :func:`adnia_linear`, :func:`adnia_arc` (the circular
   ADNIA in the arc's own plane: phi = 90 deg in the frame (e1, e2, normal)),
   :func:`adnia_spherical`, :func:`adnia_versors`; and
2. continuous-time moves conforming to :class:`planners.base.Trajectory` -
   :func:`linear_move`, :func:`arc_move` (three points in any plane), :func:`circle_move` (centre,
   axis, start point, sweep; weld seams round cylinders) and :func:`spherical_move` (the seed's
   spherical form) - whose ``at(t)`` gives position, velocity, acceleration, jerk, tool frame,
   angular velocity, path length and speed. They add what the seed leaves out: a smooth start and
   stop (:mod:`planners.profiles`; the ramps are taken out of the move's own length, as the seed
   suggests) and an orthonormal tool-frame law (:mod:`planners.rotations`). With
   ``ramp_time=0`` and ``L / (v dt)`` an integer, ``sample(dt)`` returns exactly the seed's
   ADNIA points of a line or arc.

Seed 003 Table I and its inconsistency (how this module treats it)
-----------------------------------------------------------------
The example is ``P_O = (1, 2, 3)`` mm, ``P_F = (2, 4 sqrt(2), 7)`` mm, ``v = 2.5e3`` mm/s,
``dt = 0.2e-3`` s. Then ``L = 5.5111`` mm and eq. (5) gives ``L / (v dt) = 11.02``, so ``N = 11``;
the seed prints ``N = 10`` (eq. 6), which would need ``L`` in [4.75, 5.25) mm - an arithmetic
slip. With ``N = 10`` the exact Y step is ``(4 sqrt(2) - 2) / 10 = 0.36569`` mm, but Table I adds
the printed ``0.36`` ("~0.36", eq. 7) and so ends at Y = 5.6 instead of 4 sqrt(2) = 5.657 mm.

Choices made here:

* the step count is eq. (5) as written (round half up, at least 1): 11 for this example;
* ``steps=`` forces an explicit N (the seed's N = 10);
* ``resolution=`` models the fixed-point axis steps of a microcontroller DDA of the seed's era:
  each axis step is truncated toward zero to a multiple of the controller's length unit (e.g.
  0.01 mm) before it is accumulated. With ``steps=10`` and ``resolution=1e-5`` m this
  reproduces every column of Table I exactly (to 0.01 mm); the truncation leaves the end point
  short of ``P_F`` by ``end_error`` (here 0.057 mm in Y), which the result reports;
* in exact arithmetic (no ``resolution``) the X and Z columns equal Table I and Y differs from
  it by ``l * (0.36569 - 0.36)`` mm.

Units: SI (m, s, rad) throughout; the discrete functions work in any consistent length unit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.base import sample_times
from planners.errors import (
    CoincidentPointsError,
    CollinearPointsError,
    InvalidMoveError,
)
from planners.profiles import ConstantSpeedShare, SpeedProfile
from planners.rotations import (
    ORIENTATION_MODES,
    AxisCarriedOrientation,
    GeodesicOrientation,
    InvalidOrientationError,
    OrientationLaw,
    SphericalVersorOrientation,
    angular_velocity,
    as_rotation,
    spherical_angles,
    spherical_versor,
)

__all__ = [
    "DEFAULT_MAX_ACCELERATION",
    "InvalidMoveError",
    "CoincidentPointsError",
    "CollinearPointsError",
    "adnia_step_count",
    "adnia_linear",
    "adnia_arc",
    "adnia_spherical",
    "adnia_versors",
    "LinearADNIA",
    "ArcADNIA",
    "SphericalADNIA",
    "VersorADNIA",
    "LinePath",
    "CirclePath",
    "SphericalPath",
    "CartesianState",
    "CartesianTrajectory",
    "linear_move",
    "arc_move",
    "circle_move",
    "spherical_move",
    "spherical_to_cartesian",
    "cartesian_to_spherical",
]

#: Path acceleration limit used for the start/stop ramps when neither ``ramp_time`` nor
#: ``max_acceleration`` is given, m/s^2.
DEFAULT_MAX_ACCELERATION = 5.0

#: Points closer than this (relative to max(1, coordinate size)) are taken as coincident.
_COINCIDENT_TOL = 1e-9
#: Three points whose sine of the angle at the first point is below this are collinear.
_COLLINEAR_TOL = 1e-9
#: Largest number of points sample() will build.
_MAX_SAMPLES = 50_000_000


# --------------------------------------------------------------------------------------------
# input checks
# --------------------------------------------------------------------------------------------
def _point(value: ArrayLike, field: str) -> NDArray[np.float64]:
    try:
        p = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidMoveError(f"{field}: expected 3 coordinates (x, y, z), got {value!r}") from None
    if p.shape != (3,):
        raise InvalidMoveError(f"{field}: expected 3 coordinates (x, y, z), got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise InvalidMoveError(f"{field}: coordinates must be finite, got {p.tolist()}")
    return p


def _positive(value: float, field: str, unit: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InvalidMoveError(f"{field}: expected a positive number of {unit}, got {value!r}") from None
    if not math.isfinite(x) or x <= 0.0:
        raise InvalidMoveError(f"{field}: must be a positive finite number of {unit}, got {value!r}")
    return x


def _distinct(p: NDArray[np.float64], q: NDArray[np.float64], what: str) -> float:
    d = float(np.linalg.norm(q - p))
    scale = max(1.0, float(np.max(np.abs(p))), float(np.max(np.abs(q))))
    if d <= _COINCIDENT_TOL * scale:
        raise CoincidentPointsError(f"{what} coincide ({p.tolist()}); a move needs distinct points")
    return d


def _steps(value: int, field: str = "steps") -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InvalidMoveError(f"{field}: must be a positive integer number of sampling periods, got {value!r}")
    return int(value)


def adnia_step_count(length: float, speed: float, dt: float) -> tuple[int, float]:
    """Number of sampling periods N of a move, seed 003 eq. (5) and (14).

    ``N = round(L / (v dt))`` with halves rounded up and N >= 1 (a move shorter than half a step
    still takes one step).

    Args:
        length: Path length L (any length unit).
        speed: Tool speed v (same length unit per second).
        dt: Controller sampling period, s.

    Returns:
        ``(N, L / (v dt))``: the step count and the unrounded ratio.
    """
    length = _positive(length, "length", "length units")
    speed = _positive(speed, "speed", "length units per second")
    dt = _positive(dt, "dt", "s")
    ratio = length / (speed * dt)
    return max(1, int(math.floor(ratio + 0.5))), ratio


def _step_count(length: float, speed: float | None, dt: float | None, steps: int | None
                ) -> tuple[int, float]:
    if steps is not None:
        n = _steps(steps)
        ratio = (length / (_positive(speed, "speed", "length units per second") * _positive(dt, "dt", "s"))
                 if speed is not None and dt is not None else float("nan"))
        return n, ratio
    if speed is None or dt is None:
        raise InvalidMoveError("steps: give either steps=N or both speed and dt (eq. 5: N = round(L/(v dt)))")
    return adnia_step_count(length, speed, dt)


# --------------------------------------------------------------------------------------------
# discrete ADNIA (seed 003, literal)
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LinearADNIA:
    """Output of the linear ADNIA (seed 003 eq. 1-7).

    Attributes:
        steps: N, number of sampling periods (eq. 5).
        step_ratio: ``L / (v dt)`` before rounding (NaN when N was given without v, dt).
        length: L, distance from start to end.
        delta: Axis steps (delta_x, delta_y, delta_z) actually added each period, shape (3,)
            (truncated to ``resolution`` when one was given).
        points: P_0..P_N, shape (N + 1, 3) (eq. 1).
        end_error: ``points[-1] - end``, shape (3,): 0 up to rounding in exact arithmetic.
    """

    steps: int
    step_ratio: float
    length: float
    delta: NDArray[np.float64]
    points: NDArray[np.float64]
    end_error: NDArray[np.float64]


def adnia_linear(start: ArrayLike, end: ArrayLike, speed: float | None = None,
                 dt: float | None = None, *, steps: int | None = None,
                 resolution: float | None = None) -> LinearADNIA:
    """Linear ADNIA, seed 003 eq. (1)-(7).

    Args:
        start: P_O, shape (3,).
        end: P_F, shape (3,).
        speed: Tool speed v (length unit / s); needed unless ``steps`` is given.
        dt: Sampling period, s; needed unless ``steps`` is given.
        steps: Explicit N, overriding eq. (5).
        resolution: Controller length unit; each axis step is truncated toward zero to a
            multiple of it (fixed-point DDA). None = exact arithmetic.

    Returns:
        The step count, axis steps and points P_0..P_N.

    Raises:
        InvalidMoveError: bad point, speed, dt, steps or resolution.
        CoincidentPointsError: ``start == end``.
    """
    p0 = _point(start, "start")
    p1 = _point(end, "end")
    length = _distinct(p0, p1, "start and end")
    n, ratio = _step_count(length, speed, dt, steps)
    delta = (p1 - p0) / n                                            # eq. (7)
    if resolution is not None:
        res = _positive(resolution, "resolution", "length units")
        q = delta / res
        delta = np.trunc(q + np.copysign(1e-9, q)) * res             # fixed-point step
    points = p0 + np.arange(n + 1)[:, None] * delta                   # eq. (1)
    return LinearADNIA(steps=n, step_ratio=ratio, length=length, delta=delta,
                       points=points, end_error=points[-1] - p1)


@dataclass(frozen=True)
class ArcADNIA:
    """Output of the circular ADNIA on a 3-point arc (seed 003 eq. 11-14 in the arc's plane).

    Attributes:
        steps: N (eq. 14).
        step_ratio: ``L / (v dt)`` before rounding (NaN when N was given without v, dt).
        length: Arc length L = radius * sweep.
        centre, radius, normal, sweep: The circle (see :class:`CirclePath`).
        delta_angle: Angle step, rad (eq. 11).
        points: P_0..P_N, shape (N + 1, 3).
    """

    steps: int
    step_ratio: float
    length: float
    centre: NDArray[np.float64]
    radius: float
    normal: NDArray[np.float64]
    sweep: float
    delta_angle: float
    points: NDArray[np.float64]


def adnia_arc(start: ArrayLike, via: ArrayLike, end: ArrayLike, speed: float | None = None,
              dt: float | None = None, *, steps: int | None = None) -> ArcADNIA:
    """Circular ADNIA on the arc through three points (any plane).

    In the arc's own frame (e1 towards ``start``, e2 = normal x e1) the arc is the seed's circle
    at phi = 90 deg: ``P_l = c + R (cos(l d) e1 + sin(l d) e2)``, ``d = sweep / N`` (eq. 11-18).

    Args:
        start, via, end: Points on the arc, shape (3,), in travel order.
        speed, dt: Tangential speed and sampling period (eq. 14), unless ``steps`` is given.
        steps: Explicit N.
    """
    path = CirclePath.through(start, via, end)
    n, ratio = _step_count(path.length, speed, dt, steps)
    d = path.sweep / n
    return ArcADNIA(steps=n, step_ratio=ratio, length=path.length, centre=path.centre,
                    radius=path.radius, normal=path.normal, sweep=path.sweep, delta_angle=d,
                    points=path.point_at_angle(d * np.arange(n + 1)))


@dataclass(frozen=True)
class SphericalADNIA:
    """Output of the spherical ADNIA, seed 003 eq. (11)-(18).

    Attributes:
        steps: N (eq. 14, or given).
        step_ratio: ``L / (v dt)`` before rounding (NaN when N was given without v, dt).
        length: Length L of the curve traced (angles linear in the step index).
        radius: R.
        centre: Sphere centre, shape (3,).
        delta_varphi, delta_phi: Angle steps, rad (eq. 11, 15).
        varphi, phi: Angles at each step, rad, shape (N + 1,) (eq. 12-13).
        points: P_0..P_N, shape (N + 1, 3) (eq. 16-18).
    """

    steps: int
    step_ratio: float
    length: float
    radius: float
    centre: NDArray[np.float64]
    delta_varphi: float
    delta_phi: float
    varphi: NDArray[np.float64]
    phi: NDArray[np.float64]
    points: NDArray[np.float64]


def adnia_spherical(start: ArrayLike, end: ArrayLike, speed: float | None = None,
                    dt: float | None = None, *, steps: int | None = None,
                    centre: ArrayLike = (0.0, 0.0, 0.0)) -> SphericalADNIA:
    """Spherical (circular) ADNIA, seed 003 eq. (11)-(18), literal.

    The two angles change by equal steps each period, so the tool follows the curve
    ``varphi(u), phi(u)`` linear in ``u``; its speed is constant only when that curve is a
    circle traced uniformly (one angle fixed). The continuous :func:`spherical_move` follows the
    same curve at constant speed.

    Args:
        start: Start ``(R, varphi, phi)``: radius (length unit) and seed angles, rad.
        end: End ``(R, varphi, phi)``; same R. Angles are used as given (no wrapping).
        speed, dt: Tangential speed and sampling period (eq. 14), unless ``steps`` is given.
        steps: Explicit N (the seed's example uses N = 10).
        centre: Sphere centre, shape (3,).
    """
    path = SphericalPath(start, end, centre)
    n, ratio = _step_count(path.length, speed, dt, steps)
    l = np.arange(n + 1)
    d_varphi = path.delta_varphi / n                                 # eq. (11)
    d_phi = path.delta_phi / n
    varphi = path.varphi0 + l * d_varphi                              # eq. (12)
    phi = path.phi0 + l * d_phi                                       # eq. (13)
    pts = path.centre + path.radius * spherical_versor(varphi, phi)   # eq. (16)-(18)
    return SphericalADNIA(steps=n, step_ratio=ratio, length=path.length, radius=path.radius,
                          centre=path.centre, delta_varphi=d_varphi, delta_phi=d_phi,
                          varphi=varphi, phi=phi, points=pts)


@dataclass(frozen=True)
class VersorADNIA:
    """Output of the versor ADNIA, seed 003 eq. (19)-(24).

    Attributes:
        steps: N.
        delta_varphi, delta_phi: Angle steps of the versors n, o, a, rad, shape (3,).
        raw: The seed's versors at each step before orthonormalization, (N + 1, 3, 3),
            columns n, o, a.
        frames: Orthonormal tool frames at each step (a kept, o orthogonalized, n = o x a),
            (N + 1, 3, 3).
    """

    steps: int
    delta_varphi: NDArray[np.float64]
    delta_phi: NDArray[np.float64]
    raw: NDArray[np.float64]
    frames: NDArray[np.float64]


def adnia_versors(rotation_start: ArrayLike, rotation_end: ArrayLike, steps: int) -> VersorADNIA:
    """Versor ADNIA, seed 003 eq. (19)-(24): angle steps on each of n, o, a.

    Args:
        rotation_start, rotation_end: Tool frames (3, 3), columns n, o, a.
        steps: N, the same as the position's (seed 003, conclusions).
    """
    n = _steps(steps)
    law = SphericalVersorOrientation(rotation_start, rotation_end)
    u = np.arange(n + 1) / n
    return VersorADNIA(steps=n, delta_varphi=law.angles[:, 2] / n, delta_phi=law.angles[:, 3] / n,
                       raw=law.raw_versors(u), frames=law.evaluate(u)[0])


# --------------------------------------------------------------------------------------------
# geometric paths, parametrized by arc length s
# --------------------------------------------------------------------------------------------
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


# --------------------------------------------------------------------------------------------
# continuous-time Cartesian trajectory
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CartesianState:
    """Tool-point state at one time (arrays of shape (3,), (3, 3), ()) or M times ((M, 3), ...).

    Attributes:
        position: Tool point, m, (..., 3).
        velocity: m/s, (..., 3).
        acceleration: m/s^2, (..., 3).
        jerk: m/s^3, (..., 3).
        rotation: Tool frame, (..., 3, 3), columns n, o, a (seed 003 G matrix, eq. 8).
        angular_velocity: Of the tool frame, base-frame components, rad/s, (..., 3).
        path_length: Arc length travelled s, m, (...).
        speed: ds/dt, m/s, (...).
    """

    position: NDArray[np.float64]
    velocity: NDArray[np.float64]
    acceleration: NDArray[np.float64]
    jerk: NDArray[np.float64]
    rotation: NDArray[np.float64]
    angular_velocity: NDArray[np.float64]
    path_length: NDArray[np.float64]
    speed: NDArray[np.float64]

    def pose(self) -> NDArray[np.float64]:
        """Seed 003's position matrix G (eq. 8), homogeneous 4x4, shape (..., 4, 4)."""
        G = np.zeros(self.rotation.shape[:-2] + (4, 4))
        G[..., :3, :3] = self.rotation
        G[..., :3, 3] = self.position
        G[..., 3, 3] = 1.0
        return G


class CartesianTrajectory:
    """Tool point moving along a path by a smooth speed law, with an orientation law.

    Conforms to :class:`planners.base.Trajectory`. Build it with :func:`linear_move`,
    :func:`arc_move`, :func:`circle_move` or :func:`spherical_move`.

    Args:
        path: Geometric path by arc length (:class:`LinePath`, :class:`CirclePath`,
            :class:`SphericalPath`).
        orientation: Tool-frame law in u = s / L (:mod:`planners.rotations`).
        profile: Arc-length time law (:class:`planners.profiles.SpeedProfile`) of the same length.
    """

    def __init__(self, path: Path, orientation: OrientationLaw, profile: SpeedProfile) -> None:
        if abs(profile.length - path.length) > 1e-12 * path.length:
            raise InvalidMoveError(
                f"profile: length {profile.length!r} m differs from the path's {path.length!r} m")
        self.path = path
        self.orientation = orientation
        self.profile = profile

    @property
    def kind(self) -> str:
        """``"line"``, ``"arc"`` or ``"spherical"``."""
        return self.path.kind

    @property
    def duration(self) -> float:
        """Total duration, s (``L / v + ramp_time``)."""
        return self.profile.duration

    @property
    def length(self) -> float:
        """Path length L, m."""
        return self.path.length

    @property
    def speed(self) -> float:
        """Programmed constant speed v, m/s."""
        return self.profile.speed

    @property
    def constant_speed_fraction(self) -> ConstantSpeedShare:
        """Share of the time and of the length run at the constant speed v."""
        return self.profile.constant_speed_fraction

    def constant_speed_steps(self, dt: float) -> tuple[int, float]:
        """Seed 003 eq. (5)/(14) for the constant-speed part only (the seed's N after the ramps).

        Returns:
            ``(N, L_c / (v dt))`` where ``L_c`` is the constant-speed length (N = 0 if none).
        """
        dt = _positive(dt, "dt", "s")
        lc = self.profile.constant_speed_length
        if lc <= 0.0:
            return 0, 0.0
        return adnia_step_count(lc, self.speed, dt)

    def at(self, t: ArrayLike) -> CartesianState:
        """State at time(s) ``t`` (s, any shape); times outside [0, duration] are clamped.

        Raises:
            InvalidMoveError: ``t`` contains NaN.
        """
        t = np.asarray(t, dtype=float)
        if np.any(np.isnan(t)):
            raise InvalidMoveError("t: time contains NaN")
        shape = t.shape
        s, sd, sdd, sddd = self.profile.evaluate(t.reshape(-1))
        p, d1, d2, d3 = self.path.evaluate(s)
        sd_, sdd_, sddd_ = sd[:, None], sdd[:, None], sddd[:, None]
        vel = d1 * sd_
        acc = d2 * sd_**2 + d1 * sdd_
        jerk = d3 * sd_**3 + 3.0 * d2 * sd_ * sdd_ + d1 * sddd_
        L = self.path.length
        R, dR = self.orientation.evaluate(s / L)
        w = angular_velocity(R, dR) * (sd / L)[:, None]
        v3 = shape + (3,)
        return CartesianState(position=p.reshape(v3), velocity=vel.reshape(v3),
                              acceleration=acc.reshape(v3), jerk=jerk.reshape(v3),
                              rotation=R.reshape(shape + (3, 3)), angular_velocity=w.reshape(v3),
                              path_length=s.reshape(shape), speed=sd.reshape(shape))

    def sample(self, dt: float) -> tuple[NDArray[np.float64], CartesianState]:
        """``(times, states)`` every controller period ``dt`` (s), the last at ``duration``.

        Raises:
            InvalidMoveError: ``dt`` not positive, or so small that more than 5e7 points result.
        """
        dt = _positive(dt, "dt", "s")
        if self.duration / dt > _MAX_SAMPLES:
            raise InvalidMoveError(
                f"dt: {dt:g} s gives {self.duration / dt:.3g} samples over {self.duration:g} s"
                f" (limit {_MAX_SAMPLES:.0e}); use a larger sampling period")
        times = sample_times(0.0, self.duration, dt)
        return times, self.at(times)


# --------------------------------------------------------------------------------------------
# move builders
# --------------------------------------------------------------------------------------------
def _profile(length: float, speed: float, ramp_time: float | None, max_acceleration: float | None,
             ramp_shape: str) -> SpeedProfile:
    speed = _positive(speed, "speed", "m/s")
    if ramp_time is not None and max_acceleration is not None:
        raise InvalidMoveError("ramp_time: give ramp_time or max_acceleration, not both")
    if ramp_time is not None:
        return SpeedProfile(length, speed, ramp_time=ramp_time, shape=ramp_shape)
    a = DEFAULT_MAX_ACCELERATION if max_acceleration is None else max_acceleration
    return SpeedProfile.from_max_acceleration(length, speed, a, shape=ramp_shape)


def _orientation(mode: str, rotation_start: ArrayLike | None, rotation_end: ArrayLike | None,
                 carry: tuple[NDArray[np.float64], float] | None) -> OrientationLaw:
    valid = ORIENTATION_MODES if carry is not None else tuple(m for m in ORIENTATION_MODES if m != "carry")
    if mode not in valid:
        raise InvalidOrientationError(
            f"orientation: unknown or unusable mode {mode!r} for this move; valid: {', '.join(valid)}")
    R0 = np.eye(3) if rotation_start is None else as_rotation(rotation_start, "rotation_start")
    if mode == "carry":
        if rotation_end is not None:
            raise InvalidOrientationError(
                "rotation_end: not used with orientation='carry' (the end frame follows from the"
                " arc); omit it or use orientation='geodesic'")
        axis, angle = carry
        return AxisCarriedOrientation(R0, axis, angle)
    R1 = R0 if rotation_end is None else as_rotation(rotation_end, "rotation_end")
    if mode == "geodesic":
        return GeodesicOrientation(R0, R1)
    return SphericalVersorOrientation(R0, R1)


def linear_move(start: ArrayLike, end: ArrayLike, speed: float, *,
                rotation_start: ArrayLike | None = None, rotation_end: ArrayLike | None = None,
                orientation: str = "geodesic", ramp_time: float | None = None,
                max_acceleration: float | None = None, ramp_shape: str = "quintic"
                ) -> CartesianTrajectory:
    """Straight move at constant speed with smooth start and stop (seed 003 eq. 1-7 + ramps).

    Args:
        start, end: P_O and P_F, m, (3,).
        speed: Constant tool speed v, m/s.
        rotation_start: Start tool frame (3, 3), columns n, o, a (default identity, eq. 9).
        rotation_end: End tool frame (default: ``rotation_start``, constant orientation).
        orientation: ``"geodesic"`` (slerp) or ``"spherical"`` (seed eq. 19-24).
        ramp_time: Duration of each start/stop ramp, s (0 = seed's bare constant speed).
        max_acceleration: Alternatively, the ramps' path-acceleration limit, m/s^2
            (default :data:`DEFAULT_MAX_ACCELERATION` when neither is given).
        ramp_shape: ``"quintic"`` (continuous jerk) or ``"septic"`` (continuous snap).

    Raises:
        InvalidMoveError, CoincidentPointsError, InvalidOrientationError,
        planners.profiles.InvalidProfileError, planners.profiles.MoveTooShortError.
    """
    path = LinePath(start, end)
    prof = _profile(path.length, speed, ramp_time, max_acceleration, ramp_shape)
    return CartesianTrajectory(path, _orientation(orientation, rotation_start, rotation_end, None), prof)


def arc_move(start: ArrayLike, via: ArrayLike, end: ArrayLike, speed: float, *,
             rotation_start: ArrayLike | None = None, rotation_end: ArrayLike | None = None,
             orientation: str = "carry", ramp_time: float | None = None,
             max_acceleration: float | None = None, ramp_shape: str = "quintic"
             ) -> CartesianTrajectory:
    """Circular arc through three points (any plane) at constant tangential speed.

    The arc goes from ``start`` through ``via`` to ``end``; its sweep may exceed 180 deg.

    Args:
        start, via, end: Points on the arc in travel order, m, (3,).
        speed: Tangential speed v, m/s.
        rotation_start: Start tool frame (default identity).
        rotation_end: End tool frame (only with ``"geodesic"`` or ``"spherical"``).
        orientation: ``"carry"`` (default: the start frame turns with the arc about its axis,
            so the torch keeps its work and travel angles to the seam), ``"geodesic"`` or
            ``"spherical"``.
        ramp_time, max_acceleration, ramp_shape: As :func:`linear_move`.

    Raises:
        CollinearPointsError: the three points lie on one line. And as :func:`linear_move`.
    """
    path = CirclePath.through(start, via, end)
    prof = _profile(path.length, speed, ramp_time, max_acceleration, ramp_shape)
    law = _orientation(orientation, rotation_start, rotation_end, (path.normal, path.sweep))
    return CartesianTrajectory(path, law, prof)


def circle_move(centre: ArrayLike, axis: ArrayLike, start: ArrayLike, sweep: float, speed: float, *,
                rotation_start: ArrayLike | None = None, rotation_end: ArrayLike | None = None,
                orientation: str = "carry", ramp_time: float | None = None,
                max_acceleration: float | None = None, ramp_shape: str = "quintic"
                ) -> CartesianTrajectory:
    """Full or partial circle about an axis (e.g. a weld seam round a cylinder).

    Args:
        centre: A point on the circle's axis, m, (3,).
        axis: Axis direction, (3,); the tool turns right-handedly about it for ``sweep > 0``.
        start: Start point, m, (3,); the circle lies in the plane through it normal to ``axis``.
        sweep: Angle to travel, rad (2 pi = full circle; negative = the other way).
        speed: Tangential speed, m/s.
        rotation_start, rotation_end, orientation, ramp_time, max_acceleration, ramp_shape:
            As :func:`arc_move`.
    """
    path = CirclePath.about_axis(centre, axis, start, sweep)
    prof = _profile(path.length, speed, ramp_time, max_acceleration, ramp_shape)
    law = _orientation(orientation, rotation_start, rotation_end, (path.normal, path.sweep))
    return CartesianTrajectory(path, law, prof)


def spherical_move(start: ArrayLike, end: ArrayLike, speed: float, *,
                   centre: ArrayLike = (0.0, 0.0, 0.0), rotation_start: ArrayLike | None = None,
                   rotation_end: ArrayLike | None = None, orientation: str = "geodesic",
                   ramp_time: float | None = None, max_acceleration: float | None = None,
                   ramp_shape: str = "quintic") -> CartesianTrajectory:
    """Seed 003's spherical form (eq. 11-18) as a constant-speed move.

    The tool follows the curve on which both seed angles change linearly (the points of
    :func:`adnia_spherical` lie on it), at constant speed along it.

    Args:
        start, end: ``(R, varphi, phi)``: radius, m, and seed angles, rad (same R).
        speed: Tangential speed, m/s.
        centre: Sphere centre, m, (3,).
        rotation_start, rotation_end, ramp_time, max_acceleration, ramp_shape: As :func:`linear_move`.
        orientation: ``"geodesic"`` or ``"spherical"``.
    """
    path = SphericalPath(start, end, centre)
    prof = _profile(path.length, speed, ramp_time, max_acceleration, ramp_shape)
    return CartesianTrajectory(path, _orientation(orientation, rotation_start, rotation_end, None), prof)
