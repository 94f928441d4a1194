"""The offset-wrist (UR-type) closed form (sim/robots/kinematics/offset_wrist.py), as specified
by issue 29: arms with J2, J3, J4 parallel and J5, J6 meeting off them are detected from their
chain (any DH signs, base frame, zero offsets) and solved in closed form, up to 8 solutions,
each reproducing the pose, one of them the joint vector the pose came from.

The oracle is this file's own standard-DH product (:func:`dh_pose`, the textbook matrix
entries) with a base transform in front: the code under test builds its chain from the same
numbers but never sees this product. A copy of the solver with a planted fault must fail the
same checks (:func:`test_a_planted_fault_is_caught`).
"""

from __future__ import annotations

import dataclasses
import math
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from sim.errors import KinematicsError, UnreachableError
from sim.robots.arm import arm_from_chain
from sim.robots.families.chain_family import ChainFamily
from sim.robots.kinematics import offset_wrist
from sim.robots.kinematics.chain import chain_from_dh
from sim.robots.kinematics.ik import ik_path
from sim.robots.kinematics.model import KinematicModel

#: The published tables (Universal Robots' DH parameters page), [a m, alpha rad, d m, offset].
H = math.pi / 2
UR5 = np.array([[0.0, H, 0.089159, 0.0], [-0.425, 0.0, 0.0, 0.0], [-0.39225, 0.0, 0.0, 0.0],
                [0.0, H, 0.10915, 0.0], [0.0, -H, 0.09465, 0.0], [0.0, 0.0, 0.0823, 0.0]])
UR10 = np.array([[0.0, H, 0.1273, 0.0], [-0.612, 0.0, 0.0, 0.0], [-0.5723, 0.0, 0.0, 0.0],
                 [0.0, H, 0.163941, 0.0], [0.0, -H, 0.1157, 0.0], [0.0, 0.0, 0.0922, 0.0]])


# ---------------------------------------------------------------------------- the oracle
def dh_pose(rows: np.ndarray, q: np.ndarray, base: np.ndarray | None = None) -> np.ndarray:
    """``base @ prod_i Rz(q_i + offset_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``, entry by entry."""
    T = np.eye(4) if base is None else np.array(base, dtype=float)
    for (a, alpha, d, off), qi in zip(rows, q, strict=True):
        th = qi + off
        ct, st_, ca, sa = math.cos(th), math.sin(th), math.cos(alpha), math.sin(alpha)
        T = T @ np.array([[ct, -st_ * ca, st_ * sa, a * ct],
                          [st_, ct * ca, -ct * sa, a * st_],
                          [0.0, sa, ca, d],
                          [0.0, 0.0, 0.0, 1.0]])
    return T


def with_base(chain, base: np.ndarray):
    """The chain with ``base`` in front of its first joint."""
    origins = chain.origins.copy()
    origins[0] = base @ origins[0]
    return dataclasses.replace(chain, origins=origins)


def rot_zyx(yaw: float, pitch: float, roll: float) -> np.ndarray:
    cy, sy, cp, sp, cr, sr = (math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch),
                              math.cos(roll), math.sin(roll))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


# ---------------------------------------------------------------------------- generation
def _length(lo: float, hi: float, zero_ok: bool = True):
    mag = st.floats(lo, hi, allow_nan=False)
    signed = st.tuples(mag, st.sampled_from([-1.0, 1.0])).map(lambda t: t[0] * t[1])
    return st.one_of(st.just(0.0), signed) if zero_ok else signed


@st.composite
def ur_tables(draw) -> np.ndarray:
    """A UR-type DH table: J1 perpendicular to J2 (alpha1 = +-90, any a1, d1), J2-J4 parallel
    (alpha2 = alpha3 = 0, a2, a3 not 0), J5 perpendicular to J4 and J6 (alpha4, alpha5 =
    +-90, a4 = a5 = 0: J4/J5 and J5/J6 meet), any flange (a6, alpha6, d6), any offsets."""
    sign = st.sampled_from([-1.0, 1.0])
    off = st.floats(-math.pi, math.pi, allow_nan=False)
    a1 = draw(_length(0.01, 0.3))
    a2, a3 = draw(_length(0.1, 0.7, zero_ok=False)), draw(_length(0.1, 0.7, zero_ok=False))
    d1, d2, d3, d4 = (draw(_length(0.01, 0.3)) for _ in range(4))
    d5, d6 = draw(_length(0.03, 0.2)), draw(_length(0.0, 0.2))
    a6, al6 = draw(_length(0.0, 0.1)), draw(st.floats(-math.pi, math.pi, allow_nan=False))
    return np.array([[a1, draw(sign) * H, d1, draw(off)], [a2, 0.0, d2, draw(off)],
                     [a3, 0.0, d3, draw(off)], [0.0, draw(sign) * H, d4, draw(off)],
                     [0.0, draw(sign) * H, d5, draw(off)], [a6, al6, d6, draw(off)]])


@st.composite
def bases(draw) -> np.ndarray:
    ang = st.floats(-math.pi, math.pi, allow_nan=False)
    pos = st.floats(-1.0, 1.0, allow_nan=False)
    B = np.eye(4)
    B[:3, :3] = rot_zyx(draw(ang), draw(ang), draw(ang))
    B[:3, 3] = [draw(pos), draw(pos), draw(pos)]
    return B


joints = st.lists(st.floats(-math.pi, math.pi, allow_nan=False), min_size=6, max_size=6).map(
    np.array)


def solve_all(rows: np.ndarray, base: np.ndarray, q: np.ndarray, inverse=offset_wrist.inverse,
              free: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pose of ``q`` by the oracle, and the solver's solutions (NaN rows dropped) with
    ``free`` for the joints a singular pose leaves undetermined."""
    chain = with_base(chain_from_dh(rows), base)
    arm = arm_from_chain(chain)
    assert arm.solver == "offset_wrist", arm.why_numeric
    assert arm.offset is not None
    T = dh_pose(rows, q, base)
    S = inverse(arm.offset, T, free)
    return T, S[~np.isnan(S).any(axis=1)], chain


def errors(rows: np.ndarray, base: np.ndarray, q: np.ndarray, S: np.ndarray, T: np.ndarray
           ) -> tuple[float, float]:
    """Worst pose error of the solutions (oracle FK) and the nearest one's distance to ``q``
    modulo 2 pi."""
    pose = max((float(np.abs(dh_pose(rows, s, base) - T).max()) for s in S), default=np.inf)
    near = min((float(np.abs(np.angle(np.exp(1j * (s - q)))).max()) for s in S),
               default=np.inf)
    return pose, near


# ---------------------------------------------------------------------------- the solver
@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(rows=ur_tables(), base=bases(), q=joints)
def test_every_solution_reproduces_the_pose_and_one_is_the_joint_vector(rows, base, q):
    """Generated arms and joints (hypothesis favours the singular ones: zero lengths, zero
    joints). The joints a singular pose leaves free take ``q``'s values, so one solution is
    ``q`` itself; that the free values change nothing elsewhere: the next test. Left out: the
    arm folded onto its shoulder (``|a2| = |a3|`` and ``theta3 = pi``: the wrist on J2's axis,
    where J2 is free as well and the solver keeps its own value; found by hypothesis; every
    solution still reproduces the pose, checked by the first assertion's twin below)."""
    folded = (abs(abs(rows[1, 0]) - abs(rows[2, 0])) < 1e-9
              and abs(math.sin(q[2] + rows[2, 3])) < 1e-9)
    if folded:
        T, S, _ = solve_all(rows, base, q, free=q)
        assert len(S) >= 1 and errors(rows, base, q, S, T)[0] < 1e-9
        return
    T, S, _ = solve_all(rows, base, q, free=q)
    assert 1 <= len(S) <= 8
    pose, near = errors(rows, base, q, S, T)
    assert pose < 1e-9, pose
    assert near < 1e-5, near  # the arccos of a double root (a singular q) loses digits


def test_generic_poses_need_no_free_values():
    """Random arms and joints (never singular): with the free values at zero the solutions
    still hold the joint vector and reproduce the pose."""
    rng = np.random.default_rng(7)
    for k in range(40):
        rows = _random_table(rng)
        base = np.eye(4)
        base[:3, :3] = rot_zyx(*rng.uniform(-math.pi, math.pi, 3))
        base[:3, 3] = rng.uniform(-1.0, 1.0, 3)
        q = rng.uniform(-math.pi, math.pi, 6)
        T, S, _ = solve_all(rows, base, q)
        pose, near = errors(rows, base, q, S, T)
        assert pose < 1e-9 and near < 1e-7, (k, pose, near)


def _random_table(rng: np.random.Generator) -> np.ndarray:
    """A UR-type table as :func:`ur_tables` draws them, from numpy's generator."""
    sgn = lambda: float(rng.choice([-1.0, 1.0]))  # noqa: E731
    ln = lambda lo, hi: sgn() * float(rng.uniform(lo, hi))  # noqa: E731
    off = rng.uniform(-math.pi, math.pi, 6)
    return np.array([[ln(0.0, 0.3), sgn() * H, ln(0.0, 0.3), off[0]],
                     [ln(0.1, 0.7), 0.0, ln(0.0, 0.3), off[1]],
                     [ln(0.1, 0.7), 0.0, ln(0.0, 0.3), off[2]],
                     [0.0, sgn() * H, ln(0.0, 0.3), off[3]],
                     [0.0, sgn() * H, ln(0.03, 0.2), off[4]],
                     [ln(0.0, 0.1), rng.uniform(-math.pi, math.pi), ln(0.0, 0.2), off[5]]])


def test_the_published_ur5_and_ur10_tables_are_detected_and_solved():
    rng = np.random.default_rng(29)
    for rows in (UR5, UR10):
        arm = arm_from_chain(chain_from_dh(rows))
        assert arm.solver == "offset_wrist"
        for q in rng.uniform(-math.pi, math.pi, (20, 6)):
            T = dh_pose(rows, q)
            sols = arm.ik(T)
            assert all(np.abs(dh_pose(rows, s.q) - T).max() < 1e-9 for s in sols)
            assert min(np.abs(np.angle(np.exp(1j * (s.q - q)))).max() for s in sols) < 1e-7
            # generic poses: 8 distinct branches, each labelled once
            labels = {s.branch for s in sols}
            assert labels <= set(offset_wrist.LABELS) and len(labels) == len(
                arm.labelled_branches(T))


def test_whole_turn_variants_inside_ur_ranges():
    """+-360 deg on J1, J2, J4-J6 and +-180 on J3: each branch comes with every variant whose
    joints stay inside (2 per wide joint away from 0), all in the ranges, none twice."""
    lo = np.radians([-360, -360, -180, -360, -360, -360])
    chain = chain_from_dh(UR5, lower=lo, upper=-lo)
    arm = arm_from_chain(chain)
    q = np.array([0.3, -1.2, 1.4, -0.7, 1.1, 2.0])
    sols = arm.ik(dh_pose(UR5, q))
    branches = arm.labelled_branches(dh_pose(UR5, q))
    assert len(sols) == 32 * len(branches)
    Q = np.array([s.q for s in sols])
    assert np.all((Q >= lo - 1e-12) & (Q <= -lo + 1e-12))
    assert len({tuple(np.round(x, 9)) for x in Q}) == len(Q)
    assert any(np.abs(x - q).max() < 1e-9 for x in Q)


@pytest.mark.parametrize("row, col, value, why", [
    (2, 1, math.radians(10.0), "J4 is not parallel"),        # J4 tilted off J2-J3
    (1, 1, math.radians(-20.0), "J3 is not parallel"),       # J3 tilted off J2
    (4, 0, 0.05, "J5 and J6 do not meet"),                    # a5 != 0
    (4, 1, math.radians(60.0), "not perpendicular"),          # J6 oblique to J5
])
def test_an_arm_that_is_not_ur_type_is_not_detected(row, col, value, why):
    rows = UR5.copy()
    rows[row, col] = value
    arm = arm_from_chain(chain_from_dh(rows))
    assert arm.solver == "numeric"
    assert why in arm.why_numeric


@pytest.mark.parametrize("row, col, value, joints", [
    (3, 1, 0.0, "J4 and J5"),                                 # J5 along J4: one line
    (1, 0, 0.0, "J2 and J3"),                                 # a2 = 0: J2, J3 one axis
])
def test_an_arm_with_two_joints_on_one_axis_line_is_refused(row, col, value, joints):
    """Two neighbouring joints on one axis line are one joint twice: refused (they fell back
    to the numeric solver before, which picks one split of a turn among infinitely many)."""
    rows = UR5.copy()
    rows[row, col] = value
    with pytest.raises(KinematicsError, match=f"{joints} turn about one axis line"):
        arm_from_chain(chain_from_dh(rows))


def test_an_opw_arm_stays_opw():
    """A spherical-wrist arm (KR 6-like DH) keeps the OPW closed form."""
    rows = np.array([[0.025, -H, 0.4, 0.0], [0.455, 0.0, 0.0, 0.0], [0.035, -H, 0.0, 0.0],
                     [0.0, H, 0.42, 0.0], [0.0, -H, 0.0, 0.0], [0.0, 0.0, 0.08, 0.0]])
    assert arm_from_chain(chain_from_dh(rows)).solver == "opw"


def test_singular_poses_give_fewer_solutions_without_exceptions():
    arm = arm_from_chain(chain_from_dh(UR5))
    assert arm.offset is not None
    # wrist singular (q5 = 0): J6 takes q6_free, q4 absorbs the rest; the pose is kept
    q = np.array([0.4, -1.0, 1.2, 0.3, 0.0, 0.9])
    T = dh_pose(UR5, q)
    S = offset_wrist.inverse(arm.offset, T, free=np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.9]))
    S = S[~np.isnan(S).any(axis=1)]
    assert len(S) >= 1 and all(np.abs(dh_pose(UR5, s) - T).max() < 1e-9 for s in S)
    assert min(np.abs(np.angle(np.exp(1j * (s - q)))).max() for s in S) < 1e-7
    # out of reach: no solution, no exception
    far = np.eye(4)
    far[:3, 3] = [2.0, 0.0, 0.3]
    assert np.isnan(offset_wrist.inverse(arm.offset, far)).all()
    assert arm.ik(far) == []
    # the J5/J6 point on the J1 axis: the shoulder equation has no root
    on_axis = np.eye(4)
    on_axis[:3, 3] = [0.0, 0.0, 0.3 + 0.0823]
    assert np.isnan(offset_wrist.inverse(arm.offset, on_axis)).all()


def test_singular_factors_are_the_factors_of_det_j():
    """Their product is det J (the oracle's Jacobian by central differences of its own DH
    product) up to one constant (a2 a3 for the UR5)."""
    arm = arm_from_chain(chain_from_dh(UR5))
    assert arm.offset is not None
    rng = np.random.default_rng(5)
    Q = rng.uniform(-math.pi, math.pi, (12, 6))
    f = offset_wrist.singular_factors(arm.offset, Q)
    ratio = []
    for q, w, e, s in zip(Q, f["wrist"], f["elbow"], f["shoulder"], strict=True):
        J = np.empty((6, 6))
        for i in range(6):
            dq = np.zeros(6)
            dq[i] = 1e-6
            Tp, Tm = dh_pose(UR5, q + dq), dh_pose(UR5, q - dq)
            J[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / 2e-6
            dR = (Tp[:3, :3] - Tm[:3, :3]) / 2e-6 @ dh_pose(UR5, q)[:3, :3].T
            J[3:, i] = [dR[2, 1], dR[0, 2], dR[1, 0]]
        ratio.append(abs(np.linalg.det(J)) / abs(w * e * s))
    np.testing.assert_allclose(ratio, 0.425 * 0.39225, rtol=1e-5)


# ---------------------------------------------------------------------------- planted faults
FAULTS = [
    ("q4 = s[2] * (phi - s[0] * q2 - s[1] * q3)", "q4 = s[2] * (phi - s[0] * q2 + s[1] * q3)"),
    (", float(u @ z1))", ", -float(u @ z1))"),
    ("x = p[5] + R6.T @ (x - p[5])", "x = p[5] + R6 @ (x - p[5])"),
]


@pytest.mark.parametrize("good, bad", FAULTS)
def test_a_planted_fault_is_caught(good, bad):
    """A copy of the solver with one sign or transpose flipped fails the oracle's checks on
    the first of a few fixed random arms and joint vectors."""
    src = Path(offset_wrist.__file__).read_text(encoding="utf-8")
    assert good in src
    mutant = types.ModuleType("offset_wrist_mutant")
    sys.modules[mutant.__name__] = mutant
    try:
        exec(compile(src.replace(good, bad), "offset_wrist_mutant", "exec"), mutant.__dict__)
        rng = np.random.default_rng(1)
        caught = False
        for _ in range(5):
            rows = UR5.copy()
            rows[:, 3] = rng.uniform(-math.pi, math.pi, 6)
            q = rng.uniform(-math.pi, math.pi, 6)
            T, S, _ = solve_all(rows, np.eye(4), q, inverse=mutant.inverse)
            pose, near = errors(rows, np.eye(4), q, S, T)
            if not (pose < 1e-9 and near < 1e-6):
                caught = True
                break
        assert caught, f"fault {bad!r} not caught"
    finally:
        del sys.modules[mutant.__name__]


# ---------------------------------------------------------------------------- paths
def oracle_factors(q: np.ndarray) -> tuple[float, float, float]:
    """The UR5's singular measures from the oracle's own frames: |sin| of the angle between
    J6 and J2 (wrist), |sin q3| (elbow: upper arm and forearm aligned), the J5/J6 point's
    distance from the plane of the J1 axis and the J2 axis direction (shoulder, m)."""
    z = [dh_pose(UR5[:i], q[:i])[:3, 2] for i in range(6)]
    W = dh_pose(UR5[:5], q[:5])[:3, 3]
    n = np.cross(z[0], z[1])
    return (float(np.linalg.norm(np.cross(z[5], z[1]))), abs(math.sin(q[2])),
            abs(float(W @ n)) / float(np.linalg.norm(n)))


@settings(max_examples=12, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(q0=joints, direction=st.tuples(*(st.floats(-1.0, 1.0, allow_nan=False),) * 3),
       length=st.floats(0.05, 0.3, allow_nan=False))
def test_a_line_solved_along_the_path_is_continuous_and_on_the_line(q0, direction, length):
    """A straight line of constant orientation from a pose of the UR5 (61 samples):
    ``ik_path`` (each sample's branches, the one nearest the sample before) puts every sample
    on the line (oracle FK) and keeps one branch (no joint moves more than 0.1 rad between
    samples) unless the branch ends: then the sample before lies near a singularity of the
    oracle's measures or a joint near its range's end."""
    d = np.asarray(direction)
    assume(np.linalg.norm(d) > 0.1)
    d = d / np.linalg.norm(d)
    lo = np.radians([-360, -360, -180, -360, -360, -360])
    chain = chain_from_dh(UR5, lower=lo, upper=-lo)
    q0 = np.clip(q0, lo, -lo)
    assume(min(np.array(oracle_factors(q0)) / [1.0, 1.0, 0.1]) > 0.3)
    fam = ChainFamily(arm_from_chain(chain))
    model = KinematicModel("ur5", fam, lower=lo, upper=-lo, max_speed=np.full(6, math.pi))
    T0 = dh_pose(UR5, q0)
    s = np.linspace(0.0, length, 61)
    poses = np.repeat(T0[None], len(s), axis=0)
    poses[:, :3, 3] += s[:, None] * d
    try:
        Q = ik_path(model, poses, q_start=q0)
    except UnreachableError:  # the line left the workspace or the ranges
        assume(False)
    assert np.abs(Q[0] - q0).max() < 1e-7
    for q, T in zip(Q, poses, strict=True):
        assert np.abs(dh_pose(UR5, q) - T).max() < 1e-9
    steps = np.abs(np.diff(Q, axis=0)).max(axis=1)
    for k in np.flatnonzero(steps >= 0.1):
        w, e, sh = oracle_factors(Q[k])
        near_limit = np.min(np.minimum(Q[k] - lo, -lo - Q[k])) < 0.3
        assert min(w, e, sh / 0.5) < 0.3 or near_limit, (k, steps[k], (w, e, sh))
