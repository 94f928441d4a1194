"""Composition of a cell with ``dm_control.mjcf``: robot + tool + payload + world.

Steps (:func:`prepare_robot`, :func:`new_world`, :func:`attach_robot`, :func:`finish`):

1. The robot's MJCF (``models/<folder>/<robot>.xml``) is loaded and renamed ``robot`` (every name
   in the composed model is then ``robot/<name>``, e.g. ``robot/j1``). Its keyframes are removed
   (their ``qpos`` would not match the composed model) and its ``home`` keyframe is kept as
   ``home_q``; the cell adds its own ``home`` keyframe covering every degree of freedom.
2. The tool (:mod:`sim.cells.tools`) is attached with ``site.attach`` at a site ``tool_mount`` placed on
   the robot's ``flange`` site and turned so that the tool frame's ``+z`` is the flange approach
   axis. The approach axis is the seeds' (5r: frame 6 x axis; fanuc6: ``a = z6``), which both
   point along frame 0's ``+x`` at ``q = 0``; it is expressed in the flange site's frame from
   the compiled robot at ``q = 0``. Tool names become ``robot/tool/<name>``.
3. The robot's ``tcp`` site is moved onto the tool tip: ``flange + length * approach``, keeping
   its orientation. The tcp therefore lies on the flange axis and the closed forms hold with
   ``l3 = (J4 -> flange) + length`` (5r) or ``r = length`` (fanuc6); see :func:`tool_kinematics`.
4. A body ``robot/payload`` at the tcp carries the payload: a lumped mass with the inertia of
   a solid steel sphere (7850 kg/m^3) of that mass, ``I = 2/5 m r^2``; it touches nothing. At
   0 kg it is massless and its marker invisible (one model structure for every payload).
5. The world (floor, sky, lights, cameras, offscreen buffer 1920x1080) receives the robot through
   an attachment frame: ``floor`` mount = upright at a height (a riser or column), ``ceiling`` =
   turned 180 deg about the world x axis (base up, J1 axis pointing down) under a ceiling plate.

Contacts: the cell's static geometry and the parts use the bit masks of :mod:`sim.cells.tools`;
the robot's link geoms get ``contype = conaffinity = 0`` in a cell (:func:`prepare_robot`), so
in the simulation the arm touches neither itself nor the cell: collisions are a geometric
question answered along the motion on a check model (:mod:`sim.simulation.collisions`), and
contact forces must not pollute the joint torques used for sizing. Parts touch the fixtures,
each other and the suction cup.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sim.cells.payload import payload_inertia, payload_marker
from sim.cells.tools import (
    CONTACT_FIXTURE,
    CUP_BODY,
    SUCTION_ACTUATOR,
    TIP_SITE,
    ToolSpec,
    build_tool,
)
from sim.errors import CellsimError
from sim.robots.kinematics.model import KinematicModel, kinematic_model
from sim.robots.registry import COULOMB_SPEED, RobotSpec

if TYPE_CHECKING:  # MuJoCo and dm_control are imported where a model is made or compiled
    import mujoco
    from dm_control import mjcf

    from sim.cells.mechanisms import PlacedMechanism

ROBOT_PREFIX = "robot"
#: Name prefix of the robot's friction actuators (``robot/friction_j1``, ...).
FRICTION_PREFIX = "friction_"
TOOL_PREFIX = "tool"
#: Offscreen framebuffer (pixels): large enough for 1280x720 and 1920x1080 renders.
OFFSCREEN = (1920, 1080)


# ---------------------------------------------------------------------------- small helpers
def quat_from_matrix(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unit quaternion (w, x, y, z) of a rotation matrix (3, 3)."""
    import mujoco

    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.asarray(R, dtype=float).reshape(9))
    return q


def matrix_from_quat(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation matrix (3, 3) of a quaternion (w, x, y, z)."""
    import mujoco

    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(q, dtype=float) / np.linalg.norm(q))
    return R.reshape(3, 3)


def rotation_between(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Smallest rotation (3, 3) taking unit vector ``a`` onto unit vector ``b``."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v, c = np.cross(a, b), float(a @ b)
    if c < -1.0 + 1e-12:  # opposite: turn by pi about any perpendicular
        p = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
        p /= np.linalg.norm(p)
        return 2.0 * np.outer(p, p) - np.eye(3)
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1.0 + c)


def transform(R: NDArray[np.float64] | None = None, p=(0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    """Homogeneous transform (4, 4) from a rotation (3, 3) and a translation (3,)."""
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


def look_at_xyaxes(pos, target, up=(0.0, 0.0, 1.0)) -> list[float]:
    """MJCF camera ``xyaxes`` for a camera at ``pos`` looking at ``target`` (world, m)."""
    fwd = np.asarray(target, float) - np.asarray(pos, float)
    fwd /= np.linalg.norm(fwd)
    x = np.cross(fwd, up)
    if np.linalg.norm(x) < 1e-6:
        x = np.cross(fwd, [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(x, fwd)
    return [*x.tolist(), *y.tolist()]


def _snap(v: NDArray[np.float64]) -> NDArray[np.float64]:
    v = np.where(np.abs(v) < 1e-9, 0.0, v)
    v = np.where(np.abs(np.abs(v) - 1.0) < 1e-9, np.sign(v), v)
    return v / np.linalg.norm(v)


# ---------------------------------------------------------------------------- robot statics
@dataclass(frozen=True)
class RobotStatics:
    """Constant geometry of a bare robot model at q = 0 (robot base frame = MJCF world).

    Attributes:
        base_from_frame0: Pose of site ``frame0`` in the robot's base frame, (4, 4).
        flange_body: Name of the body carrying the ``flange`` site.
        flange_local: Pose of ``flange`` in that body, (4, 4).
        tcp_body: Name of the body carrying the ``tcp`` site.
        approach_flange: Unit approach axis in the flange site's frame, (3,).
        tcp_minus_flange: Bare tcp position minus flange position along the approach axis, m.
        flange_axial: Distance along the approach axis from the J4 axis (5r) or the wrist centre
            (fanuc6, J5 anchor) to the flange, m, measured in the MJCF.
        home_q: Joint values of the robot's ``home`` keyframe (zeros without one), rad, (n,).
        frictionloss: Coulomb friction of each robot joint, N m, (n,) (the MJCF's
            ``frictionloss``; the composed robot applies it with friction actuators).
    """

    base_from_frame0: NDArray[np.float64]
    flange_body: str
    flange_local: NDArray[np.float64]
    tcp_body: str
    tcp_local_pos: NDArray[np.float64]
    tcp_local_rot: NDArray[np.float64]
    approach_flange: NDArray[np.float64]
    tcp_minus_flange: float
    flange_axial: float
    home_q: NDArray[np.float64]
    frictionloss: NDArray[np.float64]


def _site_pose(m: mujoco.MjModel, d: mujoco.MjData, name: str) -> NDArray[np.float64]:
    import mujoco

    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)
    if i < 0:
        raise CellsimError(f"robot model has no site {name!r}")
    return transform(d.site_xmat[i].reshape(3, 3), d.site_xpos[i])


def robot_statics(spec: RobotSpec) -> RobotStatics:
    """Measure a robot model's constant geometry (cached per robot name).

    Raises:
        CellsimError: The model file is missing or lacks the sites the cells rely on.
    """
    return _robot_statics(spec)


@lru_cache(maxsize=None)
def _robot_statics(spec: RobotSpec) -> RobotStatics:
    import mujoco

    if not spec.robot_path.is_file():
        raise CellsimError(f"robot {spec.name!r}: model file {spec.robot_path} is missing")
    m = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    T0, Tf, Tt = (_site_pose(m, d, s) for s in ("frame0", "flange", "tcp"))
    zeros = np.zeros(spec.n_joints)
    a0 = spec.family.home_approach()
    a_world = T0[:3, :3] @ a0
    a_fl = _snap(Tf[:3, :3].T @ a_world)
    fid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "flange")
    tid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "tcp")
    if m.body_weldid[m.site_bodyid[fid]] != m.body_weldid[m.site_bodyid[tid]]:
        raise CellsimError(f"robot {spec.name!r}: sites flange and tcp are not on one rigid body")
    off = Tt[:3, 3] - Tf[:3, 3]
    along = float(off @ a_world)
    if np.linalg.norm(off - along * a_world) > 1e-9:
        raise CellsimError(f"robot {spec.name!r}: the bare tcp is not on the flange axis")
    wrist_joint = spec.joints[spec.family.wrist_joint]
    wid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, wrist_joint)
    if wid < 0:
        raise CellsimError(f"robot {spec.name!r}: model has no joint {wrist_joint!r}")
    flange_axial = float((Tf[:3, 3] - d.xanchor[wid]) @ a_world)
    home = zeros.copy()
    kid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home")
    if kid >= 0:
        home = np.array([m.key_qpos[kid][m.jnt_qposadr[mujoco.mj_name2id(
            m, mujoco.mjtObj.mjOBJ_JOINT, j)]] for j in spec.joints])
    return RobotStatics(
        base_from_frame0=T0,
        flange_body=m.body(m.site_bodyid[fid]).name,
        flange_local=transform(matrix_from_quat(m.site_quat[fid]), m.site_pos[fid]),
        tcp_body=m.body(m.site_bodyid[tid]).name,
        tcp_local_pos=m.site_pos[tid].copy(),
        tcp_local_rot=matrix_from_quat(m.site_quat[tid]),
        approach_flange=a_fl,
        tcp_minus_flange=along,
        flange_axial=flange_axial,
        home_q=home,
        frictionloss=np.array([m.dof_frictionloss[m.jnt_dofadr[mujoco.mj_name2id(
            m, mujoco.mjtObj.mjOBJ_JOINT, j)]] for j in spec.joints]),
    )


# ---------------------------------------------------------------------------- robot rig
@dataclass
class RobotRig:
    """A robot model ready to attach: renamed ``robot``, tool and payload mounted.

    Attributes:
        spec: The robot.
        tool: The tool, or None.
        model: The robot's ``dm_control`` model (with the tool attached).
        statics: Constant geometry of the bare robot.
        tcp_from_flange: Distance flange -> tcp along the approach axis with the tool, m.
        tool_body: Body the ``tool`` camera follows (the tool's top body, else the flange body).
        payload_kg: Lumped payload at the tcp, kg.
        tcp_local: Pose of the tcp site in the flange body for a tool that is not straight
            (:attr:`ToolSpec.straight`), (4, 4); None otherwise.
    """

    spec: RobotSpec
    tool: ToolSpec | None
    model: mjcf.RootElement
    statics: RobotStatics
    tcp_from_flange: float
    tool_body: mjcf.Element
    payload_kg: float = 0.0
    home_q: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    tcp_local: NDArray[np.float64] | None = None
    prefix: str = ROBOT_PREFIX

    @property
    def frame0_height(self) -> float:
        """Height of frame 0 above the robot's base plane, m."""
        return float(self.statics.base_from_frame0[2, 3])

    def max_distance_from_frame0(self) -> float:
        """Upper bound of the tcp's distance from frame 0 (sum of link lengths), m."""
        reach = self.statics.flange_axial + self.tcp_from_flange
        return self.spec.family.reach() + reach

    def kinematics(self) -> KinematicModel:
        """Closed-form kinematic model whose tool frame is this rig's tcp (the tool tip).

        The family's wrist-to-tcp distance becomes ``flange_axial + tcp_from_flange``
        (:meth:`KinematicFamily.with_tool`: 5R ``l3``, 200iC ``R6 + r``, seed 004 eq. 6-7). The
        tcp's constant rotation relative to the seed's tool frame is the bare robot's (read
        from the MJCF).
        """
        km = kinematic_model(self.spec)
        if self.tcp_local is not None:
            # a tool that is not straight: the seed's tool frame on the flange, and the
            # constant flange -> tcp transform as the model's tcp offset
            km_f = km.with_family(km.family.with_tool(self.statics.flange_axial))
            km_f.tcp_offset = transform(km.tcp_offset[:3, :3])
            st = self.statics
            bare = transform(st.tcp_local_rot, st.flange_local[:3, 3])  # bare tcp at the flange
            offset = km_f.tcp_offset @ np.linalg.solve(bare, self.tcp_local)
            offset[np.abs(offset) < 1e-15] = 0.0
            return dataclasses.replace(km_f, tcp_offset=offset)
        reach = self.statics.flange_axial + self.tcp_from_flange
        km = km.with_family(km.family.with_tool(reach))
        km.tcp_offset = transform(km.tcp_offset[:3, :3])
        return km


def prepare_robot(spec: RobotSpec, tool: ToolSpec | None, payload_kg: float = 0.0,
                  prefix: str = ROBOT_PREFIX) -> RobotRig:
    """Load the robot, attach the tool at its flange, move its tcp, add the payload.

    ``prefix`` names the robot's model (its names become ``<prefix>/<name>``): ``robot`` for a
    cell's robot, the cell file's name for each of its other robots (``[[robots]]``)."""
    from dm_control import mjcf

    st = robot_statics(spec)
    robot = mjcf.from_path(str(spec.robot_path))
    for key in robot.find_all("key"):
        key.remove()
    robot.model = prefix
    # the arm makes no contact in the simulation (module docstring): its collision geoms are
    # checked geometrically by sim.simulation.collisions
    for geom in robot.find_all("geom"):
        geom.contype = 0
        geom.conaffinity = 0
    if tool is not None and tool.suction_gain_n > 0.0:
        # implicitfast diverged with an adhesion-held 0.5 kg part (the part tumbles); the full
        # implicit integrator (also supported by mj_inverse's invdiscrete) holds it: see sim.cells.tools
        robot.option.integrator = "implicit"
    # Coulomb friction as the drives see it (sim.robots.registry.coulomb): MuJoCo's frictionloss
    # is a soft constraint whose force depends on the timestep; a friction actuator per joint
    # applies F * clip(qd / COULOMB_SPEED, -1, 1) exactly (affine velocity bias, clamped to +-F,
    # integrated implicitly like damping)
    for j, F in zip(spec.joints, st.frictionloss, strict=True):
        if F <= 0.0:
            continue
        joint = robot.find("joint", j)
        joint.frictionloss = 0.0
        robot.actuator.add("general", name=f"{FRICTION_PREFIX}{j}", joint=joint, gaintype="fixed",
                           gainprm=[0.0], biastype="affine",
                           biasprm=[0.0, 0.0, -float(F) / COULOMB_SPEED], ctrllimited=False,
                           forcelimited=True, forcerange=[-float(F), float(F)])
    flange = robot.find("site", "flange")
    tcp = robot.find("site", "tcp")
    if flange is None or tcp is None:
        raise CellsimError(f"robot {spec.name!r}: model lacks the flange or tcp site")
    flange_body = flange.parent
    tool_body = flange_body
    tcp_from_flange = st.tcp_minus_flange
    Rf, pf = st.flange_local[:3, :3], st.flange_local[:3, 3]
    if tool is not None:
        R_mount = Rf @ rotation_between(np.array([0.0, 0.0, 1.0]), st.approach_flange)
        mount = flange_body.add("site", name="tool_mount", pos=pf, quat=quat_from_matrix(R_mount),
                                size=[0.004], group=4)
        tool_model = build_tool(tool)
        tool_model.model = TOOL_PREFIX
        mount.attach(tool_model)
        tool_body = tool_model.worldbody.body[0]
        tcp_from_flange = tool.length_m
    if tcp.parent is not flange_body:
        raise CellsimError(f"robot {spec.name!r}: sites flange and tcp must share a body")
    tcp_local = None
    if tool is not None and not tool.straight:
        # the tcp site turned by the tool's tcp rotation (expressed in the flange body), so that
        # an unturned tcp keeps the bare tcp's axes; placed at the tool's tcp
        X = tool.tcp_pose()
        tcp_pos = pf + R_mount @ X[:3, 3]
        R_tcp = R_mount @ X[:3, :3] @ R_mount.T @ st.tcp_local_rot
        tcp.quat = quat_from_matrix(R_tcp)
        tcp_local = transform(R_tcp, tcp_pos)
        tcp_from_flange = float(np.linalg.norm(X[:3, 3]))
    else:
        tcp_pos = pf + Rf @ (tcp_from_flange * st.approach_flange)
    tcp.pos = tcp_pos
    # every cell has the payload body, massless at 0 kg: one model structure for every
    # payload (a sweep's variants share their cell and its collision scan, 0 kg included)
    radius, rgba = payload_marker(payload_kg)
    body = flange_body.add("body", name="payload", pos=tcp_pos)
    body.add("inertial", pos=[0.0, 0.0, 0.0], mass=payload_kg,
             diaginertia=[payload_inertia(payload_kg)] * 3)
    body.add("geom", name="payload", type="sphere", size=[radius], contype=0, conaffinity=0,
             group=1, rgba=rgba)
    return RobotRig(spec=spec, tool=tool, model=robot, statics=st,
                    tcp_from_flange=tcp_from_flange, tool_body=tool_body,
                    payload_kg=payload_kg, home_q=st.home_q.copy(), tcp_local=tcp_local,
                    prefix=prefix)


# ---------------------------------------------------------------------------- world
def new_world(name: str, center=(0.0, 0.0, 0.8), extent: float = 3.0) -> mjcf.RootElement:
    """Empty world: floor (contacts parts only), sky, lights, offscreen buffer, visual quality."""
    from dm_control import mjcf

    w = mjcf.RootElement(model=name)
    g = getattr(w.visual, "global")
    g.offwidth, g.offheight = OFFSCREEN
    g.azimuth, g.elevation = 140.0, -25.0
    w.visual.quality.shadowsize = 2048  # 4096 costs 50 % more per frame on software GL
    w.visual.headlight.ambient = (0.3, 0.3, 0.3)
    w.visual.headlight.diffuse = (0.5, 0.5, 0.5)
    w.visual.headlight.specular = (0.0, 0.0, 0.0)
    w.visual.map.znear = 0.005
    w.visual.map.zfar = 50.0
    # the haze where the floor meets the sky: the sky's colour at the horizon, not MuJoCo's
    # default white (a bright line across every frame)
    w.visual.rgba.haze = (0.25, 0.34, 0.435, 1.0)
    w.statistic.center = center
    w.statistic.extent = extent
    w.asset.add("texture", name="sky", type="skybox", builtin="gradient",
                rgb1=(0.45, 0.6, 0.75), rgb2=(0.05, 0.08, 0.12), width=512, height=3072)
    tex = w.asset.add("texture", name="floor", type="2d", builtin="checker", mark="edge",
                      rgb1=(0.32, 0.34, 0.36), rgb2=(0.26, 0.28, 0.30),
                      markrgb=(0.55, 0.55, 0.55), width=300, height=300)
    w.asset.add("material", name="floor", texture=tex, texuniform=True, texrepeat=(4, 4),
                reflectance=0.05)
    for mname, rgba in (("steel", (0.55, 0.57, 0.6, 1)), ("dark_steel", (0.3, 0.32, 0.35, 1)),
                        ("fixture", (0.2, 0.35, 0.55, 1)), ("table", (0.45, 0.42, 0.38, 1)),
                        ("concrete", (0.62, 0.62, 0.6, 1)), ("seam", (1.0, 0.45, 0.1, 1)),
                        ("part", (0.85, 0.55, 0.2, 1)), ("slot", (0.2, 0.8, 0.3, 1))):
        w.asset.add("material", name=mname, rgba=rgba, specular=0.3, shininess=0.3)
    w.worldbody.add("geom", name="floor", type="plane", size=[0, 0, 0.05], material="floor",
                    contype=CONTACT_FIXTURE, conaffinity=CONTACT_FIXTURE)
    # shadows from a spot light (clean shadow maps); the sun and fill lights cast none
    c = np.asarray(center, dtype=float)
    key_pos = c + extent * np.array([0.35, -0.35, 1.0])
    w.worldbody.add("light", name="key", pos=key_pos, dir=c - key_pos, directional=False,
                    cutoff=50.0, exponent=1.0, attenuation=(1.0, 0.0, 0.0),
                    diffuse=(0.55, 0.55, 0.55), specular=(0.2, 0.2, 0.2), castshadow=True)
    w.worldbody.add("light", name="sun", pos=[0, 0, 6], dir=[0.2, 0.3, -1.0], directional=True,
                    diffuse=(0.3, 0.3, 0.3), specular=(0.1, 0.1, 0.1), castshadow=False)
    w.worldbody.add("light", name="fill", pos=[3, -3, 4], dir=[-0.5, 0.5, -0.7],
                    directional=True, diffuse=(0.2, 0.2, 0.2), castshadow=False)
    return w


def mount_transform(mount: str, height: float) -> NDArray[np.float64]:
    """Pose of the robot's base frame in world for a mount at ``height`` (m), (4, 4).

    ``floor``: upright, base plane at ``z = height``. ``ceiling``: base plane at ``z = height``,
    turned 180 deg about the world x axis (J1 axis pointing down; frame 0's y and z flip).
    """
    if mount == "floor":
        return transform(None, (0.0, 0.0, height))
    if mount == "ceiling":
        return transform(np.diag([1.0, -1.0, -1.0]), (0.0, 0.0, height))
    raise CellsimError(f"unknown mount {mount!r}; known: ceiling, floor")


def attach_robot(world: mjcf.RootElement, rig: RobotRig, mount: str, height: float
                 ) -> NDArray[np.float64]:
    """Attach the rig to the world; returns ``world_from_frame0`` (4, 4)."""
    T = mount_transform(mount, height)
    frame = world.worldbody.attach(rig.model)
    frame.pos = T[:3, 3]
    frame.quat = quat_from_matrix(T[:3, :3])
    return T @ rig.statics.base_from_frame0


def add_cameras(world: mjcf.RootElement, rig: RobotRig, overview_pos, overview_target,
                tool_pos, tool_fovy: float = 30.0) -> list[str]:
    """Add the ``overview`` (fixed) and ``tool`` (fixed position, aims at the tool) cameras."""
    world.worldbody.add("camera", name="overview", pos=overview_pos,
                        xyaxes=look_at_xyaxes(overview_pos, overview_target), fovy=45.0)
    world.worldbody.add("camera", name="tool", pos=tool_pos, mode="targetbody",
                        target=rig.tool_body, fovy=tool_fovy)
    return ["overview", "tool"]


def add_box(body: mjcf.Element, name: str, center, half_size, material: str,
            R: NDArray[np.float64] | None = None, contact: bool = True) -> mjcf.Element:
    """Static box (a fixture: touches parts only when ``contact``)."""
    kw = {} if R is None else {"quat": quat_from_matrix(R)}
    bits = CONTACT_FIXTURE if contact else 0
    return body.add("geom", name=name, type="box", pos=center, size=half_size,
                    material=material, contype=bits, conaffinity=bits, **kw)


class Ring(list):
    """The staves of :func:`add_ring` (a list of geoms) with the ring's parameters
    (``params``: radii, heights, angles in m and rad), so a cell can be written as a file."""

    params: dict


def add_ring(body: mjcf.Element, name: str, r_in: float, r_out: float, z0: float, z1: float,
             material: str, n: int = 72, phi0: float = 0.0, phi1: float = 2 * np.pi,
             center=(0.0, 0.0), contact: bool = True) -> list[mjcf.Element]:
    """Cylindrical shell segment (annulus r_in..r_out, z0..z1) from ``n`` box staves.

    Each stave's outer face is tangent to ``r_out`` at its middle (the true cylinder is met at
    ``n`` lines; the faceting error at r_out is ``r_out (1/cos(pi/n) - 1)``). Returns the
    staves (one object of the cell: :attr:`Layout.objects`).
    """
    staves = Ring()
    staves.params = {"r_in": float(r_in), "r_out": float(r_out), "z0": float(z0),
                     "z1": float(z1), "material": material, "n": int(n), "phi0": float(phi0),
                     "phi1": float(phi1), "center": (float(center[0]), float(center[1])),
                     "contact": bool(contact)}
    dphi = (phi1 - phi0) / n
    half_w = r_out * np.tan(dphi / 2.0)
    rm = (r_in + r_out) / 2.0
    for k in range(n):
        phi = phi0 + (k + 0.5) * dphi
        R = np.array([[np.cos(phi), -np.sin(phi), 0], [np.sin(phi), np.cos(phi), 0], [0, 0, 1.0]])
        staves.append(add_box(
            body, f"{name}{k}", [center[0] + rm * np.cos(phi), center[1] + rm * np.sin(phi),
                                 (z0 + z1) / 2], [(r_out - r_in) / 2, half_w, (z1 - z0) / 2],
            material, R=R, contact=contact))
    return staves


# ---------------------------------------------------------------------------- finishing
@dataclass
class Layout:
    """What a cell builder returns besides the world it filled.

    Attributes:
        world: The composed world.
        world_from_frame0: Pose of frame 0 in world, (4, 4).
        seams: Seams by name (world frame).
        parts: Free-body names, in order.
        slots: Target positions (P, 3), world, m.
        cameras: Camera names.
        start_q: Robot configuration at the start of the first seam (welding cells), rad.
        dims: Key dimensions of the cell for reports, m (names documented by each builder).
        objects: Cell objects made of several geoms (a ring of staves), by object name; a
            static geom in no object is an object of its own (its name). Collision reports
            name objects, not staves.
        seam_objects: Names of the objects each seam joins (the seam's workpieces): the
            welding wire may touch them while the arc is on along that seam.
    """

    world: mjcf.RootElement
    world_from_frame0: NDArray[np.float64]
    seams: dict = field(default_factory=dict)
    parts: list[str] = field(default_factory=list)
    slots: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 3)))
    cameras: list[str] = field(default_factory=list)
    start_q: NDArray[np.float64] | None = None
    home_q: NDArray[np.float64] | None = None
    dims: dict[str, float] = field(default_factory=dict)
    objects: dict[str, list[mjcf.Element]] = field(default_factory=dict)
    seam_objects: dict[str, tuple[str, ...]] = field(default_factory=dict)
    frames: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    mechanisms: tuple[PlacedMechanism, ...] = ()
    partners: tuple[Any, ...] = ()  # sim.cells.partners.CellRobot (which imports this module)


def compile_model(world: mjcf.RootElement) -> mujoco.MjModel:
    """Compile a ``dm_control`` model with MuJoCo (raises CellsimError on compiler errors)."""
    import mujoco

    try:
        return mujoco.MjModel.from_xml_string(world.to_xml_string(), world.get_assets())
    except ValueError as exc:  # mujoco reports XML/compile errors as ValueError
        # (on two lines: the error, then the element): one line
        text = "; ".join(line.strip() for line in str(exc).splitlines() if line.strip())
        raise CellsimError(f"cell model does not compile: {text}") from None


def add_home_keyframe(world: mjcf.RootElement, rig: RobotRig, home_q: NDArray[np.float64],
                      mechanisms: tuple[PlacedMechanism, ...] = (),
                      partners: tuple[Any, ...] = ()) -> tuple[mujoco.MjModel, NDArray[np.float64]]:
    """Add keyframe ``home``: robot at ``home_q``, the mechanisms at their home, the other
    robots at theirs, free bodies where built, suction off. Returns the model compiled before
    the keyframe was added (the same but for the keyframe) and the keyframe's ``qpos``."""
    import mujoco

    try:  # the MJCF written and parsed once: the keyframe is added to its spec as well
        spec = mujoco.MjSpec.from_string(world.to_xml_string(), assets=world.get_assets())
        m = spec.compile()
    except ValueError:
        compile_model(world)  # raises CellsimError, MuJoCo's message on one line
        raise
    qpos, ctrl = m.qpos0.copy(), np.zeros(m.nu)
    values = [(f"{ROBOT_PREFIX}/{j}", qj) for j, qj in zip(rig.spec.joints, home_q, strict=True)]
    for pm in mechanisms:
        values += list(zip(pm.joint_names, pm.home, strict=True))
    for cr in partners:
        values += list(zip(cr.placed.joint_names, cr.home_q, strict=True))
    for name, qj in values:
        qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)]] = qj
    for a in range(m.nu):
        if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT:
            jid = m.actuator_trnid[a, 0]
            ctrl[a] = qpos[m.jnt_qposadr[jid]]
    world.keyframe.add("key", name="home", qpos=qpos, ctrl=ctrl)
    return m, qpos


def suction_actuator_name(rig: RobotRig) -> str | None:
    """Full name of the suction actuator, or None when the tool has none."""
    if rig.tool is None or rig.tool.suction_gain_n <= 0.0:
        return None
    return f"{ROBOT_PREFIX}/{TOOL_PREFIX}/{SUCTION_ACTUATOR}"


def tip_site_name(rig: RobotRig) -> str | None:
    """Full name of the tool's ``tip`` site, or None without a tool."""
    return None if rig.tool is None else f"{ROBOT_PREFIX}/{TOOL_PREFIX}/{TIP_SITE}"


def cup_body_name(rig: RobotRig) -> str | None:
    """Full name of the suction-cup body, or None."""
    if suction_actuator_name(rig) is None:
        return None
    return f"{ROBOT_PREFIX}/{TOOL_PREFIX}/{CUP_BODY}"


Builder = Callable[[RobotRig, str], Layout]
