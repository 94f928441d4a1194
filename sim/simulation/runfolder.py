"""The run folder: its schema (file names, array names, units), writing and reading it.

This module is the one place that knows what a run folder holds. The runner writes through it
(:func:`write_trajectory`, :func:`write_summary`, :func:`write_csv`, :func:`write_text`),
and sizing, plots, video and ``cellsim render`` read through it: in the runner from the
in-memory :class:`RunRecord`, afterwards with :func:`load_run`.

A run folder DIR holds (``FILES`` lists them):

* ``model.xml``: the compiled cell (``mujoco.MjModel.from_xml_path``);
* ``scenario.toml``: the scenario as given; ``manifest.json``: versions and hashes;
* ``summary.json``: ``scenario``, ``robot``, ``joints`` (names), ``phases``
  (``[{"name", "kind", "t0", "t1"}]``), ``duration_s``, metrics, ``saturation``, ``sizing``, ``checks``, ``verdict``, ...;
* ``trajectory.npz``: the recorded arrays (``ARRAYS`` gives each one's shape and unit);
  ``trajectory.csv``: the main ones as columns;
* ``video.mp4``, ``plots/*.png``, the sizing report (``sizing.md``, ``sizing.csv``,
  ``sizing.json``, ``report.html``, ``sizing/*.png``);
* with an actuator selection, ``selection.json`` and ``selection.csv``
  (:mod:`sim.analysis.selection`).

A run that fails mid-simulation keeps what it recorded in ``DIR.failed/`` with ``error.txt``.
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sim.core.files import naming
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


@dataclass
class Phase:
    """One phase of the work cycle.

    Attributes:
        name: Phase name (e.g. ``"weld"``).
        kind: Planner kind (e.g. ``"joint"``, ``"cartesian"``); "" when unknown.
        t0: Start time, s.
        t1: End time, s.
    """

    name: str
    kind: str
    t0: float
    t1: float


@dataclass
class RunRecord:
    """A recorded run: the model's path and the sampled arrays.

    Attributes:
        arrays: Per-sample arrays by name (see the module docstring); ``t`` is strictly
            increasing.
        joints: Joint names, one per column of the joint arrays.
        phases: Phases in time order.
        model_path: ``model.xml`` of the cell, or None when ``model_xml`` is given.
        model_xml: MJCF text of the cell (alternative to ``model_path``).
        summary: The whole ``summary.json`` (may be empty).
        source: Folder the run was read from (for messages), or None.
    """

    arrays: dict[str, np.ndarray]
    joints: list[str]
    phases: list[Phase] = field(default_factory=list)
    model_path: Path | None = None
    model_xml: str | None = None
    summary: dict[str, Any] = field(default_factory=dict)
    source: Path | None = None

    @property
    def where(self) -> str:
        """How messages name this run."""
        return f"run folder {str(self.source)!r}" if self.source else "run"

    @property
    def t(self) -> np.ndarray:
        """Sample times (N,), s."""
        return self.arrays["t"]

    @property
    def t0(self) -> float:
        """Time of the first sample, s."""
        return float(self.t[0])

    @property
    def duration(self) -> float:
        """Time from the first to the last sample, s."""
        return float(self.t[-1] - self.t[0])

    def has(self, name: str) -> bool:
        """Whether the run has array ``name``."""
        return name in self.arrays

    def get(self, name: str) -> np.ndarray:
        """Array ``name``.

        Raises:
            RunFolderError: The run lacks it.
        """
        if name not in self.arrays:
            raise RunFolderError(
                f"{self.where}: trajectory.npz has no array {name!r}; it has: "
                f"{', '.join(sorted(self.arrays))}"
            )
        return self.arrays[name]

    def require(self, names: tuple[str, ...]) -> None:
        """Checks that every array in ``names`` is present.

        Raises:
            RunFolderError: Naming the missing arrays.
        """
        missing = [n for n in names if n not in self.arrays]
        if missing:
            raise RunFolderError(
                f"{self.where}: trajectory.npz lacks {', '.join(missing)} (needed here); it has: "
                f"{', '.join(sorted(self.arrays))}"
            )

    def phase_name(self, index: int) -> str:
        """Name of phase ``index`` ("" when unknown)."""
        if 0 <= index < len(self.phases):
            return self.phases[index].name
        return ""

    def load_model(self) -> Any:
        """Compiles the cell's model.

        Returns:
            A ``mujoco.MjModel``.

        Raises:
            RunFolderError: The model is missing or does not compile.
        """
        import mujoco

        try:
            if self.model_xml is not None:
                return mujoco.MjModel.from_xml_string(self.model_xml)
            if self.model_path is None:
                raise RunFolderError(f"{self.where}: no model (model.xml) to render")
            confine_model_files(self.model_path, self.where)
            return mujoco.MjModel.from_xml_path(str(self.model_path))
        except ValueError as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else repr(exc)
            raise RunFolderError(f"{self.where}: model.xml does not load: {first}") from exc

    @classmethod
    def from_arrays(
        cls,
        arrays: Mapping[str, np.ndarray],
        *,
        joints: list[str],
        phases: list[Phase] | list[dict[str, Any]] | None = None,
        model_path: str | Path | None = None,
        model_xml: str | None = None,
        summary: dict[str, Any] | None = None,
    ) -> RunRecord:
        """Builds a record from arrays in memory (same names and shapes as trajectory.npz).

        Args:
            arrays: Per-sample arrays by name; at least ``t`` (N,).
            joints: Joint names (columns of the joint arrays).
            phases: Phases as :class:`Phase` or summary-style dicts.
            model_path: Path of the cell's MJCF, or None with ``model_xml``.
            model_xml: MJCF text, alternative to ``model_path``.
            summary: Optional summary dict.

        Returns:
            The validated record.

        Raises:
            RunFolderError: Inconsistent shapes or times.
        """
        record = cls(
            arrays={k: np.asarray(v) for k, v in arrays.items()},
            joints=list(joints),
            phases=[_phase(p, "phases") for p in (phases or [])],
            model_path=Path(model_path) if model_path is not None else None,
            model_xml=model_xml,
            summary=dict(summary or {}),
        )
        record.validate()
        return record

    def validate(self) -> None:
        """Checks shapes and times.

        Raises:
            RunFolderError: ``t`` missing, not 1-D, not strictly increasing or not finite, or
                an array whose first dimension or joint column count does not match.
        """
        self.require(("t",))
        t = self.arrays["t"]
        if t.ndim != 1 or t.size < 2:
            raise RunFolderError(f"{self.where}: trajectory.npz 't' must be 1-D with >= 2 samples")
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0.0):
            raise RunFolderError(
                f"{self.where}: trajectory.npz 't' must be finite and strictly increasing"
            )
        n = t.size
        for name, value in self.arrays.items():
            if value.dtype.kind not in "fiub":
                raise RunFolderError(f"{self.where}: trajectory.npz {name!r} has dtype "
                                     f"{value.dtype}, expected numbers")
            if value.dtype.kind == "f" and not np.all(np.isfinite(value)):
                raise RunFolderError(f"{self.where}: trajectory.npz {name!r} holds NaN or inf")
            if name in ("knot_t",):
                continue
            if value.shape[:1] != (n,):
                raise RunFolderError(
                    f"{self.where}: trajectory.npz {name!r} has shape {value.shape}, expected "
                    f"{n} rows like 't'"
                )
        for name in JOINT_ARRAYS:
            if name in self.arrays and (
                self.arrays[name].ndim != 2 or self.arrays[name].shape[1] != len(self.joints)
            ):
                raise RunFolderError(
                    f"{self.where}: trajectory.npz {name!r} has shape {self.arrays[name].shape}, "
                    f"expected (N, {len(self.joints)}) for joints {', '.join(self.joints)}"
                )
        for name in ("tcp_pos", "tcp_pos_ref"):
            if name in self.arrays and self.arrays[name].shape[1:] != (3,):
                raise RunFolderError(
                    f"{self.where}: trajectory.npz {name!r} has shape {self.arrays[name].shape}, "
                    "expected (N, 3)"
                )


def confine_model_files(model_path: Path, where: str) -> None:
    """Refuse a ``model.xml`` that would read files outside its folder: ``<include>``, an
    absolute or ``..`` file name (meshes, textures, height fields, skins), or an asset
    directory pointing elsewhere.

    Raises:
        RunFolderError: The first such reference, named.
    """
    import xml.etree.ElementTree as ET

    folder = model_path.resolve().parent
    try:
        root = ET.parse(model_path).getroot()
    except (ET.ParseError, OSError) as exc:
        raise RunFolderError(f"{where}: model.xml is not valid XML ({exc})") from None
    dirs = {"": folder}
    for comp in root.iter("compiler"):
        for key in ("assetdir", "meshdir", "texturedir"):
            if key in comp.attrib:
                dirs[key] = (folder / comp.attrib[key]).resolve()
    for el in root.iter():
        if el.tag == "include":
            raise RunFolderError(f"{where}: model.xml includes {el.attrib.get('file', '?')!r}; "
                                 "a run folder's model is self-contained")
        for key in ("file", "fileright", "fileleft", "fileup", "filedown", "filefront",
                    "fileback"):
            if key in el.attrib:
                base = dirs.get("meshdir" if el.tag == "mesh" else "texturedir", folder)
                path = (base / el.attrib[key]).resolve()
                if folder not in path.parents:
                    raise RunFolderError(f"{where}: model.xml reads {el.attrib[key]!r}, outside "
                                         "the run folder")
    for key, d in dirs.items():
        if key and d != folder and folder not in d.parents:
            raise RunFolderError(f"{where}: model.xml's {key} points outside the run folder")


def _phase(item: Phase | Mapping[str, Any], where: str) -> Phase:
    if isinstance(item, Phase):
        return item
    try:
        return Phase(
            str(item["name"]), str(item.get("kind", "")), float(item["t0"]), float(item["t1"])
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise RunFolderError(
            f"{where}: each phase needs 'name', 't0', 't1' (got {dict(item)!r})"
        ) from exc


def load_run(run_dir: str | Path) -> RunRecord:
    """Reads a run folder.

    ``summary.json`` is optional: without it (the runner renders before writing it) the
    joints are named ``j1 .. jN`` and the phases are unnamed.

    Args:
        run_dir: Folder written by ``cellsim run``.

    Returns:
        The validated :class:`RunRecord` (``model_path`` set; the model is not compiled).

    Raises:
        RunFolderError: The folder or one of its files is missing or malformed.
    """
    folder = Path(run_dir)
    where = f"run folder {str(folder)!r}"
    if not folder.is_dir():
        raise RunFolderError(
            f"{where} does not exist or is not a folder (give the folder `cellsim run` wrote)"
        )
    if marker_state(folder) == "writing":
        raise RunFolderError(f"{where} is a run that was still being written (a killed or "
                             "running `cellsim run`), not a result; the next run into that "
                             "place removes it")
    missing = [n for n in (MODEL_XML, TRAJECTORY_NPZ) if not (folder / n).is_file()]
    if missing:
        raise RunFolderError(
            f"{where} lacks {', '.join(missing)} (a run folder holds model.xml, summary.json and "
            "trajectory.npz)"
        )
    try:
        with np.load(folder / TRAJECTORY_NPZ, allow_pickle=False) as npz:
            arrays = {name: npz[name] for name in npz.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise RunFolderError(f"{where}: trajectory.npz does not load ({exc})") from exc
    summary: Any = {}
    if (folder / SUMMARY_JSON).is_file():
        try:
            summary = json.loads((folder / SUMMARY_JSON).read_text())
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise RunFolderError(f"{where}: summary.json is not valid JSON ({exc})") from exc
        if not isinstance(summary, dict):
            raise RunFolderError(f"{where}: summary.json must hold a JSON object")
    joints = summary.get("joints")
    if joints is None:  # no summary (yet): the project's default names j1..jN
        width = next((arrays[k].shape[1] for k in JOINT_ARRAYS
                      if k in arrays and arrays[k].ndim == 2), 0)
        joints = [f"j{i + 1}" for i in range(width)]
    if not isinstance(joints, list) or not all(isinstance(j, str) for j in joints):
        raise RunFolderError(f"{where}: summary.json 'joints' must be a list of joint names")
    phases_raw = summary.get("phases", [])
    if not isinstance(phases_raw, list):
        raise RunFolderError(f"{where}: summary.json 'phases' must be a list")
    record = RunRecord(
        arrays=arrays,
        joints=list(joints),
        phases=[_phase(p, f"{where}: summary.json") for p in phases_raw],
        model_path=folder / MODEL_XML,
        summary=summary,
        source=folder,
    )
    record.validate()
    return record


def as_record(run: str | Path | RunRecord) -> RunRecord:
    """A :class:`RunRecord` from a run folder path or a record (returned as is)."""
    return run if isinstance(run, RunRecord) else load_run(run)


# ------------------------------------------------------------------------------------ safety
def is_run_folder(path: str | Path) -> bool:
    """Whether ``path`` is a real folder (not a symbolic link) that cellsim wrote: it holds the
    :data:`MARKER` file, or (a run folder of cellsim 0.1, before the marker) a
    ``manifest.json`` that names cellsim and the scenario's hash."""
    p = Path(path)
    if not p.is_dir() or p.is_symlink():
        return False
    if (p / MARKER).is_file():
        return True
    try:
        manifest = json.loads((p / MANIFEST_JSON).read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return False
    return isinstance(manifest, dict) and {"cellsim", "scenario_sha256"} <= manifest.keys()


def write_marker(folder: str | Path, state: str = "complete") -> Path:
    """Write the :data:`MARKER` file that makes ``folder`` cellsim's.

    ``state`` is ``"writing"`` while the runner fills its hidden temporary folder and
    ``"complete"`` once it is whole (just before it is moved into place): a folder left
    ``"writing"`` by a killed run is never read as a result (:func:`load_run`) and is removed
    by the next run into the same place (:func:`remove_stale`).
    """
    import os

    from sim import __version__

    return write_text(folder, MARKER, json.dumps({"written_by": "cellsim",
                                                  "cellsim": __version__, "state": state,
                                                  "pid": os.getpid()}) + "\n")


def marker_state(folder: str | Path) -> str | None:
    """The marker's ``state`` (``"writing"``, ``"complete"``), None without a marker; a marker
    of cellsim 0.2 without a state counts as complete."""
    try:
        doc = json.loads((Path(folder) / MARKER).read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    return str(doc.get("state", "complete")) if isinstance(doc, dict) else None


class RunLock:
    """An exclusive lock on a run folder's place: ``.<name>.lock`` next to it, holding the
    writer's pid, taken with ``flock`` (released by the kernel when the process dies, so a
    killed run never leaves the place locked).

    Raises:
        RunFolderError: Another process holds it; the message names its pid.
    """

    def __init__(self, out_dir: Path) -> None:
        self.path = out_dir.with_name(f".{out_dir.name}.lock")
        self.out_dir = out_dir
        self._fd: int | None = None

    def __enter__(self) -> RunLock:
        import fcntl
        import os

        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
        except OSError as exc:
            raise RunFolderError(f"{self.path}: cannot create the run's lock file: "
                                 f"{exc.strerror or exc}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            try:
                other = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
            finally:
                os.close(fd)
            raise RunFolderError(f"run folder {str(self.out_dir)!r} is being written by another "
                                 f"cellsim run (pid {other}); wait for it or choose another "
                                 "--out") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._fd = fd
        return self

    def __exit__(self, *exc: object) -> None:
        import os

        if self._fd is not None:
            try:
                self.path.unlink(missing_ok=True)
            except OSError:
                pass
            os.close(self._fd)
            self._fd = None


def remove_stale(out_dir: Path) -> list[Path]:
    """Remove what killed runs into ``out_dir`` left next to it: hidden temporary folders
    (``.<name>.XXXX``) and trash folders (``.<name>.old.XXXX``) that cellsim wrote. Call it
    holding the place's :class:`RunLock`: no live run can own them then. Returns what went."""
    import re
    import shutil

    gone = []
    parent = out_dir.parent
    if not parent.is_dir():
        return gone
    # tempfile.mkdtemp's names: the prefix and 8 characters of [a-z0-9_]
    pattern = re.compile(rf"^\.{re.escape(out_dir.name)}\.(old\.)?[a-z0-9_]{{8}}$")
    for entry in parent.iterdir():
        m = pattern.match(entry.name)
        if not m or entry.is_symlink() or not entry.is_dir():
            continue
        if (m.group(1) is None and is_run_folder(entry)) or (
                m.group(1) is not None and all(is_run_folder(c) for c in entry.iterdir())):
            shutil.rmtree(entry, ignore_errors=True)
            gone.append(entry)
    return gone


def check_out_dir(requested: str | Path) -> Path:
    """The absolute run folder for a requested one, if cellsim may write (and replace) it.

    A run replaces only a folder cellsim wrote (it holds :data:`MARKER`) or an empty one; it
    never writes through a symbolic link, into a file's place, or over the working directory
    or a folder that contains it.

    Raises:
        RunFolderError: One line naming the path and what is wrong with it.
    """
    raw = Path(requested)
    if raw.name in ("", ".", ".."):
        raise RunFolderError(f"run folder {str(requested)!r}: give a folder name, not "
                             f"{str(requested)!r} (cellsim replaces the whole folder)")
    if len(raw.name.encode()) > MAX_NAME_BYTES:
        raise RunFolderError(f"run folder {str(requested)[:60]!r}...: the name is too long "
                             f"({len(raw.name.encode())} bytes; at most {MAX_NAME_BYTES}, room "
                             "for the hidden temporary folder next to it)")
    try:
        return _check_out_dir(raw)
    except OSError as exc:
        raise RunFolderError(f"run folder {str(raw)!r}: {exc.strerror or exc}") from None


#: Longest run-folder name, bytes: file systems allow 255, and the runner's hidden temporary
#: folder ``.<name>.old.XXXXXXXX`` next to it needs 14 more.
MAX_NAME_BYTES = 240


def _check_out_dir(raw: Path) -> Path:
    if raw.is_symlink():
        raise RunFolderError(f"run folder {str(raw)!r} is a symbolic link; cellsim writes only "
                             "into a real folder (choose another --out)")
    target = raw.parent.resolve() / raw.name
    cwd = Path.cwd().resolve()
    if target == cwd or target in cwd.parents:
        raise RunFolderError(f"run folder {str(target)!r} is the working directory or contains "
                             "it; choose another --out")
    if target.exists() and not target.is_dir():
        raise RunFolderError(f"run folder {str(target)!r} is a file; cellsim does not replace "
                             "it (choose another --out)")
    if target.is_dir() and not is_run_folder(target) and any(target.iterdir()):
        raise RunFolderError(f"run folder {str(target)!r} exists and was not written by cellsim "
                             f"(no {MARKER} in it); cellsim does not replace it: choose another "
                             "--out, or remove the folder yourself")
    return target


# ------------------------------------------------------------------------------------ writing
def write_text(folder: str | Path, name: str, text: str) -> Path:
    """Write one of the folder's text files (``MODEL_XML``, ``SCENARIO_TOML``, ...)."""
    path = Path(folder) / name
    path.write_text(text)
    return path


def write_summary(folder: str | Path, summary: Mapping[str, Any]) -> Path:
    """Write ``summary.json`` (one-space indent, trailing newline)."""
    return write_text(folder, SUMMARY_JSON, json.dumps(summary, indent=1) + "\n")


def write_trajectory(folder: str | Path, arrays: Mapping[str, np.ndarray]) -> Path:
    """Write ``trajectory.npz`` (compressed) from the recorded arrays (see ``ARRAYS``)."""
    path = Path(folder) / TRAJECTORY_NPZ
    with naming(path):
        np.savez_compressed(path, **arrays)
    return path


def decimate(arrays: Mapping[str, np.ndarray], timestep: float, record_hz: float | None
             ) -> dict[str, np.ndarray]:
    """The recorded arrays kept at ``record_hz`` (every k-th sample, k = round(1 / (timestep
    record_hz)) >= 1, the last sample always kept); all of them when ``record_hz`` is None.
    Checks, sizing, plots and video of a run use every sample; this is what ``trajectory.npz``
    keeps."""
    out = dict(arrays)
    if record_hz is None:
        return out
    n = len(arrays["t"])
    k = max(1, int(round(1.0 / (timestep * record_hz))))
    if k == 1:
        return out
    keep = np.unique(np.append(np.arange(0, n, k), n - 1))
    for name, value in arrays.items():
        if name != "knot_t" and np.ndim(value) >= 1 and len(value) == n:
            out[name] = np.asarray(value)[keep]
    return out


def sample_rate(t: np.ndarray) -> float:
    """The median sampling rate of a time array, Hz."""
    dt = np.diff(np.asarray(t, float))
    return float(1.0 / np.median(dt)) if dt.size else 0.0


#: Joint arrays written to ``trajectory.csv`` (one column per joint: ``q_ref_j1``, ...).
CSV_JOINT_ARRAYS: tuple[str, ...] = ("q_ref", "qd_ref", "qdd_ref", "q", "qd", "tau", "tau_id")


def write_csv(folder: str | Path, arrays: Mapping[str, np.ndarray], joints: Sequence[str]
              ) -> Path:
    """Write ``trajectory.csv``: t, phase, the joint arrays per joint, tool points, tool state."""
    cols: list[tuple[str, np.ndarray]] = [("t", arrays["t"]), ("phase", arrays["phase"])]
    for key in CSV_JOINT_ARRAYS:
        for j, name in enumerate(joints):
            cols.append((f"{key}_{name}", arrays[key][:, j]))
    for key in ("tcp_pos", "tcp_pos_ref"):
        for a, axis in enumerate("xyz"):
            cols.append((f"{key}_{axis}", arrays[key][:, a]))
    for key in ("arc_on", "suction"):
        cols.append((key, arrays[key].astype(int)))
    header = ",".join(c for c, _ in cols)
    data = np.column_stack([np.asarray(v, dtype=float) for _, v in cols])
    path = Path(folder) / TRAJECTORY_CSV
    with naming(path):
        np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.9g")
    return path


def failed_folder(out_dir: Path) -> Path:
    """Where a run that failed mid-simulation keeps what it recorded."""
    return out_dir.with_name(out_dir.name + FAILED_SUFFIX)
