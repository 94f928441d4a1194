"""Cells (issue 4 section 1): composition, stability at home, the seed 001 phase-I end on the
weld seam, seam geometry, reachability of every seam point and pick pose, suction by
adhesion, and one-line errors for bad input."""

from __future__ import annotations

import warnings
from functools import lru_cache

import mujoco
import numpy as np
import pytest

from sim.cells import BARE, CELLS, MOUNTS, Seam, build_cell, resolve_tool
from sim.cells.tools import TOOLS
from sim.errors import CellsimError, UnknownNameError
from sim.robots.families import Fanuc6, FiveR
from sim.robots.kinematics.closed_form import fk_5r
from sim.robots.kinematics.ik import solve_ik
from sim.robots.registry import ROBOTS

COMBOS = [(c, r, mt) for c, s in CELLS.items() for r in s.robots for mt in s.mounts] + \
         [(None, r, mt) for r in sorted(ROBOTS) for mt in BARE.mounts]
PHASE1_END = np.deg2rad([-15.2, 116.82, -1.3, 1.4, -0.206])  # seed 001 eq. (4), Table 1


@lru_cache(maxsize=None)
def cell_and_model(cell, robot, mount="floor"):
    c = build_cell(None if cell is None else CELLS[cell], ROBOTS[robot], mount=mount)
    return c, c.compile()


def set_q(m, d, cell, q):
    for j, qj in zip(cell.joint_names, q, strict=True):
        d.qpos[m.joint(j).qposadr[0]] = qj
    mujoco.mj_forward(m, d)


def site_pose(d, name):
    s = d.site(name)
    return s.xmat.reshape(3, 3).copy(), s.xpos.copy()


def ik_in_limits(cell, T_world, current):
    km = cell.kinematics()
    T0 = np.linalg.inv(cell.world_from_frame0) @ T_world
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sols = [s for s in solve_ik(km, T0, current) if s.within_limits]
    return sols[0].q if sols else None


# ---------------------------------------------------------------------------- composition
@pytest.mark.parametrize("cell,robot,mount", COMBOS)
def test_cell_compiles_and_holds_home_without_warnings(cell, robot, mount):
    c, m = cell_and_model(cell, robot, mount)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
    mujoco.mj_forward(m, d)
    parts0 = np.array([d.body(p).xpos for p in c.parts]).reshape(-1, 3)
    tcp0 = d.site(c.tcp_site).xpos.copy()
    for _ in range(round(1.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    assert all(d.warning[i].number == 0 for i in range(len(d.warning))), \
        [(mujoco.mjtWarning(i).name, d.warning[i].number) for i in range(len(d.warning))]
    q = np.array([d.joint(j).qpos[0] for j in c.joint_names])
    # the robot's joints, then external axes, then the other robots' joints ([[robots]])
    home = np.concatenate([c.home_q, c.axis_home, *(cr.home_q for cr in c.partners)])
    assert np.abs(q - home).max() < 2e-3  # position servos hold home (sag < 0.1 deg, 2 mm)
    assert np.linalg.norm(d.site(c.tcp_site).xpos - tcp0) < 1e-3
    parts1 = np.array([d.body(p).xpos for p in c.parts]).reshape(-1, 3)
    if len(c.parts):
        assert np.linalg.norm(parts1 - parts0, axis=1).max() < 1e-3  # parts rest: drift < 1 mm


@pytest.mark.parametrize("cell,robot,mount", COMBOS)
def test_cell_names_cameras_and_frames(cell, robot, mount):
    c, m = cell_and_model(cell, robot, mount)
    kinds = [("revolute",) * c.robot.n_joints] + [
        tuple(a.kind for a in pm.spec.axes) for pm in c.mechanisms] + [
        ("revolute",) * cr.robot.n_joints for cr in c.partners]
    joint_type = {"revolute": mujoco.mjtJoint.mjJNT_HINGE,
                  "prismatic": mujoco.mjtJoint.mjJNT_SLIDE}
    for j, kind in zip(c.joint_names, [k for ks in kinds for k in ks], strict=True):
        assert m.joint(j).type == joint_type[kind]
    for a in c.actuator_names:
        assert m.actuator(a).trntype == mujoco.mjtTrn.mjTRN_JOINT
    for s in (c.tcp_site, c.frame0_site, c.flange_site):
        m.site(s)
    assert {"overview", "tool"} <= set(c.cameras)
    for cam in c.cameras:
        m.camera(cam)
    assert m.vis.global_.offwidth >= 1280 and m.vis.global_.offheight >= 720
    assert m.nlight >= 1 and m.nmesh == 0  # primitives only
    assert (c.adhesion_actuator is not None) == (c.tool is not None and c.tool.kind == "gripper")
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    R0, p0 = site_pose(d, c.frame0_site)
    np.testing.assert_allclose(c.world_from_frame0[:3, :3], R0, atol=1e-9)
    np.testing.assert_allclose(c.world_from_frame0[:3, 3], p0, atol=1e-9)
    if mount == "ceiling":  # hanging: J1 axis points down
        assert R0[2, 2] == pytest.approx(-1.0)


# ---------------------------------------------------------------------------- seed 001 cell
def test_phase1_end_puts_torch_on_seam_start():
    """Seed 001 eq. (4): the phase-I end configuration puts the wire tip on the seam start."""
    c, m = cell_and_model("weld_cylinder", "robot_5r", "floor")
    d = mujoco.MjData(m)
    set_q(m, d, c, PHASE1_END)
    R, p = site_pose(d, c.tcp_site)
    seam = c.seams["circumferential"]
    assert np.linalg.norm(p - seam.start) < 1e-4
    assert np.linalg.norm(p - seam.start) < 1e-9  # in fact exact
    # the 5R torch axis is the tcp x axis (seed 000 frame 6); it points into the joint
    np.testing.assert_allclose(R[:, 0], seam.torch_axis(0.0), atol=1e-9)
    # and matches an independent evaluation of seed 000 eq. (5) with the torch added
    dims = {**c.robot.dims, "l3": c.robot.dims["l3"] - 0.300 + c.tool.length_m}
    _, p_cf = fk_5r(PHASE1_END, dims)
    np.testing.assert_allclose(np.linalg.inv(c.world_from_frame0) @ [*seam.start, 1.0],
                               [*p_cf, 1.0], atol=1e-9)
    np.testing.assert_allclose(c.start_q, PHASE1_END)


def test_phase1_approach_stays_above_the_part():
    """Seed 001 phase I (Table 1, 4-3-4 planner) brings the torch down onto the seam from above
    the head: the wire tip and nozzle never go below the part's top face while over it."""
    from planners.poly434 import plan_434

    table1 = np.deg2rad([[0, 0, 0, 0, 0], [-7.6, 56.61, 7.08, -7.03, -0.103],
                         [-15.2, 113.22, 14.16, -14.06, -0.206],
                         [-15.2, 116.82, -1.3, 1.4, -0.206]])
    traj = plan_434([0.0, 3.33, 6.67, 10.0], table1)
    c, m = cell_and_model("weld_cylinder", "robot_5r", "floor")
    d = mujoco.MjData(m)
    r_in, r_out, top = (c.dims["head_inner_radius"], c.dims["shell_outer_radius"],
                        c.dims["part_height"])
    lowest = np.inf
    for t in np.linspace(0.0, 10.0, 501):
        set_q(m, d, c, traj.at(t).q)
        for p in (d.site(c.tcp_site).xpos, d.geom("robot/tool/nozzle").xpos):
            if r_in <= np.hypot(p[0], p[1]) <= r_out:
                lowest = min(lowest, p[2] - top)
    assert lowest > -1e-6
    np.testing.assert_allclose(traj.at(10.0).q, PHASE1_END, atol=1e-12)


@pytest.mark.parametrize("mount", MOUNTS)
def test_moving_j1_alone_traces_the_seam(mount):
    c, m = cell_and_model("weld_cylinder", "robot_5r", mount)
    seam = c.seams["circumferential"]
    d = mujoco.MjData(m)
    set_q(m, d, c, c.start_q)
    assert np.linalg.norm(d.site(c.tcp_site).xpos - seam.start) < 1e-4
    lo, hi = m.jnt_range[m.joint(c.joint_names[0]).id]
    for s in np.linspace(0.0, seam.length(), 7):
        q = c.start_q.copy()
        q[0] += s / seam.radius  # +q1 travel, in frame 0 for both mounts
        assert lo <= q[0] <= hi
        set_q(m, d, c, q)
        R, p = site_pose(d, c.tcp_site)
        assert np.linalg.norm(p - seam.point(s)) < 1e-4
        np.testing.assert_allclose(R[:, 0], seam.torch_axis(s), atol=1e-9)
    # the seam circle is about the J1 axis, on the part's top face; the torch comes from above
    # and from outside the part (its body leans radially out), on either mount
    k1, o1 = c.world_from_frame0[:3, 2], c.world_from_frame0[:3, 3]
    for s in np.linspace(0.0, seam.length(), 5):
        v = seam.point(s) - o1
        radial = v - (v @ k1) * k1
        assert np.linalg.norm(radial) == pytest.approx(c.dims["seam_radius"], abs=1e-9)
        assert seam.point(s)[2] == pytest.approx(c.dims["part_height"], abs=1e-9)
        a = seam.torch_axis(s)
        assert a[2] < -0.5 and -a @ radial > 0.0


def test_ceiling_start_pose_in_limits_and_torch_posture():
    c, m = cell_and_model("weld_cylinder", "robot_5r", "ceiling")
    rng = m.jnt_range[[m.joint(j).id for j in c.joint_names]]
    assert np.all(c.start_q >= rng[:, 0]) and np.all(c.start_q <= rng[:, 1])
    d = mujoco.MjData(m)
    set_q(m, d, c, c.start_q)
    R, _ = site_pose(d, c.tcp_site)
    seam = c.seams["circumferential"]
    np.testing.assert_allclose(R, seam.torch_rotation(0.0), atol=1e-9)
    # same part and torch work angle as on the floor
    f, _ = cell_and_model("weld_cylinder", "robot_5r", "floor")
    assert c.dims["seam_radius"] == pytest.approx(f.dims["seam_radius"])
    assert seam.torch_work_angle_deg == pytest.approx(
        f.seams["circumferential"].torch_work_angle_deg)


# ---------------------------------------------------------------------------- seam geometry
def _check_seam_geometry(seam: Seam):
    L = seam.length()
    s, P = seam.sample(2001)
    # length: the fine polyline (chords) converges on the arc length from below
    chords = np.linalg.norm(np.diff(P, axis=0), axis=1).sum()
    assert chords == pytest.approx(L, rel=1e-6) and chords <= L + 1e-12
    np.testing.assert_allclose(P[0], seam.start, atol=1e-12)
    np.testing.assert_allclose(P[-1], seam.end, atol=1e-12)
    h = 1e-6
    for si in np.linspace(h, L - h, 9):
        t = seam.tangent(si)
        fd = (seam.point(si + h) - seam.point(si - h)) / (2 * h)  # finite difference
        np.testing.assert_allclose(t, fd, atol=1e-6)
        R = seam.torch_rotation(si)
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        a = R[:, seam.tool_axis]
        np.testing.assert_allclose(a, seam.torch_axis(si), atol=1e-12)
        # travel angle (AWS): tilt of the torch axis towards the travel direction
        assert np.degrees(np.arcsin(a @ t)) == pytest.approx(seam.torch_travel_angle_deg,
                                                            abs=1e-9)
        # work angle (AWS): angle to the reference-surface normal, perpendicular to the seam
        n = seam.surface_normal - (seam.surface_normal @ t) * t
        n /= np.linalg.norm(n)
        ap = a - (a @ t) * t
        ap /= np.linalg.norm(ap)
        assert np.degrees(np.arccos(-ap @ n)) == pytest.approx(seam.torch_work_angle_deg,
                                                               abs=1e-7)
        # the torch body leans to the side the seam says (left = n x t)
        assert np.sign(-ap @ np.cross(n, t)) == seam.torch_side or seam.torch_work_angle_deg == 0


@pytest.mark.parametrize("cell,robot,mount", [x for x in COMBOS if x[0] and x[0] != "pick"])
def test_seam_geometry(cell, robot, mount):
    c, _ = cell_and_model(cell, robot, mount)
    assert c.seams
    for seam in c.seams.values():
        _check_seam_geometry(seam)
        if seam.kind == "arc":
            assert seam.length() == pytest.approx(seam.radius * seam.sweep)


def test_seam_line_and_arc_by_hand():
    line = Seam("l", "line", np.array([[0, 0, 0], [0.3, 0.4, 0.0]]), None, 45.0, 10.0)
    assert line.length() == pytest.approx(0.5)
    np.testing.assert_allclose(line.tangent(0.2), [0.6, 0.8, 0.0])
    np.testing.assert_allclose(line.point(0.25), [0.15, 0.2, 0.0])
    # quarter circle of radius 2 about z, counter-clockwise
    r2 = np.sqrt(2.0)
    arc = Seam("a", "arc", np.array([[2, 0, 1], [r2, r2, 1], [0, 2, 1]]), np.array([0, 0, 1.0]),
               30.0, 0.0)
    assert arc.length() == pytest.approx(np.pi)
    np.testing.assert_allclose(arc.center, [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(arc.tangent(0.0), [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(arc.point(np.pi / 2), [r2, r2, 1], atol=1e-12)
    _check_seam_geometry(line)
    _check_seam_geometry(arc)
    # an arc longer than half a circle keeps its travel sense
    big = Seam("b", "arc", np.array([[2, 0, 0], [-2, 0, 0], [0, -2, 0]]), None, 0.0, 0.0)
    assert big.sweep == pytest.approx(1.5 * np.pi)
    # transformed to another frame and back
    T = np.eye(4)
    T[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    T[:3, 3] = [1, 2, 3]
    back = arc.transformed(T).transformed(np.linalg.inv(T))
    np.testing.assert_allclose(back.torch_rotation(1.0), arc.torch_rotation(1.0), atol=1e-12)
    np.testing.assert_allclose(back.point(1.0), arc.point(1.0), atol=1e-12)


@pytest.mark.parametrize("points,kind,normal,match", [
    (np.zeros((2, 3)), "line", None, "coincide"),
    (np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]), "arc", None, "collinear"),
    (np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0.0]]), "arc", np.array([0, 0, -1.0]), "normal"),
    (np.zeros((3, 3)), "line", None, "shape"),
    (np.zeros((2, 3)), "spline", None, "kind"),
])
def test_bad_seams(points, kind, normal, match):
    with pytest.raises(CellsimError, match=match):
        Seam("bad", kind, points, normal, 45.0, 0.0)
    line = Seam("l", "line", np.array([[0, 0, 0], [1, 0, 0.0]]), None, 45.0, 0.0)
    with pytest.raises(CellsimError, match="outside"):
        line.point(1.5)


# ---------------------------------------------------------------------------- reachability
@pytest.mark.parametrize("robot", CELLS["weld_table"].robots)
def test_weld_table_seams_reachable(robot):
    """Every seam point: analytic IK inside the joint ranges, checked with MuJoCo FK."""
    c, m = cell_and_model("weld_table", robot)
    d = mujoco.MjData(m)
    q = c.home_q
    for seam in c.seams.values():
        for s in np.linspace(0.0, seam.length(), 13):
            if isinstance(c.robot.family, FiveR):  # the 5-axis torch stays in the plane through J1
                assert seam.plane_deviation_deg(s) < 1e-9
            T = seam.pose(s)
            q = ik_in_limits(c, T, q)
            assert q is not None, f"{seam.name} s={s:.3f} unreachable"
            set_q(m, d, c, q)
            R, p = site_pose(d, c.tcp_site)
            assert np.linalg.norm(p - T[:3, 3]) < 1e-4
            np.testing.assert_allclose(R, T[:3, :3], atol=1e-6)
            if isinstance(c.robot.family, Fanuc6):  # clear of the wrist singularity theta5 = 0
                assert abs(q[4]) > np.deg2rad(20.0)
    assert c.start_q is not None
    set_q(m, d, c, c.start_q)
    first = next(iter(c.seams.values()))
    assert np.linalg.norm(d.site(c.tcp_site).xpos - first.start) < 1e-4


def test_pick_poses_reachable_gripper_down():
    c, m = cell_and_model("pick", "lrmate200ic5l")
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    down = np.diag([1.0, -1.0, -1.0])  # tcp z (the approach a = z6) pointing down
    half_h = c.dims["part_size_z"] / 2
    targets = [d.body(p).xpos + [0, 0, half_h] for p in c.parts] + \
              [s + [0, 0, half_h] for s in c.slots]
    assert len(c.parts) == 4 and c.slots.shape == (4, 3)
    for tgt in targets:
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = down, tgt
        q = ik_in_limits(c, T, c.home_q)
        assert q is not None
        assert abs(q[4]) > np.deg2rad(20.0)
        d2 = mujoco.MjData(m)
        set_q(m, d2, c, q)
        R, p = site_pose(d2, c.tcp_site)
        assert np.linalg.norm(p - tgt) < 1e-4
        np.testing.assert_allclose(R, down, atol=1e-6)
    # parts 0.25 kg boxes 60 x 40 x 30 mm, not overlapping; slots apart
    for p in c.parts:
        assert m.body(p).mass[0] == pytest.approx(0.25)
    pos = np.array([d.body(p).xpos for p in c.parts])
    for i in range(4):
        for j in range(i + 1, 4):
            assert np.abs(pos[i] - pos[j])[:2].max() > 0.06
            assert np.abs(c.slots[i] - c.slots[j])[:2].max() > 0.06


# ---------------------------------------------------------------------------- suction
def _pick_run(suction: float, mass: float = 0.25, swing: bool = False):
    """Touch part0 from above, set suction, lift 0.1 m (optionally swing J1 by 90 deg in 0.5 s).

    Returns (lift of the part, m; largest slip of the part relative to the tcp, m)."""
    c = build_cell(CELLS["pick"], ROBOTS["lrmate200ic5l"])
    m = c.compile()
    part = c.parts[0]
    b = m.body(part).id
    m.body_inertia[b] *= mass / m.body_mass[b]
    m.body_mass[b] = mass
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    top = d.body(part).xpos + [0, 0, c.dims["part_size_z"] / 2]
    z0 = d.body(part).xpos[2]

    def pose(p):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = np.diag([1.0, -1.0, -1.0]), p
        return T

    q_above = ik_in_limits(c, pose(top + [0, 0, 0.05]), c.home_q)
    q_touch = ik_in_limits(c, pose(top - [0, 0, 0.0005]), q_above)
    q_lift = ik_in_limits(c, pose(top + [0, 0, 0.10]), q_touch)
    act = [m.actuator(a).id for a in c.actuator_names]
    suc = m.actuator(c.adhesion_actuator).id
    set_q(m, d, c, q_above)
    slip = [0.0]
    ref = [None]

    def move(q0, q1, T, u, track=False):
        n = round(T / m.opt.timestep)
        for k in range(n):
            s = (k + 1) / n
            s = 10 * s**3 - 15 * s**4 + 6 * s**5  # minimum jerk
            d.ctrl[act] = q0 + (q1 - q0) * s
            d.ctrl[suc] = u
            mujoco.mj_step(m, d)
            if track:
                R = d.site(c.tcp_site).xmat.reshape(3, 3)
                rel = R.T @ (d.body(part).xpos - d.site(c.tcp_site).xpos)
                ref[0] = rel if ref[0] is None else ref[0]
                slip[0] = max(slip[0], float(np.linalg.norm(rel - ref[0])))

    d.ctrl[act] = q_above
    move(q_above, q_touch, 0.4, 0.0)
    move(q_touch, q_touch, 0.2, suction)
    move(q_touch, q_lift, 0.5, suction, track=True)
    if swing:
        q_sw = q_lift.copy()
        q_sw[0] -= np.pi / 2
        move(q_lift, q_sw, 0.5, suction, track=True)
    move(q_lift if not swing else q_sw, q_lift if not swing else q_sw, 0.2, suction, track=True)
    assert all(d.warning[i].number == 0 for i in range(len(d.warning)))
    return d.body(part).xpos[2] - z0, slip[0]


def test_suction_on_lifts_the_part():
    lift, slip = _pick_run(1.0)
    assert lift == pytest.approx(0.10, abs=3e-3)
    assert slip < 1e-3


def test_suction_off_leaves_the_part():
    lift, _ = _pick_run(0.0)
    assert abs(lift) < 1e-3


def test_suction_holds_half_kilo_through_fast_swing():
    # 90 deg of J1 in 0.5 s at ~0.5 m radius: peak tcp acceleration ~20 m/s^2
    lift, slip = _pick_run(1.0, mass=0.5, swing=True)
    assert lift == pytest.approx(0.10, abs=3e-3)
    assert slip < 3e-3  # soft-friction creep only (see sim.cells.tools)


# ---------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs,exc,needles", [
    (dict(cell="weld_cylindre", robot="robot_5r"), UnknownNameError,
     ["weld_cylinder", "weld_table", "pick", "did you mean"]),
    (dict(cell="weld_table", robot="lrmate300"), UnknownNameError, list(ROBOTS)),
    (dict(cell="weld_cylinder", robot="lrmate200ic5l"), CellsimError, ["robot_5r"]),
    (dict(cell="pick", robot="lrmate100ib"), CellsimError, ["lrmate200ic5l"]),
    (dict(cell="weld_table", robot="lrmate100ib", tool="gripper"), UnknownNameError, list(TOOLS)),
    (dict(cell="pick", robot="lrmate200ic5l", tool="mig_torch"), CellsimError,
     ["vacuum_gripper"]),
    (dict(cell="weld_table", robot="lrmate100ib", mount="wall"), UnknownNameError,
     ["floor", "ceiling"]),
    (dict(cell="weld_table", robot="lrmate100ib", mount="ceiling"), CellsimError, ["floor"]),
    (dict(cell="weld_table", robot="lrmate100ib", tool="none"), CellsimError, ["mig_torch"]),
    (dict(cell=None, robot="robot_5r", payload_kg=-1.0), CellsimError, ["payload_kg", ">= 0"]),
    (dict(cell=None, robot="robot_5r", payload_kg=float("nan")), CellsimError, ["payload_kg"]),
])
def test_bad_input_one_line(kwargs, exc, needles):
    kw = dict(kwargs)
    cell, robot = kw.pop("cell"), kw.pop("robot")
    with pytest.raises(exc) as info:
        # names resolve through the registries (the scenario loader's way), then compose
        cspec = BARE if cell is None else CELLS.get(cell)
        if "tool" in kw:
            kw["tool"] = resolve_tool(cspec, kw["tool"])
        build_cell(cspec, ROBOTS.get(robot), **kw)
    msg = str(info.value)
    assert "\n" not in msg
    for n in needles:
        assert n in msg, msg


def test_tool_choice_and_no_tool():
    c = build_cell(None, ROBOTS["lrmate200ic5l"])
    assert c.tool is None and c.tip_site is None and c.adhesion_actuator is None
    table = CELLS["weld_table"]
    c = build_cell(table, ROBOTS["lrmate100ib"], tool=resolve_tool(table, "mig_torch_long"))
    assert c.tool.name == "mig_torch_long"
    c = build_cell(None, ROBOTS["lrmate200ic5l"], tool=resolve_tool(BARE, "none"))
    assert c.tool is None
