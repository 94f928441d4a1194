"""What a robot is, as the code sees it: :class:`RobotSpec` (name, model files, kinematic family,
speed and acceleration limits, drive trains, payload, maker's convention) and its joint position
ranges, read back from its MJCF (:func:`joint_ranges`, the single source of truth).

A spec is built from a robot folder by :mod:`sim.robots.robotfile`; the shipped ones are
:data:`sim.robots.registry.ROBOTS`. The drive physics is :mod:`sim.robots.drive`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from sim.core.resources import models_dir
from sim.errors import KinematicsError
from sim.robots.drive import Drive
from sim.robots.families import KinematicFamily


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


@cache
def _mjcf_ranges(path: str, joints: tuple[str, ...]) -> tuple[tuple[float, float], ...]:
    import mujoco  # only when ranges are read: loading the registry must not import mujoco

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


__all__ = ["RobotSpec", "joint_ranges"]
