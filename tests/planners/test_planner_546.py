"""5-4-6 planner against seed 000 (Kacso, Negrean, Schonstein), Tables 3-5 and eq. 18-24."""

from __future__ import annotations

import numpy as np
import pytest

from planners import plan_546

# Seed 000 Table 3: knot times (s) and q2, q3, q4 (deg).
TAU = np.array([0.0, 0.208, 0.416, 0.624])
Q = np.array([[0.0, 0.0, 0.0],
              [28.79, -1.2, 2.41],
              [57.59, -2.41, 4.83],
              [86.38, -3.62, 7.24]])
LINKS = {2: 0, 3: 1, 4: 2}  # link number -> column of Q

# Seed 000 Table 4 (deg), printed as a6 a5 a4 a3 a2 a1 a0; stored here ascending a0..a6.
TABLE4 = {
    (1, 2): [0.00, 0.00, 0.00, 0.00, 69.87, -41.08, 0.00],
    (1, 3): [0.00, 0.00, 0.00, 0.00, -2.83, 1.63, 0.00],
    (1, 4): [0.00, 0.00, 0.00, 0.00, 5.85, -3.44, 0.00],
    (2, 2): [28.79, 74.08, 8.40, -131.34, 77.66, 0.00, 0.00],
    (2, 3): [-1.20, -3.17, -0.70, 4.95, -2.29, 0.00, 0.00],
    (2, 4): [2.41, 6.20, 0.71, -10.99, 6.49, 0.00, 0.00],
    (3, 2): [86.38, 0.00, 0.00, 0.00, -313.96, -462.69, -177.52],
    (3, 3): [-2.41, 1.13, 0.42, -4.21, 1.46, 0.00, 0.00],
    (3, 4): [7.24, 0.00, 0.00, 0.00, -26.25, -38.68, -14.84],
}

# Seed 000 Table 5 (deg, powers of tau in s), ascending.
TABLE5 = {
    (1, 2): [0, 0, 0, 0, 37330.6, -105526.01],
    (1, 3): [0, 0, 0, 0, -1509.54, 4175.16],
    (1, 4): [0, 0, 0, 0, 3124.06, -8829.36],
    (2, 2): [172.12, -3112.59, 20072.56, -49117.04, 41492.19],
    (2, 3): [-5.96, 106.94, -677.29, 1568.68, -1223.87],
    (2, 4): [14.39, -260.3, 1678.53, -4106.62, 3468.65],
    (3, 2): [-42321.3, 506438.95, -2489638.56, 6443564.41, -9263157.66, 7018837.43, -2192115.2],
    (3, 3): [53.99, -469.65, 1401.79, -1763.19, 778.46],
    (3, 4): [-3537.72, 42334.57, -208117.34, 538646.03, -774358.71, 586751.48, -183255.93],
}


@pytest.fixture(scope="module")
def traj():
    """Table 3 knots (deg), start and end at rest with zero acceleration and jerk."""
    return plan_546(TAU, Q)


def test_degrees_and_variables(traj):
    """Eq. 19, 20, 22: quintic, quartic, sextic; the last segment in t_bar."""
    assert traj.degrees == (5, 4, 6)
    assert [traj.segment_variable(i) for i in range(3)] == ["t", "t", "t_bar"]
    assert traj.planner == "546"


@pytest.mark.parametrize("seg", [1, 2, 3])
@pytest.mark.parametrize("link", [2, 4])
def test_table4_links_2_and_4(traj, seg, link):
    """Seed 000 Table 4, links 2 and 4, every segment, to 0.02 deg."""
    ours = traj.normalized_coefficients[seg - 1][LINKS[link]]
    printed = np.array(TABLE4[(seg, link)][: ours.size])
    assert not np.any(TABLE4[(seg, link)][ours.size:])  # nothing printed above our degree
    np.testing.assert_allclose(ours, printed, atol=0.02)


@pytest.mark.parametrize("seg", [1, 2, 3])
@pytest.mark.parametrize("link", [2, 4])
def test_table5_links_2_and_4(traj, seg, link):
    """Seed 000 Table 5: the printed real-time polynomials match ours over each segment.

    Evaluated on 201 points of the segment: Table 5 against ``at`` to 0.05 deg, and our
    real-time coefficients (evaluated here with numpy) against Table 5 to 0.05 deg; the
    coefficients themselves agree to 2e-4 relative (or to the printed two decimals).
    """
    tau = np.linspace(TAU[seg - 1], TAU[seg], 201)
    printed = np.polynomial.polynomial.polyval(tau, TABLE5[(seg, link)])
    j = LINKS[link]
    np.testing.assert_allclose(traj.at(tau).q[:, j], printed, atol=0.05)
    ours = traj.real_coefficients[seg - 1][j]
    np.testing.assert_allclose(np.polynomial.polynomial.polyval(tau, ours), printed, atol=0.05)
    # Relative 2e-4, or the printed rounding (two decimals) for the small ones.
    np.testing.assert_allclose(ours, TABLE5[(seg, link)], rtol=2e-4, atol=0.006)


def test_link3_printed_tables_contradict_eq18_22():
    """Seed 000 link 3, last segment: the printed numbers break the paper's own conditions.

    Eq. 22 makes the last segment a sextic in t_bar = t - 1 with q(0) = q_m (eq. 18: -3.62
    deg, Table 3) and rest at t_bar = 0. Table 4's link-3 row is a quartic (a5 = a6 = 0);
    read in t_bar it ends at a0 = -2.41 deg, the value of the previous knot, with velocity
    a1 / t_3 != 0. Read in t instead (as Table 5 does, with tau_{k-1} = 0.416 s) it reaches
    -3.61 deg at tau = 0.624 s but still moves at about -23 deg/s. Links 2 and 4 in the same
    tables meet every condition.
    """
    c = np.array(TABLE4[(3, 3)])
    h = TAU[3] - TAU[2]
    assert c[5] == c[6] == 0.0
    p = np.polynomial.Polynomial(c)
    assert p(0.0) == pytest.approx(-2.41) and abs(p(0.0) - Q[3, 1]) > 1.0  # t_bar = 0
    assert abs(p.deriv()(0.0) / h) > 5.0                                    # not at rest
    assert p(1.0) == pytest.approx(-3.61, abs=0.006)                         # read in t
    assert abs(p.deriv()(1.0) / h + 23.2) < 0.5
    # Table 5, real time: the same quartic, ends near -3.63 deg, moving.
    r = np.polynomial.Polynomial(TABLE5[(3, 3)])
    assert r(TAU[3]) == pytest.approx(-3.62, abs=0.02)
    assert abs(r.deriv()(TAU[3])) > 20.0
    assert abs(r.deriv(2)(TAU[3])) > 100.0
    # Links 2 and 4 (Table 4 in t_bar): at the knot, at rest, and through the knot before.
    for link in (2, 4):
        pk = np.polynomial.Polynomial(TABLE4[(3, link)])
        assert pk(0.0) == pytest.approx(Q[3, LINKS[link]], abs=1e-9)
        assert pk.deriv()(0.0) == pk.deriv(2)(0.0) == pk.deriv(3)(0.0) == 0.0
        assert pk(-1.0) == pytest.approx(Q[2, LINKS[link]], abs=0.02)


def test_link3_meets_the_conditions(traj):
    """Our link 3 instead: Table 3 knots, rest (v, a, jerk = 0) at both ends, C3 at knots."""
    j = LINKS[3]
    s = traj.at(TAU)
    np.testing.assert_allclose(s.q[:, j], Q[:, j], atol=1e-12)
    for end in (0, -1):
        for name in ("qd", "qdd", "qddd"):
            assert abs(getattr(s, name)[end, j]) < 1e-7, (end, name)
    h = np.diff(TAU)
    for i in (0, 1):
        p = np.polynomial.Polynomial(traj.normalized_coefficients[i][j])
        for k, name in enumerate(("q", "qd", "qdd", "qddd")):
            left = p.deriv(k)(1.0) / h[i] ** k if k else p(1.0)
            right = getattr(s, name)[i + 1, j]
            scale = np.max(np.abs(getattr(traj.at(np.linspace(0, 0.624, 101)), name)[:, j]))
            assert abs(left - right) <= 1e-10 * scale, (i, name)
    # Table 4's link-3 row differs from ours in segment 1 already (a5: 1.63 against 1.71).
    assert traj.normalized_coefficients[0][j][5] == pytest.approx(1.71, abs=0.01)


def test_two_segments_5_6():
    """m = 2: quintic then sextic, 13 coefficients for 4 + 4 + 5 conditions."""
    times = [0.0, 0.3, 1.0]
    q = [[0.0, 1.0], [0.4, 0.5], [1.0, -0.2]]
    kw = dict(v0=[0.1, 0.0], vf=[0.0, -0.3], a0=[1.0, 0.0], af=[0.0, 2.0], j0=[0.0, 5.0],
              jf=[-3.0, 0.0])
    tr = plan_546(times, q, **kw)
    assert tr.degrees == (5, 6)
    s0, s1 = tr.at(0.0), tr.at(1.0)
    np.testing.assert_allclose([s0.q, s0.qd, s0.qdd, s0.qddd],
                               [q[0], kw["v0"], kw["a0"], kw["j0"]], atol=1e-11)
    np.testing.assert_allclose([s1.q, s1.qd, s1.qdd, s1.qddd],
                               [q[2], kw["vf"], kw["af"], kw["jf"]], atol=1e-10)
    p = [np.polynomial.Polynomial(c) for c in tr.normalized_coefficients[0]]
    mid = tr.at(0.3)
    for j in range(2):
        for k, name in enumerate(("q", "qd", "qdd", "qddd")):
            left = p[j].deriv(k)(1.0) / 0.3 ** k if k else p[j](1.0)
            assert left == pytest.approx(getattr(mid, name)[j], rel=1e-10, abs=1e-10)


def test_long_uniform_chain_keeps_an_alternating_mode():
    """Quartic middle segments with C3 continuity have a knot-to-knot eigenvalue of -1.

    Transfer of (v t, a t^2/2, j t^3/6) across one quartic of eq. 20 with eq. 21:
    [[-3, -2, -1], [-6, -5, -3], [-4, -4, -3]], characteristic polynomial
    (l + 1)(l^2 + 10 l + 1) (the degree-4 Euler-Frobenius polynomial): eigenvalues -1 and
    -5 +/- 2 sqrt(6). So a constant-velocity motion through many equal segments, started
    and ended at rest, keeps a velocity error that flips sign at every knot and never decays
    (here the joint reverses at every other knot). This is a property of the 5-4-6 scheme,
    not a numerical error: the solution still meets every condition.
    """
    T = np.array([[-3, -2, -1], [-6, -5, -3], [-4, -4, -3]], dtype=float)
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(T).real),
                               np.sort([-1.0, -5 - 2 * np.sqrt(6), -5 + 2 * np.sqrt(6)]))
    m = 40
    knots = np.arange(m + 1.0)
    tr = plan_546(knots, knots)
    err = tr.at(knots).qd[:, 0] - 1.0
    inner = err[10:30]
    np.testing.assert_allclose(inner[1:] / inner[:-1], -1.0, rtol=1e-6)
    assert np.min(tr.at(knots[5:35]).qd[:, 0]) < 0.0  # the joint moves backwards
    np.testing.assert_allclose(tr.at(knots).q[:, 0], knots, atol=1e-9)
