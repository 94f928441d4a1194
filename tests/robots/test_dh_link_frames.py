"""The frame a DH robot's ``[[links]]`` centre of mass is given in, as robot-format.md states
it (a new user's trial: the docs did not say, and the textbook frame gave J2 a 64 % larger
holding torque with no warning).

Specification, on generated link masses, centres of mass and joint values of the 6-axis DH arm
:data:`support.robots.DH_ROBOT`: the gravity torques MuJoCo computes for the generated model at
rest are those computed here by hand from the DH table, each link's weight placed with
``convention = "dh"``'s frame (DH frame i-1, turned by q_i, without row i's own offset); a
centre of mass given in the textbook's link frame i and carried in with ``com = A_i r_i`` (the
docs' formula) gives the textbook's torques. A planted fault (the centres of mass read in frame
i) is caught.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import mujoco
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from support.robots import DH_ROBOT

from sim.robots.robotfile import load_robot_folder

DH = np.array([[75, -90, 330, 0], [300, 0, 0, -90], [75, -90, 0, 0], [0, 90, 320, 0],
               [0, -90, 0, 0], [0, 0, 80, 0]], dtype=float)
G = 9.81
DH_TEXT = ("convention = \"dh\"\ndh = [[75, -90, 330, 0], [300, 0, 0, -90], [75, -90, 0, 0], "
           "[0, 90, 320, 0], [0, -90, 0, 0],\n      [0, 0, 80, 0]]")


def _A(a_mm: float, alpha_deg: float, d_mm: float, theta: float) -> np.ndarray:
    """Rz(theta) Tz(d) Tx(a) Rx(alpha), m."""
    ct, st_ = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(np.radians(alpha_deg)), np.sin(np.radians(alpha_deg))
    return np.array([[ct, -st_ * ca, st_ * sa, a_mm / 1e3 * ct],
                     [st_, ct * ca, -ct * sa, a_mm / 1e3 * st_],
                     [0.0, sa, ca, d_mm / 1e3], [0.0, 0.0, 0.0, 1.0]])


def _Rz(theta: float) -> np.ndarray:
    T = np.eye(4)
    T[:2, :2] = [[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]]
    return T


def _frames(q: np.ndarray) -> list[np.ndarray]:
    """DH frames 0..6 at joint values q (theta = q + offset)."""
    T = [np.eye(4)]
    for (a, al, d, off), qi in zip(DH, q, strict=True):
        T.append(T[-1] @ _A(a, al, d, qi + np.radians(off)))
    return T


def hand_gravity(q: np.ndarray, masses: np.ndarray, com_m: np.ndarray,
                 frame: str = "dh") -> np.ndarray:
    """Each joint's torque holding the links' weights at rest, N m (MuJoCo's sign: the
    generalized force gravity exerts, reversed), with link i's centre of mass ``com_m[i]`` in
    ``frame``: ``"dh"`` the docs' (frame i-1 turned by q_i), ``"textbook"`` DH frame i."""
    T = _frames(q)
    out = np.zeros(6)
    for j in range(6):
        axis, p0 = T[j][:3, 2], T[j][:3, 3]
        for i in range(j, 6):
            F = T[i] @ _Rz(q[i]) if frame == "dh" else T[i + 1]
            p = (F @ np.r_[com_m[i], 1.0])[:3]
            out[j] += np.cross(p - p0, [0.0, 0.0, -masses[i] * G]) @ axis
    return -out


#: A modified (Craig) table, rows [a_{i-1} mm, alpha_{i-1} deg, d_i mm, theta_offset_i deg].
MDH = np.array([[0, 0, 330, 0], [75, -90, 0, -90], [300, 0, 0, 0], [75, -90, 320, 0],
                [0, 90, 0, 0], [0, -90, 80, 0]], dtype=float)
MDH_TEXT = ("convention = \"mdh\"\ndh = ["
            + ", ".join(f"[{a:g}, {al:g}, {d:g}, {o:g}]" for a, al, d, o in MDH) + "]")


def _Rx(alpha_deg: float) -> np.ndarray:
    T = np.eye(4)
    c, s_ = np.cos(np.radians(alpha_deg)), np.sin(np.radians(alpha_deg))
    T[1:3, 1:3] = [[c, -s_], [s_, c]]
    return T


def hand_gravity_mdh(q: np.ndarray, masses: np.ndarray, com_m: np.ndarray) -> np.ndarray:
    """:func:`hand_gravity` of the :data:`MDH` arm, link i's centre of mass in Craig's frame i
    (T_i = T_{i-1} Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i); joint i about its z)."""
    T = [np.eye(4)]
    for (a, al, d, off), qi in zip(MDH, q, strict=True):
        Tx, Tz = np.eye(4), np.eye(4)
        Tx[0, 3], Tz[2, 3] = a / 1e3, d / 1e3
        T.append(T[-1] @ _Rx(al) @ Tx @ _Rz(qi + np.radians(off)) @ Tz)
    out = np.zeros(6)
    for j in range(6):
        axis, p0 = T[j + 1][:3, 2], T[j + 1][:3, 3]
        for i in range(j, 6):
            p = (T[i + 1] @ np.r_[com_m[i], 1.0])[:3]
            out[j] += np.cross(p - p0, [0.0, 0.0, -masses[i] * G]) @ axis
    return -out


def _model_gravity(masses: np.ndarray, com_m: np.ndarray, q: np.ndarray,
                   table: str | None = None) -> np.ndarray:
    links = "".join(f"""
[[links]]
mass_kg = {float(m)!r}
com_mm = [{float(c[0]) * 1e3!r}, {float(c[1]) * 1e3!r}, {float(c[2]) * 1e3!r}]
inertia_kg_m2 = [0.01, 0.01, 0.01, 0, 0, 0]
""" for m, c in zip(masses, com_m, strict=True))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "dh_arm"
        folder.mkdir()
        robot = DH_ROBOT.replace("total_kg = 25\n", "") + links
        if table is not None:
            robot = robot.replace(DH_TEXT, table)
        (folder / "robot.toml").write_text(robot)
        spec = load_robot_folder(folder)
        model = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    data = mujoco.MjData(model)
    adr = [model.jnt_qposadr[model.joint(j).id] for j in spec.joints]
    data.qpos[adr] = q
    mujoco.mj_forward(model, data)
    return np.array([data.qfrc_bias[model.jnt_dofadr[model.joint(j).id]] for j in spec.joints])


MASSES = st.lists(st.floats(0.2, 8.0), min_size=6, max_size=6).map(np.array)
COMS = st.lists(st.lists(st.floats(-200.0, 200.0), min_size=3, max_size=3), min_size=6,
                max_size=6).map(lambda c: np.array(c) / 1e3)
QS = st.lists(st.floats(-1.5, 1.5), min_size=6, max_size=6).map(np.array)


@settings(max_examples=10, deadline=None)
@given(masses=MASSES, com=COMS, q=QS)
def test_link_centres_of_mass_are_in_the_frame_the_docs_name(masses, com, q):
    # to 1e-6 N m: the generated MJCF holds positions to about 1e-9 m
    got = _model_gravity(masses, com, q)
    assert np.allclose(got, hand_gravity(q, masses, com, "dh"), rtol=1e-7, atol=1e-6)


@settings(max_examples=5, deadline=None)
@given(masses=MASSES, com=COMS, q=QS)
def test_a_textbook_centre_carried_in_with_the_docs_formula_gives_the_textbook_torques(
        masses, com, q):
    # r_i in DH frame i, carried into the link's frame with A_i (at q = 0: theta = offset)
    carried = np.array([(_A(a, al, d, np.radians(off)) @ np.r_[r, 1.0])[:3]
                        for (a, al, d, off), r in zip(DH, com, strict=True)])
    got = _model_gravity(masses, carried, q)
    assert np.allclose(got, hand_gravity(q, masses, com, "textbook"), rtol=1e-7, atol=1e-6)


@settings(max_examples=5, deadline=None)
@given(masses=MASSES, com=COMS, q=QS)
def test_a_modified_dh_arms_centres_are_in_craigs_frame_i(masses, com, q):
    assert DH_TEXT in DH_ROBOT
    got = _model_gravity(masses, com, q, MDH_TEXT)
    assert np.allclose(got, hand_gravity_mdh(q, masses, com), rtol=1e-7, atol=1e-6)


def test_planted_fault_centres_read_in_frame_i_are_caught():
    masses = np.full(6, 2.0)
    com = np.tile([-0.15, 0.0, 0.0], (6, 1))
    q = np.radians([0.0, 30.0, -20.0, 10.0, 40.0, 0.0])
    got = _model_gravity(masses, com, q)
    assert np.allclose(got, hand_gravity(q, masses, com, "dh"), rtol=1e-7, atol=1e-6)
    assert not np.allclose(got, hand_gravity(q, masses, com, "textbook"), rtol=1e-3, atol=1e-3)
