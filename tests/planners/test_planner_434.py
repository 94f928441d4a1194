"""4-3-4 planner against seed 001 (Bugnar), plus input validation and the registry.

The validation and registry tests at the end run both planners ("434" and "546").
"""

from __future__ import annotations

import numpy as np
import pytest

from planners import (
    InvalidBoundaryError,
    InvalidKnotsError,
    PlannerError,
    UnknownPlannerError,
    get_planner,
    plan_434,
    plan_546,
)

DEG = np.pi / 180.0

# Seed 001 Table 1: knot times (s) and q1..q5 (deg) of phase I.
TABLE1_TAU = np.array([0.0, 3.33, 6.67, 10.0])
TABLE1_Q = np.array([
    [0.00, 0.00, 0.00, 0.00, 0.000],
    [-7.60, 56.61, 7.08, -7.03, -0.103],
    [-15.20, 113.22, 14.16, -14.06, -0.206],
    [-15.20, 116.82, -1.30, 1.40, -0.206],
])

# Seed 001 eq. 18-20: joint 1 normalized coefficients (rad), ascending powers; segment 3 in
# t_bar. Read off the printed polynomials.
EQ18_20 = [
    np.array([0.0, 0.0, 0.0, -0.2985, 0.1659]),
    np.array([-0.1326, -0.2324, 0.1, -0.0002]),
    np.array([-0.2653, 0.0, 0.0, 0.0331, 0.0331]),
]


def _joint1(times):
    return plan_434(times, TABLE1_Q[:, 0] * DEG)


def test_eq18_20_joint1_with_table1_times():
    """Seed 001 eq. 18-20 (joint 1, Table 1 times 0/3.33/6.67/10 s) to 1e-3 rad."""
    tr = _joint1(TABLE1_TAU)
    assert tr.degrees == (4, 3, 4)
    assert [tr.segment_variable(i) for i in range(3)] == ["t", "t", "t_bar"]
    for i, printed in enumerate(EQ18_20):
        np.testing.assert_allclose(tr.normalized_coefficients[i][0], printed, atol=1e-3,
                                   err_msg=f"segment {i + 1}")


def test_eq18_20_printed_digits_come_from_tau2_6665():
    """Seed 001 eq. 18-20 to their printed rounding (5e-5) with tau = 0/3.33/6.665/10 s.

    With Table 1's tau2 = 6.67 s the largest difference is 4.6e-4 (segment 2's t coefficient,
    -0.2327 against -0.2324; the t^3 coefficient of segment 3, 0.0329 against 0.0331). The
    printed four decimals are matched only near tau1 = 3.33 s and tau2 = 6.665 s, i.e.
    Table 1's tau1 with the MATLAB snippet's tau2 (1/2 * 13.33); the MATLAB tau1 (3.335 s)
    does not match (segment 2's t^3 coefficient turns positive).
    """
    tr = _joint1([0.0, 3.33, 6.665, 10.0])
    for i, printed in enumerate(EQ18_20):
        np.testing.assert_allclose(tr.normalized_coefficients[i][0], printed, atol=5.01e-5)
    matlab = _joint1([0.0, 3.335, 6.665, 10.0])
    assert matlab.normalized_coefficients[1][0, 3] > 0 > EQ18_20[1][3]
    table1 = _joint1(TABLE1_TAU)
    worst = max(np.max(np.abs(c[0] - p)) for c, p in zip(table1.normalized_coefficients, EQ18_20))
    assert 1e-4 < worst < 1e-3


def test_eq10_last_segment_in_t():
    """Seed 001 eq. 10: the last quartic re-expanded in t = t_bar + 1 gives the same curve."""
    tr = plan_434(TABLE1_TAU, TABLE1_Q * DEG)
    a0, a1, a2, a3, a4 = tr.normalized_coefficients[2].T  # per joint
    in_t = [a4 - a3 + a2 - a1 + a0, -4 * a4 + 3 * a3 - 2 * a2 + a1, 6 * a4 - 3 * a3 + a2,
            -4 * a4 + a3, a4]
    t = np.linspace(0.0, 1.0, 11)
    h = TABLE1_TAU[3] - TABLE1_TAU[2]
    q_eq10 = sum(c[None, :] * t[:, None] ** k for k, c in enumerate(in_t))
    np.testing.assert_allclose(q_eq10, tr.at(TABLE1_TAU[2] + t * h).q, atol=1e-12)


@pytest.mark.parametrize("joint", range(5))
def test_table1_conditions_eq12_17(joint):
    """Seed 001 eq. 12-17 for every joint of Table 1: knots, rest at both ends, C2 at knots."""
    tr = plan_434(TABLE1_TAU, TABLE1_Q * DEG)
    s = tr.at(TABLE1_TAU)
    np.testing.assert_allclose(s.q[:, joint], TABLE1_Q[:, joint] * DEG, atol=1e-12)
    for end in (0, -1):
        assert abs(s.qd[end, joint]) < 1e-12 and abs(s.qdd[end, joint]) < 1e-12
    # Left-hand limits from the normalized coefficients (real-time derivative = d/dt / t_i^k).
    h = np.diff(TABLE1_TAU)
    for i in (0, 1):
        c = tr.normalized_coefficients[i][joint]
        poly = np.polynomial.Polynomial(c)
        s_end = 1.0
        for k, name in ((0, "q"), (1, "qd"), (2, "qdd")):
            left = poly.deriv(k)(s_end) / h[i] ** k if k else poly(s_end)
            right = getattr(s, name)[i + 1, joint]
            assert left == pytest.approx(right, rel=1e-10, abs=1e-12), (i, name)


def test_two_segments_is_4_4_closed_form():
    """n = 2 (4-4) at rest, q = 0, d/2, d at 0, h, 2h: q = d t^3 - d t^4 / 2 on segment 1.

    Closed form from eq. 5 with h(0)=v(0)=a(0)=0, h(1)=d/2 and, by the odd symmetry of the
    problem about the middle knot, a(1)=0: a3 = d, a4 = -d/2.
    """
    d, h = 0.8, 0.5
    tr = plan_434([0.0, h, 2 * h], [0.0, d / 2, d])
    assert tr.degrees == (4, 4)
    np.testing.assert_allclose(tr.normalized_coefficients[0][0], [0, 0, 0, d, -d / 2], atol=1e-14)
    # Segment 2 in t_bar is the point reflection: q(t_bar) = d - (d (-t_bar)^3 - d t_bar^4/2).
    np.testing.assert_allclose(tr.normalized_coefficients[1][0], [d, 0, 0, d, d / 2], atol=1e-14)


def test_434_disturbance_decays_like_cubic_spline():
    """Middle cubics with C2 continuity: a deviation shrinks by 2 - sqrt(3) per knot.

    Knot-to-knot transfer of (velocity, acceleration) for equal durations is
    [[-2, -1], [-3, -2]] (from eq. 11 with continuity eq. 14, 16); its eigenvalues are
    -2 +/- sqrt(3). A constant-velocity motion started from rest: the velocity error at the
    knots alternates in sign and decays by |-2 + sqrt(3)| = 0.268 per knot.
    """
    m = 30
    tr = plan_434(np.arange(m + 1.0), np.arange(m + 1.0))
    err = tr.at(np.arange(m + 1.0)).qd[:, 0] - 1.0
    ratios = err[2:8] / err[1:7]
    np.testing.assert_allclose(ratios, -2.0 + np.sqrt(3.0), rtol=1e-6)


def test_boundary_values_per_joint():
    """Non-zero boundary velocity/acceleration per joint (eq. 12, 17 with qdot, qddot given)."""
    times = [1.0, 1.5, 3.0, 3.2, 4.0]
    q = np.array([[0, 1], [0.3, 0.5], [0.1, 0.2], [0.4, -0.3], [0.2, 0.0]])
    v0, vf, a0, af = [0.5, -1.0], [0.2, 0.1], [3.0, -2.0], [-1.0, 4.0]
    tr = plan_434(times, q, v0=v0, vf=vf, a0=a0, af=af)
    s0, s1 = tr.at(1.0), tr.at(4.0)
    np.testing.assert_allclose([s0.q, s0.qd, s0.qdd], [q[0], v0, a0], atol=1e-12)
    np.testing.assert_allclose([s1.q, s1.qd, s1.qdd], [q[-1], vf, af], atol=1e-11)
    # Scalar boundary values apply to every joint.
    tr2 = plan_434(times, q, v0=0.5)
    np.testing.assert_allclose(tr2.at(1.0).qd, [0.5, 0.5], atol=1e-12)


# --------------------------------------------------------------------------- validation
# (shared by both planners)

GOOD_T = [0.0, 1.0, 2.0, 3.0]
GOOD_Q = [[0.0, 0.0], [0.1, 0.2], [0.2, 0.1], [0.3, 0.0]]


@pytest.mark.parametrize("name", ["434", "546"])
@pytest.mark.parametrize("times, q, pattern", [
    ([0.0, 1.0], [[0.0], [1.0]], r"times: 2 knot time\(s\).*at least 3 knots"),
    ([0.0], [[0.0]], r"at least 3 knots"),
    ([0.0, 1.0, 1.0, 2.0], GOOD_Q, r"times\[2\]=1.0 s is not greater than times\[1\]=1.0 s"),
    ([0.0, 2.0, 1.0, 3.0], GOOD_Q, r"times\[2\]=1.0 s is not greater than times\[1\]=2.0 s"),
    ([0.0, 1.0, np.nan, 3.0], GOOD_Q, r"times\[2\] is nan"),
    ([0.0, 1.0, 2.0, np.inf], GOOD_Q, r"times\[3\] is inf"),
    ([[0.0, 1.0, 2.0]], [[0.0], [1.0], [2.0]], r"times: expected a 1-D"),
    (["a", 1.0, 2.0], [0.0, 1.0, 2.0], r"times: knot times must be numbers"),
    (GOOD_T, [[0.0, 0.0], [0.1], [0.2, 0.1], [0.3, 0.0]], r"q: row 1 has 1 value\(s\), expected 2"),
    (GOOD_T, [[0.0, 0.0], [0.1, 0.2], [0.2, 0.1]], r"q: 3 row\(s\).*times has 4 knot"),
    (GOOD_T, [[0.0, 0.0], [0.1, np.nan], [0.2, 0.1], [0.3, 0.0]], r"q\[1, 1\] \(knot 1, joint 2\) is nan"),
    (GOOD_T, [[0.0, 0.0], [0.1, 0.2], [-np.inf, 0.1], [0.3, 0.0]], r"q\[2, 0\] \(knot 2, joint 1\) is -inf"),
    (GOOD_T, np.zeros((4, 2, 1)), r"q: expected shape \(n_knots, n_joints\)"),
    (GOOD_T, np.zeros((4, 0)), r"q: rows are empty"),
])
def test_bad_knots(name, times, q, pattern):
    with pytest.raises(InvalidKnotsError, match=pattern) as info:
        get_planner(name)(times, q)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", ["434", "546"])
@pytest.mark.parametrize("field", ["v0", "vf", "a0", "af"])
@pytest.mark.parametrize("value, pattern", [
    ([1.0, 2.0, 3.0], r"expected a scalar or shape \(2,\).*got shape \(3,\)"),
    ([[1.0, 2.0]], r"got shape \(1, 2\)"),
    ([1.0, np.nan], r"\[1\] \(joint 2\) is nan"),
    (np.inf, r"\[0\] \(joint 1\) is inf"),
    ("fast", r"must be numbers"),
])
def test_bad_boundary(name, field, value, pattern):
    with pytest.raises(InvalidBoundaryError, match=f"^{field}.*{pattern}"):
        get_planner(name)(GOOD_T, GOOD_Q, **{field: value})


@pytest.mark.parametrize("field", ["j0", "jf"])
def test_546_bad_jerk_boundary(field):
    with pytest.raises(InvalidBoundaryError, match=rf"^{field}: expected a scalar or shape \(2,\)"):
        plan_546(GOOD_T, GOOD_Q, **{field: [1.0, 2.0, 3.0]})


@pytest.mark.parametrize("field", ["j0", "jf"])
def test_434_rejects_jerk(field):
    with pytest.raises(InvalidBoundaryError, match=rf"^{field}: the 4-3-4 planner has no jerk.*'546'"):
        get_planner("434")(GOOD_T, GOOD_Q, **{field: 0.0})


def test_errors_are_planner_errors_and_value_errors():
    with pytest.raises(PlannerError):
        plan_434([0.0, 1.0], [0.0, 1.0])
    with pytest.raises(ValueError):
        plan_434([0.0, 1.0], [0.0, 1.0])


def test_planner_names_are_normalized_and_unknown_ones_listed():
    """Spaces and dashes are not part of a planner's name; an unknown name gets the nearest
    known one and the list."""
    assert get_planner("4-3-4") is plan_434 and get_planner(" 5-4-6 ") is plan_546
    with pytest.raises(UnknownPlannerError, match=r"unknown planner '436'.*did you mean.*known: 434, 546"):
        get_planner("436")
    with pytest.raises(UnknownPlannerError, match=r"known: 434, 546$"):
        get_planner("cubic")


#: Finite-difference weights on 5 equally spaced samples from a point into one side, exact for
#: polynomials up to degree 4: first derivative (forward; negate for backward), second
#: (either side), third (forward; negate for backward).
_FD1 = np.array([-25.0, 48.0, -36.0, 16.0, -3.0]) / 12.0
_FD2 = np.array([35.0, -104.0, 114.0, -56.0, 11.0]) / 12.0
_FD3 = np.array([-5.0, 18.0, -24.0, 14.0, -3.0]) / 2.0


def test_434_boundary_conditions_by_finite_differences_of_the_positions():
    """Seed 001's conditions (eq. 12-17) on Table 1, checked from sampled positions alone (not
    the planner's own derivatives or coefficients): one-sided difference quotients from the
    left and from the right of each interior knot agree in velocity and acceleration (C2), the
    motion starts and ends at rest, and the jerk jumps at each interior knot (three pieces,
    not one polynomial); the pieces are a quartic, a cubic and a quartic (the fifth
    differences of equally spaced samples vanish on each, the fourth on the middle one only).
    """
    tr = plan_434(TABLE1_TAU, TABLE1_Q * DEG)
    h = 0.05
    k = np.arange(5)

    def one_side(t0: float, side: int) -> tuple[np.ndarray, ...]:
        q = tr.at(t0 + side * h * k).q
        return side * (_FD1 @ q) / h, (_FD2 @ q) / h**2, side * (_FD3 @ q) / h**3

    v0, a0, _ = one_side(TABLE1_TAU[0], +1)
    vf, af, _ = one_side(TABLE1_TAU[-1], -1)
    for x in (v0, a0, vf, af):
        np.testing.assert_allclose(x, 0.0, atol=1e-9)
    np.testing.assert_allclose(tr.at(TABLE1_TAU).q, TABLE1_Q * DEG, atol=1e-12)
    for tk in TABLE1_TAU[1:-1]:
        vl, al, jl = one_side(tk, -1)
        vr, ar, jr = one_side(tk, +1)
        np.testing.assert_allclose(vl, vr, atol=1e-9, err_msg=f"velocity at {tk} s")
        np.testing.assert_allclose(al, ar, atol=1e-9, err_msg=f"acceleration at {tk} s")
        assert np.abs(jl - jr).max() > 1e-3, f"no jerk jump at {tk} s"
    fourth = []
    for i in range(3):
        q = tr.at(np.linspace(TABLE1_TAU[i], TABLE1_TAU[i + 1], 9)).q
        assert np.abs(np.diff(q, 5, axis=0)).max() < 1e-12, f"segment {i + 1} beyond quartic"
        fourth.append(np.abs(np.diff(q, 4, axis=0)).max())
    assert fourth[0] > 1e-4 and fourth[1] < 1e-12 and fourth[2] > 1e-4, fourth


def test_one_dimensional_q_is_one_joint():
    tr = plan_434([0.0, 1.0, 2.0], [0.0, 1.0, 0.5])
    assert tr.n_joints == 1 and tr.at(1.0).q.shape == (1,)
    assert tr.at(1.0).q[0] == pytest.approx(1.0, abs=1e-14)
