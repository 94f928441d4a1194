"""The kind of what a script passes to cellsim's Python face, checked where it comes in.

The command line parses its arguments; a script passes Python values, and one of the wrong
kind (a number for a path, the text ``"no"`` for a flag, ``True`` for a mass) met a
``TypeError`` deep inside, or worse was taken (``feedforward="no"`` is true): found by a
new-user trial. Each check here gives the value back, of its kind, or raises one line that
names the argument and what it got, as a :class:`~sim.errors.CellsimError` (the caller's
class: :class:`~sim.errors.UsageError` by default).
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sim.errors import CellsimError, UsageError


def got(value: Any) -> str:
    """What was given, for a message: its type and a short repr."""
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{type(value).__name__} {text}"


def path_argument(value: Any, name: str, *, error: type[CellsimError] = UsageError) -> Path:
    """A file or folder's path: a ``str`` (not empty) or an ``os.PathLike`` of one."""
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str):
        raise error(f"{name}: expected a path (str or pathlib.Path), got {got(value)}",
                    key=name)
    if not value.strip():
        raise error(f"{name}: an empty path", key=name)
    return Path(value)


def optional_path_argument(value: Any, name: str, *, error: type[CellsimError] = UsageError
                           ) -> Path | None:
    """:func:`path_argument`, or None."""
    return None if value is None else path_argument(value, name, error=error)


def number_argument(value: Any, name: str, *, error: type[CellsimError] = UsageError) -> float:
    """A real number (an ``int``, a ``float``, a NumPy scalar; not a bool: ``True`` is not
    1 kg), as a float; finite or not (the caller's range check says what it takes)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise error(f"{name}: expected a number, got {got(value)}", key=name)
    return float(value)


def count_argument(value: Any, name: str, *, least: int = 1,
                   error: type[CellsimError] = UsageError) -> int:
    """A whole number of at least ``least`` (not a bool, not a float)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise error(f"{name}: expected a whole number, got {got(value)}", key=name)
    if value < least:
        raise error(f"{name}: must be at least {least}, got {value}", key=name)
    return int(value)


def flag_argument(value: Any, name: str, *, optional: bool = False,
                  error: type[CellsimError] = UsageError) -> bool | None:
    """``True`` or ``False`` (a NumPy bool too); None where ``optional``. The text ``"no"``
    is refused: it would be taken as true."""
    if value is None and optional:
        return None
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    allowed = "True, False or None" if optional else "True or False"
    raise error(f"{name}: expected {allowed}, got {got(value)}", key=name)


def choice_argument(value: Any, name: str, choices: Sequence[str], *,
                    error: type[CellsimError] = UsageError) -> str:
    """One of ``choices`` (text)."""
    if not isinstance(value, str) or value not in choices:
        raise error(f"{name}: expected one of {', '.join(repr(c) for c in choices)}, got "
                    f"{got(value)}", key=name)
    return value


__all__ = ["choice_argument", "count_argument", "flag_argument", "got", "number_argument",
           "optional_path_argument", "path_argument"]
