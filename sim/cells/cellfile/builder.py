"""Building a checked cell file's world around a robot rig (MJCF, ``dm_control.mjcf``):
static objects, free parts, seams in world, slots, cameras, the home and start joint values."""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import NDArray

from sim.cells.cellfile.reader import CellFile, joint_values
from sim.cells.cellfile.schema import ROLE_MATERIAL, ObjectBlock
from sim.cells.cellfile.seams import seam_in_world, seam_points, seam_standoff
from sim.cells.cellfile.solids import Solid
from sim.cells.compose import (
    Layout,
    RobotRig,
    add_ring,
    look_at_xyaxes,
    matrix_from_quat,
    new_world,
    prepare_robot,
    quat_from_matrix,
)
from sim.cells.mechanisms import CONTACT_MOVING, add_mechanism
from sim.cells.partners import CellRobot
from sim.cells.seam import Seam
from sim.cells.tools import CONTACT_FIXTURE, CONTACT_PART_AFFINITY, CONTACT_PART_TYPE
from sim.errors import CellError, CellsimError
from sim.robots.kinematics.ik import solve_ik


def _friction(b: ObjectBlock) -> dict:
    return {} if b.friction is None else {"friction": [b.friction, 0.005, 0.0001]}


def _look(b: ObjectBlock, default: str) -> dict:
    if b.color is not None:
        return {"rgba": [*b.color, 1.0][:4]}
    return {"material": b.material or default}


def _add_static(world, b: ObjectBlock, solid: Solid, material: str, body=None,
                pose: NDArray[np.float64] | None = None) -> list:
    """A fixture's or workpiece's geoms, placed in the world body at the object's pose (static
    geometry, as the shipped cells have it), or in ``body`` (a mechanism's mount) at ``pose``
    in it, with the object's mass (``mass_kg``, else solid steel); returns the geoms that
    collide."""
    T = solid.pose if pose is None else pose
    bits = CONTACT_FIXTURE if b.collide else 0
    wb = world.worldbody if body is None else body
    look = _look(b, material)
    common = dict(contype=bits, conaffinity=bits, **_friction(b))
    if body is not None:  # carried by a mechanism: its mass and inertia count
        common.update(_carried_mass(b, solid))
        if b.collide:
            common.update(CONTACT_MOVING)
    R, t = T[:3, :3], T[:3, 3]
    quat = {} if np.array_equal(R, np.eye(3)) else {"quat": quat_from_matrix(R)}
    if b.shape == "box":
        return [wb.add("geom", name=b.name, type="box", pos=t, size=np.asarray(b.size_mm) * 0.5e-3,
                       **quat, **look, **common)]
    if b.shape == "cylinder":
        return [wb.add("geom", name=b.name, type="cylinder", pos=t, **quat,
                       size=[b.radius_mm * 1e-3, b.length_mm * 0.5e-3], **look, **common)]
    if b.shape == "sphere":
        return [wb.add("geom", name=b.name, type="sphere", pos=t, size=[b.radius_mm * 1e-3],
                       **look, **common)]
    if b.shape == "ring":
        half = b.length_mm * 0.5e-3
        a0, a1 = np.deg2rad(b.arc_deg) if b.arc_deg is not None else (0.0, 2 * np.pi)
        mat = b.material or material
        staves = add_ring(wb, b.name, b.inner_radius_mm * 1e-3, b.radius_mm * 1e-3,
                          t[2] - half, t[2] + half, mat, n=b.segments or 72, phi0=a0, phi1=a1,
                          center=(t[0], t[1]), contact=b.collide)
        for g in staves:
            if not np.array_equal(R, np.eye(3)):  # a turned ring: each stave about the origin
                p_local = np.asarray(g.pos) - t
                g.pos = R @ p_local + t
                g.quat = quat_from_matrix(R @ matrix_from_quat(g.quat))
            if b.color is not None:
                g.material = None
                g.rgba = look["rgba"]
            if b.friction is not None:
                g.friction = common["friction"]
            if "density" in common:
                g.density = common["density"]
            if body is not None and b.collide:
                g.contype, g.conaffinity = CONTACT_MOVING["contype"], CONTACT_MOVING["conaffinity"]
        return list(staves) if b.collide else []
    assert solid.verts is not None and solid.faces is not None
    vis = world.asset.add("mesh", name=f"{b.name}_visual", vertex=solid.verts.ravel(),
                          face=solid.faces.ravel(), inertia="shell")
    wb.add("geom", name=f"{b.name}_visual", type="mesh", mesh=vis, pos=t, **quat,
           contype=0, conaffinity=0, group=1, **look, **({} if body is None else {"mass": 0.0}))
    geoms = []
    if b.collide:
        for k, pc in enumerate(solid.pieces):
            mesh = world.asset.add("mesh", name=f"{b.name}_c{k}", vertex=pc.ravel())
            geoms.append(wb.add("geom", name=f"{b.name}_c{k}", type="mesh", mesh=mesh, pos=t,
                                **quat, group=3, rgba=(0.5, 0.5, 0.5, 0.3), **common))
    return geoms


#: Density of a carried object given no ``mass_kg`` (solid steel), kg/m^3.
STEEL_DENSITY = 7850.0


def _carried_mass(b: ObjectBlock, solid: Solid) -> dict:
    """MJCF mass keys of a carried object's geoms: uniform density, its ``mass_kg`` spread over
    its volume (else steel)."""
    if b.mass_kg is None:
        return {"density": STEEL_DENSITY}
    return {"density": float(b.mass_kg) / _volume(b, solid)}


def _volume(b: ObjectBlock, solid: Solid) -> float:
    """The volume MuJoCo gives the object's collision geoms, m^3."""
    if b.shape == "box":
        return float(np.prod(np.asarray(b.size_mm) * 1e-3))
    if b.shape == "cylinder":
        return float(np.pi * (b.radius_mm * 1e-3) ** 2 * b.length_mm * 1e-3)
    if b.shape == "sphere":
        return float(4.0 / 3.0 * np.pi * (b.radius_mm * 1e-3) ** 3)
    if b.shape == "ring":  # its staves (compose.add_ring): n boxes
        n = b.segments or 72
        a0, a1 = np.deg2rad(b.arc_deg) if b.arc_deg is not None else (0.0, 2 * np.pi)
        r_in, r_out = b.inner_radius_mm * 1e-3, b.radius_mm * 1e-3
        half_w = r_out * np.tan((a1 - a0) / n / 2.0)
        return float(n * (r_out - r_in) * 2 * half_w * b.length_mm * 1e-3)
    from scipy.spatial import ConvexHull

    return float(sum(ConvexHull(pc).volume for pc in solid.pieces))


def _add_part(world, b: ObjectBlock, solid: Solid) -> None:
    """A part: a free body at the object's pose; the mass on its collision geoms."""
    T = solid.pose
    R, t = T[:3, :3], T[:3, 3]
    quat = {} if np.array_equal(R, np.eye(3)) else {"quat": quat_from_matrix(R)}
    body = world.worldbody.add("body", name=b.name, pos=t, **quat)
    body.add("freejoint", name=b.name)
    bits = dict(contype=CONTACT_PART_TYPE, conaffinity=CONTACT_PART_AFFINITY) if b.collide \
        else dict(contype=0, conaffinity=0)
    look = _look(b, "part")
    common = dict(condim=4, **bits, **_friction(b))
    if b.shape in ("box", "cylinder", "sphere"):
        size = {"box": lambda: np.asarray(b.size_mm) * 0.5e-3,
                "cylinder": lambda: [b.radius_mm * 1e-3, b.length_mm * 0.5e-3],
                "sphere": lambda: [b.radius_mm * 1e-3]}[b.shape]()
        body.add("geom", name=b.name, type=b.shape, size=size, mass=b.mass_kg, **look, **common)
        return
    if b.shape == "ring":
        raise CellError(f"objects[{solid.index}].shape: a part cannot be a ring")
    from scipy.spatial import ConvexHull

    assert solid.verts is not None and solid.faces is not None
    vis = world.asset.add("mesh", name=f"{b.name}_visual", vertex=solid.verts.ravel(),
                          face=solid.faces.ravel(), inertia="shell")
    body.add("geom", name=f"{b.name}_visual", type="mesh", mesh=vis, contype=0, conaffinity=0,
             group=1, density=0.0, **look)
    vols = np.array([ConvexHull(pc).volume for pc in solid.pieces])
    for k, pc in enumerate(solid.pieces):
        mesh = world.asset.add("mesh", name=f"{b.name}_c{k}", vertex=pc.ravel())
        body.add("geom", name=f"{b.name}_c{k}", type="mesh", mesh=mesh, group=3,
                 rgba=(0.5, 0.5, 0.5, 0.3), mass=b.mass_kg * float(vols[k] / vols.sum()),
                 **common)


def _default_cameras(world, rig: RobotRig, T0: NDArray[np.float64], cf: CellFile,
                     taken: set[str], others: tuple[CellRobot, ...] = ()) -> list[str]:
    """``overview`` framing the robots' work envelopes and every object, and ``tool`` (a fixed
    camera aiming at the first robot's tool)."""
    reach = rig.max_distance_from_frame0()
    spheres = [(T0[:3, 3], reach)] + [(s.pose[:3, 3], s.radius) for s in cf.solids.values()]
    spheres += [(cr.world_from_frame0[:3, 3], cr.rig.max_distance_from_frame0())
                for cr in others]
    lo = np.min([p - r for p, r in spheres], axis=0)
    hi = np.max([p + r for p, r in spheres], axis=0)
    lo[2] = max(lo[2], 0.0)  # nothing below the floor is seen
    hi[2] = max(hi[2], lo[2] + 0.1)
    c = 0.5 * (lo + hi)
    radius = max(float(np.linalg.norm(p - c)) + r for p, r in spheres)
    out = []
    if "overview" not in taken:
        fovy = 45.0
        dist = radius / np.sin(np.deg2rad(fovy / 2))
        d = np.array([1.0, -0.9, 0.65])
        pos = c + dist * d / np.linalg.norm(d)
        world.worldbody.add("camera", name="overview", pos=pos, xyaxes=look_at_xyaxes(pos, c),
                            fovy=fovy)
        out.append("overview")
    if "tool" not in taken:
        d = np.array([0.9, -0.6, 0.45])
        pos = T0[:3, 3] + 1.6 * reach * d / np.linalg.norm(d)
        world.worldbody.add("camera", name="tool", pos=pos, mode="targetbody",
                            target=rig.tool_body, fovy=35.0)
        out.append("tool")
    return out


def _build(cf: CellFile, rig: RobotRig, mount: str) -> Layout:
    """Compose a checked cell file's world around a robot rig."""
    spec = cf.spec
    T_base = cf.base_pose
    world = new_world(f"{spec.name}_{rig.spec.name}", center=tuple(T_base[:3, 3]),
                      extent=3.0 * rig.max_distance_from_frame0())
    mounts = {name: add_mechanism(world, pm) for name, pm in cf.mechanisms.items()}
    if cf.robot_on is None:
        frame = world.worldbody.attach(rig.model)
        frame.pos = T_base[:3, 3]
        frame.quat = quat_from_matrix(T_base[:3, :3])
    else:  # on a track's carriage
        assert cf.robot_local is not None
        L = cf.robot_local
        site = mounts[cf.robot_on].add("site", name="robot_base", pos=L[:3, 3],
                                       quat=quat_from_matrix(L[:3, :3]), size=[0.01], group=4)
        site.attach(rig.model)
    T0 = T_base @ rig.statics.base_from_frame0
    others = []
    for pr in cf.partners.values():  # the cell's other robots, on the floor or the ceiling
        rig_p = prepare_robot(pr.robot, pr.tool, 0.0, prefix=pr.name)
        frame = world.worldbody.attach(rig_p.model)
        frame.pos = pr.base_pose[:3, 3]
        frame.quat = quat_from_matrix(pr.base_pose[:3, :3])
        others.append(CellRobot(pr, rig_p, pr.base_pose @ rig_p.statics.base_from_frame0,
                                home_q=(rig_p.home_q.copy() if pr.home_q is None
                                        else pr.home_q.copy())))
    objects: dict[str, list] = {}
    parts: list[str] = []
    frames: dict[str, NDArray[np.float64]] = {}
    for name, solid in cf.solids.items():
        b = solid.block
        frames[name] = solid.pose.copy()
        if b.role == "part":
            _add_part(world, b, solid)
            parts.append(name)
        else:
            on = cf.mounted.get(name)
            geoms = (_add_static(world, b, solid, ROLE_MATERIAL[b.role]) if on is None
                     else _add_static(world, b, solid, ROLE_MATERIAL[b.role], mounts[on[0]],
                                      on[1]))
            if len(geoms) > 1 or (geoms and geoms[0].name != name):
                objects[name] = geoms
    seams: dict[str, Seam] = {}
    seam_objects: dict[str, tuple[str, ...]] = {}
    for i, sb in enumerate(spec.seams):
        obj = cf.solids[sb.object]
        standoff = seam_standoff(sb, i, rig.tool, cf.where)
        seam = seam_in_world(sb, obj.pose, seam_points(sb, f"seams[{i}]"),
                              tool_axis=rig.spec.family.approach_column,
                              world_from_frame0=T0, standoff=standoff)
        joined = tuple(dict.fromkeys([sb.object, *sb.joins]))
        for sg in ([seam] if seam.kind != "polyline" else [seam, *seam.segments()]):
            seams[sg.name] = sg
            seam_objects[sg.name] = joined
        for cr in others:  # each other robot's tool point on the seam (its tool's stand-off)
            seam_p = seam_in_world(
                sb, obj.pose, seam_points(sb, f"seams[{i}]"),
                tool_axis=cr.robot.family.approach_column, world_from_frame0=cr.world_from_frame0,
                standoff=seam_standoff(sb, i, cr.tool, cf.where))
            for sg in ([seam_p] if seam_p.kind != "polyline" else [seam_p, *seam_p.segments()]):
                cr.seams[sg.name] = sg
    slots = []
    for sl in spec.slots:
        p = np.asarray(sl.pos_mm, dtype=float) * 1e-3
        if sl.object is not None:
            T = cf.solids[sl.object].pose
            p = T[:3, :3] @ p + T[:3, 3]
        slots.append(p)
    cams = []
    for c in spec.cameras:
        pos = np.asarray(c.pos_mm) * 1e-3
        if c.follow == "tool":
            world.worldbody.add("camera", name=c.name, pos=pos, mode="targetbody",
                                target=rig.tool_body, fovy=c.fovy_deg)
        else:
            at = np.asarray(c.look_at_mm) * 1e-3
            world.worldbody.add("camera", name=c.name, pos=pos,
                                xyaxes=look_at_xyaxes(pos, at), fovy=c.fovy_deg)
        cams.append(c.name)
    cams = _default_cameras(world, rig, T0, cf, set(cams), tuple(others)) + cams
    rb = spec.robot
    home_q = rig.home_q.copy()
    given = {key: joint_values(getattr(rb, key), rig.spec, f"{cf.where}: robot.{key}")
             for key in ("home_deg", "start_deg")}
    if given["home_deg"] is not None:
        home_q = given["home_deg"]
    first = next(iter(seams.values()), None)
    start_q = None
    own_tool = rig.tool == cf.default_tool  # start_deg is given for the cell's own tool
    if rb.start_deg is not None and own_tool:  # (given for the cell's own tool)
        start_q = given["start_deg"]
        if first is not None:
            tcp = T0 @ rig.kinematics().fk(start_q)
            gap = float(np.linalg.norm(tcp[:3, 3] - first.tcp_point(0.0)))
            if gap > 5e-5:
                raise CellError(f"{cf.where}: robot.start_deg: puts the tool point "
                                f"{gap * 1e3:.3f} mm from the start of seam "
                                f"{first.name!r} (at most 0.05 mm)")
    elif first is not None:
        km = rig.kinematics()
        T_inv = np.linalg.inv(T0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                sols = [x for x in solve_ik(km, T_inv @ first.pose(0.0), home_q)
                        if x.within_limits]
            except CellsimError:
                sols = []
        start_q = sols[0].q if sols else None
    dims = {"base_x": float(T_base[0, 3]), "base_y": float(T_base[1, 3]),
            "base_z": float(T_base[2, 3])}
    for k, v in spec.dims.items():
        if k.endswith("_mm"):
            dims[k[:-3]] = float(v) * 1e-3
        elif k.endswith("_kg"):
            dims[k[:-3]] = float(v)
        else:
            dims[k] = float(v)
    return Layout(world=world, world_from_frame0=T0, seams=seams, parts=parts,
                  slots=np.array(slots).reshape(-1, 3), cameras=cams, start_q=start_q,
                  home_q=home_q, dims=dims, objects=objects,
                  seam_objects=seam_objects, frames=frames,
                  mechanisms=tuple(cf.mechanisms.values()), partners=tuple(others))


class FileBuilder:
    """The builder ``(RobotRig, mount) -> Layout`` of a checked cell file (a class, not a
    closure, so that a scenario holding it can be sent to sweep workers)."""

    def __init__(self, cf: CellFile) -> None:
        self.cf = cf

    def __call__(self, rig: RobotRig, mount: str) -> Layout:
        return _build(self.cf, rig, mount)


def make_builder(cf: CellFile) -> FileBuilder:
    """The builder ``(RobotRig, mount) -> Layout`` of a checked cell file."""
    return FileBuilder(cf)


__all__ = ["FileBuilder", "make_builder"]
