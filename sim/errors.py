"""Exception hierarchy of cellsim.

A :class:`CellsimError` is a user mistake (bad scenario, unknown robot, unreachable pose):
the command line prints its one-line message and exits with code 2, never a traceback.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class CellsimError(Exception):
    """Base class of every user-facing error of cellsim."""


class ScenarioError(CellsimError):
    """A scenario file is malformed or inconsistent; the message names the file and field."""


class UnknownNameError(CellsimError):
    """An unknown robot, cell, tool, camera or scenario name; the message lists valid ones."""

    def __init__(self, kind: str, name: str, valid: Iterable[str]) -> None:
        valid = sorted(valid)
        close = difflib.get_close_matches(name, valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        super().__init__(f"unknown {kind} {name!r}{hint}; known: {', '.join(valid)}")
        self.kind = kind
        self.name = name
        self.valid = valid


class KinematicsError(CellsimError):
    """Base class of kinematics errors."""


class UnreachableError(KinematicsError):
    """A pose outside the workspace; the message says how far outside it is."""

    def __init__(self, message: str, distance: float = float("nan")) -> None:
        super().__init__(message)
        self.distance = distance


class SimulationError(CellsimError):
    """The simulation became unstable (NaN, MuJoCo warning); names the time and joint."""


class RenderError(CellsimError):
    """No working OpenGL backend, or an unknown camera; says what to install or choose."""
