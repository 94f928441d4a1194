"""``cellsim ik --all`` lists the same solutions for an arm named as a shipped robot and given
as its file.

The IRB 1600 by name listed 24 solutions (16 outside the joint ranges: every whole-turn variant
of the other joints of a posture outside them) and by its ``robot.toml`` 14 (one per such
posture), for the same pose: found by a session's trial. Specification, for every shipped
robot that is also an arm as data, on generated poses (the forward kinematics of generated
joint values, computed by the arm's own chain: a pose the arm reaches): both listings have the
same solutions inside the joint ranges (as joint values) and the same postures outside them
(joint values modulo a turn), each listed once; every listed solution puts the flange at the
pose (a DH product of the file's table, independent of the solvers).
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.cli import main
from sim.core.rotations import matrix_to_euler_zyx, wrap_to_pi
from sim.robots.arm import is_arm_path, load_arm

MODELS = Path(__file__).resolve().parents[2] / "models"
#: (registry name, folder) of every shipped robot that is also an arm as data.
BOTH = [(load_arm(str(d)).name, d) for d in sorted(MODELS.iterdir())
        if (d / "robot.toml").is_file() and is_arm_path(str(d))]


def _ik(robot: str, T: np.ndarray) -> list[dict]:
    a, b, g = np.rad2deg(matrix_to_euler_zyx(T[:3, :3]))
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["ik", robot, *(f"{v:.12f}" for v in 1e3 * T[:3, 3]), "--euler-zyx-deg",
                     f"{a:.12f}", f"{b:.12f}", f"{g:.12f}", "--all", "--json"])
    assert code == 0
    return json.loads(buf.getvalue())["solutions"]


def _postures(sols: list[dict], inside: bool) -> list[np.ndarray]:
    return [np.deg2rad(s["joints_deg"]) for s in sols if s["within_limits"] == inside]


def _same_sets(a: list[np.ndarray], b: list[np.ndarray], modulo_turn: bool) -> bool:
    def d(x, y):
        return np.abs(wrap_to_pi(x - y) if modulo_turn else x - y).max()

    return len(a) == len(b) and all(min(d(x, y) for y in b) < 1e-6 for x in a)


def test_the_shipped_arms_as_data_are_found():
    assert {name for name, _ in BOTH} >= {"irb1600", "irb2400", "m10ia", "kr6r900_2"}


@pytest.mark.parametrize("name, folder", BOTH, ids=[n for n, _ in BOTH])
@settings(max_examples=4, deadline=None)
@given(u=st.lists(st.floats(0.05, 0.95), min_size=6, max_size=6))
def test_by_name_and_by_file_the_same_solutions(name, folder, u):
    arm = load_arm(str(folder))
    lo, hi = arm.chain.lower, arm.chain.upper
    q = lo + np.asarray(u[:arm.chain.n]) * (hi - lo)
    T = arm.chain.fk(q)
    by_name, by_file = _ik(name, T), _ik(str(folder), T)
    for sols in (by_name, by_file):
        assert sols, "the pose of in-range joint values has a solution"
        for s in sols:  # each at the pose: the file's own DH product
            np.testing.assert_allclose(arm.chain.fk(np.deg2rad(s["joints_deg"])), T, atol=1e-6)
        outside = _postures(sols, False)
        assert all(np.abs(wrap_to_pi(x - y)).max() > 1e-6  # each posture once
                   for i, x in enumerate(outside) for y in outside[i + 1:])
    assert _same_sets(_postures(by_name, True), _postures(by_file, True), modulo_turn=False)
    assert _same_sets(_postures(by_name, False), _postures(by_file, False), modulo_turn=True)
