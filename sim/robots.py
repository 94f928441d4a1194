"""Registry of the robots cellsim models.

Each :class:`RobotSpec` names the robot's MJCF file (under ``models/``), its kinematic family
and the dimensions its closed-form kinematics use, in metres. Joint position ranges live in
the MJCF files (single source of truth, read back with :func:`joint_ranges`); joint speed
limits, which MJCF has no field for, live here. Sources of every number: the README of each
model folder and ``../shared/reference/robots.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sim.errors import UnknownNameError
from sim.resources import models_dir


@dataclass(frozen=True)
class Drive:
    """Drive train of one joint (motor + gearbox), motor-side quantities.

    Attributes:
        gear_ratio: Motor turns per joint turn (> 0).
        efficiency: Gear efficiency, 0 < eta <= 1.
        rotor_inertia: Motor rotor inertia (plus input-side gear inertia), kg m^2, motor side.
        rated_torque: Motor continuous (rated) torque, N m, motor side.
        peak_torque: Motor peak torque, N m, motor side.
        max_speed_rpm: Motor maximum speed, rpm.
    """

    gear_ratio: float
    efficiency: float
    rotor_inertia: float
    rated_torque: float
    peak_torque: float
    max_speed_rpm: float

    @property
    def reflected_inertia(self) -> float:
        """Rotor inertia seen at the joint, ``rotor_inertia * gear_ratio**2``, kg m^2."""
        return self.rotor_inertia * self.gear_ratio**2


@dataclass(frozen=True)
class RobotSpec:
    """Static description of one robot.

    Attributes:
        name: Registry name used on the command line and in scenarios.
        title: Human-readable name.
        folder: Model folder under ``models/``.
        robot_file: Robot MJCF file inside ``folder``.
        family: Kinematic family: ``"5r"`` (seed 000 Table 1 screw axes, eq. 5) or
            ``"fanuc6"`` (seed 004 modified DH, eq. 6-7).
        dims: Kinematic dimensions in metres. ``"5r"``: l1, d1, l2, l3 (seed 000 Table 1,
            l3 = J4 axis to the tool point); ``"fanuc6"``: d2, d3, d4, R4, R6 (seed 004 Table 1).
        max_speed: Joint speed limits, rad/s, shape (n_joints,).
        description: One line for ``cellsim list``.
        drives: Default drive train per joint (documented in the model's README); the
            MJCF ``armature`` equals each drive's reflected inertia.
    """

    name: str
    title: str
    folder: str
    robot_file: str
    family: str
    dims: dict[str, float]
    max_speed: tuple[float, ...]
    description: str = ""
    drives: tuple[Drive, ...] = ()
    joint_names: tuple[str, ...] = field(default=())

    @property
    def n_joints(self) -> int:
        return len(self.max_speed)

    @property
    def joints(self) -> tuple[str, ...]:
        return self.joint_names or tuple(f"j{i + 1}" for i in range(self.n_joints))

    @property
    def robot_path(self) -> Path:
        return models_dir() / self.folder / self.robot_file

    @property
    def scene_path(self) -> Path:
        return models_dir() / self.folder / "scene.xml"


def _deg(*values: float) -> tuple[float, ...]:
    return tuple(float(np.deg2rad(v)) for v in values)


ROBOTS: dict[str, RobotSpec] = {
    spec.name: spec
    for spec in (
        RobotSpec(
            name="lrmate100ib",
            title="FANUC LR Mate 100iB",
            folder="fanuc_lrmate100ib",
            robot_file="lrmate100ib.xml",
            family="5r",
            # seed 000 Table 2 point 0 fixes d1 and l1+l2+l3; split after the RoboDK table
            # (../shared/reference/robots.md); l3 = 80 mm flange + 145 mm torch.
            dims={"l1": 0.150, "d1": 0.250, "l2": 0.220, "l3": 0.225},
            max_speed=_deg(240, 270, 270, 330, 480),  # provisional; see model README
            description="5-axis FANUC LR Mate 100iB (seed 000), 5 kg payload",
        ),
        RobotSpec(
            name="lrmate200ic5l",
            title="FANUC LR Mate 200iC/5L",
            folder="fanuc_lrmate200ic",
            robot_file="lrmate200ic5l.xml",
            family="fanuc6",
            dims={"d2": 0.075, "d3": 0.400, "d4": 0.075, "R4": 0.410, "R6": 0.080},
            max_speed=_deg(270, 270, 270, 450, 450, 720),
            description="6-axis FANUC LR Mate 200iC/5L (seed 004), 5 kg payload",
        ),
        RobotSpec(
            name="robot_5r",
            title="5R welding robot",
            folder="robot_5r",
            robot_file="robot_5r.xml",
            family="5r",
            dims={"l1": 0.200, "d1": 0.900, "l2": 0.800, "l3": 0.350},  # provisional
            max_speed=_deg(150, 150, 180, 300, 300),  # provisional
            description="5-axis welding robot for large cylindrical parts (seed 001)",
        ),
    )
}


def get_robot(name: str) -> RobotSpec:
    """Look a robot up by name.

    Raises:
        UnknownNameError: The name is not registered; the message lists the known robots.
    """
    try:
        return ROBOTS[name]
    except KeyError:
        raise UnknownNameError("robot", name, ROBOTS) from None
