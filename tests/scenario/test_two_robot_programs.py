"""Two robots in one cell, each with its own TP program (issue 28): ``[robots.r2] program =
"r2.ls"`` runs r2's program (with its user frames, registers and weld speed) from r2's home in
the cell, and ``cellsim export`` of a two-robot scenario writes one program per robot
(``prog.ls`` and ``prog_r2.ls``) that run back to the same welds.

The cells and scenarios are generated (:mod:`support.two_robot_programs`: seam position, length, speeds
and both robots' bases). The oracles are independent of the planner and the exporter: the seams'
numbers as the generated cell file gives them, the weld speed the scenario gives, r2's home in
the cell file, and for the export the recorded tool points of the original run (``tcp_pos``,
``r2_tcp_pos`` while ``arc_on`` / ``r2_arc_on``), against those of the run-back. The bases are
never symmetric in the planted fault: there the first robot's program, run by r2 (the two
programs swapped), would weld r2's own seam, and the swap would not show.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from support.two_robot_programs import Tee, arc_path, distance_to_polyline, path_gap, run

from sim.errors import ScenarioError

#: The run-back's tool point stays this close to the original's, m.
BACK_TOL = 0.1e-3
#: A weld follows its seam (the cell file's numbers) this closely, m.
SEAM_TOL = 0.1e-3
#: The recorded weld speed in the middle of the weld is the programmed one within this share.
SPEED_SHARE = 0.02

RUN_SETTINGS = settings(deadline=None, derandomize=True, phases=[Phase.explicit, Phase.generate],
                        suppress_health_check=[HealthCheck.too_slow,
                                               HealthCheck.function_scoped_fixture])


@st.composite
def tees(draw: st.DrawFn, max_length: float = 200.0) -> Tee:
    """A generated case: the seams anywhere along the web, the bases moved and turned apart
    (never mirror images of each other: :func:`_asymmetric`)."""
    length = draw(st.floats(50.0, max_length))
    room = 200.0 - length / 2
    x0 = draw(st.floats(-room, room))
    b1 = (draw(st.floats(-60.0, 60.0)), -700.0 + draw(st.floats(-20.0, 60.0)))
    b2 = (draw(st.floats(-60.0, 60.0)), 700.0 - draw(st.floats(-20.0, 60.0)))
    speeds = [draw(st.floats(15.0, 40.0)) for _ in range(2)]
    home = draw(st.sampled_from([None, (10.0, 0.0, 0.0, 0.0, -80.0, 0.0),
                                 (-15.0, 5.0, -5.0, 0.0, -90.0, 10.0)]))
    r = lambda v: round(v, 1)  # noqa: E731
    return Tee(r(x0), r(length), r(speeds[0]), r(speeds[1]), (r(b1[0]), r(b1[1])),
               (r(b2[0]), r(b2[1])), home)


def _asymmetric(tee: Tee) -> bool:
    return math.dist(tee.base1, (-tee.base2[0], -tee.base2[1])) > 10.0


def _every(p: np.ndarray, most: int = 1500) -> np.ndarray:
    """At most ``most`` of the points, the last one kept."""
    k = max(1, len(p) // most)
    return np.vstack([p[::k], p[-1:]])


def _weld_speed(a: dict, robot: str | None) -> float:
    """The recorded tool point's median speed over the middle half of its weld, m/s."""
    pre = "" if robot is None else f"{robot}_"
    on = np.flatnonzero(np.asarray(a[f"{pre}arc_on"], dtype=bool))
    mid = on[len(on) // 4: 3 * len(on) // 4]
    p, t = a[f"{pre}tcp_pos"][mid], a["t"][mid]
    return float(np.median(np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)))


def check_on_seam(tee: Tee, a: dict, robot: str | None, side: str, speed_mm_s: float) -> None:
    """The robot's recorded weld follows its seam from end to end at its speed."""
    path, seam = arc_path(a, robot), tee.seam(side)
    assert distance_to_polyline(_every(path), seam).max() < SEAM_TOL
    assert np.linalg.norm(path[0] - seam[0]) < SEAM_TOL
    assert np.linalg.norm(path[-1] - seam[1]) < SEAM_TOL
    assert abs(_weld_speed(a, robot) / (speed_mm_s * 1e-3) - 1.0) < SPEED_SHARE


def check_back(orig: dict, back: dict) -> dict[str, float]:
    """Each robot's run-back weld (and where it ends the cycle) within :data:`BACK_TOL` of the
    original's; the gaps, m."""
    gaps = {}
    for robot in (None, "r2"):
        pre = "" if robot is None else f"{robot}_"
        gap = path_gap(_every(arc_path(orig, robot)), _every(arc_path(back, robot)))
        rest = float(np.linalg.norm(orig[f"{pre}tcp_pos"][-1] - back[f"{pre}tcp_pos"][-1]))
        gaps[robot or "robot"] = max(gap, rest)
        assert gap < BACK_TOL, (robot, gap)
        assert rest < BACK_TOL, (robot, rest)
    return gaps


def export(tee: Tee, root: Path) -> tuple[Path, list[str]]:
    """The generated scenario (both robots' phases) exported to ``root/prog.ls`` (and
    ``prog_r2.ls``), and the scenario that runs the two programs back; its path and the
    notes."""
    from sim.pipeline.export import write_program
    from sim.scenario import load_scenario

    notes, written = write_program(load_scenario(tee.write(root, tee.scenario_toml())),
                                   root / "prog.ls")
    assert written == [root / "prog.ls", root / "prog_r2.ls"]
    back = root / "back.toml"
    back.write_text(tee.scenario_toml(first='\nprogram = "prog.ls"\n',
                                      r2='\n[robots.r2]\nprogram = "prog_r2.ls"\n'))
    return back, notes


# ------------------------------------------------------------------------------ fast share
def test_the_path_oracle_catches_a_shifted_or_short_weld() -> None:
    """Planted fault: a weld moved 0.2 mm sideways, or cut 0.2 mm short, is caught."""
    s = np.linspace(0.0, 0.1, 1001)
    orig = np.c_[s, np.zeros_like(s), np.zeros_like(s)]
    assert path_gap(orig, np.vstack([orig[::7], orig[-1:]])) < 1e-9
    assert path_gap(orig, orig + [0.0, 0.2e-3, 0.0]) > BACK_TOL
    assert path_gap(orig, orig[orig[:, 0] < 0.0998]) > BACK_TOL


def test_export_writes_a_program_per_robot_and_refuses_an_existing_one(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``cellsim export`` writes the first robot's program to --out and r2's beside it
    (``prog_r2.ls``, in r2's own frame 0 and tool), says how to run it back; an existing
    ``prog_r2.ls`` is refused in one line (exit 2) and nothing is written."""
    from sim.cli import main
    from sim.scenario.fanuc_ls import read_ls

    tee = Tee(length=60.0, base1=(30.0, -690.0))
    path = tee.write(tmp_path, tee.scenario_toml())
    assert main(["export", str(path), "--out", str(tmp_path / "prog.ls")]) == 0
    out = capsys.readouterr().out
    assert 'robots.r2: prog_r2.ls: run it back with [robots.r2] program = "prog_r2.ls"' in out
    assert f"wrote {tmp_path / 'prog.ls'} and {tmp_path / 'prog_r2.ls'}" in out
    first, second = read_ls(tmp_path / "prog.ls"), read_ls(tmp_path / "prog_r2.ls")
    assert first.name != second.name
    # r2's weld ends where the seam ends, in r2's frame 0 (its base: at base2, turned -90 deg)
    end = tee.seam("right")[1] * 1e3 - [tee.base2[0], tee.base2[1], 330.0]
    in_f0 = np.array([-end[1], end[0], end[2]])  # Rz(+90) of world offsets
    last = second.positions[max(second.positions)].xyzwpr
    assert last is not None
    xyz = np.array(last[:3])
    assert np.abs(xyz - in_f0).max() < 1e-3 + 1e-9, (xyz, in_f0)
    # refusing: r2's program exists; neither file is (re)written
    (tmp_path / "again_r2.ls").write_text("mine")
    assert main(["export", str(path), "--out", str(tmp_path / "again.ls")]) == 2
    err = capsys.readouterr().err
    assert "again_r2.ls: exists" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "again.ls").exists()
    assert (tmp_path / "again_r2.ls").read_text() == "mine"


def test_a_robot_without_work_gets_no_program(tmp_path: Path) -> None:
    """r2 without ``[robots.r2]`` stays home: the export writes the first robot's program
    only."""
    from sim.pipeline.export import write_program
    from sim.scenario import load_scenario

    tee = Tee(length=60.0)
    _, written = write_program(load_scenario(tee.write(tmp_path, tee.scenario_toml(r2=""))),
                               tmp_path / "prog.ls")
    assert written == [tmp_path / "prog.ls"]
    assert not (tmp_path / "prog_r2.ls").exists()


@settings(RUN_SETTINGS, max_examples=2)
@given(tee=tees(max_length=120.0))
def test_r2_program_plans_onto_its_seam(tmp_path_factory: pytest.TempPathFactory,
                                        tee: Tee) -> None:
    """r2's hand-written program (UF 1 = the web, PR[1], WELD_SPEED) planned with r2's own
    context: the compiled model posed at the planned joints (MuJoCo's own kinematics) puts
    r2's tool point on its seam while its arc is on, and r2 starts at its home in the cell."""
    import mujoco

    from sim.scenario import load_scenario
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    root = tmp_path_factory.mktemp("plan")
    scenario = load_scenario(tee.write(root, tee.scenario_toml(r2=tee.r2_program_table())))
    built = build(scenario)
    motion = build_motion(scenario, built.context)
    lane = dict(motion.lanes)["r2"]
    t = np.linspace(motion.t0, motion.t1, 4001)
    on = lane.tool_state(t, "arc")
    assert on.any()
    data = mujoco.MjData(built.model)
    site = built.partner_tcp["r2"]
    pts = []
    for q in motion.at(t[on]).q:
        data.qpos[built.robot_qpos] = q
        mujoco.mj_kinematics(built.model, data)
        pts.append(data.site_xpos[site].copy())
    seam = tee.seam("right")
    assert distance_to_polyline(np.array(pts), seam).max() < SEAM_TOL
    assert np.linalg.norm(pts[0] - seam[0]) < SEAM_TOL
    assert np.linalg.norm(pts[-1] - seam[1]) < SEAM_TOL
    home = np.zeros(6) if tee.home2 is None else np.radians(tee.home2)
    if tee.home2 is None:
        home[4] = -math.pi / 2  # the LR Mate's own home
    assert np.allclose(motion.at(motion.t0).q[0, built.partner_cols["r2"]], home, atol=1e-9)


# ------------------------------------------------------------------------------ slow share
@pytest.mark.slow
@settings(RUN_SETTINGS, max_examples=3)
@given(tee=tees())
def test_r2_runs_its_program(tmp_path_factory: pytest.TempPathFactory, tee: Tee) -> None:
    """Simulated: r2's program welds r2's seam (the cell file's numbers) from end to end at
    the scenario's weld speed, from its home in the cell, while the first robot's phases
    weld its own."""
    root = tmp_path_factory.mktemp("prog")
    summary, a = run(tee.write(root, tee.scenario_toml(r2=tee.r2_program_table())),
                     root / "out")
    check_on_seam(tee, a, "r2", "right", tee.speed2)
    check_on_seam(tee, a, None, "left", tee.speed1)
    home = np.radians(tee.home2) if tee.home2 is not None else np.r_[0, 0, 0, 0, -90.0, 0] \
        * math.pi / 180
    assert np.abs(a["q"][0, 6:12] - home).max() < 1e-3


@pytest.mark.slow
@settings(RUN_SETTINGS, max_examples=3)
@given(tee=tees())
def test_export_of_two_robots_runs_back(tmp_path_factory: pytest.TempPathFactory,
                                        tee: Tee) -> None:
    """Simulated: the two exported programs, run back, give each robot's recorded weld (and its
    rest at the cycle's end) within 0.1 mm of the original run's."""
    root = tmp_path_factory.mktemp("export")
    back, _ = export(tee, root)
    _, orig = run(root / "two.toml", root / "orig")
    _, again = run(back, root / "back")
    check_back(orig, again)


@pytest.mark.slow
def test_swapped_programs_are_caught(tmp_path: Path) -> None:
    """Planted fault: the two exported programs swapped in the run-back scenario (each robot
    runs the other's, in its own frame 0) fail the round trip's oracle."""
    tee = Tee(x0=20.0, length=80.0, speed1=30.0, speed2=22.0, base1=(40.0, -680.0),
              base2=(-30.0, 690.0))
    assert _asymmetric(tee)
    back, _ = export(tee, tmp_path)
    _, orig = run(tmp_path / "two.toml", tmp_path / "orig")
    _, again = run(back, tmp_path / "back")
    check_back(orig, again)
    swapped = tmp_path / "swapped.toml"
    swapped.write_text(back.read_text().replace('"prog.ls"', '"X"')
                       .replace('"prog_r2.ls"', '"prog.ls"').replace('"X"', '"prog_r2.ls"'))
    _, bad = run(swapped, tmp_path / "swapped")
    with pytest.raises(AssertionError):
        check_back(orig, bad)


def test_an_unknown_user_frame_of_r2_names_its_table(tmp_path: Path) -> None:
    """Bad input: r2's program_frames naming no cell object is one line naming robots.r2."""
    from sim.scenario import load_scenario
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion

    tee = Tee(length=60.0)
    path = tee.write(tmp_path, tee.scenario_toml(
        r2=tee.r2_program_table().replace('"1" = "web"', '"1" = "nope"')))
    scenario = load_scenario(path)
    with pytest.raises(ScenarioError, match=r"^two\.toml: robots\.r2: .*unknown frame 'nope'"):
        build_motion(scenario, build(scenario).context)


@pytest.mark.parametrize(("drop", "message"), [
    ("program_weld_speed_mm_s", r"robots\.r2: program: r2\.ls: line 11: WELD_SPEED"),
    ("program_registers", r"robots\.r2: program: r2\.ls: line 16: PR\[1\]: no value"),
    ("program_frames", r"robots\.r2: program: r2\.ls: line 8: UFRAME_NUM = 1: no frame"),
])
def test_what_r2s_program_needs_from_the_scenario_is_one_line(tmp_path: Path, drop: str,
                                                              message: str) -> None:
    """Bad input: r2's program without its weld speed, register or user frame in
    ``[robots.r2]`` is one line naming the scenario, ``robots.r2``, the program and its line."""
    from sim.scenario import load_scenario

    tee = Tee(length=60.0)
    table = "".join(line + "\n" for line in tee.r2_program_table().splitlines()
                    if not line.startswith(drop))
    with pytest.raises(ScenarioError, match=rf"^two\.toml: {message}") as info:
        load_scenario(tee.write(tmp_path, tee.scenario_toml(r2=table)))
    assert "\n" not in str(info.value)


def test_extended_values_in_another_robots_program_say_why(tmp_path: Path) -> None:
    """A program read for a robot whose positions hold no extended axes (``no_axes``: a cell's
    other robot) says why at the position's line, not that the cell has no mechanisms."""
    from sim.robots.registry import resolve_robot
    from sim.scenario.fanuc_ls import parse_ls
    from sim.scenario.program import program_phases

    text = Tee(length=60.0).r2_program().replace(
        "R = 180.000 deg\n}", "R = 180.000 deg,\n\tE1= 10.000 deg\n}", 1)
    prog = parse_ls(text, tmp_path / "r2.ls")
    robot = resolve_robot("lrmate200ic5l")
    why = "the cell's axes move with its first robot"
    with pytest.raises(ScenarioError, match=rf"^w: program: r2\.ls: line 18: P\[1\] has "
                       rf"extended axis values \(E1\); {why}$"):
        program_phases(prog, robot, np.zeros(6), {1: "web"}, {}, "w", has_tool=True,
                       weld_speed=20.0, no_axes=why)
    with pytest.raises(ScenarioError, match="the cell has no external axes"):
        program_phases(prog, robot, np.zeros(6), {1: "web"}, {}, "w", has_tool=True,
                       weld_speed=20.0)
