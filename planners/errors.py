"""Exception tree of cellsim, rooted here in the bottom layer.

:class:`CellsimError` is the root of every exception cellsim raises, the planners' and
``sim``'s alike; it lives in ``planners`` (the dependency-free bottom layer) so that the
planners need nothing from ``sim`` while ``sim.errors`` re-exports it and adds its own branches.

Two kinds hang from the root:

* user mistakes (everything but :class:`InternalError`): one-line messages that name the
  offending file, key, joint or value and, where there is a choice, list the valid ones; the
  command line prints them and exits with code 2;
* :class:`InternalError`: a fault inside cellsim (an inconsistency no input should cause); the
  command line prints the traceback and asks for a report.

This module holds every planner exception; :class:`UnknownNameError` (raised by every
:class:`planners.registry.Registry`) builds the "did you mean" hint in one place.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable

#: A file as messages name it: a path ending in one of cellsim's input or output suffixes.
_FILE = re.compile(r"^\S.*\.(toml|ls|tp|urdf|xml|stl|obj|json|csv|npz|md|html|mp4)$", re.I)
#: A key as messages name it: ``phases[2].speed_mm_s``, ``drives[5] (j6)``, ``--rank``.
_KEY = re.compile(r"^(--[a-z][\w-]*|[A-Za-z_][\w-]*(\[-?\d+\])*( \([^()]*\))?"
                  r"(\.[A-Za-z_][\w-]*(\[-?\d+\])*( \([^()]*\))?)*)$")
_LINE = re.compile(r"^line (\d+)$")


def _where(message: str) -> tuple[str | None, str | None, int | None]:
    """``(file, key, line)`` from a one-line message's leading ``file: key: detail`` parts:
    the last part that names a file (an error inside a file another file names is the inner
    file's), the key right after it, a ``line N`` part; None where the message gives none."""
    parts = message.split(": ")[:-1]  # the last part is the detail itself
    file = key = None
    line = None
    for i, part in enumerate(parts):
        if _FILE.match(part):
            file, key, line = part, None, None
            continue
        found = _LINE.match(part)
        if found:
            line = int(found.group(1))
        elif key is None and (file is not None or i == 0) and _KEY.match(part):
            key = part
    return file, key, line


class CellsimError(Exception):
    """Root of every cellsim exception (user mistakes and internal faults).

    Attributes:
        file: The file the mistake is in, where the message names one (an error inside a file
            that another names: the inner one), else None.
        key: The key, entry or option the message names right after the file (or first, when
            it names no file): ``phases[2].speed_mm_s``, ``drives[5] (j6)``; else None.
        line: The line number the message gives (``line 10: ...``: a TP program's), else None.

    Each is read from the one-line message where the raising code does not give it.
    """

    def __init__(self, *args: object, file: str | None = None, key: str | None = None,
                 line: int | None = None) -> None:
        super().__init__(*args)
        parsed = _where(args[0]) if args and isinstance(args[0], str) else (None, None, None)
        self.file = file if file is not None else parsed[0]
        self.key = key if key is not None else parsed[1]
        self.line = line if line is not None else parsed[2]


class InternalError(CellsimError, RuntimeError):
    """A fault inside cellsim, not a user mistake: please report it with its traceback."""


class UsageError(CellsimError, ValueError):
    """A function called with arguments that cannot work together (a caller's mistake in code
    that uses cellsim as a library: wrong shape, a missing argument, a value out of domain)."""


class CellsimWarning(CellsimError, UserWarning):
    """Root of cellsim's warnings (issued with :func:`warnings.warn`, never raised)."""


class UnknownNameError(CellsimError):
    """An unknown name of something selectable (robot, cell, tool, planner, scenario, ...).

    The message lists the valid names, sorted, with a "did you mean" hint for a close match.

    Attributes:
        kind: What was looked up (``"robot"``, ``"planner"``, ...).
        name: The name asked for.
        valid: The valid names, sorted.
    """

    #: Text put before the message (subclasses name their field, e.g. ``"planner: "``).
    prefix = ""

    def __init__(self, kind: str, name: str, valid: Iterable[str]) -> None:
        valid = sorted(valid)
        close = difflib.get_close_matches(str(name), valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        super().__init__(f"{self.prefix}unknown {kind} {name!r}{hint}; known: {', '.join(valid)}")
        self.kind = kind
        self.name = name
        self.valid = valid


# ---------------------------------------------------------------------------- planners
class PlannerError(CellsimError, ValueError):
    """Base class of every planning error (a user mistake, not a bug)."""


class InvalidKnotsError(PlannerError):
    """Knot times or knot values are unusable (too few, non-increasing, NaN, wrong shape)."""


class InvalidBoundaryError(PlannerError):
    """Boundary velocities, accelerations or jerks have the wrong shape or are not finite."""


class UnknownPlannerError(UnknownNameError, PlannerError):
    """A planner name that is not registered; the message lists the valid names."""

    prefix = "planner: "


class LimitViolationError(PlannerError):
    """A trajectory exceeds a joint's position, velocity or acceleration limit.

    Attributes:
        joint: Index of the joint (0-based).
        quantity: "position", "velocity" or "acceleration".
        time: Time of the worst violation, s.
        value: Value at that time (SI units).
        limit: The limit that was exceeded (SI units).
    """

    def __init__(self, message: str, *, joint: int, quantity: str, time: float,
                 value: float, limit: float) -> None:
        super().__init__(message)
        self.joint = joint
        self.quantity = quantity
        self.time = time
        self.value = value
        self.limit = limit


class InvalidOrientationError(PlannerError):
    """A tool orientation that is not a proper rotation matrix, or an unusable orientation law."""


class InvalidProfileError(PlannerError):
    """A speed, ramp time, acceleration limit or ramp shape that cannot be used."""


class MoveTooShortError(InvalidProfileError):
    """The move is shorter than the distance its start and stop ramps need."""


class InvalidMoveError(PlannerError):
    """A Cartesian move with an unusable input (speed, period, point, step count)."""


class CoincidentPointsError(InvalidMoveError):
    """Two points of a move that must differ coincide (zero-length move)."""


class CollinearPointsError(InvalidMoveError):
    """The three points of an arc lie on one line, so they define no circle."""
