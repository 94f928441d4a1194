"""A DH table's angles typed in radians (``alpha_deg = -1.5708``) are refused when the robot
file is read, naming the row, the column and the value in degrees; they made another arm,
and the mistake surfaced far away ("no inverse-kinematics solution" on a scenario's path; a
new user's trial).

Specification, on generated rows and right or straight angles of :data:`support.robots.DH_ROBOT`
written in radians (2 to 6 decimals: 1.57 and 3.14 too; either sign): ``cellsim check`` exits 2 with one line
naming ``kinematics.dh[i][j]`` and the angle in degrees; the table in degrees checks.
"""

from __future__ import annotations

import contextlib
import io
import math
import re
import tempfile
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st
from support.robots import DH_ROBOT, DH_SCENARIO

from sim.cli import main

DH_LINE = re.search(r"dh = \[.*?\]\]", DH_ROBOT, re.S).group(0)
ROWS = [[float(x) for x in r.split(",")] for r in re.findall(r"\[([^\[\]]*)\]", DH_LINE)]


def _check(rows: list[list[float]]) -> tuple[int, str]:
    text = DH_ROBOT.replace(DH_LINE, "dh = [" + ", ".join(
        "[" + ", ".join(repr(v) for v in r) + "]" for r in rows) + "]")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "robots" / "dh_arm"
        folder.mkdir(parents=True)
        (folder / "robot.toml").write_text(text)
        (Path(tmp) / "s.toml").write_text(DH_SCENARIO)
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = main(["check", str(Path(tmp) / "s.toml")])
    return code, err.getvalue()


@settings(max_examples=10, deadline=None)
@given(row=st.integers(0, 5), col=st.sampled_from([1, 3]),
       angle=st.sampled_from([90.0, -90.0, 180.0, -180.0]), decimals=st.integers(2, 6))
def test_a_dh_angle_in_radians_is_named(row, col, angle, decimals):
    rows = [list(r) for r in ROWS]
    rows[row][col] = round(math.radians(angle), decimals)
    code, err = _check(rows)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    name = "alpha_deg" if col == 1 else "theta_offset_deg"
    assert f"kinematics.dh[{row}][{col}] ({name})" in lines[0], lines[0]
    assert f"{angle:+g} deg in radians" in lines[0], lines[0]


def test_the_table_in_degrees_checks():
    code, err = _check(ROWS)
    assert code in (0, 1), err
