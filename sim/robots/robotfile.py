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
cellsim writes its MJCF (:mod:`sim.robots.mjcf.generate`). Every key: ``docs/robot-format.md``.

Every problem is one line naming the file and the key (:class:`sim.errors.KinematicsError`).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from sim.core.resources import models_dir
from sim.core.tomlschema import load_toml
from sim.errors import HoldError, KinematicsError
from sim.robots.accel_limits import derive_accel_limits
from sim.robots.arm import arm_from_chain, chain_from_robot_file
from sim.robots.drive import Drive
from sim.robots.families import Fanuc6, FiveR
from sim.robots.families.chain_family import ChainFamily
from sim.robots.kinematics.chain import Chain, chain_from_urdf, inertia_problem
from sim.robots.mjcf.generate import generated_model_path, model_text, scene_text
from sim.robots.schema import RobotFolderSpec
from sim.robots.spec import RobotSpec


def load_robot_folder(folder: str | Path) -> RobotSpec:
    """The :class:`sim.robots.registry.RobotSpec` of a robot folder.

    Raises:
        KinematicsError: One line naming the file and the key.
    """
    folder = Path(folder)
    path = folder / "robot.toml" if folder.is_dir() else folder
    folder = path.parent
    spec, _ = load_toml(path, RobotFolderSpec, KinematicsError)
    where = str(path)
    for i, d in enumerate(spec.drives):  # as a scenario's [drives.jN] is held to it
        if d.peak_torque_nm < d.rated_torque_nm:
            raise KinematicsError(f"{where}: drives[{i}] (j{i + 1}): peak_torque_nm "
                                  f"{d.peak_torque_nm:g} N m is below rated_torque_nm "
                                  f"{d.rated_torque_nm:g} N m")
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
    if spec.links or spec.mass.total_kg is not None:
        key = "links" if spec.links else "mass.total_kg"
        raise KinematicsError(f"{where}: {key}: a robot with its own MJCF carries its link "
                              "inertials there (give [mass] estimated = true where they are "
                              "estimates)")
    maker_joints, maker_matrix = _maker(spec, n, where)
    shipped = folder.resolve().parent == models_dir().resolve()
    return RobotSpec(
        name=spec.name, title=spec.title or spec.name,
        folder=folder.name if shipped else str(folder.resolve()),
        robot_file=spec.mjcf,
        family=family,
        max_speed=tuple(float(v) for v in np.deg2rad(spec.joints.max_speed_deg_s)),
        description=spec.description,
        drives=_drives(spec),
        payload_kg=spec.mass.payload_kg,
        max_accel=() if spec.joints.max_accel_deg_s2 is None else tuple(
            float(v) for v in np.deg2rad(spec.joints.max_accel_deg_s2)),
        maker_joints=maker_joints, maker_matrix=maker_matrix,
        estimated_links=(True,) * n if spec.mass.estimated else ())


def _drives(spec: RobotFolderSpec) -> tuple[Drive, ...]:
    """``[[drives]]`` as :class:`~sim.robots.drive.Drive` objects, J1's first."""
    return tuple(Drive(d.gear_ratio, d.efficiency, d.rotor_inertia_kg_m2, d.rated_torque_nm,
                       d.peak_torque_nm, d.max_speed_rpm) for d in spec.drives)


def _mass_model(spec: RobotFolderSpec, chain: Chain, where: str) -> tuple[object, tuple[bool, ...]]:
    """The links' mass model for :mod:`sim.robots.mjcf.generate` (``[[links]]``, a URDF's inertials
    or ``[mass] total_kg``) and which links' inertials are estimates: every capsule of a total
    mass; a ``[[links]]`` entry marked ``estimate`` or without its centre of mass and inertia
    (a capsule of its mass); every link where ``[mass] estimated = true``."""
    n = chain.n
    if spec.links:
        if len(spec.links) != n:
            raise KinematicsError(f"{where}: links: {len(spec.links)} [[links]] for {n} moving "
                                  "links (one per joint, J1's link first)")
        if spec.mass.total_kg is not None:
            raise KinematicsError(f"{where}: mass.total_kg: give [[links]] or mass.total_kg, "
                                  "not both")
        out = []
        for i, lk in enumerate(spec.links):
            if (lk.com_mm is None) != (lk.inertia_kg_m2 is None):
                raise KinematicsError(f"{where}: links[{i}]: give com_mm and inertia_kg_m2 "
                                      "together (or neither: a uniform capsule of mass_kg)")
            if lk.com_mm is None:
                out.append((lk.mass_kg, None, None))
                continue
            if not np.all(np.isfinite(lk.com_mm + lk.inertia_kg_m2)):
                raise KinematicsError(f"{where}: links[{i}]: com_mm and inertia_kg_m2 must be "
                                      "finite numbers")
            ixx, iyy, izz, ixy, ixz, iyz = lk.inertia_kg_m2
            inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
            problem = inertia_problem(inertia)
            if problem:
                raise KinematicsError(f"{where}: links[{i}].inertia_kg_m2: {problem}")
            out.append((lk.mass_kg, np.asarray(lk.com_mm, float) / 1000.0, inertia))
        estimated = tuple(lk.estimate or lk.com_mm is None for lk in spec.links)
        mass: object = tuple(out)
    elif spec.mass.total_kg is not None:
        mass, estimated = spec.mass.total_kg, (True,) * n
    elif chain.inertials is not None:
        mass, estimated = None, (False,) * n
    else:
        raise KinematicsError(f"{where}: mass.total_kg: required for a robot given by a DH table "
                              "or a URDF without <inertial> on every moving link and without "
                              "[[links]] (the link inertias are estimated from it)")
    if spec.mass.estimated:
        estimated = (True,) * n
    return mass, estimated


def _maker(spec: RobotFolderSpec, n: int, where: str
           ) -> tuple[tuple[str, ...], tuple[tuple[float, ...], ...]]:
    if spec.maker is None:
        return (), ()
    M = np.array(spec.maker.matrix, dtype=float)
    if M.shape != (n, n) or len(spec.maker.joints) != n:
        raise KinematicsError(f"{where}: maker: {n} joint names and an {n} x {n} matrix")
    if abs(np.linalg.det(M)) < 1e-9:
        raise KinematicsError(f"{where}: maker.matrix: singular (the map must be invertible)")
    return tuple(spec.maker.joints), tuple(tuple(float(v) for v in row) for row in M)


def _data_robot(spec: RobotFolderSpec, path: Path) -> RobotSpec:
    """A robot given by a DH table or a URDF: its chain, the :class:`ChainFamily`, a generated
    MJCF (:mod:`sim.robots.mjcf.generate`) and acceleration limits derived from the drives."""
    where = str(path)
    chain = chain_from_robot_file(spec, path)
    n = chain.n
    if len(spec.drives) != n:
        raise KinematicsError(f"{where}: drives: {len(spec.drives)} drives for {n} joints (a "
                              "robot given by a DH table or a URDF needs one [[drives]] per joint)")
    mass, estimated = _mass_model(spec, chain, where)
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
    drives = _drives(spec)
    home = _home(spec, chain, where)
    if spec.mjcf is not None:
        # a shipped robot keeps its generated model in its folder (models/build_data_robots.py)
        model = path.parent / spec.mjcf
        if not model.is_file():
            raise KinematicsError(f"{where}: mjcf: no such file {model} (leave mjcf out and "
                                  "cellsim generates the model into its cache)")
        _check_kept_model(model, chain, home, where)
    else:
        key = path.read_text(encoding="utf-8")
        if spec.kinematics.urdf is not None:
            key += (path.parent / spec.kinematics.urdf).read_text(encoding="utf-8",
                                                                   errors="replace")
        model = generated_model_path(chain, spec.name, drives, mass,
                                     key + f"|payload {spec.mass.payload_kg!r}",
                                     payload_kg=spec.mass.payload_kg, home=home)
    maker_joints, maker_matrix = _maker(spec, n, where)
    shipped = model.parent.resolve().parent == models_dir().resolve()
    robot = RobotSpec(
        name=spec.name, title=spec.title or spec.name,
        folder=model.parent.name if shipped else str(model.parent),
        robot_file=model.name, family=ChainFamily(arm_from_chain(chain, path)),
        max_speed=tuple(float(v) for v in speed),
        description=spec.description or f"robot from {path}", drives=drives,
        payload_kg=spec.mass.payload_kg, maker_joints=maker_joints, maker_matrix=maker_matrix,
        estimated_links=estimated)
    if spec.joints.max_accel_deg_s2 is not None:
        accel = np.deg2rad(spec.joints.max_accel_deg_s2)
    else:
        accel = _derived_accel(robot, spec.mass.payload_kg,
                               None if spec.mjcf is not None else model.parent, f"{where}: drives")
    return dataclasses.replace(robot, max_accel=tuple(float(v) for v in accel))


def _derived_accel(robot: RobotSpec, payload_kg: float, cache: Path | None,
                   where: str) -> np.ndarray:
    """Acceleration limits derived from the drives (:mod:`sim.robots.accel_limits`), rad/s^2,
    kept beside a generated model in cellsim's cache (whose key covers the drives, the
    masses and the payload): a second load neither recomputes them nor imports mujoco."""
    n = robot.n_joints
    path = None if cache is None else cache / "accel_limits.json"
    if path is not None and path.is_file():
        try:
            v = np.asarray(json.loads(path.read_text(encoding="utf-8")), dtype=float)
            if v.shape == (n,) and np.all(np.isfinite(v)) and np.all(v > 0):
                return v
        except (OSError, ValueError):
            pass  # recomputed below
    try:
        accel = np.asarray(derive_accel_limits(robot, payload_kg, samples=500), dtype=float)
    except HoldError as exc:
        raise HoldError(f"{where}: {exc}", exc.needs) from None
    if path is not None:
        try:
            fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".accel.", suffix=".tmp")
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                json.dump([float(v) for v in accel], fh)
            os.replace(tmp, path)
        except OSError:
            pass  # an unwritable cache only costs time
    return accel


def load_urdf_robot(path: str | Path) -> RobotSpec:
    """A robot straight from a URDF file (``robot = "arm.urdf"`` in a scenario): the chain from
    the root link to ``tool0`` (else the last link), the URDF's own ``<inertial>`` elements as
    the link masses, and its ``<limit effort velocity>`` as the drives: a direct drive per
    joint (gear ratio 1, efficiency 1, no rotor inertia, rated = peak torque = ``effort``, the
    speed limit ``velocity``). No payload; acceleration limits derived from the efforts. For
    real drive trains, a payload or a maker's joint convention, write a robot folder
    (``docs/robot-format.md``).

    Raises:
        KinematicsError: One line naming the file and the joint or link: a URDF that cannot
            run as it is (no inertials, no effort or velocity limits) says which robot.toml
            keys supply what is missing.
    """
    path = Path(path)
    chain = chain_from_urdf(path)
    if chain.inertials is None:
        raise KinematicsError(f"{path}: {chain.no_inertials_why or 'no inertials'}; give it a "
                              "robot folder with [mass] total_kg and [[drives]] "
                              "(docs/robot-format.md)")
    for i, name in enumerate(chain.joint_names):
        if not chain.max_effort[i] > 0:
            raise KinematicsError(f"{path}: joint {name!r}: <limit effort> is missing or 0; give "
                                  "it a robot folder with [[drives]] (docs/robot-format.md)")
        if not (math.isfinite(chain.max_speed[i]) and chain.max_speed[i] > 0):
            raise KinematicsError(f"{path}: joint {name!r}: <limit velocity> is missing or 0; "
                                  "give it a robot folder with joints.max_speed_deg_s")
    drives = tuple(Drive(1.0, 1.0, 0.0, float(e), float(e), float(v) * 60.0 / (2.0 * math.pi))
                   for e, v in zip(chain.max_effort, chain.max_speed, strict=True))
    # the model's file and MJCF name: the URDF's robot name where it is a plain name
    name = chain.name if re.fullmatch(r"[A-Za-z0-9_-][A-Za-z0-9_.-]*", chain.name or "") else \
        re.sub(r"[^A-Za-z0-9_.-]", "_", path.stem).lstrip(".") or "robot"
    model = generated_model_path(chain, name, drives, None,
                                 "urdf|" + path.read_text(encoding="utf-8", errors="replace"))
    robot = RobotSpec(
        name=name, title=name, folder=str(model.parent), robot_file=model.name,
        family=ChainFamily(arm_from_chain(chain, path)),
        max_speed=tuple(float(v) for v in chain.max_speed),
        description=f"robot from {path}", drives=drives, payload_kg=0.0)
    accel = _derived_accel(robot, 0.0, model.parent, str(path))
    return dataclasses.replace(robot, max_accel=tuple(float(v) for v in accel))


def _check_kept_model(model: Path, chain: Chain, home: np.ndarray | None, where: str) -> None:
    """A generated model kept in the folder (``mjcf``) must still be the chain's: its joint
    ranges and ``home`` keyframe are compared (read as XML: mujoco is not imported here)."""
    try:
        root = ET.parse(model).getroot()
    except (ET.ParseError, OSError) as exc:
        raise KinematicsError(f"{where}: mjcf: {model} is not readable MJCF ({exc})") from None
    joints = [j for j in root.iter("joint") if j.get("range")]
    key = next((k for k in root.iter("key") if k.get("name") == "home"), None)
    try:
        ranges = np.array([[float(v) for v in j.get("range").split()] for j in joints])
        qhome = None if key is None else np.array([float(v) for v in key.get("qpos").split()])
    except (ValueError, AttributeError):
        ranges, qhome = np.zeros((0, 2)), None
    want_home = np.clip(0.0, chain.lower, chain.upper) if home is None else home
    if (ranges.shape != (chain.n, 2)
            or np.abs(ranges - np.c_[chain.lower, chain.upper]).max() > 1e-8
            or qhome is None or qhome.shape != (chain.n,)
            or np.abs(qhome - want_home).max() > 1e-8):
        raise KinematicsError(f"{where}: mjcf: {model.name} is not the model of this robot.toml "
                              "(its joint ranges or home keyframe differ): regenerate it "
                              "(models/build_data_robots.py) or leave mjcf out")


def _home(spec: RobotFolderSpec, chain: Chain, where: str) -> np.ndarray | None:
    """``[joints] home_deg`` in rad (None when not given), checked against the ranges."""
    h = spec.joints.home_deg
    if h is None:
        return None
    if len(h) != chain.n:
        raise KinematicsError(f"{where}: joints.home_deg: {len(h)} values for {chain.n} joints")
    q = np.deg2rad(h)
    for i, (v, lo, hi) in enumerate(zip(q, chain.lower, chain.upper, strict=True)):
        if not lo - 1e-12 <= v <= hi + 1e-12:
            raise KinematicsError(f"{where}: joints.home_deg: {h[i]:g} deg for "
                                  f"{chain.joint_names[i]} is outside its range "
                                  f"{np.rad2deg(lo):g} .. {np.rad2deg(hi):g} deg")
    return q


def generated_files(folder: str | Path) -> dict[Path, str]:
    """The model files cellsim generates for a robot folder given by a DH table or a URDF with
    ``mjcf`` set: ``{folder/mjcf: MJCF text, folder/scene.xml: scene}`` (written and checked by
    ``models/build_data_robots.py``)."""
    path = Path(folder) / "robot.toml"
    spec, _ = load_toml(path, RobotFolderSpec, KinematicsError)
    if spec.kinematics.convention is None or spec.mjcf is None:
        raise KinematicsError(f"{path}: generated_files needs a DH/URDF robot with mjcf")
    stem = Path(spec.mjcf).stem
    if stem != spec.name:
        raise KinematicsError(f"{path}: mjcf: must be {spec.name}.xml (the model is named "
                              "after the robot)")
    chain = chain_from_robot_file(spec, path)
    if len(spec.drives) != chain.n:
        raise KinematicsError(f"{path}: drives: {len(spec.drives)} drives for {chain.n} joints")
    mass, _ = _mass_model(spec, chain, str(path))
    drives = _drives(spec)
    xml = model_text(chain, spec.name, drives, mass, spec.mass.payload_kg,
                     home=_home(spec, chain, str(path)))
    return {path.parent / spec.mjcf: xml, path.parent / "scene.xml": scene_text(spec.name)}


__all__ = ["RobotFolderSpec", "generated_files", "load_robot_folder", "load_urdf_robot"]
