"""Registry of the robots cellsim models.

A robot is a folder under ``models/``: its MJCF, ``scene.xml``, a README deriving each number
and a ``robot.toml`` with what the code needs (:mod:`sim.robots.robotfile`: kinematic family and
dimensions, speed and acceleration limits, drive trains, payload, the maker's joint convention);
:data:`ROBOTS` is built by scanning those folders, and :func:`resolve_robot` also takes a folder
of one's own. Joint position ranges live in the MJCF files (single source of truth, read back
with :func:`joint_ranges`). Sources of every number: the README of each model folder and
``../shared/reference/robots.md``.
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
from sim.robots.families import KinematicFamily

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

    def motor_torque(self, tau_joint: ArrayLike, qd: ArrayLike, qdd: ArrayLike,
                     armature: float | ArrayLike = 0.0) -> NDArray[np.float64]:
        """The motor torque that gives joint torque ``tau_joint`` (N m, with the joint-side
        inertia ``armature * qdd`` in it) at joint speed ``qd`` and acceleration ``qdd``, N m,
        motor side: the gear's efficiency on the load torque only, in the direction power
        flows, and the rotor's inertia on the motor side::

            tau_load = tau_joint - armature qdd
            tau_m    = tau_load / (N eta) + J_r N qdd   where tau_load qd >= 0 (the motor drives)
            tau_m    = tau_load eta / N   + J_r N qdd   where the load drives back

        At standstill, ``|qd| <`` :data:`COULOMB_SPEED` (where the friction law ramps through
        zero), the motor drives (the larger torque): a servo holding a joint still sees a
        speed that only wobbles about zero, and the gear's direction of power flow must not
        flip with it from one sample to the next.

        The one formula of cellsim: the simulation's drive limit and sizing both use it."""
        tau_joint = np.asarray(tau_joint, dtype=float)
        qd = np.asarray(qd, dtype=float)
        qdd = np.asarray(qdd, dtype=float)
        n, eta = self.gear_ratio, self.efficiency
        load = tau_joint - np.asarray(armature, dtype=float) * qdd
        drives = (load * qd >= 0.0) | (np.abs(qd) < COULOMB_SPEED)
        through_gear = np.where(drives, load / (n * eta), load * eta / n)
        return through_gear + self.rotor_inertia * n * qdd

    def joint_torque_for(self, tau_motor: ArrayLike, qd: ArrayLike, qdd: ArrayLike,
                         armature: float | ArrayLike = 0.0) -> NDArray[np.float64]:
        """The joint torque at which :meth:`motor_torque` is ``tau_motor`` (its inverse at
        given ``qd`` and ``qdd``), N m."""
        tau_motor = np.asarray(tau_motor, dtype=float)
        qd = np.asarray(qd, dtype=float)
        qdd = np.asarray(qdd, dtype=float)
        n, eta = self.gear_ratio, self.efficiency
        through_gear = tau_motor - self.rotor_inertia * n * qdd
        # tau_load has the sign of through_gear; standstill as in motor_torque
        drives = (through_gear * qd >= 0.0) | (np.abs(qd) < COULOMB_SPEED)
        load = np.where(drives, through_gear * n * eta, through_gear * n / eta)
        return load + np.asarray(armature, dtype=float) * qdd

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
        estimated_links: Per moving link (J1's first), whether its inertial is an estimate
            (a capsule of an estimated mass, ``robot.toml``'s ``[mass] estimated``, a
            ``[[links]]`` entry marked ``estimate``); empty: none is.
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
    estimated_links: tuple[bool, ...] = ()

    @property
    def joints_on_estimates(self) -> tuple[str, ...]:
        """The joints whose torques rest on an estimated inertial: those with an estimated
        link at or beyond them (a joint carries every link past it)."""
        est = self.estimated_links
        return tuple(j for i, j in enumerate(self.joints) if any(est[i:]))

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


def _shipped_robots() -> Registry[RobotSpec]:
    """The robot folders of ``models/`` (each with a ``robot.toml``, :mod:`sim.robots.robotfile`)."""
    from sim.robots.robotfile import load_robot_folder

    reg: Registry[RobotSpec] = Registry("robot")
    for path in sorted(models_dir().glob("*/robot.toml")):
        spec = load_robot_folder(path.parent)
        reg.add(spec.name, spec)
    return reg




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


def resolve_robot(ref: str, base: Path | None = None) -> RobotSpec:
    """A shipped robot by name, a robot folder of one's own (a path, relative to ``base``, the
    scenario's folder, holding a ``robot.toml``), or a URDF file (``*.urdf``:
    :func:`sim.robots.robotfile.load_urdf_robot`).

    Raises:
        UnknownNameError: Unknown name (the message lists the robots).
        KinematicsError: A folder without a valid ``robot.toml``, or a URDF that cannot run as
            it is (one line naming the file and the key, joint or link).
    """
    if ref.lower().endswith(".urdf"):
        from sim.robots.robotfile import load_urdf_robot

        path = Path(ref) if base is None else base / ref
        return load_urdf_robot(path)
    if "/" in ref or "\\" in ref or ref.endswith(".toml"):
        from sim.robots.robotfile import load_robot_folder

        path = Path(ref) if base is None else base / ref
        if not (path.is_dir() and (path / "robot.toml").is_file()) and not path.is_file():
            raise KinematicsError(f"{path}: no robot folder (a folder with a robot.toml)")
        return load_robot_folder(path)
    return ROBOTS.get(ref)


# built last: a robot given by a DH table or a URDF needs this module's functions to load
#: The shipped robots by name, read from ``models/*/robot.toml``.
ROBOTS: Registry[RobotSpec] = _shipped_robots()
