"""`cellsim plan` and `cellsim list` (issue 2 section 3): output shapes, seed values through
the command line, and one-line errors with exit code 2."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import numpy as np
import pytest
from support.limits import run_limited

from sim.cli import main
from sim.core.resources import shipped_scenarios


def _run(*args: str) -> subprocess.CompletedProcess:
    return run_limited([sys.executable, "-m", "sim", *args], capture_output=True, text=True,
                          cpu_s=120)


def test_plan_json_shape_and_seed001_joint1(capsys):
    """JSON shape of the issue; seed 001 eq. 18-20 (joint 1, normalized, rad) through the CLI."""
    assert main(["plan", "bugnar_5r_phase1", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc) == {"scenario", "phases"} and doc["scenario"] == "bugnar_5r_phase1"
    (phase,) = doc["phases"]
    assert set(phase) == {"name", "planner", "time_s", "joints"}
    assert phase["planner"] == "434" and phase["time_s"] == [0.0, 3.33, 6.67, 10.0]
    assert [j["index"] for j in phase["joints"]] == [1, 2, 3, 4, 5]
    segs = phase["joints"][0]["segments"]
    assert [set(s) for s in segs] == [{"t0", "t1", "normalized", "real"}] * 3
    expected = [[0, 0, 0, -0.2985, 0.1659], [-0.1326, -0.2324, 0.1, -0.0002],
                [-0.2653, 0, 0, 0.0331, 0.0331]]
    for seg, exp in zip(segs, expected):
        np.testing.assert_allclose(seg["normalized"], exp, atol=1e-3)
    # real-time form evaluated at a segment's ends equals the knot values (rad)
    q1 = np.deg2rad([0, -7.6, -15.2, -15.2])
    for k, seg in enumerate(segs):
        b = np.asarray(seg["real"])
        for tau, q in ((seg["t0"], q1[k]), (seg["t1"], q1[k + 1])):
            assert np.polyval(b[::-1], tau) == pytest.approx(q, abs=1e-9)


def test_plan_text_lists_every_segment(capsys):
    assert main(["plan", "kacso_lrmate100ib_sequence1"]) == 0
    out = capsys.readouterr().out
    assert out.count("segment 1:") == 5 and out.count("segment 3:") == 5
    assert "t_bar" in out and "tau" in out


def test_plan_warns_about_speed_limit(capsys):
    """Seed 000's sequence drives J2 above the 100iB's 270 deg/s: plan says so on stderr."""
    assert main(["plan", "kacso_lrmate100ib_sequence1", "--json"]) == 0
    err = capsys.readouterr().err
    assert "warning" in err and "joint j2" in err and "velocity" in err


@pytest.mark.parametrize("args, fragment", [
    (["plan", "no_such_scenario"], "unknown scenario"),
    (["plan", "/nonexistent/x.toml"], "no such scenario file"),
    (["ik", "no_such_robot", "1", "2", "3"], "unknown robot"),
])
def test_bad_input_exit_code_2_one_line(args, fragment):
    res = _run(*args)
    assert res.returncode == 2, res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and fragment in lines[0], res.stderr
    assert "Traceback" not in res.stderr


@pytest.mark.parametrize("body, fragment", [
    ("name = 'x'\ndescription = 'd'\nrobot = 'robot_5r'\n[[phases]]\nname='a'\nplanner='434'\n"
     "time_s=[1]\njoints_deg=[[0,0,0,0,0]]\n", "at least 2"),
    ("name = 'x'\ndescription = 'd'\nrobot = 'robot_5r'\n[[phases]]\nname='a'\nplanner='443'\n"
     "time_s=[0,1,2]\njoints_deg=[[0,0,0,0,0],[1,1,1,1,1],[2,2,2,2,2]]\n", "phases[0].planner"),
    ("name = 'x'\ndescription = 'd'\nrobot = 'robot_5r'\n[[phases]]\nname='a'\nplanner='434'\n"
     "time_s=[0,1,0.5]\njoints_deg=[[0,0,0,0,0],[1,1,1,1,1],[2,2,2,2,2]]\n", "must increase"),
    ("name = 'x'\ndescription = 'd'\nrobot = 'robot_5r'\n[[phases]]\nname='a'\nplanner='434'\n"
     "time_s=[0,1,2]\njoints_deg=[[0,0,0,0,0],[1,1,1,1],[2,2,2,2,2]]\n", "joints_deg[1]"),
    ("name = 'x'\ndescription = 'd'\nrobot = 'robot_5r'\n[[phases]]\nname='a'\nplanner='434'\n"
     "time_s=[0,1,2]\njoints_deg=[[0,0,0,0,0],[1,nan,1,1,1],[2,2,2,2,2]]\n", "finite"),
    ("name = 'x\ndescription", "invalid TOML"),
])
def test_plan_bad_files_exit_2(tmp_path, body, fragment):
    f = tmp_path / "bad.toml"
    f.write_text(body)
    res = _run("plan", str(f))
    assert res.returncode == 2
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and fragment in lines[0] and "bad.toml" in lines[0], res.stderr


def test_list_shows_every_robot_and_scenario(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for name in ("lrmate100ib", "lrmate200ic5l", "robot_5r", *shipped_scenarios()):
        assert name in out
    assert "(invalid" not in out


def test_list_shows_each_cells_objects_seams_and_cameras(capsys):
    """Each cell's block names its objects (rings once, no painted marks), its seams with
    their lengths and its cameras; the weld table's lengths from its own dimensions."""
    import math

    from sim.cells import CELLS, weld_table

    assert main(["list"]) == 0
    out = capsys.readouterr().out
    blocks = out.split("cells:\n", 1)[1].split("tools:\n", 1)[0]
    for name in CELLS:
        assert f"  {name} " in blocks
    table = blocks.split("  weld_table ", 1)[1]
    objects = next(ln for ln in table.splitlines() if "objects:" in ln)
    assert objects.endswith(", wall") and "wall0" not in objects and "line_mark" not in objects
    line_mm = 1000.0 * (weld_table.LINE_R[1] - weld_table.LINE_R[0])
    arc_mm = 1000.0 * weld_table.ARC_R * math.radians(weld_table.ARC_DEG[1] - weld_table.ARC_DEG[0])
    assert f"seams: line (line, {line_mm:.0f} mm), arc (arc, {arc_mm:.0f} mm)" in table
    assert "cameras: overview, tool" in table
    pick = re.split(r"\n  (?=\S)", blocks.split("  pick ", 1)[1], maxsplit=1)[0]  # its block
    assert "parts: part0, part1, part2, part3" in pick and "seams:" not in pick


def _program(n: int, term: str) -> str:
    """A generated TP program: a J move, then ``n`` L moves round a 20 mm square with
    termination ``term`` (FINE or CNTx)."""
    mn = ["UFRAME_NUM=0 ;", "UTOOL_NUM=1 ;", "J P[1] 50% FINE ;"]
    mn += [f"L P[{k}] 100mm/sec {term} ;" for k in range(2, n + 2)]
    pos = []
    for k in range(1, n + 2):
        x, y, z = (450 + (k % 2) * 20, -50 + (k % 4 // 2) * 20, 50 if k == 1 else 0)
        pos.append(f"P[{k}]{{\n   GP1:\n\tUF : 0, UT : 1,\t\tCONFIG : 'N U T, 0, 0, 0',\n"
                   f"\tX = {x:.3f} mm,\tY = {y:.3f} mm,\tZ = {z:.3f} mm,\n"
                   "\tW = 180.000 deg,\tP = 0.000 deg,\tR = 0.000 deg\n};")
    return ("/PROG  GEN\n/MN\n" + "\n".join(f"  {i + 1:4d}:  {m}" for i, m in enumerate(mn))
            + "\n/POS\n" + "\n".join(pos) + "\n/END\n")


def _program_scenario(tmp_path, n: int, term: str):
    (tmp_path / "gen.ls").write_text(_program(n, term))
    (tmp_path / "s.toml").write_text('name = "gen"\ndescription = "generated"\n'
                                     'robot = "lrmate200ic5l"\ntool = "mig_torch"\n'
                                     'program = "gen.ls"\n')
    return tmp_path / "s.toml"


@pytest.mark.parametrize("n", [6, 12])
def test_blended_moves_list_their_own_segments_once(tmp_path, capsys, monkeypatch, n):
    """Issue 31: blended moves share one trajectory, and `cellsim plan` listed all of it for
    each move and checked its limits once per move: output and work grew as the square of
    the number of moves (100 CNT moves: 251 s, 4.4 GB). Now the phases' segments tile the
    trajectory's knots (each segment listed once, in order) and each trajectory is checked
    once."""
    import planners.limits as limits

    calls = []
    real = limits.find_limit_violations
    monkeypatch.setattr(limits, "find_limit_violations",
                        lambda traj, **kw: calls.append(id(traj)) or real(traj, **kw))
    assert main(["plan", str(_program_scenario(tmp_path, n, "CNT50")), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    phases = doc["phases"]
    assert len(phases) == n + 1
    spans = [(s["t0"], s["t1"]) for ph in phases[1:] for s in ph["joints"][0]["segments"]]
    distinct = sorted(set(spans))
    # the distinct segments tile the blended moves' time without a gap, and consecutive
    # windows share at most the one segment their boundary falls in
    assert all(a[1] == b[0] for a, b in zip(distinct, distinct[1:]))
    assert len(spans) <= len(distinct) + (n - 1)
    assert spans == sorted(spans)
    assert len(calls) == len(set(calls)) == 2  # the J move's trajectory and the blended one


def test_a_program_longer_than_the_bound_is_refused_at_its_line(tmp_path, capsys):
    from sim.scenario.fanuc_ls import MAX_PROGRAM_MOTIONS

    assert main(["check", str(_program_scenario(tmp_path, MAX_PROGRAM_MOTIONS, "FINE"))]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    # the file's lines: /PROG, /MN, two frame lines, the J move, then the L moves
    assert f"gen.ls: line {MAX_PROGRAM_MOTIONS + 5}: the program has " \
           f"{MAX_PROGRAM_MOTIONS + 1:,} motion instructions" in err


def test_plan_json_names_each_joint_and_its_unit(capsys):
    """``plan --json`` names each joint and gives its coefficients' unit: radians, metres on a
    linear axis (a track's coefficients are in metres, and nothing said so: found by a new-user
    trial); the track's position at its phase's start, from the JSON in metres, is the text
    output's constant term in mm over 1000 (the same plan, two units)."""
    assert main(["plan", "track_beam_weld", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    joints = doc["phases"][0]["joints"]
    assert [(j["name"], j["unit"]) for j in joints] == \
        [(f"j{k}", "rad") for k in range(1, 7)] + [("track_travel", "m")]
    assert main(["plan", "track_beam_weld"]) == 0
    text = capsys.readouterr().out
    seg = joints[6]["segments"][0]
    lines = text.splitlines()
    at = next(i for i, ln in enumerate(lines) if "joint track_travel (mm)" in ln)
    normalized = next(ln for ln in lines[at:] if "normalized:" in ln)
    constant_mm = float(normalized.split()[-1])  # "-10 t^4 +20 t^3 -1500": the t^0 term
    assert seg["normalized"][0] * 1e3 == pytest.approx(constant_mm, abs=1e-6)
    assert seg["normalized"][4] * 1e3 == pytest.approx(-10.0, abs=1e-6)  # the t^4 term
