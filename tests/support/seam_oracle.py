"""An independent oracle for weld seams: the seam campaign's (tests/campaigns/test_seam_campaign.py)
judge of a weld, written from the cell file's own numbers with numpy, never from cellsim's seam
code (``sim.cells.seam`` is not imported here).

Geometry (docs/cell-format.md): an object's frame is ``Trans(pos_mm) Rz(a) Ry(b) Rx(c)`` for
``euler_zyx_deg = [a, b, c]``; the seam's points and its reference-surface normal are in that
frame. Torch angles (AWS A3.0, the definitions of the cell format): ``t`` the travel direction,
``n`` the reference normal made perpendicular to ``t``, ``e = +-(n x t)`` the lean direction
(``+`` left), ``w`` the work angle from the surface and ``tau`` the travel angle (push > 0)::

    a = cos(tau) a_perp + sin(tau) t,     a_perp = -(sin(w) n + cos(w) e)

is the torch axis from the torch into the joint. The tool point runs ``stickout - 15 mm`` (the
MIG torch's nominal stick-out) back along ``a`` from the seam. A sine weave moves the tool point
by ``A sin(2 pi f t + phi)`` across the path in the plane normal to the torch axis
(docs/scenario-format.md): along ``a x t``.

The torch's solids are the shipped MIG torch's cylinders as ``sim/cells/tools.py`` documents
them (radius, from-to along the flange axis, mm); the oracle places them along the recorded
torch axis behind the recorded tool point and measures their depth in the cell's solids (box,
cylinder, convex prism: signed distances written here) to say where a collision must and must
not be reported.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

#: The MIG torch's nominal wire stick-out, m (the tool point is the wire tip at it).
NOMINAL_STICKOUT_M = 0.015
#: The MIG torch's length from the flange face to the tool point, m.
TORCH_LENGTH_M = 0.145
#: The MIG torch as documented in sim/cells/tools.py: (name, radius, from, to along the flange
#: axis), m.
TORCH = (("adapter", 0.025, 0.000, 0.012), ("collision_sensor", 0.030, 0.012, 0.057),
         ("neck", 0.012, 0.057, 0.085), ("nozzle", 0.011, 0.085, 0.128),
         ("contact_tip", 0.004, 0.118, 0.130), ("wire", 0.0006, 0.130, 0.145))
#: The torch parts that may never touch the work (everything but the wire).
FORBIDDEN = tuple(name for name, *_ in TORCH if name != "wire")

#: Acceptance (issue 25): tool point to seam, m; torch angles, deg; progress speed, relative;
#: seam ends, m; weave amplitude and frequency, relative.
POS_TOL_M = 0.05e-3
ANGLE_TOL_DEG = 0.5
SPEED_TOL = 0.01
END_TOL_M = 0.05e-3
WEAVE_AMP_TOL = 0.02
WEAVE_FREQ_TOL = 0.01
#: A torch part is called clear of (or in) a solid when the oracle puts it this far outside
#: (inside) it: the sampling of the cylinders' surfaces (rings 2 mm apart of 16 points: a box
#: edge between two rings is at most 1 mm from one, a rim chord 0.2 mm inside the circle) stays
#: below it; the motion between two frames is added per frame (:func:`frame_steps`).
CLEAR_MARGIN_M = 1.5e-3
#: The wire is called within its allowed depth when the oracle puts it this much less deep.
WIRE_MARGIN_M = 0.05e-3
#: Half-width of the window over which progress speed is differenced, s (jitter of the nearest
#: point averages out; the ramps are left out by more than this).
SPEED_HALF_WINDOW_S = 0.1
#: The default start and stop ramp of a Cartesian phase (3 sampling periods of 0.1 s, at least
#: 0.3 s: docs/scenario-format.md), s.
DEFAULT_RAMP_S = 0.3


# ------------------------------------------------------------------------------ rotations
def rot_zyx(deg: tuple[float, float, float] | Array) -> Array:
    """``Rz(a) Ry(b) Rx(c)`` for Z-Y-X Euler angles in degrees (the file format's rotation)."""
    a, b, c = np.radians(np.asarray(deg, dtype=float))
    rz = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0],
                   [0.0, 0.0, 1.0]])
    ry = np.array([[math.cos(b), 0.0, math.sin(b)], [0.0, 1.0, 0.0],
                   [-math.sin(b), 0.0, math.cos(b)]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(c), -math.sin(c)],
                   [0.0, math.sin(c), math.cos(c)]])
    return rz @ ry @ rx


def euler_zyx(R: Array) -> tuple[float, float, float]:
    """Z-Y-X Euler angles (deg) of a rotation: the inverse of :func:`rot_zyx`."""
    b = -math.asin(max(-1.0, min(1.0, float(R[2, 0]))))
    a = math.atan2(float(R[1, 0]), float(R[0, 0]))
    c = math.atan2(float(R[2, 1]), float(R[2, 2]))
    return (math.degrees(a), math.degrees(b), math.degrees(c))


def unit(v: Array) -> Array:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# ------------------------------------------------------------------------------ solids
@dataclass(frozen=True)
class Solid:
    """A static object as its cell file places it, with a signed distance (m; negative inside).

    Attributes:
        name: Object name.
        shape: ``box`` (``dims`` full extents), ``cylinder`` (``dims`` radius, length, along z,
            centred), ``prism`` (``dims`` circumradius, number of sides, height: a regular
            prism along z, centred, a vertex on +x; written as an STL mesh) or ``floor``
            (the plane z = 0, world).
        pos: Position of the object's frame in world, m (3,).
        R: Rotation of the object's frame in world (3, 3).
        dims: Shape dimensions, m (the prism's side count as a number).
    """

    name: str
    shape: str
    pos: Array
    R: Array
    dims: tuple[float, ...]

    def sdf(self, p: Array) -> Array:
        """Signed distance of world points (..., 3) to the solid, m: exact inside; outside
        exact for the box, cylinder and floor, a lower bound for the prism (the largest of
        its face planes' distances)."""
        q = (np.asarray(p, dtype=float) - self.pos) @ self.R
        if self.shape == "floor":
            return q[..., 2]
        if self.shape == "box":
            d = np.abs(q) - 0.5 * np.asarray(self.dims)
            dm = np.maximum(d, 0.0)
            return np.sqrt(np.einsum("...i,...i->...", dm, dm)) + np.minimum(d.max(axis=-1), 0.0)
        if self.shape == "cylinder":
            r, length = self.dims
            d = np.stack([np.hypot(q[..., 0], q[..., 1]) - r, np.abs(q[..., 2]) - length / 2],
                         axis=-1)
            return (np.linalg.norm(np.maximum(d, 0.0), axis=-1)
                    + np.minimum(d.max(axis=-1), 0.0))
        rc, sides, height = self.dims
        k = int(sides)
        ang = (np.arange(k) + 0.5) * 2 * np.pi / k
        normals = np.stack([np.cos(ang), np.sin(ang)], axis=-1)
        planes = q[..., :2] @ normals.T - rc * math.cos(math.pi / k)
        return np.maximum(planes.max(axis=-1), np.abs(q[..., 2]) - height / 2)


def prism_mesh(rc: float, sides: int, height: float) -> tuple[Array, NDArray[np.int64]]:
    """Vertices (mm) and outward triangles of the regular prism of :class:`Solid` (``rc``,
    ``height`` in mm)."""
    ang = np.arange(sides) * 2 * np.pi / sides
    ring = np.stack([rc * np.cos(ang), rc * np.sin(ang)], axis=-1)
    v = np.vstack([np.column_stack([ring, np.full(sides, -height / 2)]),
                   np.column_stack([ring, np.full(sides, height / 2)])])
    faces = []
    for i in range(sides):
        j = (i + 1) % sides
        faces += [(i, j, sides + j), (i, sides + j, sides + i)]
    for i in range(1, sides - 1):
        faces += [(0, i + 1, i), (sides, sides + i, sides + i + 1)]
    return v, np.array(faces)


def write_stl(path: Path, v: Array, f: NDArray[np.int64], binary: bool) -> None:
    """A triangle mesh as a binary or ASCII STL file (normals from the vertex order)."""
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    if binary:
        out = [b"seam campaign prism".ljust(80, b" "), struct.pack("<I", len(f))]
        for k, tri in enumerate(f):
            out.append(struct.pack("<12fH", *n[k], *v[tri[0]], *v[tri[1]], *v[tri[2]], 0))
        path.write_bytes(b"".join(out))
        return
    lines = ["solid prism"]
    for k, tri in enumerate(f):
        lines += [f"  facet normal {n[k][0]:.9e} {n[k][1]:.9e} {n[k][2]:.9e}", "    outer loop"]
        lines += ["      vertex " + " ".join(repr(float(x)) for x in v[i]) for i in tri]
        lines += ["    endloop", "  endfacet"]
    path.write_text("\n".join([*lines, "endsolid prism", ""]))


# ------------------------------------------------------------------------------ the seam
@dataclass
class SeamGeom:
    """A seam in world (m), parameterised by arc length, with its commanded torch posture.

    Attributes:
        kind: ``line``, ``polyline``, ``arc`` or ``circle``.
        points: Line / polyline: the corners (k, 3). Arc: start, via, end. Circle: the start.
        normal: The reference surface's normal (3,), world, unit.
        work_deg, travel_deg: Commanded work and travel angles.
        side: +1 lean left, -1 lean right.
        standoff: Tool point back from the seam along the torch axis, m.
        blend: Corner zone half-width (arc length, m) at each polyline corner.
        center, axis: Circle: its centre and axis (right-handed with the travel).
    """

    kind: str
    points: Array
    normal: Array
    work_deg: float
    travel_deg: float
    side: int = 1
    standoff: float = 0.0
    blend: float = 0.0
    center: Array | None = None
    axis: Array | None = None
    _c: Array = field(init=False, repr=False)
    _r: float = field(init=False, repr=False)
    _u: Array = field(init=False, repr=False)
    _v: Array = field(init=False, repr=False)
    _sweep: float = field(init=False, repr=False)
    _cum: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, dtype=float)
        self.normal = unit(self.normal)
        if self.kind in ("line", "polyline"):
            seg = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
            self._cum = np.concatenate([[0.0], np.cumsum(seg)])
            return
        if self.kind == "circle":
            assert self.center is not None and self.axis is not None
            k = unit(self.axis)
            self._c = np.asarray(self.center, dtype=float)
            d = self.points[0] - self._c
            d = d - (d @ k) * k
            self._r = float(np.linalg.norm(d))
            self._u = d / self._r
            self._v = np.cross(k, self._u)
            self._sweep = 2 * np.pi
            return
        p0, p1, p2 = self.points  # circumcentre of three points, in their plane
        a, b = p0 - p2, p1 - p2
        axb = np.cross(a, b)
        self._c = p2 + np.cross((a @ a) * b - (b @ b) * a, axb) / (2.0 * (axb @ axb))
        k = unit(np.cross(p1 - p0, p2 - p1))
        self._r = float(np.linalg.norm(p0 - self._c))
        self._u = (p0 - self._c) / self._r
        self._v = np.cross(k, self._u)
        d = p2 - self._c
        self._sweep = float(np.mod(math.atan2(d @ self._v, d @ self._u), 2 * np.pi))

    @property
    def length(self) -> float:
        if self.kind in ("line", "polyline"):
            return float(self._cum[-1])
        return self._r * self._sweep

    @property
    def corners(self) -> Array:
        """Arc lengths of a polyline's inner corners, m."""
        return self._cum[1:-1] if self.kind == "polyline" else np.zeros(0)

    def in_corner_zone(self, s: Array, widen: float = 0.0) -> NDArray[np.bool_]:
        """Whether arc lengths are in a corner zone ``[s_c - blend, s_c + blend]`` (each side
        ``widen`` m more)."""
        s = np.asarray(s, dtype=float)
        out = np.zeros(s.shape, bool)
        for sc in self.corners:
            out |= np.abs(s - sc) <= self.blend + widen
        return out

    def point(self, s: Array) -> Array:
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        if self.kind in ("line", "polyline"):
            k = np.clip(np.searchsorted(self._cum, s, side="right") - 1, 0, len(self._cum) - 2)
            f = (s - self._cum[k]) / (self._cum[k + 1] - self._cum[k])
            return self.points[k] + (self.points[k + 1] - self.points[k]) * f[..., None]
        th = (s / self._r)[..., None]
        return self._c + self._r * (np.cos(th) * self._u + np.sin(th) * self._v)

    def tangent(self, s: Array) -> Array:
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        if self.kind in ("line", "polyline"):
            k = np.clip(np.searchsorted(self._cum, s, side="right") - 1, 0, len(self._cum) - 2)
            return unit(self.points[k + 1] - self.points[k])
        th = (s / self._r)[..., None]
        return -np.sin(th) * self._u + np.cos(th) * self._v

    def frame(self, s: Array) -> tuple[Array, Array, Array]:
        """Travel direction ``t``, normal ``n`` (perpendicular to ``t``) and lean ``e``."""
        t = self.tangent(s)
        n = unit(self.normal - (t @ self.normal)[..., None] * t)
        return t, n, self.side * np.cross(n, t)

    def torch_axis(self, s: Array) -> Array:
        t, n, e = self.frame(s)
        w, tau = math.radians(self.work_deg), math.radians(self.travel_deg)
        a_perp = -(math.sin(w) * n + math.cos(w) * e)
        return math.cos(tau) * a_perp + math.sin(tau) * t

    def tcp(self, s: Array) -> Array:
        return self.point(s) - self.standoff * self.torch_axis(s)

    def nearest(self, p: Array, spacing: float = 2e-4) -> Array:
        """Arc length of the nearest seam point for each point (N, 3): the seam sampled every
        ``spacing`` m, the projection on the two chords next to the nearest sample (exact on a
        line's or a leg's chords), and on an arc three Newton steps on
        ``(point(s) - p) . point'(s) = 0`` (derivatives by central differences)."""
        from scipy.spatial import cKDTree

        n = max(2, math.ceil(self.length / spacing) + 1)
        ss = np.linspace(0.0, self.length, n)
        q = self.point(ss)
        _, j = cKDTree(q).query(p)
        best = np.full(len(p), np.inf)
        out = ss[j].copy()
        for j0 in (np.maximum(j - 1, 0), np.minimum(j, n - 2)):
            a, b = q[j0], q[j0 + 1]
            ab = b - a
            f = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
            d = np.linalg.norm(a + ab * f[:, None] - p, axis=1)
            better = d < best
            best[better] = d[better]
            out[better] = (ss[j0] + (ss[j0 + 1] - ss[j0]) * f)[better]
        if self.kind in ("arc", "circle"):
            h = 1e-5
            for _ in range(3):
                q0, qm, qp = self.point(out), self.point(out - h), self.point(out + h)
                d1, d2 = (qp - qm) / (2 * h), (qp - 2 * q0 + qm) / (h * h)
                g = np.einsum("ij,ij->i", q0 - p, d1)
                dg = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", q0 - p, d2)
                out = out - g / dg
                out = (np.mod(out, self.length) if self.kind == "circle"
                       else np.clip(out, 0.0, self.length))
        return out

    def progress(self, p: Array, spacing: float = 2e-4) -> Array:
        """Arc length along the seam of the nearest seam point to each point of a weld in time
        order (N, 3). On a line or polyline the nearest point is searched from the previous
        one onwards only (no more than 0.5 mm back, twice the blend and 3 mm ahead: a corner
        cut by its blend makes the nearest point jump ahead by up to twice the blend), so that
        a weaving point near a sharp corner is not taken for a point of the other leg; on an
        arc :meth:`nearest`, made continuous round a circle (whose start is its end) from its
        start."""
        if self.kind in ("arc", "circle"):
            s = self.nearest(p)
            if self.kind == "arc":
                return s
            L = self.length
            s = np.unwrap(s * 2 * np.pi / L) * L / (2 * np.pi)
            return np.clip(s - L * np.round(s[0] / L), 0.0, L)
        n = max(2, math.ceil(self.length / spacing) + 1)
        ss = np.linspace(0.0, self.length, n)
        q = self.point(ss)
        back, ahead = 5e-4, 2 * self.blend + 3e-3
        out = np.zeros(len(p))
        last = 0.0
        for i, pi in enumerate(p):
            lo = int(np.searchsorted(ss, last - back))
            hi = min(n - 1, int(np.searchsorted(ss, last + ahead)))
            j = lo + int(np.argmin(np.einsum("ij,ij->i", q[lo:hi + 1] - pi, q[lo:hi + 1] - pi)))
            best, last = np.inf, ss[j]
            for j0 in (max(j - 1, 0), min(j, n - 2)):
                ab = q[j0 + 1] - q[j0]
                f = float(np.clip((pi - q[j0]) @ ab / (ab @ ab), 0.0, 1.0))
                d = float(np.linalg.norm(q[j0] + f * ab - pi))
                if d < best:
                    best, last = d, ss[j0] + (ss[j0 + 1] - ss[j0]) * f
            out[i] = last
        return out


def torch_rotation(a: Array, t: Array) -> Array:
    """A tcp rotation with the torch axis ``a`` as its z axis and x along the travel ``t``
    made perpendicular to ``a`` (the roll cellsim's 6-axis seams take)."""
    x = unit(t - (t @ a) * a)
    return np.column_stack([x, np.cross(a, x), a])


def torch_rotation_5axis(a: Array, p: Array, j1_axis: Array, j1_origin: Array) -> Array:
    """The tcp rotation of a 5-axis arm (the torch axis is its x axis, J5 rolls about it) at
    ``q5 = 0``: y along ``k1 x rho`` (``rho`` the horizontal direction from the J1 axis to the
    point ``p``), made perpendicular to ``a``."""
    d = p - j1_origin
    rho = d - (d @ j1_axis) * j1_axis
    y = np.cross(j1_axis, unit(rho))
    y = unit(y - (y @ a) * a)
    return np.column_stack([a, y, np.cross(a, y)])


# ------------------------------------------------------------------------------ the judge
@dataclass
class Frames:
    """Tool frames over time: times (N,), tool points (N, 3), torch axes (N, 3), world."""

    t: Array
    p: Array
    a: Array


@dataclass
class Weave:
    amplitude_m: float
    frequency_hz: float


@dataclass
class Verdict:
    """What the oracle measured on one weld, and which acceptance numbers it broke."""

    figures: dict[str, float] = field(default_factory=dict)
    failures: list[str] = field(default_factory=list)

    def fail(self, key: str, value: float, limit: float, unit: str, where: str = "") -> None:
        self.failures.append(f"{key} {value:.4g} {unit} > {limit:.4g} {unit}{where}")

    @property
    def ok(self) -> bool:
        return not self.failures


def fit_sine(t: Array, y: Array, band: tuple[float, float] | None = None
             ) -> tuple[float, float, Array]:
    """Amplitude, frequency and the sine ``A sin(2 pi f t + phi)`` of the fit ``y = A sin(2 pi f
    t + phi) + c`` (the offset ``c`` is not returned: it is a deviation, not weave) for samples
    on a regular grid with gaps (the corner zones left out): the FFT peak of the samples on
    the grid, the gaps zero (zero-padded 16 times), as the start, then least squares. ``band``
    (Hz): look for the peak there only (the gaps of a polyline's corner zones put spurious
    low-frequency peaks in the spectrum)."""
    from scipy.optimize import least_squares

    dt = float(np.median(np.diff(t)))
    k = np.rint((t - t[0]) / dt).astype(int)
    grid = np.zeros(k[-1] + 1)
    grid[k] = y - y.mean()
    n = 1 << math.ceil(math.log2(16 * len(grid)))
    spec = np.abs(np.fft.rfft(grid, n))
    freqs = np.fft.rfftfreq(n, dt)
    keep = freqs > 0 if band is None else (freqs >= band[0]) & (freqs <= band[1])
    f0 = float(freqs[int(np.argmax(np.where(keep, spec, -np.inf)))])
    tc = t - t.mean()
    basis = np.column_stack([np.sin(2 * np.pi * f0 * tc), np.cos(2 * np.pi * f0 * tc),
                             np.ones_like(tc)])
    c0 = np.linalg.lstsq(basis, y, rcond=None)[0]

    def model(x: Array) -> Array:
        return x[0] * np.sin(2 * np.pi * x[2] * tc) + x[1] * np.cos(2 * np.pi * x[2] * tc) + x[3]

    x = least_squares(lambda x: model(x) - y, [c0[0], c0[1], f0, c0[2]]).x
    return float(np.hypot(x[0], x[1])), float(x[2]), model(x) - x[3]


def judge_weld(seam: SeamGeom, fr: Frames, t0: float, t1: float, speed: float,
               weave: Weave | None, *, pos_tol: float = POS_TOL_M,
               angle_tol: float = ANGLE_TOL_DEG, speed_tol: float = SPEED_TOL,
               end_tol: float = END_TOL_M) -> Verdict:
    """Judge one weld phase ``[t0, t1]`` on tool frames (module docstring): tool point on the
    seam outside corner zones (net of the weave), torch axis and work / travel angles outside
    corner zones, inside them no swing of the torch out of its turn from one leg's axis to the
    next (``corner_swing_deg``), progress speed on the constant-speed part, both ends, weave
    amplitude and frequency."""
    v = Verdict()
    sel = (fr.t >= t0 - 1e-9) & (fr.t <= t1 + 1e-9)
    t, p, a = fr.t[sel], fr.p[sel], unit(fr.a[sel])
    L = seam.length
    # ends, at the phase's first and last instant
    e0 = float(np.linalg.norm(p[0] - seam.tcp(np.array(0.0))))
    e1 = float(np.linalg.norm(p[-1] - seam.tcp(np.array(L))))
    v.figures.update(start_mm=e0 * 1e3, end_mm=e1 * 1e3)
    if e0 > end_tol:
        v.fail("start", e0 * 1e3, end_tol * 1e3, "mm", " from the seam's start")
    if e1 > end_tol:
        v.fail("end", e1 * 1e3, end_tol * 1e3, "mm", " from the seam's end")
    # where along the seam: the point the torch aims at, the stand-off ahead of the tool point
    # along the recorded torch axis (on the seam when the tool point is where it belongs). A
    # weave's lateral offset turns with the torch in a corner zone: there the aim point's
    # nearest seam point runs up to the amplitude along the seam, so a weaving weld's zones
    # are that much wider each side
    s = seam.progress(p + seam.standoff * a)
    widen = 0.0 if weave is None else weave.amplitude_m
    free = ~seam.in_corner_zone(s, widen)
    tt, nn, ee = seam.frame(s)
    a_cmd = seam.torch_axis(s)
    d = p - seam.tcp(s)
    # torch axis and angles outside corner zones
    axis_err = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", a, a_cmd), -1.0, 1.0)))
    travel = np.degrees(np.arcsin(np.clip(np.einsum("ij,ij->i", a, tt), -1.0, 1.0)))
    ap = a - np.einsum("ij,ij->i", a, tt)[:, None] * tt
    work = np.degrees(np.arctan2(-np.einsum("ij,ij->i", ap, nn), -np.einsum("ij,ij->i", ap, ee)))
    for key, err in (("torch_axis", axis_err), ("work_angle", np.abs(work - seam.work_deg)),
                     ("travel_angle", np.abs(travel - seam.travel_deg))):
        if free.any():
            i = int(np.argmax(np.where(free, err, -1.0)))
            v.figures[f"{key}_err_deg"] = float(err[i])
            if err[i] > angle_tol:
                v.fail(f"{key} error", float(err[i]), angle_tol, "deg",
                       f" at t={t[i]:.3f} s, s={s[i] * 1e3:.2f} of {L * 1e3:.2f} mm")
    # inside a polyline's corner zones the torch turns from one leg's axis a1 to the next
    # one's a2: on any steady turn between them (a rotation about one axis included) neither
    # angle exceeds angle(a1, a2), so what does is a swing out of the turn
    for sc in seam.corners:
        zone = np.abs(s - sc) <= seam.blend + widen
        if not zone.any():
            continue
        a1, a2 = seam.torch_axis(np.array([sc - 0.5 * seam.blend, sc + 0.5 * seam.blend]))
        turn = math.degrees(math.acos(float(np.clip(a1 @ a2, -1.0, 1.0))))
        swing = np.degrees(np.arccos(np.clip(np.minimum(a[zone] @ a1, a[zone] @ a2),
                                             -1.0, 1.0))) - turn
        i = int(np.argmax(swing))
        worst = max(v.figures.get("corner_swing_deg", 0.0), float(swing[i]))
        v.figures["corner_swing_deg"] = worst
        if swing[i] > angle_tol:
            v.fail("corner swing", float(swing[i]), angle_tol, "deg",
                   f" out of the {turn:.2f} deg turn at t={t[zone][i]:.3f} s, corner at "
                   f"{sc * 1e3:.2f} mm")
    # the weave: lateral offset along a x t, fitted where it is fully faded in
    lateral = unit(np.cross(a_cmd, tt))
    y = np.einsum("ij,ij->i", d, lateral)
    check = free.copy()
    if weave is not None:
        fade = max(DEFAULT_RAMP_S, 0.5 / weave.frequency_hz) + 0.1
        body = (t > t0 + fade) & (t < t1 - fade)
        check &= body
        amp, freq, fit = fit_sine(t[check], y[check],  # the weave: its centre is the seam's
                                  band=(0.5 * weave.frequency_hz, 2.0 * weave.frequency_hz))
        v.figures.update(weave_amplitude_mm=amp * 1e3, weave_frequency_hz=freq)
        ea, ef = abs(amp / weave.amplitude_m - 1), abs(freq / weave.frequency_hz - 1)
        if ea > WEAVE_AMP_TOL:
            v.fail("weave amplitude error", ea * 100, WEAVE_AMP_TOL * 100, "%",
                   f" ({amp * 1e3:.4f} mm for {weave.amplitude_m * 1e3:.4f})")
        if ef > WEAVE_FREQ_TOL:
            v.fail("weave frequency error", ef * 100, WEAVE_FREQ_TOL * 100, "%",
                   f" ({freq:.4f} Hz for {weave.frequency_hz:.4f})")
        d = d.copy()
        d[check] -= fit[:, None] * lateral[check]
    dev = np.linalg.norm(d, axis=1)
    if check.any():
        i = int(np.argmax(np.where(check, dev, -1.0)))
        v.figures["path_dev_mm"] = float(dev[i] * 1e3)
        if dev[i] > pos_tol:
            v.fail("path deviation", float(dev[i] * 1e3), pos_tol * 1e3, "mm",
                   f" at t={t[i]:.3f} s, s={s[i] * 1e3:.2f} of {L * 1e3:.2f} mm")
    # progress speed, differenced over +-SPEED_HALF_WINDOW_S, away from the ramps and corners
    h = SPEED_HALF_WINDOW_S
    ramp = min(DEFAULT_RAMP_S, 0.5 * (t1 - t0))
    if weave is not None:  # the weave fades in and out over the ramps, at least half a cycle
        ramp = max(ramp, 0.5 / weave.frequency_hz)
    ramp += h + 0.02
    mid = (t > t0 + ramp) & (t < t1 - ramp) & free
    if mid.any():
        tm = t[mid]
        ds = np.interp(tm + h, t, s) - np.interp(tm - h, t, s)
        zone = seam.in_corner_zone(np.interp(tm + h, t, s), widen) | seam.in_corner_zone(
            np.interp(tm - h, t, s), widen)
        rate = ds[~zone] / (2 * h)
        if rate.size:
            err = np.abs(rate / speed - 1.0)
            i = int(np.argmax(err))
            v.figures["speed_err_pct"] = float(err[i] * 100)
            if err[i] > speed_tol:
                v.fail("progress speed error", float(err[i] * 100), speed_tol * 100, "%",
                       f" ({rate[i] * 1e3:.4f} mm/s for {speed * 1e3:.4f} at "
                       f"t={tm[~zone][i]:.3f} s)")
    return v


# ------------------------------------------------------------------------------ collisions
def _torch_template(step: float = 2e-3, around: int = 16) -> dict[str, Array]:
    """Points on each torch cylinder's surface (rings every ``step`` m, ``around`` points each,
    and both end discs), in a frame with the tool point at the origin and the torch axis along
    +z: (k, 3) per part."""
    out = {}
    phi = np.arange(around) * 2 * np.pi / around
    for name, r, z0, z1 in TORCH:
        back0, back1 = TORCH_LENGTH_M - z1, TORCH_LENGTH_M - z0  # behind the tool point
        rings = np.linspace(back0, back1, max(2, math.ceil((back1 - back0) / step) + 1))
        pts = [np.column_stack([r * np.cos(phi), r * np.sin(phi), np.full(around, -u)])
               for u in rings]
        for u in (back0, back1):
            for f in (0.0, 1 / 3, 2 / 3):
                pts.append(np.column_stack([f * r * np.cos(phi), f * r * np.sin(phi),
                                            np.full(around, -u)]))
        out[name] = np.vstack(pts)
    return out


TORCH_POINTS = _torch_template()
#: Frames where a part's axis keeps it farther than this from a solid are not sampled in
#: detail: their depth is the bound from the axis (:func:`torch_depths`), m.
COARSE_CLEAR_M = 3e-3


def torch_depths(fr: Frames, solids: list[Solid]) -> dict[tuple[str, str], Array]:
    """Per (torch part, solid): the part's largest depth in the solid at each frame, m (N,);
    negative: its clearance. Exact to the sampling of the part's surface where the part is
    within :data:`COARSE_CLEAR_M` of the solid; farther, the clearance is the lower bound
    from points on its axis 2 mm apart (every point of the cylinder is within
    ``hypot(r, 1 mm)`` of one, and a signed distance changes no faster than the point)."""
    a = unit(fr.a)
    helper = np.where(np.abs(a[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    x = unit(np.cross(helper, a))
    y = np.cross(a, x)

    def place(pts: Array, sel: NDArray[np.bool_]) -> Array:
        return (fr.p[sel, None, :] + pts[None, :, 0:1] * x[sel, None, :]
                + pts[None, :, 1:2] * y[sel, None, :] + pts[None, :, 2:3] * a[sel, None, :])

    out = {}
    everywhere = np.ones(len(fr.t), bool)
    for name, r, z0, z1 in TORCH:
        back0, back1 = TORCH_LENGTH_M - z1, TORCH_LENGTH_M - z0
        n = max(2, math.ceil((back1 - back0) / 2e-3) + 1)
        axis = np.column_stack([np.zeros((n, 2)), -np.linspace(back0, back1, n)])
        slack = math.hypot(r, 0.5 * (back1 - back0) / (n - 1))
        for sd in solids:
            depth = slack - sd.sdf(place(axis, everywhere)).min(axis=1)
            close = depth > -COARSE_CLEAR_M
            if close.any():
                depth[close] = -sd.sdf(place(TORCH_POINTS[name], close)).min(axis=1)
            out[(name, sd.name)] = depth
    return out


def frame_steps(fr: Frames) -> Array:
    """How much deeper a torch point can be between a frame and its neighbours than at the
    frames, m, (N,): half the larger step to a neighbour (the tool point's step plus the
    torch's length times the axis's turn; signed distances change no faster than the point
    moves)."""
    dp = np.linalg.norm(np.diff(fr.p, axis=0), axis=1)
    da = np.linalg.norm(np.diff(unit(fr.a), axis=0), axis=1)
    step = np.concatenate([[0.0], dp + 1.05 * TORCH_LENGTH_M * da, [0.0]])
    return 0.5 * np.maximum(step[:-1], step[1:])
