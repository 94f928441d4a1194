"""Measuring a weld seam from the recorded tool frames and the seam's own geometry, never
from the planner's trajectory: the tool point's path along the seam, the progress along it
and its speed, the torch's work and travel angles, the deviation from the seam and the weave
actually woven (:func:`measure_seam`, :class:`SeamMeasurement`).

Owns the geometry of a measurement along a seam; which phases are measured and how the
figures enter the run's summary is :mod:`sim.simulation.metrics`'.
May import: planners and :mod:`sim.core`.
"""

from __future__ import annotations

import dataclasses
import struct
from collections import OrderedDict
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from planners.weave import measure_weave
from sim.core.intervals import true_runs

#: Largest gap between the chords of a curved tool-point path (an arc) and the path itself,
#: m: the arc is sampled every ``sqrt(8 R CURVE_SAGITTA)`` (0.2 mm at R = 0.5 m).
CURVE_SAGITTA = 1e-8

#: How many seams' tool-point paths (:meth:`ToolPointPath.of`) and how many nearest-point
#: queries (:meth:`ToolPointPath.nearest`) this process keeps, most recent first: the variants
#: of a sweep's plan measure the same seams, and the same reference tool points, again.
PATH_CACHE_SIZE = 16
NEAREST_CACHE_SIZE = 8
_PATHS: OrderedDict[Hashable, ToolPointPath] = OrderedDict()
_NEAREST: OrderedDict[Hashable, dict[str, NDArray[np.float64]]] = OrderedDict()


def _value_key(v: Any) -> Hashable:
    """An exact key of a value: arrays and floats by their bits (0.0 and -0.0 differ, a NaN
    equals itself), anything else by type and ``repr``."""
    if isinstance(v, np.ndarray):
        return ("a", v.dtype.str, v.shape, np.ascontiguousarray(v).tobytes())
    if isinstance(v, float | np.floating):
        return ("f", struct.pack("<d", float(v)))
    if isinstance(v, list | tuple):
        return (type(v).__name__,) + tuple(_value_key(x) for x in v)
    return (type(v).__name__, repr(v))


def seam_key(seam: Any) -> Hashable:
    """The exact key of a seam's geometry and torch posture: every field of the dataclass by
    its value (:func:`_value_key`); what a :class:`ToolPointPath` is made of."""
    return (type(seam).__qualname__,) + tuple(
        (f.name, _value_key(getattr(seam, f.name))) for f in dataclasses.fields(seam))


def _remember(cache: OrderedDict[Hashable, Any], key: Hashable, value: Any, size: int) -> None:
    cache[key] = value
    cache.move_to_end(key)
    while len(cache) > size:
        cache.popitem(last=False)


def clear_caches() -> None:
    """Forget the kept tool-point paths and nearest-point queries."""
    _PATHS.clear()
    _NEAREST.clear()


def nearest_on_polyline(p: NDArray[np.float64], pts: NDArray[np.float64], k: int = 8
                         ) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]:
    """Nearest points of world points ``p`` (N, 3) on the polyline through ``pts`` (M, 3):
    the chord (index of its first vertex, (N,)), the fraction along it (N,) and the distance,
    m (N,). The chords on either side of the ``k`` nearest vertices are tried (a point inside
    a corner is near both legs), in the order of the vertices' nearness, the chord before a
    vertex first; the first chord at the least distance is the answer (a NaN distance is
    never the least; a point with none below infinity gets chord 0 at 0 and distance inf).

    Each chord is measured once per point: a point's ``2 k`` tries on a finely sampled path
    fall in a run of ``k + 1`` chords, measured together (:func:`_nearest_in_runs`); a point
    whose tries are spread wider, or whose least distance two chords share, tries them one by
    one in order (:func:`_nearest_tries`). Both give the bits of trying every chord in order
    (``tests/simulation/test_seam_nearest_runs.py``)."""
    k = min(k, len(pts))
    _, idx = cKDTree(pts).query(p, k=k)
    idx = np.asarray(idx).reshape(len(p), k)
    # tries[q]: the q-th chord each point tries (2 k, N)
    tries = np.clip(idx.T[:, None, :] + np.array([-1, 0])[None, :, None], 0,
                    len(pts) - 2).reshape(2 * k, len(p))
    best_i = np.zeros(len(p), dtype=np.intp)
    best_u = np.zeros(len(p))
    best_d = np.full(len(p), np.inf)
    if len(p) == 0:
        return best_i, best_u, best_d
    first = np.minimum.reduce(tries, axis=0)
    span = np.maximum.reduce(tries, axis=0) - first
    in_run = span < min(2 * k, 62)  # the run's chords as the bits of an int64
    rows: slice | NDArray[np.intp] = slice(None) if in_run.all() else np.flatnonzero(in_run)
    if in_run.any():
        i, u, d, exact = _nearest_in_runs(p[rows], pts, tries[:, rows], first[rows],
                                          int(span[rows].max()) + 1)
        best_i[rows], best_u[rows], best_d[rows] = i, u, d
        in_run[np.flatnonzero(in_run)[~exact]] = False
    rest = np.flatnonzero(~in_run)
    if len(rest):
        best_i[rest], best_u[rest], best_d[rest] = _nearest_tries(p[rest], pts, tries[:, rest])
    return best_i, best_u, best_d


def _chord_distance(p: NDArray[np.float64], a: NDArray[np.float64], ab: NDArray[np.float64],
                    den: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The fraction along chords ``a + u ab`` nearest to ``p`` and the distance, row by row
    (``den``: ``max(ab . ab, 1e-30)``)."""
    u = np.clip(np.einsum("ij,ij->i", p - a, ab) / den, 0.0, 1.0)
    return u, np.linalg.norm(p - (a + u[:, None] * ab), axis=1)


def _nearest_in_runs(p: NDArray[np.float64], pts: NDArray[np.float64], tries: NDArray[np.intp],
                     first: NDArray[np.intp], width: int
                     ) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64],
                                NDArray[np.bool_]]:
    """:func:`nearest_on_polyline` for points whose tries (2 k, n) lie in a run of ``width``
    chords from ``first``: each chord of the run that is tried measured once. Returns the
    chord, fraction and distance, and whether the answer is exact: one chord at the least
    distance, below infinity (elsewhere the order of the tries decides:
    :func:`_nearest_tries`)."""
    n = len(p)
    tried = np.bitwise_or.reduce(np.left_shift(1, tries - first), axis=0)
    ab_all = pts[1:] - pts[:-1]
    den_all = np.maximum(np.einsum("ij,ij->i", ab_all, ab_all), 1e-30)
    last = len(pts) - 2
    dist = np.empty((width, n))
    frac = np.empty((width, n))
    for w in range(width):
        c = np.minimum(first + w, last)  # beyond the path: not tried
        frac[w], d = _chord_distance(p, np.take(pts, c, axis=0), np.take(ab_all, c, axis=0),
                                     np.take(den_all, c))
        dist[w] = np.where(((tried >> w) & 1).astype(bool) & ~np.isnan(d), d, np.inf)
    least = np.minimum.reduce(dist, axis=0)
    pick = np.zeros(n, dtype=np.intp)
    count = np.zeros(n, dtype=np.intp)
    for w in range(width - 1, -1, -1):  # the lowest chord at the least distance
        hit = dist[w] == least
        count += hit
        pick[hit] = w
    exact = (count == 1) & (least < np.inf)
    return first + pick, frac[pick, np.arange(n)], least, exact


def _nearest_tries(p: NDArray[np.float64], pts: NDArray[np.float64], tries: NDArray[np.intp]
                   ) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]:
    """:func:`nearest_on_polyline` trying each point's chords (``tries``, 2 k, n) one by one,
    in order."""
    best_d = np.full(len(p), np.inf)
    best_i = np.zeros(len(p), dtype=np.intp)
    best_u = np.zeros(len(p))
    for i0 in tries:
        a, ab = pts[i0], pts[i0 + 1] - pts[i0]
        u, d = _chord_distance(p, a, ab, np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-30))
        better = d < best_d
        best_d = np.where(better, d, best_d)
        best_i = np.where(better, i0, best_i)
        best_u = np.where(better, u, best_u)
    return best_i, best_u, best_d


@dataclass(frozen=True, eq=False)
class ToolPointPath:
    """A seam's tool-point path (:meth:`sim.cells.seam.Seam.tcp_point`) as a polyline, with the
    seam's frame at its vertices (world, m).

    A line or a polyline's segment is exact from its two ends (the torch axis is constant along
    it); an arc is sampled finely enough that its chords stay within :data:`CURVE_SAGITTA` of
    it. At a polyline corner each leg has its own vertex (with a stand-off their tool points
    differ); both keep the corner's ``s``.

    Attributes:
        s: Seam arc length of each vertex, m (M,).
        point: Tool point (M, 3). tangent: Travel direction (M, 3). axis: Commanded torch axis
            (M, 3).
        closed: The path ends where it starts (a full circle).
    """

    s: NDArray[np.float64]
    point: NDArray[np.float64]
    tangent: NDArray[np.float64]
    axis: NDArray[np.float64]
    closed: bool
    key: Hashable = None

    @classmethod
    def of(cls, seam: Any) -> ToolPointPath:
        """The seam's tool-point path; kept per process by the seam's value
        (:func:`seam_key`: the same seam again gives the same path, bit for bit)."""
        key = seam_key(seam)
        path = _PATHS.get(key)
        if path is None:
            path = cls._make(seam, key)
            _remember(_PATHS, key, path, PATH_CACHE_SIZE)
        else:
            _PATHS.move_to_end(key)
        return path

    @classmethod
    def _make(cls, seam: Any, key: Hashable = None) -> ToolPointPath:
        s_all, rows = [], []
        s0 = 0.0
        for seg in seam.segments():
            L = float(seg.length())
            n = 2
            if seg.kind != "line":
                h = min(1e-3, float(np.sqrt(8.0 * float(seg.radius) * CURVE_SAGITTA)))
                n = max(3, int(np.ceil(L / h)) + 1)
            ss = np.linspace(0.0, L, n)
            s_all.append(s0 + ss)
            rows.append(seg.path_rows(ss))
            s0 += L
        point, tangent, axis = (np.concatenate(v) for v in zip(*rows, strict=True))
        s_arr = np.concatenate(s_all)
        for v in (s_arr, point, tangent, axis):  # shared by every caller of a kept path
            v.setflags(write=False)
        return cls(s_arr, point, tangent, axis,
                   bool(np.linalg.norm(point[0] - point[-1]) < 1e-9), key)

    @property
    def length(self) -> float:
        """The seam's length, m."""
        return float(self.s[-1])

    def nearest(self, p: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        """For points ``p`` (N, 3, in time order): the nearest seam parameter ``s`` (m), and
        there the tool point, travel direction and commanded torch axis (interpolated along
        the chord; the directions made unit) and the distance ``dist`` (m). On a closed path
        the points are followed round: the first near 0, the next ones continuing.

        A path made by :meth:`of` keeps its latest answers per process, by the points' exact
        values (the reference's tool points are the same for every variant of a plan); each
        call gets its own arrays."""
        p = np.asarray(p, dtype=float)
        if self.key is None:
            return self._nearest(p)
        key = (self.key, _value_key(p))
        got = _NEAREST.get(key)
        if got is None:
            got = self._nearest(p)
            _remember(_NEAREST, key, {k: v.copy() for k, v in got.items()}, NEAREST_CACHE_SIZE)
            return got
        _NEAREST.move_to_end(key)
        return {k: v.copy() for k, v in got.items()}

    def _nearest(self, p: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        i0, u, dist = nearest_on_polyline(p, self.point)
        s = self.s[i0] + u * (self.s[i0 + 1] - self.s[i0])
        if self.closed and len(s):
            s = np.unwrap(s, period=self.length)
            s = s - self.length * np.floor(s[0] / self.length + 0.5)
        out = {"s": np.clip(s, 0.0, self.length), "dist": dist}
        for key in ("point", "tangent", "axis"):
            v = getattr(self, key)
            out[key] = v[i0] + u[:, None] * (v[i0 + 1] - v[i0])
        for key in ("tangent", "axis"):
            out[key] /= np.linalg.norm(out[key], axis=1, keepdims=True)
        return out


def seam_progress(seam: Any, p: NDArray[np.float64]) -> NDArray[np.float64]:
    """Nearest seam parameter ``s*`` (m, 0..length) of each point of ``p`` (N, 3, in time
    order) on the seam's tool-point path (:class:`ToolPointPath`)."""
    return ToolPointPath.of(seam).nearest(p)["s"]


def in_zones(s: NDArray[np.float64], zones: Sequence[tuple[float, float]]) -> NDArray[np.bool_]:
    """Which seam parameters ``s`` lie in one of the arc-length intervals ``zones``."""
    inside = np.zeros(np.shape(s), dtype=bool)
    for a, b in zones:
        inside |= (s >= a) & (s <= b)
    return inside


def angle_deg(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Angle between unit vectors, row by row, deg (accurate near 0)."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v), axis=1),
                                 np.einsum("ij,ij->i", u, v)))


def corner_torch_excess(a: NDArray[np.float64], s: NDArray[np.float64], seam: Any,
                        zones: Sequence[tuple[float, float]]) -> float | None:
    """:attr:`SeamMeasurement.corner_torch_excess_deg` of torch axes ``a`` (N, 3, unit) at seam
    parameters ``s`` (N,), m: per corner zone ``(s0, s1)``, the legs' commanded axes at its
    ends; None when no sample lies in a zone."""
    worst: float | None = None
    L = float(seam.length())
    for z0, z1 in zones:
        inside = (s >= z0) & (s <= z1)
        if not np.any(inside):
            continue
        a1 = seam.torch_axis(min(max(float(z0), 0.0), L))[None, :]
        a2 = seam.torch_axis(min(max(float(z1), 0.0), L))[None, :]
        turn = float(angle_deg(a1, a2)[0])
        swing = np.maximum(angle_deg(a[inside], a1), angle_deg(a[inside], a2)) - turn
        worst = max(0.0 if worst is None else worst, float(np.max(swing)))
    return None if worst is None else max(worst, 0.0)


def progress_speed(t: NDArray[np.float64], s: NDArray[np.float64], keep: NDArray[np.bool_],
                   period: float | None = None) -> tuple[float, NDArray[np.float64]]:
    """Rate of progress ``ds/dt`` (m/s) over the samples ``keep``: the progress over the time
    of each run of kept samples, summed (a stretch left out, a corner, counts neither its
    progress nor its time). With ``period`` (a weave's, s) each run is cut to whole periods,
    so that a weave's motion along the seam averages out. Returns the mean speed and the
    speeds of the pieces (each period, or each sample interval without a period)."""
    ds, dt, pieces = 0.0, 0.0, []
    for i0, i1 in true_runs(keep):
        tt, ss = t[i0:i1], s[i0:i1]
        if len(tt) < 2:
            continue
        if period is not None:
            cycles = int(np.floor((tt[-1] - tt[0]) / period + 1e-9))
            if cycles < 1:
                continue
            ends = np.searchsorted(tt, tt[0] + period * np.arange(cycles + 1) - 1e-9)
            ends = np.minimum(ends, len(tt) - 1)
            tt, ss = tt[ends], ss[ends]
        ds += float(ss[-1] - ss[0])
        dt += float(tt[-1] - tt[0])
        pieces.append(np.diff(ss) / np.maximum(np.diff(tt), 1e-12))
    if dt <= 0.0:
        return float("nan"), np.zeros(0)
    return ds / dt, np.concatenate(pieces)


@dataclass(frozen=True, eq=False)
class SeamMeasurement:
    """What :func:`measure_seam` measured of one phase along a seam (SI units, degrees).

    Attributes:
        s: Nearest seam parameter of each sample's tool point, m (N,).
        in_corner: Samples whose ``s`` lies in a corner zone (N,).
        axis_error_deg: Angle of the torch axis from the seam's commanded axis, deg (N,).
        work_angle_deg, travel_angle_deg: The measured work angle (from the reference normal,
            as :class:`sim.cells.seam.Seam` holds it) and travel angle, deg (N,).
        deviation: Distance of the tool point, the programmed weave offset taken out, from the
            seam's tool point nearest to it, m (N,).
        lateral: Offset of the tool point from the seam's tool point at ``s`` in the weave's
            lateral direction (``travel x torch axis``, in the plane normal to the commanded
            torch axis), m (N,).
        travel_speed: Progress ``ds/dt`` over the constant-speed part outside the corner
            zones, m/s; ``travel_speed_cv`` the coefficient of variation of its pieces.
        torch_angle_error_deg, work_angle_error_deg, travel_angle_error_deg: Largest torch
            axis error and largest work and travel angle errors (absolute), outside the corner
            zones, deg; ``t_worst_angle`` the time of the largest axis error, s.
        max_deviation: Largest ``deviation`` outside the corner zones, m; ``corner_deviation``
            inside them (None without corner samples).
        corner_torch_excess_deg: Inside the corner zones, how far the torch swings out of its
            turn from one leg's commanded axis ``a1`` to the next one's ``a2``: the largest
            ``max(angle(a, a1), angle(a, a2)) - angle(a1, a2)`` (0 for any turn that moves the
            axis steadily from ``a1`` to ``a2``, a rotation about one axis included; a torch
            that swings off through the corner and back shows its swing), deg; None without
            corner samples.
        start_error, end_error: Distance of the first and last sample's tool point from the
            seam's first and last tool points, m.
        weave: With a weave: ``measure_weave``'s ``amplitude_m``, ``frequency_hz`` and
            ``centre_m`` of ``lateral`` over the weave window, outside the corner zones.
    """

    s: NDArray[np.float64]
    in_corner: NDArray[np.bool_]
    axis_error_deg: NDArray[np.float64]
    work_angle_deg: NDArray[np.float64]
    travel_angle_deg: NDArray[np.float64]
    deviation: NDArray[np.float64]
    lateral: NDArray[np.float64]
    travel_speed: float
    travel_speed_cv: float
    torch_angle_error_deg: float
    work_angle_error_deg: float
    travel_angle_error_deg: float
    t_worst_angle: float | None
    max_deviation: float
    corner_deviation: float | None
    corner_torch_excess_deg: float | None
    start_error: float
    end_error: float
    weave: dict[str, float] | None


def _weave_figures(t: NDArray[np.float64], lateral: NDArray[np.float64],
                   keep: NDArray[np.bool_], period: float) -> dict[str, float] | None:
    """``measure_weave`` on each run of kept samples two periods long or more, the figures
    weighted by the runs' durations (a corner left out is a gap in the signal)."""
    figs, weights = [], []
    for i0, i1 in true_runs(keep):
        if t[i1 - 1] - t[i0] >= 2.0 * period and i1 - i0 >= 16:
            figs.append(measure_weave(t[i0:i1], lateral[i0:i1]))
            weights.append(t[i1 - 1] - t[i0])
    if not figs:
        return None
    w = np.asarray(weights) / np.sum(weights)
    return {key: float(sum(wi * f[key] for wi, f in zip(w, figs, strict=True)))
            for key in ("amplitude_m", "frequency_hz", "centre_m")}


def measure_seam(t: NDArray[np.float64], pos: NDArray[np.float64], rot: NDArray[np.float64],
                 seam: Any, *, axis_column: int = 2,
                 corner_zones: Sequence[tuple[float, float]] = (),
                 cruise: tuple[float, float] | None = None,
                 weave_offset: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
                 weave_period: float | None = None,
                 weave_window: tuple[float, float] | None = None) -> SeamMeasurement:
    """Measure a recorded pass along a seam from the tool frames alone.

    Args:
        t: Sample times, s (N,), increasing.
        pos: Tool point, world, m (N, 3).
        rot: Tool frame rotations, world (N, 3, 3); column ``axis_column`` is the torch axis
            (2 for the 6-axis arms, 0 for the 5-axis family).
        seam: The :class:`sim.cells.seam.Seam` (world frame) the pass follows: its tool-point
            path, tangent, reference normal, torch side, work and travel angles are the
            reference.
        corner_zones: Arc-length intervals ``(s0, s1)`` of the seam, m, where the torch turns
            at a corner: left out of the angle, deviation and speed figures.
        cruise: The constant-speed part, ``(t0, t1)`` s; the whole pass if None.
        weave_offset: The weave's programmed displacement of the tool point at times ``t``,
            world, m (N, 3); the deviation is taken net of it.
        weave_period: The weave's period, s: the travel speed is averaged over whole cycles and
            the weave's amplitude and frequency measured.
        weave_window: The weave's full-amplitude part, ``(t0, t1)`` s (default: ``cruise``).

    The nearest seam parameter ``s*`` of each tool point on the seam's tool-point path
    (:class:`ToolPointPath`) gives the seam's local frame there (travel direction ``t``,
    reference normal ``n`` made
    perpendicular to it, lean direction ``e = side n x t``); with the recorded torch axis
    ``a`` the travel angle is ``asin(a . t)`` and the work angle ``atan2(-a . e, -a . n)``
    (:mod:`sim.cells.seam`). The travel speed is ``ds*/dt`` (:func:`progress_speed`), so a
    weave's lateral motion does not count.
    """
    t = np.asarray(t, dtype=float)
    pos = np.asarray(pos, dtype=float)
    a = np.asarray(rot, dtype=float)[:, :, axis_column]
    path = ToolPointPath.of(seam)
    near = path.nearest(pos)
    s, c, tan, a_cmd = near["s"], near["point"], near["tangent"], near["axis"]
    # the seam's local frame at s* (AWS, sim.cells.seam): n the reference normal made
    # perpendicular to the travel direction, e the direction the torch body leans to
    n = seam.surface_normal - (tan @ seam.surface_normal)[:, None] * tan
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    e = seam.torch_side * np.cross(n, tan)
    travel = np.degrees(np.arcsin(np.clip(np.einsum("ij,ij->i", a, tan), -1.0, 1.0)))
    work = np.degrees(np.arctan2(-np.einsum("ij,ij->i", a, e), -np.einsum("ij,ij->i", a, n)))
    axis_err = angle_deg(a, a_cmd)
    work_err = np.abs((work - seam.torch_work_angle_deg + 180.0) % 360.0 - 180.0)
    travel_err = np.abs(travel - seam.torch_travel_angle_deg)
    corner = in_zones(s, corner_zones)
    # the weave's lateral direction: travel x torch axis, in the plane normal to the torch
    lat = np.cross(tan - np.einsum("ij,ij->i", tan, a_cmd)[:, None] * a_cmd, a_cmd)
    lat /= np.linalg.norm(lat, axis=1, keepdims=True)
    lateral = np.einsum("ij,ij->i", pos - c, lat)
    deviation, corner_net = near["dist"], corner
    if weave_offset is not None:
        net = path.nearest(pos - np.asarray(weave_offset(t), dtype=float))
        deviation, corner_net = net["dist"], in_zones(net["s"], corner_zones)
    lo, hi = (t[0], t[-1]) if cruise is None else cruise
    speed, pieces = progress_speed(t, s, (t >= lo - 1e-9) & (t <= hi + 1e-9) & ~corner,
                                   weave_period)
    out = ~corner
    worst = int(np.flatnonzero(out)[np.argmax(axis_err[out])]) if np.any(out) else None
    weave = None
    if weave_period is not None:
        wlo, whi = (lo, hi) if weave_window is None else weave_window
        weave = _weave_figures(t, lateral, (t >= wlo) & (t <= whi) & ~corner, weave_period)
    return SeamMeasurement(
        s=s, in_corner=corner, axis_error_deg=axis_err, work_angle_deg=work,
        travel_angle_deg=travel, deviation=deviation, lateral=lateral,
        travel_speed=speed,
        travel_speed_cv=float(np.std(pieces) / max(abs(speed), 1e-12)) if pieces.size else 0.0,
        torch_angle_error_deg=float(axis_err[worst]) if worst is not None else 0.0,
        work_angle_error_deg=float(np.max(work_err[out], initial=0.0)),
        travel_angle_error_deg=float(np.max(travel_err[out], initial=0.0)),
        t_worst_angle=float(t[worst]) if worst is not None else None,
        max_deviation=float(np.max(deviation[~corner_net], initial=0.0)),
        corner_deviation=float(np.max(deviation[corner_net])) if np.any(corner_net) else None,
        corner_torch_excess_deg=corner_torch_excess(a, s, seam, corner_zones),
        start_error=float(np.linalg.norm(pos[0] - path.point[0])),
        end_error=float(np.linalg.norm(pos[-1] - path.point[-1])),
        weave=weave)
