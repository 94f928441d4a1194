"""Headless rendering: backend choice, state interpolation, overlays, frames, run folders.

Uses the synthetic run folder of :mod:`sim.render.synthetic` (demo 4R arm, a free-joint part,
cameras ``overview`` and ``tool``), so nothing here depends on the robot models.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp
from support.limits import run_limited

import sim.render.gl as gl
from sim.errors import RenderError
from sim.render.interp import QposInterpolator, slerp
from sim.render.overlay import (
    OverlayStyle,
    PathOverlay,
    caption_text,
    draw_caption,
    simplify_polyline,
)
from sim.render.synthetic import JOINTS, write_synthetic_run
from sim.simulation.runfolder import RunFolderError, RunRecord, load_run

REPO = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    gl.configure_gl()
    return write_synthetic_run(tmp_path_factory.mktemp("render") / "run", duration=2.0)


def _mujoco():
    gl.configure_gl()
    import mujoco

    return mujoco


def _red(img: np.ndarray) -> np.ndarray:
    """Pixels of the actual-path red (R high, G and B low and alike), bool (H, W)."""
    im = img.astype(int)
    r, g, b = im[..., 0], im[..., 1], im[..., 2]
    return (r - np.maximum(g, b) > 100) & (np.abs(g - b) < 50)


def _green(img: np.ndarray) -> np.ndarray:
    im = img.astype(int)
    return im[..., 1] - np.maximum(im[..., 0], im[..., 2]) > 80


def _orange(img: np.ndarray) -> np.ndarray:
    """Bead orange: R high, G in between, B low."""
    im = img.astype(int)
    r, g, b = im[..., 0], im[..., 1], im[..., 2]
    return (r > 150) & (g - b > 40) & (r - g > 40)


def _subprocess_env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    return env


# ----------------------------------------------------------------------------- backends


def test_at_least_one_backend_works() -> None:
    available = gl.available_backends()
    assert available, "no headless OpenGL backend works (EGL works on this machine's Mesa)"
    assert set(available) <= set(gl.BACKENDS)
    assert gl.configure_gl() in available
    assert gl.active_backend() == gl.configure_gl()
    assert os.environ["MUJOCO_GL"] == gl.active_backend()


def test_probe_is_cached_per_process() -> None:
    first = gl.probe_backend("egl")
    assert gl.probe_backend("EGL") is first


def test_unknown_backend_name_lists_choices() -> None:
    with pytest.raises(RenderError, match="unknown OpenGL backend 'vulkan'.*egl, osmesa"):
        gl.configure_gl("vulkan")


def test_no_working_backend_says_what_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    failed = {name: gl.ProbeResult(name, False, f"lib{name} not found") for name in gl.BACKENDS}
    monkeypatch.setattr(gl, "_probe_cache", failed)
    monkeypatch.setattr(gl, "_configured", None)
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    with pytest.raises(RenderError) as info:
        gl.configure_gl()
    message = str(info.value)
    assert "\n" not in message
    assert "no headless OpenGL backend works" in message
    assert "apt-get install libegl1" in message and "apt-get install libosmesa6" in message
    with pytest.raises(RenderError, match="'osmesa' OpenGL backend does not work.*libosmesa6"):
        gl.configure_gl("osmesa")


def test_backend_is_switched_when_mujoco_was_imported_first() -> None:
    """mujoco imported with MUJOCO_GL unset binds GLFW; configure_gl rebinds it to EGL/OSMesa."""
    code = (
        "import mujoco, sim.render.gl\n"
        "before = mujoco.rendering.classic.gl_context.GLContext.__module__\n"
        "name = sim.render.gl.configure_gl()\n"
        "after = mujoco.rendering.classic.gl_context.GLContext.__module__\n"
        "m = mujoco.MjModel.from_xml_string('<mujoco><worldbody><light pos=\"0 0 2\"/>"
        "<geom type=\"sphere\" size=\".1\"/></worldbody></mujoco>')\n"
        "d = mujoco.MjData(m); mujoco.mj_forward(m, d)\n"
        "with mujoco.Renderer(m, 32, 32) as r:\n"
        "    r.update_scene(d); img = r.render()\n"
        "print(before, name, after, int(img.max()))\n"
    )
    env = _subprocess_env()
    env.pop("MUJOCO_GL", None)
    env.pop("PYOPENGL_PLATFORM", None)
    proc = run_limited([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          cpu_s=300, check=False)
    assert proc.returncode == 0, proc.stderr
    before, name, after, peak = proc.stdout.split()
    assert before == "mujoco.glfw"
    assert name in gl.BACKENDS and after == f"mujoco.{name}"
    assert int(peak) > 0
    assert "Exception ignored" not in proc.stderr


def test_pyopengl_bound_elsewhere_is_reported_clearly() -> None:
    code = (
        "import OpenGL.platform, mujoco, sim.render.gl\n"
        "from sim.errors import RenderError\n"
        "try:\n"
        "    sim.render.gl.configure_gl()\n"
        "except RenderError as exc:\n"
        "    print(exc)\n"
    )
    env = _subprocess_env()
    env.pop("MUJOCO_GL", None)
    env["PYOPENGL_PLATFORM"] = "glx"
    proc = run_limited([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          cpu_s=300, check=False)
    assert proc.returncode == 0, proc.stderr
    assert "already imported with MUJOCO_GL='glfw'" in proc.stdout
    assert "PyOpenGL is already bound to the 'glx' platform" in proc.stdout


# ------------------------------------------------------------------------ interpolation


def _interp_model():
    mujoco = _mujoco()
    xml = """<mujoco><worldbody>
      <body name="a"><freejoint/><geom size=".1"/></body>
      <body name="b"><joint name="h" type="hinge"/><joint name="s" type="slide"/>
        <geom size=".1"/><body><joint type="ball"/><geom size=".1"/></body></body>
    </worldbody></mujoco>"""
    return mujoco.MjModel.from_xml_string(xml)


def test_qpos_interpolation_lerp_and_slerp_match_scipy() -> None:
    model = _interp_model()
    assert model.nq == 7 + 1 + 1 + 4
    rng = np.random.default_rng(3)
    t = np.array([0.0, 0.4, 1.0])
    rots = Rotation.random(3, random_state=5)
    balls = Rotation.random(3, random_state=6)
    qpos = np.zeros((3, model.nq))
    qpos[:, 0:3] = rng.normal(size=(3, 3))
    qpos[:, 3:7] = np.roll(rots.as_quat(), 1, axis=1)  # scipy (x, y, z, w) -> MuJoCo (w, x, y, z)
    qpos[1, 3:7] *= -1.0  # same rotation, opposite sign: the interpolation must take the short arc
    qpos[:, 7:9] = rng.normal(size=(3, 2))
    qpos[:, 9:13] = np.roll(balls.as_quat(), 1, axis=1)
    interp = QposInterpolator(model, t, qpos)
    free_slerp = Slerp(t, rots)
    ball_slerp = Slerp(t, balls)
    for time in (0.1, 0.25, 0.4, 0.77):
        got = interp(time)
        for lin in (slice(0, 3), slice(7, 9)):
            cols = range(lin.start, lin.stop)
            expected = np.array([np.interp(time, t, qpos[:, i]) for i in cols])
            np.testing.assert_allclose(got[lin], expected, atol=1e-12)
        for sl, ref in ((slice(3, 7), free_slerp), (slice(9, 13), ball_slerp)):
            q = got[sl]
            assert abs(np.linalg.norm(q) - 1.0) < 1e-12
            angle = (Rotation.from_quat(np.roll(q, -1)) * ref([time]).inv()).magnitude()
            assert angle[0] < 1e-9
    np.testing.assert_array_equal(interp(-1.0), qpos[0])
    np.testing.assert_array_equal(interp(5.0), qpos[-1])
    with pytest.raises(ValueError, match="nq"):
        QposInterpolator(model, t, qpos[:, :-1])


def test_slerp_midpoint_halves_the_rotation_angle() -> None:
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    angle = 2.0
    q1 = np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])
    mid = slerp(np.array([1.0, 0, 0, 0]), q1, 0.5)
    expected = np.concatenate([[np.cos(angle / 4)], np.sin(angle / 4) * axis])
    np.testing.assert_allclose(mid, expected, atol=1e-12)
    # nearly equal quaternions: the normalized-lerp branch stays a unit quaternion
    q2 = np.array([1.0, 1e-5, 0.0, 0.0])
    assert abs(np.linalg.norm(slerp(np.array([1.0, 0, 0, 0]), q2, 0.3)) - 1.0) < 1e-12


# ------------------------------------------------------------------------------ frames


def test_kinematic_state_matches_mj_forward(run_dir: Path) -> None:
    """The positions-only stages give the visualiser the same poses as a full mj_forward."""
    from sim.render.frames import FrameRenderer

    mujoco = _mujoco()
    with FrameRenderer(run_dir, width=64, height=48) as fr:
        fr.set_state(0.937)
        ref = mujoco.MjData(fr.model)
        ref.qpos[:] = fr.data.qpos
        mujoco.mj_forward(fr.model, ref)
        for name in ("xpos", "xmat", "geom_xpos", "geom_xmat", "site_xpos", "cam_xpos",
                     "cam_xmat", "light_xpos"):
            np.testing.assert_allclose(getattr(fr.data, name), getattr(ref, name), atol=1e-12,
                                       err_msg=name)


def test_unknown_camera_lists_the_models_cameras(run_dir: Path) -> None:
    from sim.render.frames import FrameRenderer

    message = r"unknown camera 'top'; the model's cameras: overview, tool"
    with pytest.raises(RenderError, match=message):
        FrameRenderer(run_dir, cameras=("overview", "top"), width=64, height=48)


@pytest.mark.parametrize(
    ("width", "height", "match"),
    [(161, 120, "width must be even"), (160, 121, "height must be even"),
     (8, 120, "between 16 and"), (160.0, 120, "integer")],
)
def test_bad_sizes_are_rejected(run_dir: Path, width, height, match: str) -> None:
    from sim.render.frames import FrameRenderer

    with pytest.raises(RenderError, match=match):
        FrameRenderer(run_dir, width=width, height=height)


def test_small_offscreen_buffer_is_enlarged(run_dir: Path) -> None:
    """A model whose <global offwidth offheight> is smaller than the frame still renders."""
    from sim.render.frames import FrameRenderer

    record = load_run(run_dir)
    record.model_xml = record.model_path.read_text().replace(
        'offwidth="1280" offheight="720"', 'offwidth="64" offheight="48"')
    assert 'offwidth="64"' in record.model_xml
    with FrameRenderer(record, width=160, height=120, caption=False) as fr:
        img = fr.render(1.0)
        assert img.shape == (120, 160, 3)
        assert img.std() > 10.0


def test_trails_and_bead_are_drawn_in_the_scene(run_dir: Path) -> None:
    """Red actual path grows, green reference is whole from the start, the bead appears
    only once the arc is on; none of these colours exists in the cell without overlay."""
    from sim.render.frames import FrameRenderer

    record = load_run(run_dir)
    weld = next(p for p in record.phases if p.name == "weld")
    kw = dict(width=200, height=150, caption=False)
    with FrameRenderer(run_dir, overlay=False, **kw) as bare:
        plain = [bare.render(t) for t in (0.0, weld.t1, record.t[-1])]
    for img in plain:
        assert _red(img).sum() == 0 and _green(img).sum() == 0 and _orange(img).sum() == 0
    with FrameRenderer(run_dir, **kw) as fr:
        start = fr.render(0.0)
        before_arc = fr.render(weld.t0 - 0.05)
        after_weld = fr.render(weld.t1)
        end = fr.render(record.t[-1])
    assert _green(start).sum() > 30  # the whole planned path is shown from t = 0
    assert _red(start).sum() == 0  # nothing travelled yet
    assert _orange(before_arc).sum() == 0
    assert _orange(after_weld).sum() > 20
    assert _red(end).sum() > _red(before_arc).sum() > 10


def test_overlay_geoms_are_bounded(run_dir: Path) -> None:
    mujoco = _mujoco()
    record = load_run(run_dir)
    overlay = PathOverlay(record, OverlayStyle(max_segments=6))
    assert len(overlay.reference) <= 7 and len(overlay.actual) <= 7
    model = record.load_model()
    data = mujoco.MjData(model)
    data.qpos[:] = record.get("qpos")[-1]
    mujoco.mj_forward(model, data)
    scene = mujoco.MjvScene(model, maxgeom=model.ngeom + 5)  # room for 5 overlay geoms only
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
    cam.fixedcamid = 0
    mujoco.mjv_updateScene(model, data, mujoco.MjvOption(), None, cam,
                           mujoco.mjtCatBit.mjCAT_ALL, scene)
    before = scene.ngeom
    added = overlay.add_to_scene(scene, record.t[-1], 120)
    assert added == scene.ngeom - before <= 5
    assert scene.ngeom <= scene.maxgeom
    assert overlay.max_geoms >= added


def test_polyline_simplification_stays_within_tolerance() -> None:
    line = np.linspace([0.0, 0.0, 0.0], [1.0, 2.0, 3.0], 500)
    np.testing.assert_array_equal(simplify_polyline(line, 1e-6, 100), [0, 499])
    s = np.linspace(0.0, 2 * np.pi, 2000)
    helix = np.stack([0.3 * np.cos(s), 0.3 * np.sin(s), 0.05 * s], axis=1)
    tol = 0.001
    idx = simplify_polyline(helix, tol, 1000)
    assert idx[0] == 0 and idx[-1] == len(helix) - 1 and np.all(np.diff(idx) > 0)
    # every dropped point lies within tol of its chord (brute-force point-segment distance)
    for a, b in zip(idx[:-1], idx[1:]):
        p, q = helix[a], helix[b]
        pts = helix[a:b + 1]
        u = np.clip((pts - p) @ (q - p) / np.dot(q - p, q - p), 0.0, 1.0)
        dist = np.linalg.norm(pts - (p + u[:, None] * (q - p)), axis=1)
        assert dist.max() <= tol + 1e-12
    # A chord spanning angle d on radius r has sagitta r (1 - cos(d/2)) <= tol, so one turn
    # needs at least 2 pi / d_max chords; Douglas-Peucker halves arcs, so at most twice that.
    fewest = 2 * np.pi / (2 * np.arccos(1 - tol / 0.3))
    assert 0.95 * fewest <= len(idx) - 1 <= 2.0 * fewest
    capped = simplify_polyline(helix, tol, 10)
    assert len(capped) <= 10


def test_tiled_cameras_are_side_by_side(run_dir: Path) -> None:
    from sim.render.frames import FrameRenderer

    kw = dict(width=96, height=64, caption=False)
    with FrameRenderer(run_dir, cameras=("overview", "tool"), **kw) as both:
        tiled = both.render(1.1).copy()
    with FrameRenderer(run_dir, cameras=("overview",), **kw) as one:
        left = one.render(1.1).copy()
    with FrameRenderer(run_dir, cameras=("tool",), **kw) as one:
        right = one.render(1.1).copy()
    assert tiled.shape == (64, 192, 3)
    np.testing.assert_array_equal(tiled[:, :96], left)
    np.testing.assert_array_equal(tiled[:, 96:], right)
    assert np.abs(left.astype(int) - right.astype(int)).mean() > 5  # two different views


@pytest.mark.parametrize(("fps", "expected"), [(10.0, 21), (30.0, 61), (7.0, 15), (29.97, 60)])
def test_frame_count_is_floor_duration_times_fps_plus_one(run_dir: Path, fps: float,
                                                          expected: int) -> None:
    from sim.render.frames import FrameRenderer

    with FrameRenderer(run_dir, width=32, height=32) as fr:
        times = fr.frame_times(fps)
    assert len(times) == expected == int(np.floor(2.0 * fps + 1e-9)) + 1
    np.testing.assert_allclose(np.diff(times), 1.0 / fps)
    assert times[0] == 0.0 and times[-1] <= 2.0


@pytest.mark.parametrize(("fps", "speed", "expected"), [(12.0, 4.0, 7), (3.0, 1.0, 7),
                                                      (10.0, 0.5, 41), (30.0, 3.0, 21)])
def test_a_time_lapse_takes_a_frame_every_speed_over_fps_seconds(run_dir: Path, fps: float,
                                                                  speed: float,
                                                                  expected: int) -> None:
    """Playback ``speed`` (simulated seconds per second of video): the 2 s run's frames lie
    ``speed / fps`` apart, ``floor(2 fps / speed) + 1`` of them; speed 1 is the plain video."""
    from sim.render.frames import FrameRenderer

    with FrameRenderer(run_dir, width=32, height=32) as fr:
        times = fr.frame_times(fps, speed)
        plain = fr.frame_times(fps)
        assert np.array_equal(fr.frame_times(fps, 1.0), plain)
    assert len(times) == expected == int(np.floor(2.0 * fps / speed + 1e-9)) + 1
    np.testing.assert_allclose(np.diff(times), speed / fps)
    assert times[0] == 0.0 and times[-1] <= 2.0


def test_the_shadow_map_is_sized_to_the_tile_and_never_above_the_model():
    """Twice the tile's longer side, a power of two, capped by the model's own map."""
    from sim.render.frames import shadow_size

    for w, h in ((320, 240), (480, 360), (640, 480), (1280, 720), (1920, 1080), (16, 16)):
        side = shadow_size(w, h, 4096)
        assert side & (side - 1) == 0 and side <= 4096
        assert side >= min(4096, 2 * max(w, h)) and (side == 256 or side < 4 * max(w, h)
                                                     or side == 4096)
    assert shadow_size(480, 360, 512) == 512


def test_bad_fps_is_rejected(run_dir: Path) -> None:
    from sim.render.frames import FrameRenderer

    with FrameRenderer(run_dir, width=32, height=32) as fr:
        for fps in (0.0, -5.0, float("nan")):
            with pytest.raises(RenderError, match="fps must be a positive"):
                fr.frame_times(fps)
        for speed in (0.0, -1.0, float("nan"), float("inf")):
            with pytest.raises(RenderError, match="playback speed must be a positive"):
                fr.frame_times(10.0, speed)


# ----------------------------------------------------------------------------- caption


def test_caption_names_phase_and_largest_torque(run_dir: Path) -> None:
    record = load_run(run_dir)
    tau = record.get("tau")
    for time in (0.123, 0.95, 1.77):
        row = np.array([np.interp(time, record.t, tau[:, j]) for j in range(tau.shape[1])])
        j = int(np.argmax(np.abs(row)))
        phase = next(p.name for p in record.phases if p.t0 <= time < p.t1)
        text = caption_text(record, time)
        assert f"t={time:6.2f} s" in text
        assert phase in text
        assert f"{JOINTS[j]} {abs(row[j]):6.1f} N m" in text
        weld = next(p for p in record.phases if p.name == "weld")
        assert ("ARC" in text) == (weld.t0 <= time <= weld.t1)


def test_caption_only_touches_the_top_strip() -> None:
    frame = np.full((120, 160, 3), 200, np.uint8)
    draw_caption(frame, "t=  1.00 s  weld  |tau|max j2   12.0 N m")
    changed = np.any(frame != 200, axis=2)
    rows = np.flatnonzero(changed.any(axis=1))
    assert rows.size and rows.max() < 120 * 0.15
    assert (frame[rows.max() + 1:] == 200).all()
    assert (frame[: rows.max() + 1] == 255).any()  # white text drawn


# --------------------------------------------------------------------------- run folders


def test_missing_or_incomplete_run_folder(tmp_path: Path, run_dir: Path) -> None:
    with pytest.raises(RunFolderError, match="does not exist"):
        load_run(tmp_path / "nope")
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(RunFolderError, match="lacks model.xml, trajectory.npz"):
        load_run(empty)
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / "model.xml").write_text((run_dir / "model.xml").read_text())
    (broken / "trajectory.npz").write_bytes(b"not a zip")
    with pytest.raises(RunFolderError, match="trajectory.npz does not load"):
        load_run(broken)


def test_summary_is_optional_and_joints_default_to_j1_jn(tmp_path: Path, run_dir: Path) -> None:
    folder = tmp_path / "nosummary"
    folder.mkdir()
    for name in ("model.xml", "trajectory.npz"):
        (folder / name).write_bytes((run_dir / name).read_bytes())
    record = load_run(folder)
    assert record.joints == ["j1", "j2", "j3", "j4"]
    assert record.phases == []
    (folder / "summary.json").write_text(json.dumps({"joints": "j1"}))
    with pytest.raises(RunFolderError, match="'joints' must be a list"):
        load_run(folder)


def test_inconsistent_arrays_are_reported(run_dir: Path) -> None:
    from sim.render.frames import FrameRenderer

    base = load_run(run_dir)
    arrays = dict(base.arrays)
    arrays["qpos"] = arrays["qpos"][:, :-1]
    record = RunRecord.from_arrays(arrays, joints=base.joints, model_path=base.model_path)
    message = r"'qpos' has shape \(201, 10\) but model.xml has nq=11"
    with pytest.raises(RunFolderError, match=message):
        FrameRenderer(record, width=32, height=32)
    bad_t = dict(base.arrays)
    bad_t["t"] = bad_t["t"][::-1].copy()
    with pytest.raises(RunFolderError, match="strictly increasing"):
        RunRecord.from_arrays(bad_t, joints=base.joints, model_path=base.model_path)
    short = dict(base.arrays)
    short["tau"] = short["tau"][:, :2]
    with pytest.raises(RunFolderError, match=r"'tau' has shape \(201, 2\), expected \(N, 4\)"):
        RunRecord.from_arrays(short, joints=base.joints, model_path=base.model_path)
