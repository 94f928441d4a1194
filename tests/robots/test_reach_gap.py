"""How far out of reach an OPW arm's pose is (``opw.reach_gap``), and arms that cannot be arms.

The docs promise that an unreachable point's error says how far out of reach it is; a trial's
own DH arm said only "no inverse-kinematics solution (opw solver)". Oracle: the OPW solver
itself (ROS-Industrial's ``opw_kinematics``, ported independently of the gap): on generated
arms and poses a pose has a solution exactly when its gap is 0, and every pose the forward
kinematics reaches has gap 0. A planted fault (the inner reach taken as the outer) is caught.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.errors import KinematicsError
from sim.robots.arm import arm_from_chain
from sim.robots.kinematics import opw
from sim.robots.kinematics.chain import chain_from_dh

MM = 1e-3


@st.composite
def opw_arms(draw) -> opw.OPWParameters:
    """A six-axis OPW arm as DH rows (lengths in mm drawn, the LR Mate's layout) and the OPW
    parameters cellsim derives from it."""
    a1, c1, c2, a2, c3, c4 = (draw(st.floats(lo, hi)) * MM for lo, hi in (
        (0, 300), (100, 800), (150, 1200), (-200, 200), (150, 1200), (0, 300)))
    rows = np.array([[a1, -np.pi / 2, c1, 0.0], [c2, 0.0, 0.0, -np.pi / 2],
                     [a2, -np.pi / 2, 0.0, 0.0], [0.0, np.pi / 2, c3, 0.0],
                     [0.0, -np.pi / 2, 0.0, 0.0], [0.0, 0.0, c4, 0.0]])
    arm = arm_from_chain(chain_from_dh(rows, lower=np.full(6, -np.pi), upper=np.full(6, np.pi)))
    assert arm.opw is not None, arm.why_numeric
    return arm.opw


def _pose(p: np.ndarray, angles: np.ndarray) -> np.ndarray:
    from sim.core.rotations import euler_zyx_to_matrix

    T = np.eye(4)
    T[:3, :3] = euler_zyx_to_matrix(*angles)
    T[:3, 3] = p
    return T


@settings(max_examples=60, deadline=None)
@given(arm=opw_arms(), q=st.lists(st.floats(-np.pi, np.pi), min_size=6, max_size=6))
def test_every_pose_the_arm_reaches_has_no_gap(arm, q):
    gap, inner, outer = opw.reach_gap(arm, opw.forward(arm, np.array(q)))
    assert gap <= 1e-9 and 0 <= inner <= outer


@settings(max_examples=150, deadline=None)
@given(arm=opw_arms(),
       p=st.lists(st.floats(-2.5, 2.5), min_size=3, max_size=3),
       angles=st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3))
def test_a_pose_has_a_solution_exactly_when_its_gap_is_zero(arm, p, angles):
    T = _pose(np.array(p), np.array(angles))
    gap, _, _ = opw.reach_gap(arm, T)
    solved = bool(np.isfinite(opw.inverse(arm, T)).all(axis=1).any())
    if gap > 1e-7:
        assert not solved, gap
    if solved:
        assert gap <= 1e-7, gap


def test_the_gap_is_the_distance_past_the_outer_reach_along_the_arm():
    """Straight out along the arm (shoulder in front, a1 = b = 0 in the plane): the wrist
    centre at ``outer + d`` from J2's axis is ``d`` out of reach, and a planted fault (inner
    and outer swapped) would say otherwise."""
    rows = np.array([[0.0, -np.pi / 2, 0.4, 0.0], [0.5, 0.0, 0.0, -np.pi / 2],
                     [0.0, -np.pi / 2, 0.0, 0.0], [0.0, np.pi / 2, 0.6, 0.0],
                     [0.0, -np.pi / 2, 0.0, 0.0], [0.0, 0.0, 0.1, 0.0]])
    arm = arm_from_chain(chain_from_dh(rows)).opw
    assert arm is not None
    T = np.eye(4)  # flange z along +x: the wrist centre 0.1 m behind the flange
    T[:3, :3] = [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]
    T[:3, 3] = [1.1 + 0.25 + 0.1, 0.0, 0.4]  # wrist centre 1.35 m out: 0.25 m past 1.1 m
    gap, inner, outer = opw.reach_gap(arm, T)
    assert (inner, outer) == pytest.approx((0.1, 1.1), abs=1e-12)
    assert gap == pytest.approx(0.25, abs=1e-12)


def test_neighbouring_joints_on_one_axis_line_are_refused():
    """A zero-length upper arm puts J2 and J3 on one line: one joint twice (a trial's arm
    flooded the console with numpy warnings and blamed the reach)."""
    rows = np.array([[0.075, -np.pi / 2, 0.330, 0.0], [0.300, 0.0, 0.0, -np.pi / 2],
                     [0.075, -np.pi / 2, 0.0, 0.0], [0.0, np.pi / 2, 0.320, 0.0],
                     [0.0, -np.pi / 2, 0.0, 0.0], [0.0, 0.0, 0.080, 0.0]])
    assert arm_from_chain(chain_from_dh(rows)).opw is not None
    rows[1, 0] = 0.0
    with pytest.raises(KinematicsError, match="J2 and J3 turn about one axis line"):
        arm_from_chain(chain_from_dh(rows))
