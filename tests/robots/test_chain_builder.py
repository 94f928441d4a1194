"""MJCF chain builder: seed 002 RTT (eq. 2.19) and RRRT exercise, seed 004 Table 1 as MDH,
seed 000 Table 1 as screws, random DH/MDH chains against independent matrix products."""

from __future__ import annotations

import numpy as np
import pytest

from sim.core.resources import models_dir
from sim.errors import KinematicsError
from sim.robots.kinematics.closed_form import fk_5r, fk_fanuc6, mdh_transform
from sim.robots.kinematics.dh import DHRow, MDHRow, ScrewAxis
from sim.robots.kinematics.mujoco_fk import MujocoKinematics
from sim.robots.mjcf.builder import (
    RRRT_DIMS,
    RRRT_Q4,
    RTT_L1,
    KinematicChain,
    example_chains,
    fanuc6_chain,
    five_r_chain,
    rrrt_chain,
    rrrt_exercise_q,
    rtt_chain,
)
from sim.robots.registry import get_robot


def _mj(chain: KinematicChain) -> MujocoKinematics:
    return MujocoKinematics.from_xml_string(chain.to_mjcf(), chain.joints)


def _eq_2_19(q: np.ndarray, L1: float) -> np.ndarray:
    """Seed 002 eq. (2.19), transcribed."""
    c1, s1 = np.cos(q[0]), np.sin(q[0])
    return np.array([[c1, -s1, 0, -(q[2] + L1) * s1], [s1, c1, 0, (q[2] + L1) * c1],
                     [0, 0, 1, q[1]], [0, 0, 0, 1]])


@pytest.mark.parametrize("convention", ["screw", "dh"])
def test_rtt_matches_seed002_eq_2_19(convention):
    chain = rtt_chain(convention=convention)
    mj = _mj(chain)
    rng = np.random.default_rng(0)
    for q in np.column_stack([rng.uniform(-3, 3, 20), rng.uniform(0, 1, 20), rng.uniform(-0.5, 0.5, 20)]):
        ref = _eq_2_19(q, RTT_L1)
        np.testing.assert_allclose(chain.fk(q), ref, atol=1e-12)
        np.testing.assert_allclose(mj.fk(q), ref, atol=1e-12)
    model = chain.compile()
    assert [model.joint(i).type for i in range(3)] == [3, 2, 2]  # hinge, slide, slide


def test_rrrt_exercise_trajectory():
    """Seed 002 exercise (c): q1 = 0, q2 = -t pi/20, q3 = t pi/20, q4 = 10 over t in [0, 10] s.

    Built model (MuJoCo) == builder product == the hand-derived position of the (assumed)
    geometry; with q2 + q3 = 0 the forearm stays horizontal while the tool point travels a
    quarter circle of radius L2 around the J2 axis.
    """
    chain = rrrt_chain()
    mj = _mj(chain)
    t = np.linspace(0.0, 10.0, 41)
    Q = rrrt_exercise_q(t)
    H, L2, L3 = RRRT_DIMS["H"], RRRT_DIMS["L2"], RRRT_DIMS["L3"]
    T_mj = mj.fk(Q)
    for q, T in zip(Q, T_mj):
        np.testing.assert_allclose(T, chain.fk(q), atol=1e-12)
        c1, s1 = np.cos(q[0]), np.sin(q[0])
        r = L2 * np.cos(q[1]) + (L3 + q[3]) * np.cos(q[1] + q[2])
        z = H - L2 * np.sin(q[1]) - (L3 + q[3]) * np.sin(q[1] + q[2])
        np.testing.assert_allclose(T[:3, 3], [c1 * r, s1 * r, z], atol=1e-12)
        np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-12)  # q2 + q3 = 0
    np.testing.assert_allclose(T_mj[0, :3, 3], [L2 + L3 + RRRT_Q4, 0, H], atol=1e-12)
    np.testing.assert_allclose(T_mj[-1, :3, 3], [L3 + RRRT_Q4, 0, H + L2], atol=1e-12)


def test_seed004_table1_as_mdh_equals_fk_fanuc6():
    dims = get_robot("lrmate200ic5l").dims
    for tool in (0.0, 0.12):
        chain = fanuc6_chain(dims, tool)
        mj = _mj(chain)
        for q in np.random.default_rng(1).uniform(-3, 3, size=(20, 6)):
            R, p = fk_fanuc6(q, dims, tool)
            for T in (chain.fk(q), mj.fk(q)):
                np.testing.assert_allclose(T[:3, :3], R, atol=1e-12)
                np.testing.assert_allclose(T[:3, 3], p, atol=1e-12)


@pytest.mark.parametrize("name", ["lrmate100ib", "robot_5r"])
def test_seed000_table1_as_screws_equals_fk_5r(name):
    dims = get_robot(name).dims
    chain = five_r_chain(dims)
    mj = _mj(chain)
    for q in np.random.default_rng(2).uniform(-3, 3, size=(20, 5)):
        R, p = fk_5r(q, dims)
        for T in (chain.fk(q), mj.fk(q)):
            np.testing.assert_allclose(T[:3, :3], R, atol=1e-12)
            np.testing.assert_allclose(T[:3, 3], p, atol=1e-12)


def _rot(axis: str, a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    T = np.eye(4)
    if axis == "x":
        T[1:3, 1:3] = [[c, -s], [s, c]]
    else:
        T[0:2, 0:2] = [[c, -s], [s, c]]
    return T


def _trans(axis: str, d: float) -> np.ndarray:
    T = np.eye(4)
    T["xyz".index(axis), 3] = d
    return T


def test_random_dh_and_mdh_chains():
    """Random 6-joint chains, mixed R/P: builder FK and MuJoCo FK equal independent products
    (standard DH ``Rz Tz Tx Rx``; MDH: seed 004 eq. 1 via ``closed_form.mdh_transform``)."""
    rng = np.random.default_rng(4)
    for _ in range(5):
        kinds = rng.choice(["R", "P"], size=6)
        par = rng.uniform(-1, 1, size=(6, 4))
        dh = KinematicChain("dh", [DHRow(*p, joint=k) for p, k in zip(par, kinds)])
        mdh = KinematicChain("mdh", [MDHRow(*p, joint=k) for p, k in zip(par, kinds)])
        tool = _trans("z", 0.1) @ _rot("x", 0.3)
        dh.tool, mdh.tool = tool, tool
        for q in rng.uniform(-1, 1, size=(5, 6)):
            T_dh, T_mdh = np.eye(4), np.eye(4)
            for (theta, d, a, alpha), k, qi in zip(par, kinds, q):
                th, dd = (theta + qi, d) if k == "R" else (theta, d + qi)
                T_dh = T_dh @ _rot("z", th) @ _trans("z", dd) @ _trans("x", a) @ _rot("x", alpha)
                # MDH row (alpha, d, theta, r) = par columns in that order
                al, d_m, th_m, r_m = theta, d, a, alpha
                th_m, r_m = (th_m + qi, r_m) if k == "R" else (th_m, r_m + qi)
                T_mdh = T_mdh @ mdh_transform(al, d_m, th_m, r_m)
            np.testing.assert_allclose(dh.fk(q), T_dh @ tool, atol=1e-12)
            np.testing.assert_allclose(_mj(dh).fk(q), T_dh @ tool, atol=1e-12)
            np.testing.assert_allclose(mdh.fk(q), T_mdh @ tool, atol=1e-12)
            np.testing.assert_allclose(_mj(mdh).fk(q), T_mdh @ tool, atol=1e-12)


def test_screw_chain_with_tilted_axes_and_rotated_home():
    rng = np.random.default_rng(5)
    axes = rng.normal(size=(4, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    rows = [ScrewAxis(tuple(k), tuple(rng.uniform(-0.5, 0.5, 3)), joint=j)
            for k, j in zip(axes, "RPRR")]
    M = _rot("x", 0.4) @ _rot("z", -0.3)
    M[:3, 3] = [0.3, 0.2, 0.9]
    chain = KinematicChain("screw", rows, tool=M)
    mj = _mj(chain)
    for q in rng.uniform(-1, 1, size=(10, 4)):
        np.testing.assert_allclose(mj.fk(q), chain.fk(q), atol=1e-12)


def test_shipped_examples_are_up_to_date():
    """models/examples/*.xml are what `python -m sim.robots.mjcf.builder` generates."""
    for name, chain in example_chains().items():
        text = (models_dir() / "examples" / f"{name}.xml").read_text()
        assert chain.to_mjcf() in text
        assert text.startswith("<!-- generated")


def test_bad_tables():
    with pytest.raises(KinematicsError, match="convention"):
        KinematicChain("euler", [])
    with pytest.raises(KinematicsError, match="row 1"):
        KinematicChain("dh", [MDHRow(0, 0, 0, 0)])
    with pytest.raises(KinematicsError, match="joint type"):
        KinematicChain("mdh", [MDHRow(0, 0, 0, 0, joint="X")])
    with pytest.raises(KinematicsError, match="joint values"):
        rtt_chain().fk([0.0, 0.1])
