"""A robot folder of one's own beside the scenario, named without a path (``robot = "my_arm"``,
as a shipped robot is named), is looked up among the shipped robots; the refusal now says the
folder is there and how to name it (a new user's trial read only "unknown robot").

Specification, on generated folder names: ``robot = "<name>"`` exits 2 with one line naming
the folder and the path to give, ``"./<name>"``; ``robot = "./<name>"`` checks; a name with no such
folder keeps the shipped robots' list.
"""

from __future__ import annotations

import contextlib
import io
import tempfile
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st
from support.robots import DH_ROBOT, DH_SCENARIO

from sim.cli import main
from sim.robots.registry import ROBOTS

NAMES = st.from_regex(r"[a-z][a-z0-9_]{2,12}", fullmatch=True).filter(
    lambda n: n not in set(ROBOTS.names()))


def _check(name: str, ref: str, make: bool = True) -> tuple[int, str]:
    with tempfile.TemporaryDirectory() as tmp:
        if make:
            (Path(tmp) / name).mkdir()
            (Path(tmp) / name / "robot.toml").write_text(DH_ROBOT)
        (Path(tmp) / "s.toml").write_text(DH_SCENARIO.replace('"robots/dh_arm"', f'"{ref}"'))
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = main(["check", str(Path(tmp) / "s.toml")])
    return code, err.getvalue()


@settings(max_examples=5, deadline=None)
@given(name=NAMES)
def test_a_folder_named_without_a_path_is_pointed_to(name):
    assert '"robots/dh_arm"' in DH_SCENARIO
    code, err = _check(name, name)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert f"unknown robot {name!r}" in lines[0] and f'give it as a path, "./{name}"' in lines[0]
    code, err = _check(name, f"./{name}")
    assert code in (0, 1), err


def test_without_such_a_folder_the_shipped_robots_are_listed():
    code, err = _check("my_arm", "my_arm", make=False)
    assert code == 2 and "known: " in err and "./my_arm" not in err, err
