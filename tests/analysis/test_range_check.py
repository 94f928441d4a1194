"""The verdict's ``range`` check: a simulated joint past its position range is a result to
report, not a pass (a new user's drive override too weak for J2 let the arm fall to 135.6 deg
against its 135 deg range; only tracking and saturation said so).

Specification, on every shipped robot and generated joint records: per joint, the check's value
is how far the recorded ``q`` goes past the joint's range, in deg, computed here from the range
MuJoCo compiles from the robot's own MJCF (0 inside it), and the check fails exactly when that
exceeds the tracking tolerance; its line reads "past the joint's position range". A planted
fault (the ranges read one joint off) is caught. In a cell with other robots their joints are
checked against their own ranges.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.analysis import verdict
from sim.analysis.verdict import check_line, run_checks
from sim.robots.registry import _shipped_robots, get_robot

ROBOTS = sorted(name for name, _ in _shipped_robots())
TOL_DEG = 0.1


def _mjcf_ranges(spec) -> np.ndarray:
    model = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    return np.array([model.joint(j).range for j in spec.joints])


def _arrays(q: np.ndarray) -> dict[str, np.ndarray]:
    return {"q": q, "q_ref": q.copy(), "qd": np.zeros_like(q), "qdd_ref": np.zeros_like(q)}


def _range_checks(spec, q: np.ndarray) -> dict[str, object]:
    checks = run_checks(_arrays(q), {}, spec, TOL_DEG, torch_angle_tolerance_deg=1.0)
    return {c.joint: c for c in checks if c.name == "range"}


@pytest.mark.parametrize("name", ROBOTS)
@settings(max_examples=8, deadline=None)
@given(data=st.data())
def test_a_joint_past_its_range_fails_by_how_far(name, data):
    spec = get_robot(name)
    rng = _mjcf_ranges(spec)
    n = len(spec.joints)
    k = data.draw(st.integers(0, n - 1), label="joint")
    side = data.draw(st.sampled_from([0, 1]), label="side")
    # (clear of the tolerance itself: 0.1 deg past a bound reads 0.1 only to rounding)
    past_deg = data.draw(st.one_of(st.just(0.0), st.floats(-5.0, 5.0).filter(
        lambda x: abs(x - TOL_DEG) > 1e-6)), label="past_deg")
    samples = data.draw(st.integers(2, 50), label="samples")
    at = data.draw(st.integers(0, samples - 1), label="at")
    q = np.tile(rng.mean(axis=1), (samples, 1))
    bound = rng[k, side]
    q[at, k] = bound + (1 if side else -1) * np.radians(past_deg)
    got = _range_checks(spec, q)
    assert set(got) == set(spec.joints)
    want = max(past_deg, 0.0)
    assert got[spec.joints[k]].value == pytest.approx(want, abs=1e-9)
    assert got[spec.joints[k]].passed == (want <= TOL_DEG)
    for j in spec.joints:
        if j != spec.joints[k]:
            assert got[j].value == 0.0 and got[j].passed


def test_the_line_says_past_the_range():
    c = {"name": "range", "joint": "j2", "subject": "", "value": 0.6, "limit": 0.1,
         "unit": "deg", "pass": False, "severity": "error"}
    assert check_line(c) == "range j2: 0.6 deg past the joint's position range (at most 0.1 deg)"


def test_other_robots_joints_are_checked_against_their_own_ranges():
    arm = get_robot("lrmate200ic5l")
    other = get_robot("lrmate100ib")
    system = arm.with_partners([("r2", other)])
    q = np.tile(np.concatenate([_mjcf_ranges(arm).mean(axis=1),
                                _mjcf_ranges(other).mean(axis=1)]), (3, 1))
    q[1, len(arm.joints) + 1] = _mjcf_ranges(other)[1, 1] + np.radians(2.0)
    got = _range_checks(system, q)
    assert got["r2_j2"].value == pytest.approx(2.0) and not got["r2_j2"].passed
    assert all(c.passed for j, c in got.items() if j != "r2_j2")


def test_a_track_axis_is_checked_in_mm_and_an_unlimited_joint_never_fails():
    import dataclasses

    from sim.robots.mechanisms.registry import MECHANISMS

    arm = get_robot("lrmate200ic5l")
    track = MECHANISMS.get("floor_track_4m")
    system = arm.with_axes([("track_travel", a) for a in track.axes])
    lo, hi = track.axes[0].range  # m
    q = np.tile(np.r_[_mjcf_ranges(arm).mean(axis=1), 0.5 * (lo + hi)], (3, 1))
    q[2, -1] = hi + 0.0003  # 0.3 mm past
    checks = run_checks(_arrays(q), {}, system, TOL_DEG, torch_angle_tolerance_deg=1.0,
                        tracking_tolerance_mm=0.5)
    got = {c.joint: c for c in checks if c.name == "range"}["track_travel"]
    assert got.unit == "mm" and got.value == pytest.approx(0.3) and got.passed
    q[2, -1] = hi + 0.0008
    checks = run_checks(_arrays(q), {}, system, TOL_DEG, torch_angle_tolerance_deg=1.0,
                        tracking_tolerance_mm=0.5)
    got = {c.joint: c for c in checks if c.name == "range"}["track_travel"]
    assert got.value == pytest.approx(0.8) and not got.passed
    # an axis without limits (its range -inf..inf) is never past it
    free = dataclasses.replace(track.axes[0], range=(-np.inf, np.inf))
    system = arm.with_axes([("track_travel", free)])
    q[2, -1] = 1e6
    checks = run_checks(_arrays(q), {}, system, TOL_DEG, torch_angle_tolerance_deg=1.0)
    got = {c.joint: c for c in checks if c.name == "range"}["track_travel"]
    assert got.value == 0.0 and got.passed


def test_planted_fault_ranges_one_joint_off_are_caught(monkeypatch):
    spec = get_robot("lrmate200ic5l")
    rng = _mjcf_ranges(spec)
    q = np.tile(rng.mean(axis=1), (3, 1))
    q[1, 1] = rng[1, 1] + np.radians(1.0)
    assert _range_checks(spec, q)["j2"].value == pytest.approx(1.0)
    real = verdict.joint_ranges
    monkeypatch.setattr(verdict, "joint_ranges", lambda s: np.roll(real(s), 1, axis=0))
    assert _range_checks(spec, q)["j2"].value != pytest.approx(1.0)
