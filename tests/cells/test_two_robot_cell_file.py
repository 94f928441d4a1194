"""A cell file's other robots (``[[robots]]``, issue 28): hostile entries are one line naming the
file and the key, and `cellsim run` exits 2 before anything is written; every shipped scenario's
cell with other robots composes, holds every robot at its home while it steps, and places each
robot where its cell file says; docs/cell-format.md documents every key of a ``[[robots]]``
entry."""

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
SHIPPED_CELL = models_dir() / "cells" / "two_robot_tee.toml"
ENTRY = '[[robots]]\nname = "r2"\nmodel = "lrmate200ic5l"\n'
#: A scenario of the first robot alone (the other robots without work stay at home).
SCENARIO = """name = "two"
description = "hostile cell files"
robot = "lrmate200ic5l"
cell = "cell.toml"

[[phases]]
name = "start"
planner = "434"
time_s = [0.0, 0.5]
joints_deg = [[0, 0, 0, 0, -90, 0], [0, 0, 0, 0, -90, 0]]
"""


def _cell(*, entry: str = "", replace: tuple[str, str] | None = None, before_objects: str = "",
          append: str = "") -> str:
    """The shipped two-robot cell with its ``[[robots]]`` entry extended by ``entry``."""
    text = SHIPPED_CELL.read_text()
    assert ENTRY in text
    text = text.replace(ENTRY, ENTRY + entry)
    if replace is not None:
        assert replace[0] in text
        text = text.replace(replace[0], replace[1])
    if before_objects:
        text = text.replace("[[objects]]", before_objects + "\n[[objects]]", 1)
    return text + append


def _run(tmp_path: Path, cell: str, capsys) -> tuple[int, list[str]]:
    (tmp_path / "cell.toml").write_text(cell)
    (tmp_path / "two.toml").write_text(SCENARIO)
    out = tmp_path / "out"
    rc = main(["run", str(tmp_path / "two.toml"), "--no-video", "--out", str(out)])
    err = capsys.readouterr().err
    assert not out.exists(), "nothing is written for a bad cell file"
    return rc, [ln for ln in err.splitlines() if ln.strip()]


HOSTILE = {
    "unknown model": (_cell(replace=(ENTRY, ENTRY.replace("lrmate200ic5l", "lrmate300"))),
                      r"robots\[0\]\.model: unknown robot 'lrmate300'"),
    "duplicate name": (_cell(before_objects=ENTRY + "base_pos_mm = [1500, 600, 0]\n"),
                       r"robots\[1\]\.name: 'r2' is already another robot's name"),
    "reserved name": (_cell(replace=('name = "r2"', 'name = "robot"')),
                      r"robots\[0\]\.name: 'robot' is reserved"),
    "an object's name": (_cell(replace=('name = "r2"', 'name = "web"')),
                         r"robots\[0\]\.name: 'web' is an object's or mechanism's name"),
    "a mechanism's name": (
        _cell(before_objects='[[mechanisms]]\nname = "r2"\nmodel = "motopos_d500"\n'
                             'pos_mm = [2000, 0, 0]\n'),
        r"robots\[0\]\.name: 'r2' is an object's or mechanism's name"),
    "name pattern": (_cell(replace=('name = "r2"', 'name = "r 2"')),
                     r"robots\[0\]\.name: must match the pattern"),
    "home_deg count": (_cell(entry="home_deg = [0, 0, 0, 0, -90]\n"),
                       r"robots\[0\]\.home_deg: 5 values; robot lrmate200ic5l has 6 joints"),
    "home_deg range": (_cell(entry="home_deg = [0, 0, 0, 0, -90, 400]\n"),
                       r"robots\[0\]\.home_deg\[5\]: 400 deg is outside joint j6's range "
                       r"\[-360, 360\] deg"),
    "home_deg nan": (_cell(entry="home_deg = [0, 0, 0, 0, -90, nan]\n"),
                     r"robots\[0\]\.home_deg\[5\]: must be a finite number"),
    "suction tool": (_cell(entry='tool = "vacuum_gripper"\n'),
                     r"robots\[0\]\.tool: 'vacuum_gripper' is a suction gripper"),
    "unknown tool": (_cell(entry='tool = "mig_torchh"\n'),
                     r"robots\[0\]\.tool: unknown tool 'mig_torchh' "
                     r"\(did you mean 'mig_torch'\?\)"),
    "missing tool file": (_cell(entry='tool = "tools/nope.toml"\n'), r"robots\[0\]\.tool: "),
    "on a track": (_cell(entry='on = "track"\n'), r"robots\[0\]\.on: unknown key; valid keys: "
                   r"base_euler_zyx_deg, base_pos_mm, home_deg, model, mount, name, tool"),
    "mount": (_cell(entry='mount = "wall"\n'), r"robots\[0\]\.mount: must be 'floor' or 'ceiling'"),
    "no model": (_cell(replace=(ENTRY, '[[robots]]\nname = "r2"\n')),
                 r"robots\[0\]\.model: required key is missing"),
    "nine robots": (_cell(append="".join(
        f'\n[[robots]]\nname = "x{i}"\nmodel = "lrmate200ic5l"\nbase_pos_mm = [{2000 + 500 * i}, '
        '0, 0]\n' for i in range(8))), r"robots: must have at most 8 items"),
    # the table is 1200 x 500 x 450 mm about (0, 0, 225): (0, 200, 300) is 50 mm from its
    # nearest face (y = 250)
    "base inside the table": (
        _cell(replace=("base_pos_mm = [0, 600, 0]", "base_pos_mm = [0, 200, 300]")),
        r"robots\[0\]\.base_pos_mm: the base of robot 'r2' \[0\.0, 200\.0, 300\.0\] mm is "
        r"50\.0 mm inside fixture 'table' \(objects\[0\]\); stand it on the object"),
    "base inside the web": (
        _cell(replace=("base_pos_mm = [0, 600, 0]", "base_pos_mm = [100, 2, 600]")),
        r"robots\[0\]\.base_pos_mm: the base of robot 'r2' .* mm is 3\.0 mm inside workpiece "
        r"'web' \(objects\[2\]\)"),
}


@pytest.mark.parametrize("case", HOSTILE)
def test_a_hostile_robots_entry_is_one_line_and_exit_2(case, tmp_path, capsys):
    cell, pattern = HOSTILE[case]
    rc, lines = _run(tmp_path, cell, capsys)
    assert rc == 2, lines
    assert len(lines) == 1, lines
    assert lines[0].startswith("cellsim: error: two.toml: cell: "), lines[0]
    assert "cell.toml" in lines[0] and "Traceback" not in lines[0]
    assert re.search(pattern, lines[0]), lines[0]


def test_a_base_on_the_table_or_within_the_tolerance_is_taken(tmp_path, capsys):
    """The oracle of the base check is not blind: on the table's top (z = 450 mm) and 0.5 mm
    into it (under the 1 mm tolerance) the cell is read, 1.5 mm into it is refused."""
    from sim.cells.cellfile import read_cell_file

    for z, ok in ((450.0, True), (449.5, True), (448.5, False)):
        text = _cell(replace=("base_pos_mm = [0, 600, 0]", f"base_pos_mm = [0, 100, {z}]"))
        (tmp_path / "cell.toml").write_text(text)
        if ok:
            cf = read_cell_file(tmp_path / "cell.toml")
            np.testing.assert_allclose(cf.partners["r2"].base_pose[:3, 3], [0, 0.1, z * 1e-3])
        else:
            rc, lines = _run(tmp_path, text, capsys)
            assert rc == 2 and "1.5 mm inside fixture 'table'" in lines[0], lines


def test_the_first_robots_base_check_still_holds(tmp_path, capsys):
    text = _cell(replace=("base_pos_mm = [0, -600, 0]", "base_pos_mm = [0, -200, 300]"))
    rc, lines = _run(tmp_path, text, capsys)
    assert rc == 2 and len(lines) == 1
    assert re.search(r"cell.toml: robot\.base_pos_mm: the robot base \[0\.0, -200\.0, 300\.0\] "
                     r"mm is 50\.0 mm inside fixture 'table'", lines[0]), lines


# ---------------------------------------------------------------------------- shipped cells
def _cell_file_of(name: str, robot: str) -> dict:
    """The shipped cell file of cell ``name`` laid out for ``robot``, as TOML."""
    for path in sorted((models_dir() / "cells").glob("*.toml")):
        doc = tomllib.loads(path.read_text())
        if doc["name"] == name and doc.get("robot", {}).get("model") in (None, robot):
            return doc
    raise AssertionError(f"no shipped cell file for {name}")


def _two_robot_scenarios() -> list[str]:
    from sim.scenario import load_scenario

    return sorted(n for n in shipped_scenarios() if load_scenario(n).partners)


def test_a_shipped_scenario_has_two_robots():
    assert "two_robot_tee_weld" in _two_robot_scenarios()


@pytest.mark.parametrize("name", _two_robot_scenarios())
def test_a_shipped_two_robot_cell_composes_steps_and_holds_home(name):
    """The scenario's cell compiles with every robot in it; stepped 1 s from the home keyframe
    with the servos on their home targets, no MuJoCo warning, every joint (the other robots'
    too) within 2 mm / 0.1 deg of its home, the robots apart; each other robot's base and frame
    0 where its cell file puts them (its base_pos_mm, base_euler_zyx_deg)."""
    from sim.scenario import load_scenario
    from sim.simulation.compile import build

    sc = load_scenario(name)
    built = build(sc)
    m, cell = built.model, built.cell
    assert [cr.name for cr in cell.partners] == [w.name for w in sc.partners]
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
    home = np.concatenate([cell.home_q, cell.axis_home, *(cr.home_q for cr in cell.partners)])
    assert home.size == len(cell.joint_names) == built.robot_act.size
    d.ctrl[built.robot_act] = home
    for _ in range(round(1.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    assert all(d.warning[i].number == 0 for i in range(len(d.warning)))
    q = d.qpos[built.robot_qpos]
    assert np.abs(q - home).max() < 2e-3
    doc = _cell_file_of(cell.name, sc.robot.name)
    for cr in cell.partners:
        assert m.joint(f"{cr.name}/j1").type == mujoco.mjtJoint.mjJNT_HINGE
        assert np.all(q[built.partner_cols[cr.name]] == d.qpos[[
            m.jnt_qposadr[m.joint(j).id] for j in cr.placed.joint_names]])
        # MuJoCo's pose of its base body against the cell file's numbers
        entry = next(r for r in doc["robots"] if r["name"] == cr.name)
        yaw = np.deg2rad(entry.get("base_euler_zyx_deg", [0, 0, 0])[0])
        base = d.body(f"{cr.name}/base")
        np.testing.assert_allclose(base.xpos, np.multiply(entry.get("base_pos_mm", [0, 0, 0]),
                                                          1e-3), atol=1e-9)
        np.testing.assert_allclose(base.xmat.reshape(3, 3)[:, 0], [np.cos(yaw), np.sin(yaw), 0],
                                   atol=1e-9)
    # the robots do not touch at home: their tools' and arms' collision geoms are apart
    ft = np.zeros(6)
    mujoco.mj_kinematics(m, d)

    def geoms(prefix: str) -> list[int]:
        return [g for g in range(m.ngeom) if m.body(m.geom_bodyid[g]).name.startswith(prefix)
                and (m.geom_group[g] == 3 or m.geom(g).name.startswith(f"{prefix}tool/"))]

    first = geoms("robot/")
    for cr in cell.partners:
        other = geoms(f"{cr.name}/")
        assert first and other
        assert min(mujoco.mj_geomDistance(m, d, a, b, 1.0, ft) for a in first for b in other) > 0.05


def test_the_shipped_cell_is_what_the_scenario_names():
    """The shipped scenario's cell is models/cells/two_robot_tee.toml, with r2 facing the first
    robot across the tee."""
    from sim.scenario import load_scenario

    sc = load_scenario("two_robot_tee_weld")
    assert sc.cell is not None and sc.cell.name == "two_robot_tee"
    doc = tomllib.loads(SHIPPED_CELL.read_text())
    assert doc["name"] == "two_robot_tee"
    (r2,) = doc["robots"]
    assert r2["base_pos_mm"][1] == -doc["robot"]["base_pos_mm"][1]
    assert (r2["base_euler_zyx_deg"][0] - doc["robot"]["base_euler_zyx_deg"][0]) % 360 == 180


# ---------------------------------------------------------------------------- docs
def test_cell_format_documents_every_key_of_a_robots_entry():
    """docs/cell-format.md's [[robots]] table lists exactly OtherRobotBlock's keys."""
    from sim.cells.cellfile.schema import OtherRobotBlock

    doc = (ROOT / "docs" / "cell-format.md").read_text()
    start = doc.index("### `[[robots]]`")
    end = doc.find("\n#", start + 5)
    section = doc[start:end if end > 0 else None]
    keys = set(re.findall(r"^\| `([a-z][a-z0-9_]*)`", section, flags=re.M))
    assert keys == set(OtherRobotBlock.model_fields), keys ^ set(OtherRobotBlock.model_fields)
