"""cellsim: physics simulation of industrial robot welding and pick cells on MuJoCo."""

import os as _os
from typing import TYPE_CHECKING as _TYPE_CHECKING

__version__ = "0.1.0"


def _default_gl() -> str:
    """A headless OpenGL backend for MuJoCo, chosen before anything imports ``mujoco``.

    MuJoCo reads ``MUJOCO_GL`` once, at import; left unset on Linux it binds GLFW, which needs a
    display. This picks EGL or OSMesa by which library is installed (cheap); rendering
    commands then probe and, if needed, switch with :func:`sim.render.gl.configure_gl`.
    """
    import ctypes.util

    for backend, library in (("egl", "EGL"), ("osmesa", "OSMesa")):
        if ctypes.util.find_library(library):
            return backend
    return "disable"  # simulation still works; rendering says what to install


#: Values of ``MUJOCO_GL`` that mujoco accepts on Linux (it refuses to import with any other).
_MUJOCO_GL_VALUES = ("", "disable", "disabled", "off", "false", "0", "enable", "enabled", "on",
                     "true", "1", "glfw", "glx", "egl", "osmesa")

if "MUJOCO_GL" not in _os.environ:
    _os.environ["MUJOCO_GL"] = _default_gl()
elif _os.environ["MUJOCO_GL"].lower().strip() not in _MUJOCO_GL_VALUES:
    # A value mujoco refuses would break every command, rendering or not: keep it aside for
    # the rendering commands to report (sim.render.gl.configure_gl) and use the default.
    _os.environ["CELLSIM_INVALID_MUJOCO_GL"] = _os.environ["MUJOCO_GL"]
    _os.environ["MUJOCO_GL"] = _default_gl()

# --------------------------------------------------------------------------------- the API
# ``import sim`` stays cheap (no mujoco, no registries): the API's names are imported on first
# use (PEP 562), and the OpenGL default above is set before any of them can import mujoco.
if _TYPE_CHECKING:
    from sim.api import (
        Check,
        Collision,
        MechanismAxis,
        MechanismResult,
        RobotResult,
        RunOptions,
        RunResult,
        Saturation,
        Scenario,
        SelectedDrive,
        SizedJoint,
        SizingCheck,
        SweepResult,
        WeldResult,
        evaluate,
        load_scenario,
        run,
        sweep,
    )
    from sim.errors import (
        CatalogError,
        CellsimError,
        CellsimWarning,
        InternalError,
        LimitError,
        ReachError,
        RenderError,
        RunFolderError,
        ScenarioError,
        SimulationError,
        SweepError,
        UnknownNameError,
    )

__all__ = [
    # the API (sim.api)
    "Check", "Collision", "MechanismAxis", "MechanismResult", "RobotResult", "RunOptions",
    "RunResult", "Saturation", "Scenario", "SelectedDrive", "SizedJoint", "SizingCheck",
    "SweepResult", "WeldResult", "evaluate", "load_scenario", "run", "sweep",
    # the exception tree (sim.errors; CellsimError is its root)
    "CatalogError", "CellsimError", "CellsimWarning", "InternalError", "LimitError",
    "ReachError", "RenderError", "RunFolderError", "ScenarioError", "SimulationError",
    "SweepError", "UnknownNameError",
    "__version__",
]

_API_NAMES = frozenset(__all__[:18])
_ERROR_NAMES = frozenset(__all__[18:-1])


def __getattr__(name: str) -> object:
    if name in _API_NAMES or name in _ERROR_NAMES:
        import importlib

        module = importlib.import_module("sim.api" if name in _API_NAMES else "sim.errors")
        value = getattr(module, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'sim' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
