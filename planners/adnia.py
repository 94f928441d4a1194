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

This module is the seed's algorithm; it gives both

1. the seed's discrete algorithms, literal: :func:`adnia_linear`, :func:`adnia_arc` (the circular
   ADNIA in the arc's own plane: phi = 90 deg in the frame (e1, e2, normal)),
   :func:`adnia_spherical`, :func:`adnia_versors`, with the step count of eq. (5)
   (:func:`adnia_step_count`, :mod:`planners.move_inputs`); and
2. continuous-time moves conforming to :class:`planners.base.Trajectory` -
   :func:`linear_move`, :func:`arc_move` (three points in any plane), :func:`circle_move` (centre,
   axis, start point, sweep; weld seams round cylinders) and :func:`spherical_move` (the seed's
   spherical form) - whose ``at(t)`` gives position, velocity, acceleration, jerk, tool frame,
   angular velocity, path length and speed. They add what the seed leaves out: a smooth start and
   stop (:mod:`planners.profiles`; the ramps are taken out of the move's own length, as the seed
   suggests) and an orthonormal tool-frame law (:mod:`planners.rotations`). With
   ``ramp_time=0`` and ``L / (v dt)`` an integer, ``sample(dt)`` returns exactly the seed's
   ADNIA points of a line or arc. Their paths (the line, the arc, the seed's spherical curve, by
   arc length) are :mod:`planners.paths`'s, the trajectories and move builders
   :mod:`planners.cartesian`'s; this module re-exports them.

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

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.cartesian import (
    DEFAULT_MAX_ACCELERATION,
    CartesianState,
    CartesianTrajectory,
    arc_move,
    circle_move,
    linear_move,
    spherical_move,
)
from planners.errors import (
    CoincidentPointsError,
    CollinearPointsError,
    InvalidMoveError,
)
from planners.move_inputs import (
    _distinct,
    _point,
    _positive,
    _step_count,
    _steps,
    adnia_step_count,
)
from planners.paths import (
    CirclePath,
    LinePath,
    Path,
    SphericalPath,
    cartesian_to_spherical,
    spherical_to_cartesian,
)
from planners.rotations import SphericalVersorOrientation, spherical_versor

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
    "Path",
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
