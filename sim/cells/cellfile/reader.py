"""Reading a cell file: the schema's content checked as a whole (names, solids, seams on
their objects, cameras, the robot base) into a :class:`CellFile`, once, with no robot needed;
every problem is one line naming the file and the key."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.cells.cellfile.schema import (
    BASE_TOLERANCE_M,
    DIM_UNITS,
    RESERVED,
    SEAM_TOLERANCE_M,
    CellFileSpec,
)
from sim.cells.cellfile.seams import ctwd_key, seam_in_world, seam_points
from sim.cells.cellfile.solids import Solid, geom_names, object_pose, read_solid
from sim.cells.mechanisms import PlacedMechanism
from sim.cells.partners import PlacedRobot
from sim.core.tomlschema import load_toml
from sim.errors import CellError, CellsimError, UnknownNameError


@dataclass
class CellFile:
    """A checked cell file (what the builder needs besides the robot).

    Attributes:
        path: The file. spec: Its validated content. solids: Its objects by name (an object
            on a mechanism at the mechanism's home).
        base_pose: The robot base frame in world (mount included; on a track: at the track's
            home), (4, 4).
        default_tool: The default tool reference as written (resolved by :mod:`sim.cells`).
        mechanisms: The placed mechanisms by name, in the file's order.
        mounted: Objects on a mechanism: ``name -> (mechanism, pose in its mount frame)``.
        robot_on: The mechanism the robot's base stands on (a track), or None.
        robot_local: The robot base frame in that mechanism's mount frame, (4, 4).
        partners: The cell's other robots (``[[robots]]``) by name, in the file's order.
    """

    path: Path
    spec: CellFileSpec
    solids: dict[str, Solid]
    base_pose: NDArray[np.float64]
    default_tool: object = None  # the resolved ``tool`` (a ToolSpec), set by sim.cells
    mechanisms: dict[str, PlacedMechanism] = field(default_factory=dict)
    mounted: dict[str, tuple[str, NDArray[np.float64]]] = field(default_factory=dict)
    robot_on: str | None = None
    robot_local: NDArray[np.float64] | None = None
    partners: dict[str, PlacedRobot] = field(default_factory=dict)

    @property
    def where(self) -> str:
        return str(self.path)


def read_cell_file(path: str | Path) -> CellFile:
    """Read and check a cell file (no robot needed).

    Raises:
        CellError: One line naming the file and the key: unreadable file, unknown key, wrong
            type, a mesh file missing, duplicate names, a seam naming an unknown object, a seam
            point more than 1 mm outside its object, a robot base inside a fixture.
    """
    path = Path(path)
    spec, _ = load_toml(path, CellFileSpec, CellError)
    where = str(path)
    mechanisms = read_mechanisms(spec, path)
    solids: dict[str, Solid] = {}
    mounted: dict[str, tuple[str, NDArray[np.float64]]] = {}
    for i, ob in enumerate(spec.objects):
        if ob.name in solids or ob.name in RESERVED or ob.name in mechanisms:
            what = (f"is already the name of objects[{solids[ob.name].index}]"
                    if ob.name in solids else "is a mechanism's name" if ob.name in mechanisms
                    else "is reserved")
            raise CellError(f"{where}: objects[{i}].name: {ob.name!r} {what}")
        solid = read_solid(ob, i, path.parent, where)
        if ob.on is not None:
            if ob.on not in mechanisms:
                raise CellError(f"{where}: objects[{i}].on: "
                                f"{UnknownNameError('mechanism', ob.on, list(mechanisms))}")
            if ob.role == "part":
                raise CellError(f"{where}: objects[{i}].on: a part is a free body; only "
                                "fixtures and workpieces are mounted on a mechanism")
            pm = mechanisms[ob.on]
            mounted[ob.name] = (ob.on, solid.pose.copy())
            solid.pose = pm.mount_in_world(pm.home) @ solid.pose
        solids[ob.name] = solid
    for pm in mechanisms.values():
        clash = sorted(pm.names & set(solids))
        if clash:
            raise CellError(f"{where}: objects[{solids[clash[0]].index}].name: {clash[0]!r} is "
                            f"a name of mechanism {pm.name!r}'s model; rename the object")
    owner: dict[str, int] = {}  # every geom name the objects become -> the object's index
    for sd in solids.values():
        for g in geom_names(sd.block, len(sd.pieces)):
            if g in owner or (g != sd.block.name and g in solids) or g in RESERVED:
                other = owner.get(g, solids[g].index if g in solids else None)
                clash = f"objects[{other}]" if other is not None else "a reserved name"
                raise CellError(f"{where}: objects[{sd.index}].name: {sd.block.name!r} gives a "
                                f"geom named {g!r}, which clashes with {clash}; rename one")
            owner[g] = sd.index

    def known(name: str, key: str, static: bool = False) -> Solid:
        if name not in solids:
            valid = [n for n, s in solids.items() if not static or s.block.role != "part"]
            raise CellError(f"{where}: {key}: {UnknownNameError('object', name, valid)}")
        return solids[name]

    seam_names: set[str] = set()
    for i, sb in enumerate(spec.seams):
        key = f"{where}: seams[{i}]"
        if sb.name in seam_names:
            raise CellError(f"{key}.name: {sb.name!r} is already a seam's name")
        seam_names.add(sb.name)
        obj = known(sb.object, f"seams[{i}].object", static=True)
        if obj.block.role == "part":
            raise CellError(f"{key}.object: {sb.object!r} is a part (a free body); seams lie on "
                            "fixtures or workpieces")
        for j, other in enumerate(sb.joins):
            known(other, f"seams[{i}].joins[{j}]", static=True)
        pts = seam_points(sb, key)
        for k, p in enumerate(pts):
            pw = obj.pose[:3, :3] @ p + obj.pose[:3, 3]
            d = obj.distance(pw)
            if d > SEAM_TOLERANCE_M:
                raise CellError(f"{key}.points_mm[{k}]: {np.round(p * 1e3, 3).tolist()} mm is "
                                f"{d * 1e3:.2f} mm outside object {sb.object!r} (at most "
                                f"{SEAM_TOLERANCE_M * 1e3:g} mm); the points are in the "
                                "object's frame")
        try:
            seam = seam_in_world(sb, obj.pose, pts, tool_axis=2, world_from_frame0=np.eye(4),
                                  standoff=0.0)
        except CellsimError as exc:
            raise CellError(f"{key}: {exc}") from None
        # the torch posture must exist all along (a polyline's every segment, an arc's every
        # point): the normal may not run along the seam anywhere
        if seam.kind == "polyline":  # each segment at its middle
            cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(seam.points, axis=0),
                                                                  axis=1))])
            where_s = [(0.5 * (cum[k] + cum[k + 1]), f"segment {k + 1}")
                       for k in range(len(cum) - 1)]
        else:
            where_s = [(x, f"{x * 1e3:.1f} mm from its start")
                       for x in np.linspace(0.0, seam.length(), 65)]
        for s_, label in where_s:
            t = seam.tangent(float(s_))
            n_w = seam.surface_normal
            if np.linalg.norm(n_w - (n_w @ t) * t) < 1e-6:
                raise CellError(f"{key}.normal: {np.round(sb.normal, 6).tolist()} runs along the "
                                f"seam ({label}); the reference surface's normal must be across "
                                "the seam")
        if sb.stickout_mm is not None and sb.ctwd_mm is not None:
            raise CellError(f"{key}.ctwd_mm: give one of stickout_mm or ctwd_mm (both set the "
                            "contact-tip-to-work distance)")
        dist_key = ctwd_key(sb)
        if sb.kind == "arc" and dist_key is not None:
            axis = seam.normal
            if abs(abs(axis @ seam.surface_normal) - 1.0) > 1e-6:
                raise CellError(f"{key}.{dist_key}: on an arc a stand-off other than the tool's "
                                "needs the normal along the arc's axis (the torch then keeps its "
                                "posture to the circle, and the tool point runs a coaxial arc)")
    for i, sl in enumerate(spec.slots):
        if sl.object is not None:
            known(sl.object, f"slots[{i}].object")
    cams = [c.name for c in spec.cameras]
    for i, c in enumerate(spec.cameras):
        if cams.count(c.name) > 1:
            raise CellError(f"{where}: cameras[{i}].name: {c.name!r} is used twice")
        if (c.look_at_mm is None) == (c.follow is None):
            raise CellError(f"{where}: cameras[{i}]: give one of look_at_mm (a fixed view) or "
                            "follow = \"tool\" (a fixed camera turning to follow the tool)")
        if c.look_at_mm is not None and np.linalg.norm(np.subtract(c.look_at_mm, c.pos_mm)) < 1.0:
            raise CellError(f"{where}: cameras[{i}].look_at_mm: the camera looks at itself")
    for k in spec.dims:
        if not k.endswith(DIM_UNITS):
            raise CellError(f"{where}: dims.{k}: a dimension's key ends in its unit: "
                            f"{', '.join(DIM_UNITS)}")

    rb = spec.robot
    base = object_pose(rb.base_pos_mm, rb.base_euler_zyx_deg)
    if rb.mount == "ceiling":  # a half turn about the base's x axis (exact)
        base[:3, :3] = base[:3, :3] @ np.diag([1.0, -1.0, -1.0])
    robot_local = None
    if rb.on is not None:
        if rb.on not in mechanisms:
            raise CellError(f"{where}: robot.on: "
                            f"{UnknownNameError('mechanism', rb.on, list(mechanisms))}")
        pm = mechanisms[rb.on]
        if pm.spec.kind != "track":
            raise CellError(f"{where}: robot.on: {rb.on!r} is a {pm.spec.kind}; a robot's base "
                            "stands on a track")
        robot_local = base
        base = pm.mount_in_world(pm.home) @ base
    _check_base_clear(solids, base, f"{where}: robot.base_pos_mm", "the robot base",
                      rb.base_pos_mm)
    carried: dict[str, list[str]] = {name: [] for name in mechanisms}
    for obj, (mech, _) in mounted.items():
        carried[mech].append(obj)
    if rb.on is not None:
        carried[rb.on].append("robot")
    mechanisms = {name: dataclasses.replace(pm, carries=tuple(carried[name]))
                  for name, pm in mechanisms.items()}
    partners = read_partners(spec, path, set(solids) | set(mechanisms), solids)
    return CellFile(path=path, spec=spec, solids=solids, base_pose=base, mechanisms=mechanisms,
                    mounted=mounted, robot_on=rb.on, robot_local=robot_local, partners=partners)


def _check_base_clear(solids: dict[str, Solid], base: NDArray[np.float64], key: str,
                      what: str, given: list[float]) -> None:
    """Refuse a robot base origin more than :data:`BASE_TOLERANCE_M` inside a fixture or
    workpiece (``key`` starts the message: file and key)."""
    for s in solids.values():
        if s.block.role == "part" or not s.block.collide:
            continue
        d = s.distance(base[:3, 3])
        if d < -BASE_TOLERANCE_M:
            raise CellError(f"{key}: {what} {given} mm is {-d * 1e3:.1f} mm inside "
                            f"{s.block.role} {s.block.name!r} (objects[{s.index}]); stand it on "
                            "the object, not in it")


def joint_values(values_deg: list[float] | None, robot: Any, key: str
                 ) -> NDArray[np.float64] | None:
    """A robot's joint values given in a cell file (``home_deg``, ``start_deg``), rad; None
    when not given.

    Raises:
        CellError: ``key`` named when the count is not the robot's joint count or a value is
            outside its joint's range.
    """
    from sim.robots.spec import joint_ranges

    if values_deg is None:
        return None
    n = robot.n_joints
    if len(values_deg) != n:
        raise CellError(f"{key}: {len(values_deg)} values; robot {robot.name} has {n} joints")
    q = np.deg2rad(np.asarray(values_deg, dtype=float))
    for j, (qj, (lo, hi)) in enumerate(zip(q, joint_ranges(robot)[:n], strict=True)):
        if not lo - 1e-9 <= qj <= hi + 1e-9:
            raise CellError(f"{key}[{j}]: {values_deg[j]:g} deg is outside joint "
                            f"{robot.joints[j]}'s range [{np.rad2deg(lo):g}, "
                            f"{np.rad2deg(hi):g}] deg (robot {robot.name})")
    return q


def read_partners(spec: CellFileSpec, path: Path, taken: set[str],
                  solids: dict[str, Solid] | None = None) -> dict[str, PlacedRobot]:
    """The cell file's other robots (``[[robots]]``): model and home resolved, each base
    checked against ``solids`` as the first robot's is; their tools are resolved with the
    cell's (:func:`sim.cells.registry.load_cell`, :func:`partner_tool`).

    Raises:
        CellError: One line naming the file and the key (a name taken or reserved, an unknown
            robot, home values that do not fit the robot, a base inside a fixture or
            workpiece).
    """
    from sim.robots.registry import resolve_robot

    where = path.name
    out: dict[str, PlacedRobot] = {}
    for i, rb in enumerate(spec.robots):
        key = f"{where}: robots[{i}]"
        if rb.name in out or rb.name in RESERVED or rb.name in taken:
            what = ("is already another robot's name" if rb.name in out else "is reserved"
                    if rb.name in RESERVED else "is an object's or mechanism's name")
            raise CellError(f"{key}.name: {rb.name!r} {what}")
        try:
            robot = resolve_robot(rb.model, path.parent)
        except CellsimError as exc:
            raise CellError(f"{key}.model: {exc}") from None
        home = joint_values(rb.home_deg, robot, f"{key}.home_deg")
        base = object_pose(rb.base_pos_mm, rb.base_euler_zyx_deg)
        if rb.mount == "ceiling":
            base[:3, :3] = base[:3, :3] @ np.diag([1.0, -1.0, -1.0])
        _check_base_clear(solids or {}, base, f"{key}.base_pos_mm",
                          f"the base of robot {rb.name!r}", rb.base_pos_mm)
        out[rb.name] = PlacedRobot(rb.name, robot, None, base, home, i)
    return out


def partner_tool(spec: CellFileSpec, path: Path, placed: PlacedRobot,
                 load: Callable[[str, Path], Any]) -> PlacedRobot:
    """A placed robot with its tool: its ``tool``, else the cell's (``load`` reads a tool
    reference relative to the cell file's folder: :func:`sim.cells.registry.tool_from_ref`).

    Raises:
        CellError: An unknown tool or a suction gripper (one line naming the file and key).
    """
    key = f"{path.name}: robots[{placed.index}].tool"
    ref = spec.robots[placed.index].tool
    ref = spec.tool if ref is None else ref
    try:
        tool = None if ref is None or ref == "none" else load(ref, path.parent)
    except CellsimError as exc:
        raise CellError(f"{key}: {exc}") from None
    if tool is not None and tool.suction_gain_n > 0.0:
        raise CellError(f"{key}: {tool.name!r} is a suction gripper; a cell's other robots "
                        "carry torches or tools without suction (the first robot picks)")
    return dataclasses.replace(placed, tool=tool)


def read_mechanisms(spec: CellFileSpec, path: Path) -> dict[str, PlacedMechanism]:
    """The cell file's ``[[mechanisms]]`` placed (their files read, their home values checked).

    Raises:
        CellError: One line naming the file and the key: a duplicate or reserved name, an
            unknown mechanism or a bad mechanism file, a home value for an axis the mechanism
            lacks, in the wrong unit or outside the axis's range.
    """
    from sim.robots.mechanisms.registry import mechanism_from_ref

    where = str(path)
    out: dict[str, PlacedMechanism] = {}
    for i, mb in enumerate(spec.mechanisms):
        key = f"{where}: mechanisms[{i}]"
        if mb.name in out or mb.name in RESERVED:
            what = "is already a mechanism's name" if mb.name in out else "is reserved"
            raise CellError(f"{key}.name: {mb.name!r} {what}")
        try:
            mech = mechanism_from_ref(mb.model, path.parent)
        except CellsimError as exc:
            raise CellError(f"{key}.model: {exc}") from None
        home = np.zeros(mech.n_axes)
        units = {a.name: ("deg" if a.kind == "revolute" else "mm") for a in mech.axes}
        for k, v in mb.home.items():
            axis, _, unit = k.rpartition("_")
            if axis not in units:
                valid = [f"{a}_{u}" for a, u in units.items()]
                raise CellError(f"{key}.home.{k}: {UnknownNameError('axis', k, valid)}")
            if unit != units[axis]:
                raise CellError(f"{key}.home.{k}: axis {axis!r} is "
                                f"{'revolute' if units[axis] == 'deg' else 'prismatic'}; give "
                                f"{axis}_{units[axis]}")
            j = mech.axis_names.index(axis)
            value = float(np.deg2rad(v) if unit == "deg" else v * 1e-3)
            lo, hi = mech.axes[j].range
            if not (np.isfinite(value) and lo - 1e-12 <= value <= hi + 1e-12):
                shown = np.rad2deg([lo, hi]) if unit == "deg" else np.multiply([lo, hi], 1e3)
                raise CellError(f"{key}.home.{k}: {v!r} is outside the axis's range "
                                f"[{shown[0]:g}, {shown[1]:g}] {unit}")
            home[j] = value
        pose = object_pose(mb.pos_mm, mb.euler_zyx_deg)
        out[mb.name] = PlacedMechanism(name=mb.name, spec=mech, pose=pose, home=home)
    return out


__all__ = ["CellFile", "partner_tool", "read_cell_file", "read_mechanisms", "read_partners"]
