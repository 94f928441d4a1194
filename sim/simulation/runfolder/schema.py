"""The run folder's schema: its file names, the arrays of ``trajectory.npz`` (shape and unit),
the bounds on what is read from a folder, and how messages quote what was read.

Owns the names and shapes every other part of :mod:`sim.simulation.runfolder` reads and writes.
May import: :mod:`sim.errors` only.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sim.errors import RunFolderError

# ------------------------------------------------------------------------------------ schema
MODEL_XML = "model.xml"
SCENARIO_TOML = "scenario.toml"
MANIFEST_JSON = "manifest.json"
SUMMARY_JSON = "summary.json"
TRAJECTORY_NPZ = "trajectory.npz"
TRAJECTORY_CSV = "trajectory.csv"
VIDEO_MP4 = "video.mp4"
PLOTS_DIR = "plots"
ERROR_TXT = "error.txt"
SIZING_MD = "sizing.md"
SIZING_CSV = "sizing.csv"
SIZING_JSON = "sizing.json"
REPORT_HTML = "report.html"
SELECTION_JSON = "selection.json"
SELECTION_CSV = "selection.csv"
SIZING_CHARTS_DIR = "sizing"
#: Suffix of the folder a failed run leaves next to the one it would have written.
FAILED_SUFFIX = ".failed"
#: The marker file cellsim writes first into every run folder: a folder is cellsim's (and may
#: be replaced by a later run) only when it holds this file.
MARKER = ".cellsim-run"

#: Every file (or folder) a complete run folder may hold, in the order a person reads them.
FILES: tuple[str, ...] = (SUMMARY_JSON, REPORT_HTML, SIZING_MD, SIZING_CSV, SIZING_JSON,
                          SELECTION_JSON, SELECTION_CSV, SIZING_CHARTS_DIR, VIDEO_MP4, PLOTS_DIR, TRAJECTORY_NPZ,
                          TRAJECTORY_CSV, MODEL_XML, SCENARIO_TOML, MANIFEST_JSON)


@dataclass(frozen=True)
class ArraySpec:
    """One recorded array: its shape (N samples, n joints, P parts, K knots) and unit."""

    shape: str
    unit: str
    description: str


#: The arrays of ``trajectory.npz`` (SI units; positions in the world frame).
ARRAYS: dict[str, ArraySpec] = {
    "t": ArraySpec("(N,)", "s", "sample time"),
    "phase": ArraySpec("(N,)", "-", "index of the phase (summary.json 'phases')"),
    "q_ref": ArraySpec("(N, n)", "rad", "reference joint position"),
    "qd_ref": ArraySpec("(N, n)", "rad/s", "reference joint speed"),
    "qdd_ref": ArraySpec("(N, n)", "rad/s^2", "reference joint acceleration"),
    "qddd_ref": ArraySpec("(N, n)", "rad/s^3", "reference joint jerk"),
    "q": ArraySpec("(N, n)", "rad", "simulated joint position"),
    "qd": ArraySpec("(N, n)", "rad/s", "simulated joint speed"),
    "qdd": ArraySpec("(N, n)", "rad/s^2", "simulated joint acceleration (velocity increments)"),
    "tau": ArraySpec("(N, n)", "N m", "joint torque the drive delivers (servo + feed-forward)"),
    "tau_actuator": ArraySpec("(N, n)", "N m", "position servo's part of tau"),
    "tau_ff": ArraySpec("(N, n)", "N m", "feed-forward part of tau"),
    "tau_id": ArraySpec("(N, n)", "N m", "inverse dynamics of the reference"),
    "tau_limit": ArraySpec("(N, n)", "N m", "the drive's torque limit at the joint at each step"),
    "tcp_pos": ArraySpec("(N, 3)", "m", "simulated tool point, world"),
    "tcp_pos_ref": ArraySpec("(N, 3)", "m", "reference tool point, world"),
    "tcp_quat": ArraySpec("(N, 4)", "-", "simulated tcp orientation (w, x, y, z), world"),
    "qpos": ArraySpec("(N, nq)", "m, rad, -", "full MuJoCo qpos (robot, parts)"),
    "arc_on": ArraySpec("(N,)", "bool", "welding arc on"),
    "suction": ArraySpec("(N,)", "bool", "suction on"),
    "knot_t": ArraySpec("(K,)", "s", "knot times of the joint polynomials"),
    "part_pos": ArraySpec("(N, P, 3)", "m", "part positions, world"),
    "part_quat": ArraySpec("(N, P, 4)", "-", "part orientations (w, x, y, z), world"),
}

#: Arrays every run must have to be rendered.
REQUIRED_FOR_VIDEO: tuple[str, ...] = ("t", "qpos")
#: Arrays the plots need.
REQUIRED_FOR_PLOTS: tuple[str, ...] = (
    "t",
    "q_ref",
    "qd_ref",
    "qdd_ref",
    "qddd_ref",
    "q",
    "qd",
    "tau",
    "tau_id",
    "tcp_pos",
    "tcp_pos_ref",
)
#: Per-sample arrays with one column per joint.
JOINT_ARRAYS: tuple[str, ...] = (
    "q_ref", "qd_ref", "qdd_ref", "qddd_ref", "q", "qd", "tau", "tau_id",
)  # fmt: skip

# ------------------------------------------------------------------------- reading bounds
#: Largest ``model.xml`` read from a run folder, bytes (a compiled cell carries its meshes
#: inline: the shipped cells' are well under a megabyte).
MAX_MODEL_BYTES = 256 * 1024 * 1024
#: Largest ``summary.json`` read from a run folder, bytes.
MAX_SUMMARY_BYTES = 64 * 1024 * 1024
#: Most bytes ``trajectory.npz`` may take, on disk and unpacked (all arrays together): twice
#: what the longest run records (``MAX_STEPS`` of :mod:`sim.simulation.motion`, about 1 KB a
#: step). Every array's size is checked against it before a byte of it is unpacked.
MAX_TRAJECTORY_BYTES = 4 * 1024**3
#: Most arrays ``trajectory.npz`` may hold.
MAX_TRAJECTORY_ARRAYS = 256
#: Largest file a run folder's ``model.xml`` may name (a mesh, texture, height field, skin).
MAX_ASSET_BYTES = 1024**3


# ------------------------------------------------------------------------------ messages
def short_repr(value: Any, limit: int = 80) -> str:
    """``repr`` of a value for a one-line message, shortened to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def file_error(path: Path, prefix: str) -> Callable[[str], RunFolderError]:
    """The error :func:`~sim.core.files.read_input` raises for ``path``: its message (which
    begins with the path) after ``prefix`` instead of the path."""
    return lambda message: RunFolderError(f"{prefix}: {message.removeprefix(f'{path}: ')}")
