"""Trails and bead simplified on screen (sim.render.screenpath) stay within half a pixel of
the paths they stand for.

The oracle projects with OpenGL's own matrices written here (a look-at view and glFrustum /
glOrtho, then the viewport), not with the module's formula, and measures every vertex of the
full path (up to the frame's time, then the frame's interpolated point) against every drawn
segment. A planted fault (distance to the chord's line instead of to the chord) drops the
turning point of a path that runs back over itself, and the oracle sees it.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import sim.render.screenpath as sp
from sim.render.screenpath import ScreenPath, camera_key

TOL = sp.SCREEN_TOL_PX


def _camera(yaw: float, pitch: float, ortho: bool) -> SimpleNamespace:
    fwd = np.array([np.cos(pitch) * np.cos(yaw), np.cos(pitch) * np.sin(yaw), np.sin(pitch)])
    up0 = np.array([0.0, 0.0, 1.0])
    right = np.cross(fwd, up0)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    return SimpleNamespace(pos=np.array([0.3, -0.2, 1.1]), forward=fwd, up=up,
                           frustum_near=0.05, frustum_bottom=-0.02, frustum_top=0.02,
                           orthographic=ortho)


def _pixels(points: np.ndarray, cam: SimpleNamespace, width: int, height: int) -> np.ndarray:
    """OpenGL: eye coordinates by the look-at matrix, clip by glFrustum / glOrtho (the
    frustum's width from the viewport's aspect), NDC, viewport."""
    right = np.cross(cam.forward, cam.up)
    view = np.eye(4)
    view[:3, :3] = np.stack([right, cam.up, -cam.forward])
    view[:3, 3] = -view[:3, :3] @ cam.pos
    n, b, t, f = cam.frustum_near, cam.frustum_bottom, cam.frustum_top, 50.0
    half = 0.5 * (t - b) * width / height
    left, r = -half, half
    proj = np.zeros((4, 4))
    if cam.orthographic:
        proj[0, 0], proj[1, 1], proj[2, 2] = 2 / (r - left), 2 / (t - b), -2 / (f - n)
        proj[0, 3], proj[1, 3] = -(r + left) / (r - left), -(t + b) / (t - b)
        proj[3, 3] = 1.0
    else:
        proj[0, 0], proj[1, 1] = 2 * n / (r - left), 2 * n / (t - b)
        proj[0, 2], proj[1, 2] = (r + left) / (r - left), (t + b) / (t - b)
        proj[2, 2], proj[2, 3], proj[3, 2] = -(f + n) / (f - n), -2 * f * n / (f - n), -1.0
    h = np.c_[points, np.ones(len(points))] @ (proj @ view).T
    ndc = h[:, :2] / h[:, 3:4]
    return np.c_[(ndc[:, 0] + 1) * width / 2, (ndc[:, 1] + 1) * height / 2]


def _worst(full: np.ndarray, drawn: np.ndarray) -> float:
    """Largest distance of a vertex of ``full`` from the polyline ``drawn`` (pixels)."""
    if len(drawn) == 1:
        return float(np.linalg.norm(full - drawn[0], axis=1).max())
    a, b = drawn[:-1][None], drawn[1:][None]
    q = full[:, None]
    ab = b - a
    s = np.clip(((q - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1)
    return float(np.linalg.norm(q - a - s[..., None] * ab, axis=-1).min(axis=1).max())


def _scaled(cam: SimpleNamespace) -> SimpleNamespace:
    """The orthographic camera as the module sees it: MuJoCo's frustum in metres."""
    if not cam.orthographic:
        return cam
    return SimpleNamespace(**{**vars(cam), "frustum_bottom": 1.5 * cam.frustum_bottom / 0.02,
                              "frustum_top": 1.5 * cam.frustum_top / 0.02})


def _path(steps: np.ndarray, start: np.ndarray) -> np.ndarray:
    return start + np.cumsum(steps, axis=0)


def _lift(points: np.ndarray, eye: np.ndarray) -> np.ndarray:  # as the overlay does
    v = eye - points
    d = np.linalg.norm(v, axis=1, keepdims=True)
    return points + v / d * np.minimum(0.02, 0.25 * d)


def _check(points: np.ndarray, times: np.ndarray, time: float, last: np.ndarray | None,
           cam: SimpleNamespace, height: int) -> float:
    width = height * 4 // 3
    mcam = _scaled(cam)
    drawn = ScreenPath(points, times, _lift).upto(time, camera_key(mcam, height), last)
    k = int(np.searchsorted(times, time, side="right"))
    full = _lift(points[:k] if last is None else np.vstack([points[:k], last]), mcam.pos)
    assert len(drawn) <= len(full)
    # every drawn vertex is one of the full path's; the ends are the path's
    assert all((full == v).all(axis=1).any() for v in drawn)
    if len(full):
        assert (drawn[0] == full[0]).all() and (drawn[-1] == full[-1]).all()
    return _worst(_pixels(full, mcam, width, height), _pixels(drawn, mcam, width, height))


paths = st.integers(3, 120).flatmap(lambda n: st.tuples(
    st.lists(st.tuples(*[st.floats(-0.02, 0.02)] * 3), min_size=n, max_size=n),
    st.sampled_from([0.0, 0.3, 0.7, 1.0]), st.booleans(), st.booleans(),
    st.sampled_from([0.01, 0.05, 0.2, 1.0])))


@settings(max_examples=60, deadline=None)
@given(paths, st.floats(-np.pi, np.pi), st.floats(-1.2, -0.2), st.sampled_from([120, 360, 720]))
def test_drawn_path_within_half_a_pixel(data, yaw, pitch, height) -> None:
    steps, frac, with_last, ortho, scale = data  # scale: steps of 0.1 to 6 px at 360 px
    cam = _camera(yaw, pitch, ortho)
    start = cam.pos + 1.5 * cam.forward
    pts = _path(scale * np.array(steps), start)
    times = np.linspace(0.0, 1.0, len(pts))
    last = pts[min(len(pts) - 1, int(frac * len(pts)))] + 0.003 if with_last else None
    assert _check(pts, times, frac, last, cam, height) <= TOL + 1e-6


def _out_and_back() -> tuple[np.ndarray, SimpleNamespace]:
    """A tool point that moves 0.2 m along the image's x and comes back 0.1 m."""
    cam = _camera(0.4, -0.6, False)
    right = np.cross(cam.forward, cam.up)
    s = np.r_[np.linspace(0, 0.2, 21), np.linspace(0.19, 0.1, 10)]
    pts = cam.pos + 1.5 * cam.forward + s[:, None] * right
    return pts, cam


def test_a_path_that_runs_back_keeps_its_turning_point() -> None:
    pts, cam = _out_and_back()
    times = np.linspace(0, 1, len(pts))
    assert _check(pts, times, 1.0, None, cam, 360) <= TOL + 1e-6


def test_planted_fault_line_distance_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    def line_distance(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        ab = (b - a) / max(float(np.linalg.norm(b - a)), 1e-300)
        rel = q - a
        return np.abs(rel[:, 0] * ab[1] - rel[:, 1] * ab[0])

    monkeypatch.setattr(sp, "segment_distances", line_distance)
    pts, cam = _out_and_back()
    assert _check(pts, np.linspace(0, 1, len(pts)), 1.0, None, cam, 360) > 10 * TOL


def test_planted_fault_wider_tolerance_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sp, "SCREEN_TOL_PX", 4 * TOL)
    cam = _camera(0.4, -0.6, False)
    u = np.linspace(0, 1, 200)
    right = np.cross(cam.forward, cam.up)
    pts = cam.pos + 1.5 * cam.forward + np.outer(0.3 * u, right) + np.outer(
        0.05 * np.sin(6 * np.pi * u), cam.up)
    assert _check(pts, u, 1.0, None, cam, 360) > TOL + 1e-6


def test_a_point_behind_the_camera_keeps_every_vertex() -> None:
    cam = _camera(0.0, -0.5, False)
    pts = cam.pos + np.outer(np.linspace(-1.0, 2.0, 40), cam.forward)
    drawn = ScreenPath(pts, np.linspace(0, 1, 40), lambda p, e: p).upto(
        1.0, camera_key(cam, 360), None)
    assert len(drawn) == 40


def test_a_frame_does_not_depend_on_the_frames_before_it() -> None:
    """Worker processes render different frames first: the same frame must come out the
    same (the cache holds a pure function of the camera pose); a moving camera (on_screen
    False) draws every vertex."""
    cam = _camera(0.3, -0.5, False)
    u = np.linspace(0, 1, 50)
    pts = cam.pos + 1.5 * cam.forward + np.outer(0.2 * u, np.cross(cam.forward, cam.up)) \
        + np.outer(0.01 * np.sin(9 * u), cam.up)
    fixed = camera_key(cam, 360)
    fresh = ScreenPath(pts, u, _lift).upto(0.7, fixed, pts[30] + 0.001)
    path = ScreenPath(pts, u, _lift)
    for k in range(8):
        moved = SimpleNamespace(**{**vars(cam), "pos": cam.pos + 1e-3 * k})
        assert len(path.upto(1.0, camera_key(moved, 360), None, on_screen=False)) == 50
        path.upto(0.2 * (k % 5), camera_key(moved, 360), None)
    assert np.array_equal(path.upto(0.7, fixed, pts[30] + 0.001), fresh)
    assert len(fresh) < 36


def _segments(scene: object, first: int, rgba: tuple[float, ...]) -> list[np.ndarray]:
    """The line geoms of one colour from ``first`` on, as polylines (joined where one
    segment starts at the previous one's end): (M, 3) each."""
    out: list[list[np.ndarray]] = []
    for i in range(first, scene.ngeom):  # type: ignore[attr-defined]
        g = scene.geoms[i]  # type: ignore[attr-defined]
        if not np.allclose(g.rgba, rgba, atol=1e-6):
            continue
        a = np.array(g.pos, float)
        b = a + np.array(g.mat, float).reshape(3, 3)[:, 2] * float(g.size[2])
        if out and np.allclose(out[-1][-1], a, atol=1e-6):
            out[-1].append(b)
        else:
            out.append([a, b])
    return [np.array(p) for p in out]


def test_the_overlay_draws_its_paths_within_the_tolerance(tmp_path, monkeypatch) -> None:
    """PathOverlay.add_to_scene on a real scene: each colour's polyline, simplified on screen,
    within the tolerance of the one drawn without the screen step (SCREEN_TOL_PX = 0)."""
    from sim.render import gl

    gl.configure_gl()
    import mujoco

    from sim.render.overlay import OverlayStyle, PathOverlay
    from sim.render.synthetic import write_synthetic_run
    from sim.simulation.runfolder import load_run

    record = load_run(write_synthetic_run(tmp_path / "run"))
    model = record.load_model()
    data = mujoco.MjData(model)
    style = OverlayStyle()
    for time in (0.3 * record.duration + record.t0, record.t[-1]):
        drawn = {}
        for tol in (0.0, TOL):
            monkeypatch.setattr(sp, "SCREEN_TOL_PX", tol)
            overlay = PathOverlay(record, style, model)
            scene = mujoco.MjvScene(model, maxgeom=model.ngeom + overlay.max_geoms + 10)
            cam = mujoco.MjvCamera()
            cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
            cam.fixedcamid = 0
            mujoco.mj_forward(model, data)
            mujoco.mjv_updateScene(model, data, mujoco.MjvOption(), None, cam,
                                   mujoco.mjtCatBit.mjCAT_ALL, scene)
            first = scene.ngeom
            overlay.add_to_scene(scene, time, 360, fixed_camera=True)
            gcam = scene.camera[0]
            ns = SimpleNamespace(pos=np.array(gcam.pos), forward=np.array(gcam.forward),
                                 up=np.array(gcam.up), frustum_near=gcam.frustum_near,
                                 frustum_bottom=gcam.frustum_bottom,
                                 frustum_top=gcam.frustum_top,
                                 orthographic=bool(gcam.orthographic))
            drawn[tol] = {c: _segments(scene, first, c) for c in
                          (style.reference_rgba, style.actual_rgba, style.bead_rgba)}
        for colour, full in drawn[0.0].items():
            simple = drawn[TOL][colour]
            assert len(simple) == len(full)
            assert sum(map(len, simple)) <= sum(map(len, full))
            for f, s in zip(full, simple, strict=True):
                worst = _worst(_pixels(f, ns, 480, 360), _pixels(s, ns, 480, 360))
                assert worst <= TOL + 1e-6, (colour, worst)
        assert sum(map(len, drawn[TOL][style.reference_rgba])) < sum(
            map(len, drawn[0.0][style.reference_rgba]))  # the screen step dropped vertices
