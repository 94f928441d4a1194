"""Analytic inverse kinematics: seed 000 Tables 2-3, FK(IK) round trips, branches, errors."""

from __future__ import annotations

import numpy as np
import pytest

from sim.core.rotations import euler_zyx_to_matrix, make_transform, wrap_to_pi
from sim.errors import KinematicsError, UnreachableError
from sim.robots.families import Fanuc6, FiveR
from sim.robots.kinematics.closed_form import fk_5r, fk_fanuc6
from sim.robots.kinematics.ik import SingularityWarning, ik_5r_seed, ik_path, solve_ik
from sim.robots.kinematics.model import (
    KinematicModel,
    closed_form_model,
    kinematic_model,
)
from sim.robots.registry import ROBOTS, get_robot

ALL_ROBOTS = sorted(ROBOTS)

# Seed 000 Table 2 (mm, deg) and Table 3 (q2, q3, q4 in deg; q1 = q5 = 0).
TABLE2 = [(595.0, 0.0, 250.0, 0.0, 0.0, 0.0), (660.56, 0.0, 5.17, 0.0, 30.0, 0.0),
          (599.91, 0.0, -240.68, 0.0, 60.0, 0.0), (428.36, 0.0, -426.53, 0.0, 90.0, 0.0)]
TABLE3 = [(0.0, 0.0, 0.0), (28.79, -1.2, 2.41), (57.59, -2.41, 4.83), (86.38, -3.62, 7.24)]

# Joint ranges used where a test needs them independent of the MJCF (deg):
# 200iC after seed 004 Table 2 / the FANUC manual, the 5R robots a generous symmetric set.
RANGES_DEG = {
    Fanuc6: [(-170, 170), (-100, 130), (-230, 90), (-190, 190), (-120, 120), (-360, 360)],
    FiveR: [(-160, 160), (-35, 150), (-120, 120), (-180, 180), (-200, 200)],
}


def _model_with_ranges(name: str) -> KinematicModel:
    m = closed_form_model(ROBOTS[name])
    if type(m.family) not in RANGES_DEG:  # an arm given as data: its own ranges
        return m
    r = np.deg2rad(np.array(RANGES_DEG[type(m.family)]))
    m.lower, m.upper = r[:, 0], r[:, 1]
    return m


def _random_in_range(m: KinematicModel, rng: np.random.Generator, n: int) -> np.ndarray:
    lo = np.maximum(m.lower, -np.pi) if m.lower is not None else np.full(m.n_joints, -np.pi)
    hi = np.minimum(m.upper, np.pi) if m.upper is not None else np.full(m.n_joints, np.pi)
    return rng.uniform(lo, hi, size=(n, m.n_joints))


def test_seed000_table3_from_table2():
    """Seed 000: IK (eq. 13-17, eq. 14 re-derived) of Table 2 gives Table 3 within 0.35 deg.

    The configurations are chosen by branch continuity from home (no knowledge of Table 3).
    """
    m = closed_form_model(ROBOTS["lrmate100ib"])
    assert m.dims == {"l1": 0.150, "d1": 0.250, "l2": 0.220, "l3": 0.225}
    poses = [make_transform(euler_zyx_to_matrix(*np.deg2rad(row[3:])), np.array(row[:3]) / 1e3)
             for row in TABLE2]
    Q = np.rad2deg(ik_path(m, poses, respect_limits=False))
    np.testing.assert_allclose(Q[:, [0, 4]], 0.0, atol=1e-9)
    np.testing.assert_allclose(Q[:, 1:4], np.array(TABLE3), atol=0.35)
    # and the seed-style entry point gives the same front/elbow-up solution
    for row, q in zip(TABLE2, Q):
        sols = ik_5r_seed(np.array(row[:3]) / 1e3, np.deg2rad(row[4]), np.deg2rad(row[5]), m.dims)
        assert np.abs(np.rad2deg(sols[0]) - q).max() < 1e-9


def test_seed000_eq14_rederived_against_eq5():
    """The corrected eq. (14): sin q3 from the wrist point equals sin q3 of the source config."""
    m = closed_form_model(ROBOTS["lrmate100ib"])
    d = m.dims
    rng = np.random.default_rng(3)
    for q in rng.uniform(-1.2, 1.2, size=(20, 5)):
        R, p = fk_5r(q, d)
        beta = q[1] + q[2] + q[3]
        r = np.hypot(p[0], p[1]) * np.sign(np.cos(q[0]) * p[0] + np.sin(q[0]) * p[1])
        u = r - d["l1"] - d["l3"] * np.cos(beta)
        v = p[2] + d["l3"] * np.sin(beta)
        s3 = (d["d1"] ** 2 + d["l2"] ** 2 - u**2 - v**2) / (2 * d["d1"] * d["l2"])
        assert s3 == pytest.approx(np.sin(q[2]), abs=1e-12)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_fk_of_ik_round_trip(name):
    """FK(IK(pose)) = pose to 1e-9 for random in-range configurations; the source config is
    among the solutions (modulo 2 pi)."""
    m = _model_with_ranges(name)
    rng = np.random.default_rng(11)
    for q in _random_in_range(m, rng, 60):
        T = m.fk(q)
        sols = solve_ik(m, T, current=np.zeros(m.n_joints))
        assert sols
        for s in sols:
            np.testing.assert_allclose(m.fk(s.q), T, atol=1e-9)
        dist = min(np.abs(wrap_to_pi(s.q - q)).max() for s in sols)
        assert dist < 1e-9
        # the closed forms of the seeds agree with the model's forward kinematics
        if not isinstance(m.family, (FiveR, Fanuc6)):
            continue
        R, p = fk_5r(q, m.dims) if isinstance(m.family, FiveR) else fk_fanuc6(q, m.dims)
        np.testing.assert_allclose(T[:3, :3], R, atol=1e-12)
        np.testing.assert_allclose(T[:3, 3], p, atol=1e-12)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_fk_of_ik_with_mjcf_tcp(name):
    """Same round trip on the model whose tool frame is the MJCF ``tcp`` site."""
    m = kinematic_model(ROBOTS[name])
    rng = np.random.default_rng(5)
    for q in rng.uniform(-1.0, 1.0, size=(20, m.n_joints)):
        T = m.fk(q)
        for s in solve_ik(m, T, q):
            np.testing.assert_allclose(m.fk(s.q), T, atol=1e-9)


def test_200ic_eight_solutions_and_2pi_representations():
    """Seed 004: 8 solutions away from singularities (shoulder x elbow x wrist flip); J4/J6
    also in their theta +- 2 pi representation where the ranges allow it."""
    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    m.lower = m.upper = None  # no ranges: one representation each
    q = np.deg2rad([20.0, 10.0, -20.0, 30.0, 40.0, 50.0])
    sols = solve_ik(m, m.fk(q), q)
    assert len(sols) == 8
    assert {s.branch for s in sols} == {f"{a}/{b}/{c}" for a in ("front", "back")
                                        for b in ("up", "down") for c in ("noflip", "flip")}
    assert np.abs(sols[0].q - q).max() < 1e-9  # the nearest to the current one is first
    ranged = _model_with_ranges("lrmate200ic5l")
    sols_r = solve_ik(ranged, ranged.fk(q), q)
    assert len(sols_r) > 8
    for s in sols_r:
        np.testing.assert_allclose(ranged.fk(s.q), ranged.fk(q), atol=1e-9)
    # J6 (range +-360 deg) has both representations for every branch
    j6 = {(s.branch, round(float(s.q[5]), 9)) for s in sols_r}
    for branch in {s.branch for s in sols_r}:
        vals = sorted(v for b, v in j6 if b == branch)
        assert any(abs(b - a - 2 * np.pi) < 1e-9 for a in vals for b in vals)
    assert q.tolist() == pytest.approx(sols_r[0].q.tolist(), abs=1e-9)


def test_ranking_prefers_within_limits_then_nearest():
    m = _model_with_ranges("lrmate200ic5l")
    q = np.deg2rad([10.0, 20.0, -30.0, 100.0, 50.0, 200.0])
    current = np.deg2rad([0.0, 0.0, 0.0, 170.0, 0.0, 0.0])
    sols = solve_ik(m, m.fk(q), current)
    flags = [s.within_limits for s in sols]
    assert flags == sorted(flags, reverse=True)
    inside = [s for s in sols if s.within_limits]
    weights = 1.0 / m.max_speed
    costs = [np.sqrt(np.sum(((s.q - current) * weights) ** 2)) for s in inside]
    assert costs == sorted(costs)
    assert all(np.all(s.q >= m.lower - 1e-9) and np.all(s.q <= m.upper + 1e-9) for s in inside)


@pytest.mark.parametrize("name", ["lrmate100ib", "robot_5r"])
def test_5r_shoulder_flip_and_elbows(name):
    """5R: both elbows, and the shoulder-flip solution (q1 + pi) where it reaches.

    The target is near the J1 axis with the tool pointing down (beta = 90 deg), its wrist point
    at mid-reach of J2, so that both shoulder branches reach it.
    """
    m = closed_form_model(ROBOTS[name])
    d = m.dims
    mid = (abs(d["d1"] - d["l2"]) + d["d1"] + d["l2"]) / 2
    p = np.array([0.02, 0.01, mid - d["l3"]])
    T = make_transform(euler_zyx_to_matrix(np.arctan2(p[1], p[0]), np.pi / 2, 0.2), p)
    sols = solve_ik(m, T)
    branches = {s.branch for s in sols}
    assert {"front/up", "front/down", "back/up", "back/down"} <= branches
    front = [s for s in sols if s.branch.startswith("front")][0]
    for s in sols:
        np.testing.assert_allclose(m.fk(s.q), T, atol=1e-9)
        if s.branch.startswith("back"):
            assert abs(wrap_to_pi(s.q[0] - front.q[0] - np.pi)) < 1e-9


def test_200ic_unreachable_distance_in_mm():
    """A pose beyond reach: UnreachableError with the wrist centre's distance outside (m)."""
    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    d = m.dims
    p = np.array([1.5, 0.0, 0.3])
    R = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])  # a along +x
    with pytest.raises(UnreachableError) as err:
        solve_ik(m, make_transform(R, p))
    w = p - d["R6"] * R[:, 2]
    expected = np.hypot(w[0] - d["d2"], w[2]) - (d["d3"] + np.hypot(d["R4"], d["d4"]))
    assert err.value.distance == pytest.approx(expected, abs=1e-12)
    assert f"{1e3 * expected:.1f} mm" in str(err.value)


def test_5r_unreachable_and_wrong_orientation():
    m = closed_form_model(ROBOTS["lrmate100ib"])
    d = m.dims
    T = make_transform(np.eye(3), [1.0, 0.0, 0.25])
    with pytest.raises(UnreachableError) as err:
        solve_ik(m, T)
    u, v = 1.0 - d["l1"] - d["l3"], 0.25
    assert err.value.distance == pytest.approx(np.hypot(u, v) - d["d1"] - d["l2"], abs=1e-12)
    # tool x axis out of the arm plane: a 5-axis arm cannot take this orientation
    R = euler_zyx_to_matrix(0.3, 0.2, 0.0)
    with pytest.raises(UnreachableError, match="5-axis"):
        solve_ik(m, make_transform(R, [0.5, 0.0, 0.1]))


def test_wrist_singularity_keeps_j4_and_warns():
    """theta5 = 0 (seed 004 eq. 23): a valid solution with J4 = current J4, and a warning."""
    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    q = np.deg2rad([15.0, 10.0, -25.0, 40.0, 0.0, -20.0])
    current = np.deg2rad([14.0, 9.0, -24.0, 33.0, 2.0, -10.0])
    with pytest.warns(SingularityWarning, match="theta5"):
        sols = solve_ik(m, m.fk(q), current)
    front_up = [s for s in sols if s.branch == "front/up/singular"]
    assert front_up
    s = front_up[0]
    assert s.q[3] == pytest.approx(current[3], abs=1e-12)
    assert s.q[4] == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(m.fk(s.q), m.fk(q), atol=1e-9)
    assert s.q[3] + s.q[5] == pytest.approx(q[3] + q[5], abs=1e-9)


def test_ik_path_branch_continuity_and_error_index():
    m = _model_with_ranges("lrmate200ic5l")
    q0 = np.deg2rad([0.0, 10.0, -10.0, 170.0, 60.0, 300.0])
    q1 = np.deg2rad([40.0, 30.0, -40.0, 185.0, 80.0, 350.0])
    Q = np.linspace(q0, q1, 25)
    poses = m.fk(Q)
    out = ik_path(m, poses, q_start=q0)
    np.testing.assert_allclose(out, Q, atol=1e-8)  # same branch and representation throughout
    assert np.abs(np.diff(out, axis=0)).max() < np.deg2rad(3.0)
    bad = poses.copy()
    bad[7, :3, 3] = [3.0, 0.0, 0.0]
    with pytest.raises(UnreachableError, match=r"path point 7 \(X Y Z = 3000\.0 0\.0 0\.0 mm "
                       r"in frame 0\): .*the wrist centre is [0-9.]+ mm outside the arm's "
                       "reach"):
        ik_path(m, bad, q_start=q0)


def test_ik_path_5r_follows_a_line():
    """A straight weld line for the 5R robot: FK of the path IK reproduces every pose."""
    m = closed_form_model(ROBOTS["robot_5r"])
    P = np.linspace([1.2, -0.3, 0.2], [1.2, 0.4, 0.2], 15)
    poses = [make_transform(euler_zyx_to_matrix(np.arctan2(p[1], p[0]), 0.6, 0.1), p) for p in P]
    Q = ik_path(m, poses, q_start=np.array([0.0, 0.5, -0.2, 0.3, 0.1]), respect_limits=False)
    np.testing.assert_allclose(m.fk(Q), np.array(poses), atol=1e-9)
    assert np.abs(np.diff(Q, axis=0)).max() < 0.2


def test_bad_pose_input():
    m = closed_form_model(ROBOTS["robot_5r"])
    with pytest.raises(KinematicsError):
        solve_ik(m, np.full((4, 4), np.nan))
    with pytest.raises(KinematicsError):
        solve_ik(m, np.eye(3))
    with pytest.raises(KinematicsError):
        ik_path(m, np.eye(4))


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_ik_puts_mujocos_tcp_on_the_pose(name):
    """Replaces test_registry_dims_used (``closed_form_model(spec).dims == spec.dims``, the
    same dict passed through): poses taken from MuJoCo's compile of the shipped MJCF (site
    ``tcp`` in site ``frame0``) at random in-range configurations; every IK solution of the
    robot's kinematic model, set in MuJoCo, puts the tcp on the pose, and one of them is the
    configuration the pose came from. Fails when the model's dimensions, tcp offset or IK
    differ from the MJCF a person edits."""
    import mujoco

    spec = get_robot(name)
    m = kinematic_model(spec)
    mj = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    data = mujoco.MjData(mj)
    f0, tcp = mj.site("frame0").id, mj.site("tcp").id

    def tcp_in_frame0(q: np.ndarray) -> np.ndarray:
        data.qpos[:] = q
        mujoco.mj_kinematics(mj, data)
        R0 = data.site_xmat[f0].reshape(3, 3)
        return make_transform(R0.T @ data.site_xmat[tcp].reshape(3, 3),
                              R0.T @ (data.site_xpos[tcp] - data.site_xpos[f0]))

    lo, hi = np.clip(mj.jnt_range.T, -np.pi, np.pi)
    for q in np.random.default_rng(11).uniform(lo, hi, size=(5, mj.njnt)):
        T = tcp_in_frame0(q)
        sols = solve_ik(m, T, current=q)
        assert sols
        for s in sols:
            np.testing.assert_allclose(tcp_in_frame0(s.q), T, atol=1e-7)
        assert min(np.abs(wrap_to_pi(s.q - q)).max() for s in sols) < 1e-6


def test_5axis_orientation_tolerance_for_typed_angles():
    """5-axis robots: a tool x axis a hair out of the arm plane (rounded, typed-in angles) is
    accepted and solved to the nearest reachable orientation; a clear miss is refused with the
    angle in the message."""
    import numpy as np
    import pytest

    from sim.core.rotations import rot_z
    from sim.errors import UnreachableError
    from sim.robots.kinematics.ik import PLANE_TOL, solve_ik
    from sim.robots.kinematics.model import closed_form_model

    kin = closed_form_model(ROBOTS["lrmate100ib"])
    q = np.deg2rad([20.0, 30.0, -10.0, 15.0, 5.0])
    T = np.asarray(kin.fk(q), dtype=float)
    for angle, ok in ((0.5 * np.degrees(np.arcsin(PLANE_TOL)), True), (1.0, False)):
        Tt = T.copy()
        Tt[:3, :3] = rot_z(np.deg2rad(angle)) @ T[:3, :3]  # turn the tool out of the plane
        if ok:
            sol = solve_ik(kin, Tt, current=q)[0]
            np.testing.assert_allclose(sol.q, q, atol=np.deg2rad(0.05))
        else:
            with pytest.raises(UnreachableError, match="deg out of the vertical plane"):
                solve_ik(kin, Tt, current=q)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_ik_path_takes_the_solution_solve_ik_ranks_first(name):
    """``ik_path`` picks each point's solution in O(n) per branch (each joint's nearest
    in-range turn on its own); the oracle is :func:`solve_ik`'s solutions, every whole-turn
    representation enumerated, the nearest taken (inside the ranges where they are
    respected): the same joints at every point of generated paths (random configurations,
    random starting configurations, with and without the ranges)."""
    rng = np.random.default_rng(sum(map(ord, name)))
    for model in (_model_with_ranges(name), closed_form_model(ROBOTS[name])):
        Q = _random_in_range(model, rng, 12)
        poses = model.fk(Q)
        for respect in (True, False):
            prev = _random_in_range(model, rng, 1)[0] * 1.5
            got = ik_path(model, poses, q_start=prev, respect_limits=respect)
            for k, T in enumerate(poses):
                sols = solve_ik(model, T, prev)
                if respect:
                    sols = [s for s in sols if s.within_limits]
                want = min(sols, key=lambda s: s.cost).q
                np.testing.assert_allclose(got[k], want, atol=1e-9, err_msg=f"point {k}")
                prev = want


def test_a_chains_batched_forward_kinematics_is_the_dh_product():
    """``Chain.fk_many`` (the path IK's check of the closed form's branches) against the
    standard DH product ``Rz(theta) Tz(d) Tx(a) Rx(alpha)`` written here, on random tables and
    configurations; and row by row equal to ``Chain.fk``."""
    from sim.robots.kinematics.chain import chain_from_dh

    def rz(t):
        c, s = np.cos(t), np.sin(t)
        return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])

    def rx(t):
        c, s = np.cos(t), np.sin(t)
        return np.array([[1.0, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])

    def tr(x, z):
        T = np.eye(4)
        T[0, 3], T[2, 3] = x, z
        return T

    rng = np.random.default_rng(11)
    for _ in range(4):
        rows = np.c_[rng.uniform(-0.5, 0.5, (6, 1)), rng.uniform(-np.pi, np.pi, (6, 1)),
                     rng.uniform(-0.5, 0.5, (6, 1)), rng.uniform(-np.pi, np.pi, (6, 1))]
        chain = chain_from_dh(rows)
        Q = rng.uniform(-np.pi, np.pi, (9, 6))
        got = chain.fk_many(Q)
        for q, T in zip(Q, got):
            want = np.eye(4)
            for (a, alpha, d, off), qi in zip(rows, q):
                want = want @ rz(qi + off) @ tr(0.0, d) @ tr(a, 0.0) @ rx(alpha)
            np.testing.assert_allclose(T, want, atol=1e-12)
            np.testing.assert_allclose(T, chain.fk(q), atol=1e-12)
