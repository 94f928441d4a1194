"""Rendering the frames of a recorded run, one tile per camera, side by side.

:class:`FrameRenderer` owns one ``mujoco.Renderer`` (one OpenGL context) and closes it
explicitly (use it as a context manager), so nothing is left for the interpreter to free at
exit. For a frame at time ``t`` it interpolates ``qpos`` from the record
(:class:`~sim.render.interp.QposInterpolator`), runs the position-dependent stages MuJoCo's
visualiser needs (``mj_kinematics``, ``mj_comPos``, ``mj_camlight``, and ``mj_tendon`` /
``mj_flex`` when the model has tendons / flexes; no dynamics, no collision detection),
renders each camera with the overlay (:mod:`sim.render.overlay`) and draws the caption.

``width`` and ``height`` are the size of ONE camera tile; the frame is
``(height, width * len(cameras), 3)``. The model's offscreen framebuffer
(``<visual><global offwidth offheight>``) is set to the tile's size on the loaded model (the
file is not changed): larger costs software OpenGL time for the same pixels, smaller cannot
hold the tile. Likewise the shadow map is sized to the tile (:func:`shadow_size`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from sim.errors import RenderError
from sim.render.gl import configure_gl
from sim.render.interp import QposInterpolator
from sim.render.overlay import OverlayStyle, PathOverlay, caption_text, draw_caption
from sim.simulation.runfolder import (
    REQUIRED_FOR_VIDEO,
    RunFolderError,
    RunRecord,
    as_record,
)

#: Largest tile side accepted, pixels (8K; larger sizes fail in most OpenGL drivers).
MAX_SIDE = 8192


def validate_size(width: int, height: int) -> None:
    """Checks a tile size for H.264 yuv420p video.

    Raises:
        RenderError: Not an integer, smaller than 16, larger than :data:`MAX_SIDE`, or odd
            (yuv420p stores colour at half resolution, so both sides must be even).
    """
    for name, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise RenderError(f"video {name} must be an integer number of pixels, got {value!r}")
        if not 16 <= value <= MAX_SIDE:
            raise RenderError(f"video {name} must be between 16 and {MAX_SIDE} pixels, got {value}")
        if value % 2:
            raise RenderError(
                f"video {name} must be even for H.264 yuv420p, got {value} "
                f"(try {value - 1} or {value + 1})"
            )


def camera_names(model: Any) -> list[str]:
    """Names of the model's cameras, in model order (unnamed ones as ``#<id>``)."""
    import mujoco

    names = []
    for i in range(model.ncam):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_CAMERA, i)
        names.append(name if name else f"#{i}")
    return names


def resolve_cameras(model: Any, cameras: Sequence[str]) -> list[int]:
    """Camera ids of ``cameras``.

    Raises:
        RenderError: An empty list, or an unknown name; the message lists the model's cameras.
    """
    import mujoco

    if isinstance(cameras, str):
        cameras = (cameras,)
    if not cameras:
        raise RenderError("no camera given; name at least one (--camera NAME)")
    ids = []
    for name in cameras:
        cid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, str(name))
        if cid < 0:
            known = camera_names(model)
            listed = ", ".join(known) if known else "none (add a <camera name=...> to the cell)"
            raise RenderError(f"unknown camera {name!r}; the model's cameras: {listed}")
        ids.append(cid)
    return ids


def shadow_size(width: int, height: int, model_size: int) -> int:
    """Side of the shadow map for a ``width`` x ``height`` tile: the smallest power of two at
    least twice the tile's longer side, never more than the model's own (MuJoCo's default
    4096). Software OpenGL spends a fifth to a third of a small frame on a 4096 map; at 480 x
    360 a 1024 map changes 0.1 % of the pixels by more than 8 levels (shadow edges)."""
    side = 1 << max(0, (2 * max(int(width), int(height)) - 1).bit_length())
    return int(min(max(side, 256), model_size))


def frame_times(record: RunRecord, fps: float, speed: float = 1.0) -> np.ndarray:
    """Video frame times of ``record``: ``t0 + k speed / fps`` for
    ``k = 0 .. floor(duration * fps / speed)`` (see :meth:`FrameRenderer.frame_times`).

    ``speed`` is the playback speed, simulated seconds per second of video (4: a time-lapse
    four times faster than real time; 0.5: slow motion).

    Raises:
        RenderError: ``fps`` or ``speed`` not positive and finite, or more than
            :data:`MAX_FRAMES` frames.
    """
    if not np.isfinite(fps) or fps <= 0:
        raise RenderError(f"fps must be a positive number, got {fps!r}")
    if isinstance(speed, bool) or not np.isfinite(speed) or speed <= 0:
        raise RenderError(f"the video's playback speed must be a positive number, got {speed!r}")
    count = record.duration * fps / speed
    if not np.isfinite(count) or count + 1 > MAX_FRAMES:
        raise RenderError(f"--fps {fps:g} at speed {speed:g} over the run's "
                          f"{record.duration:.4g} s gives {count + 1:.3g} frames, more than "
                          f"{MAX_FRAMES:,}: lower --fps or raise the speed")
    n = int(np.floor(count + 1e-9)) + 1
    return record.t0 + (np.arange(n) * float(speed)) / float(fps)


class FrameRenderer:
    """Renders a run's frames at chosen times.

    Args:
        run: A run folder or a :class:`~sim.simulation.runfolder.RunRecord`.
        cameras: Camera names, tiled left to right.
        width: Tile width, pixels (even).
        height: Tile height, pixels (even).
        overlay: Draw trails and weld bead.
        caption: Draw the caption.
        gl: OpenGL backend (``"egl"``, ``"osmesa"``) or None for automatic.
        style: Overlay colours and sizes.

    Raises:
        RenderError: Bad size, unknown camera, or no OpenGL backend.
        RunFolderError: The run is incomplete or does not match its model.
    """

    def __init__(
        self,
        run: Any,
        *,
        cameras: Sequence[str] = ("overview",),
        width: int = 640,
        height: int = 480,
        overlay: bool = True,
        caption: bool = True,
        gl: str | None = None,
        style: OverlayStyle | None = None,
    ) -> None:
        self._renderer: Any = None
        validate_size(width, height)
        self.record: RunRecord = as_record(run)
        self.record.require(REQUIRED_FOR_VIDEO)
        configure_gl(gl)
        import mujoco

        self._mj = mujoco
        model = self.record.load_model()
        self.camera_ids = resolve_cameras(model, cameras)
        self.cameras = [str(c) for c in ([cameras] if isinstance(cameras, str) else cameras)]
        qpos = self.record.get("qpos")
        if qpos.ndim != 2 or qpos.shape[1] != model.nq:
            raise RunFolderError(
                f"{self.record.where}: trajectory.npz 'qpos' has shape {qpos.shape} but model.xml "
                f"has nq={model.nq}"
            )
        # the offscreen framebuffer is the tile's size: the renderer renders into its corner
        # anyway, and software OpenGL pays for the whole (multisampled) buffer every frame
        # (a cell's 1920 x 1080 buffer: ~16 % more CPU per 480 x 360 frame, same pixels)
        model.vis.global_.offwidth = int(width)
        model.vis.global_.offheight = int(height)
        model.vis.quality.shadowsize = shadow_size(width, height,
                                                   int(model.vis.quality.shadowsize))
        self.views = self._views(model, qpos, width / height)
        # tiles whose camera stays put (the overlay is simplified on screen once for them)
        self.fixed = [(v.track_site is None) if v is not None else
                      (int(model.cam_bodyid[c]) == 0
                       and int(model.cam_mode[c]) == int(mujoco.mjtCamLight.mjCAMLIGHT_FIXED))
                      for v, c in zip(self.views, self.camera_ids, strict=True)]
        self.model = model
        self.data = mujoco.MjData(model)
        self.width, self.height = int(width), int(height)
        self.interp = QposInterpolator(model, self.record.t, qpos)
        self.overlay = PathOverlay(self.record, style, model) if overlay else None
        self.caption = caption
        extra = self.overlay.max_geoms if self.overlay else 0
        max_geom = 10000 + extra
        try:
            self._renderer = mujoco.Renderer(model, self.height, self.width, max_geom=max_geom)
        except Exception as exc:  # context creation failures come as various types
            raise RenderError(
                f"could not create a {self.width}x{self.height} OpenGL renderer: {exc}"
            ) from exc
        self._geoms = self._renderer.scene.geoms
        self.painter = CollisionPainter(model, self.record.summary.get("collisions", ())
                                        if self.record.summary else ())
        self._tiles = [np.empty((self.height, self.width, 3), np.uint8) for _ in self.camera_ids]

    def _views(self, model: Any, qpos: np.ndarray, aspect: float) -> list[Any]:
        """Per tile: a framed free camera (``overview``, ``tool``: :mod:`sim.analysis.framing`)
        or None for a model camera rendered as it is."""
        import mujoco

        from sim.analysis.framing import FOVY_DEG, overview_view, tool_view

        views: list[Any] = []
        tcp = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "robot/tcp")
        for name, cid in zip(self.cameras, self.camera_ids, strict=True):
            if name == "overview":
                views.append(overview_view(model, qpos, cid, aspect))
            elif name == "tool" and tcp >= 0:
                views.append(tool_view(model, qpos, cid, tcp))
            else:
                views.append(None)
        if any(v is not None for v in views):
            model.vis.global_.fovy = FOVY_DEG
        return views

    # -- life cycle ---------------------------------------------------------------------
    def close(self) -> None:
        """Frees the OpenGL context (idempotent)."""
        renderer, self._renderer = self._renderer, None
        self._geoms = None
        if renderer is not None:
            renderer.close()

    def __enter__(self) -> FrameRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:  # last resort; callers close explicitly
        try:
            self.close()
        except Exception:  # noqa: BLE001 - never raise from a finalizer
            pass

    # -- frames -------------------------------------------------------------------------
    @property
    def frame_shape(self) -> tuple[int, int, int]:
        """Shape of one frame, (height, width * n_cameras, 3)."""
        return (self.height, self.width * len(self.camera_ids), 3)

    def frame_times(self, fps: float, speed: float = 1.0) -> np.ndarray:
        """Video frame times ``t0 + k speed / fps`` for ``k = 0 .. floor(duration * fps /
        speed)`` (``speed``: simulated seconds per second of video).

        The frame count is ``floor(duration * fps / speed) + 1``: the first frame shows the
        first sample, the last one the state at most ``speed / fps`` before the end.

        Raises:
            RenderError: ``fps`` or ``speed`` not positive and finite.
        """
        return frame_times(self.record, fps, speed)

    def set_state(self, time: float) -> None:
        """Puts the interpolated state at ``time`` into ``self.data`` (positions only)."""
        mj, m, d = self._mj, self.model, self.data
        self.interp(time, out=d.qpos)
        mj.mj_kinematics(m, d)
        mj.mj_comPos(m, d)
        mj.mj_camlight(m, d)
        if m.ntendon:
            mj.mj_tendon(m, d)
        if m.nflex:
            mj.mj_flex(m, d)

    def caption_at(self, time: float) -> str:
        """Caption text of the frame at ``time`` (see :func:`~sim.render.overlay.caption_text`)."""
        return caption_text(self.record, time)

    def _update_scene(self, tile: int) -> None:
        """The renderer's scene for one tile at the current state: its model camera, or its
        framed free camera (the tool camera re-aimed at the tool point)."""
        view = self.views[tile]
        if view is None:
            self._renderer.update_scene(self.data, self.camera_ids[tile])
            return
        if view.track_site is not None:
            view.lookat = self.data.site_xpos[view.track_site].copy()
        self._renderer.update_scene(self.data, view.camera())

    def segment(self, time: float, tile: int = 0) -> np.ndarray:
        """Geom id seen at every pixel of one tile at ``time`` (-1: nothing), (H, W): the
        same view as :meth:`render`, without overlays (tests check what the frame shows)."""
        if self._renderer is None:
            raise RenderError("segment() called after close()")
        self.set_state(time)
        r = self._renderer
        self._update_scene(tile)
        r.enable_segmentation_rendering()
        try:
            seg = r.render()
        finally:
            r.disable_segmentation_rendering()
        ids, types = seg[..., 0], seg[..., 1]
        return np.where(types == self._mj.mjtObj.mjOBJ_GEOM, ids, -1)

    def render(
        self, time: float, out: np.ndarray | None = None, *, caption: bool | None = None
    ) -> np.ndarray:
        """Renders the frame at ``time`` (s).

        Args:
            time: Frame time, s (clamped to the record).
            out: Optional C-contiguous uint8 array of :attr:`frame_shape` to fill.
            caption: Draw the caption; None: as chosen at construction. (The video writer
                draws it in its encoder thread instead, with :meth:`caption_at`.)

        Returns:
            The frame (H, W * n_cameras, 3) uint8.
        """
        if self._renderer is None:
            raise RenderError("render() called after close()")
        self.set_state(time)
        if out is None:
            out = np.empty(self.frame_shape, np.uint8)
        r = self._renderer
        single = len(self.camera_ids) == 1
        for k in range(len(self.camera_ids)):
            self._update_scene(k)
            self.painter.paint(r.scene, time)
            if self.overlay is not None:
                self.overlay.add_to_scene(r.scene, time, self.height, self._geoms, self.data,
                                          self.fixed[k])
            if single:
                r.render(out=out)
            else:
                r.render(out=self._tiles[k])
                out[:, k * self.width : (k + 1) * self.width] = self._tiles[k]
        if self.caption if caption is None else caption:
            draw_caption(out, self.caption_at(time))
        return out


#: Most frames of one video (an hour at 30 fps).
MAX_FRAMES = 108_000

#: Colour of the geoms that collide, while they touch (RGBA).
COLLISION_RGBA = (1.0, 0.08, 0.05, 1.0)
#: A collision shorter than this is painted over this long (centred on it), s, so that a brief
#: hit shows in a few frames of a 30 fps video instead of falling between two.
MIN_PAINT_S = 0.1


class CollisionPainter:
    """Draws the geoms of a run's collisions (``summary["collisions"]``) in red while they touch.

    A robot link's collision geoms are hidden in the video (group 3): the whole link (its
    visual geoms) is painted instead; a tool, cell or part geom is painted itself. A collision
    shorter than :data:`MIN_PAINT_S` is painted over that long.
    """

    def __init__(self, model: Any, collisions: Sequence[dict[str, Any]]) -> None:
        import mujoco

        from sim.simulation.collision_model import painted_geoms

        self._mj = mujoco
        self.intervals: list[tuple[float, float, frozenset[int]]] = []
        for c in collisions:
            ids = painted_geoms(model, [str(n) for n in c.get("all_geoms", c.get("geoms", ()))])
            if ids:
                t0, t1 = float(c["t0"]), float(c["t1"])
                pad = max(0.0, MIN_PAINT_S - (t1 - t0)) / 2.0
                self.intervals.append((t0 - pad, t1 + pad, frozenset(ids)))

    def active(self, time: float) -> frozenset[int]:
        """Geom ids in collision at ``time`` (s)."""
        out: set[int] = set()
        for t0, t1, ids in self.intervals:
            if t0 <= time <= t1:
                out |= ids
        return frozenset(out)

    def paint(self, scene: Any, time: float) -> int:
        """Paint the colliding geoms of ``scene`` red; returns how many were painted."""
        ids = self.active(time) if self.intervals else frozenset()
        if not ids:
            return 0
        geom = self._mj.mjtObj.mjOBJ_GEOM
        n = 0
        for i in range(scene.ngeom):
            g = scene.geoms[i]
            if g.objtype == geom and g.objid in ids:
                g.rgba[:] = COLLISION_RGBA
                n += 1
        return n
