"""Jacobians and singularities: finite differences, MuJoCo's mj_jacSite, seed 004 eq. 22-25."""

from __future__ import annotations

import numpy as np
import pytest

from sim.robots.kinematics.jacobian import (
    geometric_jacobian,
    manipulability,
    numeric_jacobian,
    singularity_measures,
    task_jacobian,
    task_jacobian_5r,
)
from sim.robots.kinematics.model import closed_form_model, kinematic_model
from sim.robots.kinematics.mujoco_fk import MujocoKinematics
from sim.robots.registry import ROBOTS

ALL_ROBOTS = sorted(ROBOTS)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_jacobian_matches_finite_differences(name):
    m = closed_form_model(ROBOTS[name])
    rng = np.random.default_rng(1)
    for q in rng.uniform(-2.0, 2.0, size=(10, m.n_joints)):
        np.testing.assert_allclose(geometric_jacobian(m, q), numeric_jacobian(m, q), atol=1e-7)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_jacobian_vectorized_equals_loop(name):
    m = closed_form_model(ROBOTS[name])
    Q = np.random.default_rng(2).uniform(-2.0, 2.0, size=(7, m.n_joints))
    J = geometric_jacobian(m, Q)
    assert J.shape == (7, 6, m.n_joints)
    for k, q in enumerate(Q):
        np.testing.assert_allclose(J[k], geometric_jacobian(m, q), atol=1e-15)
    meas = singularity_measures(m, Q)
    for key, val in meas.items():
        assert val.shape == (7,), key
        single = singularity_measures(m, Q[3])[key]
        assert float(single) == pytest.approx(float(val[3]), rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_mujoco_fk_and_jacobian_match_closed_form(name):
    """MJCF (site tcp in site frame0, mj_jacSite) against seed 000 eq. 5 / seed 004 eq. 6-7."""
    m = kinematic_model(ROBOTS[name])
    mj = MujocoKinematics.for_robot(ROBOTS[name])
    Q = np.random.default_rng(3).uniform(m.lower, m.upper, size=(25, m.n_joints))
    np.testing.assert_allclose(mj.fk(Q), m.fk(Q), atol=1e-12)
    np.testing.assert_allclose(mj.jacobian(Q), geometric_jacobian(m, Q), atol=1e-12)
    # and the MJCF's tcp is the seed's tool frame itself
    np.testing.assert_allclose(m.tcp_offset, np.eye(4), atol=1e-9)


def test_200ic_det_factorization():
    """Seed 004 eq. 22: det J = det(A) det(C); here, at the tcp,
    det J = -d3 (R4 c3 - d4 s3) rho_w s5 (eq. 23-25 factors), checked on random configs."""
    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    d = m.dims
    Q = np.random.default_rng(4).uniform(-3.0, 3.0, size=(40, 6))
    s = singularity_measures(m, Q)
    expected = -d["d3"] * s["elbow"] * np.hypot(d["R4"], d["d4"]) * s["shoulder"] * s["wrist"]
    np.testing.assert_allclose(s["det"], expected, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(s["manipulability"], np.abs(s["det"]), rtol=1e-6, atol=1e-12)


def _det(m, q):
    return float(np.linalg.det(geometric_jacobian(m, np.asarray(q, dtype=float))))


def test_seed004_singular_conditions_give_zero_det():
    """Seed 004: theta5 = 0 (eq. 23), theta3 = atan2(R4, d4) and + pi (eq. 24), eq. 25."""
    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    d = m.dims
    regular = [0.3, 0.4, -0.5, 0.7, 0.6, -0.2]
    scale = abs(_det(m, regular))
    assert scale > 1e-3
    # eq. 23: wrist
    assert abs(_det(m, [0.3, 0.4, -0.5, 0.7, 0.0, -0.2])) < 1e-15
    # eq. 24: elbow, theta3 = atan2(R4, d4) = 1.3899 rad, and + pi = 4.5315 rad
    t3 = np.arctan2(d["R4"], d["d4"])
    assert t3 == pytest.approx(1.3899, abs=1e-4)
    for t in (t3, t3 + np.pi):
        assert abs(_det(m, [0.3, 0.4, t, 0.7, 0.6, -0.2])) < 1e-15
        assert singularity_measures(m, np.array([0.3, 0.4, t, 0.7, 0.6, -0.2]))["sigma_min"] < 1e-12
    # eq. 25 (as printed): d2 + d3 S2 + C2 (R4 C3 - d4 S3) + S2 (R4 S3 + d4 C3) = 0. Solve it
    # for theta2 at a few theta3 (brentq) and evaluate det J at theta2 -> -theta2 (the seed's
    # sign of theta2 in eq. 25 is opposite to eq. 6's; see sim.robots.kinematics.jacobian).
    from scipy.optimize import brentq

    def eq25(t2, t3):
        return (d["d2"] + d["d3"] * np.sin(t2) + np.cos(t2) * (d["R4"] * np.cos(t3) - d["d4"] * np.sin(t3))
                + np.sin(t2) * (d["R4"] * np.sin(t3) + d["d4"] * np.cos(t3)))

    n_checked = 0
    for t3 in np.linspace(-1.0, 1.0, 5):
        grid = np.linspace(-np.pi, np.pi, 721)
        vals = eq25(grid, t3)
        for i in np.nonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]:
            t2 = brentq(eq25, grid[i], grid[i + 1], args=(t3,), xtol=1e-14)
            q = [0.3, -t2, t3, 0.7, 0.6, -0.2]
            assert abs(_det(m, q)) < 1e-12 * max(1.0, scale)
            assert abs(singularity_measures(m, np.array(q))["shoulder"]) < 1e-12
            # the wrist centre is then on the J1 axis
            axes, points, _ = m.joint_frames(np.array(q))
            assert np.hypot(*points[4, :2]) < 1e-12
            n_checked += 1
    assert n_checked >= 5


def test_seed004_eq25_printed_equals_shoulder_factor_with_theta2_negated():
    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    d = m.dims
    Q = np.random.default_rng(5).uniform(-3, 3, size=(30, 6))
    t2, t3 = Q[:, 1], Q[:, 2]
    printed = (d["d2"] + d["d3"] * np.sin(-t2) + np.cos(-t2) * (d["R4"] * np.cos(t3) - d["d4"] * np.sin(t3))
               + np.sin(-t2) * (d["R4"] * np.sin(t3) + d["d4"] * np.cos(t3)))
    np.testing.assert_allclose(singularity_measures(m, Q)["shoulder"], printed, atol=1e-15)


@pytest.mark.parametrize("name", ["lrmate100ib", "robot_5r"])
def test_5r_task_jacobian_det_and_singularities(name):
    """5R: det of the Jacobian of seed 000's task vector (eq. 8) = reach * d1 * l2 * cos q3."""
    m = closed_form_model(ROBOTS[name])
    d = m.dims
    Q = np.random.default_rng(6).uniform(-2, 2, size=(30, 5))
    Jt = task_jacobian_5r(m, Q)
    s = singularity_measures(m, Q)
    np.testing.assert_allclose(np.linalg.det(Jt), s["shoulder"] * d["d1"] * d["l2"] * s["elbow"],
                               rtol=1e-9, atol=1e-15)
    # reach is the tool point's signed distance from the J1 axis (seed 000 eq. 5)
    P = m.fk(Q)[:, :3, 3]
    np.testing.assert_allclose(np.abs(s["shoulder"]), np.hypot(P[:, 0], P[:, 1]), atol=1e-12)
    # rows 4-5 of the task Jacobian by finite differences of the Euler angles (eq. 6)
    from sim.core.rotations import matrix_to_euler_zyx

    q = np.array([0.2, 0.3, -0.4, 0.5, 0.6])
    h = 1e-6
    for i in range(5):
        dq = np.zeros(5)
        dq[i] = h
        e = (matrix_to_euler_zyx(m.fk(q + dq)[:3, :3]) - matrix_to_euler_zyx(m.fk(q - dq)[:3, :3])) / (2 * h)
        np.testing.assert_allclose(task_jacobian(m, q)[3:, i], e[1:], atol=1e-7)
    # elbow stretched: q3 = 90 deg -> singular
    assert abs(np.linalg.det(task_jacobian_5r(m, np.array([0.2, 0.3, np.pi / 2, 0.5, 0.6])))) < 1e-15
    # the 6 x 5 geometric Jacobian never has full row rank: Yoshikawa on it is 0
    assert manipulability(geometric_jacobian(m, q)) < 1e-6 * manipulability(task_jacobian_5r(m, q))


def test_manipulability_matches_singular_values():
    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    J = geometric_jacobian(m, np.random.default_rng(7).uniform(-2, 2, size=(5, 6)))
    sv = np.linalg.svd(J, compute_uv=False)
    np.testing.assert_allclose(manipulability(J), np.prod(sv, axis=-1), rtol=1e-9)


def test_measures_along_a_trajectory_through_the_wrist_singularity():
    """Vectorized measures along a joint path crossing theta5 = 0: the wrist measure changes
    sign, the smallest singular value dips to ~0 exactly there."""
    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    Q = np.linspace([0.1, 0.2, -0.3, 0.4, -0.5, 0.1], [0.2, 0.3, -0.2, 0.5, 0.5, 0.2], 101)
    s = singularity_measures(m, Q)
    i = int(np.argmin(s["sigma_min"]))
    assert i == 50 and abs(Q[i, 4]) < 1e-12
    assert s["sigma_min"][i] < 1e-12 < s["sigma_min"][0]
    assert np.sign(s["wrist"][0]) == -np.sign(s["wrist"][-1])
