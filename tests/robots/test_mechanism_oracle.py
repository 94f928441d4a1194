"""The mechanism inverse-dynamics oracle (tests/support/mechanism_oracle.py) is itself right:
it equals pinocchio's RNEA on generated chains of revolute and prismatic axes with payloads
(pinocchio's model built here with its own API), and textbook hand cases (a tilt axis with an
offset point mass, a turntable, a vertical track); its friction law is cellsim's.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from support.mechanism_oracle import (
    OracleAxis,
    OraclePayload,
    chain_from_spec,
    inverse_dynamics,
)

from sim.robots.drive import COULOMB_SPEED, Drive
from sim.robots.mechanisms.spec import AxisSpec, LinkSpec, MechanismSpec

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
G = 9.81

coord = st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False)


def vec3():
    return st.tuples(coord, coord, coord).map(np.array)


@st.composite
def unit_vectors(draw):
    v = draw(vec3())
    assume(np.linalg.norm(v) > 0.2)
    return v / np.linalg.norm(v)


@st.composite
def rotations(draw):
    w, t = draw(unit_vectors()), draw(st.floats(-np.pi, np.pi))
    wx = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    return np.eye(3) + np.sin(t) * wx + (1 - np.cos(t)) * wx @ wx


@st.composite
def inertia_tensors(draw):
    """A physical inertia tensor: principal moments obeying the triangle inequality, turned."""
    a, b = draw(st.floats(0.01, 5.0)), draw(st.floats(0.01, 5.0))
    c = draw(st.floats(abs(a - b) + 1e-3, a + b))
    R = draw(rotations())
    return R @ np.diag([a, b, c]) @ R.T


@st.composite
def chains(draw):
    n = draw(st.integers(1, 4))
    axes = []
    for _ in range(n):
        tensor = draw(inertia_tensors())
        axes.append(OracleAxis(
            draw(st.sampled_from(["revolute", "prismatic"])), draw(vec3()), draw(unit_vectors()),
            draw(st.floats(0.1, 50.0)), draw(vec3()), np.sort(np.linalg.eigvalsh(tensor)),
            armature=draw(st.floats(0.0, 3.0))))
    mount = np.eye(4)
    mount[:3, :3], mount[:3, 3] = draw(rotations()), draw(vec3())
    payload = OraclePayload(draw(st.floats(0.1, 500.0)), draw(vec3()), draw(inertia_tensors()))
    return axes, mount, draw(st.one_of(st.none(), st.just(payload)))


def pinocchio_model(axes, mount, payload, gravity):
    """The same chain built with pinocchio's API: each joint placed at ``pos`` in its parent
    joint's frame, an unaligned revolute/prismatic joint along ``axis``, the link's inertia
    and the payload's (placed at the mount) appended to the joints."""
    model = pin.Model()
    parent = 0
    for i, ax in enumerate(axes):
        joint = (pin.JointModelRevoluteUnaligned if ax.kind == "revolute"
                 else pin.JointModelPrismaticUnaligned)(np.asarray(ax.axis, dtype=float))
        parent = model.addJoint(parent, joint, pin.SE3(np.eye(3), np.asarray(ax.pos, float)),
                                f"j{i}")
        model.appendBodyToJoint(parent, pin.Inertia(ax.mass, np.asarray(ax.com, float),
                                                    np.diag(ax.inertia)), pin.SE3.Identity())
    if payload is not None:
        model.appendBodyToJoint(parent, pin.Inertia(payload.mass, np.asarray(payload.com),
                                                    np.asarray(payload.inertia)),
                                pin.SE3(mount[:3, :3], mount[:3, 3]))
    model.armature = np.array([ax.armature for ax in axes])
    model.gravity.linear = np.asarray(gravity, dtype=float)
    return model


def pinocchio_torques(model, q, qd, qdd):
    data = model.createData()
    return np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(q.shape[0])])


def trajectory(draw, n, samples=4):
    arr = st.lists(st.floats(-3.0, 3.0), min_size=samples * n, max_size=samples * n)
    return tuple(np.array(draw(arr)).reshape(samples, n) for _ in range(3))


@SETTINGS
@given(chain=chains(), gravity=vec3().map(lambda g: 10.0 * g), data=st.data())
def test_the_oracle_equals_pinocchio_on_generated_chains(chain, gravity, data):
    """Any chain of 1-4 revolute/prismatic axes (random directions, offsets, masses, centres
    of mass, inertias, armatures), with or without a turned, offset payload on the mount, any
    gravity, random q, qd, qdd: the oracle's torques equal pinocchio's to 1e-9 relative."""
    axes, mount, payload = chain
    q, qd, qdd = trajectory(data.draw, len(axes))
    got = inverse_dynamics(axes, q, qd, qdd, mount, payload, gravity)
    want = pinocchio_torques(pinocchio_model(axes, mount, payload, gravity), q, qd, qdd)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * max(1.0, np.abs(want).max()))


def test_pinocchio_catches_a_planted_fault_in_the_oracles_inputs():
    """Planted faults: a centre of mass 1 mm off, a payload turned 1 mrad, or the payload left
    out, and the comparison with pinocchio fails."""
    rng = np.random.default_rng(3)
    axes = [OracleAxis("revolute", [0, 0, 0.8], [1, 0, 0], 60.0, [0.0, 0.05, 0.1],
                       [2.0, 3.0, 4.0]),
            OracleAxis("revolute", [0, 0, 0.2], [0, 0, 1], 30.0, [0.01, 0.0, 0.05],
                       [1.0, 1.0, 1.5])]
    mount = np.eye(4)
    mount[2, 3] = 0.05
    payload = OraclePayload(250.0, [0.1, 0.2, 0.3], np.diag([5.0, 8.0, 11.0]))
    q, qd, qdd = (rng.uniform(-2, 2, (20, 2)) for _ in range(3))
    want = pinocchio_torques(pinocchio_model(axes, mount, payload, (0, 0, -G)), q, qd, qdd)
    tol = 1e-9 * np.abs(want).max()
    assert np.abs(inverse_dynamics(axes, q, qd, qdd, mount, payload) - want).max() < tol
    off = [axes[0], OracleAxis("revolute", [0, 0, 0.2], [0, 0, 1], 30.0, [0.011, 0.0, 0.05],
                               [1.0, 1.0, 1.5])]
    turned = mount.copy()
    c, s = np.cos(1e-3), np.sin(1e-3)
    turned[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    for faulty in (inverse_dynamics(off, q, qd, qdd, mount, payload),
                   inverse_dynamics(axes, q, qd, qdd, turned, payload),
                   inverse_dynamics(axes, q, qd, qdd, mount, None)):
        assert np.abs(faulty - want).max() > 1e3 * tol


@SETTINGS
@given(m=st.floats(0.1, 800.0), r=st.floats(-1.0, 1.0), inertia=st.floats(0.0, 20.0),
       theta=st.floats(-4.0, 4.0), qd=st.floats(-3.0, 3.0), qdd=st.floats(-5.0, 5.0))
def test_a_tilt_axis_holding_an_offset_point_mass(m, r, inertia, theta, qd, qdd):
    """A horizontal tilt axis (x) with a point mass m at r along y, and a link inertia I about
    x: tau = m g r cos(theta) + (m r^2 + I) qdd (the centripetal pull passes through the axis)."""
    axes = [OracleAxis("revolute", [0.3, -0.2, 0.8], [1, 0, 0], 1e-9, [0, 0, 0],
                       [inertia, 0.5, 0.5])]
    payload = OraclePayload(m, [0.0, r, 0.0])
    tau = inverse_dynamics(axes, [theta], [qd], [qdd], payload=payload)
    expected = m * G * r * np.cos(theta) + (m * r * r + inertia) * qdd
    assert tau[0] == pytest.approx(expected, abs=1e-9 * max(1.0, abs(expected)) + 1e-8)


@SETTINGS
@given(m=st.floats(0.1, 800.0), r=st.floats(0.0, 1.0), izz=st.floats(0.0, 20.0),
       theta=st.floats(-4.0, 4.0), qd=st.floats(-3.0, 3.0), qdd=st.floats(-5.0, 5.0))
def test_a_turntable_with_an_offset_part_needs_no_hold_torque(m, r, izz, theta, qd, qdd):
    """A vertical turntable axis with a part at r off centre: tau = (m r^2 + Izz) qdd, gravity
    and speed aside."""
    axes = [OracleAxis("revolute", [0, 0, 0.5], [0, 0, 1], 1e-9, [0, 0, 0], [0.5, 0.5, 0.0])]
    payload = OraclePayload(m, [r, 0.0, 0.3], np.diag([0.0, 0.0, izz]))
    tau = inverse_dynamics(axes, [theta], [qd], [qdd], payload=payload)
    expected = (m * r * r + izz) * qdd
    assert tau[0] == pytest.approx(expected, abs=1e-9 * max(1.0, abs(expected)))


@pytest.mark.parametrize("direction,g_along", [([1, 0, 0], 0.0), ([0, 0, 1], G),
                                               ([0, 0.6, 0.8], 0.8 * G)])
def test_a_track_pushes_its_carriage_and_payload_as_one_mass(direction, g_along):
    """A prismatic axis: F = (m_carriage + m_payload) (qdd + g along the axis) + armature qdd."""
    axes = [OracleAxis("prismatic", [0, 0, 0.2], direction, 120.0, [0.1, 0.0, 0.1],
                       [1.0, 2.0, 3.0], armature=40.0)]
    qdd = np.array([[0.0], [1.5], [-2.0]])
    F = inverse_dynamics(axes, [[0.5], [1.0], [2.0]], [[0.0], [0.7], [-0.3]], qdd,
                         payload=OraclePayload(600.0, [0.0, 0.3, 0.4], np.eye(3)))
    np.testing.assert_allclose(F, 720.0 * (qdd + g_along) + 40.0 * qdd, atol=1e-9)


def test_damping_and_friction_follow_cellsims_law():
    """Damping adds ``c qd``; Coulomb friction ``F clip(qd / COULOMB_SPEED, -1, 1)``: full
    above COULOMB_SPEED, a linear ramp through zero below it."""
    bare = OracleAxis("revolute", [0, 0, 0.8], [1, 0, 0], 40.0, [0, 0.1, 0], [1, 2, 3])
    rough = OracleAxis("revolute", [0, 0, 0.8], [1, 0, 0], 40.0, [0, 0.1, 0], [1, 2, 3],
                       damping=7.0, friction=12.0)
    qd = np.array([[-1.0], [-COULOMB_SPEED], [-0.25 * COULOMB_SPEED], [0.0],
                   [0.5 * COULOMB_SPEED], [2 * COULOMB_SPEED], [0.3]])
    q = np.full_like(qd, 0.4)
    qdd = np.full_like(qd, 1.2)
    extra = inverse_dynamics([rough], q, qd, qdd) - inverse_dynamics([bare], q, qd, qdd)
    np.testing.assert_allclose(extra[:, 0], 7.0 * qd[:, 0] + 12.0 * np.array(
        [-1.0, -1.0, -0.25, 0.0, 0.5, 1.0, 1.0]), atol=1e-9)


def test_the_chain_from_a_spec_reads_its_numbers_and_drive_armature():
    drive = Drive(120.0, 0.9, 2e-4, 1.0, 3.0, 3000.0)
    link = LinkSpec(35.0, np.array([0.0, 0.02, 0.1]), np.array([1.0, 2.0, 3.0]))
    mech = MechanismSpec("p", "p", "positioner", (
        AxisSpec("tilt", "revolute", np.array([0, 0, 0.8]), np.array([1.0, 0, 0]), (-2, 2),
                 1.0, 1.0, drive, link, friction=5.0, damping=2.0),))
    (ax,) = chain_from_spec(mech)
    assert ax.armature == pytest.approx(2e-4 * 120.0**2)
    assert (ax.mass, ax.friction, ax.damping) == (35.0, 5.0, 2.0)
    assert chain_from_spec(mech, armature=False)[0].armature == 0.0


@SETTINGS
@given(tilt=st.floats(-2.4, 2.4), rotate=st.floats(-7.0, 7.0), m=st.floats(1.0, 500.0),
       com=vec3())
def test_a_d500_like_positioner_holding_a_part_needs_the_moments_of_the_weights(tilt, rotate,
                                                                                m, com):
    """A tilt (x) - rotate positioner read from its spec, a part of mass m on a turned, raised
    faceplate, at rest: each axis's torque is the moment about it of the weights of everything
    it carries (statics with x/z rotation matrices written here)."""
    drive = Drive(120.0, 0.9, 2e-4, 1.0, 3.0, 3000.0)
    links = (LinkSpec(80.0, np.array([0.0, 0.02, 0.1]), np.array([3.0, 4.0, 5.0])),
             LinkSpec(40.0, np.array([0.01, 0.0, 0.03]), np.array([1.0, 1.0, 1.8])))
    mount = np.eye(4)
    c30, s30 = np.cos(np.pi / 6), np.sin(np.pi / 6)
    mount[:3, :3] = [[c30, -s30, 0], [s30, c30, 0], [0, 0, 1]]
    mount[:3, 3] = [0.0, 0.0, 0.05]
    mech = MechanismSpec("d500", "D500-like", "positioner", (
        AxisSpec("tilt", "revolute", np.array([0, 0, 0.8]), np.array([1.0, 0, 0]), (-2.4, 2.4),
                 1.0, 1.0, drive, links[0]),
        AxisSpec("rotate", "revolute", np.array([0, 0, 0.25]), np.array([0, 0, 1.0]),
                 (-20.0, 20.0), 1.0, 1.0, drive, links[1])), mount=mount)
    tau = inverse_dynamics(chain_from_spec(mech), [tilt, rotate], [0.0, 0.0], [0.0, 0.0],
                           mount, OraclePayload(m, com, np.diag([2.0, 3.0, 4.0])))
    ct, st_, cr, sr = np.cos(tilt), np.sin(tilt), np.cos(rotate), np.sin(rotate)
    Rx = np.array([[1, 0, 0], [0, ct, -st_], [0, st_, ct]])
    R2 = Rx @ np.array([[cr, -sr, 0], [sr, cr, 0], [0, 0, 1]])
    o1 = np.array([0, 0, 0.8])
    o2 = o1 + Rx @ [0, 0, 0.25]
    weights = [(80.0, o1 + Rx @ links[0].com), (40.0, o2 + R2 @ links[1].com),
               (m, o2 + R2 @ (mount[:3, 3] + mount[:3, :3] @ com))]
    up = np.array([0.0, 0.0, G])
    hold_tilt = np.array([1.0, 0, 0]) @ sum(np.cross(c - o1, w * up) for w, c in weights)
    hold_rotate = (Rx @ [0, 0, 1.0]) @ sum(np.cross(c - o2, w * up) for w, c in weights[1:])
    np.testing.assert_allclose(tau, [hold_tilt, hold_rotate], rtol=0,
                               atol=1e-9 * max(1.0, abs(hold_tilt)))
