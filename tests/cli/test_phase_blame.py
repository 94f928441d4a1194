"""A mistake is named where the user wrote it (found by a new-user trial of milestone 3's
cells and programs). Specification, on generated mistakes:

* a joint move that leaves a joint past its range, followed by a Cartesian move, is reported
  as that joint's ``limit`` (the phase and joint the user typed), not as the later move's
  branch or reach failure that only follows from it (``cellsim check`` exit 1 with a
  ``limit:`` line; ``cellsim run`` exit 2 with the same line);
* a TP program's move is named by its file and line and its positions (``weld_plate.ls: line
  23 (C P[8] P[7])``): an unreachable position, a joint past its range and a cycle too long
  for the step limit (which also names the longest move) each point at the line;
* ``cellsim plan`` of a joint-only scenario that starts from the cell's home plans it (it
  said "the start pose needs the cell's home").

Oracles: the joint ranges read in the test from the robot's MJCF, the line numbers found in
the program text the test wrote, the home read from the robot's MJCF
(its ``home`` keyframe; the planned start evaluated from the printed JSON polynomial). A planted fault (the earlier
limit not looked for) is caught."""

from __future__ import annotations

import contextlib
import io
import json
import re
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from sim.cli import main
from sim.core.resources import scenarios_dir

ROOT = Path(__file__).resolve().parents[2]
MJCF = ROOT / "models" / "fanuc_lrmate200ic" / "lrmate200ic5l.xml"
PROGRAM = "weld_plate.ls"


def joint_ranges_deg() -> dict[str, tuple[float, float]]:
    """The LR Mate 200iC/5L's joint ranges, deg, from its MJCF (the source a person edits)."""
    out = {}
    for j in ET.parse(MJCF).getroot().find("worldbody").iter("joint"):
        lo, hi = (float(x) for x in j.get("range", "").split())
        out[j.get("name", "")] = (float(np.degrees(lo)), float(np.degrees(hi)))
    return out


RANGES = joint_ranges_deg()


def _cli(args: list[str]) -> tuple[int, list[str], list[str]]:
    """``cellsim ARGS`` in this process: its exit code, its stdout's lines and its error
    lines (``cellsim: error: ...``; the progress lines on stderr left out)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(args)
    errors = [ln for ln in err.getvalue().splitlines() if ln.startswith("cellsim: error: ")]
    return code, out.getvalue().strip().splitlines(), errors


def _limit_named(line: str, where: str, joint: str, side: str) -> bool:
    """Whether ``line`` names the phase ``where``, the joint and the side of its range, with
    the limit of the MJCF's range."""
    lo, hi = RANGES[joint]
    want = lo if side == "below" else hi
    m = re.search(rf"{re.escape(where)}: joint {joint}: position (\S+) deg is {side} "
                  rf"(?:lower|upper) limit (\S+) deg", line)
    return bool(m) and abs(float(m.group(2)) - want) < 5e-3


# ------------------------------------------------------------------------------------------
# a scenario's own joint phase past a range, then a linear move
# ------------------------------------------------------------------------------------------

def _scenario(joint: str, value_deg: float) -> str:
    q = {"j1": -20.0, "j2": 20.0, "j3": -60.0, "j4": 0.0, "j5": -30.0, "j6": 0.0}
    q[joint] = value_deg
    row = ", ".join(f"{q[f'j{k}']:.6g}" for k in range(1, 7))
    return f"""name = "blame"
description = "a joint past its range, then a line"
robot = "lrmate200ic5l"

[[phases]]
name = "swing"
planner = "434"
time_s = [0.0, 2.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [{row}]]

[[phases]]
name = "line"
kind = "linear"
to_mm = [400, -200, 0]
speed_mm_s = 50
"""


def _check_scenario_blame(joint: str, side: str, over_deg: float) -> None:
    lo, hi = RANGES[joint]
    value = lo - over_deg if side == "below" else hi + over_deg
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "blame.toml"
        path.write_text(_scenario(joint, value))
        code, out, err = _cli(["check", str(path)])
        assert code == 1, (out, err)
        limits = [ln for ln in out if ln.startswith("limit: ")]
        assert any(_limit_named(ln, "blame.toml: phases[0] (swing)", joint, side)
                   for ln in limits), out
        code, out, err = _cli(["run", str(path), "--no-video", "--no-plots",
                               "--out", str(Path(tmp) / "run")])
        assert code == 2, (out, err)
        assert len(err) == 1 and _limit_named(err[0], "blame.toml: phases[0] (swing)",
                                              joint, side), err


@settings(max_examples=6, deadline=None, derandomize=True, database=None)
@given(joint=st.sampled_from(["j1", "j2", "j4", "j5"]), side=st.sampled_from(["below", "above"]),
       over_deg=st.floats(1.0, 40.0))
@example(joint="j1", side="below", over_deg=30.0)  # the trial's: J1 at -200 deg, then a line
def test_a_joint_past_its_range_is_named_before_the_move_that_follows(
        joint: str, side: str, over_deg: float) -> None:
    _check_scenario_blame(joint, side, over_deg)


def test_the_planted_fault_of_blaming_the_later_move_is_caught(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from sim.simulation.motion import build

    monkeypatch.setattr(build, "_earlier_limit", lambda *a, **k: None)
    with pytest.raises(AssertionError):
        _check_scenario_blame("j1", "below", 30.0)


# ------------------------------------------------------------------------------------------
# a TP program's moves named by their line
# ------------------------------------------------------------------------------------------

def _program_copy(tmp: Path, edit: Any) -> tuple[Path, str]:
    """The shipped TP weld scenario and its program copied into ``tmp``, the program's text
    passed through ``edit``; the scenario's path and the program's new text."""
    src = scenarios_dir()
    (tmp / "programs").mkdir()
    text = edit((src / "programs" / PROGRAM).read_text())
    (tmp / "programs" / PROGRAM).write_text(text)
    scen = tmp / "tp.toml"
    scen.write_text((src / "lrmate200ic_tp_weld_plate.toml").read_text())
    return scen, text


def _move_line(text: str, kind: str, point: int) -> tuple[int, str]:
    """The file line (1-based) of the program's ``kind`` move to (or, for C, via) P[point],
    and how the message names its positions (a C move's via point, then its end, on the
    line after)."""
    lines = text.splitlines()
    for n, ln in enumerate(lines, start=1):
        m = re.search(rf"\d+:\s+{kind} P\[(\d+)\]", ln)
        if not m:
            continue
        pts = [int(m.group(1))]
        if kind == "C":
            pts.append(int(re.search(r"P\[(\d+)\]", lines[n]).group(1)))  # ':  P[7] ...'
        if point in pts:
            return n, " ".join(f"P[{p}]" for p in pts)
    raise AssertionError(f"no {kind} move to P[{point}]")


def _set_position(text: str, point: int, key: str, value: float) -> str:
    """The program with P[point]'s ``key`` (``X``, ``J1``, ...) set to ``value``."""
    head, rest = text.split(f"P[{point}]{{", 1)
    body, tail = rest.split("};", 1)
    body, n = re.subn(rf"\b{key}\s*=\s*-?[\d.]+", f"{key}= {value:.3f}", body)
    assert n == 1, (point, key)
    return f"{head}P[{point}]{{{body}}};{tail}"


@settings(max_examples=4, deadline=None, derandomize=True, database=None)
@given(case=st.sampled_from([("L", 3), ("L", 4), ("L", 6), ("C", 8), ("C", 7), ("L", 9)]),
       x_mm=st.floats(1300.0, 3000.0))
def test_an_unreachable_program_position_names_its_line(
        case: tuple[str, int], x_mm: float) -> None:
    kind, point = case
    with tempfile.TemporaryDirectory() as tmp:
        scen, text = _program_copy(Path(tmp), lambda t: _set_position(t, point, "X", x_mm))
        line, pts = _move_line(text, kind, point)
        code, out, err = _cli(["check", str(scen)])
        assert code == 1, (out, err)
        assert any(ln.startswith(f"reach: tp.toml: {PROGRAM}: line {line} ({kind} {pts})")
                   for ln in out), out


@settings(max_examples=4, deadline=None, derandomize=True, database=None)
@given(side=st.sampled_from(["below", "above"]), over_deg=st.floats(1.0, 30.0))
def test_a_program_joint_past_its_range_names_its_line(side: str, over_deg: float) -> None:
    # J1 (a FANUC program's J1 is the model's j1, sign and zero; the other joints' conversion
    # is tests/scenario/test_weld_programs.py's)
    joint, name = "J1", "j1"
    lo, hi = RANGES[name]
    value = lo - over_deg if side == "below" else hi + over_deg
    with tempfile.TemporaryDirectory() as tmp:
        # P[2]: the J move before the first weld's L move
        scen, text = _program_copy(Path(tmp), lambda t: _set_position(t, 2, joint, value))
        line, _ = _move_line(text, "J", 2)
        code, out, err = _cli(["check", str(scen)])
        assert code == 1, (out, err)
        assert any(_limit_named(
            ln, f"tp.toml: {PROGRAM}: line {line} (J P[2]) (line{line:03d}_J)", name, side)
                   for ln in out), out


@settings(max_examples=3, deadline=None, derandomize=True, database=None)
@given(point=st.sampled_from([4, 6, 9]), mm_s=st.floats(1e-4, 0.02))
def test_a_move_too_slow_to_simulate_names_its_line_before_it_is_solved(point: int,
                                                                         mm_s: float) -> None:
    # a speed typed a thousand times too slow: refused before its inverse kinematics (it
    # was solved for minutes first), naming the program's line
    def slow(t: str) -> str:
        return re.sub(rf"(L P\[{point}\]) \d+mm/sec", rf"\g<1> {mm_s:.5f}mm/sec", t)

    with tempfile.TemporaryDirectory() as tmp:
        scen, text = _program_copy(Path(tmp), slow)
        line, _ = _move_line(text, "L", point)
        t0 = time.process_time()
        code, out, err = _cli(["check", str(scen)])
        assert time.process_time() - t0 < 20.0  # CPU time: a few planned moves, not 10^5 IKs
        assert code == 2 and len(err) == 1, (out, err)
        assert f"tp.toml: {PROGRAM}: line {line} (L P[{point}]) (line{line:03d}_L): the move " \
            "lasts" in err[0] and "longer than a run can simulate (2000 s" in err[0], err


@settings(max_examples=4, deadline=None, derandomize=True, database=None)
@given(seconds=st.lists(st.floats(100.0, 1900.0), min_size=2, max_size=4).filter(
    lambda xs: sum(xs) > 2100.0))
def test_a_cycle_too_long_names_its_longest_phase(seconds: list[float]) -> None:
    holds = "".join(f"""
[[phases]]
name = "wait{k}"
kind = "hold"
duration_s = {s!r}
""" for k, s in enumerate(seconds))
    longest = int(np.argmax(seconds))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "long.toml"
        path.write_text(f"""name = "long"
description = "waits longer than a run"
robot = "lrmate200ic5l"

[[phases]]
name = "swing"
planner = "434"
time_s = [0.0, 1.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [10, 0, 0, 0, -90, 0]]
{holds}""")
        code, out, err = _cli(["check", str(path)])
    assert code == 2 and len(err) == 1, (out, err)
    assert "the cycle lasts" in err[0]
    assert f"(the longest, {seconds[longest]:.4g} s: phases[{longest + 1}] (wait{longest}): " \
        "duration_s)" in err[0], err


# ------------------------------------------------------------------------------------------
# `cellsim plan` of joint moves from the cell's home
# ------------------------------------------------------------------------------------------

def _home_deg() -> dict[str, float]:
    """The robot's home (its MJCF's ``home`` keyframe where it has one, else 0 rad: what a
    bare cell starts at)."""
    root = ET.parse(MJCF).getroot()
    names = [j.get("name", "") for j in root.find("worldbody").iter("joint")]
    key = next((k for k in root.iter("key") if k.get("name") == "home"), None)
    q = [0.0] * len(names) if key is None else [float(x) for x in key.get("qpos", "").split()]
    return {n: float(np.degrees(v)) for n, v in zip(names, q, strict=False)}


@settings(max_examples=4, deadline=None, derandomize=True, database=None)
@given(targets=st.lists(st.lists(st.floats(-60.0, 60.0), min_size=6, max_size=6),
                        min_size=1, max_size=2),
       seconds=st.floats(0.5, 4.0))
def test_plan_of_joint_moves_from_home_starts_at_home(
        targets: list[list[float]], seconds: float) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "home_move.toml"
        rows = ", ".join("[" + ", ".join(repr(float(v)) for v in q) + "]" for q in targets)
        path.write_text(f"""name = "home_move"
description = "joint moves from home"
robot = "lrmate200ic5l"

[[phases]]
name = "swing"
planner = "434"
durations_s = [{", ".join(repr(float(seconds)) for _ in targets)}]
joints_deg = [{rows}]
""")
        code, out, err = _cli(["plan", str(path), "--json"])
        assert code == 0, err
        doc = json.loads("\n".join(out))
    home = _home_deg()
    (phase,) = doc["phases"]
    for j in phase["joints"]:
        first, last = j["segments"][0], j["segments"][-1]
        # the real-time polynomial at its own segment's start and end (ascending powers)
        start = sum(c * first["t0"] ** k for k, c in enumerate(first["real"]))
        end = sum(c * last["t1"] ** k for k, c in enumerate(last["real"]))
        assert np.degrees(start) == pytest.approx(home[j["name"]], abs=1e-6)
        assert np.degrees(end) == pytest.approx(targets[-1][j["index"] - 1], abs=1e-6)
