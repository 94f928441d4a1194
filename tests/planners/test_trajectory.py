"""PiecewisePolynomialTrajectory: evaluation, shapes, time range, coefficient forms, extrema."""

from __future__ import annotations

import numpy as np
import pytest

from planners import PiecewisePolynomialTrajectory, PlannerError, plan_434, plan_546
from planners.base import JointState, Trajectory

PLANS = {"434": plan_434, "546": plan_546}

TIMES = np.array([2.0, 2.4, 3.5, 3.6, 5.0])
Q = np.array([[0.0, 1.0, -0.5], [0.4, 0.8, -0.2], [0.9, 0.1, 0.3], [1.0, 0.0, 0.2],
              [0.6, -0.4, 0.0]])


@pytest.fixture(params=sorted(PLANS))
def traj(request):
    return PLANS[request.param](TIMES, Q, v0=[0.1, 0.0, -0.2], af=[0.0, 1.0, 0.5])


def test_conforms_to_protocol(traj):
    assert isinstance(traj, Trajectory)
    assert isinstance(traj, PiecewisePolynomialTrajectory)
    assert traj.start == 2.0 and traj.end == 5.0 and traj.duration == pytest.approx(3.0)
    assert traj.n_joints == 3 and traj.n_segments == 4
    np.testing.assert_array_equal(traj.knots, TIMES)
    with pytest.raises(ValueError):
        traj.knots[0] = 1.0  # read-only
    assert traj.planner in PLANS
    assert "n_segments=4" in repr(traj)


def test_shapes(traj):
    s = traj.at(3.0)
    assert isinstance(s, JointState)
    for a in (s.q, s.qd, s.qdd, s.qddd):
        assert a.shape == (3,)
    s = traj.at(np.linspace(2.0, 5.0, 7))
    for a in (s.q, s.qd, s.qdd, s.qddd):
        assert a.shape == (7, 3)
    s = traj.at([2.5])
    assert s.q.shape == (1, 3)


def test_scalar_and_array_agree(traj):
    t = np.array([2.0, 2.1, 2.4, 3.55, 4.99, 5.0])
    many = traj.at(t)
    for i, ti in enumerate(t):
        one = traj.at(float(ti))
        np.testing.assert_array_equal(one.q, many.q[i])
        np.testing.assert_array_equal(one.qddd, many.qddd[i])


@pytest.mark.parametrize("t", [1.9, 5.0 + 1e-6, np.nan, -np.inf])
def test_time_out_of_range(traj, t):
    with pytest.raises(PlannerError, match=r"t=.* s is outside the trajectory's time range \[2, 5\] s"):
        traj.at(t)
    with pytest.raises(PlannerError, match="outside"):
        traj.at([3.0, t])


def test_time_slack(traj):
    """Up to 1e-9 s outside [start, end] is accepted and clamped to the end points."""
    np.testing.assert_array_equal(traj.at(2.0 - 5e-10).q, traj.at(2.0).q)
    np.testing.assert_array_equal(traj.at(5.0 + 5e-10).q, traj.at(5.0).q)


def test_sample(traj):
    times, s = traj.sample(0.25)
    np.testing.assert_allclose(times, np.arange(2.0, 5.0001, 0.25))
    assert s.q.shape == (times.size, 3)
    np.testing.assert_allclose(s.q[[0, -1]], Q[[0, -1]], atol=1e-12)
    times, _ = traj.sample(0.7)
    assert times[-1] == 5.0
    for bad in (0.0, -1.0, np.nan):
        with pytest.raises(PlannerError, match="dt"):
            traj.sample(bad)


def test_segment_variable(traj):
    assert [traj.segment_variable(i) for i in range(4)] == ["t", "t", "t", "t_bar"]
    assert traj.segment_variable(-1) == "t_bar"
    with pytest.raises(IndexError):
        traj.segment_variable(4)


def test_coefficient_shapes(traj):
    degs = traj.degrees
    assert len(traj.normalized_coefficients) == len(traj.real_coefficients) == 4
    for d, a, b in zip(degs, traj.normalized_coefficients, traj.real_coefficients):
        assert a.shape == b.shape == (3, d + 1)


def test_normalized_coefficients_evaluate_like_at(traj):
    """Evaluate the normalized form by hand (seed 001 eq. 5-9) and compare with at()."""
    for i, c in enumerate(traj.normalized_coefficients):
        t0, t1 = TIMES[i], TIMES[i + 1]
        h = t1 - t0
        # At tau_i itself at() uses segment i+1 (the 4-3-4 jerk jumps there): stop short.
        last = traj.segment_variable(i) == "t_bar"
        s = np.linspace(-1.0, 0.0, 9) if last else np.linspace(0.0, 1.0, 9)[:-1]
        tau = np.clip((t1 if last else t0) + s * h, t0, t1)
        st = traj.at(tau)
        for j in range(3):
            p = np.polynomial.Polynomial(c[j])
            np.testing.assert_allclose(p(s), st.q[:, j], atol=1e-12)
            np.testing.assert_allclose(p.deriv(1)(s) / h, st.qd[:, j], rtol=1e-10, atol=1e-10)
            np.testing.assert_allclose(p.deriv(2)(s) / h**2, st.qdd[:, j], rtol=1e-10, atol=1e-9)
            np.testing.assert_allclose(p.deriv(3)(s) / h**3, st.qddd[:, j], rtol=1e-10, atol=1e-8)


def test_real_coefficients_evaluate_like_at(traj):
    """Seed 000 Table 5 form: ascending powers of tau (s) on each segment."""
    for i, b in enumerate(traj.real_coefficients):
        tau = np.linspace(TIMES[i], TIMES[i + 1], 9)
        st = traj.at(tau)
        for j in range(3):
            p = np.polynomial.Polynomial(b[j])
            cond = np.polynomial.polynomial.polyval(np.abs(tau), np.abs(b[j]))
            np.testing.assert_allclose(p(tau), st.q[:, j], atol=1e-12 * np.max(cond) + 1e-12)
            np.testing.assert_allclose(p.deriv()(tau), st.qd[:, j],
                                       atol=1e-11 * np.max(cond) / np.diff(TIMES).min() + 1e-11)


def test_real_coefficients_of_a_known_polynomial():
    """Binomial re-expansion checked on a hand case: q = (tau - 2)^2 on [2, 3] (t = tau - 2)."""
    knots = [2.0, 3.0, 4.0]
    coef = np.zeros((2, 1, 5))
    coef[0, 0, 2] = 1.0                  # t^2, t = tau - 2
    coef[1, 0, :3] = [4.0, 4.0, 1.0]     # (t_bar + 2)^2, t_bar = tau - 4  -> (tau - 2)^2
    tr = PiecewisePolynomialTrajectory(knots, coef, [4, 4], planner="test")
    np.testing.assert_allclose(tr.real_coefficients[0][0], [4.0, -4.0, 1.0, 0.0, 0.0], atol=1e-13)
    np.testing.assert_allclose(tr.real_coefficients[1][0], [4.0, -4.0, 1.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(tr.at([2.0, 2.5, 3.0, 4.0]).q[:, 0], [0.0, 0.25, 1.0, 4.0])
    np.testing.assert_allclose(tr.at([2.5, 3.5]).qd[:, 0], [1.0, 3.0])


def test_knot_evaluation_uses_right_segment_and_434_jerk_jumps():
    """At an interior knot at() uses the segment on the right; 4-3-4 jerk jumps there."""
    tr = plan_434(TIMES, Q)
    k = 2
    c_left = tr.normalized_coefficients[k - 1]
    h = np.diff(TIMES)
    jerk_left = np.array([np.polynomial.Polynomial(c).deriv(3)(1.0) for c in c_left]) / h[k - 1] ** 3
    jerk_right = np.array([np.polynomial.Polynomial(c).deriv(3)(0.0)
                           for c in tr.normalized_coefficients[k]]) / h[k] ** 3
    np.testing.assert_allclose(tr.at(TIMES[k]).qddd, jerk_right, rtol=1e-12)
    assert np.max(np.abs(jerk_left - jerk_right)) > 1.0


def test_extrema_closed_form_4_4():
    """4-4 at rest through 0, d/2, d at 0, h, 2h: q = d t^3 - d t^4/2 on segment 1.

    Peak velocity d/h at the middle knot; peak acceleration 1.5 d/h^2 at t = 1/2 (and 3/2);
    peak |jerk| 6 d/h^3 at the ends and on both sides of the middle knot; position spans [0, d].
    """
    d, h = 1.3, 0.7
    tr = plan_434([1.0, 1.0 + h, 1.0 + 2 * h], [0.0, d / 2, d])
    e = tr.extrema()
    assert e.qd_peak[0] == pytest.approx(d / h, rel=1e-12)
    assert e.qd_time[0] == pytest.approx(1.0 + h, abs=1e-6)
    assert e.qdd_peak[0] == pytest.approx(1.5 * d / h**2, rel=1e-12)
    assert min(abs(e.qdd_time[0] - (1.0 + h / 2)), abs(e.qdd_time[0] - (1.0 + 1.5 * h))) < 1e-9
    assert e.qddd_peak[0] == pytest.approx(6 * d / h**3, rel=1e-12)
    assert np.min(np.abs(e.qddd_time[0] - np.array([1.0, 1.0 + h, 1.0 + 2 * h]))) < 1e-12
    assert e.q_min[0] == pytest.approx(0.0, abs=1e-14) and e.q_max[0] == pytest.approx(d)


def test_extrema_against_dense_sampling(traj):
    """Exact extremes: consistent with at() at their times, never below a dense sampling."""
    e = traj.extrema()
    t = np.linspace(traj.start, traj.end, 100_001)
    s = traj.at(t)
    j = np.arange(3)
    pairs = ((e.qd_peak, e.qd_time, "qd"), (e.qdd_peak, e.qdd_time, "qdd"),
             (e.qddd_peak, e.qddd_time, "qddd"))
    for peak, when, name in pairs:
        sampled = np.max(np.abs(getattr(s, name)), axis=0)
        assert np.all(peak >= sampled * (1 - 1e-12))
        # Within what the sampling can miss (slope x half a step), except jerk at knots.
        if name != "qddd":
            assert np.all(peak <= sampled * (1 + 2e-3))
        at_peak = np.abs(getattr(traj.at(when), name)[j, j])
        if name == "qddd" and traj.planner == "434":
            continue  # jerk jumps at knots: the peak may be the left-hand limit
        np.testing.assert_allclose(at_peak, peak, rtol=1e-9)
    np.testing.assert_allclose(traj.at(e.q_min_time).q[j, j], e.q_min, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(traj.at(e.q_max_time).q[j, j], e.q_max, rtol=1e-12, atol=1e-14)
    assert np.all(e.q_min <= s.q.min(axis=0)) and np.all(e.q_max >= s.q.max(axis=0))


def test_extrema_of_a_standing_joint():
    """A joint that does not move: all peaks zero (degenerate polynomials, no roots)."""
    tr = plan_546([0.0, 1.0, 2.0, 3.0], [[0.5, 0.0], [0.5, 1.0], [0.5, 2.0], [0.5, 3.0]])
    e = tr.extrema()
    assert e.qd_peak[0] == e.qdd_peak[0] == e.qddd_peak[0] == 0.0
    assert e.q_min[0] == e.q_max[0] == 0.5
    assert e.qd_peak[1] > 1.0
