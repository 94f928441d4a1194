"""Choice of the OpenGL backend for headless rendering (EGL or OSMesa).

MuJoCo's Python bindings read the ``MUJOCO_GL`` environment variable exactly once, when
``import mujoco`` runs: ``mujoco/__init__.py`` imports
``mujoco.rendering.classic.gl_context``, whose module body reads ``MUJOCO_GL`` and binds
``gl_context.GLContext`` to ``mujoco.egl.GLContext``, ``mujoco.osmesa.GLContext`` or (when
unset on Linux) ``mujoco.glfw.GLContext``. ``mujoco.Renderer`` looks ``gl_context.GLContext``
up each time one is created. ``mujoco.egl`` and ``mujoco.osmesa`` also set
``PYOPENGL_PLATFORM``, which PyOpenGL reads once, when ``OpenGL`` is first imported.
(dm_control's own renderer reads ``MUJOCO_GL`` when ``dm_control._render`` is imported; cellsim
renders through ``mujoco.Renderer`` only.)

:func:`configure_gl` must therefore be called before ``mujoco`` is imported by anything that
renders. It probes each candidate backend in a short-lived subprocess (which creates a
context and renders one frame, so a broken driver cannot crash this process), caches the
result for the life of the process, sets ``MUJOCO_GL`` / ``PYOPENGL_PLATFORM``, and returns the
backend's name. When ``mujoco`` was already imported with another backend, it rebinds
``gl_context.GLContext`` to the chosen backend when that is safe (PyOpenGL not yet bound to
another platform) and otherwise raises :class:`~sim.errors.RenderError` saying so.
"""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import dataclass

from sim.errors import RenderError

#: Headless backends cellsim knows, in the order automatic selection tries them.
BACKENDS: tuple[str, ...] = ("egl", "osmesa")

#: What to install for each backend (Debian/Ubuntu package names).
INSTALL_HINTS: dict[str, str] = {
    "egl": "`apt-get install libegl1 libgl1-mesa-dri` (EGL: Mesa, or the NVIDIA driver's)",
    "osmesa": "`apt-get install libosmesa6` (OSMesa, software)",
}

#: Seconds a probe subprocess may take (software EGL on a loaded machine takes a few).
PROBE_TIMEOUT_S = 120.0

_PROBE_CODE = r"""
import ctypes.util
import os
import sys
library = {"egl": "EGL", "osmesa": "OSMesa"}[os.environ["MUJOCO_GL"]]
if ctypes.util.find_library(library) is None:
    sys.exit("lib%s not found" % library)
import mujoco
model = mujoco.MjModel.from_xml_string(
    '<mujoco><worldbody><light pos="0 0 2"/>'
    '<geom type="sphere" size="0.1" rgba="1 0 0 1"/></worldbody></mujoco>')
data = mujoco.MjData(model)
mujoco.mj_forward(model, data)
ctx = mujoco.rendering.classic.gl_context.GLContext
sys.stdout.write("context=%s.%s\n" % (ctx.__module__, ctx.__name__))
with mujoco.Renderer(model, 16, 16) as renderer:
    renderer.update_scene(data)
    image = renderer.render()
if image.shape != (16, 16, 3) or int(image.max()) == 0:
    sys.exit("rendered an all-black frame")
sys.stdout.write("ok\n")
"""


@dataclass(frozen=True)
class ProbeResult:
    """Outcome of probing one backend.

    Attributes:
        backend: ``"egl"`` or ``"osmesa"``.
        ok: True when a context was created and a non-black frame rendered.
        detail: On failure, the last line the probe printed (the reason); else "".
    """

    backend: str
    ok: bool
    detail: str = ""


_probe_cache: dict[str, ProbeResult] = {}
_configured: str | None = None


def _check_name(name: str) -> str:
    key = name.lower().strip()
    if key not in BACKENDS:
        raise RenderError(
            f"unknown OpenGL backend {name!r}; choose one of: {', '.join(BACKENDS)}"
        )
    return key


def probe_backend(name: str) -> ProbeResult:
    """Tries one backend in a subprocess: create a context and render one 16x16 frame.

    The result is cached for the life of the process.

    Args:
        name: ``"egl"`` or ``"osmesa"``.

    Returns:
        The :class:`ProbeResult`.

    Raises:
        RenderError: ``name`` is not a known backend.
    """
    key = _check_name(name)
    if key in _probe_cache:
        return _probe_cache[key]
    env = dict(os.environ)
    env["MUJOCO_GL"] = key
    env["PYOPENGL_PLATFORM"] = key
    try:
        proc = subprocess.run(
            [sys.executable, "-I", "-c", _PROBE_CODE],  # isolated: no planted modules
            env=env,
            capture_output=True,
            text=True,
            timeout=PROBE_TIMEOUT_S,
            check=False,
        )
    except subprocess.TimeoutExpired:
        result = ProbeResult(key, False, f"probe timed out after {PROBE_TIMEOUT_S:.0f} s")
    else:
        if proc.returncode == 0 and proc.stdout.rstrip().endswith("ok"):
            result = ProbeResult(key, True)
        else:
            lines = [ln.strip() for ln in (proc.stderr + proc.stdout).splitlines() if ln.strip()]
            detail = lines[-1] if lines else f"exit status {proc.returncode}"
            result = ProbeResult(key, False, detail[:300])
    _probe_cache[key] = result
    return result


def available_backends() -> list[str]:
    """Backends that work on this machine (each probed once per process), in preference order."""
    return [name for name in BACKENDS if probe_backend(name).ok]


def active_backend() -> str | None:
    """The backend :func:`configure_gl` chose in this process, or None before it ran."""
    return _configured


def _pyopengl_platform() -> str | None:
    """Platform PyOpenGL is bound to (``"egl"``, ``"osmesa"``, ``"glx"``...); None before import."""
    if "OpenGL.platform" not in sys.modules:
        return None
    platform = getattr(sys.modules["OpenGL.platform"], "PLATFORM", None)
    if platform is None:
        return None
    cls = type(platform).__name__.lower()  # e.g. EGLPlatform, OSMesaPlatform, GLXPlatform
    return cls.removesuffix("platform") or None


def _activate(backend: str) -> None:
    """Sets the environment and, if mujoco is already imported, rebinds its GLContext."""
    gl_module = sys.modules.get("mujoco.rendering.classic.gl_context")
    current = (str(getattr(gl_module, "_MUJOCO_GL", "")) or "glfw") if gl_module else None
    bound = _pyopengl_platform()
    if bound is not None and bound != backend:
        before = f"mujoco was already imported with MUJOCO_GL={current!r} and " if current else ""
        raise RenderError(
            f"{before}PyOpenGL is already bound to the {bound!r} platform, so the {backend!r} "
            f"backend cannot be used in this process; set MUJOCO_GL={backend} in the environment "
            "or call sim.render.gl.configure_gl() before anything imports mujoco or OpenGL"
        )
    os.environ["MUJOCO_GL"] = backend
    os.environ["PYOPENGL_PLATFORM"] = backend
    if gl_module is None:
        if "mujoco" in sys.modules:
            raise RenderError(
                "mujoco was imported but its classic renderer (mujoco.rendering.classic) is "
                "missing; reinstall mujoco"
            )
        return  # mujoco not imported yet: it will read MUJOCO_GL itself
    context_cls = getattr(gl_module, "GLContext", None)
    if current == backend and context_cls is not None and backend in context_cls.__module__:
        return
    try:
        if backend == "egl":
            from mujoco.egl import GLContext as backend_cls
        else:
            from mujoco.osmesa import GLContext as backend_cls
    except (ImportError, OSError, AttributeError) as exc:
        raise RenderError(
            f"mujoco was already imported with MUJOCO_GL={current!r} and switching it to "
            f"{backend!r} failed ({exc}); set MUJOCO_GL={backend} before starting cellsim"
        ) from exc
    gl_module.GLContext = backend_cls
    gl_module._MUJOCO_GL = backend
    mujoco_module = sys.modules.get("mujoco")
    if mujoco_module is not None and hasattr(mujoco_module, "GLContext"):
        mujoco_module.GLContext = backend_cls


def adopt_backend(name: str) -> str:
    """Activates ``name`` without probing it: for a process started by one whose
    :func:`configure_gl` chose it on this machine (the video's worker processes), which would
    otherwise probe again (a subprocess, about a second each).

    Raises:
        RenderError: Unknown name, or mujoco imported earlier with a backend that cannot be
            switched.
    """
    key = _check_name(name)
    _probe_cache.setdefault(key, ProbeResult(key, True))
    return configure_gl(key)


def configure_gl(preferred: str | None = None) -> str:
    """Chooses and activates a headless OpenGL backend; call before importing mujoco.

    Without ``preferred``, a ``MUJOCO_GL`` of ``egl``/``osmesa`` already in the environment is
    honoured as the choice; otherwise EGL (GPU or Mesa) is tried, then OSMesa. The first call
    probes (a subprocess, about a second); later calls return the cached choice.

    Args:
        preferred: ``"egl"``, ``"osmesa"`` (e.g. from ``--gl``), or None for automatic.

    Returns:
        The active backend name.

    Raises:
        RenderError: Unknown name; ``MUJOCO_GL`` set to a value that is no backend (and no
            ``preferred``); the requested backend (or every backend) does not work here, with
            what to install; or mujoco was imported earlier with a backend that
            cannot be switched.
    """
    global _configured
    if preferred is not None:
        preferred = _check_name(preferred)
    invalid = os.environ.get("CELLSIM_INVALID_MUJOCO_GL")
    if preferred is None and invalid is not None:
        raise RenderError(f"MUJOCO_GL={invalid!r} is not an OpenGL backend; set MUJOCO_GL to "
                          f"one of {', '.join(BACKENDS)}, unset it, or give --gl")
    if _configured is not None and preferred in (None, _configured):
        return _configured
    if preferred is not None:
        candidates: tuple[str, ...] = (preferred,)
    else:
        env = os.environ.get("MUJOCO_GL", "").lower().strip()
        candidates = (env,) if env in BACKENDS else BACKENDS
    failures = []
    for name in candidates:
        result = probe_backend(name)
        if result.ok:
            _activate(name)
            _configured = name
            return name
        failures.append(f"{name}: {result.detail}")
    if preferred is not None:
        how = f"the {preferred!r} OpenGL backend does not work here"
    elif len(candidates) == 1:
        how = f"MUJOCO_GL={candidates[0]} is set but that backend does not work here"
    else:
        how = "no headless OpenGL backend works here"
    hints = " or ".join(INSTALL_HINTS[name] for name in candidates)
    raise RenderError(f"{how} ({'; '.join(failures)}); install {hints}")
