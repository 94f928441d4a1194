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
import math
import os
import zipfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sim.core.files import check_input, naming, read_input
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
            return mujoco.MjModel.from_xml_path(confine_model_files(self.model_path, self.where))
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
            phases=[_phase(p, f"phases[{i}]") for i, p in enumerate(phases or [])],
            model_path=Path(model_path) if model_path is not None else None,
            model_xml=model_xml,
            summary=dict(summary or {}),
        )
        record.validate()
        return record

    def validate(self) -> None:
        """Checks dtypes, shapes and times.

        Raises:
            RunFolderError: ``t`` missing, not 1-D numbers, not strictly increasing or not
                finite; an array that is not numbers (or holds NaN or inf), whose first
                dimension does not match ``t``, or whose shape is not the one :data:`ARRAYS`
                gives it (joint columns: one per name of ``joints``).
        """
        self.require(("t",))
        for name, value in self.arrays.items():
            if not isinstance(value, np.ndarray) or value.dtype.kind not in "fiub":
                kind = value.dtype if isinstance(value, np.ndarray) else type(value).__name__
                raise RunFolderError(f"{self.where}: trajectory.npz {name!r} has dtype "
                                     f"{kind}, expected numbers")
        t = self.arrays["t"]
        if t.ndim != 1 or t.size < 2 or t.dtype.kind not in "fiu":
            raise RunFolderError(f"{self.where}: trajectory.npz 't' must be 1-D numbers with "
                                 f">= 2 samples (it has shape {t.shape}, dtype {t.dtype})")
        tf = t.astype(np.float64)  # no wrap-around of integer differences
        if not np.all(np.isfinite(tf)) or np.any(np.diff(tf) <= 0.0):
            raise RunFolderError(
                f"{self.where}: trajectory.npz 't' must be finite and strictly increasing"
            )
        n = t.size
        for name, value in self.arrays.items():
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
        for name, value in self.arrays.items():
            spec = ARRAYS.get(name)
            if spec is None:
                continue
            dims = [d.strip() for d in spec.shape.strip("()").split(",") if d.strip()]
            want = {"N": n, "n": len(self.joints)}
            if value.ndim != len(dims) or any(
                    (d.isdigit() and size != int(d)) or (d in want and size != want[d])
                    for d, size in zip(dims, value.shape)):
                raise RunFolderError(
                    f"{self.where}: trajectory.npz {name!r} has shape {value.shape}, expected "
                    f"{spec.shape} (N = {n} samples, n = {len(self.joints)} joints)"
                )


# --------------------------------------------------------------------- model.xml's files
#: MJCF elements whose file attributes MuJoCo resolves against ``<compiler meshdir>`` (height
#: fields, skins and flexcomp meshes too, not only meshes) or ``texturedir``, and the
#: attributes it reads files from.
_MESHDIR_FILES: dict[str, tuple[str, ...]] = {
    "mesh": ("file",), "hfield": ("file",), "skin": ("file",), "flexcomp": ("file",),
}
_TEXTUREDIR_FILES: dict[str, tuple[str, ...]] = {
    "texture": ("file", "fileright", "fileleft", "fileup", "filedown", "filefront",
                "fileback"),
}
#: Elements that read other files cellsim does not follow: refused in a run folder's model.
_REFUSED_ELEMENTS: dict[str, str] = {
    "include": "includes another file",
    "model": "attaches another model file (<model file=...>)",
    "plugin": "uses a MuJoCo plugin, which may read files cellsim cannot check",
    "extension": "uses a MuJoCo plugin (<extension>), which may read files cellsim cannot check",
}
#: Most elements of a run folder's ``model.xml`` (the shipped cells have a few thousand).
MAX_MODEL_ELEMENTS = 1_000_000


def _mj_abs_prefix(path: str) -> str:
    """The part of ``path`` MuJoCo takes for an absolute prefix (its ``FilePath::AbsPrefix``):
    a leading ``/`` or ``\\``, or everything up to a ``:/`` or ``:\\`` ("" when relative)."""
    if not path:
        return ""
    if path[0] in "/\\":
        return path[0]
    for mark in (":/", ":\\"):
        i = path.find(mark)
        if i >= 0:
            return path[:i + 2]
    return ""


def _mj_reduce(path: str) -> str:
    """``path`` as MuJoCo reduces it (``FilePath::PathReduce``): ``\\`` and ``/`` both separate,
    ``.`` and empty parts go, ``..`` removes the part before it (lexically, not as the file
    system would through a symbolic link), parts are joined with ``/``."""
    prefix = _mj_abs_prefix(path)
    parts: list[str] = []
    start = len(prefix)
    for i in range(start, len(path)):
        if path[i] in "/\\":
            part, start = path[start:i], i + 1
            if part == ".." and parts and parts[-1] != "..":
                parts.pop()
            elif part not in (".", ""):
                parts.append(part)
    parts.append(path[start:])
    return prefix + "/".join(parts)


def _mj_join(base: str, name: str) -> str:
    """``base`` and ``name`` joined and reduced as MuJoCo does (``name`` when it is absolute)."""
    if not _mj_abs_prefix(name) and base:
        name = base + name if base[-1] in "/\\" else f"{base}/{name}"
    return _mj_reduce(name)


def _mj_strip(name: str) -> str:
    """``name`` without its folders, as ``<compiler strippath="true">`` reads it."""
    return name[max(name.rfind("/"), name.rfind("\\")) + 1:]


def _show(value: Any, limit: int = 80) -> str:
    """``repr`` of a value for a one-line message, shortened to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _model_elements(data: bytes, where: str) -> list[tuple[str, dict[str, str], int]]:
    """The elements of ``model.xml`` that bear on the files MuJoCo reads: ``(tag, attributes,
    depth)`` of the root, the ``<compiler>`` sections and every element with a ``file*``
    attribute or a tag of :data:`_REFUSED_ELEMENTS`, in document order.

    Parsed with expat without namespace processing (tags and attribute names as MuJoCo's
    tinyxml2 reads them), as UTF-8 whatever the XML declaration says (tinyxml2 reads UTF-8 only);
    a DOCTYPE (entities: tinyxml2 does not read them as expat does) is refused.
    """
    from xml.parsers import expat

    class _Refused(Exception):
        pass

    kept: list[tuple[str, dict[str, str], int]] = []
    depth = 0
    count = 0

    def start(tag: str, attrs: dict[str, str]) -> None:
        nonlocal depth, count
        count += 1
        if count > MAX_MODEL_ELEMENTS:
            raise _Refused(f"more than {MAX_MODEL_ELEMENTS:,} elements")
        if (depth == 0 or tag == "compiler" or tag in _REFUSED_ELEMENTS
                or any(k.startswith("file") for k in attrs)):
            kept.append((tag, attrs, depth))
        depth += 1

    def end(tag: str) -> None:
        nonlocal depth
        depth -= 1

    def doctype(*args: Any) -> None:
        raise _Refused("a DOCTYPE (entity declarations), which a run folder's model has none of")

    parser = expat.ParserCreate(encoding="UTF-8")
    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = doctype
    try:
        parser.Parse(data, True)
    except expat.ExpatError as exc:
        raise RunFolderError(f"{where}: model.xml is not valid XML "
                             f"({expat.errors.messages.get(exc.code, exc)}, line {exc.lineno})"
                             ) from None
    except _Refused as exc:
        raise RunFolderError(f"{where}: model.xml has {exc}") from None
    return kept


def model_file_names(data: bytes, where: str) -> list[tuple[str, str, str, bool]]:
    """The files and asset folders an MJCF model makes MuJoCo read, named as MuJoCo names them.

    Args:
        data: The model's XML (UTF-8).
        where: How messages name the run.

    Returns:
        ``(what, value, name, is_dir)`` for the effective ``meshdir`` and ``texturedir`` (when
        set) and for every file attribute: ``what`` as messages say it (``"<hfield file>"``),
        the attribute's ``value``, and ``name``, the path MuJoCo opens relative to the model
        file's folder (absolute when MuJoCo takes it for absolute): ``value`` with
        ``strippath`` applied, joined to its dir, reduced as :func:`_mj_reduce` does.

    Raises:
        RunFolderError: Not XML (:func:`_model_elements`), a root other than ``<mujoco>``, an
            element of :data:`_REFUSED_ELEMENTS`, a file attribute of an element cellsim does
            not know, a name with white space or control characters, or a drive or resource
            name (``c:...``, ``scheme:...``).
    """
    elements = _model_elements(data, where)
    if not elements or elements[0][0] != "mujoco":
        root = elements[0][0] if elements else "?"
        raise RunFolderError(f"{where}: model.xml's root element is <{_show(root)[1:-1]}>, not "
                             "<mujoco> (a run folder holds a compiled MJCF model)")
    dirs = {"meshdir": "", "texturedir": ""}
    strip = False
    for tag, attrs, depth in elements:
        if tag != "compiler" or depth != 1:  # MuJoCo reads the root's <compiler> sections only
            continue
        if "assetdir" in attrs:  # first: meshdir and texturedir of the same section override it
            dirs["meshdir"] = dirs["texturedir"] = attrs["assetdir"]
        for key in ("meshdir", "texturedir"):
            if key in attrs:
                dirs[key] = attrs[key]
        if "strippath" in attrs:
            strip = attrs["strippath"] == "true"

    def check_name(what: str, value: str) -> None:
        if any(c.isspace() or not c.isprintable() for c in value):
            raise RunFolderError(f"{where}: model.xml's {what} {_show(value)} holds white space "
                                 "or control characters; a run folder's file names have none")
        head = value.split("/")[0].split("\\")[0]
        if ":" in head and head.split(":")[0][:1].isalpha():
            raise RunFolderError(f"{where}: model.xml's {what} {_show(value)} is a drive or "
                                 "resource name (MuJoCo reads it as absolute), not a file of "
                                 "the run folder")

    out: list[tuple[str, str, str, bool]] = []
    for key, value in dirs.items():
        if value:
            check_name(f"<compiler {key}>", value)
            out.append((f"<compiler {key}>", value, _mj_reduce(value), True))
    for tag, attrs, _ in elements:
        if tag in _REFUSED_ELEMENTS:
            raise RunFolderError(f"{where}: model.xml {_REFUSED_ELEMENTS[tag]} "
                                 f"({_show(attrs.get('file', attrs.get('plugin', tag)))}); "
                                 "a run folder's model is self-contained")
        known = _MESHDIR_FILES.get(tag, _TEXTUREDIR_FILES.get(tag, ()))
        folder = dirs["meshdir" if tag in _MESHDIR_FILES else "texturedir"]
        for key, value in attrs.items():
            if not key.startswith("file"):
                continue
            what = f"<{_show(tag)[1:-1]} {_show(key)[1:-1]}>"
            if key not in known:
                raise RunFolderError(f"{where}: model.xml's {what} names a file "
                                     f"({_show(value)}) that cellsim does not check; a run "
                                     "folder's model reads none")
            if not value:
                continue
            check_name(what, value)
            name = _mj_strip(value) if strip else value
            out.append((what, value, _mj_join(_mj_reduce(folder), _mj_reduce(name)), False))
    return out


def confine_model_files(model_path: Path, where: str) -> str:
    """Refuse a ``model.xml`` that would make MuJoCo read a file outside its run folder, and
    say how to load it.

    Every file the model names is resolved exactly as MuJoCo (4.0) resolves it: the
    ``<compiler>`` sections in order (``assetdir`` sets both ``meshdir`` and ``texturedir``,
    ``meshdir``/``texturedir`` of the same section override it, a later section overrides an
    earlier one, ``strippath`` drops a name's folders); ``meshdir`` for ``<mesh>``,
    ``<hfield>``, ``<skin>`` and ``<flexcomp>`` files, ``texturedir`` for ``<texture>``'s
    seven file attributes; an absolute name bypasses the dirs; ``\\`` separates like ``/``
    and ``..`` is reduced lexically (MuJoCo's ``FilePath``). The result is resolved through
    symbolic links and must lie inside the folder; what exists there must be a regular file
    (a FIFO would block MuJoCo). ``<include>``, ``<model file>``, plugins, a DOCTYPE, a root
    other than ``<mujoco>`` (a URDF), names MuJoCo would read relative to the working
    directory or through a resource provider (``x:/..``, ``scheme:...``) and names with
    white space or control characters (which expat and tinyxml2 read differently) are refused.

    Args:
        model_path: The run folder's ``model.xml``.
        where: How messages name the run.

    Returns:
        The path to give ``mujoco.MjModel.from_xml_path`` (absolute, the folder resolved:
        the one the files were resolved against).

    Raises:
        RunFolderError: The first file or element at fault, named, one line.
    """
    folder = Path(os.path.realpath(model_path.parent))
    load = folder / model_path.name
    if "\\" in str(load):  # MuJoCo would read the backslash as a separator
        raise RunFolderError(f"{where}: the folder's path holds a backslash, which MuJoCo reads "
                             "as a separator; move the run folder")
    real = Path(os.path.realpath(load))
    if folder not in real.parents:
        raise RunFolderError(f"{where}: model.xml is a symbolic link to {str(real)!r}, outside "
                             "the run folder")
    data = read_input(load, _file_error(load, f"{where}: model.xml"), "model file",
                      MAX_MODEL_BYTES)
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise RunFolderError(f"{where}: model.xml is not UTF-8 text ({exc.reason} at byte "
                             f"{exc.start})") from None
    base = f"{folder}/"  # MuJoCo's model file dir: from_xml_path(load)'s folder
    for what, value, name, is_dir in model_file_names(data, where):
        resolved = _mj_join(base, name)
        if not resolved.startswith("/"):  # "x:/..": absolute to MuJoCo, relative to the OS
            raise RunFolderError(f"{where}: model.xml's {what} {_show(value)} is read as "
                                 f"{_show(resolved)}, relative to the working directory, not "
                                 "the run folder")
        target = Path(os.path.realpath(resolved))
        if not (folder in target.parents or (is_dir and target == folder)):
            raise RunFolderError(f"{where}: model.xml's {what} {_show(value)} resolves to "
                                 f"{str(target)!r}, outside the run folder")
        if not is_dir and os.path.lexists(target):
            check_input(target, _file_error(target, f"{where}: model.xml's {what} "
                                                    f"{_show(value)} ({str(target)!r})"),
                        "model asset", MAX_ASSET_BYTES)
    return str(load)


# ------------------------------------------------------------------------------ reading
def _file_error(path: Path, prefix: str) -> Callable[[str], RunFolderError]:
    """The error :func:`~sim.core.files.read_input` raises for ``path``: its message (which
    begins with the path) after ``prefix`` instead of the path."""
    return lambda message: RunFolderError(f"{prefix}: {message.removeprefix(f'{path}: ')}")


def _run_file(folder: Path, name: str, where: str, max_bytes: int) -> Path | None:
    """The run folder's file ``name``, None when there is none; refused (one line) when it
    resolves outside the folder (a symbolic link elsewhere), is not a regular file (a FIFO
    would block the reader, a device never ends) or is larger than ``max_bytes``."""
    path = folder / name
    if not os.path.lexists(path):
        return None
    real = Path(os.path.realpath(path))
    if Path(os.path.realpath(folder)) not in real.parents:
        raise RunFolderError(f"{where}: {name} is a symbolic link to {str(real)!r}, outside the "
                             "run folder")
    check_input(path, _file_error(path, f"{where}: {name}"), "file", max_bytes)
    return path


def _read_trajectory(path: Path, where: str) -> dict[str, np.ndarray]:
    """The arrays of ``trajectory.npz``, read without numpy's loader so that nothing is trusted
    before it is checked: a zip of ``.npy`` members (stored or deflated, at most
    :data:`MAX_TRAJECTORY_ARRAYS`), each a numeric array whose header's shape and dtype give
    exactly the member's unpacked size, all together at most :data:`MAX_TRAJECTORY_BYTES`
    (checked before a byte is unpacked: a header claiming a huge shape allocates nothing);
    the zip's checksums are verified.

    Raises:
        RunFolderError: Naming the member and what is wrong (one line).
    """
    import lzma
    import stat
    import struct
    import zlib

    fmt = np.lib.format
    damaged = (OSError, ValueError, EOFError, TypeError, KeyError, IndexError, OverflowError,
               RuntimeError, NotImplementedError, struct.error, zlib.error, lzma.LZMAError,
               zipfile.BadZipFile)
    arrays: dict[str, np.ndarray] = {}
    member = "?"
    try:
        # not blocking on a FIFO put in its place since it was checked; a regular file only
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            os.close(fd)
            raise RunFolderError(f"{where}: trajectory.npz is not a regular file")
        with os.fdopen(fd, "rb") as fh, zipfile.ZipFile(fh) as zf:
            infos = zf.infolist()
            if len(infos) > MAX_TRAJECTORY_ARRAYS:
                raise RunFolderError(f"{where}: trajectory.npz holds {len(infos):,} members, "
                                     f"more than the {MAX_TRAJECTORY_ARRAYS} arrays a run has")
            # zipfile trusts the directory's size: a damaged one drops members silently; the
            # end record's count of members (its zip64 mark 0xFFFF aside) must match
            fh.seek(-22 - len(zf.comment), os.SEEK_END)
            end = fh.read(22)
            counts = struct.unpack("<HH", end[8:12]) if end[:4] == b"PK\x05\x06" else None
            if counts is None or any(c not in (len(infos), 0xFFFF) for c in counts):
                raise zipfile.BadZipFile(f"the end record counts {counts} members, the "
                                         f"directory lists {len(infos)}")
            if len({info.filename for info in infos}) != len(infos):
                raise zipfile.BadZipFile("two members of one name")
            total = sum(info.file_size for info in infos)
            if total > MAX_TRAJECTORY_BYTES:
                raise RunFolderError(f"{where}: trajectory.npz unpacks to {total:,} bytes, more "
                                     f"than the {MAX_TRAJECTORY_BYTES:,} a run records")
            for info in infos:
                member = info.filename
                if not member.endswith(".npy"):
                    raise RunFolderError(f"{where}: trajectory.npz member {_show(member)} is not "
                                         "an array (.npy)")
                if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
                    raise RunFolderError(f"{where}: trajectory.npz member {_show(member)} is "
                                         f"packed with method {info.compress_type}, not stored "
                                         "or deflated as numpy writes it")
                with zf.open(info) as fp:
                    version = fmt.read_magic(fp)
                    if version == (1, 0):
                        shape, fortran, dtype = fmt.read_array_header_1_0(fp)
                    elif version == (2, 0):
                        shape, fortran, dtype = fmt.read_array_header_2_0(fp)
                    else:
                        raise ValueError(f"unsupported .npy version {version}")
                    if dtype.kind not in "fiub" or dtype.hasobject or dtype.itemsize == 0:
                        raise RunFolderError(f"{where}: trajectory.npz {_show(member[:-4])} has "
                                             f"dtype {_show(str(dtype))}, expected numbers")
                    if any(not isinstance(d, int) or d < 0 for d in shape):
                        raise ValueError(f"invalid shape {_show(shape)}")
                    count = math.prod(shape)
                    left = info.file_size - fp.tell()
                    if count * dtype.itemsize != left:
                        raise RunFolderError(
                            f"{where}: trajectory.npz {_show(member[:-4])}: its header claims shape "
                            f"{_show(shape)} of {dtype} ({count * dtype.itemsize:,} bytes) but "
                            f"the member holds {left:,}")
                    flat = np.empty(count, dtype)
                    view = memoryview(flat).cast("B")
                    done = 0
                    while done < left:
                        chunk = fp.read(min(left - done, 1 << 20))
                        if not chunk:
                            raise EOFError("the member ends early")
                        view[done:done + len(chunk)] = chunk
                        done += len(chunk)
                    if fp.read(1):
                        raise ValueError("the member is longer than its header says")
                arrays[member[:-4]] = (flat.reshape(shape[::-1]).T if fortran
                                       else flat.reshape(shape))
    except RunFolderError:
        raise
    except MemoryError:
        raise RunFolderError(f"{where}: trajectory.npz does not fit in memory (member "
                             f"{_show(member)})") from None
    except damaged as exc:
        detail = str(exc).splitlines()[0] if str(exc).strip() else type(exc).__name__
        inside = f"member {_show(member)} is " if member != "?" else ""
        raise RunFolderError(f"{where}: trajectory.npz does not load ({inside}damaged: "
                             f"{type(exc).__name__}: {_show(detail, 160)})") from None
    return arrays


def _read_summary(path: Path, where: str) -> dict[str, Any]:
    """``summary.json`` (or another JSON file of the run) as a dict (UTF-8, at most
    :data:`MAX_SUMMARY_BYTES`, a JSON object)."""
    data = read_input(path, _file_error(path, f"{where}: {path.name}"), "file",
                      MAX_SUMMARY_BYTES)
    try:
        summary = json.loads(data.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise RunFolderError(f"{where}: {path.name} is not UTF-8 text ({exc.reason} at byte "
                             f"{exc.start})") from None
    except RecursionError:
        raise RunFolderError(f"{where}: {path.name} nests too deeply to read") from None
    except ValueError as exc:  # json.JSONDecodeError, and integers of too many digits
        raise RunFolderError(f"{where}: {path.name} is not valid JSON "
                             f"({_show(str(exc), 160)})") from None
    if not isinstance(summary, dict):
        raise RunFolderError(f"{where}: {path.name} must hold a JSON object, not "
                             f"{type(summary).__name__}")
    return summary


def _number(value: Any) -> bool:
    """Whether ``value`` is a real number (a JSON number; not a bool, not a string)."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_))


def _interval(item: Mapping[str, Any], where: str) -> tuple[float, float]:
    """``item``'s ``t0``, ``t1``: finite numbers with t0 <= t1."""
    times = []
    for key in ("t0", "t1"):
        if key not in item:
            raise RunFolderError(f"{where} has no {key!r}")
        value = item[key]
        if not _number(value) or not math.isfinite(float(value)):
            raise RunFolderError(f"{where}.{key} must be a finite number of seconds, not "
                                 f"{_show(value)}")
        times.append(float(value))
    if times[0] > times[1]:
        raise RunFolderError(f"{where} ends (t1 {times[1]:g} s) before it starts (t0 "
                             f"{times[0]:g} s)")
    return times[0], times[1]


def _phase(item: Phase | Mapping[str, Any], where: str) -> Phase:
    """A :class:`Phase` from a phase or a summary-style dict ``{"name", "kind", "t0", "t1"}``.

    Raises:
        RunFolderError: Not an object, a name or kind that is not a string, times that are not
            finite numbers or end before they start; ``where`` names the phase.
    """
    if isinstance(item, Phase):
        return item
    if not isinstance(item, Mapping):
        raise RunFolderError(f"{where} must be an object with 'name', 't0', 't1', not "
                             f"{_show(item)}")
    if not isinstance(item.get("name"), str):
        raise RunFolderError(f"{where}.name must be a string, not {_show(item.get('name'))}")
    kind = item.get("kind", "")
    if not isinstance(kind, str):
        raise RunFolderError(f"{where}.kind must be a string, not {_show(kind)}")
    t0, t1 = _interval(item, where)
    return Phase(item["name"], kind, t0, t1)


def _check_collisions(collisions: Any, where: str) -> None:
    """``summary.json``'s ``collisions`` as the video reads them: a list of objects with
    finite ``t0`` <= ``t1`` and ``geoms``/``all_geoms`` lists of names."""
    if not isinstance(collisions, list):
        raise RunFolderError(f"{where} must be a list, not {type(collisions).__name__}")
    for i, c in enumerate(collisions):
        if not isinstance(c, dict):
            raise RunFolderError(f"{where}[{i}] must be an object, not {_show(c)}")
        for key in ("geoms", "all_geoms"):
            if key in c and (not isinstance(c[key], list)
                             or not all(isinstance(g, str) for g in c[key])):
                raise RunFolderError(f"{where}[{i}].{key} must be a list of geom names")
        if c.get("all_geoms", c.get("geoms")):
            _interval(c, f"{where}[{i}]")


def load_run(run_dir: str | Path) -> RunRecord:
    """Reads a run folder.

    ``summary.json`` is optional: without it (the runner renders before writing it) the
    joints are named ``j1 .. jN`` and the phases are unnamed. Nothing outside the folder is
    read (a file that is a symbolic link elsewhere, or a ``model.xml`` naming a file elsewhere,
    is refused: :func:`confine_model_files`), every file is bounded in size, and any damage
    is one :class:`RunFolderError` naming the folder and the file (and member or field).

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
    model = _run_file(folder, MODEL_XML, where, MAX_MODEL_BYTES)
    npz = _run_file(folder, TRAJECTORY_NPZ, where, MAX_TRAJECTORY_BYTES)
    missing = [n for n, p in ((MODEL_XML, model), (TRAJECTORY_NPZ, npz)) if p is None]
    if missing:
        raise RunFolderError(
            f"{where} lacks {', '.join(missing)} (a run folder holds model.xml, summary.json and "
            "trajectory.npz)"
        )
    assert model is not None and npz is not None
    confine_model_files(model, where)
    arrays = _read_trajectory(npz, where)
    summary_path = _run_file(folder, SUMMARY_JSON, where, MAX_SUMMARY_BYTES)
    summary = _read_summary(summary_path, where) if summary_path is not None else {}
    joints = summary.get("joints")
    if joints is None:  # no summary (yet): the project's default names j1..jN
        width = next((arrays[k].shape[1] for k in JOINT_ARRAYS
                      if k in arrays and arrays[k].ndim == 2), 0)
        joints = [f"j{i + 1}" for i in range(width)]
    if not isinstance(joints, list) or not all(isinstance(j, str) for j in joints):
        raise RunFolderError(f"{where}: summary.json 'joints' must be a list of joint names")
    if "joints" in summary:
        for name in JOINT_ARRAYS:
            if name in arrays and arrays[name].ndim == 2 and arrays[name].shape[1] != len(joints):
                raise RunFolderError(f"{where}: summary.json 'joints' names {len(joints)} joints "
                                     f"but trajectory.npz {name!r} has {arrays[name].shape[1]} "
                                     "columns")
    phases_raw = summary.get("phases", [])
    if not isinstance(phases_raw, list):
        raise RunFolderError(f"{where}: summary.json 'phases' must be a list")
    phases = [_phase(p, f"{where}: summary.json 'phases'[{i}]")
              for i, p in enumerate(phases_raw)]
    if "collisions" in summary:
        _check_collisions(summary["collisions"], f"{where}: summary.json 'collisions'")
    record = RunRecord(
        arrays=arrays,
        joints=list(joints),
        phases=phases,
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
    of cellsim 0.2 without a state counts as complete. Only a small regular file is read (a
    FIFO or a symbolic link in its place counts as no marker: nothing blocks, nothing outside
    the folder is read)."""
    import stat

    try:
        fd = os.open(Path(folder) / MARKER,
                     os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        doc = json.loads(os.read(fd, 4096).decode())
    except (OSError, ValueError, RecursionError):  # JSON and UTF-8 errors are ValueErrors
        return None
    finally:
        os.close(fd)
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


def read_json(folder: str | Path, name: str) -> dict[str, Any] | None:
    """A JSON file of a run folder (``summary.json``, ``sizing.json``) as a dict, read under the
    same bounds as :func:`load_run` reads ``summary.json``; None when the folder has no such
    file.

    Raises:
        RunFolderError: The file is a link out of the folder, too large, or not a JSON object.
    """
    where = f"run folder {str(folder)!r}"
    path = _run_file(Path(folder), name, where, MAX_SUMMARY_BYTES)
    return None if path is None else _read_summary(path, where)
