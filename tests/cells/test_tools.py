"""End-of-arm tools (issue 4 section 1): masses, straight geometry, attachment at the flange and
the tcp moved to the tool tip (checked against the seeds' closed forms with the tool length
added), payload, suction-cup contact semantics."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from sim.cells import build_cell
from sim.cells.tools import (
    CUP_BODY,
    SUCTION_ACTUATOR,
    TIP_SITE,
    TOOLS,
    build_tool,
    get_tool,
)
from sim.errors import UnknownNameError
from sim.robots.families import Fanuc6, FiveR
from sim.robots.kinematics.closed_form import fk_5r, fk_fanuc6
from sim.robots.registry import ROBOTS, get_robot

RNG = np.random.default_rng(7)


def _compile(model) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(model.to_xml_string(), model.get_assets())


@pytest.mark.parametrize("name", sorted(TOOLS))
def test_tool_mass_and_straight_geometry(name):
    spec = TOOLS[name]
    m = _compile(build_tool(TOOLS[name]))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    # the geoms' masses (from densities x volumes) add up to the stated tool mass (1 %)
    assert m.body_subtreemass[0] == pytest.approx(spec.mass_kg, rel=0.01)
    # straight tool: centre of mass on the axis, between the flange face and the tip
    com = d.subtree_com[0]
    assert np.hypot(com[0], com[1]) < 1e-9
    assert 0.0 < com[2] < spec.length_m
    # tip site on the axis at the tool length, oriented as the tool frame
    sid = m.site(TIP_SITE).id
    np.testing.assert_allclose(d.site_xpos[sid], [0.0, 0.0, spec.length_m], atol=1e-12)
    np.testing.assert_allclose(d.site_xmat[sid].reshape(3, 3), np.eye(3), atol=1e-12)
    # no geom reaches beyond the tip or behind the flange face
    for g in range(m.ngeom):
        lo, hi = d.geom_xpos[g][2] - m.geom_rbound[g], d.geom_xpos[g][2] + m.geom_rbound[g]
        assert hi <= spec.length_m + max(m.geom_rbound[g], 1e-9) and lo >= -m.geom_rbound[g]
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER:
            # cylinders run along the tool axis, their far end not beyond the tip
            assert d.geom_xpos[g][2] + m.geom_size[g][1] <= spec.length_m + 1e-12


def test_torch_geoms_touch_nothing():
    for name in ("mig_torch", "mig_torch_long"):
        m = _compile(build_tool(TOOLS[name]))
        assert np.all(m.geom_contype == 0) and np.all(m.geom_conaffinity == 0)


def test_vacuum_gripper_adhesion_actuator():
    spec = get_tool("vacuum_gripper")
    m = _compile(build_tool(TOOLS["vacuum_gripper"]))
    a = m.actuator(SUCTION_ACTUATOR)
    assert m.actuator_trntype[a.id] == mujoco.mjtTrn.mjTRN_BODY
    assert m.actuator_trnid[a.id, 0] == m.body(CUP_BODY).id
    np.testing.assert_allclose(m.actuator_ctrlrange[a.id], [0.0, 1.0])
    assert m.actuator_gainprm[a.id, 0] == pytest.approx(spec.suction_gain_n)
    # the lip: geoms of the cup body that collide, active only on penetration (margin 0) but
    # detected 3 mm before (gap), so that suction reaches a part lying just below the lip
    lips = [g for g in range(m.ngeom)
            if m.geom_bodyid[g] == m.body(CUP_BODY).id and m.geom_contype[g]]
    assert len(lips) >= 3
    for g in lips:
        assert m.geom_margin[g] == 0.0 and m.geom_gap[g] > 0.0
        # lip bottoms lie exactly in the tcp plane z = length
        assert m.geom_pos[g][2] + m.geom_size[g][0] == pytest.approx(spec.length_m)


@pytest.mark.parametrize("dist, active", [(0.002, False), (-0.0005, True), (0.004, None)])
def test_mujoco_margin_gap_semantics(dist, active):
    """The gripper relies on MuJoCo 4's reading of margin/gap (measured, not assumed): a contact
    is active below ``margin`` and detected-but-inactive for a further ``gap``."""
    xml = f"""<mujoco><worldbody>
      <body pos="0 0 0.1"><geom type="sphere" size="0.01" margin="0" gap="0.003"/></body>
      <body pos="0 0 {0.08 - dist}"><freejoint/><geom type="box" size="0.01 0.01 0.01"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    if active is None:
        assert d.ncon == 0
        return
    assert d.ncon == 1
    assert d.contact[0].dist == pytest.approx(dist, abs=1e-9)
    assert (d.contact[0].exclude == 0) == active


def test_unknown_tool_lists_choices():
    with pytest.raises(UnknownNameError) as exc:
        build_tool(TOOLS.get("mig_torhc"))
    msg = str(exc.value)
    assert "\n" not in msg and "did you mean 'mig_torch'" in msg
    for name in TOOLS:
        assert name in msg


def _bare_robot(spec):
    m = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    return m, mujoco.MjData(m)


def _pose(m, d, site):
    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, site)
    return d.site_xmat[i].reshape(3, 3).copy(), d.site_xpos[i].copy()


@pytest.mark.parametrize("robot", sorted(ROBOTS))
@pytest.mark.parametrize("tool", sorted(TOOLS))
def test_tcp_on_tool_tip_matches_closed_form(robot, tool):
    """tcp = flange + tool length along the approach axis; MuJoCo vs seed 000 eq. 5 (5r, with
    l3 = l3 - (bare tcp - flange) + length), seed 004 eq. 6-7 (r = length) or, for an arm
    given as data, its URDF joint product."""
    spec = get_robot(robot)
    tl = TOOLS[tool].length_m
    cell = build_cell(None, ROBOTS[robot], tool=TOOLS[tool])
    m = cell.compile()
    d = mujoco.MjData(m)
    mb, db = _bare_robot(spec)
    mujoco.mj_forward(mb, db)
    Rf0, pf0 = _pose(mb, db, "flange")
    Rt0, pt0 = _pose(mb, db, "tcp")
    R00, p00 = _pose(mb, db, "frame0")
    bare_offset = float(np.linalg.norm(pt0 - pf0))  # bare tcp beyond the flange, on its axis
    qadr = [m.joint(j).qposadr[0] for j in cell.joint_names]
    lo, hi = mb.jnt_range[:, 0], mb.jnt_range[:, 1]
    for _ in range(6):
        q = lo + (hi - lo) * RNG.uniform(0.1, 0.9, spec.n_joints)
        d.qpos[qadr] = q
        mujoco.mj_forward(m, d)
        R0, p0 = _pose(m, d, cell.frame0_site)
        Rt, pt = _pose(m, d, cell.tcp_site)
        Rfl, pfl = _pose(m, d, cell.flange_site)
        Rtip, ptip = _pose(m, d, cell.tip_site)
        # MuJoCo: the tool's own tip site is the tcp
        np.testing.assert_allclose(ptip, pt, atol=1e-9)
        # closed form, in frame 0
        rel = R0.T @ (pt - p0)
        if isinstance(spec.family, FiveR):
            dims = {**spec.dims, "l3": spec.dims["l3"] - bare_offset + tl}
            Rcf, pcf = fk_5r(q, dims)
            axis = Rcf[:, 0]
        elif isinstance(spec.family, Fanuc6):
            Rcf, pcf = fk_fanuc6(q, spec.dims, tool_length=tl - bare_offset)
            axis = Rcf[:, 2]
        else:  # an arm given as data: its URDF's joint product, the tool along the flange z
            T = spec.family.arm.chain.fk(q)
            axis = T[:3, 2]
            pcf = T[:3, 3] + (tl - bare_offset) * axis
        np.testing.assert_allclose(rel, pcf, atol=1e-9)
        # the tcp lies on the flange axis, the tool length beyond the flange
        np.testing.assert_allclose(pt, pfl + tl * (R0 @ axis), atol=1e-9)
        # same tcp orientation as the bare robot's at the same q
        db.qpos[:] = q
        mujoco.mj_forward(mb, db)
        Rtb, _ = _pose(mb, db, "tcp")
        Rb0, _ = _pose(mb, db, "frame0")
        np.testing.assert_allclose(R0.T @ Rt, Rb0.T @ Rtb, atol=1e-9)


@pytest.mark.parametrize("robot", ["lrmate200ic5l", "robot_5r"])
def test_payload_lumped_sphere_at_tcp(robot):
    payload = 2.5
    plain = build_cell(None, ROBOTS[robot], tool=TOOLS["mig_torch"]).compile()
    cell = build_cell(None, ROBOTS[robot], tool=TOOLS["mig_torch"], payload_kg=payload)
    m = cell.compile()
    assert m.body_subtreemass[0] - plain.body_subtreemass[0] == pytest.approx(payload)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    b = m.body("robot/payload").id
    assert m.body_mass[b] == pytest.approx(payload)
    np.testing.assert_allclose(d.xipos[b], d.site(cell.tcp_site).xpos, atol=1e-9)
    r = (3 * payload / (4 * np.pi * 7850.0)) ** (1 / 3)  # solid steel sphere of that mass
    np.testing.assert_allclose(m.body_inertia[b], [0.4 * payload * r * r] * 3, rtol=1e-9)
    assert np.all(m.geom_contype[m.geom_bodyid == b] == 0)
