"""The shipped mechanisms by name, :data:`MECHANISMS`, and :func:`mechanism_from_ref`, which
also takes a mechanism file of one's own.

A shipped mechanism is a folder (Menagerie style): ``models/positioners/<name>/``,
``models/turntables/<name>/`` or ``models/tracks/<name>/``, holding the ``mechanism.toml`` a
person edits (:mod:`sim.robots.mechanisms.mechfile`) and a README deriving every number.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from planners.registry import Registry
from sim.core.registry import LazyRegistry
from sim.core.resources import models_dir
from sim.errors import MechanismError
from sim.robots.mechanisms.mechfile import MECHANISM_FILE, read_mechanism
from sim.robots.mechanisms.spec import MechanismSpec

#: The folders of ``models/`` holding one folder per shipped mechanism.
MECHANISM_FOLDERS = ("positioners", "turntables", "tracks")


def shipped_mechanism_files() -> tuple[Path, ...]:
    """Every ``models/<positioners|turntables|tracks>/*/mechanism.toml``, sorted per folder."""
    return tuple(path for folder in MECHANISM_FOLDERS
                 for path in sorted((models_dir() / folder).glob(f"*/{MECHANISM_FILE}")))


def _shipped_mechanisms() -> Iterator[tuple[str, MechanismSpec]]:
    for path in shipped_mechanism_files():
        spec = read_mechanism(path)
        yield spec.name, spec


def mechanism_from_ref(ref: str | Path, base: Path | None = None) -> MechanismSpec:
    """A shipped mechanism by name, or a mechanism file of one's own: a path (relative to
    ``base``, the folder of the file naming it) to a ``*.toml`` file or to a folder holding a
    ``mechanism.toml``.

    Raises:
        UnknownNameError: Unknown name (the message lists the shipped mechanisms).
        MechanismError: No such file, or a file that is not a valid mechanism (one line naming
            the file and the key).
    """
    text = str(ref)
    if isinstance(ref, Path) or "/" in text or "\\" in text or text.endswith(".toml"):
        path = Path(ref) if base is None else base / ref
        if path.is_dir():
            path = path / MECHANISM_FILE
        if not path.is_file():
            raise MechanismError(f"{path}: no mechanism file (a *.toml file, or a folder with "
                                 f"a {MECHANISM_FILE})")
        return read_mechanism(path)
    return MECHANISMS.get(text)


#: The shipped mechanisms by name, read the first time the registry is looked into.
MECHANISMS: Registry[MechanismSpec] = LazyRegistry("mechanism", _shipped_mechanisms)

__all__ = ["MECHANISMS", "MECHANISM_FOLDERS", "mechanism_from_ref", "shipped_mechanism_files"]
