"""The ``robot.toml`` schema: one pydantic model per table (:class:`RobotFolderSpec` the whole
file), with the quantities and ranges of every key (``docs/robot-format.md``).

Reading a file against it and turning it into a :class:`~sim.robots.spec.RobotSpec` is
:mod:`sim.robots.robotfile`; this module only says what a valid file holds.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from sim.core.tomlschema import (
    ANGLE_DEG,
    EFFICIENCY,
    GEAR_RATIO,
    INERTIA_KG_M2,
    JOINT_ACCEL_DEG_S2,
    JOINT_DEG,
    JOINT_SPEED_DEG_S,
    LENGTH_MM,
    MASS_KG,
    PAYLOAD_KG,
    ROTOR_INERTIA_KG_M2,
    SPEED_RPM,
    TORQUE_NM,
    Columns,
    Quantity,
    Real,
    Strict,
)

#: The quantities of a DH row's columns: ``[a_mm, alpha_deg, d_mm, theta_offset_deg]``.
DH_COLUMNS = Columns((LENGTH_MM, ANGLE_DEG, LENGTH_MM, ANGLE_DEG))
#: The entries of a maker matrix: joint-coupling factors (FANUC's J2/J3 coupling is 1).
MAKER_FACTOR = Quantity("a joint-coupling factor", "", -100.0, 100.0)


class FamilyKinematics(Strict):
    """``[kinematics]``: one of the seeds' families with its dimensions, or a DH table (``dh``
    or ``mdh``), or a URDF."""

    family: Literal["five_r", "fanuc6"] | None = None
    dims_mm: dict[str, LENGTH_MM.type] | None = None
    convention: Literal["dh", "mdh", "urdf"] | None = None
    dh: Annotated[list[list[Real]], DH_COLUMNS] | None = None
    urdf: str | None = None


class RobotJoints(Strict):
    """``[joints]``: ranges and home (deg), speed and acceleration limits."""

    range_deg: list[list[JOINT_DEG.type]] | None = None
    home_deg: list[JOINT_DEG.type] | None = None
    max_speed_deg_s: list[JOINT_SPEED_DEG_S.type] | None = None
    max_accel_deg_s2: list[JOINT_ACCEL_DEG_S2.type] | None = None


class RobotMass(Strict):
    """``[mass]``: the rated payload and, for a DH/URDF robot, the links' total mass."""

    payload_kg: PAYLOAD_KG.type = 0.0
    total_kg: MASS_KG.type | None = None
    estimated: bool | None = None


class LinkBlock(Strict):
    """One moving link's inertial (``[[links]]``, J1's link first), in its joint's frame at
    q = 0 (a URDF's child link frame of the joint; a DH arm's frame at the joint)."""

    mass_kg: MASS_KG.type
    com_mm: list[LENGTH_MM.type] | None = Field(None, min_length=3, max_length=3)
    inertia_kg_m2: list[INERTIA_KG_M2.type] | None = Field(None, min_length=6, max_length=6)
    estimate: bool = False
    source: str = ""


class DriveBlock(Strict):
    """``[[drives]]``: one joint's motor and reducer, motor side."""

    gear_ratio: GEAR_RATIO.type
    efficiency: EFFICIENCY.type
    rotor_inertia_kg_m2: ROTOR_INERTIA_KG_M2.type
    rated_torque_nm: TORQUE_NM.type
    peak_torque_nm: TORQUE_NM.type
    max_speed_rpm: SPEED_RPM.type


class MakerBlock(Strict):
    """``[maker]``: the controller's joint names and convention."""

    joints: list[str]
    matrix: list[list[MAKER_FACTOR.type]]


class RobotFolderSpec(Strict):
    name: str = Field(pattern=r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*$")
    title: str | None = None
    description: str = ""
    mjcf: str | None = None
    kinematics: FamilyKinematics
    joints: RobotJoints = RobotJoints()
    mass: RobotMass = RobotMass()
    links: list[LinkBlock] = []
    drives: list[DriveBlock] = []
    maker: MakerBlock | None = None


__all__ = ["DH_COLUMNS", "MAKER_FACTOR", "DriveBlock", "FamilyKinematics", "LinkBlock",
           "MakerBlock", "RobotFolderSpec", "RobotJoints", "RobotMass"]
