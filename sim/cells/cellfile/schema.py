"""A cell file's schema: its tables and keys, their types, units and ranges (pydantic).

The keys are documented in ``docs/cell-format.md`` (a test keeps the two in step); the checks
that need more than one key (geometry, names, seams on their objects) are
:mod:`~sim.cells.cellfile.reader`'s.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from sim.core.text import PlainText
from sim.core.tomlschema import ANGLE_DEG, Quantity, Strict

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
#: An object's mass: a part's (at most :data:`PART_MASS_KG`'s 1000 kg, checked by the reader) or
#: a workpiece's on a mechanism (heavy positioners carry tonnes).
OBJECT_MASS_KG = Quantity("an object's mass", "kg", 1e-6, 1e5)
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
    on: str | None = None


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
    mass_kg: OBJECT_MASS_KG.type | None = None
    color: list[COLOR.type] | None = Field(None, min_length=3, max_length=4)
    material: Literal[MATERIALS] | None = None  # type: ignore[valid-type]
    friction: FRICTION.type | None = None
    collide: bool = True
    on: str | None = None


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


class MechanismBlock(Strict):
    """``[[mechanisms]]``: a turntable, positioner or track placed in the cell."""

    name: str = Field(pattern=_NAME)
    model: str
    pos_mm: list[Mm] = _vec3([0.0, 0.0, 0.0])
    euler_zyx_deg: list[Deg] = _vec3([0.0, 0.0, 0.0])
    home: dict[str, float] = {}


class OtherRobotBlock(Strict):
    """``[[robots]]``: another robot in the cell, with its own tool, base and home (its work is
    the scenario's ``[robots.<name>]``)."""

    name: str = Field(pattern=_NAME)
    model: str
    tool: str | None = None
    base_pos_mm: list[Mm] = _vec3([0.0, 0.0, 0.0])
    base_euler_zyx_deg: list[Deg] = _vec3([0.0, 0.0, 0.0])
    mount: Literal["floor", "ceiling"] = "floor"
    home_deg: list[float] | None = None


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
    mechanisms: list[MechanismBlock] = []
    robots: list[OtherRobotBlock] = Field([], max_length=8)


__all__ = ["CameraBlock", "CellFileSpec", "MechanismBlock", "ObjectBlock", "OtherRobotBlock",
           "RobotBlock", "SeamBlock", "SlotBlock"]
