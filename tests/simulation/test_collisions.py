"""Collisions and clearance (issue 11): the robot may not go through itself, its tool or its cell.

Specifications:

* a linear move that plunges the torch through the welding table's base plate reports a
  tool-plate collision starting when the wire tip reaches the plate top, fails the verdict, and
  makes ``cellsim run --strict`` and ``cellsim check`` exit 1;
* a joint move folding the LR Mate 200iC/5L's forearm down into its own base reports a
  self-collision in that phase, with the same consequences;
* the clearance reported for a cylinder tool over a box fixture equals the analytic distance;
* every shipped scenario passes ``cellsim check`` (seed 000's sequence excepted: it exceeds the
  100iB's J2 speed and acceleration limits by design) and runs with ``"collisions": []``;
* allowed contacts are declared: the wire on the seam's workpiece while the arc is on, the cup
  lip on the part it picks; the nozzle never.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from support.scenarios import joint_phase, write_scenario

from sim.cli import main
from sim.core.resources import shipped_scenarios
from sim.pipeline.run import RunOptions, run_scenario
from sim.scenario import load_scenario, parse_scenario

HEAD = """name = "{name}"
description = "collision test"
robot = "lrmate200ic5l"
{cell}

[[phases]]
name = "start"
planner = "434"
time_s = [0.0, 0.5, 1.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [0, 0, 0, 0, -90, 0], [0, 0, 0, 0, -90, 0]]
"""

#: Torch pointing down above the base plate (top at z = -150 mm in frame 0, clear of the V
#: plates and the wall), then straight down 100 mm at 50 mm/s: 50 mm through the plate top.
PLUNGE = HEAD.format(name="plunge", cell='cell = "weld_table"\ntool = "mig_torch"') + """
[[phases]]
name = "above"
planner = "434"
durations_s = [1.5]
to_mm = [330.0, 120.0, -100.0]
euler_zyx_deg = [0.0, 0.0, 180.0]

[[phases]]
name = "plunge"
kind = "linear"
to_mm = [330.0, 120.0, -200.0]
speed_mm_s = 50.0
"""

#: The forearm folded down into the robot's own base (bare scene, no tool).
FOLD = HEAD.format(name="fold", cell="") + """
[[phases]]
name = "fold"
planner = "434"
durations_s = [3.0]
joints_deg = [[0.0, 60.0, -140.0, 0.0, -90.0, 0.0]]
"""


def _write(tmp_path: Path, text: str, name: str) -> Path:
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


def _run(tmp_path_factory, text: str, name: str):
    """Run a scenario text (no video, plots or sizing): (folder, scenario path, summary)."""
    tmp = tmp_path_factory.mktemp(name)
    path = _write(tmp, text, name)
    summary = run_scenario(load_scenario(path), RunOptions(
        out_dir=tmp / "run", video=False, plots=False, sizing=False, progress=False))
    return tmp, path, summary


@pytest.fixture(scope="module")
def plunge_run(tmp_path_factory):
    return _run(tmp_path_factory, PLUNGE, "plunge")


@pytest.fixture(scope="module")
def fold_run(tmp_path_factory):
    return _run(tmp_path_factory, FOLD, "fold")


def _plate_top(run_dir: Path) -> float:
    import mujoco

    m = mujoco.MjModel.from_xml_path(str(run_dir / "model.xml"))
    g = m.geom("base_plate")
    return float(m.geom_pos[g.id][2] + m.geom_size[g.id][2])


def test_plunge_reports_tool_plate_collision_from_the_plate_top(plunge_run):
    tmp, _, summary = plunge_run
    run_dir = tmp / "run"
    traj = np.load(run_dir / "trajectory.npz")
    t, tip_z = traj["t"], traj["tcp_pos"][:, 2]
    top = _plate_top(run_dir)
    t_hit = float(t[np.argmax(tip_z <= top)])  # the wire tip reaches the plate top
    hits = [c for c in summary["collisions"]
            if c["bodies"] == ["robot/tool/torch", "base_plate"]]
    assert hits, summary["collisions"]
    first = hits[0]
    assert first["phase"] == "plunge" and first["kind"] == "cell"
    assert t_hit - 0.05 <= first["t0"] <= t_hit + 0.5, (t_hit, first)
    # 50 mm through the plate top: the worst penetration is tens of mm, found at the end
    assert first["depth_mm"] > 20.0
    assert summary["verdict"] == "fail"
    failed = [c for c in summary["checks"] if c["name"] == "collision" and not c["pass"]]
    assert failed and all(c["severity"] == "error" for c in failed)


def test_plunge_strict_run_and_check_exit_1(plunge_run, capsys):
    tmp, path, _ = plunge_run
    assert main(["run", str(path), "--strict", "--no-video", "--no-plots", "--quiet",
                 "--out", str(tmp / "strict")]) == 1
    assert "collision robot/tool/torch / base_plate" in capsys.readouterr().out
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out
    assert "collision: plunge: cell collision robot/tool/torch / base_plate" in out


def test_fold_reports_a_self_collision_in_its_phase(fold_run, capsys):
    _, path, summary = fold_run
    selfs = [c for c in summary["collisions"] if c["kind"] == "self"]
    assert selfs, summary["collisions"]
    assert all(c["phase"] == "fold" for c in selfs)
    into_base = [c for c in selfs if c["bodies"][0] in ("robot/base", "robot/link1")
                 or c["bodies"][1] in ("robot/base", "robot/link1")]
    assert into_base, selfs
    # penetration depths are measured (GJK/EPA), not read off contact points: a fold that
    # keeps two links overlapping is one interval, not a flicker of short ones
    by_pair: dict = {}
    for c in selfs:
        by_pair.setdefault(tuple(c["bodies"]), []).append(c)
    for pair, hits in by_pair.items():
        gaps = [b["t0"] - a["t1"] for a, b in zip(hits, hits[1:])]
        assert all(g > 0.01 for g in gaps), (pair, gaps)
    assert summary["verdict"] == "fail"
    assert main(["check", str(path)]) == 1
    assert "self collision" in capsys.readouterr().out


def test_fold_strict_exits_1(fold_run, tmp_path):
    _, path, _ = fold_run
    assert main(["run", str(path), "--strict", "--no-video", "--no-plots", "--quiet",
                 "--out", str(tmp_path / "strict")]) == 1


def _torch_samples(built, poses):
    """Samples of a static torch at each pose (frame 0, (4, 4)), one phase each."""
    from sim.robots.kinematics.ik import solve_ik
    from sim.simulation.collisions import MotionSamples

    qs = []
    for T in poses:
        sols = [s for s in solve_ik(built.context.kinematics, T,
                                    current=np.radians([0, 0, 0, 0, -90, 0]))
                if s.within_limits]
        qs.append(sols[0].q)
    n = len(qs)
    qpos = np.tile(built.model.key_qpos[0], (n, 1))
    qpos[:, built.robot_qpos] = np.array(qs)
    return MotionSamples(t=np.arange(n) * 1.0, qpos=qpos, phase=np.arange(n),
                         arc_on=np.zeros(n, bool), suction=np.zeros(n, bool))


@pytest.mark.parametrize("tilt_deg", [0.0, 10.0, 25.0])
@pytest.mark.parametrize("height_mm", [3.0, 12.0, 40.0])
def test_clearance_equals_the_analytic_distance(tilt_deg, height_mm):
    """A straight torch (cylinders: contact tip r 4 mm ending 15 mm behind the wire tip, nozzle
    r 11 mm ending 17 mm behind it) tilted by ``tilt`` over the base plate (a box): the tool's
    clearance is the height of the lowest point of its cylinders' end discs over the plate top,
    ``min(z_end - r sin(tilt))`` (the wire is a work geom and left out)."""
    from sim.core.rotations import rot_y
    from sim.simulation.collisions import check_motion
    from sim.simulation.compile import build

    sc = parse_scenario(PLUNGE)
    built = build(sc)
    top0 = -0.150  # plate top in frame 0
    a = np.radians(tilt_deg)
    R = np.array([[1.0, 0, 0], [0, -1.0, 0], [0, 0, -1.0]]) @ rot_y(a)  # tool z down, tilted
    axis = R[:, 2]
    # the wire tip (tcp) such that the contact tip's end disc sits height_mm over the plate
    tip_z = top0 + height_mm * 1e-3 - 0.015 * (-axis[2]) + 0.004 * np.sin(a)
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = [0.33, 0.12, tip_z]
    samples = _torch_samples(built, [T])
    report = check_motion(built, samples, ["static"], [None])
    ends = {"contact_tip": (0.015, 0.004), "nozzle": (0.017, 0.011)}
    expected = min(tip_z + back * (-axis[2]) - r * np.sin(a) - top0 for back, r in ends.values())
    got = report.clearance[0]["tool_mm"]
    assert got == pytest.approx(expected * 1e3, abs=0.1), report.clearance[0]
    assert report.clearance[0]["tool_pair"][1] == "base_plate"


def _wire_sinks(sinks_mm, arc_on: bool):
    """Collisions of a torch pointing down with its wire tip sunk into the base plate (a
    workpiece of the 'arc' seam), one static sample per depth, one phase welding 'arc'."""
    from sim.simulation.collisions import (
        CollisionModel,
        allowed_contacts,
        find_collisions,
    )
    from sim.simulation.compile import build

    built = build(parse_scenario(PLUNGE))
    poses = []
    for sink in sinks_mm:
        T = np.eye(4)
        T[:3, :3] = np.diag([1.0, -1.0, -1.0])
        T[:3, 3] = [0.33, 0.12, -0.150 - sink * 1e-3]
        poses.append(T)
    samples = _torch_samples(built, poses)
    samples.arc_on[:] = arc_on
    samples.phase[:] = 0
    cm = CollisionModel(built)
    found = find_collisions(cm, samples, ["weld"], allowed_contacts(cm, samples, ["arc"]))
    return [c for c in found if c["kind"] == "cell"]


def test_wire_in_the_pool_is_allowed_with_the_arc_on_the_nozzle_never():
    """Arc on along the seam: the wire 1 mm into its workpiece is the tip in the weld pool
    (allowed up to its radius + 1 mm); 5 mm deep, or the nozzle on the plate, is a collision."""
    found = _wire_sinks([1.0, 5.0, 30.0], arc_on=True)
    assert found and all(c["t0"] >= 1.0 for c in found)  # not at 0: 1 mm is allowed
    plate = [c for c in found if c["bodies"] == ["robot/tool/torch", "base_plate"]]
    assert len(plate) == 1 and plate[0]["t0"] == 1.0 and plate[0]["t1"] == 2.0
    assert plate[0]["geoms"][0] in ("robot/tool/nozzle", "robot/tool/contact_tip")
    assert "robot/tool/wire" in plate[0]["all_geoms"]


def test_wire_touching_with_the_arc_off_only_up_to_its_touch_depth():
    """Arc off: the wire may touch a workpiece up to its radius + the torch's touch depth
    (0.6 + 0.5 mm: touch sensing, the tip set on the root); 1.5 mm deep is a collision from the
    first sample."""
    assert _wire_sinks([0.5, 1.0], arc_on=False) == []
    found = _wire_sinks([1.5, 30.0], arc_on=False)
    assert found and found[0]["t0"] == 0.0
    assert found[0]["bodies"] == ["robot/tool/torch", "base_plate"]
    assert found[0]["depth_mm"] > 10.0 and "robot/tool/wire" in found[0]["all_geoms"]


def test_clearance_finds_the_minimum_between_coarse_samples():
    """The torch goes down and up twice over the plate, its contact tip's lowest point at
    ``h(t) = min(10 + 400 |t - 0.055|, 10.8 + 400 |t - 0.15|)`` mm: the true minimum, 10 mm at
    0.055 s, lies between two coarse samples (every 10 ms) and a shallower dip (10.8 mm) sits on
    one; the reported clearance is the true minimum."""
    from sim.simulation.collisions import check_motion
    from sim.simulation.compile import build

    built = build(parse_scenario(PLUNGE))
    t = np.arange(0.0, 0.2005, 0.001)
    h = np.minimum(10.0 + 400.0 * np.abs(t - 0.055), 10.8 + 400.0 * np.abs(t - 0.15))
    poses = []
    for hk in h:
        T = np.eye(4)
        T[:3, :3] = np.diag([1.0, -1.0, -1.0])
        T[:3, 3] = [0.33, 0.12, -0.150 + hk * 1e-3 - 0.015]  # contact tip end 15 mm up
        poses.append(T)
    samples = _torch_samples(built, poses)
    samples.t = t
    samples.phase[:] = 0
    report = check_motion(built, samples, ["dips"], [None])
    entry = report.clearance[0]
    assert entry["tool_mm"] == pytest.approx(10.0, abs=0.1), entry
    assert entry["tool_t"] == pytest.approx(0.055, abs=1e-9)


@pytest.mark.parametrize("name", sorted(shipped_scenarios()))
def test_shipped_scenario_passes_cellsim_check(name, capsys):
    """`cellsim check` finds nothing on a shipped scenario, except the kinds of finding its
    [expect] table declares (check_findings, with a reason)."""
    expected = set(load_scenario(name).expect.check_findings)
    rc = main(["check", name])
    out = capsys.readouterr().out
    if expected:
        assert rc == 1
        kinds = {line.split(":")[0] for line in out.splitlines() if ": " in line}
        assert kinds - {name} == expected, out
    else:
        assert rc == 0, out
        assert "collision" not in out


@pytest.mark.parametrize("name", sorted(shipped_scenarios()))
def test_shipped_scenario_runs_without_collision(name, scenario_run):
    run_dir, summary = scenario_run(name)
    assert summary["collisions"] == [], summary["collisions"]
    stored = json.loads((run_dir / "summary.json").read_text())
    assert stored["collisions"] == []
    # the first robot's entries: one per phase (a cell's other robots add theirs, named)
    assert {c["phase"] for c in stored["clearance"]
            if "robot" not in c and "robots" not in c} == {p["name"] for p in stored["phases"]}
    assert any(c["name"] == "collision" and c["pass"] for c in stored["checks"])


def test_video_paints_the_colliding_geoms_red_while_they_touch(plunge_run):
    """The renderer's scene (built without OpenGL here) has the torch and the plate red inside
    the collision interval and their own colours before it."""
    import mujoco

    from sim.render.frames import COLLISION_RGBA, CollisionPainter

    tmp, _, summary = plunge_run
    model = mujoco.MjModel.from_xml_path(str(tmp / "run" / "model.xml"))
    data = mujoco.MjData(model)
    traj = np.load(tmp / "run" / "trajectory.npz")
    hit = next(c for c in summary["collisions"] if c["bodies"][1] == "base_plate")
    painter = CollisionPainter(model, summary["collisions"])
    plate, nozzle = model.geom("base_plate").id, model.geom("robot/tool/nozzle").id
    for time, inside in ((hit["t0"] - 0.5, False), (0.5 * (hit["t0"] + hit["t1"]), True)):
        i = int(np.searchsorted(traj["t"], time))
        data.qpos[:] = traj["qpos"][i]
        mujoco.mj_kinematics(model, data)
        scene = mujoco.MjvScene(model, maxgeom=2000)
        mujoco.mjv_updateScene(model, data, mujoco.MjvOption(), None, mujoco.MjvCamera(),
                               mujoco.mjtCatBit.mjCAT_ALL, scene)
        painted = painter.paint(scene, float(traj["t"][i]))
        red = {int(g.objid) for g in scene.geoms[:scene.ngeom]
               if g.objtype == mujoco.mjtObj.mjOBJ_GEOM
               and np.allclose(g.rgba, COLLISION_RGBA)}
        assert (painted > 0) is inside
        assert ({plate, nozzle} <= red) is inside, (time, red)


def test_held_part_in_transfer_hitting_the_cell_is_a_collision():
    """The pick scenario's reference with part0 pushed 10 mm into the infeed table during a
    transfer phase: a collision while suction holds it, and when it rests too (deeper than a
    resting contact's 1 mm); 0.5 mm deep at rest is a resting contact."""
    from sim.simulation.collisions import (
        CollisionModel,
        allowed_contacts,
        find_collisions,
        phase_seams,
        samples_from_motion,
    )
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    sc = load_scenario("lrmate200ic_pick_place")
    built = build(sc)
    motion = build_motion(sc, built.context)
    samples = samples_from_motion(built, motion, 0.01)
    names = [pm.name for pm in motion.phases]
    k = names.index("above_slot0")
    sel = samples.phase == k
    adr = built.part_qpos[0]
    samples.qpos[np.ix_(sel, adr[2:3])] -= 0.01  # 10 mm down into the infeed table
    cm = CollisionModel(built)
    found = find_collisions(cm, samples, names, allowed_contacts(cm, samples, phase_seams(motion)))
    held = [c for c in found if c["kind"] == "held_part"]
    assert held and all(c["phase"] == "above_slot0" for c in held), found
    assert held[0]["bodies"] == ["part0", "infeed_top"]
    assert held[0]["depth_mm"] == pytest.approx(10.0, abs=0.5)
    # nothing held: a part resting 0.5 mm into the table is a resting contact; 10 mm is not
    samples.suction[:] = False
    found = find_collisions(cm, samples, names, allowed_contacts(cm, samples, phase_seams(motion)))
    assert [c["bodies"] for c in found] == [["part0", "infeed_top"]]
    samples.qpos[np.ix_(sel, adr[2:3])] += 0.0095
    found = find_collisions(cm, samples, names, allowed_contacts(cm, samples, phase_seams(motion)))
    assert found == []


@pytest.mark.parametrize("text", [PLUNGE, FOLD], ids=["plunge", "fold"])
def test_the_coarse_scan_skips_no_sample_that_collides(text):
    """Checking only the intervals the coarse scan cannot rule out finds the same collisions as
    checking every sample of the reference (1 kHz)."""
    from sim.simulation import collisions as C
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    sc = parse_scenario(text)
    built = build(sc)
    motion = build_motion(sc, built.context)
    samples = C.samples_from_motion(built, motion, 0.001)
    cm = C.CollisionModel(built)
    allowed = C.allowed_contacts(cm, samples, C.phase_seams(motion))
    names = [pm.name for pm in motion.phases]
    fast = C.find_collisions(cm, samples, names, allowed)
    every = cm.scan(samples.qpos, np.arange(samples.t.size))
    every = every.select(~C.allowed_mask(every, allowed))
    colliding = np.unique(every.s)
    assert colliding.size > 0
    # every colliding sample lies in a reported interval of its pair
    spans = [(c["t0"], c["t1"]) for c in fast]
    for i in colliding:
        assert any(t0 <= samples.t[i] <= t1 for t0, t1 in spans), samples.t[i]
    # and the intervals begin and end on colliding samples (none invented)
    firsts = {float(samples.t[i]) for i in colliding}
    assert all(c["t0"] in firsts and c["t1"] in firsts for c in fast)
    # the bound does its job: far fewer samples are checked one by one than there are
    coarse = C.coarse_samples(samples)
    checked = C._intervals_to_check(cm, samples, coarse,
                                    cm.scan(samples.qpos, coarse, ranged=True), allowed)
    assert sum(b - a + 1 for a, b in checked) < samples.t.size


def test_motion_bound_bounds_every_geom_displacement():
    """Within each coarse interval of the fold, no checked geom's centre moves farther than
    :func:`motion_bound` (computed from joint travel and reach, not from the geoms' paths)."""
    import mujoco

    from sim.simulation import collisions as C
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    sc = parse_scenario(FOLD)
    built = build(sc)
    motion = build_motion(sc, built.context)
    samples = C.samples_from_motion(built, motion, 0.001)
    cm = C.CollisionModel(built)
    coarse = C.coarse_samples(samples)
    bound = C.motion_bound(cm, samples, coarse)[C.LINK]  # the robot's geoms (no part here)
    model, data = cm.model, mujoco.MjData(cm.model)
    ids = np.array(sorted(cm.geoms))
    pos = np.empty((samples.t.size, ids.size, 3))
    for i in range(samples.t.size):
        data.qpos[:] = samples.qpos[i]
        mujoco.mj_kinematics(model, data)
        pos[i] = data.geom_xpos[ids]
    for k in range(len(coarse) - 1):
        seg = pos[coarse[k]:coarse[k + 1] + 1]
        moved = np.max(np.linalg.norm(seg - seg[0], axis=2))
        assert moved <= bound[k] + 1e-12, (k, moved, bound[k])
    assert np.max(bound) > 0.0



def _pick_with(part: str, phase: str, shift, suction: bool | None = None):
    """Collisions of the pick scenario's reference with ``part`` moved by ``shift`` (m, world)
    during ``phase`` (optionally with suction forced on or off everywhere)."""
    from sim.simulation import collisions as C
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    sc = load_scenario("lrmate200ic_pick_place")
    built = build(sc)
    motion = build_motion(sc, built.context)
    samples = C.samples_from_motion(built, motion, 0.005)
    names = [pm.name for pm in motion.phases]
    sel = samples.phase == names.index(phase)
    adr = built.part_qpos[built.cell.parts.index(part)]
    samples.qpos[np.ix_(sel, adr[:3])] += np.asarray(shift, float)
    if suction is not None:
        samples.suction[:] = suction
    cm = C.CollisionModel(built)
    return C.find_collisions(cm, samples, names,
                             C.allowed_contacts(cm, samples, C.phase_seams(motion)))


def test_held_part_driven_into_a_resting_part_is_a_collision():
    """part0, held during above_slot0, pushed 30 mm along +x into part1 resting next to it."""
    found = [c for c in _pick_with("part0", "above_slot0", [0.05, 0.0, 0.0])
             if set(c["bodies"]) == {"part0", "part1"}]
    assert found and found[0]["phase"] == "above_slot0" and found[0]["depth_mm"] > 20.0


def test_held_part_set_down_into_the_tray_floor_is_a_collision():
    """Set-down may touch the tray up to 1 mm: part0 put in its slot 0.5 mm deep while it is
    lowered is a set-down contact; 10 mm into the tray floor at release is a collision."""
    from sim.simulation import collisions as C
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    sc = load_scenario("lrmate200ic_pick_place")
    built = build(sc)
    motion = build_motion(sc, built.context)
    samples = C.samples_from_motion(built, motion, 0.005)
    names = [pm.name for pm in motion.phases]
    adr = built.part_qpos[0]
    slot = np.asarray(built.cell.slots[0])
    for phase, sink in (("down_slot0", 0.0005), ("release0", 0.010)):
        sel = samples.phase == names.index(phase)
        samples.qpos[np.ix_(sel, adr[:3])] = slot - [0.0, 0.0, sink]
        samples.qpos[np.ix_(sel, adr[3:7])] = [1.0, 0.0, 0.0, 0.0]
    cm = C.CollisionModel(built)
    found = C.find_collisions(cm, samples, names,
                              C.allowed_contacts(cm, samples, C.phase_seams(motion)))
    hits = [c for c in found if c["bodies"][0] == "part0"]
    assert hits and {c["phase"] for c in hits} == {"release0"}, found
    assert hits[0]["bodies"][1] == "tray_floor"
    assert hits[0]["depth_mm"] == pytest.approx(10.0, abs=0.6)


# ------------------------------------------------------- where the tool meets the last link
MOUNT_ARMS = ("m10ia", "m20ia", "ar2010", "irb1600", "kr10r1420", "kr6r900_2", "irb2400")


def _mount_case(tmp_path: Path, robot: str, tool: str = "mig_torch", q5: float = -60.0):
    """A joint move of ``robot`` with ``tool``, the wrist straight then bent."""
    return write_scenario(
        tmp_path, robot, [joint_phase([[0, 0, 0, 0, q5, 0], [10, 5, -5, 0, q5, 30],
                                       [20, 10, -10, 0, q5, 60]])],
        filename=f"{robot}.toml", name=f"mount_{robot}", tool=tool,
        description=f"a joint move of {robot} with {tool}, the wrist straight then bent")


@pytest.mark.parametrize("robot", MOUNT_ARMS)
def test_the_shapes_meeting_at_a_tool_mount_are_declared_not_reported(robot, tmp_path, capsys):
    """The generated arms' last-but-one link is a capsule whose cap reaches past the flange
    into the torch's adapter at every angle of J6: ``cellsim check`` found a collision there
    for the whole cycle of any scenario. Each declared pair is measured here on the compiled
    cell itself (MuJoCo's distance, J6 swept over its range, the other joints anywhere): it
    overlaps at every angle; and the check finds nothing else on a plain joint move."""
    import mujoco

    from sim.simulation.allowed_contacts import mount_overlaps
    from sim.simulation.collision_model import CollisionModel
    from sim.simulation.compile import build

    path = _mount_case(tmp_path, robot)
    built = build(load_scenario(path))
    pairs = mount_overlaps(CollisionModel(built))
    m = built.model
    d = mujoco.MjData(m)
    j6 = m.joint("robot/j6").id
    rng = np.random.default_rng(6)
    for a, b, reason in pairs:
        assert m.geom(a).name.startswith("robot/tool/") and "every angle of j6" in reason
        assert m.body(m.geom_bodyid[b]).name == "robot/link5"
        lo, hi = m.jnt_range[j6]
        for angle in np.linspace(lo, hi, 25):
            d.qpos[:] = rng.uniform(m.jnt_range[:, 0], m.jnt_range[:, 1])
            d.qpos[m.jnt_qposadr[j6]] = angle
            mujoco.mj_kinematics(m, d)
            assert mujoco.mj_geomDistance(m, d, a, b, 1.0, None) < -1e-4
    assert main(["check", str(path)]) == 0, capsys.readouterr().out


def test_a_tool_clear_of_the_wrist_declares_nothing(tmp_path):
    from sim.simulation.allowed_contacts import mount_overlaps
    from sim.simulation.collision_model import CollisionModel
    from sim.simulation.compile import build

    built = build(load_scenario(_mount_case(tmp_path, "lrmate200ic5l")))
    assert mount_overlaps(CollisionModel(built)) == []


ROD_TORCH = """
name = "rod_torch"
description = "a torch with a rod reaching back along the wrist (a planted fault)"
kind = "torch"
mass_kg = 1.0
tcp_mm = [0, 0, 300]

[[shapes]]
name = "body"
shape = "cylinder"
radius_mm = 20
from_mm = [0, 0, 0]
to_mm = [0, 0, 285]

[[shapes]]
name = "rod"
shape = "box"
size_mm = [20, 20, 40]
pos_mm = [0, 0, -200]
"""


def test_a_tool_reaching_back_past_the_mount_still_collides(tmp_path, capsys):
    """Planted fault: a rod 200 mm behind the flange sits in the forearm (link4) while the
    wrist is straight: the declaration of the mount's own overlap does not hide it."""
    (tmp_path / "rod_torch.toml").write_text(ROD_TORCH)
    path = _mount_case(tmp_path, "m10ia", tool="rod_torch.toml", q5=0.0)
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out
    hits = [line for line in out.splitlines() if line.startswith("collision:")]
    assert hits and all("robot/link4" in h and "robot/tool/rod" in h for h in hits), out


@pytest.mark.parametrize("name", shipped_scenarios())
def test_every_checked_geom_is_named_by_its_link(name):
    """A finding names the link that touched: a geom the model file left unnamed is
    ``<body>#<k>``, never the name dm_control gives it when attaching (``robot//unnamed_geom_18``
    was reported for an LR Mate link: found by a new-user trial), for every shipped scenario's
    composed cell; and every name is unique and leads back to its geom (the video and the 3D
    replay paint what a finding names: a robot link's every geom, its collision geoms being
    hidden; anything else the geom itself)."""
    import re

    from sim.simulation.collision_model import LINK, CollisionModel, geom_id, painted_geoms
    from sim.simulation.compile import build

    built = build(load_scenario(name))
    model = built.model
    cm = CollisionModel(built)
    names = [cg.name for cg in cm.geoms.values()]
    assert names and len(set(names)) == len(names)
    assert any("#" in n for n in names)  # the shipped robots' files leave link geoms unnamed
    for cg in cm.geoms.values():
        body = int(model.geom_bodyid[cg.id])
        assert "unnamed" not in cg.name, cg.name
        k = re.fullmatch(r"(.+)#(\d+)", cg.name)
        if k:  # a geom the file left unnamed: its body, and which of the body's it is
            assert k.group(1) == model.body(body).name
        assert geom_id(model, cg.name) == cg.id
        link = cg.role == LINK and not model.body(body).name.startswith("robot/tool/") \
            and model.body(body).name.startswith("robot/")
        want = set(np.flatnonzero(model.geom_bodyid == body)) if link else {cg.id}
        assert painted_geoms(model, [cg.name]) == want
    assert geom_id(model, "robot/link2#999") == -1 and geom_id(model, "no such#0") == -1
