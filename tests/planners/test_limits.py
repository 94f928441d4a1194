"""Joint limit checks (planners.limits) on trajectories with known extremes.

The reference case is the 4-4 trajectory at rest through 0, d/2, d at 0, h, 2h, whose first
segment is q = d t^3 - d t^4 / 2 (seed 001 eq. 5 with eq. 12-14 and the odd symmetry of the
problem): peak |velocity| d/h at t = h, peak |acceleration| 1.5 d/h^2 at t = h/2 and 3h/2,
positions within [0, d].
"""

from __future__ import annotations

import numpy as np
import pytest

from planners import (
    InvalidBoundaryError,
    LimitViolationError,
    PlannerError,
    check_limits,
    find_limit_violations,
    plan_434,
    plan_546,
)

D, H = 1.2, 0.8          # rad, s
VPEAK = D / H            # rad/s at t = H
APEAK = 1.5 * D / H**2   # rad/s^2 at t = H/2 and 3H/2


@pytest.fixture
def traj():
    """Joint 1: the closed-form 4-4 case; joint 2: the same scaled by -0.5."""
    q = np.array([[0.0, 0.0], [D / 2, -D / 4], [D, -D / 2]])
    return plan_434([0.0, H, 2 * H], q)


def test_within_limits_passes(traj):
    check_limits(traj, lower=[-0.1, -D / 2 - 0.1], upper=[D + 0.1, 0.1], max_velocity=VPEAK * 1.001,
                 max_acceleration=APEAK * 1.001)
    # Exactly at the limit is not a violation.
    check_limits(traj, lower=[0.0, -D / 2], upper=[D, 0.0], max_velocity=VPEAK,
                 max_acceleration=APEAK)
    assert find_limit_violations(traj, max_velocity=VPEAK) == []


def test_velocity_violation_message_and_attributes(traj):
    limit = 0.99 * VPEAK
    with pytest.raises(LimitViolationError) as info:
        check_limits(traj, max_velocity=limit, joint_names=["shoulder", "elbow"])
    err = info.value
    assert (err.joint, err.quantity) == (0, "velocity")
    assert err.value == pytest.approx(VPEAK, rel=1e-12)
    assert err.limit == pytest.approx(limit)
    assert err.time == pytest.approx(H, abs=1e-6)
    msg = str(err)
    assert "\n" not in msg
    assert msg.startswith("joint shoulder: velocity ")
    assert f"{np.degrees(VPEAK):.4g} deg/s" in msg and f"+/-{np.degrees(limit):.4g} deg/s" in msg
    assert f"t={H:.4f} s" in msg
    assert isinstance(err, PlannerError)


def test_acceleration_violation(traj):
    with pytest.raises(LimitViolationError, match=r"joint j1: acceleration .* deg/s\^2") as info:
        check_limits(traj, max_acceleration=0.999 * APEAK)
    err = info.value
    assert err.quantity == "acceleration"
    assert abs(err.value) == pytest.approx(APEAK, rel=1e-12)
    assert min(abs(err.time - H / 2), abs(err.time - 1.5 * H)) < 1e-9


def test_position_violations_both_sides(traj):
    found = find_limit_violations(traj, lower=[0.1, -0.1], upper=[D - 0.1, 1.0])
    kinds = [(v.joint, v.quantity, v.value > v.limit) for v in found]
    assert kinds == [(0, "position", False), (0, "position", True), (1, "position", False)]
    low, high, j2 = found
    assert low.value == pytest.approx(0.0, abs=1e-12) and low.time == pytest.approx(0.0, abs=1e-9)
    assert high.value == pytest.approx(D) and high.time == pytest.approx(2 * H)
    assert j2.value == pytest.approx(-D / 2)
    assert "below lower limit" in low.message() and "above upper limit" in high.message()
    # First exceedance from the sampling: below 0.1 from the start; above D - 0.1 before the
    # end (q = D - 0.1 at t = 2H - x with d x^3 - d x^4 / 2 = 0.1 for x = (2H - t) / H).
    assert low.first_time == 0.0
    x = 0.55
    for _ in range(50):  # Newton on D (x^3 - x^4 / 2) = 0.1
        x -= (D * (x**3 - x**4 / 2) - 0.1) / (D * (3 * x**2 - 2 * x**3))
    assert high.first_time == pytest.approx(2 * H - x * H, abs=2 * (2 * H) / 2000)


def test_all_violations_listed_and_counted(traj):
    found = find_limit_violations(traj, max_velocity=0.1, max_acceleration=0.1)
    assert [(v.joint, v.quantity) for v in found] == [
        (0, "velocity"), (0, "acceleration"), (1, "velocity"), (1, "acceleration")]
    np.testing.assert_allclose([abs(v.value) for v in found],
                               [VPEAK, APEAK, VPEAK / 2, APEAK / 2], rtol=1e-12)
    with pytest.raises(LimitViolationError, match=r"\(and 3 more violation\(s\)\)"):
        check_limits(traj, max_velocity=0.1, max_acceleration=0.1)


def test_sampled_only_check_agrees(traj):
    """With a coarse dt the exact extremes still decide (the sampling alone would miss)."""
    found = find_limit_violations(traj, max_velocity=0.999 * VPEAK, dt=0.3)
    assert len(found) == 1 and found[0].value == pytest.approx(VPEAK, rel=1e-12)


def test_overshoot_between_knots_is_caught():
    """q = 0, 1, 0: the 5-4-6 curve rises above 1 between the knots (exact max from roots)."""
    tr = plan_546([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 1.0, 0.0])
    dense = tr.at(np.linspace(0.0, 3.0, 300_001)).q[:, 0]
    assert dense.max() > 1.0
    (v,) = find_limit_violations(tr, upper=1.0)
    assert v.value == pytest.approx(dense.max(), abs=1e-9) and v.value >= dense.max()
    assert v.time == pytest.approx(np.linspace(0.0, 3.0, 300_001)[np.argmax(dense)], abs=1e-4)


@pytest.mark.parametrize("kwargs, pattern", [
    ({"max_velocity": [1.0, 2.0, 3.0]}, r"max_velocity: expected a scalar or shape \(2,\)"),
    ({"lower": np.nan}, r"lower: limits must not be NaN"),
    ({"upper": "high"}, r"upper: limits must be numbers"),
    ({"joint_names": ["a"]}, r"joint_names: 1 name\(s\) given for 2 joints"),
])
def test_bad_limits(traj, kwargs, pattern):
    with pytest.raises(InvalidBoundaryError, match=pattern):
        check_limits(traj, **kwargs)


def test_infinite_limit_means_none(traj):
    """An infinite limit checks nothing. Joint 1 under infinite limits on every quantity, joint 2
    under finite ones just inside its closed-form extremes (the 4-4 case scaled by -0.5:
    positions -D/2 .. 0, velocity -D/(2h) at t = h, |acceleration| 0.75 D/h^2): exactly joint
    2's four violations are found, at those values; with every limit infinite, none."""
    inf = np.inf
    found = find_limit_violations(traj, lower=[-inf, -0.45 * D], upper=[inf, -0.01],
                                  max_velocity=[inf, 0.45 * VPEAK],
                                  max_acceleration=[inf, 0.45 * APEAK])
    assert [(v.joint, v.quantity, v.limit) for v in found] == [
        (1, "position", -0.45 * D), (1, "position", -0.01), (1, "velocity", 0.45 * VPEAK),
        (1, "acceleration", 0.45 * APEAK)]
    lower, upper, velocity, acceleration = found
    assert lower.value == pytest.approx(-D / 2, rel=1e-9)
    assert upper.value == pytest.approx(0.0, abs=1e-12)
    assert velocity.value == pytest.approx(-VPEAK / 2, rel=1e-9)
    assert velocity.time == pytest.approx(H, abs=1e-9)
    assert abs(acceleration.value) == pytest.approx(APEAK / 2, rel=1e-9)
    # the same finite limits on joint 1 too: its violations appear (the infinite ones hid them)
    assert len(find_limit_violations(traj, upper=[0.5 * D, -0.01])) == 2
    everything = {"lower": -inf, "upper": inf, "max_velocity": inf, "max_acceleration": inf}
    assert find_limit_violations(traj, **everything) == []
    check_limits(traj, **everything)  # does not raise
