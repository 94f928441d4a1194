"""The 3D replay of report.html in a real headless browser (Debian's chromium, driven by
Playwright): it loads offline with no console error, draws, puts the robot where the recorded
poses say (pixels checked against mujoco's own kinematics projected with the page's camera
matrices), and a click on the torque chart moves the replay there.

Skipped, with the reason, when chromium or Playwright is missing (``make browser-deps``
installs chromium). One browser per module; the tests on the default scenario's run (shared
through ``scenario_run``) are slow, one on a two-link arm's tiny run is in the fast share.
"""

from __future__ import annotations

import base64
import io
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
SCENARIO = "bugnar_5r_weld_cycle"
BACKGROUND = np.array([0xEE, 0xF1, 0xF5])  # the page's scene background
TOL_PX = 3.0
READY_POLLS = 4000


@pytest.fixture(scope="module")
def browser():
    if CHROMIUM is None:
        pytest.skip("no chromium on this machine (make browser-deps installs Debian's chromium)")
    sync_api = pytest.importorskip("playwright.sync_api",
                                   reason="Playwright is not installed (pip install -e '.[test]')")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=[
            "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"])
        yield b
        b.close()


class Page:
    """One page of a report, offline: every http(s) request is refused and recorded."""

    def __init__(self, browser, path: Path):
        self.ctx = browser.new_context(viewport={"width": 1200, "height": 900},
                                       device_scale_factor=1)
        self.requests: list[str] = []
        self.errors: list[str] = []
        self.ctx.set_default_timeout(0)  # no wall-clock limit (a loaded machine is no failure)
        self.ctx.route("**/*", self._route)
        self.page = self.ctx.new_page()
        self.page.on("console", lambda m: m.type in ("error", "warning")
                     and self.errors.append(f"{m.type}: {m.text}"))
        self.page.on("pageerror", lambda e: self.errors.append(f"pageerror: {e}"))
        start = time.perf_counter()
        self.page.goto(path.resolve().as_uri())
        for _ in range(READY_POLLS):  # bounded by a count of polls
            if self.page.evaluate("!!(window.cellsimReplay && window.cellsimReplay.ready)"):
                break
            if any(e.startswith("pageerror") for e in self.errors):
                raise AssertionError(f"the replay failed to load: {self.errors}")
            self.page.wait_for_timeout(50)
        else:
            raise AssertionError(f"the replay was not ready after {READY_POLLS} polls: "
                                 f"{self.errors}")
        self.load_s = time.perf_counter() - start

    def _route(self, route):
        url = route.request.url
        self.requests.append(url)
        if url.startswith(("http:", "https:")):
            route.abort()
        else:
            route.continue_()

    def js(self, expr: str, arg=None):
        return self.page.evaluate(expr, arg)

    def pixels(self) -> np.ndarray:
        from PIL import Image

        url = self.js("window.cellsimReplay.canvas.toDataURL('image/png')")
        raw = base64.b64decode(url.split(",", 1)[1])
        return np.asarray(Image.open(io.BytesIO(raw)).convert("RGB"), dtype=np.int32)

    def close(self):
        self.ctx.close()


@pytest.fixture(scope="module")
def default_run(scenario_run):
    run_dir, _ = scenario_run(SCENARIO)
    return Path(run_dir)


# ---- the oracle: mujoco's kinematics, projected with the page's camera ------------------------

def _surface_points(model, data, g) -> np.ndarray:
    """World points on geom g's surface whose projected bounding box is its silhouette's (to a
    fraction of a pixel): box corners, cylinder rims, sphere/capsule-cap samples, mesh
    vertices."""
    import mujoco

    s, typ = model.geom_size[g], int(model.geom_type[g])
    k = np.linspace(0, 2 * np.pi, 96, endpoint=False)
    ring = np.stack([np.cos(k), np.sin(k), np.zeros_like(k)], 1)
    n = 400
    i = np.arange(n) + 0.5
    phi, th = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    ball = np.stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)], 1)
    if typ == mujoco.mjtGeom.mjGEOM_BOX:
        local = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * s
    elif typ == mujoco.mjtGeom.mjGEOM_CYLINDER:
        local = np.concatenate([ring * s[0] + [0, 0, h] for h in (-s[1], s[1])])
    elif typ == mujoco.mjtGeom.mjGEOM_CAPSULE:
        local = np.concatenate([ball * s[0] + [0, 0, h] for h in (-s[1], s[1])])
    elif typ == mujoco.mjtGeom.mjGEOM_SPHERE:
        local = ball * s[0]
    elif typ == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        local = ball * s
    elif typ == mujoco.mjtGeom.mjGEOM_MESH:
        m = int(model.geom_dataid[g])
        v0, nv = model.mesh_vertadr[m], model.mesh_vertnum[m]
        local = model.mesh_vert[v0:v0 + nv]
    else:
        return np.zeros((0, 3))
    return data.geom_xpos[g] + local @ data.geom_xmat[g].reshape(3, 3).T


def predicted_bbox(model, qpos, bodies, cam) -> np.ndarray:
    """(x0, y0, x1, y1) in canvas pixels of the named bodies' visible geoms at ``qpos``."""
    import mujoco

    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    ids = {mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in bodies}
    pts = np.concatenate([_surface_points(model, data, g) for g in range(model.ngeom)
                          if model.geom_bodyid[g] in ids and model.geom_group[g] < 3
                          and model.geom_rgba[g][3] > 0])
    proj = np.array(cam["projection"]).reshape(4, 4).T  # three.js stores column-major
    view = np.array(cam["view"]).reshape(4, 4).T
    clip = (proj @ view @ np.c_[pts, np.ones(len(pts))].T).T
    ndc = clip[:, :3] / clip[:, 3:4]
    x = (ndc[:, 0] + 1) / 2 * cam["width"]
    y = (1 - ndc[:, 1]) / 2 * cam["height"]
    box = np.array([x.min(), y.min(), x.max(), y.max()])
    return np.clip(box, 0, [cam["width"], cam["height"]] * 2)  # what the canvas can show


def drawn_bbox(img: np.ndarray) -> np.ndarray:
    mask = np.abs(img - BACKGROUND).sum(axis=2) > 40
    ys, xs = np.nonzero(mask)
    assert xs.size, "nothing drawn"
    return np.array([xs.min(), ys.min(), xs.max() + 1, ys.max() + 1], float)


def _robot_setup(page: Page, model, qpos0):
    """Only the moving bodies drawn, the camera close to those with a drawn geom (aimed by
    mujoco's kinematics; a massless payload's invisible marker does not move the aim)."""
    import mujoco

    from sim.analysis.replay.scene import geoms_and_meshes

    moving = page.js("window.cellsimReplay.movingBodies")
    page.js("(b) => window.cellsimReplay.solo(b)", moving)
    data = mujoco.MjData(model)
    data.qpos[:] = qpos0
    mujoco.mj_kinematics(model, data)
    drawn = {g["body"] for g in geoms_and_meshes(model)[0]}
    ids = [i for i in (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in moving)
           if i in drawn]
    target = data.xpos[ids].mean(axis=0)
    eye = target + [2.4, -2.7, 1.5]
    page.js("(a) => window.cellsimReplay.look(a[0], a[1], 45)", [eye.tolist(), target.tolist()])
    return moving


def _fastest_frames(page: Page, t, tcp, count=2):
    """Display-frame times where the tool point moves fastest, apart from each other."""
    ft = np.array(page.js("window.cellsimReplay.frameTimes()"))
    idx = np.clip(np.searchsorted(t, ft - 1e-6), 0, t.size - 1)
    step = np.linalg.norm(np.diff(tcp[idx], axis=0), axis=1)
    order = np.argsort(-step)
    picked: list[int] = []
    for i in order:
        if all(abs(ft[i] - ft[j]) > 2.0 for j in picked):
            picked.append(int(i))
        if len(picked) == count:
            break
    return [float(ft[i]) for i in picked]


def _bbox_error(page: Page, model, t, qpos, bodies, when: float) -> tuple[float, np.ndarray]:
    got_t = page.page.evaluate("(x) => window.cellsimReplay.setTime(x)", when)
    i = int(np.argmin(np.abs(t - got_t)))
    assert abs(t[i] - got_t) < 1e-4
    cam = page.js("window.cellsimReplay.camera()")
    want = predicted_bbox(model, qpos[i], bodies, cam)
    got = drawn_bbox(page.pixels())
    return float(np.abs(want - got).max()), want


@pytest.mark.slow
def test_default_report_loads_offline_draws_and_stays_under_10_mb(browser, default_run):
    report = default_run / "report.html"
    size_mb = report.stat().st_size / 1e6
    assert size_mb < 10, size_mb
    page = Page(browser, report)
    try:
        assert page.errors == []
        assert all(u.startswith(("file:", "data:")) for u in page.requests), page.requests
        img = page.pixels()
        assert img.shape[0] > 100 and img.shape[1] > 100
        assert (np.abs(img - BACKGROUND).sum(axis=2) > 40).mean() > 0.01, "blank canvas"
        print(f"report.html {size_mb:.2f} MB, loaded in {page.load_s:.2f} s")
    finally:
        page.close()


def _recorded(run_dir: Path):
    import mujoco

    z = np.load(run_dir / "trajectory.npz")
    model = mujoco.MjModel.from_xml_path(str(run_dir / "model.xml"))
    return model, z["t"], z["qpos"], z["tcp_pos"]


@pytest.mark.slow
def test_two_slider_positions_draw_the_robot_where_the_recorded_poses_put_it(browser,
                                                                                 default_run):
    model, t, qpos, tcp = _recorded(default_run)
    page = Page(browser, default_run / "report.html")
    try:
        bodies = _robot_setup(page, model, qpos[0])
        t1, t2 = _fastest_frames(page, t, tcp)
        e1, want1 = _bbox_error(page, model, t, qpos, bodies, t1)
        img1 = page.pixels()
        e2, want2 = _bbox_error(page, model, t, qpos, bodies, t2)
        img2 = page.pixels()
        assert e1 <= TOL_PX and e2 <= TOL_PX, (e1, e2)
        assert np.abs(want1 - want2).max() > 5 * TOL_PX  # the two positions differ visibly
        assert (np.abs(img1 - img2).sum(axis=2) > 40).sum() > 100
        assert page.errors == []
    finally:
        page.close()


@pytest.mark.slow
def test_planted_faults_are_caught_by_the_pixel_check(browser, default_run, tmp_path):
    """Poses shifted by one display frame, and two bodies' poses swapped: the drawn robot is
    no longer where the recorded poses put it."""
    from sim.analysis.replay import build_payload
    from sim.analysis.replay.page import replay_section
    from sim.simulation.runfolder import load_run

    model, t, qpos, tcp = _recorded(default_run)
    rec = load_run(default_run)
    payload = build_payload(model, rec.arrays, rec.summary, list(rec.joints))
    fr = payload["frames"]
    nb = len(fr["bodies"])

    def f32(o):
        return np.frombuffer(base64.b64decode(o["f32"]), "<f4").copy()

    def enc(a):
        return {"f32": base64.b64encode(a.astype("<f4").tobytes()).decode()}

    pos, quat = f32(fr["pos"]).reshape(-1, nb, 3), f32(fr["quat"]).reshape(-1, nb, 4)
    faults = {"shifted": (np.roll(pos, 1, axis=0), np.roll(quat, 1, axis=0)),
              "swapped": (pos[:, ::-1], quat[:, ::-1])}
    for name, (p, q) in faults.items():
        bad = dict(payload, frames=dict(fr, pos=enc(p), quat=enc(q)))
        path = tmp_path / f"{name}.html"
        path.write_text(f"<!DOCTYPE html><html><body>{replay_section(bad)}</body></html>")
        page = Page(browser, path)
        try:
            bodies = _robot_setup(page, model, qpos[0])
            t1 = _fastest_frames(page, t, tcp, 1)[0]
            err, _ = _bbox_error(page, model, t, qpos, bodies, t1)
            assert err > TOL_PX, (name, err)
        finally:
            page.close()


@pytest.mark.slow
def test_a_click_on_the_torque_chart_moves_the_replay_there(browser, default_run):
    page = Page(browser, default_run / "report.html")
    try:
        fps = page.js("window.cellsimReplay.fps")
        page.page.locator('[data-chart="torque"]').scroll_into_view_if_needed()
        for frac in (0.2, 0.71):
            c = page.js("window.cellsimReplay.chart('torque')")
            x = round(c["left"] + frac * c["width"])  # a whole pixel, as a user clicks
            want = c["min"] + (x - c["left"]) / c["width"] * (c["max"] - c["min"])
            page.page.mouse.click(x, round(c["top"] + c["height"] / 2))
            got = page.js("window.cellsimReplay.time()")
            assert abs(got - want) <= 1 / fps, (got, want, fps)
            slider = float(page.page.locator("input.replay-slider").input_value())
            assert abs(slider - got) < 1e-6
        assert page.errors == []
    finally:
        page.close()


def test_a_tiny_run_replays_offline_with_the_arm_where_its_poses_put_it(browser, tmp_path):
    """The fast share's browser check: a two-link arm's run (written here), viewed."""
    import mujoco
    from test_replay import ARM

    from sim.cli import main

    run = tmp_path / "run"
    run.mkdir()
    (run / "model.xml").write_text(ARM)
    t = np.linspace(0, 2, 201)
    qpos = np.c_[1.5 * t, -t]
    np.savez(run / "trajectory.npz", t=t, qpos=qpos, q=qpos, qd=np.ones_like(qpos), tau=qpos)
    assert main(["view", str(run)]) == 0
    model = mujoco.MjModel.from_xml_string(ARM)
    page = Page(browser, run / "report.html")
    try:
        assert page.errors == []
        assert all(u.startswith(("file:", "data:")) for u in page.requests), page.requests
        bodies = _robot_setup(page, model, qpos[0])
        assert sorted(bodies) == ["l1", "l2", "tip"]  # tip: only a hidden (group 3) geom
        boxes = [_bbox_error(page, model, t, qpos, bodies, when) for when in (0.4, 1.6)]
        assert all(err <= TOL_PX for err, _ in boxes), boxes
        assert np.abs(boxes[0][1] - boxes[1][1]).max() > 5 * TOL_PX
    finally:
        page.close()


def _gold(img: np.ndarray) -> np.ndarray:
    """Pixels of the bead's colour (0xd4a017, lit): red and green well above blue."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return (r > 110) & (r >= g) & (g - b > 40) & (r - b > 70)


def test_the_bead_is_a_tube_laid_up_to_the_replays_time(browser, tmp_path):
    """The bead (arc on) is drawn as a tube of the weld's width, not a hairline, along the
    recorded tool points up to the time shown and not beyond; before the arc starts there is
    none. The oracle: the recorded points projected with the page's camera matrices."""
    from test_replay import ARM

    from sim.cli import main

    run = tmp_path / "run"
    run.mkdir()
    (run / "model.xml").write_text(ARM)
    t = np.linspace(0, 2, 201)
    qpos = np.c_[0.2 * t, -0.1 * t]
    tcp = np.c_[0.2 + 0.2 * t, 0.05 * np.sin(2 * t), np.full_like(t, 0.1)]
    arc = (t >= 0.5) & (t <= 1.5)
    np.savez(run / "trajectory.npz", t=t, qpos=qpos, q=qpos, qd=qpos, tau=qpos,
             tcp_pos=tcp, arc_on=arc)
    assert main(["view", str(run)]) == 0
    page = Page(browser, run / "report.html")
    try:
        page.js("window.cellsimReplay.solo([], true)")  # the overlays alone
        target = np.array([0.4, 0.0, 0.1])
        page.js("(a) => window.cellsimReplay.look(a[0], a[1], 45)",
                [(target + [0.0, -0.2, 0.1]).tolist(), target.tolist()])
        before = page.page.evaluate("(x) => window.cellsimReplay.setTime(x)", 0.3)
        assert before < 0.5 and not _gold(page.pixels()).any()
        now = page.page.evaluate("(x) => window.cellsimReplay.setTime(x)", 1.0)
        gold = _gold(page.pixels())
        cam = page.js("window.cellsimReplay.camera()")
        proj = np.array(cam["projection"]).reshape(4, 4).T
        view = np.array(cam["view"]).reshape(4, 4).T

        def px(p):
            clip = (proj @ view @ np.c_[p, np.ones(len(p))].T).T
            ndc = clip[:, :3] / clip[:, 3:4]
            return np.c_[(ndc[:, 0] + 1) / 2 * cam["width"], (1 - ndc[:, 1]) / 2 * cam["height"]]

        laid = px(tcp[(t >= 0.55) & (t <= now - 0.05)])
        ahead = px(tcp[(t >= now + 0.1) & (t <= 1.45)])
        assert all(gold[int(y), int(x)] for x, y in laid), "the bead laid so far is missing"
        assert not any(gold[max(0, int(y) - 1):int(y) + 2, max(0, int(x) - 1):int(x) + 2].any()
                       for x, y in ahead), "bead drawn ahead of the replay's time"
        # its width on screen: the tube's 6 mm diameter projected at the middle point
        mid = tcp[np.argmin(np.abs(t - 0.75))]
        d = float(np.linalg.norm((view @ np.r_[mid, 1.0])[:3]))
        want = 0.006 * cam["height"] / 2 / np.tan(np.radians(45) / 2) / d
        x, y = px(mid[None])[0]
        column = gold[:, int(round(x))]
        rows = np.nonzero(column[int(y) - 3 * int(want):int(y) + 3 * int(want) + 1])[0]
        assert want > 10 and rows.size >= 0.6 * want, (rows.size, want)  # a hairline: 1-2 px
        assert page.errors == []
    finally:
        page.close()
