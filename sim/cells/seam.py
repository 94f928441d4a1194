"""Weld seams: straight lines and circular arcs in 3D, with the torch posture along them.

A :class:`Seam` is a curve parameterised by arc length ``s`` in metres (``0 <= s <= length()``),
in the world frame. Its torch posture follows the AWS definitions (AWS A3.0):

* **work angle** ``w``: angle between the torch axis and the normal ``n`` of the reference
  (major) surface, measured in the plane perpendicular to the seam; 0 = torch along the normal,
  45 deg = the usual fillet posture.
* **travel angle** ``tau``: tilt of the torch axis in the plane of the torch axis and the seam;
  positive = *push* (forehand: the torch points ahead, in the travel direction), negative = drag.

With ``t(s)`` the travel direction, ``n(s)`` the reference normal made perpendicular to ``t``, and
``e(s) = side * (n x t) / |n x t|`` the in-surface direction towards which the torch body leans
(``side = +1``: to the left of the travel direction seen from the torch side of the surface,
``-1``: to the right), the torch axis pointing from the torch into the joint is::

    a(s) = cos(tau) * a_perp + sin(tau) * t,     a_perp = -(cos(w) n + sin(w) e)

**Desired tcp rotation** (:meth:`Seam.torch_rotation`), columns ``[x y z]`` of the tcp frame in
world. Which tcp axis is the torch axis depends on the robot family (``tool_axis``):

* ``fanuc6`` (LR Mate 200iC, seed 004): the approach vector ``a = z6`` is the torch axis:
  ``z = a``, ``x`` = travel direction made perpendicular to ``a``, ``y = z x x``. The roll about the
  torch axis is free for a 6-axis robot; this choice is a convention.
* ``5r`` (LR Mate 100iB, 5R welding robot; seed 000 eq. 5): the frame 6 **x axis** is the torch
  axis (it is the J5 axis: J5 rolls the torch about itself): ``x = a``. The roll is the one of
  ``q5 = 0``: ``y = k1 x rho`` with ``k1`` the J1 axis and ``rho`` the horizontal direction from
  the J1 axis to the seam point (seed 000 eq. 5: ``y6 = (-s1, c1, 0)`` at ``q5 = 0``), then
  ``z = x x y``. A 5-axis robot can only reach torch axes lying in the vertical plane through J1
  and the tool point: :meth:`Seam.plane_deviation_deg` says how far a posture is from that.

Arcs are given by three points (start, via, end) in travel order; ``normal`` is the arc plane's
unit normal, right-handed with the travel direction (counter-clockwise seen from its tip).
Polylines are two or more points in travel order (:meth:`Seam.segments` gives their straight
segments as line seams; welding one in a single pass with corner blending is the weld-programs
issue's).

**Stand-off** (``standoff_m``): the tool point of a torch is the wire tip at the tool's nominal
stick-out ``l0`` (the contact tip is ``l0`` behind it on the torch axis). A seam (a cell file's
``ctwd_mm`` or ``stickout_mm``) or a weld phase (a scenario's ``ctwd_mm``) may ask for a
contact-tip-to-work distance ``c`` other than ``l0``: the contact tip then stays ``c`` from the
seam point along the torch axis, so the tool point runs ``standoff_m = c - l0`` back along the
torch axis from the seam (:meth:`Seam.tcp_point`), ``p_tool = p_seam - standoff_m * a``. On a
polyline every segment takes the stand-off along its own torch axis; where the axis turns at a
corner, so does the stand-off (the tool point moves by ``standoff_m * (a_k - a_k+1)`` while the
wire tip stays on the seam): give :meth:`Seam.tcp_point` the torch axis the motion commands there.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import CellsimError

_EPS = 1e-9


def _cross3(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.cross(a, b)`` of two float 3-vectors, bit for bit (the same products and
    differences, in Python floats: no fused multiply-add either way), without ``np.cross``'s
    per-call set-up (a seam's tool-point path takes thousands)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _unit(v: ArrayLike, what: str) -> NDArray[np.float64]:
    v = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(v))
    if not np.isfinite(n) or n < _EPS:
        raise CellsimError(f"seam: {what} must be a non-zero finite vector, got {v.tolist()}")
    return v / n


@dataclass(frozen=True, eq=False)
class Seam:
    """A weld seam in the world frame (metres, degrees for the torch angles).

    Attributes:
        name: Seam name, unique in its cell.
        kind: ``"line"``, ``"arc"`` or ``"polyline"``.
        points: Line: (2, 3) start, end. Arc: (3, 3) start, via, end, in travel order.
            Polyline: (N, 3), N >= 2, in travel order.
        normal: Arc plane unit normal (3,), right-handed with the travel direction; None for
            lines (computed from the points when None is given for an arc).
        torch_work_angle_deg: Work angle ``w``, deg (module docstring).
        torch_travel_angle_deg: Travel angle ``tau``, deg, positive = push.
        surface_normal: Normal of the reference (major) surface, pointing to the torch side (3,).
        torch_side: ``+1`` / ``-1``: the torch body leans to the left / right of the travel
            direction (seen from the torch side of the reference surface).
        tool_axis: Column of the tcp rotation along the torch axis: 0 for the ``5r`` family
            (frame 6 x axis), 2 for ``fanuc6`` (a = z6).
        world_from_frame0: Pose of the robot's frame 0 in world (4, 4); used for the ``5r``
            roll convention (J1 axis = its z axis through its origin). Identity if None.
        description: One line: what joint this is.
        standoff_m: Distance the tool point keeps back from the seam along the torch axis, m
            (module docstring); 0 puts the tool point on the seam.
    """

    name: str
    kind: Literal["line", "arc", "polyline"]
    points: NDArray[np.float64]
    normal: NDArray[np.float64] | None
    torch_work_angle_deg: float
    torch_travel_angle_deg: float
    surface_normal: NDArray[np.float64] = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    torch_side: int = 1
    tool_axis: int = 2
    world_from_frame0: NDArray[np.float64] | None = None
    description: str = ""
    standoff_m: float = 0.0

    # ------------------------------------------------------------------ validation
    def __post_init__(self) -> None:
        set_ = object.__setattr__
        pts = np.array(self.points, dtype=float)
        if self.kind not in ("line", "arc", "polyline"):
            raise CellsimError(f"seam {self.name!r}: kind must be 'line', 'arc' or 'polyline', "
                               f"got {self.kind!r}")
        want = {"line": (2, 3), "arc": (3, 3)}.get(self.kind, (max(len(pts), 2), 3))
        if pts.shape != want or not np.all(np.isfinite(pts)):
            raise CellsimError(f"seam {self.name!r}: a {self.kind} needs finite points of shape "
                               f"{want}, got {pts.shape}")
        set_(self, "points", pts)
        set_(self, "surface_normal",
             _unit(self.surface_normal, f"seam {self.name!r} surface_normal"))
        if self.torch_side not in (1, -1):
            raise CellsimError(f"seam {self.name!r}: torch_side must be +1 or -1")
        if self.tool_axis not in (0, 2):
            raise CellsimError(f"seam {self.name!r}: tool_axis must be 0 (5r) or 2 (fanuc6)")
        T = np.eye(4) if self.world_from_frame0 is None else np.array(self.world_from_frame0, float)
        set_(self, "world_from_frame0", T)
        if not (np.isfinite(self.standoff_m) and abs(self.standoff_m) < 1.0):
            raise CellsimError(f"seam {self.name!r}: standoff_m must be a finite length under "
                               f"1 m, got {self.standoff_m!r}")
        if self.kind == "polyline":
            seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
            if np.any(seg < 1e-6):
                k = int(np.argmax(seg < 1e-6))
                raise CellsimError(f"seam {self.name!r}: points {k} and {k + 1} coincide")
            set_(self, "normal", None if self.normal is None else _unit(self.normal, "normal"))
            set_(self, "_cum", np.concatenate([[0.0], np.cumsum(seg)]))
            return
        if self.kind == "line":
            if np.linalg.norm(pts[1] - pts[0]) < 1e-6:
                raise CellsimError(f"seam {self.name!r}: start and end coincide")
            set_(self, "normal", None if self.normal is None else _unit(self.normal, "normal"))
            return
        p0, p1, p2 = pts
        n_pts = np.cross(p1 - p0, p2 - p1)
        if np.linalg.norm(n_pts) < 1e-9:
            raise CellsimError(f"seam {self.name!r}: arc points are collinear")
        n_pts = n_pts / np.linalg.norm(n_pts)
        n = n_pts if self.normal is None else _unit(self.normal, f"seam {self.name!r} normal")
        if float(n @ n_pts) < 1.0 - 1e-6:
            raise CellsimError(f"seam {self.name!r}: normal {np.round(n, 6).tolist()} is not the "
                               f"right-handed normal of the arc through its points "
                               f"{np.round(n_pts, 6).tolist()}")
        set_(self, "normal", n)
        # circumcentre in the plane of the three points
        a, b = p0 - p2, p1 - p2
        axb = np.cross(a, b)
        c = p2 + np.cross(np.dot(a, a) * b - np.dot(b, b) * a, axb) / (2.0 * np.dot(axb, axb))
        u = (p0 - c) / np.linalg.norm(p0 - c)
        v = np.cross(n, u)
        ang = lambda p: float(np.mod(np.arctan2((p - c) @ v, (p - c) @ u), 2 * np.pi))  # noqa: E731
        sweep = ang(p2)
        if sweep < 1e-9:
            sweep = 2 * np.pi
        if not 0.0 < ang(p1) < sweep:
            raise CellsimError(f"seam {self.name!r}: the via point is not between start and end")
        set_(self, "_center", c)
        set_(self, "_radius", float(np.linalg.norm(p0 - c)))
        set_(self, "_u", u)
        set_(self, "_v", v)
        set_(self, "_sweep", sweep)

    # ------------------------------------------------------------------ geometry
    @property
    def start(self) -> NDArray[np.float64]:
        """Start point, m, (3,)."""
        return self.points[0].copy()

    @property
    def end(self) -> NDArray[np.float64]:
        """End point, m, (3,)."""
        return self.points[-1].copy()

    @property
    def center(self) -> NDArray[np.float64] | None:
        """Arc centre, m, (3,); None for a line."""
        return None if self.kind == "line" else self._center.copy()  # type: ignore[attr-defined]

    @property
    def radius(self) -> float | None:
        """Arc radius, m; None for a line."""
        return None if self.kind == "line" else self._radius  # type: ignore[attr-defined]

    @property
    def sweep(self) -> float | None:
        """Arc sweep angle, rad, in (0, 2 pi]; None for a line."""
        return None if self.kind == "line" else self._sweep  # type: ignore[attr-defined]

    def length(self) -> float:
        """Seam length, m."""
        if self.kind == "polyline":
            return float(self._cum[-1])  # type: ignore[attr-defined]
        if self.kind == "line":
            return float(np.linalg.norm(self.points[1] - self.points[0]))
        return self._radius * self._sweep  # type: ignore[attr-defined]

    def _check_s(self, s: float) -> float:
        s = float(s)
        L = self.length()
        if not np.isfinite(s) or s < -1e-9 or s > L + 1e-9:
            raise CellsimError(f"seam {self.name!r}: arc length s={s:.6g} m outside [0, {L:.6g}]")
        return min(max(s, 0.0), L)

    def point(self, s: float) -> NDArray[np.float64]:
        """Point at arc length ``s`` (m), world, m, (3,)."""
        s = self._check_s(s)
        if self.kind == "polyline":
            k, u = self._segment(s)
            return self.points[k] + (self.points[k + 1] - self.points[k]) * u
        if self.kind == "line":
            p0, p1 = self.points
            return p0 + (p1 - p0) * (s / self.length())
        th = s / self._radius  # type: ignore[attr-defined]
        c, r, u, v = self._center, self._radius, self._u, self._v  # type: ignore[attr-defined]
        return c + r * (np.cos(th) * u + np.sin(th) * v)

    def tangent(self, s: float) -> NDArray[np.float64]:
        """Unit travel direction at arc length ``s`` (m), (3,)."""
        s = self._check_s(s)
        if self.kind == "polyline":
            k, _ = self._segment(s)
            d = self.points[k + 1] - self.points[k]
            return d / np.linalg.norm(d)
        if self.kind == "line":
            d = self.points[1] - self.points[0]
            return d / np.linalg.norm(d)
        th = s / self._radius  # type: ignore[attr-defined]
        return -np.sin(th) * self._u + np.cos(th) * self._v  # type: ignore[attr-defined]

    def _segment(self, s: float) -> tuple[int, float]:
        """Polyline segment index holding ``s`` and the fraction along it (a corner belongs to
        the segment it ends)."""
        cum = self._cum  # type: ignore[attr-defined]
        k = int(np.clip(np.searchsorted(cum, s, side="left") - 1, 0, len(cum) - 2))
        return k, (s - cum[k]) / (cum[k + 1] - cum[k])

    def segments(self) -> list[Seam]:
        """The straight segments of a polyline as line seams ``<name>/1``, ``<name>/2``, ...
        (same torch posture and stand-off); a line or arc gives itself."""
        if self.kind != "polyline":
            return [self]
        return [Seam(name=f"{self.name}/{k + 1}", kind="line",
                     points=self.points[k:k + 2].copy(), normal=None,
                     torch_work_angle_deg=self.torch_work_angle_deg,
                     torch_travel_angle_deg=self.torch_travel_angle_deg,
                     surface_normal=self.surface_normal, torch_side=self.torch_side,
                     tool_axis=self.tool_axis, world_from_frame0=self.world_from_frame0,
                     description=f"segment {k + 1} of {self.name}", standoff_m=self.standoff_m)
                for k in range(len(self.points) - 1)]

    def tcp_point(self, s: float, axis: ArrayLike | None = None) -> NDArray[np.float64]:
        """Where the tool point goes at ``s``: the seam point moved ``standoff_m`` back along
        the torch axis, world, m, (3,).

        ``axis``: the unit torch axis the motion commands at ``s`` where it is not the seam's
        own (a polyline's corner zone, where the torch turns from one segment's posture to the
        next); default :meth:`torch_axis`.
        """
        p = self.point(s)
        if self.standoff_m == 0.0:
            return p
        a = self.torch_axis(s) if axis is None else _unit(axis, f"seam {self.name!r} axis")
        return p - self.standoff_m * a

    def tcp_points(self) -> NDArray[np.float64]:
        """The tool point's control points (:meth:`tcp_point` at the seam's own points): a
        line's start and end, an arc's start, via and end (the stand-off path of an arc with
        a constant torch posture is the coaxial arc through them), (k, 3), m."""
        if self.standoff_m == 0.0:
            return self.points.copy()
        if self.kind == "arc":
            v = self.points[1] - self._center  # type: ignore[attr-defined]
            th = float(np.mod(np.arctan2(v @ self._v, v @ self._u), 2 * np.pi))  # type: ignore[attr-defined]
            ss = [0.0, th * self._radius, self.length()]  # type: ignore[attr-defined]
        elif self.kind == "line":
            ss = [0.0, self.length()]
        else:
            ss = list(self._cum)  # type: ignore[attr-defined]
        return np.array([self.tcp_point(x) for x in ss])

    def sample(self, n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``n >= 2`` equally spaced arc lengths (n,) and their points (n, 3), m."""
        s = np.linspace(0.0, self.length(), int(n))
        return s, np.array([self.point(x) for x in s])

    # ------------------------------------------------------------------ torch posture
    def torch_axis(self, s: float) -> NDArray[np.float64]:
        """Unit torch axis at ``s``, pointing from the torch into the joint, world, (3,)."""
        return self._torch_axis(s, self.tangent(s))

    def path_row(self, s: float) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                           NDArray[np.float64]]:
        """``(tcp_point(s), tangent(s), torch_axis(s))``, the same values, each computed once
        (the tool-point path of :mod:`sim.simulation.seam_measure` samples a seam by them)."""
        t = self.tangent(s)
        a = self._torch_axis(s, t)
        p = self.point(s)
        return (p if self.standoff_m == 0.0 else p - self.standoff_m * a), t, a

    def path_rows(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                        NDArray[np.float64],
                                                        NDArray[np.float64]]:
        """:meth:`path_row` at each arc length of ``s`` (m, (m,), within the seam), stacked:
        tool points, tangents and torch axes, (m, 3) each. An arc's rows are computed as
        arrays (the same operations element by element; each row's dot products and norm
        as :meth:`path_row` takes them), a line's or polyline's row by row."""
        s = np.asarray(s, dtype=float)
        if self.kind != "arc" or s.size == 0:
            rows = [self.path_row(float(x)) for x in s]
            return tuple(np.array(v).reshape(-1, 3) for v in zip(*rows, strict=True)) \
                if rows else (np.zeros((0, 3)),) * 3  # type: ignore[return-value]
        for x in (s.min(), s.max()):
            self._check_s(float(x))
        r, c, u, v = self._radius, self._center, self._u, self._v  # type: ignore[attr-defined]
        th = s / r
        sin, cos = np.sin(th)[:, None], np.cos(th)[:, None]
        t = -sin * u + cos * v
        sn = self.surface_normal
        n = sn - np.array([sn @ ti for ti in t])[:, None] * t
        norm = np.array([np.linalg.norm(ni) for ni in n])
        if np.any(norm < _EPS):
            k = int(np.argmax(norm < _EPS))
            self._torch_axis(float(s[k]), t[k])  # raises, naming where
        n = n / norm[:, None]
        e = self.torch_side * np.stack([n[:, 1] * t[:, 2] - n[:, 2] * t[:, 1],
                                        n[:, 2] * t[:, 0] - n[:, 0] * t[:, 2],
                                        n[:, 0] * t[:, 1] - n[:, 1] * t[:, 0]], axis=1)
        w = np.deg2rad(self.torch_work_angle_deg)
        tau = np.deg2rad(self.torch_travel_angle_deg)
        a = np.cos(tau) * -(np.cos(w) * n + np.sin(w) * e) + np.sin(tau) * t
        p = c + r * (cos * u + sin * v)
        return (p if self.standoff_m == 0.0 else p - self.standoff_m * a), t, a

    def _torch_axis(self, s: float, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """:meth:`torch_axis` at ``s`` given the tangent ``t`` there."""
        n = self.surface_normal - (self.surface_normal @ t) * t
        if np.linalg.norm(n) < _EPS:
            raise CellsimError(f"seam {self.name!r}: the surface normal runs along the seam at "
                               f"{s * 1e3:.1f} mm from its start (it must be across the seam)")
        n = n / np.linalg.norm(n)
        e = self.torch_side * _cross3(n, t)
        w = np.deg2rad(self.torch_work_angle_deg)
        tau = np.deg2rad(self.torch_travel_angle_deg)
        a_perp = -(np.cos(w) * n + np.sin(w) * e)
        return np.cos(tau) * a_perp + np.sin(tau) * t

    def weld_normal(self, s: float) -> NDArray[np.float64]:
        """The seam's local normal at ``s``: the torch axis at zero travel angle, reversed
        (``cos(w) n + sin(w) e``: from the joint out towards the torch, across the seam), world,
        unit (3,). Welding downhand (flat, 1F/1G) is this normal pointing up."""
        t = self.tangent(s)
        n = self.surface_normal - (self.surface_normal @ t) * t
        n = _unit(n, f"seam {self.name!r}: the surface normal along the seam;")
        e = self.torch_side * np.cross(n, t)
        w = np.deg2rad(self.torch_work_angle_deg)
        return np.cos(w) * n + np.sin(w) * e

    def torch_rotation(self, s: float) -> NDArray[np.float64]:
        """Desired tcp rotation at ``s`` in world, (3, 3); see the module docstring for the axes.

        For ``tool_axis == 2`` (fanuc6) ``R[:, 2]`` is the torch axis, for ``tool_axis == 0``
        (5r) ``R[:, 0]`` is.
        """
        a = self.torch_axis(s)
        if self.tool_axis == 2:
            t = self.tangent(s)
            x = t - (t @ a) * a
            if np.linalg.norm(x) < 1e-6:  # torch along the seam: any perpendicular will do
                x = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
            x = x / np.linalg.norm(x)
            return np.column_stack([x, np.cross(a, x), a])
        T = self.world_from_frame0
        k1, o1 = T[:3, 2], T[:3, 3]
        d = self.point(s) - o1
        rho = d - (d @ k1) * k1
        y = np.cross(k1, _unit(rho, f"seam {self.name!r}: point on the J1 axis;"))
        y = y - (y @ a) * a  # exact for torch axes in the J1 plane (the 5R can only do those)
        y = _unit(y, f"seam {self.name!r}: torch axis along the horizontal normal of the J1 plane;")
        return np.column_stack([a, y, np.cross(a, y)])

    def plane_deviation_deg(self, s: float) -> float:
        """Angle (deg) between the torch axis and the vertical plane through J1 and the point.

        0 for every posture a 5-axis robot (5r family) can take.
        """
        T = self.world_from_frame0
        k1, o1 = T[:3, 2], T[:3, 3]
        d = self.point(s) - o1
        rho = d - (d @ k1) * k1
        normal = np.cross(k1, _unit(rho, f"seam {self.name!r}: point on the J1 axis;"))
        return float(np.rad2deg(np.arcsin(np.clip(abs(self.torch_axis(s) @ normal), 0.0, 1.0))))

    def pose(self, s: float) -> NDArray[np.float64]:
        """Desired tcp pose at ``s`` in world (the stand-off included), (4, 4)."""
        T = np.eye(4)
        T[:3, :3] = self.torch_rotation(s)
        T[:3, 3] = self.tcp_point(s)
        return T

    def transformed(self, T: ArrayLike) -> Seam:
        """The same seam expressed in another frame: ``T`` maps world to that frame, (4, 4).

        Example: ``seam.transformed(np.linalg.inv(cell.world_from_frame0))`` is the seam in the
        robot's frame 0 (its ``world_from_frame0`` becomes ``T @ world_from_frame0``).
        """
        T = np.asarray(T, dtype=float)
        R, p = T[:3, :3], T[:3, 3]
        return Seam(name=self.name, kind=self.kind, points=self.points @ R.T + p,
                    normal=None if self.normal is None else R @ self.normal,
                    torch_work_angle_deg=self.torch_work_angle_deg,
                    torch_travel_angle_deg=self.torch_travel_angle_deg,
                    surface_normal=R @ self.surface_normal, torch_side=self.torch_side,
                    tool_axis=self.tool_axis, world_from_frame0=T @ self.world_from_frame0,
                    description=self.description, standoff_m=self.standoff_m)
