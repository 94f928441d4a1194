"""ADNIA Cartesian interpolation (planners.adnia) against seed 003 and independent computations.

Seed references: Table I and eq. (1)-(7) (linear ADNIA), eq. (8)-(10) (position matrix G),
eq. (11)-(18) (circular/spherical ADNIA example). Independent computations: circumcentre by a
linear solve, arc length by scipy quadrature, finite differences of the continuous trajectory,
the discrete algorithms as a second formulation of ``sample(dt)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.spatial.transform import Rotation

from planners.adnia import (
    DEFAULT_MAX_ACCELERATION,
    CartesianTrajectory,
    CoincidentPointsError,
    CollinearPointsError,
    InvalidMoveError,
    adnia_arc,
    adnia_linear,
    adnia_spherical,
    adnia_step_count,
    adnia_versors,
    arc_move,
    circle_move,
    linear_move,
    spherical_move,
)
from planners.base import Trajectory
from planners.errors import PlannerError
from planners.profiles import InvalidProfileError, MoveTooShortError
from planners.rotations import InvalidOrientationError

MM = 1e-3

# Seed 003 Table I, mm: step l, X_l, Y_l, Z_l
TABLE_I = np.array([
    [0, 1.0, 2.00, 3.0],
    [1, 1.1, 2.36, 3.4],
    [2, 1.2, 2.72, 3.8],
    [3, 1.3, 3.08, 4.2],
    [4, 1.4, 3.44, 4.6],
    [5, 1.5, 3.80, 5.0],
    [6, 1.6, 4.16, 5.4],
    [7, 1.7, 4.52, 5.8],
    [8, 1.8, 4.88, 6.2],
    [9, 1.9, 5.24, 6.6],
    [10, 2.0, 5.60, 7.0],
])
# The example of eq. (6): SI units
P_O = np.array([1.0, 2.0, 3.0]) * MM
P_F = np.array([2.0, 4.0 * math.sqrt(2.0), 7.0]) * MM
V = 2.5e3 * MM          # m/s
DT = 0.2e-3             # s


# ---------------------------------------------------------------------------------------------
# seed 003 linear ADNIA, eq. (1)-(7) and Table I
# ---------------------------------------------------------------------------------------------
def test_eq5_step_count_is_11_and_seed_10_is_a_slip() -> None:
    """Eq. (5) on the eq. (6) example gives L/(v dt) = 11.02 -> N = 11, not the printed 10."""
    L = math.sqrt(1.0**2 + (4 * math.sqrt(2) - 2) ** 2 + 4.0**2)     # mm, by hand
    ratio = L / (2.5e3 * 0.2e-3)
    assert ratio == pytest.approx(11.0223, abs=1e-4)
    n, r = adnia_step_count(L * MM, V, DT)
    assert n == 11 and r == pytest.approx(ratio, rel=1e-14)
    res = adnia_linear(P_O, P_F, V, DT)
    assert res.steps == 11 and res.length == pytest.approx(L * MM, rel=1e-15)
    # the seed's N = 10 would need L/(v dt) in [9.5, 10.5), i.e. L in [4.75, 5.25) mm
    assert not 4.75 <= L < 5.25


def test_table_I_reproduced_with_fixed_point_steps() -> None:
    """Table I, all columns, to 0.01 mm: N = 10 (as printed) and 0.01 mm DDA axis steps."""
    res = adnia_linear(P_O, P_F, V, DT, steps=10, resolution=0.01 * MM)
    assert res.steps == 10
    assert np.allclose(res.delta / MM, [0.1, 0.36, 0.4], atol=1e-12)        # eq. (7)
    assert np.max(np.abs(res.points / MM - TABLE_I[:, 1:])) < 0.01
    assert np.max(np.abs(res.points / MM - TABLE_I[:, 1:])) < 1e-9          # in fact exact
    # the truncated steps stop short of P_F in Y: 5.6 vs 4 sqrt(2)
    assert res.end_error / MM == pytest.approx([0.0, 5.6 - 4 * math.sqrt(2), 0.0], abs=1e-12)
    # eq. (10): G_7 with the default orientation n, o, a along x, y, z (eq. 9)
    G7 = np.eye(4)
    G7[:3, 3] = res.points[7]
    assert np.allclose(G7[:3, 3] / MM, [1.7, 4.52, 5.8], atol=1e-12)


def test_table_I_in_exact_arithmetic() -> None:
    """N = 10 with exact steps: X and Z equal Table I; Y is off by l (0.36569 - 0.36) mm."""
    res = adnia_linear(P_O, P_F, steps=10)
    exact_dy = (4 * math.sqrt(2) - 2) / 10          # 0.365685 mm (eq. 7 prints "~0.36")
    assert res.delta[1] / MM == pytest.approx(exact_dy, rel=1e-14)
    l = TABLE_I[:, 0]
    assert np.allclose(res.points[:, 0] / MM, TABLE_I[:, 1], atol=1e-12)
    assert np.allclose(res.points[:, 2] / MM, TABLE_I[:, 3], atol=1e-12)
    dy = res.points[:, 1] / MM - TABLE_I[:, 2]
    assert np.allclose(dy, l * (exact_dy - 0.36), atol=1e-12)
    assert dy[-1] == pytest.approx(0.0569, abs=1e-4)                      # 4 sqrt 2 - 5.6
    assert np.sum(np.abs(dy) > 0.01) == 9                                  # l = 2..10 miss 0.01 mm
    assert np.allclose(res.points[-1], P_F, atol=1e-18)
    assert np.allclose(res.end_error, 0.0, atol=1e-18)


def test_linear_adnia_eq1_is_running_sum_eq2() -> None:
    """Eq. (2): x_l = x_O + sum of l axis steps equals eq. (1) x_O + l delta."""
    res = adnia_linear(P_O, P_F, V, DT)
    running = P_O + np.cumsum(np.vstack([np.zeros(3), np.tile(res.delta, (res.steps, 1))]), axis=0)
    assert np.allclose(res.points, running, atol=1e-18)
    # the actual speed of the discrete form is L / (N dt)
    assert np.linalg.norm(res.delta) / DT == pytest.approx(res.length / (res.steps * DT), rel=1e-14)


# ---------------------------------------------------------------------------------------------
# seed 003 circular ADNIA example, eq. (11)-(18)
# ---------------------------------------------------------------------------------------------
def test_spherical_example_eq_15_to_18() -> None:
    """N = 10, (R, varphi, phi) from (1, 0, 90 deg) to (1, 90 deg, 45 deg)."""
    d = math.radians
    res = adnia_spherical((1.0, 0.0, d(90)), (1.0, d(90), d(45)), steps=10)
    assert math.degrees(res.delta_varphi) == pytest.approx(9.0, abs=1e-13)     # eq. (15)
    assert math.degrees(res.delta_phi) == pytest.approx(-4.5, abs=1e-13)       # -4 deg 30'
    for l in range(11):
        x = math.sin(d(90 - l * 4.5)) * math.cos(d(0 + l * 9))                    # eq. (16)
        y = math.sin(d(90 - l * 4.5)) * math.sin(d(0 + l * 9))                    # eq. (17)
        z = math.cos(d(90 - l * 4.5))                                             # eq. (18)
        assert np.allclose(res.points[l], [x, y, z], atol=1e-15)
    assert np.allclose(np.linalg.norm(res.points, axis=1), 1.0, atol=1e-15)


def test_spherical_step_count_eq14_uses_curve_length() -> None:
    """Eq. (14): N = round(L / (v dt)) with L the length of the traced curve (quadrature)."""
    d = math.radians
    start, end = (0.2, d(10), d(80)), (0.2, d(130), d(30))
    dvarphi, dphi = d(120), d(-50)
    L_ref = quad(lambda u: 0.2 * math.hypot(dphi, math.sin(d(80) + u * dphi) * dvarphi), 0, 1,
                 epsabs=1e-14, epsrel=1e-13, limit=200)[0]
    v, dt = 0.05, 4e-3
    res = adnia_spherical(start, end, v, dt)
    assert res.length == pytest.approx(L_ref, rel=1e-13)
    assert res.steps == math.floor(L_ref / (v * dt) + 0.5)


def test_spherical_move_passes_through_the_seed_points() -> None:
    """The continuous spherical move follows the curve the discrete eq. (12)-(18) samples."""
    d = math.radians
    start, end = (1.0, 0.0, d(90)), (1.0, d(90), d(45))
    res = adnia_spherical(start, end, steps=10)
    mv = spherical_move(start, end, 0.5, ramp_time=0.1)
    path = mv.path
    u = np.arange(11) / 10
    s = path.arc_length(u)
    assert np.allclose(path.evaluate(s)[0], res.points, atol=1e-13)    # inversion u(s(u)) = u
    # arc length against quadrature of |dp/du|
    for k in (3, 7, 10):
        ref = quad(lambda w: math.hypot(d(-45), math.sin(d(90) - w * d(45)) * d(90)), 0, u[k],
                   epsabs=1e-14, epsrel=1e-13, limit=200)[0]
        assert s[k] == pytest.approx(ref, rel=1e-13)
    times, st_ = mv.sample(1e-3)
    assert np.allclose(np.linalg.norm(st_.position, axis=1), 1.0, atol=1e-12)


def test_versor_adnia_eq_19_to_24() -> None:
    """Eq. (19)-(22) with N = 10; all frames orthonormal."""
    d = math.radians
    a0 = np.array([1.0, 0.0, 0.0])
    a1 = np.array([0.0, math.sin(d(45)), math.cos(d(45))])
    o0, o1 = np.array([0.0, 1.0, 0.0]), np.array([-1.0, 0.0, 0.0])
    R0 = np.column_stack([np.cross(o0, a0), o0, a0])
    R1 = np.column_stack([np.cross(o1, a1), o1, a1])
    res = adnia_versors(R0, R1, 10)
    assert math.degrees(res.delta_varphi[2]) == pytest.approx(9.0, abs=1e-13)
    assert math.degrees(res.delta_phi[2]) == pytest.approx(-4.5, abs=1e-13)
    a_seed = np.array([[math.sin(d(90 - l * 4.5)) * math.cos(d(l * 9)),
                        math.sin(d(90 - l * 4.5)) * math.sin(d(l * 9)),
                        math.cos(d(90 - l * 4.5))] for l in range(11)])
    assert np.allclose(res.raw[:, :, 2], a_seed, atol=1e-15)
    assert np.allclose(res.frames[:, :, 2], a_seed, atol=1e-15)
    F = res.frames
    assert np.max(np.abs(np.swapaxes(F, 1, 2) @ F - np.eye(3))) < 1e-12
    assert np.max(np.abs(np.linalg.det(F) - 1)) < 1e-12


# ---------------------------------------------------------------------------------------------
# the continuous form against the discrete one
# ---------------------------------------------------------------------------------------------
def test_sample_is_linear_adnia_without_ramps() -> None:
    """ramp_time = 0 and v = L / (N dt): sample(dt) returns the eq. (1) points P_0..P_N."""
    N = 11
    disc = adnia_linear(P_O, P_F, steps=N)
    v = disc.length / (N * DT)
    mv = linear_move(P_O, P_F, v, ramp_time=0.0)
    times, st_ = mv.sample(DT)
    assert len(times) == N + 1
    assert np.allclose(st_.position, disc.points, atol=1e-15)
    G = st_.pose()                                   # eq. (8)-(9): identity orientation
    assert np.allclose(G[7, :3, :3], np.eye(3)) and np.allclose(G[7, :3, 3], disc.points[7])


def test_sample_is_arc_adnia_without_ramps() -> None:
    A, B, C = np.array([0.4, 0.1, 0.3]), np.array([0.35, 0.25, 0.32]), np.array([0.2, 0.3, 0.25])
    disc = adnia_arc(A, B, C, 0.05, 2e-3)
    v = disc.length / (disc.steps * 2e-3)
    mv = arc_move(A, B, C, v, ramp_time=0.0)
    times, st_ = mv.sample(2e-3)
    assert len(times) == disc.steps + 1
    assert np.allclose(st_.position, disc.points, atol=1e-14)
    assert np.allclose(disc.points[-1], C, atol=1e-14)
    assert disc.steps == math.floor(disc.length / (0.05 * 2e-3) + 0.5)


# ---------------------------------------------------------------------------------------------
# property tests (hypothesis) on random lines and arcs
# ---------------------------------------------------------------------------------------------
coord = st.floats(-2.0, 2.0)
points = st.tuples(coord, coord, coord).map(np.array)
rotvecs = st.tuples(*(st.floats(-3.0, 3.0),) * 3).map(np.array)


def _circumcentre(A: np.ndarray, B: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Independent circumcentre: equidistance equations plus the plane equation."""
    n = np.cross(B - A, C - A)
    M = np.array([2 * (B - A), 2 * (C - A), n])
    rhs = np.array([B @ B - A @ A, C @ C - A @ A, n @ A])
    return np.linalg.solve(M, rhs), n / np.linalg.norm(n)


def _check_common(mv: CartesianTrajectory, v: float, dt: float) -> None:
    """Rest at both ends, FD derivatives, orthonormal frames, constant speed, v*dt spacing."""
    D, T = mv.duration, mv.profile.ramp_time
    ends = mv.at(np.array([0.0, D]))
    for q in (ends.velocity, ends.acceleration, ends.jerk, ends.angular_velocity):
        assert np.all(q == 0.0)
    assert np.all(ends.speed == 0.0)
    assert ends.path_length.tolist() == [0.0, mv.length]
    # finite differences at interior times
    t = np.linspace(0.02 * D, 0.98 * D, 41)
    h = 1e-4 * min(T, D)
    # the quintic ramp's snap jumps where a ramp meets the constant part: keep the central
    # differences (error ~ h * snap jump there) off those two instants
    t = t[(np.abs(t - T) > 3 * h) & (np.abs(t - (D - T)) > 3 * h)]
    stp, stm, st0 = mv.at(t + h), mv.at(t - h), mv.at(t)
    dense = mv.at(np.linspace(0, D, 801))
    for f, df in (("position", "velocity"), ("velocity", "acceleration"), ("acceleration", "jerk")):
        fd = (getattr(stp, f) - getattr(stm, f)) / (2 * h)
        scale = np.max(np.abs(getattr(dense, df))) + 1e-12
        assert np.max(np.abs(fd - getattr(st0, df))) < 1e-5 * scale, (f, df)
    w_fd = Rotation.from_matrix(stp.rotation @ np.swapaxes(stm.rotation, 1, 2)).as_rotvec() / (2 * h)
    assert np.max(np.abs(w_fd - st0.angular_velocity)) < 1e-5 * (np.max(np.abs(dense.angular_velocity)) + 1e-9)
    # orthonormal tool frames everywhere
    R = dense.rotation
    assert np.max(np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(3))) < 1e-12
    assert np.max(np.abs(np.linalg.det(R) - 1.0)) < 1e-12
    # constant speed on the constant-speed part
    tc = np.linspace(T, D - T, 201)
    sc = mv.at(tc)
    assert np.max(np.abs(np.linalg.norm(sc.velocity, axis=1) / v - 1.0)) < 1e-9
    assert np.max(np.abs(sc.speed / v - 1.0)) < 1e-12
    # sample(dt): equal arc-length spacing v dt on the constant-speed part
    times, ss = mv.sample(dt)
    assert times[0] == 0.0 and times[-1] == D and np.allclose(np.diff(times)[:-1], dt)
    inside = (times[:-1] >= T) & (times[1:] <= D - T)
    ds = np.diff(ss.path_length)[inside]
    assert np.allclose(ds, v * dt, rtol=1e-9, atol=0)


def _check_step_count(disc, ratio_ref: float) -> None:
    """Eq. (5)/(14): N = round(L / (v dt)), halves up (ties decided on the code's own L)."""
    assert disc.step_ratio == pytest.approx(ratio_ref, rel=1e-11)
    assert disc.steps == max(1, math.floor(disc.step_ratio + 0.5))
    assert abs(disc.steps - ratio_ref) <= 0.5 + 1e-9 or disc.steps == 1


@settings(max_examples=25, deadline=None)
@given(points, points, st.floats(0.02, 2.0), st.floats(0.05, 0.9), rotvecs, rotvecs)
def test_random_lines(p0, p1, v, ramp_share, w0, w1) -> None:
    L = float(np.linalg.norm(p1 - p0))
    assume(L > 0.01)
    T = ramp_share * L / v                      # ramps fit: v T <= L
    R0, R1 = Rotation.from_rotvec(w0).as_matrix(), Rotation.from_rotvec(w1).as_matrix()
    mv = linear_move(p0, p1, v, rotation_start=R0, rotation_end=R1, ramp_time=T)
    assert mv.length == pytest.approx(L, rel=1e-14) and mv.duration == pytest.approx(L / v + T)
    dt = mv.duration / 157.0
    _check_common(mv, v, dt)
    st_ = mv.at(np.linspace(0, mv.duration, 301))
    # on the line: distance from the line through p0, p1
    e = (p1 - p0) / L
    r = st_.position - p0
    off = r - (r @ e)[:, None] * e
    assert np.max(np.linalg.norm(off, axis=1)) < 1e-12 * max(1.0, np.abs(p0).max(), np.abs(p1).max())
    assert np.allclose(st_.position[[0, -1]], [p0, p1], atol=1e-15 * max(1, np.abs(p1).max()) * 4)
    assert np.allclose(st_.rotation[0], R0, atol=1e-12) and np.allclose(st_.rotation[-1], R1, atol=1e-12)
    # Euclidean spacing v dt on the constant part
    times, ss = mv.sample(dt)
    inside = (times[:-1] >= T) & (times[1:] <= mv.duration - T)
    dist = np.linalg.norm(np.diff(ss.position, axis=0), axis=1)[inside]
    assert np.allclose(dist, v * dt, rtol=1e-9, atol=0)
    # discrete form: N = round(L / (v dt)), equal axis steps
    ddt = L / v / 37.3
    disc = adnia_linear(p0, p1, v, ddt)
    _check_step_count(disc, L / (v * ddt))
    assert np.allclose(np.linalg.norm(np.diff(disc.points, axis=0), axis=1), L / disc.steps, rtol=1e-12)


@settings(max_examples=25, deadline=None)
@given(points, st.floats(0.05, 1.5), rotvecs, st.floats(0.3, 2 * math.pi - 0.3),
       st.floats(0.1, 0.9), st.floats(0.02, 1.0), st.floats(0.05, 0.9), rotvecs, st.booleans())
def test_random_arcs(c, radius, wplane, sweep, via_share, v, ramp_share, w0, carry) -> None:
    E = Rotation.from_rotvec(wplane).as_matrix()           # columns e1, e2, normal of the plane
    ang = np.array([0.0, via_share * sweep, sweep])
    A, B, C = c + radius * (np.cos(ang)[:, None] * E[:, 0] + np.sin(ang)[:, None] * E[:, 1])
    L = radius * sweep
    T = ramp_share * L / v
    R0 = Rotation.from_rotvec(w0).as_matrix()
    kw = dict(orientation="carry") if carry else dict(orientation="geodesic", rotation_end=R0.T)
    mv = arc_move(A, B, C, v, rotation_start=R0, ramp_time=T, **kw)
    centre, normal = _circumcentre(A, B, C)
    assert np.allclose(mv.path.centre, centre, atol=1e-12)
    assert mv.path.radius == pytest.approx(radius, rel=1e-12)
    assert mv.path.sweep == pytest.approx(sweep, rel=1e-11)           # > pi handled
    assert mv.length == pytest.approx(L, rel=1e-11)
    assert abs(mv.path.normal @ E[:, 2] - 1.0) < 1e-12                # travel direction A->B->C
    dt = mv.duration / 211.0
    _check_common(mv, v, dt)
    st_ = mv.at(np.linspace(0, mv.duration, 301))
    r = st_.position - centre
    scale = max(1.0, float(np.abs(c).max()) + radius)
    assert np.max(np.abs(np.linalg.norm(r, axis=1) - radius)) < 1e-12 * scale     # on the circle
    assert np.max(np.abs(r @ normal)) < 1e-12 * scale                              # in its plane
    assert np.allclose(st_.position[-1], C, atol=1e-12 * scale)
    # centripetal acceleration v^2/R on the constant-speed part (physics)
    tc = np.linspace(T, mv.duration - T, 50)
    acc = mv.at(tc).acceleration
    assert np.allclose(np.linalg.norm(acc, axis=1), v**2 / radius, rtol=1e-9)
    if carry:
        # constant work/travel angles: tool frame fixed in the (radial, tangent, normal) frame
        sc = mv.at(tc)
        radial = (sc.position - mv.path.centre) / mv.path.radius
        tangent = np.cross(normal, radial)
        local = np.stack([radial, tangent, np.broadcast_to(normal, radial.shape)], axis=1) @ sc.rotation
        assert np.allclose(local, local[0], atol=1e-12)
    disc = adnia_arc(A, B, C, v, mv.duration / 50)
    _check_step_count(disc, L / (v * mv.duration / 50))


# ---------------------------------------------------------------------------------------------
# circles about an axis, spherical moves, septic ramps, defaults
# ---------------------------------------------------------------------------------------------
def test_full_circle_round_cylinder() -> None:
    """Weld seam round a cylinder: 360 deg about an axis, torch frame carried round."""
    centre, axis = np.array([0.5, 0.0, 0.3]), np.array([0.0, 1.0, 1.0])
    start = np.array([0.6, 0.2, 0.1])
    mv = circle_move(centre, axis, start, 2 * math.pi, 0.02, ramp_time=0.5)
    k = axis / np.linalg.norm(axis)
    foot = centre + ((start - centre) @ k) * k
    R = np.linalg.norm(start - foot)
    assert mv.path.radius == pytest.approx(R, rel=1e-14)
    assert mv.length == pytest.approx(2 * math.pi * R, rel=1e-14)
    st_ = mv.at(np.array([0.0, mv.duration]))
    assert np.allclose(st_.position, start, atol=1e-15)
    assert np.allclose(st_.rotation[1], np.eye(3), atol=1e-14)       # full turn: back to the start frame
    _check_common(mv, 0.02, 0.01)
    # negative sweep turns the other way: mirror of the positive quarter turn about the radial plane
    p_pos = circle_move(centre, axis, start, math.pi / 2, 0.02, ramp_time=0.0).at(1e9).position
    p_neg = circle_move(centre, axis, start, -math.pi / 2, 0.02, ramp_time=0.0).at(1e9).position
    tangent0 = np.cross(k, (start - foot) / R)
    assert (p_pos - foot) @ tangent0 == pytest.approx(R, rel=1e-12)
    assert (p_neg - foot) @ tangent0 == pytest.approx(-R, rel=1e-12)


def test_spherical_move_properties() -> None:
    d = math.radians
    R0 = Rotation.from_rotvec([0.2, -0.3, 0.1]).as_matrix()
    R1 = Rotation.from_rotvec([-0.4, 0.5, 0.9]).as_matrix()
    mv = spherical_move((0.3, d(-20), d(70)), (0.3, d(100), d(20)), 0.1, centre=(0.1, 0.2, 0.3),
                        rotation_start=R0, rotation_end=R1, orientation="spherical", ramp_time=0.2)
    _check_common(mv, 0.1, 0.01)
    p = mv.at(np.linspace(0, mv.duration, 500)).position
    assert np.max(np.abs(np.linalg.norm(p - [0.1, 0.2, 0.3], axis=1) - 0.3)) < 1e-12


def test_septic_ramps_and_default_acceleration() -> None:
    mv = linear_move([0, 0, 0], [0.5, 0.2, -0.1], 0.4, ramp_shape="septic", ramp_time=0.3)
    _check_common(mv, 0.4, 0.005)
    d = linear_move([0, 0, 0], [0.5, 0.2, -0.1], 0.4)      # default ramps: acceleration limit
    t = np.linspace(0, d.duration, 20001)
    a = np.linalg.norm(d.at(t).acceleration, axis=1)
    assert a.max() == pytest.approx(DEFAULT_MAX_ACCELERATION, rel=1e-6)
    limited = linear_move([0, 0, 0], [0.5, 0.2, -0.1], 0.4, max_acceleration=1.5)
    assert np.linalg.norm(limited.at(t * limited.duration / d.duration).acceleration, axis=1).max() \
        == pytest.approx(1.5, rel=1e-6)


def test_constant_speed_share_and_steps() -> None:
    mv = linear_move([0, 0, 0], [0.3, 0.0, 0.4], 0.1, ramp_time=0.5)   # L = 0.5 m
    share = mv.constant_speed_fraction
    assert share.length == pytest.approx((0.5 - 0.1 * 0.5) / 0.5)
    assert share.time == pytest.approx((mv.duration - 1.0) / mv.duration)
    n, ratio = mv.constant_speed_steps(0.01)
    assert ratio == pytest.approx(0.45 / (0.1 * 0.01)) and n == 450


def test_trajectory_protocol_and_shapes() -> None:
    mv = arc_move([1, 0, 0], [0, 1, 0], [-1, 0, 0], 0.5, ramp_time=0.2)
    assert isinstance(mv, Trajectory)
    s = mv.at(0.3)
    assert s.position.shape == (3,) and s.rotation.shape == (3, 3) and np.ndim(s.speed) == 0
    s2 = mv.at(np.zeros((4, 5)))
    assert s2.position.shape == (4, 5, 3) and s2.rotation.shape == (4, 5, 3, 3)
    assert s2.pose().shape == (4, 5, 4, 4)
    before, after = mv.at(-1.0), mv.at(mv.duration + 1.0)     # clamped: at rest at the ends
    assert np.allclose(before.position, [1, 0, 0]) and np.all(before.velocity == 0)
    assert np.allclose(after.position, [-1, 0, 0], atol=1e-15) and np.all(after.velocity == 0)


# ---------------------------------------------------------------------------------------------
# bad input: one-line errors that name the field
# ---------------------------------------------------------------------------------------------
NOT_ORTHO = np.eye(3) + 0.01


@pytest.mark.parametrize("call, exc, field", [
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 0.0), InvalidMoveError, "speed"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], -1.0), InvalidMoveError, "speed"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], float("nan")), InvalidMoveError, "speed"),
    (lambda: linear_move([0, 0, 0], [0, 0, 0], 1.0), CoincidentPointsError, "start and end"),
    (lambda: linear_move([0, float("nan"), 0], [1, 0, 0], 1.0), InvalidMoveError, "start"),
    (lambda: linear_move([0, 0], [1, 0, 0], 1.0), InvalidMoveError, "start"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0).sample(0.0), InvalidMoveError, "dt"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0).sample(-1e-3), InvalidMoveError, "dt"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0).sample(1e-12), InvalidMoveError, "dt"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0).at(float("nan")), InvalidMoveError, "t"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0, rotation_start=NOT_ORTHO),
     InvalidOrientationError, "rotation_start"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0, rotation_end=np.diag([1, 1, -1])),
     InvalidOrientationError, "rotation_end"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0, orientation="carry"),
     InvalidOrientationError, "orientation"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0, ramp_time=0.1, max_acceleration=1.0),
     InvalidMoveError, "ramp_time"),
    (lambda: linear_move([0, 0, 0], [0.001, 0, 0], 1.0, ramp_time=0.1), MoveTooShortError, "length"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0, ramp_time=-1), InvalidProfileError, "ramp_time"),
    (lambda: linear_move([0, 0, 0], [1, 0, 0], 1.0, max_acceleration=0), InvalidProfileError,
     "max_acceleration"),
    (lambda: arc_move([0, 0, 0], [1, 1, 1], [2, 2, 2], 1.0), CollinearPointsError, "via"),
    (lambda: arc_move([0, 0, 0], [0, 0, 0], [2, 2, 0], 1.0), CoincidentPointsError, "start and via"),
    (lambda: arc_move([0, 0, 0], [1, 1, 0], [0, 0, 0], 1.0), CoincidentPointsError, "start and end"),
    (lambda: arc_move([1, 0, 0], [0, 1, 0], [-1, 0, 0], 1.0, rotation_end=np.eye(3)),
     InvalidOrientationError, "rotation_end"),
    (lambda: arc_move([1, 0, 0], [0, 1, 0], [-1, 0, 0], 1.0, orientation="slerp"),
     InvalidOrientationError, "orientation"),
    (lambda: circle_move([0, 0, 0], [0, 0, 1], [0, 0, 2], 1.0, 1.0), CoincidentPointsError, "start"),
    (lambda: circle_move([0, 0, 0], [0, 0, 0], [1, 0, 0], 1.0, 1.0), InvalidMoveError, "axis"),
    (lambda: circle_move([0, 0, 0], [0, 0, 1], [1, 0, 0], 0.0, 1.0), InvalidMoveError, "sweep"),
    (lambda: spherical_move((1, 0, 1), (2, 0, 0.5), 1.0), InvalidMoveError, "end"),
    (lambda: spherical_move((-1, 0, 1), (1, 0, 0.5), 1.0), InvalidMoveError, "start"),
    (lambda: spherical_move((1, 0.3, 0.7), (1, 0.3, 0.7), 1.0), CoincidentPointsError, "start and end"),
    (lambda: adnia_linear([0, 0, 0], [1, 0, 0], steps=0), InvalidMoveError, "steps"),
    (lambda: adnia_linear([0, 0, 0], [1, 0, 0]), InvalidMoveError, "steps"),
    (lambda: adnia_linear([0, 0, 0], [1, 0, 0], 1.0, 0.0), InvalidMoveError, "dt"),
    (lambda: adnia_linear([0, 0, 0], [1, 0, 0], 1.0, 1e-3, resolution=-1), InvalidMoveError, "resolution"),
    (lambda: adnia_step_count(1.0, 0.0, 1e-3), InvalidMoveError, "speed"),
])
def test_bad_input(call, exc, field: str) -> None:
    with pytest.raises(exc) as e:
        call()
    msg = str(e.value)
    assert msg.startswith(f"{field}:") or msg.startswith(field), msg
    assert "\n" not in msg
    assert isinstance(e.value, PlannerError)


def test_orientation_error_lists_valid_modes() -> None:
    with pytest.raises(InvalidOrientationError, match="valid: geodesic, carry, spherical"):
        arc_move([1, 0, 0], [0, 1, 0], [-1, 0, 0], 1.0, orientation="slerp")
    with pytest.raises(InvalidOrientationError, match="valid: geodesic, spherical$"):
        linear_move([0, 0, 0], [1, 0, 0], 1.0, orientation="carry")
