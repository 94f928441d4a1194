"""Registry of the robots cellsim models.

Each :class:`RobotSpec` names the robot's MJCF file (under ``models/``), its kinematic family
and the dimensions its closed-form kinematics use, in metres. Joint position ranges live in
the MJCF files (single source of truth, read back with :func:`joint_ranges`); joint speed
limits, which MJCF has no field for, live here. Sources of every number: the README of each
model folder and ``../shared/reference/robots.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.registry import Registry
from sim.core.resources import models_dir
from sim.errors import KinematicsError
from sim.robots.families import Fanuc6, FiveR, KinematicFamily

#: Joint speed (rad/s) from which a joint's Coulomb friction is its ``frictionloss`` in full;
#: below it the friction torque ramps linearly through zero: ``F * clip(qd / COULOMB_SPEED, -1,
#: 1)``, a smooth odd law that is ``F sign(qd)`` wherever ``|qd| >= 1e-3 rad/s``. The simulation
#: applies this law (:mod:`sim.cells.compose`: one friction actuator per joint) and the inverse
#: dynamics adds it, so both see the same friction.
COULOMB_SPEED = 1e-3


def coulomb(frictionloss: ArrayLike, qd: ArrayLike) -> NDArray[np.float64]:
    """Coulomb friction torque opposing nothing, ``F * clip(qd / COULOMB_SPEED, -1, 1)``, N m
    (the torque a drive spends on friction; shapes broadcast, ``F`` per joint)."""
    return np.asarray(frictionloss, dtype=float) * np.clip(
        np.asarray(qd, dtype=float) / COULOMB_SPEED, -1.0, 1.0)


#: Motor speed, as a fraction of its maximum, up to which the peak torque is available (the
#: generic peak curve of :meth:`Drive.peak_torque_at`).
PEAK_KNEE_FRACTION = 0.7
#: rad/s -> rpm.
RPM_PER_RAD_S = 60.0 / (2.0 * np.pi)


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

    def peak_torque_at(self, speed_rpm: ArrayLike,
                       knee_fraction: float = PEAK_KNEE_FRACTION) -> NDArray[np.float64]:
        """Peak (intermittent) motor torque available at ``|speed_rpm|``, N m, motor side.

        A generic S1/peak shape: the peak torque up to ``knee_fraction * max_speed_rpm``, then
        a straight voltage-limit slope down to the rated torque at ``max_speed_rpm``; zero above
        ``max_speed_rpm``.
        """
        n = np.abs(np.asarray(speed_rpm, dtype=float))
        n_max = float(self.max_speed_rpm)
        n_k = knee_fraction * n_max
        slope = (self.peak_torque - self.rated_torque) / max(n_max - n_k, 1e-300)
        out = np.where(n <= n_k, self.peak_torque, self.peak_torque - slope * (n - n_k))
        return np.where(n <= n_max, out, 0.0)

    def joint_peak_torque_at(self, joint_speed: ArrayLike) -> NDArray[np.float64]:
        """The drive's peak torque at the joint, ``peak_torque_at(motor speed) x ratio x
        efficiency``, N m, at joint speed(s) ``joint_speed`` (rad/s)."""
        rpm = np.asarray(joint_speed, dtype=float) * self.gear_ratio * RPM_PER_RAD_S
        return self.peak_torque_at(rpm) * self.gear_ratio * self.efficiency

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
        family: The kinematic family object with the robot's dimensions, m
            (:class:`~sim.robots.families.FiveR`: seed 000 Table 1 screw axes, eq. 5, l1, d1,
            l2, l3 with l3 = J4 axis to the tool point; :class:`~sim.robots.families.Fanuc6`:
            seed 004 modified DH, eq. 6-7, d2, d3, d4, R4, R6).
        max_speed: Joint speed limits, rad/s, shape (n_joints,).
        description: One line for ``cellsim list``.
        drives: Default drive train per joint (documented in the model's README); the
            MJCF ``armature`` equals each drive's reflected inertia.
        payload_kg: Rated payload, kg.
        max_accel: Joint acceleration limits, rad/s^2, shape (n_joints,): derived from the drive
            train with the rated payload (:mod:`sim.robots.accel_limits`, rounded down to two
            significant digits in deg/s^2; the model's README shows the derivation).
        maker_joints: The maker's joint names (its controller's), when it has a convention.
        maker_matrix: ``M`` with ``maker joint values = M @ seed joint values`` (rows of the
            matrix); empty: the seed's convention is the maker's (:mod:`sim.robots.maker`).
    """

    name: str
    title: str
    folder: str
    robot_file: str
    family: KinematicFamily
    max_speed: tuple[float, ...]
    description: str = ""
    drives: tuple[Drive, ...] = ()
    joint_names: tuple[str, ...] = field(default=())
    payload_kg: float = 0.0
    max_accel: tuple[float, ...] = ()
    maker_joints: tuple[str, ...] = ()
    maker_matrix: tuple[tuple[float, ...], ...] = ()

    @property
    def n_joints(self) -> int:
        return len(self.max_speed)

    @property
    def dims(self) -> dict[str, float]:
        """The family's kinematic dimensions, m."""
        return self.family.dims

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


#: The shipped robots by name.
ROBOTS: Registry[RobotSpec] = Registry("robot")
for _spec in (
        RobotSpec(
            name="lrmate100ib",
            title="FANUC LR Mate 100iB",
            folder="fanuc_lrmate100ib",
            robot_file="lrmate100ib.xml",
            # seed 000 Table 2 point 0 fixes d1 and l1+l2+l3; split after the RoboDK table
            # (../shared/reference/robots.md); l3 = 80 mm flange + 145 mm torch.
            family=FiveR({"l1": 0.150, "d1": 0.250, "l2": 0.220, "l3": 0.225}),
            # as commonly quoted for the LR Mate 100iB/200iB family (estimate, see model README)
            max_speed=_deg(240, 270, 270, 330, 480),
            description="5-axis FANUC LR Mate 100iB (seed 000), 5 kg payload",
            # estimated beta-iS class motors (0.2-0.75 kW) + harmonic reducers; the README of
            # the model lists the sizing criteria (speed, gravity torque with 5 kg payload)
            drives=(
                Drive(120, 0.75, 2.0e-5, 0.65, 2.4, 6000),
                Drive(120, 0.75, 4.5e-5, 1.3, 4.5, 6000),
                Drive(120, 0.75, 2.0e-5, 0.65, 2.4, 6000),
                Drive(80, 0.70, 5.0e-6, 0.32, 1.0, 5000),
                Drive(50, 0.70, 3.0e-6, 0.25, 0.8, 5000),
            ),
            payload_kg=5.0,
            max_accel=_deg(1800, 4500, 7500, 8700, 200000),
            # FANUC's joints (J3 from the horizontal; the 5-axis wrist is J5, J6) from the
            # RoboDK-derived table: theta = (J1, J2, -J2 - J3, -J5, -J6) (sim/robots/maker.py)
            maker_joints=("J1", "J2", "J3", "J5", "J6"),
            maker_matrix=((1, 0, 0, 0, 0), (0, 1, 0, 0, 0), (0, -1, -1, 0, 0),
                          (0, 0, 0, -1, 0), (0, 0, 0, 0, -1)),
        ),
        RobotSpec(
            name="lrmate200ic5l",
            title="FANUC LR Mate 200iC/5L",
            folder="fanuc_lrmate200ic",
            robot_file="lrmate200ic5l.xml",
            family=Fanuc6({"d2": 0.075, "d3": 0.400, "d4": 0.075, "R4": 0.410, "R6": 0.080}),
            max_speed=_deg(270, 270, 270, 450, 450, 720),  # ROS-Industrial URDF
            description="6-axis FANUC LR Mate 200iC/5L (seed 004), 5 kg payload",
            # estimated beta-iS class motors (0.2-0.75 kW) + harmonic reducers (model README)
            drives=(
                Drive(120, 0.75, 2.0e-5, 0.65, 2.4, 6000),
                Drive(120, 0.75, 4.5e-5, 1.3, 4.5, 6000),
                Drive(120, 0.75, 2.0e-5, 0.65, 2.4, 6000),
                Drive(75, 0.70, 5.0e-6, 0.32, 1.0, 6000),
                Drive(75, 0.70, 5.0e-6, 0.32, 1.0, 6000),
                Drive(48, 0.70, 3.0e-6, 0.25, 0.8, 6000),
            ),
            payload_kg=5.0,
            max_accel=_deg(1400, 2300, 5200, 40000, 43000, 210000),
            # FANUC's joints: U = s * theta (the URDF's), J3 from the horizontal:
            # FANUC = (U1, U2, U3 - U2, U4, U5, U6) (sim/robots/maker.py)
            maker_joints=("J1", "J2", "J3", "J4", "J5", "J6"),
            maker_matrix=((1, 0, 0, 0, 0, 0), (0, -1, 0, 0, 0, 0), (0, 1, 1, 0, 0, 0),
                          (0, 0, 0, -1, 0, 0), (0, 0, 0, 0, 1, 0), (0, 0, 0, 0, 0, -1)),
        ),
        RobotSpec(
            name="robot_5r",
            title="5R welding robot",
            folder="robot_5r",
            robot_file="robot_5r.xml",
            # chosen for seed 001's cell (models/robot_5r/README.md): l3 = 100 mm flange +
            # 300 mm torch; long upper arm, short forearm for a large seam radius
            family=FiveR({"l1": 0.250, "d1": 1.000, "l2": 0.600, "l3": 0.400}),
            max_speed=_deg(150, 150, 180, 300, 450),  # estimate for the 1.8-2 m reach class
            description="5-axis welding robot for large cylindrical parts (seed 001)",
            # estimated alpha-iS class motors (1-3 kW) + cycloidal/harmonic reducers
            drives=(
                Drive(160, 0.80, 1.2e-3, 8.0, 32.0, 4000),
                Drive(160, 0.80, 2.3e-3, 12.0, 46.0, 4000),
                Drive(150, 0.80, 5.2e-4, 4.0, 15.0, 5000),
                Drive(90, 0.75, 2.9e-4, 2.0, 7.8, 5000),
                Drive(60, 0.75, 1.0e-4, 1.0, 4.0, 5000),
            ),
            payload_kg=10.0,
            max_accel=_deg(1200, 1700, 3700, 6900, 28000),
        ),
):
    ROBOTS.add(_spec.name, _spec)


@lru_cache(maxsize=None)
def _mjcf_ranges(path: str, joints: tuple[str, ...]) -> tuple[tuple[float, float], ...]:
    import mujoco

    model = mujoco.MjModel.from_xml_path(path)
    out = []
    for j in joints:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        if jid < 0:
            raise KinematicsError(f"{path}: no joint named {j!r}; joints: {', '.join(joints)}")
        lo, hi = model.jnt_range[jid]
        out.append((float(lo), float(hi)) if model.jnt_limited[jid] else (-np.inf, np.inf))
    return tuple(out)


def joint_ranges(spec: RobotSpec) -> NDArray[np.float64]:
    """Joint position ranges read from the robot's MJCF (the single source of truth).

    Args:
        spec: The robot.

    Returns:
        Array of shape (n_joints, 2): lower and upper limit of joints ``j1..jN``, rad, in the
        seed's convention (MuJoCo qpos equals the seed's joint value).
    """
    return np.array(_mjcf_ranges(str(spec.robot_path), spec.joints), dtype=float)


def get_robot(name: str) -> RobotSpec:
    """Look a robot up by name.

    Raises:
        UnknownNameError: The name is not registered; the message lists the known robots.
    """
    return ROBOTS.get(name)
