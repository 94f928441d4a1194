"""A user's own cell as files (issue 12): the cell of :func:`make_cell` and the scenario that
welds its seam, with the numbers the tests check them against.

The LR Mate 200iC/5L on a 500 mm pedestal, its base moved and turned 30 deg about z, a table (box
fixture) and a concave L bracket read from an STL file (:func:`write_bracket`), turned 25 deg
about z, with a line seam on the bracket's lower flange given in the bracket's frame. The seam is
welded with the torch along -normal (work angle 90, travel angle 0).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

BASE_MM = (200.0, -100.0, 500.0)
BASE_YAW_DEG = 30.0
BRACKET_POS_MM = (680.0, -20.0, 450.0)
BRACKET_YAW_DEG = 25.0
SEAM_MM = ((40.0, 70.0, 10.0), (160.0, 70.0, 10.0))
SPEED_MM_S = 10.0


def rz(deg: float) -> np.ndarray:
    a = np.deg2rad(deg)
    return np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])


def write_bracket(path: Path) -> None:
    """A closed L-section bracket, 200 mm long along x: a 120 x 10 mm flange (y, z) and a
    10 x 100 mm upright at y = 0..10 (mm), as binary STL."""
    import trimesh

    prof = np.array([[0, 0], [120, 0], [120, 10], [10, 10], [10, 100], [0, 100]], float)
    n = len(prof)
    v = np.array([[x, y, z] for x in (0.0, 200.0) for (y, z) in prof])
    cap = [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)]
    faces = [(a, c, b) for a, b, c in cap] + [(a + n, b + n, c + n) for a, b, c in cap]
    for i in range(n):
        j = (i + 1) % n
        faces += [(i, j, j + n), (i, j + n, i + n)]
    mesh = trimesh.Trimesh(v, np.array(faces))
    mesh.fix_normals()
    assert mesh.is_watertight and mesh.volume == pytest.approx(120 * 10 * 200 + 10 * 90 * 200)
    mesh.export(path)


CELL = f"""
name = "user_cell"
description = "a user's cell: turned robot on a pedestal, table, L bracket from an STL"
tool = "mig_torch"

[robot]
base_pos_mm = {list(BASE_MM)}
base_euler_zyx_deg = [{BASE_YAW_DEG}, 0, 0]

[[objects]]
name = "pedestal"
shape = "box"
size_mm = [300, 300, 500]
pos_mm = [{BASE_MM[0]}, {BASE_MM[1]}, 250]

[[objects]]
name = "table"
shape = "box"
size_mm = [500, 700, 40]
pos_mm = [{BRACKET_POS_MM[0] + 100}, {BRACKET_POS_MM[1] + 50}, 430]

[[objects]]
name = "bracket"
shape = "mesh"
file = "parts/bracket.stl"
role = "workpiece"
pos_mm = {list(BRACKET_POS_MM)}
euler_zyx_deg = [{BRACKET_YAW_DEG}, 0, 0]

[[seams]]
name = "bead"
object = "bracket"
kind = "line"
points_mm = {[list(p) for p in SEAM_MM]}
normal = [0, 0, 1]
work_angle_deg = 90
travel_angle_deg = 0
"""

SCENARIO = f"""
name = "user_weld"
description = "weld the bead on the bracket"
robot = "lrmate200ic5l"
cell = "cells/user_cell.toml"

[[actions]]
action = "arc_on"
phase = "weld"
[[actions]]
action = "arc_off"
phase = "weld"
at = "end"

[[phases]]
name = "ready"
planner = "434"
time_s = [0.0, 1.0, 2.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [5, 5, -10, 0, -85, 0], [10, 10, -20, 0, -70, 0]]

[[phases]]
name = "approach"
planner = "434"
durations_s = [1.5]
to_mm = [40, 70, 80]
frame = "bracket"
euler_zyx_deg = [0, 180, 0]

[[phases]]
name = "down"
kind = "linear"
to_mm = [40, 70, 10]
frame = "bracket"
speed_mm_s = 50

[[phases]]
name = "weld"
kind = "linear"
seam = "bead"
orientation = "seam"
speed_mm_s = {SPEED_MM_S}

[[phases]]
name = "lift"
kind = "linear"
to_mm = [750, 30, 650]
frame = "world"
speed_mm_s = 100
"""


def make_cell(root: Path, cell: str = CELL, scenario: str = SCENARIO) -> Path:
    """Write the cell, its STL and the scenario under ``root``; returns the scenario path."""
    (root / "cells" / "parts").mkdir(parents=True, exist_ok=True)
    write_bracket(root / "cells" / "parts" / "bracket.stl")
    (root / "cells" / "user_cell.toml").write_text(cell)
    path = root / "user_weld.toml"
    path.write_text(scenario)
    return path
