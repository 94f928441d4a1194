"""A scenario's other robots (``[robots.<name>]``, issue 28): hostile work is one line naming the
file, ``robots.<name>`` and the key, and `cellsim run` exits 2; ``[drives.r2_j2]`` reaches r2's
drive in the compiled model; the shipped two_robot_tee_weld welds both seams and its deliberate
near miss (measured here with MuJoCo's geom distances on the recorded qpos) is under the
scenario's clearance and over 10 mm, with nothing touching anywhere in the cycle."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import mujoco
import numpy as np
import pytest

from sim.cli import main
from sim.core.resources import models_dir, shipped_scenarios

ROOT = Path(__file__).resolve().parents[2]
CELL = (models_dir() / "cells" / "two_robot_tee.toml").read_text()
SHIPPED = Path(shipped_scenarios()["two_robot_tee_weld"]).read_text()
SCENARIO = SHIPPED.replace('cell = "two_robot_tee"', 'cell = "cell.toml"')
R2_START = '[[robots.r2.phases]]\nname = "start"\n'
R2_ACTIONS = '[[robots.r2.actions]]'
#: The docs' positioner cell (docs/cell-format.md) with a second robot across the positioner.
POSITIONER_CELL = """name = "positioner_cell"
tool = "mig_torch"

[robot]
model = "lrmate200ic5l"

[[robots]]
name = "r2"
model = "lrmate200ic5l"
base_pos_mm = [1500, 0, 0]
base_euler_zyx_deg = [180, 0, 0]

[[mechanisms]]
name = "positioner"
model = "motopos_d500"
pos_mm = [750, 0, 0]

[[objects]]
name = "flange"
shape = "cylinder"
radius_mm = 120
length_mm = 15
pos_mm = [0, 0, 7.5]
role = "workpiece"
on = "positioner"

[[objects]]
name = "pipe"
shape = "cylinder"
radius_mm = 50
length_mm = 150
pos_mm = [0, 0, 90]
role = "workpiece"
on = "positioner"

[[seams]]
name = "fillet"
object = "pipe"
kind = "arc"
points_mm = [[50, 0, -75], [0, 50, -75], [-50, 0, -75]]
normal = [0, 0, 1]
work_angle_deg = 45
lean = "right"
joins = ["flange"]
"""
START = """[[phases]]
name = "start"
planner = "434"
time_s = [0.0, 1.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [0, 0, 0, 0, -90, 0]]
"""
POSITIONER_SCENARIO = f"""name = "p2"
description = "r2 welds a seam the positioner carries"
robot = "lrmate200ic5l"
cell = "cell.toml"

{START}
{START.replace("[[phases]]", "[[robots.r2.phases]]")}
[[robots.r2.phases]]
name = "to_seam"
planner = "434"
durations_s = [2.0]
to_seam = "fillet"
approach_mm = 30

[[robots.r2.phases]]
name = "touch"
kind = "linear"
to_seam = "fillet"
orientation = "seam"
speed_mm_s = 20.0

[[robots.r2.phases]]
name = "weld"
kind = "circular"
seam = "fillet"
orientation = "seam"
speed_mm_s = 10.0
"""
BARE = f"""name = "bare"
description = "no cell"
robot = "lrmate200ic5l"

{START}
{START.replace("[[phases]]", "[[robots.r2.phases]]")}"""


def _with(old: str, new: str, text: str = SCENARIO) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def _run(tmp_path: Path, scenario: str, capsys, cell: str = CELL) -> tuple[int, list[str]]:
    (tmp_path / "cell.toml").write_text(cell)
    (tmp_path / "two.toml").write_text(scenario)
    out = tmp_path / "out"
    rc = main(["run", str(tmp_path / "two.toml"), "--no-video", "--out", str(out)])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip() and not re.match(
        r"cellsim: (build|plan) [0-9.]+ s$", ln)]  # the stage timings before a planning error
    assert not (out / "summary.json").exists()
    return rc, lines


HOSTILE = {
    "unknown robot": (SCENARIO.replace("robots.r2.", "robots.r3."),
                      r"two\.toml: robots\.r3: cell two_robot_tee has no other robot 'r3'; its "
                      r"\[\[robots\]\]: r2"),
    "a close name": (SCENARIO.replace("robots.r2.", "robots.r22."),
                     r"robots\.r22: cell two_robot_tee has no other robot 'r22' \(did you mean "
                     r"'r2'\?\)"),
    "no other robots in the cell": (
        SCENARIO, r"two\.toml: robots\.r2: cell two_robot_tee has no other robots"),
    "no cell": (BARE, r"two\.toml: robots\.r2: a scenario without a cell has one robot"),
    "bad phase key": (_with(R2_START, R2_START + "joints_degg = 1\n"),
                      r"two\.toml: robots\.r2\.phases\[0\]\.joints_degg: unknown key \(did you "
                      r"mean 'joints_deg'\?\); valid keys: .*joints_deg, joints_maker_deg"),
    "bad key of a linear phase": (
        _with('name = "clear"\n', 'name = "clear"\nspeed = 3\n'),
        r"robots\.r2\.phases\[5\]\.speed: unknown key \(did you mean 'speed_mm_s'\?\); valid "
        r"keys: .*orientation"),
    "bad key of its work": (_with(R2_ACTIONS, "[robots.r2]\nphase = []\n\n" + R2_ACTIONS),
                            r"robots\.r2\.phase: unknown key \(did you mean 'phases'\?\); valid "
                            r"keys: actions, phases, program"),
    "bad action key": (_with('[[robots.r2.actions]]\naction = "arc_on"\n',
                             '[[robots.r2.actions]]\naction = "arc_on"\nwhen = 1\n'),
                       r"robots\.r2\.actions\[0\]\.when: unknown key; valid keys: action, at, "
                       r"phase, time_s"),
    "bad weave key": (_with('\nseam = "fillet_2"\norientation = "seam"\nspeed_mm_s = 25.0\n',
                            '\nseam = "fillet_2"\norientation = "seam"\nspeed_mm_s = 25.0\n'
                            '[robots.r2.phases.weave]\npattern = "sine"\namplitude = 2\n'),
                      r"robots\.r2\.phases\[3\]\.weave\.amplitude: unknown key \(did you mean "
                      r"'amplitude_mm'\?\); valid keys: amplitude_mm, dwell_s, frequency_hz"),
    "bad weave key of the first robot": (
        _with('\nseam = "fillet_1"\norientation = "seam"\nspeed_mm_s = 25.0\n',
              '\nseam = "fillet_1"\norientation = "seam"\nspeed_mm_s = 25.0\n'
              '[phases.weave]\npattern = "sine"\namplitude = 2\n'),
        r"two\.toml: phases\[3\]\.weave\.amplitude: unknown key \(did you mean 'amplitude_mm'\?\)"),
    "axes in a joint phase": (_with(R2_START, R2_START + "axes = { positioner_tilt_deg = 10 }\n"),
                              r"robots\.r2: phases\[0\]\.axes: the cell's axes move with its "
                              r"first robot's phases"),
    "downhand": (_with('to_seam = "fillet_2"\napproach_mm = 100\n',
                       'to_seam = "fillet_2"\napproach_mm = 100\ndownhand = true\n'),
                 r"robots\.r2: phases\[1\]\.downhand: the cell's axes move with its first "
                 r"robot's phases"),
    "follow": (_with('\nseam = "fillet_2"\norientation = "seam"\n',
                     '\nseam = "fillet_2"\norientation = "seam"\nfollow = "track"\n'),
               r"robots\.r2: phases\[3\]\.follow: the cell's axes move with its first robot's"),
    "suction tool": (_with(R2_ACTIONS, '[robots.r2]\ntool = "vacuum_gripper"\n\n' + R2_ACTIONS),
                     r"robots\.r2\.tool: 'vacuum_gripper' is a suction gripper"),
    "unknown tool": (_with(R2_ACTIONS, '[robots.r2]\ntool = "mig_torchh"\n\n' + R2_ACTIONS),
                     r"robots\.r2\.tool: unknown tool 'mig_torchh'"),
    "arc without a torch": (_with(R2_ACTIONS, '[robots.r2]\ntool = "none"\n\n' + R2_ACTIONS),
                            r"robots\.r2: actions\[0\]\.action: arc_on needs a torch tool"),
    "action at no phase": (_with('[[robots.r2.actions]]\naction = "arc_on"\nphase = "weld"\n',
                                 '[[robots.r2.actions]]\naction = "arc_on"\nphase = "wled"\n'),
                           r"robots\.r2: actions\[0\]\.phase: no phase named 'wled' \(did you "
                           r"mean 'weld'\?\)"),
    "phases and a program": (_with(R2_ACTIONS, '[robots.r2]\nprogram = "p.ls"\n\n' + R2_ACTIONS),
                             r"robots\.r2: give phases \(at least one\) or program"),
    "a missing program": (
        SCENARIO[:SCENARIO.index(R2_ACTIONS)] + '[robots.r2]\nprogram = "nope.ls"\n',
        r"robots\.r2: program: .*nope\.ls: no such TP program"),
    "unknown drive": (SCENARIO + "\n[drives.r2_j9]\ngear_ratio = 120.0\n",
                      r"two\.toml: drives\.r2_j9: unknown joint \(did you mean 'r2_j\d'\?\); .*"
                      r"the other robots' r2_j1, r2_j2, r2_j3, r2_j4, r2_j5, r2_j6"),
    "unknown seam": (SCENARIO.replace('"fillet_2"', '"fillet_3"'),
                     r"robots\.r2: phases\[1\] \(to_seam\)\.to_seam: unknown seam 'fillet_3' "
                     r"\(did you mean 'fillet_2'\?\)"),
}
NO_PARTNERS = CELL[:CELL.index("[[robots]]")] + CELL[CELL.index("[[objects]]"):]


@pytest.mark.parametrize("case", HOSTILE)
def test_hostile_work_of_another_robot_is_one_line_and_exit_2(case, tmp_path, capsys):
    scenario, pattern = HOSTILE[case]
    cell = NO_PARTNERS if case == "no other robots in the cell" else CELL
    rc, lines = _run(tmp_path, scenario, capsys, cell)
    assert rc == 2, lines
    assert len(lines) == 1, lines
    assert lines[0].startswith("cellsim: error: two.toml: "), lines[0]
    assert re.search(pattern, lines[0]), lines[0]


_WELD_ONLY = POSITIONER_SCENARIO[:POSITIONER_SCENARIO.index('[[robots.r2.phases]]\nname = "to_seam"')] \
    + POSITIONER_SCENARIO[POSITIONER_SCENARIO.index('[[robots.r2.phases]]\nname = "weld"'):]


@pytest.mark.parametrize("text, where", [
    (POSITIONER_SCENARIO, r"phases\[1\]\.to_seam"),  # its approach to the carried seam
    (_WELD_ONLY, r"phases\[1\]\.seam"),  # the weld along it
    (_WELD_ONLY.replace('kind = "circular"\nseam = "fillet"\norientation = "seam"',
                        'kind = "linear"\nto_mm = [0, 0, 100]\nframe = "pipe"'),
     r"phases\[1\]\.frame"),  # a move in its frame
])
def test_another_robot_working_on_what_a_positioner_carries_is_refused(tmp_path, capsys, text,
                                                                       where):
    rc, lines = _run(tmp_path, text, capsys, POSITIONER_CELL)
    assert rc == 2 and len(lines) == 1, lines
    assert re.search(r"two\.toml: robots\.r2: " + where + r": '(fillet|pipe)' is carried by "
                     r"'positioner'", lines[0]), lines


def test_the_first_robot_may_weld_it_and_the_hostile_scenarios_start_valid(tmp_path):
    """The oracles above are not blind: the unmodified scenario and its cell parse, and the cells
    without other robots take a scenario without [robots.*]."""
    from sim.scenario import load_scenario

    (tmp_path / "cell.toml").write_text(CELL)
    (tmp_path / "two.toml").write_text(SCENARIO)
    sc = load_scenario(tmp_path / "two.toml")
    assert [w.name for w in sc.partners] == ["r2"] and len(sc.partners[0].phases) == 6
    (tmp_path / "cell.toml").write_text(NO_PARTNERS)
    (tmp_path / "two.toml").write_text(SCENARIO[:SCENARIO.index(R2_ACTIONS)])
    assert load_scenario(tmp_path / "two.toml").partners == ()


def test_a_drive_override_of_another_robot_reaches_its_joint(tmp_path):
    """[drives.r2_j2] gear_ratio doubled: r2's J2 actuator force range doubles and its armature
    (the rotor's reflected inertia, J_r N^2) quadruples in the compiled model; the first robot's
    J2 keeps its own."""
    from sim.scenario import load_scenario
    from sim.simulation.compile import build

    (tmp_path / "cell.toml").write_text(CELL)
    models = []
    for extra in ("", "\n[drives.r2_j2]\ngear_ratio = {n}\n"):
        base = load_scenario("two_robot_tee_weld")
        n = base.drive_train[base.system.joints.index("r2_j2")].gear_ratio
        (tmp_path / "two.toml").write_text(SCENARIO + extra.format(n=2 * n))
        models.append(build(load_scenario(tmp_path / "two.toml")).model)
    a, b = models
    for m in (a, b):
        assert m.actuator("r2/a2").id > m.actuator("robot/a2").id
    np.testing.assert_allclose(b.actuator("r2/a2").forcerange, 2 * a.actuator("r2/a2").forcerange)
    np.testing.assert_allclose(b.joint("r2/j2").armature, 4 * a.joint("r2/j2").armature)
    np.testing.assert_allclose(b.actuator("robot/a2").forcerange, a.actuator("robot/a2").forcerange)
    np.testing.assert_allclose(b.actuator("r2/a3").forcerange, a.actuator("r2/a3").forcerange)


def test_the_docs_list_every_key_of_another_robots_work():
    """docs/scenario-format.md's "Two robots" table lists exactly RobotWorkSpec's keys."""
    from sim.scenario.schema import RobotWorkSpec

    doc = (ROOT / "docs" / "scenario-format.md").read_text()
    start = doc.index("## Two robots (`[robots.<name>]`)")
    section = doc[start:doc.index("\n## ", start + 5)]
    keys = set(re.findall(r"^\| `([a-z][a-z0-9_]*)`", section, flags=re.M))
    assert keys == set(RobotWorkSpec.model_fields), keys ^ set(RobotWorkSpec.model_fields)


# ---------------------------------------------------------------------------- the shipped run
def _robot_geoms(m, prefix: str) -> list[int]:
    """A robot's arm collision geoms (group 3) and its tool's geoms."""
    return [g for g in range(m.ngeom) if m.body(m.geom_bodyid[g]).name.startswith(f"{prefix}/")
            and (m.geom_group[g] == 3 or m.geom(g).name.startswith(f"{prefix}/tool/"))]


def _closest(m, d, a: list[int], b: list[int]) -> tuple[float, int, int]:
    ft = np.zeros(6)
    return min((mujoco.mj_geomDistance(m, d, ga, gb, 0.3, ft), ga, gb) for ga in a for gb in b)


@pytest.mark.slow  # one run of the shipped scenario (shared with the pipeline tests' session)
def test_the_shipped_near_miss_is_under_the_clearance_and_touches_nothing(scenario_run):
    """On the run's own model.xml posed at the recorded qpos (every 20th sample, every sample
    around the closest one): the two robots' tools and arms come within 10 to 25 mm of each
    other, under the scenario's clearance_mm, once both arcs are off, and never touch; while
    both weld they stay at least clearance_mm apart. Each robot's arc-on tool path lies on its
    own fillet line (the cell file's numbers: y = -5 / +5 mm, z = 462 mm, x from -380 to 380
    mm). The verdict passes, as [expect] declares."""
    out, summary = scenario_run("two_robot_tee_weld")
    scenario = tomllib.loads(SHIPPED)
    clearance = scenario["simulation"]["clearance_mm"]
    assert summary["verdict"] == scenario["expect"]["verdict"] == "pass"
    assert summary["collisions"] == []
    m = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    d = mujoco.MjData(m)
    a = np.load(out / "trajectory.npz")
    t, qpos = a["t"], a["qpos"]
    first, other = _robot_geoms(m, "robot"), _robot_geoms(m, "r2")
    assert len(first) == len(other) > 20

    def closest(k: int) -> tuple[float, int, int]:
        d.qpos[:] = qpos[k]
        mujoco.mj_kinematics(m, d)
        return _closest(m, d, first, other)

    coarse = np.arange(0, t.size, 20)
    dist = np.array([closest(k)[0] for k in coarse])
    assert dist.min() > 0.0  # nothing touches (a sample between two 20 ms apart moves < 1 mm)
    k0 = int(coarse[np.argmin(dist)])
    best, k_best = min((closest(k)[0], k) for k in range(max(k0 - 40, 0), min(k0 + 41, t.size)))
    assert 10.0 < best * 1e3 < 25.0 and best * 1e3 < clearance, best
    arcs = a["arc_on"].astype(bool) | a["r2_arc_on"].astype(bool)
    assert not arcs[k_best] and t[k_best] > t[np.flatnonzero(a["r2_arc_on"])[-1]]
    both = a["arc_on"][coarse].astype(bool) & a["r2_arc_on"][coarse].astype(bool)
    assert both.sum() > 1000 and dist[both].min() * 1e3 > clearance
    for key, y in (("tcp_pos", -0.005), ("r2_tcp_pos", 0.005)):
        on = a[key.replace("tcp_pos", "arc_on")].astype(bool)
        p = a[key][on]
        assert np.abs(p[:, 1:] - [y, 0.462]).max() < 5e-5, key
        assert p[0, 0] == pytest.approx(-0.38, abs=5e-5) and p[-1, 0] == pytest.approx(0.38,
                                                                                        abs=5e-5)


@pytest.mark.slow  # shares the run above
def test_the_distance_measure_sees_the_torches_touch(scenario_run):
    """The measure above is not blind: at the closest sample, r2's arm moved a few degrees
    (J1 +1, J2 -4, J3 +4 deg) puts its gas nozzle into the first robot's (a negative distance,
    the nozzles the pair), and the recorded pose itself is the 10 to 25 mm above."""
    out, _ = scenario_run("two_robot_tee_weld")
    m = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    d = mujoco.MjData(m)
    a = np.load(out / "trajectory.npz")
    first, other = _robot_geoms(m, "robot"), _robot_geoms(m, "r2")

    def closest(q: np.ndarray) -> tuple[float, int, int]:
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        return _closest(m, d, first, other)

    after = np.flatnonzero(a["t"] > a["t"][np.flatnonzero(a["r2_arc_on"])[-1]])
    _, k0 = min((closest(a["qpos"][k])[0], k) for k in after[::20])
    gap, k = min((closest(a["qpos"][k])[0], k) for k in range(k0 - 20, k0 + 21))
    assert 0.010 < gap < 0.025
    q = a["qpos"][k].copy()
    q[[m.jnt_qposadr[m.joint(f"r2/j{i}").id] for i in (1, 2, 3)]] += np.deg2rad([1, -4, 4])
    depth, g1, g2 = closest(q)
    assert depth < 0.0 and {m.geom(g1).name, m.geom(g2).name} == {"robot/tool/nozzle",
                                                                  "r2/tool/nozzle"}
