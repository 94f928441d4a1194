"""A two-robot cell's outputs measure every robot (issue 28): the other robot's weld, speeds,
joints and checks in the summary, against oracles that do not use cellsim's kinematics or
metrics: the tool point from the LR Mate's link product (support.two_robots) at the recorded
joint columns, on the seam the generated cell file writes, progressing at the set speed.

One generated cell is simulated once (session-scoped) for the fast tests; the independence of
the second robot's physics (its torques equal the same robot's alone in an equivalent cell) runs
two more simulations and is slow.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.two_robots import TwoCell, generate, line_distance, tool_points, write_alone, write_two

SEED = 28


@pytest.fixture(scope="session")
def two_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[TwoCell, Any]:
    from sim.pipeline.run import RunOptions, evaluate_scenario
    from sim.scenario import load_scenario

    cell = generate(SEED)
    path = write_two(cell, tmp_path_factory.mktemp("two") / "gen")
    ev = evaluate_scenario(load_scenario(path),
                           RunOptions(video=False, plots=False, progress=False))
    return cell, ev


def _cols(summary: dict[str, Any], name: str) -> list[int]:
    joints = summary["joints"]
    return [joints.index(j) for j in summary["robots"][name]["joints"]]


def _weld_window(arrays: dict[str, Any], summary: dict[str, Any], name: str) -> Any:
    """Samples of the robot's weld phase with its arc on (from its own phases' times)."""
    ph = next(p for p in summary["robots"][name]["phases"] if p["name"] == "weld")
    t = arrays["t"]
    arc = np.asarray(arrays[f"{name}_arc_on"] if name != "robot" else arrays["arc_on"], bool)
    return arc & (t >= ph["t0"]) & (t <= ph["t1"])


def _oracle(cell: TwoCell, arrays: dict[str, Any], summary: dict[str, Any], *,
            cols: list[int], seam: tuple[Any, Any], base: Any) -> dict[str, float]:
    """The r2 weld's figures from the link product at the recorded joints: largest distance
    from the seam line, mm; progress at start and end, mm; cruise travel speed, mm/s (the
    middle 60 % of the weld, a least-squares slope of progress over time)."""
    sel = _weld_window(arrays, summary, "r2")
    q = np.asarray(arrays["q"])[sel][:, cols]
    t = np.asarray(arrays["t"])[sel]
    p = tool_points(base, q)
    dist, s = line_distance(p, *seam)
    n = len(t)
    mid = slice(int(0.2 * n), int(0.8 * n))
    speed = np.polyfit(t[mid], s[mid], 1)[0]
    return {"max_dev_mm": float(dist.max() * 1e3), "s0_mm": float(s[0] * 1e3),
            "s1_mm": float(s[-1] * 1e3), "speed_mm_s": float(speed * 1e3),
            "tcp_err_mm": float(np.abs(p - np.asarray(arrays["r2_tcp_pos"])[sel]).max() * 1e3)}


def test_r2_tool_point_on_its_seam_at_its_speed(two_run):
    """The second robot's tool point, from the link product at its recorded joints, lies on
    the seam the file writes (0.1 mm), covers it end to end and progresses within 1 % of the
    set speed; the recorded ``r2_tcp_pos`` is that point."""
    cell, ev = two_run
    a, s = ev.record.arrays, ev.summary
    o = _oracle(cell, a, s, cols=_cols(s, "r2"), seam=cell.right, base=cell.r2_base)
    assert o["max_dev_mm"] < 0.1
    assert abs(o["s0_mm"]) < 0.1 and abs(o["s1_mm"] - cell.length) < 0.1
    assert abs(o["speed_mm_s"] / cell.speed2 - 1.0) < 0.01
    assert o["tcp_err_mm"] < 1e-6


def test_planted_faults_are_caught(two_run):
    """The oracle fails a seam shifted by 1 mm and the first robot's joint columns."""
    cell, ev = two_run
    a, s = ev.record.arrays, ev.summary
    a0, b0 = cell.right
    shift = np.array([0.0, 1e-3, 0.0])
    o = _oracle(cell, a, s, cols=_cols(s, "r2"), seam=(a0 + shift, b0 + shift),
                base=cell.r2_base)
    assert o["max_dev_mm"] > 0.9
    o = _oracle(cell, a, s, cols=_cols(s, "robot"), seam=cell.right, base=cell.r2_base)
    assert o["max_dev_mm"] > 1.0 or o["tcp_err_mm"] > 1.0


def test_summary_measures_r2_weld_like_the_oracle(two_run):
    """summary["weld"]'s r2 entry (robot "r2", seam "right") gives the oracle's seam length,
    set and travel speed and path deviation; the first robot's entry is its own (seam
    "left", its set speed)."""
    cell, ev = two_run
    a, s = ev.record.arrays, ev.summary
    o = _oracle(cell, a, s, cols=_cols(s, "r2"), seam=cell.right, base=cell.r2_base)
    welds = {w["robot"]: w for w in s["weld"]}
    assert set(welds) == {"robot", "r2"}
    w2, w1 = welds["r2"], welds["robot"]
    assert w2["seam"] == "right" and w1["seam"] == "left"
    assert w2["seam_length_mm"] == pytest.approx(cell.length, abs=1e-6)
    assert w2["set_speed_mm_s"] == pytest.approx(cell.speed2, rel=1e-9)
    assert w1["set_speed_mm_s"] == pytest.approx(cell.speed1, rel=1e-9)
    assert w2["travel_speed_mm_s"] == pytest.approx(o["speed_mm_s"], rel=2e-3)
    assert w2["max_path_deviation_mm"] == pytest.approx(o["max_dev_mm"], abs=0.01)
    assert abs(w2["start_error_mm"]) < 0.1 and abs(w2["end_error_mm"]) < 0.1
    assert w2["torch_angle_error_deg"] < 0.1
    speeds = [c for c in s["cartesian_speed"] if c.get("robot") == "r2"]
    assert [c["phase"] for c in speeds] == ["touch", "weld"]
    assert speeds[1]["set_mm_s"] == pytest.approx(cell.speed2, rel=1e-9)
    assert abs(speeds[1]["cruise_mm_s"] / o["speed_mm_s"] - 1.0) < 0.01


def test_summary_robots_and_checks_cover_r2(two_run):
    """summary["robots"] names each robot's model, tool, base, joints and cycle end; the
    checks cover r2's joints (tracking, saturation, speed, acceleration) and its weld (torch
    angle, Cartesian speeds, subjects naming r2)."""
    cell, ev = two_run
    s = ev.summary
    r = s["robots"]
    assert list(r) == ["robot", "r2"]
    assert r["r2"]["model"] == "lrmate200ic5l" and r["r2"]["tool"] == "mig_torch"
    assert r["r2"]["joints"] == [f"r2_j{k}" for k in range(1, 7)]
    assert r["robot"]["joints"] == [f"j{k}" for k in range(1, 7)]
    assert r["r2"]["base_pos_mm"] == pytest.approx(list(cell.r2_pos), abs=1e-6)
    assert r["r2"]["frame0_pos_mm"][:2] == pytest.approx(list(cell.r2_pos[:2]), abs=1e-6)
    assert r["r2"]["frame0_euler_zyx_deg"][0] == pytest.approx(-90.0, abs=1e-9)
    assert r["r2"]["t_end_s"] == pytest.approx(r["r2"]["phases"][-1]["t1"])
    assert r["r2"]["phases"][0]["t1"] == pytest.approx(cell.start2_s)
    assert max(r["robot"]["t_end_s"], r["r2"]["t_end_s"]) == pytest.approx(s["duration_s"])
    # the tool point's deviation from its reference: the recorded arrays' own figure
    a = ev.record.arrays
    dev = np.linalg.norm(np.asarray(a["r2_tcp_pos"]) - a["r2_tcp_pos_ref"], axis=1).max()
    assert r["r2"]["max_tcp_deviation_mm"] == pytest.approx(dev * 1e3, rel=1e-12)
    checks = s["checks"]
    for name in ("tracking", "saturation", "speed", "acceleration"):
        got = {c["joint"] for c in checks if c["name"] == name}
        assert {f"r2_j{k}" for k in range(1, 7)} <= got, name
    torch = [c for c in checks if c["name"] == "torch_angle"]
    assert sorted(c["subject"].split(":")[0] for c in torch) == ["r2", "robot"]
    assert any(c["subject"].startswith("r2: weld") for c in checks
               if c["name"] == "cartesian_speed")
    (pay,) = [c for c in checks if c["name"] == "payload" and c["subject"].startswith("r2")]
    assert pay["value"] == pytest.approx(1.0) and pay["limit"] == pytest.approx(5.0)
    assert s["verdict"] in ("pass", "fail")


def test_planted_summary_fault_fails_the_r2_checks(two_run):
    """A planted r2 weld error reaches the verdict: the torch angle check of r2 fails."""
    from sim.analysis.verdict import torch_angle_checks

    _, ev = two_run
    s = dict(ev.summary)
    s["weld"] = [dict(w, torch_angle_error_deg=5.0) if w["robot"] == "r2" else w
                 for w in s["weld"]]
    failed = [c for c in torch_angle_checks(s, 2.0) if not c.passed]
    assert [c.subject.split(":")[0] for c in failed] == ["r2"]


def test_console_prints_each_robots_weld(two_run, capsys):
    """The console's weld lines carry the robot's name (the lines `cellsim run` prints)."""
    from sim.cli.run import _who

    _, ev = two_run
    whos = [_who(w) for w in ev.summary["weld"]]
    assert whos == ["robot: ", "r2: "]
    assert _who({"phase": "weld"}) == ""


@pytest.mark.slow  # two more simulations (the generated cell with r2 alone)
def test_r2_physics_is_its_own(two_run, tmp_path: Path):
    """The second robot's recorded torques equal the same robot's doing the same phases as the
    only robot of an equivalent cell (its base, tool and seam), to 1e-9 of the peak."""
    from sim.pipeline.run import RunOptions, evaluate_scenario
    from sim.scenario import load_scenario

    cell, ev = two_run
    alone = evaluate_scenario(load_scenario(write_alone(cell, tmp_path / "alone")),
                              RunOptions(video=False, plots=False, progress=False, sizing=False))
    a2, a1 = ev.record.arrays, alone.record.arrays
    cols = _cols(ev.summary, "r2")
    # the alone run ends with r2's last phase; its last sample's acceleration (hence tau) is
    # a one-sided difference, where the two-robot run still runs on: compared up to before it
    n = min(len(a1["t"]), len(a2["t"])) - 1
    np.testing.assert_allclose(a2["t"][:n], a1["t"][:n], rtol=0, atol=1e-12)
    tau2 = np.asarray(a2["tau"])[:n, cols]
    tau1 = np.asarray(a1["tau"])[:n, :6]
    peak = np.abs(tau1).max(axis=0)
    assert np.abs(tau2 - tau1).max(axis=0) / peak == pytest.approx(np.zeros(6), abs=1e-9)
    # planted: the first robot's columns are another robot's torques
    tau_r1 = np.asarray(a2["tau"])[:n, _cols(ev.summary, "robot")]
    assert np.max(np.abs(tau_r1 - tau1).max(axis=0) / peak) > 1e-3
    # a cell without other robots: no "robots", no "robot" in its entries (as before)
    assert "robots" not in alone.summary
    assert all("robot" not in w for w in alone.summary["weld"] + alone.summary["cartesian_speed"])
    # the same robot's weld measured alone and as r2 agree
    w_alone = alone.summary["weld"][0]
    w_r2 = next(w for w in ev.summary["weld"] if w["robot"] == "r2")
    for key in ("travel_speed_mm_s", "max_path_deviation_mm", "seam_length_mm"):
        assert w_r2[key] == pytest.approx(w_alone[key], rel=1e-6, abs=1e-9), key


def test_run_result_types_each_robots_welds(two_run):
    """RunResult: every robot's welds typed (WeldResult), per robot (RobotResult), equal to the
    summary's figures; the oracle's r2 travel speed."""
    from sim.api.results import RobotResult, RunResult, WeldResult

    cell, ev = two_run
    res = RunResult.from_evaluation(ev)
    assert [w.robot for w in res.welds] == ["robot", "r2"]
    assert all(isinstance(w, WeldResult) for w in res.welds)
    (w2,) = res.welds_of("r2")
    assert w2.seam == "right" and w2.set_speed_mm_s == pytest.approx(cell.speed2, rel=1e-9)
    o = _oracle(cell, ev.record.arrays, ev.summary, cols=_cols(ev.summary, "r2"),
                seam=cell.right, base=cell.r2_base)
    assert w2.travel_speed_mm_s == pytest.approx(o["speed_mm_s"], rel=2e-3)
    assert list(res.robots) == ["robot", "r2"]
    r2 = res.robots["r2"]
    assert isinstance(r2, RobotResult) and r2.welds == (w2,)
    assert r2.joints == tuple(f"r2_j{k}" for k in range(1, 7))
    assert r2.phases == ("start", "to_seam", "touch", "weld")
    assert res.robots["robot"].welds == res.welds_of()
    # a summary of a single robot (no "robot" keys): its welds are the first robot's
    single = dict(ev.summary, weld=[{k: v for k, v in w.items() if k != "robot"}
                                    for w in ev.summary["weld"][:1]])
    single.pop("robots")
    one = RunResult.from_summary(single)
    assert [w.robot for w in one.welds] == ["robot"] and one.robots == {}


def test_cli_list_and_plan_show_the_other_robot(tmp_path: Path, capsys):
    """`cellsim list --cell` names r2 with its model, tool and the file's base; `cellsim plan`
    lists r2's phases (its joints r2_j1..), its start phase's knots at the file's times."""
    from sim.cli import main

    cell = generate(SEED + 1)
    path = write_two(cell, tmp_path / "gen")
    assert main(["list", "--cell", str(path.parent / "cell.toml")]) == 0
    out = capsys.readouterr().out
    base = ", ".join(f"{x:.6g}" for x in cell.r2_pos)
    assert f"other robots: r2 (lrmate200ic5l, mig_torch; base {base} mm, yaw -90 deg)" in out
    assert main(["plan", str(path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    (r2,) = doc["robots"]
    assert r2["name"] == "r2"
    assert [p["name"] for p in r2["phases"]] == ["start", "to_seam", "touch", "weld"]
    start = r2["phases"][0]
    assert start["time_s"][0] == 0.0 and start["time_s"][-1] == pytest.approx(cell.start2_s)
    assert [j["index"] for j in start["joints"]] == [1, 2, 3, 4, 5, 6]
    assert [p["name"] for p in doc["phases"]] == ["start", "to_seam", "touch", "weld"]
    assert main(["plan", str(path)]) == 0
    text = capsys.readouterr().out
    assert "robot r2 (lrmate200ic5l, 6 joints), 4 polynomial phase(s)" in text
    assert "  joint r2_j1" in text and "external axes" not in text


def test_video_overlay_lays_r2_bead_on_its_seam(two_run):
    """The video's overlay lays a bead for r2 too: one run, from r2's arc on, on the file's
    seam (0.1 mm), covering it; the first robot's bead on its own seam."""
    from sim.render.overlay import PathOverlay

    cell, ev = two_run
    ov = PathOverlay(ev.record)
    (r2,) = ov.others
    (run,) = r2.bead_runs
    pts, _, t0, _ = run
    dist, s = line_distance(pts, *cell.right)
    assert dist.max() < 1e-4
    assert s.min() < 1e-4 and s.max() > cell.length * 1e-3 - 1e-4
    arc = np.asarray(ev.record.arrays["r2_arc_on"], bool)
    assert t0 == pytest.approx(ev.record.arrays["t"][np.argmax(arc)])
    (own,) = ov.bead_runs
    assert line_distance(own[0], *cell.left)[0].max() < 1e-4
    # planted: r2's bead is not on the first robot's seam
    assert line_distance(pts, *cell.left)[0].max() > 5e-3
    assert ov.max_geoms > r2.max_geoms > 0


def test_tool_path_plot_per_robot(two_run, tmp_path: Path):
    """plots: tool_path_r2.png; its seam line is r2's arc-on path, on r2's seam (0.1 mm), its
    error axes shaded with r2's phases; r2's joints' figures shade r2's phases."""
    import matplotlib

    matplotlib.use("Agg")
    from sim.analysis.plots import _joint_phases, other_robots, tool_path_figure

    cell, ev = two_run
    rec = ev.record
    assert other_robots(rec) == ["r2"]
    fig = tool_path_figure(rec, "r2")
    ax3d = fig.axes[0]
    xs, ys, zs = ax3d.lines[2].get_data_3d()
    pts = np.column_stack([xs, ys, zs]) * 1e-3
    assert line_distance(pts, *cell.right)[0].max() < 1e-4
    assert "r2" in ax3d.get_title()
    assert _joint_phases(rec, "r2_j1") == ev.summary["robots"]["r2"]["phases"]
    assert _joint_phases(rec, "j1") == rec.phases
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_report_has_a_section_per_robot(two_run):
    """sizing.md and report.html: a section per robot naming its joints, its weld (the
    summary's figures) and its joints' sizing; none for a cell with one robot."""
    from sim.analysis.report import robot_sections, sizing_html, sizing_markdown

    _, ev = two_run
    s = ev.summary
    secs = robot_sections(s, ev.sizing)
    assert [x.title for x in secs] == ["robot (lrmate200ic5l)", "r2 (lrmate200ic5l)"]
    r2 = secs[1]
    assert [row[0] for row in r2.joints] == [f"r2_j{k}" for k in range(1, 7)]
    assert all(row[2] != "n/a" for row in r2.joints)  # sized
    (weld,) = r2.welds
    w2 = next(w for w in s["weld"] if w["robot"] == "r2")
    assert weld[:2] == ("weld", "right")
    assert float(weld[4]) == pytest.approx(w2["travel_speed_mm_s"], rel=1e-3)
    md = sizing_markdown(ev.sizing, (), s)
    assert "## Robot r2 (lrmate200ic5l)" in md and "| r2_j6 |" in md
    page = sizing_html(ev.sizing, {}, s)
    assert "<h2>Robot r2 (lrmate200ic5l)</h2>" in page
    single = {k: v for k, v in s.items() if k != "robots"}
    assert robot_sections(single, ev.sizing) == []
    assert "## Robot" not in sizing_markdown(ev.sizing, (), single)


@pytest.mark.slow  # one more generated cell per seed
@pytest.mark.parametrize("seed", [3, 11])
def test_generated_cells_r2_against_oracle(seed: int, tmp_path: Path):
    """More generated cells: r2's tool point (link product at its recorded joints) on the
    file's seam within 0.1 mm at its set speed within 1 %, and the summary's r2 weld agrees."""
    from sim.pipeline.run import RunOptions, evaluate_scenario
    from sim.scenario import load_scenario

    cell = generate(seed)
    ev = evaluate_scenario(load_scenario(write_two(cell, tmp_path / "gen")),
                           RunOptions(video=False, plots=False, progress=False, sizing=False))
    a, s = ev.record.arrays, ev.summary
    o = _oracle(cell, a, s, cols=_cols(s, "r2"), seam=cell.right, base=cell.r2_base)
    assert o["max_dev_mm"] < 0.1
    assert abs(o["speed_mm_s"] / cell.speed2 - 1.0) < 0.01
    w2 = next(w for w in s["weld"] if w["robot"] == "r2")
    assert w2["travel_speed_mm_s"] == pytest.approx(o["speed_mm_s"], rel=2e-3)
    assert w2["max_path_deviation_mm"] == pytest.approx(o["max_dev_mm"], abs=0.01)
    assert w2["seam_length_mm"] == pytest.approx(cell.length, abs=1e-6)


@pytest.mark.slow  # a whole `cellsim run` (sizing, report, no video)
def test_cellsim_run_prints_each_robots_weld(tmp_path: Path, capsys):
    """`cellsim run` prints r2's line and each robot's weld line prefixed with its name, and
    writes tool_path_r2.png and report sections for r2."""
    from sim.cli import main

    cell = generate(SEED + 2)
    path = write_two(cell, tmp_path / "gen")
    out_dir = tmp_path / "run"
    assert main(["run", str(path), "--no-video", "--quiet", "--out", str(out_dir)]) == 0
    text = capsys.readouterr().out
    assert f"  robot: weld weld: {cell.length:.1f} mm at {cell.speed1:.2f} mm/s" in text
    assert f"  r2: weld weld: {cell.length:.1f} mm at {cell.speed2:.2f} mm/s" in text
    assert "  r2 (lrmate200ic5l): cycle end " in text
    assert (out_dir / "plots" / "tool_path_r2.png").is_file()
    assert "## Robot r2 (lrmate200ic5l)" in (out_dir / "sizing.md").read_text()
    summary = json.loads((out_dir / "summary.json").read_text())
    # the headline names whose joint tracks worst and that its tcp deviation is the first
    # robot's (r2's has its own line)
    errs = dict(zip(summary["joints"], summary["max_tracking_error_deg"], strict=True))
    worst = max(errs, key=lambda j: errs[j])
    head = text.splitlines()[0]
    assert f"max tracking error {errs[worst]:.4f} deg ({worst})" in head, head
    assert head.endswith(f"max tcp deviation {summary['max_tcp_deviation_mm']:.3f} mm (robot)")
    from sim.api.results import RunResult

    res = RunResult.load(out_dir)
    assert res.welds_of("r2")[0].set_speed_mm_s == pytest.approx(cell.speed2)
    assert summary["robots"]["r2"]["joints"] == list(res.robots["r2"].joints)
