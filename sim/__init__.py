"""cellsim: physics simulation of industrial robot welding and pick cells on MuJoCo."""

import os as _os

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


if "MUJOCO_GL" not in _os.environ:
    _os.environ["MUJOCO_GL"] = _default_gl()
