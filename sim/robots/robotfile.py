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

A robot may instead be given by a DH table or a URDF (``[kinematics] convention = "dh" | "mdh"
| "urdf"``, with ``[[drives]]`` and ``[mass] total_kg``): its family is
:class:`sim.robots.families.chain_family.ChainFamily` (OPW closed form or numeric IK) and
cellsim writes its MJCF (:mod:`sim.robots.generate`). Every key: ``docs/robot-format.md``.

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
    """``[kinematics]``: one of the seeds' families with its dimensions, or a DH table (``dh``
    or ``mdh``), or a URDF."""

    family: Literal["five_r", "fanuc6"] | None = None
    dims_mm: dict[str, float] | None = None
    convention: Literal["dh", "mdh", "urdf"] | None = None
    dh: list[list[float]] | None = None
    urdf: str | None = None


class RobotJoints(Strict):
    range_deg: list[list[float]] | None = None
    max_speed_deg_s: list[float] | None = None
    max_accel_deg_s2: list[float] | None = None


class RobotMass(Strict):
    payload_kg: float = Field(0.0, ge=0)
    total_kg: float | None = Field(None, gt=0)


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
    title: str | None = None
    description: str = ""
    mjcf: str | None = None
    kinematics: FamilyKinematics
    joints: RobotJoints = RobotJoints()
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
    k = spec.kinematics
    if (k.family is None) == (k.convention is None):
        raise KinematicsError(f"{where}: kinematics: give family (with dims_mm) or convention "
                              "(\"dh\", \"mdh\" with dh rows, or \"urdf\" with urdf)")
    if k.convention is not None:
        return _data_robot(spec, path)
    if spec.mjcf is None or k.dims_mm is None or spec.joints.max_speed_deg_s is None:
        missing = [key for key, v in (("mjcf", spec.mjcf), ("kinematics.dims_mm", k.dims_mm),
                                      ("joints.max_speed_deg_s", spec.joints.max_speed_deg_s))
                   if v is None]
        raise KinematicsError(f"{where}: {missing[0]}: required with kinematics.family")
    if not (folder / spec.mjcf).is_file():
        raise KinematicsError(f"{where}: mjcf: no such file {folder / spec.mjcf}")
    dims = {key: v / 1000.0 for key, v in k.dims_mm.items()}
    family_cls = {"five_r": FiveR, "fanuc6": Fanuc6}[k.family]
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
    maker_joints, maker_matrix = _maker(spec, n, where)
    from sim.core.resources import models_dir

    shipped = folder.resolve().parent == models_dir().resolve()
    return RobotSpec(
        name=spec.name, title=spec.title or spec.name,
        folder=folder.name if shipped else str(folder.resolve()),
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


def _maker(spec: RobotFolderSpec, n: int, where: str):
    if spec.maker is None:
        return (), ()
    M = np.array(spec.maker.matrix, dtype=float)
    if M.shape != (n, n) or len(spec.maker.joints) != n:
        raise KinematicsError(f"{where}: maker: {n} joint names and an {n} x {n} matrix")
    if abs(np.linalg.det(M)) < 1e-9:
        raise KinematicsError(f"{where}: maker.matrix: singular (the map must be invertible)")
    return tuple(spec.maker.joints), tuple(tuple(float(v) for v in row) for row in M)


def _data_robot(spec: RobotFolderSpec, path: Path):
    """A robot given by a DH table or a URDF: its chain, the :class:`ChainFamily`, a generated
    MJCF (:mod:`sim.robots.generate`) and acceleration limits derived from the drives."""
    import dataclasses

    from sim.robots.accel_limits import derive_accel_limits
    from sim.robots.arm import arm_from_chain, chain_from_robot_file
    from sim.robots.families.chain_family import ChainFamily
    from sim.robots.generate import generated_model_path
    from sim.robots.registry import Drive, RobotSpec

    where = str(path)
    chain = chain_from_robot_file(spec, path)
    n = chain.n
    if len(spec.drives) != n:
        raise KinematicsError(f"{where}: drives: {len(spec.drives)} drives for {n} joints (a "
                              "robot given by a DH table or a URDF needs one [[drives]] per joint)")
    if spec.mass.total_kg is None:
        raise KinematicsError(f"{where}: mass.total_kg: required for a robot given by a DH table "
                              "or a URDF (the link inertias are estimated from it)")
    if spec.joints.max_speed_deg_s is not None:
        if len(spec.joints.max_speed_deg_s) != n:
            raise KinematicsError(f"{where}: joints.max_speed_deg_s: "
                                  f"{len(spec.joints.max_speed_deg_s)} values for {n} joints")
        speed = np.deg2rad(spec.joints.max_speed_deg_s)
    elif chain.max_speed is not None and np.all(np.isfinite(chain.max_speed)):
        speed = chain.max_speed
    else:
        raise KinematicsError(f"{where}: joints.max_speed_deg_s: required (the URDF gives no "
                              "velocity limits)")
    drives = tuple(Drive(d.gear_ratio, d.efficiency, d.rotor_inertia_kg_m2, d.rated_torque_nm,
                         d.peak_torque_nm, d.max_speed_rpm) for d in spec.drives)
    key = path.read_text(encoding="utf-8")
    if spec.kinematics.urdf is not None:
        key += (path.parent / spec.kinematics.urdf).read_text(encoding="utf-8", errors="replace")
    model = generated_model_path(chain, spec.name, drives, spec.mass.total_kg,
                                 key + f"|payload {spec.mass.payload_kg!r}",
                                 payload_kg=spec.mass.payload_kg)
    maker_joints, maker_matrix = _maker(spec, n, where)
    robot = RobotSpec(
        name=spec.name, title=spec.title or spec.name, folder=str(model.parent),
        robot_file=model.name, family=ChainFamily(arm_from_chain(chain, path)),
        max_speed=tuple(float(v) for v in speed),
        description=spec.description or f"robot from {path}", drives=drives,
        payload_kg=spec.mass.payload_kg, maker_joints=maker_joints, maker_matrix=maker_matrix)
    if spec.joints.max_accel_deg_s2 is not None:
        accel = np.deg2rad(spec.joints.max_accel_deg_s2)
    else:
        try:
            accel = derive_accel_limits(robot, spec.mass.payload_kg, samples=500)
        except KinematicsError as exc:
            raise KinematicsError(f"{where}: drives: {exc}") from None
    return dataclasses.replace(robot, max_accel=tuple(float(v) for v in accel))


__all__ = ["RobotFolderSpec", "load_robot_folder"]
