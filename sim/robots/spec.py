"""What a robot is, as the code sees it: :class:`RobotSpec` (name, model files, kinematic family,
speed and acceleration limits, drive trains, payload, maker's convention) and its joint position
ranges, read back from its MJCF (:func:`joint_ranges`, the single source of truth).

A spec is built from a robot folder by :mod:`sim.robots.robotfile`; the shipped ones are
:data:`sim.robots.registry.ROBOTS`. The drive physics is :mod:`sim.robots.drive`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from sim.core.resources import models_dir
from sim.errors import KinematicsError
from sim.robots.drive import Drive
from sim.robots.families import KinematicFamily
from sim.robots.mechanisms.spec import AxisSpec


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
        external: The cell's external axes after the arm's joints, ``(name, axis)`` each
            (:meth:`with_axes`): the joint names, limits and drives above then cover them too;
            the kinematics (``family``, the model files) stay the arm's (:attr:`arm`).
        partners: The cell's other robots after the external axes, ``(name, robot)`` each
            (:meth:`with_partners`): their joints are named ``<name>_<joint>``.
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
    external: tuple[tuple[str, AxisSpec], ...] = ()
    partners: tuple[tuple[str, RobotSpec], ...] = ()

    def with_axes(self, axes: Sequence[tuple[str, AxisSpec]]) -> RobotSpec:
        """The arm with a cell's external axes after its joints (a cell's driven joints):
        names, speed and acceleration limits, drives and ranges of both; the arm itself when
        there are none."""
        if not axes:
            return self
        arm = self.arm
        k = len(axes)
        accel = arm.max_accel or (np.inf,) * arm.n_joints
        return dataclasses.replace(
            arm, joint_names=arm.joints + tuple(n for n, _ in axes),
            max_speed=arm.max_speed + tuple(float(a.max_speed) for _, a in axes),
            max_accel=tuple(accel) + tuple(float(a.max_accel) for _, a in axes),
            drives=arm.drives + tuple(a.drive for _, a in axes) if arm.drives else (),
            estimated_links=(arm.estimated_links + (False,) * k) if arm.estimated_links else (),
            external=tuple(axes))

    def with_partners(self, partners: Sequence[tuple[str, RobotSpec]]) -> RobotSpec:
        """This system (the arm and its cell's axes) with the cell's other robots' joints
        after it (``<name>_<joint>``: names, limits, drives); itself when there are none."""
        if not partners:
            return self
        names = list(self.joints)
        speed, accel = list(self.max_speed), list(self.max_accel or (np.inf,) * self.n_joints)
        drives: list[Drive] | None = list(self.drives) if self.drives else None
        est = list(self.estimated_links or (False,) * self.n_joints)
        for name, r in partners:
            names += [f"{name}_{j}" for j in r.joints]
            speed += list(r.max_speed)
            accel += list(r.max_accel or (np.inf,) * r.n_joints)
            drives = drives + list(r.drives) if drives is not None and r.drives else None
            est += list(r.estimated_links or (False,) * r.n_joints)
        return dataclasses.replace(
            self, joint_names=tuple(names), max_speed=tuple(speed), max_accel=tuple(accel),
            drives=tuple(drives or ()),
            estimated_links=tuple(est) if any(est) else (),
            partners=self.partners + tuple(partners))

    @property
    def without_partners(self) -> RobotSpec:
        """The arm and its cell's axes, without the cell's other robots (what the first
        robot's phases move); itself when there are none."""
        if not self.partners:
            return self
        n = self.n_joints - sum(r.n_joints for _, r in self.partners)
        return dataclasses.replace(
            self, joint_names=self.joints[:n], max_speed=self.max_speed[:n],
            max_accel=self.max_accel[:n] if np.all(np.isfinite(self.max_accel[:n])) else (),
            drives=self.drives[:n], estimated_links=self.estimated_links[:n], partners=())

    @property
    def n_arm(self) -> int:
        """The arm's joints (without external axes and other robots)."""
        return self.n_joints - len(self.external) - sum(r.n_joints for _, r in self.partners)

    @property
    def linear(self) -> tuple[bool, ...]:
        """Whether each joint of the system is linear (a track's travel: m, N)."""
        k = self.n_joints - self.n_arm - len(self.external)
        return ((False,) * self.n_arm + tuple(a.kind == "prismatic" for _, a in self.external)
                + (False,) * k)

    @property
    def arm(self) -> RobotSpec:
        """The robot without external axes and other robots."""
        if not self.external and not self.partners:
            return self
        n = self.n_arm
        return dataclasses.replace(
            self, joint_names=self.joints[:n], max_speed=self.max_speed[:n],
            max_accel=self.max_accel[:n] if np.all(np.isfinite(self.max_accel[:n])) else (),
            drives=self.drives[:n], estimated_links=self.estimated_links[:n], external=(),
            partners=())

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
        seed's convention (MuJoCo qpos equals the seed's joint value), then those of the
        external axes (rad or m, from their mechanism files), then those of the cell's other
        robots (:meth:`RobotSpec.with_partners`).
    """
    arm = spec.arm
    ranges = np.array(_mjcf_ranges(str(arm.robot_path), arm.joints), dtype=float)
    if spec.external:
        ranges = np.vstack([ranges, [a.range for _, a in spec.external]])
    for _, other in spec.partners:
        ranges = np.vstack([ranges, joint_ranges(other)])
    return ranges


__all__ = ["RobotSpec", "joint_ranges"]
