"""Collisions and clearance between two robots of one cell (issue 28).

Specifications:

* two LR Mate 200iC/5L with MIG torches facing each other, each driven by a joint phase whose
  knot its own inverse kinematics puts at a common point (torch down): the planted crossing is
  reported as a ``robot_robot`` collision of the two tools naming both robots (bodies,
  ``robots``, ``message``), over every sample where the oracle finds the tools overlapping and
  as deep as it finds them; it fails the verdict, ``cellsim run --strict`` and ``cellsim
  check`` exit 1 and say both robots;
* the clean variant (the tips apart along the line between the bases) reports no collision,
  and its clearance between the robots is the oracle's smallest distance (the tools', and every
  geom's); below ``simulation.clearance_mm`` it is a warning naming both robots;
* the coarse search bounds each robot's geoms by its own joints (every geom of either robot
  moves less within a coarse interval than its robot's bound);
* faults planted in the collision check (a model dropping r2's tool; a coarse search bounding
  r2's geoms as if r2 stood still, blind to r2 swinging through the other robot's tool between
  two coarse samples) are caught by the oracle.

The oracle (:mod:`support.robot_pair_oracle`) measures the two robots from the recorded
``qpos`` without cellsim's collision code. The geometry is generated (hypothesis): the bases'
distance and yaws, the crossing point and, for the clean variant, how far apart the tips pass;
one example of each in the fast share, more under ``slow``.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.robot_pair_oracle import (
    RANGE_M,
    Pair,
    PairDistances,
    pair_distances,
    tool_geoms,
    write_pair,
)

from sim.cli import main

#: Penetration cellsim tolerates before a contact is a collision, mm.
TOLERANCE_MM = 0.1
#: The tool bodies of the two robots.
TOOLS = {"robot/tool/torch", "r2/tool/torch"}

#: The fast share's examples: a crossing, and the same cell with the tips 130 mm apart.
CROSSING = Pair(1300.0, 4.0, -6.0, (15.0, 25.0, 300.0), 0.0)
CLEAN = Pair(1300.0, 4.0, -6.0, (15.0, 25.0, 300.0), 130.0)


def pairs(sep: st.SearchStrategy[float]) -> st.SearchStrategy[Pair]:
    """Two robots 1.2 to 1.4 m apart, each turned up to 8 deg off facing the other, their
    tips commanded to a point near the middle, 200 to 400 mm above the floor."""
    return st.builds(Pair, st.floats(1200.0, 1400.0), st.floats(-8.0, 8.0),
                     st.floats(-8.0, 8.0),
                     st.tuples(st.floats(-40.0, 40.0), st.floats(-80.0, 80.0),
                               st.floats(200.0, 400.0)), sep)


# --------------------------------------------------------------------------------------------
# Runs
# --------------------------------------------------------------------------------------------


def _run(folder: Path, pair: Pair, clearance_mm: float | None = None) -> dict[str, Any]:
    """``cellsim run --strict`` on the pair's scenario: its exit code, console output,
    summary, recorded arrays, compiled model and the oracle's distances."""
    import mujoco

    path = write_pair(folder, pair, clearance_mm=clearance_mm)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = main(["run", str(path), "--strict", "--no-video", "--no-plots", "--quiet",
                   "--out", str(folder / "run")])
    run = folder / "run"
    arrays = dict(np.load(run / "trajectory.npz"))
    model = mujoco.MjModel.from_xml_path(str(run / "model.xml"))
    return {"path": path, "rc": rc, "out": out.getvalue(), "arrays": arrays, "model": model,
            "summary": json.loads((run / "summary.json").read_text()),
            "oracle": pair_distances(model, arrays["qpos"])}


@pytest.fixture(scope="module")
def crossing(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("crossing"), CROSSING)


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("clean"), CLEAN, clearance_mm=100.0)


# --------------------------------------------------------------------------------------------
# What the oracle asserts
# --------------------------------------------------------------------------------------------


def assert_crossing_reported(collisions: list[dict[str, Any]], t: np.ndarray,
                             od: PairDistances, t_cross: float) -> None:
    """The planted crossing happened (the tips met) and the report has it: every sample where
    the oracle finds the tools overlapping beyond the tolerance lies in a tool-tool collision
    naming both robots, as deep as the oracle finds it; every robot-robot collision is an
    overlap of the oracle's."""
    i_cross = int(np.argmin(np.abs(t - t_cross)))
    assert od.tips[i_cross] < 0.5e-3, "the tips did not meet: no crossing was planted"
    assert od.tools[i_cross] < -TOLERANCE_MM * 1e-3
    tool_tool = [c for c in collisions if set(c["bodies"]) == TOOLS]
    assert tool_tool, collisions
    for c in tool_tool:
        assert c["kind"] == "robot_robot" and c["robots"] == ["robot", "r2"], c
        assert c["message"].startswith("robot tool ") and " against r2 tool " in c["message"]
    deep = np.flatnonzero(od.tools < -2 * TOLERANCE_MM * 1e-3)
    assert t[i_cross] in t[deep]
    for i in deep:
        assert any(c["t0"] <= t[i] <= c["t1"] for c in tool_tool), (t[i], tool_tool)
    for c in tool_tool:
        inside = (t >= c["t0"]) & (t <= c["t1"])
        assert c["depth_mm"] == pytest.approx(-1e3 * od.tools[inside].min(), abs=1e-3)
    for c in collisions:
        if c["kind"] == "robot_robot":
            i = int(np.argmin(np.abs(t - c["t_worst"])))
            assert od.robots[i] * 1e3 <= -c["depth_mm"] + 1e-3, c


def robot_pair_clearance(clearance: list[dict[str, Any]]) -> dict[str, float]:
    """The smallest ``tool_mm`` and ``arm_mm`` of the entries between robot and r2, and of
    both (``all``), mm (inf where none is in range)."""
    rows = [c for c in clearance if c.get("robots") == ["robot", "r2"]]
    best = {g: min([c[f"{g}_mm"] for c in rows if c[f"{g}_mm"] is not None] or [np.inf])
            for g in ("tool", "arm")}
    return {**best, "all": min(best.values())}


def assert_clean_matches(collisions: list[dict[str, Any]], clearance: list[dict[str, Any]],
                         od: PairDistances) -> None:
    """No robot-robot collision, and the clearance between the robots is the oracle's smallest
    distance (the tools': a tool against the other robot's tool)."""
    assert od.robots.min() > 1e-3, "the clean variant touches: the generator is wrong"
    assert not [c for c in collisions if c["kind"] == "robot_robot"], collisions
    got = robot_pair_clearance(clearance)
    assert od.robots.min() < 0.1 and got["all"] < np.inf
    assert got["all"] == pytest.approx(1e3 * od.robots.min(), abs=1e-3)
    if od.tools.min() < RANGE_M:  # the tools in range: a tool against tool or link
        assert got["tool"] <= 1e3 * od.tools.min() + 1e-3
    assert got["all"] >= 1e3 * od.bound.min() - 1e-6  # never below the spheres' bound


# --------------------------------------------------------------------------------------------
# The fast share: one crossing, one clean run
# --------------------------------------------------------------------------------------------


def test_a_crossing_of_the_tools_is_a_collision_naming_both_robots(crossing):
    s = crossing["summary"]
    assert_crossing_reported(s["collisions"], crossing["arrays"]["t"], crossing["oracle"],
                             CROSSING.t_cross_s)
    for c in s["collisions"]:
        # r2's phase: its own with the motion at hand, "cycle" from the arrays alone
        assert c["robot_phases"]["robot"] == "cross" and c["robot_phases"]["r2"] in (
            "cross", "cycle"), c


def test_with_the_motion_each_robot_counts_in_its_own_phases(crossing):
    """Sampled with the motion, r2's entries and phases are its own (``r2: cross``)."""
    from sim.scenario import load_scenario
    from sim.simulation import collisions as C
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    sc = load_scenario(crossing["path"])
    built = build(sc)
    motion = build_motion(sc, built.context)
    samples = C.samples_from_arrays(crossing["arrays"], motion)
    report = C.check_motion(built, samples, [pm.name for pm in motion.phases],
                            C.phase_seams(motion))
    assert [c["phase"] for c in report.clearance] == [
        "start", "cross", "r2: start", "r2: cross", "start: robot / r2", "cross: robot / r2"]
    tools = [c for c in report.collisions if set(c["bodies"]) == TOOLS]
    assert tools and all(c["robot_phases"] == {"robot": "cross", "r2": "cross"} for c in tools)
    assert_crossing_reported(report.collisions, crossing["arrays"]["t"], crossing["oracle"],
                             CROSSING.t_cross_s)


def test_a_crossing_fails_the_verdict_and_strict_run_and_check_exit_1(crossing, capsys):
    s = crossing["summary"]
    assert s["verdict"] == "fail" and crossing["rc"] == 1
    failed = [c for c in s["checks"] if c["name"] == "collision" and not c["pass"]]
    assert any("robot/tool/torch / r2/tool/torch" in c["subject"] for c in failed), failed
    assert "collision robot/tool/torch / r2/tool/torch" in crossing["out"]
    assert main(["check", str(crossing["path"])]) == 1
    out = capsys.readouterr().out
    # each robot's phase (r2's named): the first robot's alone once named a phase that had
    # ended while r2's move caused the hit (found by a new-user trial)
    assert "collision: cross, r2: cross: robot_robot collision robot/tool/torch / r2/tool/torch" \
        in out


@pytest.mark.parametrize(("entry", "label"), [
    ({"phase": "weld"}, "weld"),  # one robot
    ({"phase": "park", "robot_phases": {"robot": "park"}}, "park"),  # the first against the cell
    ({"phase": "park", "robot_phases": {"r2": "clear"}}, "r2: clear"),  # r2 against the cell
    ({"phase": "park", "robot_phases": {"robot": "park", "r2": "clear"}}, "park, r2: clear"),
])
def test_a_collision_is_labelled_with_each_robots_own_phase(entry, label):
    from sim.simulation.collisions import collision_phase

    assert collision_phase(entry) == label


def test_the_clean_variant_has_no_collision_and_the_oracles_clearance(clean):
    s = clean["summary"]
    assert s["collisions"] == []
    assert_clean_matches(s["collisions"], s["clearance"], clean["oracle"])


def test_a_near_miss_is_a_clearance_warning_naming_both_robots(clean):
    """The clean run's robots pass closer than its ``simulation.clearance_mm`` (100 mm): a
    warning (the verdict passes, ``--strict`` too) whose subject names both robots."""
    s = clean["summary"]
    assert s["verdict"] == "pass" and clean["rc"] == 0
    warned = [c for c in s["checks"] if c["name"] == "clearance" and not c["pass"]]
    assert warned and all(c["severity"] == "warning" for c in warned)
    assert all(c["subject"].endswith(": robot / r2") for c in warned), warned
    assert min(c["value"] for c in warned) == pytest.approx(
        robot_pair_clearance(s["clearance"])["all"])
    assert "warning: clearance cross: robot / r2:" in clean["out"]


def test_each_robot_is_bounded_by_its_own_joints(crossing):
    """Within each coarse interval no geom of either robot moves farther than its robot's
    bound, and the first robot's bound leaves out r2's joints (r2 moving alone: 0)."""
    from sim.scenario import load_scenario
    from sim.simulation import collisions as C
    from sim.simulation.compile import build

    built = build(load_scenario(crossing["path"]))
    samples = C.samples_from_arrays(crossing["arrays"])
    cm = C.CollisionModel(built)
    coarse = C.coarse_samples(samples)
    bounds = C.motion_bound(cm, samples, coarse)
    for robot, key in (("robot", C.LINK), ("r2", "r2/")):
        moved = _displacement(cm.model, samples.qpos, coarse,
                              np.array(sorted(cm.ids(robot=robot))))
        assert np.all(moved <= bounds[key] + 1e-12), robot
        assert np.max(moved) > 0.0
    # r2 alone moving: the first robot's bound is 0
    qpos = samples.qpos.copy()
    lead = built.robot_qpos[:built.cell.robot.n_joints]
    qpos[:, lead] = qpos[0, lead]
    alone = C.MotionSamples(samples.t, qpos, samples.phase, samples.arc_on, samples.suction)
    b = C.motion_bound(cm, alone, coarse)
    assert np.max(b[C.LINK]) == 0.0 and np.max(b["r2/"]) > 0.0


def _displacement(model: Any, qpos: np.ndarray, coarse: np.ndarray, ids: np.ndarray
                  ) -> np.ndarray:
    """The farthest any of the geoms ``ids`` moves from an interval's first sample within each
    coarse interval, m."""
    import mujoco

    data = mujoco.MjData(model)
    pos = np.empty((qpos.shape[0], ids.size, 3))
    for i in range(qpos.shape[0]):
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        pos[i] = data.geom_xpos[ids]
    out = np.zeros(len(coarse) - 1)
    for k in range(len(coarse) - 1):
        seg = pos[coarse[k]:coarse[k + 1] + 1]
        out[k] = np.max(np.linalg.norm(seg - seg[0], axis=2))
    return out


# --------------------------------------------------------------------------------------------
# Planted faults
# --------------------------------------------------------------------------------------------


def _dropping_r2_tool(base: Any) -> Any:
    """A collision model class that leaves r2's tool out (the fault)."""

    class Dropping(base):  # type: ignore[misc, valid-type]
        def __init__(self, built: Any) -> None:
            import mujoco

            super().__init__(built)
            for g in self.ids(role="tool", robot="r2"):
                del self.geoms[g]
                self.role[g] = -1
                self.robot_of[g] = -1
            self.model = self._masked(built.model, 1e-3, every=True)
            self.range_model = self._masked(built.model, 0.1)
            self.pair_model = self._masked(built.model, 0.1, robots_only=True)
            self._data = mujoco.MjData(self.model)
            self._range_data = mujoco.MjData(self.range_model)
            self._pair_data = mujoco.MjData(self.pair_model)

    return Dropping


def _check(run: dict[str, Any]) -> Any:
    from sim.scenario import load_scenario
    from sim.simulation import collisions as C
    from sim.simulation.compile import build

    built = build(load_scenario(run["path"]))
    return C.check_motion(built, C.samples_from_arrays(run["arrays"]), ["start", "cross"],
                          [None, None])


def test_the_oracle_catches_a_model_that_drops_r2s_tool(crossing, clean, monkeypatch):
    from sim.simulation import collisions as C

    # the check itself, called as the run calls it, agrees with the oracle
    good = _check(crossing)
    assert_crossing_reported(good.collisions, crossing["arrays"]["t"], crossing["oracle"],
                             CROSSING.t_cross_s)
    monkeypatch.setattr(C, "CollisionModel", _dropping_r2_tool(C.CollisionModel))
    bad = _check(crossing)
    assert not [c for c in bad.collisions if set(c["bodies"]) == TOOLS]
    with pytest.raises(AssertionError):
        assert_crossing_reported(bad.collisions, crossing["arrays"]["t"], crossing["oracle"],
                                 CROSSING.t_cross_s)
    bad = _check(clean)
    with pytest.raises(AssertionError):
        assert_clean_matches(bad.collisions, bad.clearance, clean["oracle"])
    # the oracle without r2's tool agrees with the faulty model: what it measures is the tool
    tool = frozenset(tool_geoms(clean["model"], "r2").tolist())
    dropped = pair_distances(clean["model"], clean["arrays"]["qpos"], drop=tool)
    assert robot_pair_clearance(bad.clearance)["all"] == pytest.approx(
        1e3 * dropped.robots.min(), abs=1e-3)


def _swipe(run: dict[str, Any]) -> tuple[Any, Any]:
    """The crossing's cell with the first robot standing at the crossing and r2 swinging its
    J1 through it in 31 ms (1 kHz samples, 0.06 rad each: the robots do not touch at the
    coarse samples 10 ms before and after): (the compiled cell, the samples)."""
    from sim.scenario import load_scenario
    from sim.simulation import collisions as C
    from sim.simulation.compile import build

    built = build(load_scenario(run["path"]))
    t = run["arrays"]["t"]
    q0 = run["arrays"]["qpos"][int(np.argmin(np.abs(t - CROSSING.t_cross_s)))]
    n = 31
    qpos = np.tile(q0, (n, 1))
    j1 = built.robot_qpos[built.partner_cols["r2"]][0]
    qpos[:, j1] += np.linspace(-0.9, 0.9, n)
    samples = C.MotionSamples(np.arange(n) * 1e-3, qpos, np.zeros(n, int), np.zeros(n, bool),
                              np.zeros(n, bool))
    return built, samples


def test_the_coarse_search_follows_r2s_motion_and_the_oracle_catches_one_blind_to_it(
        crossing, monkeypatch):
    """r2 swinging through the first robot's tool between two coarse samples: the check finds
    every overlapping sample the oracle finds; a coarse search bounding r2's geoms as if r2
    stood still rules that interval out, and the oracle catches it."""
    from sim.simulation import collisions as C

    built, samples = _swipe(crossing)
    od = pair_distances(built.model, samples.qpos)
    coarse = C.coarse_samples(samples)
    assert list(coarse) == [0, 10, 20, 30]
    assert od.tools[15] < -0.01 and np.all(od.robots[coarse] > 0.0)  # hidden between them
    report = C.check_motion(built, samples, ["swipe"], [None])
    assert_crossing_reported(report.collisions, samples.t, od, 0.015)
    real = C.motion_bound

    def blind(cm, samples, coarse):
        out = real(cm, samples, coarse)
        out["r2/"] = np.zeros_like(out["r2/"])
        return out

    monkeypatch.setattr(C, "motion_bound", blind)
    bad = C.check_motion(built, samples, ["swipe"], [None])
    assert bad.collisions == []
    with pytest.raises(AssertionError):
        assert_crossing_reported(bad.collisions, samples.t, od, 0.015)


# --------------------------------------------------------------------------------------------
# The slow share: generated cells
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
@settings(max_examples=6, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(pair=pairs(st.just(0.0)))
def test_generated_crossings_are_reported_naming_both_robots(pair, tmp_path_factory):
    run = _run(tmp_path_factory.mktemp("gen_crossing"), pair)
    s = run["summary"]
    assert_crossing_reported(s["collisions"], run["arrays"]["t"], run["oracle"], pair.t_cross_s)
    assert s["verdict"] == "fail" and run["rc"] == 1


@pytest.mark.slow
@settings(max_examples=6, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(pair=pairs(st.floats(110.0, 170.0)))
def test_generated_clean_passes_have_the_oracles_clearance(pair, tmp_path_factory):
    run = _run(tmp_path_factory.mktemp("gen_clean"), pair)
    s = run["summary"]
    assert_clean_matches(s["collisions"], s["clearance"], run["oracle"])
    assert s["collisions"] == [] and run["rc"] == 0
