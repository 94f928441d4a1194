"""Kinematic families as objects: each robot's family agrees with the seeds' closed forms,
finite differences, its own inverse and the factored determinant of its Jacobian."""

from __future__ import annotations

import numpy as np
import pytest

from sim.robots.closed_form import fk_5r, fk_fanuc6
from sim.robots.families import Fanuc6, FiveR, KinematicFamily
from sim.robots.registry import ROBOTS, joint_ranges

ALL_ROBOTS = sorted(ROBOTS)
#: The robots of the seeds' kinematic families (the arms given as data, ChainFamily, are
#: checked against their URDF and DH products in tests/test_robots_as_data.py).
SEED_ROBOTS = [n for n in ALL_ROBOTS if isinstance(ROBOTS[n].family, (FiveR, Fanuc6))]


def _random_q(name: str, n: int = 50, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    r = np.clip(joint_ranges(ROBOTS[name]), -np.pi, np.pi)
    return rng.uniform(r[:, 0], r[:, 1], size=(n, r.shape[0]))


def _seed_fk(family: KinematicFamily, q: np.ndarray) -> np.ndarray:
    """The seeds' printed equations, independent of the family's product of transforms."""
    if isinstance(family, FiveR):
        R, p = fk_5r(q, family.dims)
    else:
        assert isinstance(family, Fanuc6)
        R, p = fk_fanuc6(q, family.dims, tool_length=family.tool_length)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_spec_holds_a_family_object(name):
    family = ROBOTS[name].family
    assert isinstance(family, KinematicFamily)
    assert family.n_joints == ROBOTS[name].n_joints
    assert ROBOTS[name].dims == family.dims


@pytest.mark.parametrize("name", SEED_ROBOTS)
@pytest.mark.parametrize("tool", [0.0, 0.145])
def test_fk_equals_the_seed_equations(name, tool):
    base = ROBOTS[name].family
    family = base.with_tool(base.wrist_to_tcp + tool)
    for q in _random_q(name):
        np.testing.assert_allclose(family.fk(q), _seed_fk(family, q), atol=1e-12)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_jacobian_equals_finite_differences(name):
    family = ROBOTS[name].family
    h = 1e-6
    for q in _random_q(name, 10):
        J = family.jacobian(q)
        for i in range(family.n_joints):
            dq = np.zeros(family.n_joints)
            dq[i] = h
            Tp, Tm = family.fk(q + dq), family.fk(q - dq)
            np.testing.assert_allclose(J[:3, i], (Tp[:3, 3] - Tm[:3, 3]) / (2 * h), atol=1e-8)
            dR = Tp[:3, :3] @ Tm[:3, :3].T
            w = np.array([dR[2, 1] - dR[1, 2], dR[0, 2] - dR[2, 0], dR[1, 0] - dR[0, 1]]) / (4 * h)
            np.testing.assert_allclose(J[3:, i], w, atol=1e-8)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_ik_inverts_fk(name):
    family = ROBOTS[name].family
    for q in _random_q(name, 30, seed=1):
        T = family.fk(q)
        sols = family.ik(T, np.zeros(family.n_joints))
        assert sols
        for qs, _branch in sols:
            np.testing.assert_allclose(family.fk(qs), T, atol=1e-9)
        wrapped = [np.abs(np.angle(np.exp(1j * (qs - q)))).max() for qs, _ in sols]
        assert min(wrapped) < 1e-8


@pytest.mark.parametrize("name", SEED_ROBOTS)
def test_singular_factors_factor_the_determinant(name):
    """det(task Jacobian) / (product of the factors) is the same constant everywhere (seed 000:
    d1 l2; seed 004 eq. 22: d3 sqrt(R4^2 + d4^2)), so each factor's zero is a singularity."""
    family = ROBOTS[name].family
    Q = _random_q(name, 200, seed=2)
    det = np.linalg.det(family.task_jacobian(family.jacobian(Q)))
    product = np.prod(list(family.singular_factors(Q).values()), axis=0)
    keep = np.abs(product) > 1e-3
    ratio = det[keep] / product[keep]
    d = family.dims
    expected = d["d1"] * d["l2"] if isinstance(family, FiveR) else d["d3"] * np.hypot(d["R4"],
                                                                                      d["d4"])
    np.testing.assert_allclose(np.abs(ratio), expected, rtol=1e-9)
    assert np.ptp(np.sign(ratio)) == 0


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_with_tool_moves_the_tool_point_along_the_approach_axis(name):
    family = ROBOTS[name].family
    longer = family.with_tool(family.wrist_to_tcp + 0.1)
    assert longer.wrist_to_tcp == pytest.approx(family.wrist_to_tcp + 0.1)
    for q in _random_q(name, 10, seed=3):
        T0, T1 = family.fk(q), longer.fk(q)
        np.testing.assert_allclose(T1[:3, :3], T0[:3, :3], atol=1e-12)
        np.testing.assert_allclose(T1[:3, 3] - T0[:3, 3], 0.1 * T0[:3, family.approach_column],
                                   atol=1e-12)
    # measuring the tool point at q = 0 gives the same arm back
    home = longer.fk(np.zeros(family.n_joints))[:3, 3]
    assert family.tool_from_home_tcp(home).wrist_to_tcp == pytest.approx(longer.wrist_to_tcp,
                                                                         abs=1e-12)
    np.testing.assert_allclose(family.home_approach(),
                               family.fk(np.zeros(family.n_joints))[:3, family.approach_column],
                               atol=1e-12)


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_wrist_centre_stays_within_the_reach_bound(name):
    family = ROBOTS[name].family
    Q = _random_q(name, 500, seed=4)
    _, points, _ = family.joint_frames(Q)
    wrist = points[:, family.wrist_centre_index]
    assert np.linalg.norm(wrist, axis=1).max() <= family.reach() + 1e-12


def test_families_compare_by_value():
    a = FiveR({"l1": 0.1, "d1": 0.2, "l2": 0.3, "l3": 0.4})
    assert a == FiveR({"l1": 0.1, "d1": 0.2, "l2": 0.3, "l3": 0.4})
    assert a != a.with_tool(0.5) and hash(a) == hash(a.with_tool(0.4))
    f = Fanuc6({"d2": 0.075, "d3": 0.4, "d4": 0.075, "R4": 0.41, "R6": 0.08})
    assert f != f.with_tool(0.2) and f.with_tool(0.2).tool_length == pytest.approx(0.12)
