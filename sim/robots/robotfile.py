"""A robot is a folder: ``models/<folder>/robot.toml`` beside the MJCF, ``scene.xml`` and a
README deriving each number. The registry (:data:`sim.robots.registry.ROBOTS`) scans
``models/*/robot.toml``; a scenario may name a folder of its own (``robot = "path/to/folder"``).

``robot.toml`` of a robot with one of the seeds' closed forms::

    name = "lrmate200ic5l"
    title = "FANUC LR Mate 200iC/5L"
    description = "one line for cellsim list"
    mjcf = "lrmate200ic5l.xml"             # the joint ranges are the MJCF's
    [kinematics]
    family = "fanuc6"                      # "five_r" (seed 000) or "fanuc6" (seed 004)
    dims_mm = { d2 = 75, d3 = 400, d4 = 75, R4 = 410, R6 = 80 }
    [joints]
    max_speed_deg_s = [270, 270, 270, 450, 450, 720]
    max_accel_deg_s2 = [1400, 2300, 5200, 40000, 43000, 210000]
    [mass]
    payload_kg = 5.0
    [[drives]]                             # one per joint, motor side
    gear_ratio = 120
    efficiency = 0.75
    rotor_inertia_kg_m2 = 2.0e-5
    rated_torque_nm = 0.65
    peak_torque_nm = 2.4
    max_speed_rpm = 6000
    [maker]                                # the controller's joint convention (optional)
    joints = ["J1", "J2", "J3", "J4", "J5", "J6"]
    matrix = [[1, 0, 0, 0, 0, 0], ...]     # maker joint values = matrix @ seed joint values

Every problem is one line naming the file and the key (:class:`sim.errors.KinematicsError`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from sim.core.tomlschema import Strict, load_toml
from sim.errors import KinematicsError


class FamilyKinematics(Strict):
    family: Literal["five_r", "fanuc6"]
    dims_mm: dict[str, float]


class RobotJoints(Strict):
    max_speed_deg_s: list[float]
    max_accel_deg_s2: list[float] | None = None


class RobotMass(Strict):
    payload_kg: float = Field(0.0, ge=0)


class DriveBlock(Strict):
    gear_ratio: float = Field(gt=0)
    efficiency: float = Field(gt=0, le=1)
    rotor_inertia_kg_m2: float = Field(ge=0)
    rated_torque_nm: float = Field(gt=0)
    peak_torque_nm: float = Field(gt=0)
    max_speed_rpm: float = Field(gt=0)


class MakerBlock(Strict):
    joints: list[str]
    matrix: list[list[float]]


class RobotFolderSpec(Strict):
    name: str = Field(pattern=r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*$")
    title: str
    description: str = ""
    mjcf: str
    kinematics: FamilyKinematics
    joints: RobotJoints
    mass: RobotMass = RobotMass()
    drives: list[DriveBlock] = []
    maker: MakerBlock | None = None


def load_robot_folder(folder: str | Path):  # -> RobotSpec (imported lazily: no cycle)
    """The :class:`sim.robots.registry.RobotSpec` of a robot folder.

    Raises:
        KinematicsError: One line naming the file and the key.
    """
    from sim.robots.families import Fanuc6, FiveR
    from sim.robots.registry import Drive, RobotSpec

    folder = Path(folder)
    path = folder / "robot.toml" if folder.is_dir() else folder
    folder = path.parent
    spec, _ = load_toml(path, RobotFolderSpec, KinematicsError)
    where = str(path)
    if not (folder / spec.mjcf).is_file():
        raise KinematicsError(f"{where}: mjcf: no such file {folder / spec.mjcf}")
    dims = {k: v / 1000.0 for k, v in spec.kinematics.dims_mm.items()}
    family_cls = {"five_r": FiveR, "fanuc6": Fanuc6}[spec.kinematics.family]
    try:
        family = family_cls(dims)
    except (KinematicsError, KeyError, ValueError) as exc:
        raise KinematicsError(f"{where}: kinematics.dims_mm: {exc}") from None
    n = family.n_joints
    for key, values in (("joints.max_speed_deg_s", spec.joints.max_speed_deg_s),
                        ("joints.max_accel_deg_s2", spec.joints.max_accel_deg_s2)):
        if values is not None and len(values) != n:
            raise KinematicsError(f"{where}: {key}: {len(values)} values for {n} joints")
    if spec.drives and len(spec.drives) != n:
        raise KinematicsError(f"{where}: drives: {len(spec.drives)} drives for {n} joints")
    maker_joints: tuple[str, ...] = ()
    maker_matrix: tuple[tuple[float, ...], ...] = ()
    if spec.maker is not None:
        M = np.array(spec.maker.matrix, dtype=float)
        if M.shape != (n, n) or len(spec.maker.joints) != n:
            raise KinematicsError(f"{where}: maker: {n} joint names and an {n} x {n} matrix")
        if abs(np.linalg.det(M)) < 1e-9:
            raise KinematicsError(f"{where}: maker.matrix: singular (the map must be invertible)")
        maker_joints = tuple(spec.maker.joints)
        maker_matrix = tuple(tuple(float(v) for v in row) for row in M)
    from sim.core.resources import models_dir

    shipped = folder.resolve().parent == models_dir().resolve()
    return RobotSpec(
        name=spec.name, title=spec.title, folder=folder.name if shipped else str(folder.resolve()),
        robot_file=spec.mjcf,
        family=family,
        max_speed=tuple(float(v) for v in np.deg2rad(spec.joints.max_speed_deg_s)),
        description=spec.description,
        drives=tuple(Drive(d.gear_ratio, d.efficiency, d.rotor_inertia_kg_m2,
                           d.rated_torque_nm, d.peak_torque_nm, d.max_speed_rpm)
                     for d in spec.drives),
        payload_kg=spec.mass.payload_kg,
        max_accel=() if spec.joints.max_accel_deg_s2 is None else tuple(
            float(v) for v in np.deg2rad(spec.joints.max_accel_deg_s2)),
        maker_joints=maker_joints, maker_matrix=maker_matrix)


__all__ = ["RobotFolderSpec", "load_robot_folder"]
