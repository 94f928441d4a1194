"""The exception tree of ``sim`` (its root is :class:`planners.errors.CellsimError`).

Every exception cellsim defines derives from :class:`CellsimError`, re-exported here from the
bottom layer so that the planners' errors share it. A user mistake (bad scenario, unknown name,
unreachable pose, damaged run folder) is printed by the command line as one line, exit code 2;
an :class:`InternalError` is a fault inside cellsim and is reported with its traceback.
"""

from __future__ import annotations

from planners.errors import (
    CellsimError,
    CellsimWarning,
    InternalError,
    PlannerError,
    UnknownNameError,
    UsageError,
)


class ScenarioError(CellsimError):
    """A scenario file is malformed or inconsistent; the message names the file and field."""


class ReachError(ScenarioError):
    """A scenario's target or path is out of reach, or reachable only outside the joint ranges
    (``cellsim check`` reports it as a finding; elsewhere it is a scenario mistake)."""


class LimitError(ScenarioError):
    """The reference motion takes a joint past its range where a later phase cannot be
    planned from (``cellsim check`` reports each line as a ``limit`` finding).

    Attributes:
        lines: One per violation, naming the phase, joint, time, value and limit.
    """

    def __init__(self, lines: list[str]) -> None:
        more = f" (and {len(lines) - 1} more)" if len(lines) > 1 else ""
        super().__init__(lines[0] + more)
        self.lines = list(lines)


class KinematicsError(CellsimError):
    """Base class of kinematics errors."""


class MechanismError(KinematicsError):
    """A mechanism file (turntable, positioner, track) is malformed; the message names the file
    and the key."""


class HoldError(KinematicsError):
    """A robot's drives cannot hold the arm against gravity somewhere in its joint ranges.

    Attributes:
        needs: The torque each failing joint must hold, N m at the joint, by joint name.
    """

    def __init__(self, message: str, needs: dict[str, float] | None = None) -> None:
        super().__init__(message)
        self.needs = dict(needs or {})


class UnreachableError(KinematicsError):
    """A pose outside the workspace; the message says how far outside it is."""

    def __init__(self, message: str, distance: float = float("nan")) -> None:
        super().__init__(message)
        self.distance = distance


class SingularityWarning(CellsimWarning):
    """An IK solution sits on a singularity; one joint was kept at its current value."""


class CellError(CellsimError):
    """A cell cannot be composed as asked (robot, tool, mount or payload it does not take)."""


class SimulationError(CellsimError):
    """The simulation became unstable (NaN, MuJoCo warning); names the time and joint."""


class RunFolderError(CellsimError):
    """A run folder is missing, incomplete or inconsistent; names the folder and the file/field."""


class CatalogError(CellsimError):
    """A motor or reducer catalogue is missing or malformed; the message names the file, the
    entry and the key."""


class SweepError(CellsimError):
    """Bad sweep input (payloads, speed scales, workers) or failed variants; one line."""


class RenderError(CellsimError):
    """No working OpenGL backend, or an unknown camera; says what to install or choose."""


__all__ = [
    "CellError", "CellsimError", "CellsimWarning", "InternalError", "KinematicsError",
    "MechanismError", "PlannerError", "RenderError", "RunFolderError", "ScenarioError",
    "SimulationError", "SingularityWarning", "SweepError", "UnknownNameError",
    "UnreachableError", "UsageError",
]
