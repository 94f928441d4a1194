"""What cellsim draws over the cell: tool-point trails, the weld bead and a caption.

Trails and bead are added to a ``mujoco.MjvScene`` as extra geoms after
``mjv_updateScene`` and before rendering, so the robot occludes them correctly:

* reference tool path (``tcp_pos_ref``): the whole planned path, green ``mjGEOM_LINE``
  segments (width in pixels, unlit, so the colour is exact);
* actual tool path (``tcp_pos``): red line segments from the start up to the frame's time;
* weld bead: where ``arc_on`` is true, a wide bead-coloured line laid along the actual path
  up to the frame's time (so it grows while welding), lifted towards the eye by the bead radius
  so that a bead in a fillet's corner is not buried in the plates; its width is
  ``OverlayStyle.bead_radius`` (m) but never thinner than ``bead_min_px`` pixels on screen.

A cell's other robots (``summary["robots"]``) get the same trails and bead from their own
recorded tool points (``<name>_tcp_pos``, ``<name>_tcp_pos_ref``, ``<name>_arc_on``).

Each line point is moved towards the camera along its line of sight by a few millimetres
(``lift_*``): its projection is unchanged, but it is drawn in front of the bead and the
reference, instead of flickering with them at equal depth. Paths are
simplified (Ramer-Douglas-Peucker, ``tolerance``) to at most ``max_segments`` segments each,
which bounds the geoms added per frame (each is a draw call; straight seams cost one), and
then again on screen for the frame's camera, to :data:`~sim.render.screenpath.SCREEN_TOL_PX`
(:mod:`sim.render.screenpath`; for a fixed camera once per video).

MuJoCo's renderer (``render_gl3.c``) never draws a line geom into the shadow map (lines cast
no shadow), but draws it in every other pass: mirrored in a reflective floor, in the main pass
and once more, added, in the pass of each shadow-casting light (unlit: its colour is added
again where that light's shadow does not fall). So every segment costs a few draw calls.

The caption (time, phase, highest |joint torque| with the joint's name, arc/suction state) is
drawn into the image with Pillow.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from sim.core.intervals import true_runs
from sim.render.interp import interp_rows, sample_index
from sim.render.screenpath import ScreenPath, camera_key, rdp_keep
from sim.simulation.runfolder import RunRecord


@dataclass(frozen=True)
class OverlayStyle:
    """Colours and sizes of the overlay.

    Attributes:
        reference_rgba: Colour of the reference tool path (RGBA, 0..1).
        actual_rgba: Colour of the actual tool path.
        bead_rgba: Colour of the weld bead.
        line_px: Trail line width, pixels; None: 1.5 px per 240 px of image height, >= 1.5.
        bead_radius: Weld bead radius, m.
        bead_min_px: Smallest on-screen bead diameter, pixels.
        lift_reference: How far reference points move towards the camera, m.
        lift_actual: How far actual-path points move towards the camera, m.
        tolerance: Path simplification tolerance (Ramer-Douglas-Peucker), m.
        max_segments: Most segments per trail (bound on the geoms added per frame).
    """

    reference_rgba: tuple[float, float, float, float] = (0.10, 0.85, 0.20, 1.0)
    actual_rgba: tuple[float, float, float, float] = (1.0, 0.08, 0.08, 1.0)
    bead_rgba: tuple[float, float, float, float] = (1.0, 0.72, 0.15, 1.0)
    line_px: float | None = None
    bead_radius: float = 0.004
    bead_min_px: float = 5.0
    lift_reference: float = 0.015
    lift_actual: float = 0.02
    tolerance: float = 0.001
    max_segments: int = 400


def simplify_polyline(points: np.ndarray, tolerance: float, max_points: int) -> np.ndarray:
    """Indices of the vertices kept by Ramer-Douglas-Peucker simplification.

    Every dropped point lies within ``tolerance`` of the chord between the kept vertices
    around it. If more than ``max_points`` vertices remain, the tolerance is doubled until
    they fit.

    Args:
        points: Polyline vertices (N, 3), m.
        tolerance: Largest distance of a dropped point from the simplified line, m (> 0).
        max_points: Most vertices to keep (>= 2).

    Returns:
        Sorted indices (M,), 2 <= M <= max(max_points, 2) (M = N when N < 2), holding 0 and N - 1.
    """
    pts = np.asarray(points, dtype=float)
    n = len(pts)
    if n <= 2:
        return np.arange(n)
    max_points = max(int(max_points), 2)
    tol = max(float(tolerance), 1e-9)
    while True:
        idx = rdp_keep(pts, tol, _line_distances)
        if len(idx) <= max_points:
            return idx
        tol *= 2.0


def _line_distances(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point of ``q`` (N, 3) from the line through ``a`` and ``b`` (from
    ``a`` where they coincide)."""
    rel = q - a
    chord = b - a
    length = float(np.linalg.norm(chord))
    if length < 1e-12:
        return np.linalg.norm(rel, axis=1)
    return np.linalg.norm(np.cross(rel, chord / length), axis=1)


class PathOverlay:
    """Trails and bead of one run, ready to be added to a scene at any time.

    Args:
        record: The run; uses ``tcp_pos_ref``, ``tcp_pos`` and ``arc_on`` when present.
        style: Colours and sizes.
    """

    def __init__(self, record: RunRecord, style: OverlayStyle | None = None,
                 model: Any = None) -> None:
        self.style = style or OverlayStyle()
        # a bead laid on a part a positioner turns rides on the part: its points are kept in the
        # frame of the body the part is mounted on (``<mechanism>_mount``), posed from the
        # recorded qpos (``model``: the run's model), and drawn where that body is at the
        # frame's time (:meth:`add_to_scene`'s ``data``)
        self.bead_body: list[int | None] = []
        carriers = _bead_carriers(record, model)
        self.t = record.t
        n_max = self.style.max_segments + 1
        self.reference: np.ndarray | None = None
        if record.has("tcp_pos_ref"):
            ref = record.get("tcp_pos_ref").astype(float)
            self.reference = ref[simplify_polyline(ref, self.style.tolerance, n_max)]
        self.actual: np.ndarray | None = None
        self.actual_t: np.ndarray | None = None
        self._actual_full: np.ndarray | None = None
        self.bead_runs: list[tuple[np.ndarray, np.ndarray, float, float]] = []
        if record.has("tcp_pos"):
            act = record.get("tcp_pos").astype(float)
            self._actual_full = act
            idx = simplify_polyline(act, self.style.tolerance, n_max)
            self.actual, self.actual_t = act[idx], self.t[idx]
            if record.has("arc_on"):
                arc = record.get("arc_on").astype(bool)
                runs = true_runs(arc)
                lengths = [
                    float(np.linalg.norm(np.diff(act[a:b], axis=0), axis=1).sum()) for a, b in runs
                ]
                total = sum(lengths) or 1.0
                for (a, b), length in zip(runs, lengths, strict=True):
                    share = max(2, int(n_max * length / total))
                    t_end = float(self.t[b]) if b < len(self.t) else float(self.t[-1])
                    body = carriers.get(int(a)) if carriers else None
                    if body is None:
                        sub = a + simplify_polyline(act[a:b], self.style.tolerance, share)
                        pts = act[sub]
                    else:  # simplified where it lies: on the part (in the world it barely moves)
                        idx = np.unique(np.append(np.arange(a, b, max(1, (b - a) // 4000)),
                                                  b - 1))
                        local = _in_body(model, record, body, idx, act[idx])
                        keep = simplify_polyline(local, self.style.tolerance, share)
                        sub, pts = idx[keep], local[keep]
                    self.bead_runs.append((pts, self.t[sub], float(self.t[a]), t_end))
                    self.bead_body.append(body)
        # each drawn path simplified again on screen, per camera pose (:mod:`screenpath`)
        st = self.style
        self._screen_ref = (None if self.reference is None else ScreenPath(
            self.reference, np.zeros(len(self.reference)), _lifter(st.lift_reference)))
        self._screen_act = (None if self.actual is None or self.actual_t is None
                            else ScreenPath(self.actual, self.actual_t,
                                            _lifter(st.lift_actual)))
        self._screen_bead = [None if body is not None else ScreenPath(
            pts, pts_t, _lifter(st.bead_radius))
            for (pts, pts_t, _, _), body in zip(self.bead_runs, self.bead_body, strict=True)]
        # a cell's other robots: each its own trails and bead, from its recorded tool point
        # (``<name>_tcp_pos``, ``_tcp_pos_ref``, ``_arc_on``); their seams stand still
        self.others: list[PathOverlay] = [
            PathOverlay(_RobotView(record, name), self.style)  # type: ignore[arg-type]
            for name in _other_robots(record)]

    @property
    def max_geoms(self) -> int:
        """Most geoms :meth:`add_to_scene` adds in one call."""
        n = 0
        if self.reference is not None:
            n += len(self.reference)
        if self.actual is not None:
            n += len(self.actual) + 1
        n += sum(len(p) + 1 for p, _, _, _ in self.bead_runs)
        return n + sum(o.max_geoms for o in self.others)

    def add_to_scene(self, scene: Any, time: float, height: int, geoms: Any = None,
                     data: Any = None, fixed_camera: bool = False) -> int:
        """Appends the overlay at ``time`` to ``scene`` (after ``mjv_updateScene``).

        Args:
            scene: The ``mujoco.MjvScene`` (its camera must be set: uses ``scene.camera[0]``).
            time: Frame time, s.
            height: Image height, pixels (line widths and the bead's smallest size).
            geoms: ``scene.geoms`` cached by the caller (building it is costly), or None.
            data: The ``mujoco.MjData`` posed at ``time`` (a bead on a turning part is drawn
                where the part is); None: every bead where it was laid.
            fixed_camera: The camera stays put from frame to frame: the paths are simplified
                on screen once for it (:mod:`sim.render.screenpath`); False: every vertex.

        Returns:
            Number of geoms added (stops silently at ``scene.maxgeom``).
        """
        import mujoco

        st = self.style
        cam = scene.camera[0]
        eye = np.array(cam.pos, dtype=float)
        span = (cam.frustum_top - cam.frustum_bottom) / max(height, 1)
        ortho = bool(cam.orthographic)
        near = max(float(cam.frustum_near), 1e-9)
        line_px = st.line_px if st.line_px is not None else max(1.5, 1.5 * height / 240.0)
        if geoms is None:
            geoms = scene.geoms
        room = scene.maxgeom - scene.ngeom
        added = 0
        eye3 = np.zeros(3)
        mat = np.eye(3).ravel()

        key = camera_key(cam, height)

        def polyline(points: np.ndarray, gtype: int, rgba: tuple, widths: np.ndarray | float,
                     emission: float) -> None:
            nonlocal added
            rgba32 = np.asarray(rgba, dtype=np.float32)
            w = np.broadcast_to(np.asarray(widths, dtype=float), (max(len(points) - 1, 0),))
            for k in range(len(points) - 1):
                if added >= room:
                    return
                g = geoms[scene.ngeom]
                mujoco.mjv_initGeom(g, gtype, eye3, eye3, mat, rgba32)
                g.emission = emission
                g.castshadow = 0
                mujoco.mjv_connector(g, gtype, float(w[k]), points[k], points[k + 1])
                scene.ngeom += 1
                added += 1

        # Weld bead: a wide line along the actual path where the arc was on, up to `time`.
        for (pts, pts_t, t_start, t_end), body, screen in zip(
                self.bead_runs, self.bead_body, self._screen_bead, strict=True):
            if time < t_start:
                continue
            last = (interp_rows(self.t, self._actual_full, time)
                    if time < t_end and self._actual_full is not None else None)
            if screen is not None:
                path = screen.upto(time, key, last, fixed_camera)
            else:  # on a turning part: where the part is now (not simplified on screen)
                k = int(np.searchsorted(pts_t, time, side="right"))
                path = pts[:k]
                if body is not None and data is not None:
                    R, p = data.xmat[body].reshape(3, 3), data.xpos[body]
                    path = path @ R.T + p
                if last is not None:
                    path = np.vstack([path, last])
                path = _lifted(path, eye, st.bead_radius)
            if len(path) < 2:
                continue
            # `path` is lifted towards the eye by the bead radius: a bead laid in a fillet's
            # corner would otherwise be buried in both plates; the width is measured at the
            # segment's middle before the lift
            mid = 0.5 * (path[1:] + path[:-1])
            dist = np.linalg.norm(mid - eye, axis=1) + st.bead_radius
            px = span if ortho else dist * span / near  # metres per pixel at each segment
            # a wide line (bead width on screen, at least bead_min_px); lines also cost far
            # less than capsules on software OpenGL
            width_px = np.maximum(2.0 * st.bead_radius / px, st.bead_min_px)
            polyline(path, mujoco.mjtGeom.mjGEOM_LINE, st.bead_rgba, width_px, 0.35)
        # Reference path, whole.
        if self._screen_ref is not None:
            polyline(self._screen_ref.upto(np.inf, key, None, fixed_camera),
                     mujoco.mjtGeom.mjGEOM_LINE,
                     st.reference_rgba, line_px, 1.0)
        # Actual path up to `time`.
        if self._screen_act is not None and self._actual_full is not None:
            path = self._screen_act.upto(time, key, interp_rows(self.t, self._actual_full, time),
                                         fixed_camera)
            polyline(path, mujoco.mjtGeom.mjGEOM_LINE, st.actual_rgba, line_px, 1.0)
        for other in self.others:
            added += other.add_to_scene(scene, time, height, geoms, data, fixed_camera)
        return added


def _lifted(points: np.ndarray, eye: np.ndarray, lift: float) -> np.ndarray:
    """``points`` moved towards ``eye`` by ``lift`` (at most a quarter of their distance):
    the same pixels, drawn in front of what lies at their depth."""
    v = eye - points
    d = np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-9)
    return points + v / d * np.minimum(lift, 0.25 * d)


def _lifter(lift: float) -> Any:
    """``f(points, eye)``: :func:`_lifted` by ``lift``."""
    return lambda points, eye: _lifted(points, eye, lift)


def _other_robots(record: RunRecord) -> list[str]:
    """A cell's other robots with a recorded tool point (``summary["robots"]`` after the
    first), in the cell's order; empty for a cell with one robot."""
    robots = list((record.summary or {}).get("robots", {}))[1:]
    return [name for name in robots if record.has(f"{name}_tcp_pos")]


class _RobotView:
    """One of a cell's other robots' recorded tool point as a run's own (``tcp_pos``,
    ``tcp_pos_ref``, ``arc_on`` are its ``<name>_...`` arrays), for :class:`PathOverlay`."""

    KEYS = ("tcp_pos", "tcp_pos_ref", "arc_on")

    def __init__(self, record: RunRecord, name: str) -> None:
        self.record, self.name = record, name
        self.t = record.t
        self.summary: dict[str, Any] = {}

    def _key(self, key: str) -> str | None:
        return f"{self.name}_{key}" if key in self.KEYS else None

    def has(self, key: str) -> bool:
        k = self._key(key)
        return k is not None and self.record.has(k)

    def get(self, key: str) -> Any:
        k = self._key(key)
        if k is None:
            raise KeyError(key)
        return self.record.get(k)


def _bead_carriers(record: RunRecord, model: Any) -> dict[int, int]:
    """The body carrying each arc-on run's seam, by the run's first sample: the mount of the
    mechanism the summary's weld entry names (``carried_by``); empty without a model."""
    if model is None or not record.summary or not record.has("phase"):
        return {}
    carried = {w["phase"]: w.get("carried_by") for w in record.summary.get("weld", ())
               if w.get("robot", "robot") == "robot"}  # the first robot's phases
    names = [p["name"] if isinstance(p, dict) else str(p)
             for p in record.summary.get("phases", ())]
    if not any(carried.values()) or not record.has("arc_on"):
        return {}
    phase = record.get("phase")
    out = {}
    for a, _ in true_runs(record.get("arc_on").astype(bool)):
        k = int(phase[a])
        mech = carried.get(names[k]) if k < len(names) else None
        if mech:
            out[int(a)] = int(model.body(f"{mech}_mount").id)
    return out


def _in_body(model: Any, record: RunRecord, body: int, samples: np.ndarray,
             points: np.ndarray) -> np.ndarray:
    """World points laid at recorded samples, in the frame the body had at each."""
    import mujoco

    data = mujoco.MjData(model)
    qpos = record.get("qpos")
    out = np.empty_like(points)
    for i, (s, x) in enumerate(zip(samples, points, strict=True)):
        data.qpos[:] = qpos[s]
        mujoco.mj_kinematics(model, data)
        R, p = data.xmat[body].reshape(3, 3), data.xpos[body]
        out[i] = R.T @ (x - p)
    return out


# ----------------------------------------------------------------------------------------
# Caption


@lru_cache(maxsize=8)
def _font(size: int) -> Any:
    from PIL import ImageFont

    spec = importlib.util.find_spec("matplotlib")
    if spec is not None and spec.submodule_search_locations:
        ttf = (
            Path(list(spec.submodule_search_locations)[0])
            / "mpl-data" / "fonts" / "ttf" / "DejaVuSansMono.ttf"
        )
        if ttf.is_file():
            return ImageFont.truetype(str(ttf), size)
    return ImageFont.load_default(size=size)


def caption_text(record: RunRecord, time: float) -> str:
    """Caption of the frame at ``time``: time, phase, highest |joint torque|, arc/suction.

    Args:
        record: The run.
        time: Frame time, s.

    Returns:
        One line, e.g. ``"t=1.20 s  weld  |tau|max j2 23.4 N m  ARC"``.
    """
    t = record.t
    i = sample_index(t, time)
    parts = [f"t={time - record.t0:6.2f} s"]
    if record.has("phase") and record.phases:
        parts.append(record.phase_name(int(record.get("phase")[i])))
    if record.has("tau") and record.joints:
        tau = interp_rows(t, record.get("tau"), time)
        j = int(np.argmax(np.abs(tau)))
        parts.append(f"|tau|max {record.joints[j]} {abs(float(tau[j])):6.1f} N m")
    if record.has("arc_on") and bool(record.get("arc_on")[i]):
        parts.append("ARC")
    if record.has("suction") and bool(record.get("suction")[i]):
        parts.append("SUCTION")
    return "  ".join(parts)


def draw_caption(frame: np.ndarray, text: str) -> None:
    """Draws ``text`` in a darkened strip along the top of ``frame`` (in place).

    Args:
        frame: RGB image (H, W, 3) uint8, C-contiguous.
        text: One line of text; the font size follows the image height (about 4 %), shrunk
            (down to 7 px) and then the text cut to fit the width.
    """
    from PIL import Image, ImageDraw

    height, width = frame.shape[:2]
    size = max(9, int(round(height * 0.04)))
    while size > 7 and _font(size).getlength(text) > width - size:
        size -= 1  # narrow frames: smaller font, then cut the text
    font = _font(size)
    while text and font.getlength(text) > width - 2:
        text = text[:-1]
    strip_h = min(height, int(size * 1.6))
    strip = frame[:strip_h]
    strip[:] = (strip.astype(np.uint16) * 2 // 5).astype(np.uint8)
    image = Image.fromarray(strip)
    x = min(max(2, size // 2), max(0, int(width - 2 - font.getlength(text))))
    ImageDraw.Draw(image).text((x, (strip_h - size) // 2), text, fill=(255, 255, 255), font=font)
    strip[:] = np.asarray(image)
