"""Where cellsim finds its shipped models and scenarios.

In a source checkout (or an editable install) they are the top-level ``models/`` and
``scenarios/`` folders; in a wheel they are shipped as ``sim/_data/models`` and
``sim/_data/scenarios`` (see ``pyproject.toml``).
"""

from __future__ import annotations

from pathlib import Path

from planners.registry import Registry

#: The ``sim`` package folder (this module lives in ``sim/core``).
_PKG = Path(__file__).resolve().parents[1]


def _data_dir(name: str) -> Path:
    for candidate in (_PKG / "_data" / name, _PKG.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(
        f"cellsim's {name}/ folder is missing (looked in {_PKG / '_data' / name} and "
        f"{_PKG.parent / name}); reinstall cellsim"
    )


def models_dir() -> Path:
    """Folder holding one sub-folder per robot model (MuJoCo Menagerie layout)."""
    return _data_dir("models")


def scenarios_dir() -> Path:
    """Folder holding the shipped scenario files (``*.toml``)."""
    return _data_dir("scenarios")


def shipped_scenarios() -> Registry[Path]:
    """Shipped scenario files by name (file stem), sorted (read from the folder each call)."""
    registry: Registry[Path] = Registry("scenario")
    for path in sorted(scenarios_dir().glob("*.toml")):
        registry.add(path.stem, path)
    return registry
