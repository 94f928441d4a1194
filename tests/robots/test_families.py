"""Kinematic families as objects: each robot's family agrees with the seeds' closed forms,
finite differences, its own inverse and the factored determinant of its Jacobian."""

from __future__ import annotations

import numpy as np
import pytest

from sim.robots.families import Fanuc6, FiveR, KinematicFamily
from sim.robots.kinematics.closed_form import fk_5r, fk_fanuc6
from sim.robots.registry import ROBOTS, joint_ranges

ALL_ROBOTS = sorted(ROBOTS)
#: The robots of the seeds' kinematic families (the arms given as data, ChainFamily, are
#: checked against their URDF and DH products in tests/robots/test_robots_as_data.py).
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


def _rz(t: float) -> np.ndarray:
    T = np.eye(4)
    T[:2, :2] = [[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]]
    return T


def _ry(t: float) -> np.ndarray:
    T = np.eye(4)
    T[0, 0], T[0, 2], T[2, 0], T[2, 2] = np.cos(t), np.sin(t), -np.sin(t), np.cos(t)
    return T


def _rx(t: float) -> np.ndarray:
    T = np.eye(4)
    T[1:3, 1:3] = [[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]]
    return T


def _move(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = x, y, z
    return T


def _product_fk(family_key: str, dims_mm: dict[str, float], q: np.ndarray) -> np.ndarray:
    """Tool frame as a product of elementary transforms written here from the papers (not
    cellsim's code): the 5R arm of seed 000 (J1 about z, J2..J4 about y, J5 about the tool's
    x; l1, d1, l2, l3), and the 200iC's modified DH table of seed 004 (Khalil-Dombre rows
    ``Rx(alpha) Tx(d) Rz(theta) Tz(r)``, theta2 offset pi/2, the tool R6 along z6)."""
    d = {k: v / 1000.0 for k, v in dims_mm.items()}
    if family_key == "five_r":
        q1, q2, q3, q4, q5 = q
        return (_rz(q1) @ _move(x=d["l1"]) @ _ry(q2) @ _move(z=d["d1"]) @ _ry(q3)
                @ _move(x=d["l2"]) @ _ry(q4) @ _move(x=d["l3"]) @ _rx(q5))
    assert family_key == "fanuc6"
    h = np.pi / 2
    rows = [(0.0, 0.0, q[0], 0.0), (h, d["d2"], h + q[1], 0.0), (0.0, d["d3"], q[2], 0.0),
            (h, d["d4"], q[3], d["R4"]), (-h, 0.0, q[4], 0.0), (h, 0.0, q[5], 0.0)]
    T = np.eye(4)
    for alpha, a, theta, r in rows:
        T = T @ _rx(alpha) @ _move(x=a) @ _rz(theta) @ _move(z=r)
    return T @ _move(z=d["R6"])


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_family_is_the_robot_files_data(name):
    """Replaces test_spec_holds_a_family_object, whose ``spec.dims == family.dims`` restated
    the property (``RobotSpec.dims`` returns ``family.dims``): the family has as many joints as
    the shipped MJCF has hinges and robot.toml has drives, and a seed family's dims and forward
    kinematics are those of robot.toml's ``dims_mm`` put through a product of transforms
    written in this test (so a loader that scaled, dropped or swapped a dimension fails)."""
    import tomllib

    import mujoco

    spec = ROBOTS[name]
    family = spec.family
    toml = tomllib.loads((spec.robot_path.parent / "robot.toml").read_text(encoding="utf-8"))
    assert isinstance(family, KinematicFamily)
    model = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    assert family.n_joints == model.njnt == len(toml["drives"])
    key = toml["kinematics"].get("family")
    if key is None:  # an arm given as data: checked against its URDF in test_robots_as_data
        return
    dims_mm = toml["kinematics"]["dims_mm"]
    assert {k: family.dims[k] for k in dims_mm} == pytest.approx(
        {k: v / 1000.0 for k, v in dims_mm.items()}, abs=1e-15)
    for q in _random_q(name, 20, seed=5):
        np.testing.assert_allclose(family.fk(q), _product_fk(key, dims_mm, q), atol=1e-12)


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
