"""A robot file whose per-joint keys disagree on the number of joints names the key that is
wrong: a row left out of ``kinematics.dh`` was reported as "joints.range_deg: 6 rows for 5
joints" (a new user's trial), sending the user to the one key that was right.

Specification, on generated mistakes in :data:`support.robots.DH_ROBOT` (one row left out of,
or one added to, the DH table, ``joints.range_deg`` or ``joints.max_speed_deg_s``):
``cellsim check`` exits 2 with one line naming the robot file and the key changed (and not
the DH table when the table was right); the file as written checks.
"""

from __future__ import annotations

import contextlib
import io
import re
import tempfile
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st
from support.robots import DH_ROBOT, DH_SCENARIO

from sim.cli import main

DH = ("dh = [[75, -90, 330, 0], [300, 0, 0, -90], [75, -90, 0, 0], [0, 90, 320, 0], "
      "[0, -90, 0, 0],\n      [0, 0, 80, 0]]")
RANGE = "range_deg = [[-170, 170], [-100, 140], [-150, 150], [-190, 190], [-120, 120], [-360, 360]]"
SPEED = "max_speed_deg_s = [270, 270, 270, 450, 450, 720]"
KEYS = {"kinematics.dh": DH, "joints.range_deg": RANGE, "joints.max_speed_deg_s": SPEED}


def _rows(text: str) -> tuple[str, list[str]]:
    key, value = text.split(" = ", 1)
    inner = value.strip()[1:-1]
    if inner.lstrip().startswith("["):
        return key, re.findall(r"\[[^\[\]]*\]", inner)
    return key, [x.strip() for x in inner.split(",")]


def _check(robot: str) -> tuple[int, str]:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "robots" / "dh_arm"
        folder.mkdir(parents=True)
        (folder / "robot.toml").write_text(robot)
        (Path(tmp) / "s.toml").write_text(DH_SCENARIO)
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = main(["check", str(Path(tmp) / "s.toml")])
    return code, err.getvalue()


@settings(max_examples=12, deadline=None)
@given(key=st.sampled_from(sorted(KEYS)), row=st.integers(0, 5), add=st.booleans())
def test_the_key_with_a_row_too_many_or_too_few_is_named(key, row, add):
    assert all(text in DH_ROBOT for text in KEYS.values())
    name, rows = _rows(KEYS[key])
    rows = rows[:row] + [rows[row]] + rows[row:] if add else rows[:row] + rows[row + 1:]
    code, err = _check(DH_ROBOT.replace(KEYS[key], f"{name} = [{', '.join(rows)}]"))
    lines = [ln for ln in err.splitlines() if ln.startswith("cellsim: error:")]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert "robot.toml" in lines[0] and key in lines[0], lines[0]
    if key != "kinematics.dh":
        assert "kinematics.dh" not in lines[0], lines[0]


def test_the_robot_as_written_checks():
    code, err = _check(DH_ROBOT)
    assert code in (0, 1), err
