"""Cells as data: a TOML file lays out a user's cell (format and figure: ``docs/cell-format.md``).

A cell file places the robot's base, the static objects (fixtures, workpieces: boxes,
cylinders, spheres, STL/OBJ meshes), the parts that can be picked, the weld seams (in their
workpiece's frame, with AWS work and travel angles), the slots parts go to and the cameras.
:func:`load_cell_file` reads and checks it once (every problem is one line naming the file and
the key) and returns a :class:`sim.cells.CellSpec` whose builder composes the world around any
robot; the scenario names the file (``cell = "cells/my_cell.toml"``, relative to the scenario).

Frames and units: lengths in mm and angles in deg in the file, SI inside. ``pos_mm`` and
``euler_zyx_deg`` place an object in world (``R = Rz(a) Ry(b) Rx(c)``); a box is centred on its
position, a cylinder too with its axis along the object's z. The robot base frame (the MJCF
model's origin: the base plane on the J1 axis) is at ``base_pos_mm`` turned by
``base_euler_zyx_deg``; ``mount = "ceiling"`` turns it further by 180 deg about its x axis (J1
pointing down), so ``base_pos_mm`` is then where the base plane meets the ceiling.

Seam torch angles (AWS A3.0 terms; the file's convention, converted for :class:`Seam`):

* ``work_angle_deg``: angle between the torch axis and the reference surface (the plane whose
  outward ``normal`` the seam gives), measured in the plane perpendicular to the seam; 90 deg
  puts the torch along ``-normal``, 45 deg is the usual fillet posture. The torch leans to the
  ``lean`` side (``"left"`` or ``"right"`` of the travel direction, seen from the torch side);
* ``travel_angle_deg``: tilt in the plane of the torch axis and the seam, positive = push
  (the torch points ahead), negative = drag.

:class:`Seam` measures its work angle from the normal, so it receives ``90 - work_angle_deg``.

A seam's ``ctwd_mm`` (contact-tip-to-work distance; ``stickout_mm`` is the same distance under
its older name, and a seam gives at most one of the two) becomes its stand-off,
``Seam.standoff_m = ctwd - the torch's nominal stick-out``: the tool point (the wire tip at the
nominal stick-out) then runs that far back from the seam along the torch axis, on lines, arcs
and polylines alike (:mod:`sim.cells.seam`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from sim.cells.compose import (
    Layout,
    RobotRig,
    look_at_xyaxes,
    matrix_from_quat,
    new_world,
    quat_from_matrix,
)
from sim.cells.seam import Seam
from sim.cells.tools import (
    CONTACT_FIXTURE,
    CONTACT_PART_AFFINITY,
    CONTACT_PART_TYPE,
    ToolSpec,
)
from sim.core.rotations import euler_zyx_to_matrix
from sim.core.text import PlainText
from sim.core.tomlschema import ANGLE_DEG, Quantity, Strict, load_toml
from sim.errors import CellError, CellsimError

_NAME = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*$"
#: A seam point may lie at most this far outside its object, m.
SEAM_TOLERANCE_M = 1e-3
#: The robot base origin may lie at most this deep inside a static object, m.
BASE_TOLERANCE_M = 1e-3
#: Materials of the roles (colours of :func:`sim.cells.compose.new_world`).
ROLE_MATERIAL = {"fixture": "fixture", "workpiece": "steel", "part": "part"}
#: Materials of :func:`sim.cells.compose.new_world` an object may name.
MATERIALS = ("steel", "dark_steel", "fixture", "table", "concrete", "seam", "part", "slot")
#: Units a ``[dims]`` key may end in: mm (converted to m, the suffix dropped), kg (dropped),
#: deg (kept).
DIM_UNITS = ("_mm", "_kg", "_deg")
#: Names a cell object may not take (the world's own geoms, the robot's prefix, frames).
RESERVED = ("floor", "robot", "world", "frame0", "overview", "tool")


#: Largest length a cell file takes, mm (1 km): a bigger one is a typo, and would only make
#: MuJoCo's compiler or the closed forms fail later with less helpful words.
MAX_MM = 1e6
#: Smallest size of a solid, mm (1 um): a smaller one is a typo (MuJoCo's compiler refuses a
#: geom of 1e-300 m: its volume and inertia vanish).
MIN_SIZE_MM = 1e-3
#: A coordinate (a position, a seam point) in mm (:class:`sim.core.tomlschema.Quantity`).
COORD_MM = Quantity("a position in the cell", "mm", -MAX_MM, MAX_MM)
#: A solid's size, radius or length in mm.
SIZE_MM = Quantity("a size of a solid", "mm", MIN_SIZE_MM, MAX_MM)
#: A ring's inner radius in mm (0: a full cylinder sector).
INNER_RADIUS_MM = Quantity("an inner radius", "mm", 0.0, MAX_MM)
#: A part's mass, kg.
PART_MASS_KG = Quantity("a part's mass", "kg", 1e-6, 1000.0)
#: A sliding friction coefficient.
FRICTION = Quantity("a friction coefficient", "", 1e-6, 5.0)
#: A colour component (RGB(A)).
COLOR = Quantity("a colour component", "", 0.0, 1.0)
#: A length or coordinate in mm, bounded.
Mm = COORD_MM.type
#: A size in mm: positive, bounded.
Size = SIZE_MM.type
#: An orientation angle, deg (:data:`sim.core.tomlschema.ANGLE_DEG`).
Deg = ANGLE_DEG.type


def _vec3(default: list[float] | None = None):
    if default is None:
        return Field(min_length=3, max_length=3)
    return Field(default, min_length=3, max_length=3)


class RobotBlock(Strict):
    """``[robot]``: where the robot stands."""

    model: str | None = None
    base_pos_mm: list[Mm] = _vec3([0.0, 0.0, 0.0])
    base_euler_zyx_deg: list[Deg] = _vec3([0.0, 0.0, 0.0])
    mount: Literal["floor", "ceiling"] = "floor"
    home_deg: list[float] | None = None
    start_deg: list[float] | None = None


class ObjectBlock(Strict):
    """``[[objects]]``: a fixture, workpiece or part."""

    name: str = Field(pattern=_NAME)
    shape: Literal["box", "cylinder", "sphere", "mesh", "ring"]
    size_mm: list[Size] | None = Field(None, min_length=3, max_length=3)
    radius_mm: Size | None = None
    inner_radius_mm: INNER_RADIUS_MM.type | None = None
    length_mm: Size | None = None
    arc_deg: list[Deg] | None = Field(None, min_length=2, max_length=2)
    segments: int | None = Field(None, ge=3, le=720)
    file: str | None = None
    mesh_unit: Literal["mm", "m"] = "mm"
    pos_mm: list[Mm] = _vec3([0.0, 0.0, 0.0])
    euler_zyx_deg: list[Deg] = _vec3([0.0, 0.0, 0.0])
    role: Literal["fixture", "workpiece", "part"] = "fixture"
    mass_kg: PART_MASS_KG.type | None = None
    color: list[COLOR.type] | None = Field(None, min_length=3, max_length=4)
    material: Literal[MATERIALS] | None = None  # type: ignore[valid-type]
    friction: FRICTION.type | None = None
    collide: bool = True


class SeamBlock(Strict):
    """``[[seams]]``: a weld seam in its object's frame."""

    name: str = Field(pattern=_NAME)
    object: str
    kind: Literal["line", "arc", "polyline"]
    points_mm: list[list[Mm]] = Field(max_length=10000)
    normal: list[float] = _vec3()
    work_angle_deg: float = Field(90.0, ge=0, le=90)
    travel_angle_deg: float = Field(0.0, gt=-90, lt=90)
    lean: Literal["left", "right"] = "left"
    stickout_mm: float | None = Field(None, gt=0, le=100)
    ctwd_mm: float | None = Field(None, gt=0, le=100)
    joins: list[str] = []
    description: PlainText = ""


class SlotBlock(Strict):
    """``[[slots]]``: where a part's centre goes (world, or an object's frame)."""

    name: str = Field(pattern=_NAME)
    pos_mm: list[Mm] = _vec3()
    object: str | None = None


class CameraBlock(Strict):
    """``[[cameras]]``: a fixed camera."""

    name: str = Field(pattern=_NAME)
    pos_mm: list[Mm] = _vec3()
    look_at_mm: list[Mm] | None = Field(None, min_length=3, max_length=3)
    follow: Literal["tool"] | None = None
    fovy_deg: float = Field(45.0, gt=1, lt=170)


class CellFileSpec(Strict):
    """Top level of a cell file."""

    name: str = Field(pattern=_NAME)
    description: PlainText = ""
    tool: str | None = None
    tools: list[str] | None = None
    robot: RobotBlock = RobotBlock()
    objects: list[ObjectBlock] = []
    seams: list[SeamBlock] = []
    slots: list[SlotBlock] = []
    cameras: list[CameraBlock] = []
    dims: dict[str, float] = {}


# ---------------------------------------------------------------------------- geometry
def _pose(pos_mm: list[float], euler_deg: list[float]) -> NDArray[np.float64]:
    T = np.eye(4)
    T[:3, :3] = euler_zyx_to_matrix(*np.deg2rad(np.asarray(euler_deg, dtype=float)))
    T[:3, 3] = np.asarray(pos_mm, dtype=float) * 1e-3
    return T


@dataclass
class Solid:
    """One cell object's geometry in its own frame, for the load-time checks and the build.

    Attributes:
        block: The file's entry. index: Its index in ``objects``.
        pose: World pose, (4, 4).
        pieces: Mesh objects: convex collision pieces (vertex arrays, m, object frame).
        verts, faces: Mesh objects: the visual mesh (m, object frame).
        radius: Bounding radius about the object's origin, m.
    """

    block: ObjectBlock
    index: int
    pose: NDArray[np.float64]
    pieces: list[NDArray[np.float64]] = field(default_factory=list)
    verts: NDArray[np.float64] | None = None
    faces: NDArray[np.int64] | None = None
    radius: float = 0.0
    _halfspaces: list[NDArray[np.float64]] = field(default_factory=list)

    def distance(self, p_world: NDArray[np.float64]) -> float:
        """Signed distance of a world point from the object (negative inside), m; for a mesh
        the distance to its surface, negative inside one of its convex pieces."""
        T = self.pose
        p = T[:3, :3].T @ (np.asarray(p_world, dtype=float) - T[:3, 3])
        b = self.block
        if b.shape == "box":
            h = np.asarray(b.size_mm) * 0.5e-3
            q = np.abs(p) - h
            return float(np.linalg.norm(np.maximum(q, 0.0)) + min(q.max(), 0.0))
        if b.shape == "cylinder":
            d = np.array([np.hypot(p[0], p[1]) - b.radius_mm * 1e-3,
                          abs(p[2]) - b.length_mm * 0.5e-3])
            return float(min(d.max(), 0.0) + np.linalg.norm(np.maximum(d, 0.0)))
        if b.shape == "sphere":
            return float(np.linalg.norm(p) - b.radius_mm * 1e-3)
        if b.shape == "ring":
            return _ring_distance(p, b)
        from sim.cells.meshes import point_mesh_distance

        assert self.verts is not None and self.faces is not None
        surf = point_mesh_distance(p, self.verts, self.faces)
        inside = any(np.all(H[:, :3] @ p + H[:, 3] <= 1e-9) for H in self._halfspaces)
        return -surf if inside else surf


def _volume(points: NDArray[np.float64]) -> float:
    from scipy.spatial import ConvexHull, QhullError

    try:
        return float(ConvexHull(points).volume)
    except (QhullError, ValueError):
        return 0.0


def _ring_distance(p: NDArray[np.float64], b: ObjectBlock) -> float:
    """Signed distance from a ring sector (annulus r_in..r_out, |z| <= L/2, angles a0..a1 from
    the object's x axis), m: exact for the cut faces too."""
    r_in, r_out = (b.inner_radius_mm or 0.0) * 1e-3, b.radius_mm * 1e-3
    half = b.length_mm * 0.5e-3
    a0, a1 = np.deg2rad(b.arc_deg) if b.arc_deg is not None else (0.0, 2 * np.pi)
    sweep = a1 - a0
    rho = float(np.hypot(p[0], p[1]))
    phi = float(np.mod(np.arctan2(p[1], p[0]) - a0, 2 * np.pi))
    dz = abs(p[2]) - half
    inside_angle = sweep >= 2 * np.pi - 1e-12 or phi <= sweep
    if inside_angle:
        d = [max(r_in - rho, rho - r_out), dz]
        if sweep < 2 * np.pi - 1e-12:  # distance to the nearer cut face (a half-plane)
            to_face = min(rho * np.sin(min(phi, np.pi / 2)),
                          rho * np.sin(min(sweep - phi, np.pi / 2)))
            d.append(-to_face)
        dd = np.array(d)
        return float(min(dd.max(), 0.0) + np.linalg.norm(np.maximum(dd, 0.0)))
    # outside the angles: the distance to the nearer cut face (a rectangle r_in..r_out x z)
    best = np.inf
    for a in (a0, a1):
        u = np.array([np.cos(a), np.sin(a)])
        t = float(np.clip(p[:2] @ u, r_in, r_out))
        d2 = float(np.linalg.norm(p[:2] - t * u))
        best = min(best, float(np.hypot(d2, max(dz, 0.0))))
    return best


def _geom_names(b: ObjectBlock, pieces: int) -> list[str]:
    """The names of the geoms an object becomes in the model."""
    if b.shape == "ring":
        return [f"{b.name}{k}" for k in range(b.segments or 72)]
    if b.shape == "mesh":
        return [f"{b.name}_visual", *(f"{b.name}_c{k}" for k in range(pieces))]
    return [b.name]


#: Convex pieces smaller than this are left out of a mesh's collision geoms, m^3 (1 mm^3:
#: MuJoCo's compiler refuses a mesh whose volume is too small to compute its inertia).
MIN_PIECE_VOLUME = 1e-9


def _solid(block: ObjectBlock, index: int, base: Path, where: str) -> Solid:
    key = f"{where}: objects[{index}]"
    shape = block.shape
    need = {"box": ("size_mm",), "cylinder": ("radius_mm", "length_mm"),
            "sphere": ("radius_mm",), "mesh": ("file",),
            "ring": ("radius_mm", "inner_radius_mm", "length_mm")}[shape]
    optional = {"ring": ("arc_deg", "segments")}.get(shape, ())
    for k in need:
        if getattr(block, k) is None:
            raise CellError(f"{key}.{k}: required for a {shape}")
    extra = [k for k in ("size_mm", "radius_mm", "inner_radius_mm", "length_mm", "file",
                         "arc_deg", "segments")
             if k not in need and k not in optional and getattr(block, k) is not None]
    if extra:
        raise CellError(f"{key}.{extra[0]}: not used with shape = {shape!r} (it takes "
                        f"{', '.join(need)})")
    if shape == "ring":
        if block.inner_radius_mm >= block.radius_mm:
            raise CellError(f"{key}.inner_radius_mm: must be less than radius_mm")
        if block.arc_deg is not None and not 0 < block.arc_deg[1] - block.arc_deg[0] <= 360:
            raise CellError(f"{key}.arc_deg: [from, to] with 0 < to - from <= 360")
    if block.size_mm is not None and min(block.size_mm) <= 0:
        raise CellError(f"{key}.size_mm: full extents must be positive (mm)")
    if block.role == "part" and shape == "ring":
        raise CellError(f"{key}.shape: a part cannot be a ring (a part is one free body: a box, "
                        "cylinder, sphere or mesh)")
    if block.role == "part" and block.mass_kg is None:
        raise CellError(f"{key}.mass_kg: required for a part (a free body)")
    if block.role != "part" and block.mass_kg is not None:
        raise CellError(f"{key}.mass_kg: only parts have a mass (role = \"part\"); "
                        f"{block.role}s are static")
    s = Solid(block, index, _pose(block.pos_mm, block.euler_zyx_deg))
    if shape == "box":
        s.radius = float(np.linalg.norm(block.size_mm)) * 0.5e-3
    elif shape == "cylinder":
        s.radius = float(np.hypot(block.radius_mm, block.length_mm / 2)) * 1e-3
    elif shape == "sphere":
        s.radius = float(block.radius_mm) * 1e-3
    elif shape == "ring":
        s.radius = float(np.hypot(block.radius_mm, block.length_mm / 2)) * 1e-3
    else:
        from scipy.spatial import ConvexHull

        from sim.cells.meshes import convex_pieces, read_mesh

        path = (base / str(block.file)).resolve()
        s.verts, s.faces = read_mesh(path, block.mesh_unit, where=f"{key}.file")
        pieces = convex_pieces(path, block.mesh_unit, where=f"{key}.file")
        s.pieces = [pc for pc in pieces if _volume(pc) >= MIN_PIECE_VOLUME]
        if not s.pieces:
            raise CellError(f"{key}.file: {path.name}: the mesh encloses less than 1 mm^3 "
                            "(check mesh_unit: the file's coordinates are read as "
                            f"{block.mesh_unit})")
        s._halfspaces = [ConvexHull(pc).equations for pc in s.pieces]
        s.radius = float(np.max(np.linalg.norm(s.verts, axis=1)))
    return s


# ---------------------------------------------------------------------------- the file
@dataclass
class CellFile:
    """A checked cell file (what the builder needs besides the robot).

    Attributes:
        path: The file. spec: Its validated content. solids: Its objects by name.
        base_pose: The robot base frame in world (mount included), (4, 4).
        default_tool: The default tool reference as written (resolved by :mod:`sim.cells`).
    """

    path: Path
    spec: CellFileSpec
    solids: dict[str, Solid]
    base_pose: NDArray[np.float64]
    default_tool: object = None  # the resolved ``tool`` (a ToolSpec), set by sim.cells

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
    solids: dict[str, Solid] = {}
    for i, ob in enumerate(spec.objects):
        if ob.name in solids or ob.name in RESERVED:
            what = (f"is already the name of objects[{solids[ob.name].index}]"
                    if ob.name in solids else "is reserved")
            raise CellError(f"{where}: objects[{i}].name: {ob.name!r} {what}")
        solids[ob.name] = _solid(ob, i, path.parent, where)
    owner: dict[str, int] = {}  # every geom name the objects become -> the object's index
    for sd in solids.values():
        for g in _geom_names(sd.block, len(sd.pieces)):
            if g in owner or (g != sd.block.name and g in solids) or g in RESERVED:
                other = owner.get(g, solids[g].index if g in solids else None)
                clash = f"objects[{other}]" if other is not None else "a reserved name"
                raise CellError(f"{where}: objects[{sd.index}].name: {sd.block.name!r} gives a "
                                f"geom named {g!r}, which clashes with {clash}; rename one")
            owner[g] = sd.index

    def known(name: str, key: str, static: bool = False) -> Solid:
        if name not in solids:
            from sim.errors import UnknownNameError

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
        pts = _seam_points(sb, key)
        for k, p in enumerate(pts):
            pw = obj.pose[:3, :3] @ p + obj.pose[:3, 3]
            d = obj.distance(pw)
            if d > SEAM_TOLERANCE_M:
                raise CellError(f"{key}.points_mm[{k}]: {np.round(p * 1e3, 3).tolist()} mm is "
                                f"{d * 1e3:.2f} mm outside object {sb.object!r} (at most "
                                f"{SEAM_TOLERANCE_M * 1e3:g} mm); the points are in the "
                                "object's frame")
        try:
            seam = _seam_in_world(sb, obj.pose, pts, tool_axis=2, world_from_frame0=np.eye(4),
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
        dist_key = _ctwd_key(sb)
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
    base = _pose(rb.base_pos_mm, rb.base_euler_zyx_deg)
    if rb.mount == "ceiling":  # a half turn about the base's x axis (exact)
        base[:3, :3] = base[:3, :3] @ np.diag([1.0, -1.0, -1.0])
    for s in solids.values():
        if s.block.role == "part" or not s.block.collide:
            continue
        d = s.distance(base[:3, 3])
        if d < -BASE_TOLERANCE_M:
            raise CellError(f"{where}: robot.base_pos_mm: the robot base {rb.base_pos_mm} mm is "
                            f"{-d * 1e3:.1f} mm inside {s.block.role} {s.block.name!r} "
                            f"(objects[{s.index}]); stand it on the object, not in it")
    return CellFile(path=path, spec=spec, solids=solids, base_pose=base)


def _seam_points(sb: SeamBlock, key: str) -> NDArray[np.float64]:
    want = {"line": "2", "arc": "3 (start, via, end)", "polyline": "at least 2"}[sb.kind]
    ok = {"line": len(sb.points_mm) == 2, "arc": len(sb.points_mm) == 3,
          "polyline": len(sb.points_mm) >= 2}[sb.kind]
    if not ok:
        raise CellError(f"{key}.points_mm: a {sb.kind} seam takes {want} points, got "
                        f"{len(sb.points_mm)}")
    for k, p in enumerate(sb.points_mm):
        if len(p) != 3:
            raise CellError(f"{key}.points_mm[{k}]: {len(p)} values; a point is [x, y, z] mm")
    pts = np.asarray(sb.points_mm, dtype=float) * 1e-3
    if not np.all(np.isfinite(pts)):
        raise CellError(f"{key}.points_mm: must be finite numbers")
    return pts


def _ctwd_key(sb: SeamBlock) -> str | None:
    """The key that sets a seam's contact-tip-to-work distance (``ctwd_mm`` or its synonym
    ``stickout_mm``), or None."""
    if sb.ctwd_mm is not None:
        return "ctwd_mm"
    return "stickout_mm" if sb.stickout_mm is not None else None


def _standoff(sb: SeamBlock, i: int, tool: ToolSpec | None, where: str) -> float:
    """A seam's stand-off, m (:mod:`sim.cells.seam`): its contact-tip-to-work distance less
    the torch's nominal stick-out; 0 when the seam gives none.

    Raises:
        CellError: The distance is shorter than the nominal stick-out: the modelled wire (that
            long) would reach into the work.
    """
    key = _ctwd_key(sb)
    if key is None:
        return 0.0
    ctwd = float(getattr(sb, key)) * 1e-3
    if tool is None or tool.kind != "torch":
        return ctwd
    try:
        return tool.standoff(ctwd)
    except CellsimError as exc:
        raise CellError(f"{where}: seams[{i}].{key}: {exc}; give at least the nominal, or a "
                        "tool with a shorter stickout_mm") from None


def _seam_in_world(sb: SeamBlock, T_obj: NDArray[np.float64], pts: NDArray[np.float64], *,
                   tool_axis: int, world_from_frame0: NDArray[np.float64],
                   standoff: float) -> Seam:
    R, t = T_obj[:3, :3], T_obj[:3, 3]
    normal = np.asarray(sb.normal, dtype=float)
    if not np.all(np.isfinite(normal)) or np.linalg.norm(normal) < 1e-9:
        raise CellsimError("normal: must be a non-zero vector")
    return Seam(name=sb.name, kind=sb.kind, points=pts @ R.T + t, normal=None,
                torch_work_angle_deg=90.0 - sb.work_angle_deg,
                torch_travel_angle_deg=sb.travel_angle_deg,
                surface_normal=R @ (normal / np.linalg.norm(normal)),
                torch_side=1 if sb.lean == "left" else -1, tool_axis=tool_axis,
                world_from_frame0=world_from_frame0, description=sb.description,
                standoff_m=standoff)


# ---------------------------------------------------------------------------- building
def _friction(b: ObjectBlock) -> dict:
    return {} if b.friction is None else {"friction": [b.friction, 0.005, 0.0001]}


def _look(b: ObjectBlock, default: str) -> dict:
    if b.color is not None:
        return {"rgba": [*b.color, 1.0][:4]}
    return {"material": b.material or default}


def _add_static(world, b: ObjectBlock, solid: Solid, material: str) -> list:
    """A fixture's or workpiece's geoms, placed in the world body at the object's pose (static
    geometry, as the shipped cells have it); returns the geoms that collide."""
    T = solid.pose
    bits = CONTACT_FIXTURE if b.collide else 0
    wb = world.worldbody
    look = _look(b, material)
    common = dict(contype=bits, conaffinity=bits, **_friction(b))
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
        from sim.cells.compose import add_ring

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
        return list(staves) if b.collide else []
    assert solid.verts is not None and solid.faces is not None
    vis = world.asset.add("mesh", name=f"{b.name}_visual", vertex=solid.verts.ravel(),
                          face=solid.faces.ravel(), inertia="shell")
    wb.add("geom", name=f"{b.name}_visual", type="mesh", mesh=vis, pos=t, **quat,
           contype=0, conaffinity=0, group=1, **look)
    geoms = []
    if b.collide:
        for k, pc in enumerate(solid.pieces):
            mesh = world.asset.add("mesh", name=f"{b.name}_c{k}", vertex=pc.ravel())
            geoms.append(wb.add("geom", name=f"{b.name}_c{k}", type="mesh", mesh=mesh, pos=t,
                                **quat, group=3, rgba=(0.5, 0.5, 0.5, 0.3), **common))
    return geoms


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
                     taken: set[str]) -> list[str]:
    """``overview`` framing the robot's work envelope and every object, and ``tool`` (a fixed
    camera aiming at the tool)."""
    reach = rig.max_distance_from_frame0()
    spheres = [(T0[:3, 3], reach)] + [(s.pose[:3, 3], s.radius) for s in cf.solids.values()]
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
    frame = world.worldbody.attach(rig.model)
    frame.pos = T_base[:3, 3]
    frame.quat = quat_from_matrix(T_base[:3, :3])
    T0 = T_base @ rig.statics.base_from_frame0
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
            geoms = _add_static(world, b, solid, ROLE_MATERIAL[b.role])
            if len(geoms) > 1 or (geoms and geoms[0].name != name):
                objects[name] = geoms
    seams: dict[str, Seam] = {}
    seam_objects: dict[str, tuple[str, ...]] = {}
    for i, sb in enumerate(spec.seams):
        obj = cf.solids[sb.object]
        standoff = _standoff(sb, i, rig.tool, cf.where)
        seam = _seam_in_world(sb, obj.pose, _seam_points(sb, f"seams[{i}]"),
                              tool_axis=rig.spec.family.approach_column,
                              world_from_frame0=T0, standoff=standoff)
        joined = tuple(dict.fromkeys([sb.object, *sb.joins]))
        for sg in ([seam] if seam.kind != "polyline" else [seam, *seam.segments()]):
            seams[sg.name] = sg
            seam_objects[sg.name] = joined
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
    cams = _default_cameras(world, rig, T0, cf, set(cams)) + cams
    rb = spec.robot
    n = rig.spec.n_joints
    home_q = rig.home_q.copy()
    for key in ("home_deg", "start_deg"):
        v = getattr(rb, key)
        if v is not None and len(v) != n:
            raise CellError(f"{cf.where}: robot.{key}: {len(v)} values; robot "
                            f"{rig.spec.name} has {n} joints")
    if rb.home_deg is not None:
        home_q = np.deg2rad(np.asarray(rb.home_deg, dtype=float))
    first = next(iter(seams.values()), None)
    start_q = None
    own_tool = rig.tool == cf.default_tool  # start_deg is given for the cell's own tool
    if rb.start_deg is not None and own_tool:  # (given for the cell's own tool)
        start_q = np.deg2rad(np.asarray(rb.start_deg, dtype=float))
        if first is not None:
            tcp = T0 @ rig.kinematics().fk(start_q)
            gap = float(np.linalg.norm(tcp[:3, 3] - first.tcp_point(0.0)))
            if gap > 5e-5:
                raise CellError(f"{cf.where}: robot.start_deg: puts the tool point "
                                f"{gap * 1e3:.3f} mm from the start of seam "
                                f"{first.name!r} (at most 0.05 mm)")
    elif first is not None:
        from sim.robots.ik import solve_ik

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
                  seam_objects=seam_objects, frames=frames)



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


__all__ = ["CellFile", "CellFileSpec", "make_builder", "read_cell_file"]
