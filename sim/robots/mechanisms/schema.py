"""The mechanism file schema (``mechanism.toml``): one pydantic model per table
(:class:`MechanismFile` the whole file), with the quantity and range of every key
(``docs/mechanism-format.md``).

Keys carry their unit (``_mm``, ``_deg``, ``_deg_s``, ``_mm_s``, ``_kg``, ``_kg_m2``, ...). An
axis declares both unit families optional (``range_deg`` and ``range_mm``, ...): which one it
must give follows from its ``kind`` and is checked by :mod:`sim.robots.mechanisms.mechfile`,
which also turns a valid file into a :class:`~sim.robots.mechanisms.spec.MechanismSpec`. A
drive's keys are the robot file's ``[[drives]]`` (:class:`sim.robots.schema.DriveBlock`).
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from sim.core.text import PlainText
from sim.core.tomlschema import (
    ANGLE_DEG,
    JOINT_ACCEL_DEG_S2,
    JOINT_DEG,
    JOINT_SPEED_DEG_S,
    MASS_KG,
    MIN_PRINCIPAL_INERTIA_KG_M2,
    PAYLOAD_KG,
    Quantity,
    Strict,
)
from sim.robots.schema import DriveBlock

#: A name of a mechanism, an axis or a shape (as a robot's name).
NAME_PATTERN = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*$"

#: Lengths in a mechanism (axis origins, centres of mass, shape positions), mm: a track may be
#: tens of metres long.
MECH_LENGTH_MM = Quantity("a length in a mechanism", "mm", -1e5, 1e5)
#: A shape's extents (box sides, cylinder radius and length), mm.
SHAPE_SIZE_MM = Quantity("a shape size", "mm", 1e-2, 1e5)
#: A prismatic axis's position limits, mm.
TRAVEL_MM = Quantity("a travel position", "mm", -1e5, 1e5)
#: A prismatic axis's speed limit, mm/s.
LINEAR_SPEED_MM_S = Quantity("a linear speed", "mm/s", 1e-3, 1e5)
#: A prismatic axis's acceleration limit, mm/s^2.
LINEAR_ACCEL_MM_S2 = Quantity("a linear acceleration", "mm/s^2", 1e-3, 1e7)
#: Coulomb friction at a revolute axis, N m.
FRICTION_NM = Quantity("a friction torque", "N m", 0.0, 1e6)
#: Coulomb friction at a prismatic axis, N.
FRICTION_N = Quantity("a friction force", "N", 0.0, 1e7)
#: Viscous damping at an axis, N m s/rad (revolute) or N s/m (prismatic).
DAMPING = Quantity("a viscous damping", "N m s/rad or N s/m", 0.0, 1e7)
#: A principal moment of inertia at the centre of mass, kg m^2.
PRINCIPAL_INERTIA_KG_M2 = Quantity("a principal moment of inertia", "kg m^2",
                                   MIN_PRINCIPAL_INERTIA_KG_M2, 1e5)
#: A colour component (red, green, blue, alpha).
COLOUR = Quantity("a colour component", "", 0.0, 1.0)
#: A component of an axis direction (normalised on reading; not all zero).
AXIS_COMPONENT = Quantity("an axis component", "", -1e6, 1e6)

class ShapeBlock(Strict):
    """``[[base_shapes]]`` and ``[[axes.link.shapes]]``: a box (``size_mm``, full extents) or a
    cylinder (``radius_mm``, ``length_mm``, along its frame's z), in the base or link frame."""

    name: str | None = Field(None, pattern=NAME_PATTERN)
    kind: Literal["box", "cylinder"]
    size_mm: list[SHAPE_SIZE_MM.type] | None = Field(None, min_length=3, max_length=3)
    radius_mm: SHAPE_SIZE_MM.type | None = None
    length_mm: SHAPE_SIZE_MM.type | None = None
    pos_mm: list[MECH_LENGTH_MM.type] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    euler_zyx_deg: list[ANGLE_DEG.type] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    rgba: list[COLOUR.type] = Field([0.95, 0.6, 0.1, 1.0], min_length=4, max_length=4)


class LinkBlock(Strict):
    """``[axes.link]``: the body an axis moves, in its link frame."""

    mass_kg: MASS_KG.type
    com_mm: list[MECH_LENGTH_MM.type] = Field(min_length=3, max_length=3)
    inertia_kg_m2: list[PRINCIPAL_INERTIA_KG_M2.type] = Field(min_length=3, max_length=3)
    shapes: list[ShapeBlock] = []


class AxisBlock(Strict):
    """``[[axes]]``: one axis, base first. Revolute axes take the ``_deg`` keys and
    ``friction_nm``, prismatic axes the ``_mm`` keys and ``friction_n``."""

    name: str = Field(pattern=NAME_PATTERN)
    kind: Literal["revolute", "prismatic"]
    pos_mm: list[MECH_LENGTH_MM.type] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    axis: list[AXIS_COMPONENT.type] = Field(min_length=3, max_length=3)
    range_deg: list[JOINT_DEG.type] | None = Field(None, min_length=2, max_length=2)
    range_mm: list[TRAVEL_MM.type] | None = Field(None, min_length=2, max_length=2)
    max_speed_deg_s: JOINT_SPEED_DEG_S.type | None = None
    max_speed_mm_s: LINEAR_SPEED_MM_S.type | None = None
    max_accel_deg_s2: JOINT_ACCEL_DEG_S2.type | None = None
    max_accel_mm_s2: LINEAR_ACCEL_MM_S2.type | None = None
    friction_nm: FRICTION_NM.type | None = None
    friction_n: FRICTION_N.type | None = None
    damping: DAMPING.type = 0.0
    drive: DriveBlock
    link: LinkBlock


class MountBlock(Strict):
    """``[mount]``: where a workpiece or a robot's base is attached, in the last link's frame."""

    pos_mm: list[MECH_LENGTH_MM.type] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    euler_zyx_deg: list[ANGLE_DEG.type] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)


class MechanismFile(Strict):
    """The whole file."""

    name: str | None = Field(None, pattern=NAME_PATTERN)
    title: PlainText | None = None
    kind: Literal["turntable", "positioner", "track"]
    description: PlainText = ""
    payload_kg: PAYLOAD_KG.type = 0.0
    axes: list[AxisBlock] = Field(min_length=1, max_length=6)
    base_shapes: list[ShapeBlock] = []
    mount: MountBlock = MountBlock()


#: Unit-suffixed keys of an axis by kind: ``{kind: {quantity: key}}`` (the other kind's key is
#: refused on that axis).
AXIS_UNIT_KEYS: dict[str, dict[str, str]] = {
    "revolute": {"range": "range_deg", "max_speed": "max_speed_deg_s",
                 "max_accel": "max_accel_deg_s2", "friction": "friction_nm"},
    "prismatic": {"range": "range_mm", "max_speed": "max_speed_mm_s",
                  "max_accel": "max_accel_mm_s2", "friction": "friction_n"},
}

__all__ = ["AXIS_COMPONENT", "AXIS_UNIT_KEYS", "COLOUR", "DAMPING", "FRICTION_N", "FRICTION_NM",
           "LINEAR_ACCEL_MM_S2", "LINEAR_SPEED_MM_S", "MECH_LENGTH_MM", "NAME_PATTERN",
           "PRINCIPAL_INERTIA_KG_M2", "SHAPE_SIZE_MM", "TRAVEL_MM", "AxisBlock", "LinkBlock",
           "MechanismFile", "MountBlock", "ShapeBlock"]
