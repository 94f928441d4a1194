"""Property tests of both planners over random problems (hypothesis).

Random problems: 2 to 50 segments, 1 to 4 joints, durations whose longest is 100 to 1000
times the shortest, a knot clock that does not start at 0, random knot positions and random
boundary values. Checked for every problem: the knots are met (1e-9), continuity up to the
planner's order (seed 001 eq. 14, 16; seed 000 eq. 21), the boundary conditions (seed 001
eq. 12, 17; seed 000 eq. 18), finite differences of at() against its derivatives, the two
coefficient forms against each other within their conditioning, and, for small problems, a
second formulation (dense solve in real local time, written independently here).

Tolerances are relative to the size of the trajectory itself (its largest |q|, |qd|, ...),
not to the knot values: with uneven durations the interpolating polynomials can swing far
beyond the knots (5-4-6 especially: at 50 segments with a 100x duration spread the median
swing is several hundred times the knot range), and rounding scales with that swing.
"""

from __future__ import annotations

from math import factorial

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from planners import plan_434, plan_546

ORDER = {"434": 2, "546": 3}           # highest continuous derivative
PLANS = {"434": plan_434, "546": plan_546}
NAMES = ("q", "qd", "qdd", "qddd")

SETTINGS = settings(max_examples=40, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])


@st.composite
def problems(draw, min_segments=2, max_segments=50):
    m = draw(st.integers(min_segments, max_segments))
    nj = draw(st.integers(1, 4))
    shortest = draw(st.floats(0.01, 1.0))
    spread = draw(st.floats(100.0, 1000.0))
    u = draw(arrays(np.float64, m, elements=st.floats(0.0, 1.0)))
    lo_i = draw(st.integers(0, m - 1))
    hi_i = draw(st.integers(0, m - 2))
    hi_i = hi_i + (hi_i >= lo_i)         # a different segment
    u[lo_i], u[hi_i] = 0.0, 1.0           # the spread is exactly `spread`
    h = shortest * spread**u
    t0 = draw(st.floats(-100.0, 100.0))
    times = t0 + np.concatenate(([0.0], np.cumsum(h)))
    # Values rounded to 1e-6 (0 or at least 1e-6 in size): no subnormal corner cases.
    q = draw(arrays(np.float64, (m + 1, nj), elements=st.floats(-3.0, 3.0).map(lambda x: round(x, 6))))
    bvals = {}
    for key in ("v0", "vf", "a0", "af", "j0", "jf"):
        if draw(st.booleans()):
            bvals[key] = draw(arrays(np.float64, nj,
                                     elements=st.floats(-2.0, 2.0).map(lambda x: round(x, 6))))
    return times, q, bvals


def _plan(name, times, q, bvals):
    kw = {k: v for k, v in bvals.items() if name == "546" or not k.startswith("j")}
    return PLANS[name](times, q, **kw), kw


def _sides(traj, k):
    """k-th real-time derivative at every interior knot from the left and from the right,
    evaluated directly from the normalized coefficients. Shapes (m-1, n_joints)."""
    h = np.diff(traj.knots)
    m = traj.n_segments
    left, right = [], []
    for i in range(m - 1):
        a = traj.normalized_coefficients[i]
        b = traj.normalized_coefficients[i + 1]
        s_right = -1.0 if i + 1 == m - 1 else 0.0
        left.append([np.polynomial.Polynomial(c).deriv(k)(1.0) for c in a])
        right.append([np.polynomial.Polynomial(c).deriv(k)(s_right) for c in b])
    return np.array(left) / h[:-1, None] ** k, np.array(right) / h[1:, None] ** k


def _scale(traj, name):
    """Largest |derivative| per joint, for relative tolerances."""
    t = np.concatenate([traj.knots, np.linspace(traj.start, traj.end, 2001)])
    return np.max(np.abs(getattr(traj.at(np.clip(t, traj.start, traj.end)), name)), axis=0) + 1e-300


@pytest.mark.parametrize("name", sorted(PLANS))
@SETTINGS
@given(problems())
def test_knots_and_continuity(name, problem):
    times, q, bvals = problem
    traj, _ = _plan(name, times, q, bvals)
    qscale = max(1.0, float(np.max(_scale(traj, "q"))))
    # Knots met from both sides (seed 001 eq. 13, 15; seed 000 eq. 21) and by at().
    left, right = _sides(traj, 0)
    assert np.max(np.abs(left - q[1:-1])) <= 1e-9 * qscale
    assert np.max(np.abs(right - q[1:-1])) <= 1e-9 * qscale
    assert np.max(np.abs(traj.at(times).q - q)) <= 1e-9 * qscale
    # Continuity of derivatives 1..order, relative to each joint's largest value.
    for k in range(1, ORDER[name] + 1):
        left, right = _sides(traj, k)
        scale = _scale(traj, NAMES[k])
        assert np.all(np.abs(left - right) <= 1e-8 * scale), (k, np.max(np.abs(left - right) / scale))


@pytest.mark.parametrize("name", sorted(PLANS))
@SETTINGS
@given(problems())
def test_boundary_conditions(name, problem):
    times, q, bvals = problem
    traj, kw = _plan(name, times, q, bvals)
    nj = q.shape[1]
    s0, s1 = traj.at(times[0]), traj.at(times[-1])
    qscale = max(1.0, float(np.max(_scale(traj, "q"))))
    np.testing.assert_allclose(s0.q, q[0], rtol=0, atol=1e-12 * qscale)
    np.testing.assert_allclose(s1.q, q[-1], rtol=0, atol=1e-9 * qscale)
    keys = [("v0", "vf", 1), ("a0", "af", 2)] + ([("j0", "jf", 3)] if name == "546" else [])
    for k0, kf, k in keys:
        scale = _scale(traj, NAMES[k])
        for key, state in ((k0, s0), (kf, s1)):
            want = kw.get(key, np.zeros(nj))
            err = np.abs(getattr(state, NAMES[k]) - want)
            assert np.all(err <= 1e-8 * scale), (key, np.max(err / scale))


@pytest.mark.parametrize("name", sorted(PLANS))
@SETTINGS
@given(problems(), st.randoms(use_true_random=False))
def test_derivatives_match_finite_differences(name, problem, rnd):
    times, q, bvals = problem
    traj, _ = _plan(name, times, q, bvals)
    h = np.diff(times)
    seg = np.array([rnd.randrange(traj.n_segments) for _ in range(20)])
    frac = np.array([rnd.uniform(0.2, 0.8) for _ in range(20)])
    t = times[seg] + frac * h[seg]
    step = 1e-5 * h[seg]
    tp, tm = t + step, t - step
    sp, sm, s = traj.at(tp), traj.at(tm), traj.at(t)
    dt = (tp - tm)[:, None]            # exact float spacing
    for k in range(3):
        fd = (getattr(sp, NAMES[k]) - getattr(sm, NAMES[k])) / dt
        exact = getattr(s, NAMES[k + 1])
        scale = _scale(traj, NAMES[k + 1])
        # Truncation (relative), plus the rounding floor of a difference of two values.
        tol = 1e-5 * scale + 1e-13 * _scale(traj, NAMES[k]) / dt
        assert np.all(np.abs(fd - exact) <= tol), (k, np.max(np.abs(fd - exact) / tol))


@pytest.mark.parametrize("name", sorted(PLANS))
@SETTINGS
@given(problems())
def test_coefficient_forms_agree_where_well_conditioned(name, problem):
    """Real-time coefficients (seed 000 Table 5 form) against at() (normalized form).

    Evaluating sum b_k tau^k loses about eps * sum |b_k| |tau|^k: the forms must agree to
    within a small multiple of that, and segments where that bound is below 1e-6 of the
    position scale (well conditioned) must agree to 1e-6.
    """
    times, q, bvals = problem
    traj, _ = _plan(name, times, q, bvals)
    qscale = _scale(traj, "q")
    for i, b in enumerate(traj.real_coefficients):
        tau = np.linspace(times[i], times[i + 1], 7)
        ours = traj.at(tau).q
        for j in range(q.shape[1]):
            real = np.polynomial.polynomial.polyval(tau, b[j])
            cond = np.polynomial.polynomial.polyval(np.abs(tau), np.abs(b[j]))
            err = np.abs(real - ours[:, j])
            assert np.all(err <= 1e-13 * cond + 1e-12 * qscale[j])
            if np.max(1e-13 * cond) < 1e-6 * qscale[j]:
                assert np.all(err <= 1e-6 * qscale[j])


# --------------------------------------------------------------------------- second formulation
def _reference(name, times, q, kw):
    """Independent dense solve: q_i(u) = sum_k c_ik u^k with u = tau - tau_{i-1} in real
    seconds (no normalization, no t_bar), conditions written one by one."""
    m = len(times) - 1
    K = ORDER[name]
    deg = [4] + [3] * (m - 2) + [4] if name == "434" else [5] + [4] * (m - 2) + [6]
    h = np.diff(times)
    off = np.concatenate(([0], np.cumsum(np.array(deg) + 1)))
    n = off[-1]
    nj = q.shape[1]

    def drow(i, k, u):
        r = np.zeros(n)
        for p in range(k, deg[i] + 1):
            r[off[i] + p] = factorial(p) / factorial(p - k) * u ** (p - k)
        return r

    A, B = [], []
    starts = [q[0]] + [kw.get(key, np.zeros(nj)) for key in ("v0", "a0", "j0")[:K]]
    ends = [q[-1]] + [kw.get(key, np.zeros(nj)) for key in ("vf", "af", "jf")[:K]]
    for k in range(K + 1):
        A.append(drow(0, k, 0.0))
        B.append(starts[k])
        A.append(drow(m - 1, k, h[-1]))
        B.append(ends[k])
    for i in range(m - 1):
        A.append(drow(i, 0, h[i]))
        B.append(q[i + 1])
        A.append(drow(i + 1, 0, 0.0))
        B.append(q[i + 1])
        for k in range(1, K + 1):
            A.append(drow(i, k, h[i]) - drow(i + 1, k, 0.0))
            B.append(np.zeros(nj))
    c = np.linalg.solve(np.array(A), np.array(B))
    return [c[off[i]: off[i] + deg[i] + 1] for i in range(m)]


@pytest.mark.parametrize("name", sorted(PLANS))
@SETTINGS
@given(problems(max_segments=6))
def test_matches_independent_dense_formulation(name, problem):
    times, q, bvals = problem
    traj, kw = _plan(name, times, q, bvals)
    ref = _reference(name, times, q, kw)
    qscale = _scale(traj, "q")
    h_min = np.min(np.diff(times))
    for i, c in enumerate(ref):
        u = np.linspace(0.0, times[i + 1] - times[i], 5)
        st_ = traj.at(times[i] + u)
        for k in range(ORDER[name] + 1):
            want = np.array([np.polynomial.Polynomial(c[:, j]).deriv(k)(u) for j in range(q.shape[1])]).T
            # Relative to the derivative's size, with a floor set by the positions' rounding.
            tol = 1e-6 * _scale(traj, NAMES[k]) + 1e-12 * qscale / h_min**k
            err = np.abs(getattr(st_, NAMES[k]) - want)
            assert np.all(err <= tol), (i, k, np.max(err / tol))


@pytest.mark.parametrize("name", sorted(PLANS))
@SETTINGS
@given(problems(max_segments=20), st.floats(-5.0, 5.0), st.floats(-5.0, 5.0))
def test_linear_in_the_data(name, problem, alpha, beta):
    """Coefficients are linear in (q, boundary values): plan(a x + b y) = a plan(x) + b plan(y)."""
    times, q, bvals = problem
    q2 = np.roll(q, 1, axis=0)
    t1, kw = _plan(name, times, q, bvals)
    t2, _ = _plan(name, times, q2, {})
    t3, _ = _plan(name, times, alpha * q + beta * q2, {k: alpha * v for k, v in kw.items()})
    size = [max(np.max(np.abs(c)) for c in tr.normalized_coefficients) for tr in (t1, t2, t3)]
    scale = abs(alpha) * size[0] + abs(beta) * size[1] + size[2] + 1e-300
    for a, b, c in zip(t1.normalized_coefficients, t2.normalized_coefficients,
                       t3.normalized_coefficients):
        assert np.max(np.abs(c - (alpha * a + beta * b))) <= 1e-9 * scale
