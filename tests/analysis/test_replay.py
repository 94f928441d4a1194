"""The 3D replay's data (sim.analysis.replay) without a browser: decimation keeps peaks and
bounds, body poses match a hand-written planar-arm kinematics, the page is one self-contained
section that ``cellsim view`` puts into report.html, with no OpenGL; the default run's report
stays under 10 MB. The browser checks are in test_replay_browser.py."""

from __future__ import annotations

import base64
import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.limits import run_limited

from sim.analysis.replay.page import BEGIN, END, VENDOR, replay_section, with_replay
from sim.analysis.replay.payload import build_payload
from sim.analysis.replay.scene import frame_indices
from sim.analysis.replay.series import minmax_bins

ARM = """<mujoco><worldbody><geom type="plane" size="1 1 0.1"/>
<body name="l1"><joint name="a" type="hinge" axis="0 0 1"/>
  <geom type="box" size="0.25 0.02 0.02" pos="0.25 0 0" rgba="1 0 0 1"/>
  <body name="l2" pos="0.5 0 0"><joint name="b" type="hinge" axis="0 0 1"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/>
    <body name="tip" pos="0.3 0 0"><geom type="sphere" size="0.01" group="3"/></body>
  </body></body>
<camera name="top" pos="0 0 3"/></worldbody></mujoco>"""


def _f32(o):
    return np.frombuffer(base64.b64decode(o["f32"]), "<f4")


def _arm_oracle(q1, q2):
    """World positions of l1, l2, tip of the planar arm (written here, not by mujoco)."""
    l2 = np.array([0.5 * np.cos(q1), 0.5 * np.sin(q1), 0.0])
    tip = l2 + [0.3 * np.cos(q1 + q2), 0.3 * np.sin(q1 + q2), 0.0]
    return np.array([[0.0, 0.0, 0.0], l2, tip])


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=5000),
       st.integers(1, 300))
def test_minmax_bins_keep_every_peak_and_the_time_order(values, columns):
    y = np.array(values)
    t = np.arange(y.size) * 0.01
    x, yy = minmax_bins(t, y[:, None], columns)
    assert yy.max() == y.max() and yy.min() == y.min()
    assert np.all(np.diff(x) >= 0) and x[0] == t[0] and x[-1] == t[-1]
    assert x.size <= max(2 * columns, y.size)


@settings(max_examples=40, deadline=None)
@given(st.floats(0.5, 400), st.floats(1, 60), st.integers(2, 5000))
def test_frames_are_bounded_include_both_ends_and_follow_the_rate(duration, fps, budget):
    t = np.linspace(0, duration, int(duration * 200) + 1)
    idx = frame_indices(t, fps, budget)
    assert idx[0] == 0 and idx[-1] == t.size - 1 and np.all(np.diff(idx) > 0)
    assert idx.size <= budget
    assert idx.size <= max(2, int(duration * fps) + 1)


def _arm_payload(qpos, t):
    import mujoco

    model = mujoco.MjModel.from_xml_string(ARM)
    arrays = {"t": t, "qpos": qpos, "q": qpos, "q_ref": qpos + 0.01,
              "qd": np.gradient(qpos, t, axis=0), "tau": np.sin(qpos),
              "tcp_pos": np.zeros((t.size, 3)), "arc_on": t > t[-1] / 2}
    summary = {"scenario": "arm", "phases": [{"name": "p", "t0": 0.0, "t1": float(t[-1])}],
               "collisions": [{"t0": 0.1, "t1": 0.2, "bodies": ["l1", "l2"],
                               "geoms": ["", ""]}]}
    return model, build_payload(model, arrays, summary, ["a", "b"], fps=10)


@settings(max_examples=10, deadline=None)
@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3))
def test_body_poses_at_the_frames_are_the_recorded_poses(a0, a1, b0, b1):
    t = np.linspace(0, 2, 201)
    qpos = np.c_[np.linspace(a0, a1, t.size), np.linspace(b0, b1, t.size)]
    model, p = _arm_payload(qpos, t)
    ft = _f32(p["frames"]["t"])
    bodies = p["frames"]["bodies"]
    assert set(bodies) <= {1, 2, 3}
    pos = _f32(p["frames"]["pos"]).reshape(ft.size, len(bodies), 3)
    static = _f32(p["static"]["pos"]).reshape(-1, 3)
    for k, tk in enumerate(ft):
        i = int(np.argmin(np.abs(t - tk)))
        want = _arm_oracle(*qpos[i])
        got = np.array([pos[k, bodies.index(b)] if b in bodies else static[b]
                        for b in (1, 2, 3)])
        np.testing.assert_allclose(got, want, atol=2e-6)
        if abs(qpos[i][0] - qpos[i][1]) > 0.1:  # a planted fault: the joints swapped
            assert not np.allclose(got, _arm_oracle(qpos[i][1], qpos[i][0]), atol=1e-3)


def test_payload_shows_visible_geoms_cameras_charts_and_the_bead():
    t = np.linspace(0, 2, 201)
    qpos = np.c_[np.sin(t), np.cos(t)]
    model, p = _arm_payload(qpos, t)
    types = sorted(g["type"] for g in p["geoms"])
    assert types == [0, 3, 6]  # plane, capsule, box; the group-3 sphere is left out
    assert [c["name"] for c in p["cameras"]] == ["top"]
    assert [c["id"] for c in p["charts"]] == ["torque", "speed", "error"]
    err = _f32(p["charts"][2]["y"][0])
    np.testing.assert_allclose(err, np.degrees(0.01), rtol=1e-5)  # q_ref - q, degrees
    arc = np.frombuffer(base64.b64decode(p["paths"][0]["arc"]["u8"]), np.uint8)
    assert arc.sum() == (t > 1).sum()
    assert p["collisions"][0]["t0"] == 0.1


def test_the_section_is_self_contained_and_view_replaces_it(tmp_path):
    t = np.linspace(0, 1, 11)
    _, p = _arm_payload(np.c_[t, t], t)
    sec = replay_section(p)
    assert sec.startswith(BEGIN) and sec.endswith(END)
    assert 'type="importmap"' in sec and "data:text/javascript;base64," in sec
    assert ' src="http' not in sec and ' href="http' not in sec
    alone = with_replay(None, sec, "x")
    assert alone.count(BEGIN) == 1 and "<h1>x</h1>" in alone
    report = "<html><body><h1>r</h1><p>rest</p></body></html>"
    once = with_replay(report, sec)
    assert once.index("</h1>") < once.index(BEGIN) < once.index("<p>rest")
    again = with_replay(once, sec.replace("Replay", "Replay2"))
    assert again.count(BEGIN) == 1 and "Replay2" in again and "<p>rest" in again
    vendor = Path(__file__).resolve().parents[2] / "sim/analysis/replay/vendor"
    assert all((vendor / n).is_file() for n in VENDOR)
    for lic in ("LICENSE-three.txt", "LICENSE-uplot.txt"):
        assert "MIT License" in (vendor / lic).read_text()


@pytest.mark.slow
def test_default_report_is_under_10_mb_and_view_works_without_opengl(scenario_run, tmp_path):
    run_dir, _ = scenario_run("bugnar_5r_weld_cycle")
    report = Path(run_dir) / "report.html"
    assert report.stat().st_size < 10e6
    assert report.read_text().count(BEGIN) == 1
    copy = tmp_path / "run"
    shutil.copytree(run_dir, copy)
    (copy / "report.html").unlink()
    env = dict(os.environ, MUJOCO_GL="bogus", PYOPENGL_PLATFORM="bogus")
    env.pop("DISPLAY", None)
    res = run_limited([sys.executable, "-m", "sim", "view", str(copy)], cpu_s=120, env=env,
                      capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    text = (copy / "report.html").read_text()
    assert text.count(BEGIN) == 1 and "cellsim-replay-data" in text
    assert len(text) < 10e6


def _tiny_run(folder: Path, qpos_cols: int = 2) -> Path:
    folder.mkdir()
    (folder / "model.xml").write_text(ARM)
    t = np.linspace(0, 1, 101)
    q = np.c_[t, -t]
    np.savez(folder / "trajectory.npz", t=t, qpos=q[:, :qpos_cols], q=q, qd=np.ones_like(q),
             tau=q)
    return folder


def test_view_writes_a_report_of_its_own_and_refuses_poses_that_do_not_fit(tmp_path, capsys):
    from sim.cli import main

    run = _tiny_run(tmp_path / "run")
    assert main(["view", str(run)]) == 0
    assert str(run / "report.html") in capsys.readouterr().out  # headless: the path
    text = (run / "report.html").read_text()
    assert text.count(BEGIN) == 1 and "<h1>cellsim replay: run</h1>" in text
    assert main(["view", str(run)]) == 0  # refreshed in place, once
    assert (run / "report.html").read_text().count(BEGIN) == 1
    bad = _tiny_run(tmp_path / "bad", qpos_cols=1)
    assert main(["view", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "trajectory.npz" in err and "qpos" in err and len(err.strip().splitlines()) == 1


SHIPPED = sorted(__import__("sim.core.resources", fromlist=["x"]).shipped_scenarios())
#: The framed overview is checked on the default cycle in the fast share (its run is shared
#: with other tests), on the other scenarios (the two-robot cell's among them) in the slow share.
OVERVIEW_FAST = {"bugnar_5r_weld_cycle"}


@pytest.mark.parametrize("name", [n if n in OVERVIEW_FAST else pytest.param(
    n, marks=pytest.mark.slow) for n in SHIPPED])
def test_the_first_view_frames_every_robot_over_the_whole_cycle(name, scenario_run):
    """The replay opens on the video's framed overview: every link of every robot at every
    one of 40 times along the cycle inside the picture (a pinhole projection written here
    from the preset's position, orientation and field of view), and the robots fill at least
    40 % of the picture's height or width (a view from far away fails)."""
    import mujoco

    from sim.analysis.replay.payload import OVERVIEW_ASPECT, framed_overview

    run_dir = Path(scenario_run(name)[0])
    model = mujoco.MjModel.from_xml_path(str(run_dir / "model.xml"))
    qpos = np.load(run_dir / "trajectory.npz")["qpos"]
    views = framed_overview(model, qpos)
    assert [v["name"] for v in views] == ["framed overview"] and views[0]["body"] == 0
    v = views[0]
    w, x, y, z = v["quat"]
    rot = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    assert abs(rot[2, 0]) < 1e-9  # the picture's horizontal stays level (world z up)
    data = mujoco.MjData(model)
    names = [model.body(int(b)).name for b in model.geom_bodyid]
    bodies = [model.body(b).name for b in range(model.nbody)]
    robots = {b.split("/")[0] for b in bodies if "/link" in b}  # robot, r2, ...
    arm = [g for g, n in enumerate(names) if n.split("/")[0] in robots
           and model.geom_group[g] <= 2 and model.geom_rgba[g, 3] > 0]
    assert arm
    half_h = np.tan(np.radians(v["fovy"]) / 2)
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for i in np.linspace(0, len(qpos) - 1, 40).astype(int):
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        cam = (data.geom_xpos[arm] - v["pos"]) @ rot  # camera frame: x right, y up, -z ahead
        depth = -cam[:, 2]
        assert (depth > 0).all(), (name, i)
        ndc = cam[:, :2] / depth[:, None] / [half_h * OVERVIEW_ASPECT, half_h]
        rad = model.geom_rbound[arm] / depth / half_h  # the bounding sphere, roughly
        assert (np.abs(ndc) + rad[:, None] <= 1.0 + 1e-9).all(), (name, i, np.abs(ndc).max())
        lo, hi = np.minimum(lo, ndc.min(axis=0)), np.maximum(hi, ndc.max(axis=0))
    assert ((hi - lo) / 2 >= 0.4).any(), (name, lo, hi)


def test_a_robot_links_collision_paints_the_links_visible_geoms():
    """A finding names a robot link's collision geom (hidden in pictures; one the model file
    left unnamed is ``<body>#<k>``): the page paints that link's visible geoms, as the video
    does, and a name the model does not have paints nothing."""
    from sim.scenario import load_scenario
    from sim.simulation.collision_model import LINK, CollisionModel
    from sim.simulation.compile import build

    built = build(load_scenario("lrmate200ic_weld_plate"))
    model = built.model
    link = next(cg for cg in CollisionModel(built).geoms.values()
                if cg.role == LINK and "#" in cg.name and cg.name.startswith("robot/link"))
    body = int(model.geom_bodyid[link.id])
    t = np.linspace(0.0, 1.0, 11)
    arrays = {"t": t, "qpos": np.tile(model.qpos0, (t.size, 1)), "tcp_pos": np.zeros((t.size, 3)),
              "arc_on": np.zeros(t.size, bool)}
    summary = {"scenario": "s", "collisions": [
        {"t0": 0.2, "t1": 0.4, "geoms": [link.name, "nowhere"], "bodies": ["a", "b"]}]}
    p = build_payload(model, arrays, summary, [f"j{i}" for i in range(6)], fps=10)
    shown = {g["name"] for g in p["geoms"] if g["body"] == body}
    assert shown and set(p["collisions"][0]["geoms"]) >= shown
    assert all(model.geom(int(model.geom(n).id)).bodyid == body
               for n in p["collisions"][0]["geoms"])
