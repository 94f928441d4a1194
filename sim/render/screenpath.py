"""Overlay polylines simplified where they are drawn: in the image, to a fraction of a pixel.

Every segment of a trail or bead is one geom, and software OpenGL draws each geom in every
pass of a frame (reflection, main, shadowed light), so the segments cost CPU time in every
frame. Simplified in the world (1 mm, :func:`sim.render.overlay.simplify_polyline`), a path
still has vertices that are far less than a pixel apart on screen. :func:`screen_coords`
projects points through a ``mujoco.MjvGLCamera`` (pixels, up to an offset), and
:func:`simplify_screen` keeps the vertices a Ramer-Douglas-Peucker pass needs so that every
dropped vertex lies within ``tol_px`` of the drawn segment that replaces it (the distance to
the segment, not to its line: a path that runs back over itself keeps its turning point).
Then the drawn polyline and the path it stands for are within ``tol_px`` of each other on
screen both ways (a segment's band is convex and holds the vertices it replaces).

:class:`ScreenPath` applies it to a path drawn up to a frame's time: the simplification of the
whole path is computed once per camera pose (a fixed camera: once per video) and a frame draws
its kept vertices before the frame's sample, then the last stretch (the vertices since the last
kept one and the frame's interpolated point) simplified on its own. A camera that moves from
frame to frame (the tool camera) draws every vertex instead (simplifying in every frame would
cost what it saves); which cameras stay put is the caller's to say.

At 480 x 360 on the default weld cycle, 0.25 px halves the overlay's geoms (240 to 126 a
frame); 0.23 % of the pixels change by more than 8 levels (anti-aliased line edges moved by a
fraction of a pixel); 0.5 px: 94 geoms, 0.37 %.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

#: Largest on-screen distance between a drawn trail or bead and the path it stands for, px.
SCREEN_TOL_PX = 0.25


def camera_key(cam: Any, height: int) -> tuple[float, ...]:
    """What a ``mujoco.MjvGLCamera`` and the image height fix about the projection."""
    return (*map(float, cam.pos), *map(float, cam.forward), *map(float, cam.up),
            float(cam.frustum_near), float(cam.frustum_bottom), float(cam.frustum_top),
            float(bool(cam.orthographic)), float(height))


def screen_coords(points: np.ndarray, key: tuple[float, ...]) -> np.ndarray | None:
    """Image coordinates of ``points`` (N, 3) in pixels, up to an offset per axis (N, 2), for
    the camera :func:`camera_key` describes; None if a point is not beyond the near plane
    (its projection is not a pixel)."""
    pos, fwd, up = np.array(key[0:3]), np.array(key[3:6]), np.array(key[6:9])
    near, bottom, top, ortho, height = key[9:14]
    right = np.cross(fwd, up)
    d = np.asarray(points, dtype=float) - pos
    z = d @ fwd
    xy = np.stack([d @ right, d @ up], axis=1)
    span = (top - bottom) / max(height, 1.0)  # metres per pixel on the near plane
    if span <= 0:
        return None
    if ortho:
        return xy / span
    if len(z) and float(z.min()) <= near:
        return None
    return xy * (near / span) / z[:, None]


def segment_distances(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point of ``q`` (N, 2) from the segment ``a``-``b``."""
    ab = b - a
    length2 = float(ab @ ab)
    rel = q - a
    if length2 <= 0.0:
        return np.linalg.norm(rel, axis=1)
    s = np.clip(rel @ ab / length2, 0.0, 1.0)
    return np.linalg.norm(rel - s[:, None] * ab, axis=1)


def rdp_keep(points: np.ndarray, tol: float,
             distances: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
             = segment_distances) -> np.ndarray:
    """Ramer-Douglas-Peucker: indices of the vertices of the polyline ``points`` (N, d) kept
    so that every dropped vertex is within ``tol`` of the kept vertices around it, as
    ``distances(q, a, b)`` measures (default: the segment ``a``-``b``). Sorted, with 0 and
    N - 1."""
    n = len(points)
    if n <= 2:
        return np.arange(n)
    keep = np.zeros(n, dtype=bool)
    keep[0] = keep[-1] = True
    stack = [(0, n - 1)]
    while stack:
        a, b = stack.pop()
        if b <= a + 1:
            continue
        dist = distances(points[a + 1 : b], points[a], points[b])
        k = int(np.argmax(dist))
        if dist[k] > tol:
            i = a + 1 + k
            keep[i] = True
            stack.append((a, i))
            stack.append((i, b))
    return np.flatnonzero(keep)


def simplify_screen(uv: np.ndarray, tol_px: float = SCREEN_TOL_PX) -> np.ndarray:
    """Indices of the vertices of the image polyline ``uv`` (N, 2) kept so that every dropped
    vertex lies within ``tol_px`` of the segment between the kept vertices around it
    (Ramer-Douglas-Peucker, distance to the segment). Sorted, with 0 and N - 1."""
    return rdp_keep(uv, tol_px, segment_distances)


def simplified(points: np.ndarray, key: tuple[float, ...], tol_px: float | None = None
               ) -> np.ndarray:
    """``points`` (N, 3) without the vertices :func:`simplify_screen` drops (all of them kept
    where a point is not in front of the camera)."""
    uv = screen_coords(points, key)
    if uv is None or len(points) <= 2:
        return points
    return points[simplify_screen(uv, SCREEN_TOL_PX if tol_px is None else tol_px)]


class ScreenPath:
    """A path drawn from its start up to a frame's time, simplified on screen.

    Args:
        points: The path's vertices (N, 3), as drawn (lifted towards the camera by the caller
            through ``lift``).
        times: Each vertex's time (N,), non-decreasing.
        lift: ``lift(points, eye)``: the points as drawn for a camera at ``eye``.
        tol_px: Largest on-screen distance of the drawn polyline from the path, px
            (None: :data:`SCREEN_TOL_PX`).
    """

    def __init__(self, points: np.ndarray, times: np.ndarray, lift: Any,
                 tol_px: float | None = None) -> None:
        self.points = np.asarray(points, dtype=float)
        self.times = np.asarray(times, dtype=float)
        self.lift = lift
        self.tol_px = float(SCREEN_TOL_PX if tol_px is None else tol_px)
        self._cache: dict[tuple[float, ...], tuple[np.ndarray, np.ndarray, bool]] = {}

    def _for_camera(self, key: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray, bool]:
        """The path as drawn for the camera ``key``, the vertices kept on screen, and whether
        it projects (a pure function of ``key``: a frame does not depend on the frames a
        process rendered before it); a few poses are kept (a few tiles' fixed cameras)."""
        got = self._cache.get(key)
        if got is not None:
            return got
        drawn = self.lift(self.points, np.array(key[0:3]))
        uv = screen_coords(drawn, key)
        kept = simplify_screen(uv, self.tol_px) if uv is not None else np.arange(len(drawn))
        if len(self._cache) >= 4:
            self._cache.pop(next(iter(self._cache)))
        self._cache[key] = got = (drawn, kept, uv is not None)
        return got

    def upto(self, time: float, key: tuple[float, ...], last: np.ndarray | None,
             on_screen: bool = True) -> np.ndarray:
        """The drawn polyline: vertices before ``time`` (those at ``time`` included), then
        ``last`` (the point at ``time``, not yet lifted) if given; (M, 3). ``on_screen``
        False (a camera that moves from frame to frame): every vertex, lifted."""
        k = int(np.searchsorted(self.times, time, side="right"))
        if not on_screen:
            eye = np.array(key[0:3])
            path = self.points[:k] if last is None else np.vstack([self.points[:k], last])
            return self.lift(path, eye)
        drawn, kept, projects = self._for_camera(key)
        m = int(np.searchsorted(kept, k, side="left"))  # kept vertices before k
        head = drawn[kept[: max(m - 1, 0)]]
        start = int(kept[m - 1]) if m else k
        tail = drawn[start:k]
        if last is not None:
            tail = np.vstack([tail, self.lift(np.asarray(last, float)[None, :],
                                              np.array(key[0:3]))])
        if projects and len(tail) > 2:
            tail = simplified(tail, key, self.tol_px)
        return np.vstack([head, tail]) if len(head) else tail
