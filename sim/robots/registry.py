"""Registry of the robots cellsim models: :data:`ROBOTS`, :func:`get_robot`, :func:`resolve_robot`.

A robot is a folder under ``models/``: its MJCF, ``scene.xml``, a README deriving each number
and a ``robot.toml`` with what the code needs (:mod:`sim.robots.robotfile`: kinematic family and
dimensions, speed and acceleration limits, drive trains, payload, the maker's joint convention);
:data:`ROBOTS` is built by scanning those folders on first use, and :func:`resolve_robot` also takes a folder
of one's own. Joint position ranges live in the MJCF files (single source of truth, read back
with :func:`joint_ranges`). Sources of every number: the README of each model folder and
``../shared/reference/robots.md``.

The registry is the top of the robot-data chain, each importing only those before it:
:mod:`~sim.robots.drive` (drive physics) <- :mod:`~sim.robots.spec` (:class:`RobotSpec`,
:func:`joint_ranges`) <- :mod:`~sim.robots.schema` (the ``robot.toml`` schema) <-
:mod:`~sim.robots.arm` <- :mod:`~sim.robots.robotfile` (loading a folder) <- this module. It
re-exports :class:`Drive`, :class:`RobotSpec`, :func:`joint_ranges`, :func:`coulomb` and the
drive constants under their old path.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from planners.registry import Registry
from sim.core.registry import LazyRegistry
from sim.core.resources import models_dir
from sim.errors import KinematicsError
from sim.robots.drive import (
    COULOMB_SPEED,
    PEAK_KNEE_FRACTION,
    RPM_PER_RAD_S,
    Drive,
    coulomb,
)
from sim.robots.robotfile import load_robot_folder, load_urdf_robot
from sim.robots.spec import RobotSpec, joint_ranges


def _shipped_robots() -> Iterator[tuple[str, RobotSpec]]:
    """The robot folders of ``models/``, each with a ``robot.toml``
    (:mod:`sim.robots.robotfile`)."""
    for path in sorted(models_dir().glob("*/robot.toml")):
        spec = load_robot_folder(path.parent)
        yield spec.name, spec


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
        path = Path(ref) if base is None else base / ref
        return _own_name(load_urdf_robot(path), path)
    if "/" in ref or "\\" in ref or ref.endswith(".toml"):
        path = Path(ref) if base is None else base / ref
        if not (path.is_dir() and (path / "robot.toml").is_file()) and not path.is_file():
            raise KinematicsError(f"{path}: no robot folder (a folder with a robot.toml)")
        return _own_name(load_robot_folder(path), path / "robot.toml" if path.is_dir() else path)
    if ref not in ROBOTS and base is not None and (base / ref / "robot.toml").is_file():
        # a folder of one's own beside the scenario, named as a shipped robot is named
        raise KinematicsError(f"unknown robot {ref!r}; {base / ref} is a robot folder: give "
                              f"it as a path, \"./{ref}\"")
    return ROBOTS.get(ref)


def _own_name(spec: RobotSpec, where: Path) -> RobotSpec:
    """A robot of one's own must not take a shipped robot's name: cells are laid out for a
    robot by name (``[robot] model``), and would take this arm for that one.

    Raises:
        KinematicsError: The name is a shipped robot's (one line naming the file).
    """
    if spec.name in ROBOTS.names() and spec.folder != ROBOTS.get(spec.name).folder:
        raise KinematicsError(f"{where}: name {spec.name!r} is a shipped robot's name (cells laid "
                              "out for that robot would take this arm for it); give your robot "
                              "a name of its own")
    return spec


#: The shipped robots by name, read from ``models/*/robot.toml`` the first time it is looked
#: into (importing this module reads no file).
ROBOTS: Registry[RobotSpec] = LazyRegistry("robot", _shipped_robots)


__all__ = ["COULOMB_SPEED", "PEAK_KNEE_FRACTION", "ROBOTS", "RPM_PER_RAD_S", "Drive", "RobotSpec",
           "coulomb", "get_robot", "joint_ranges", "resolve_robot"]
