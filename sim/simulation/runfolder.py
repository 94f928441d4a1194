"""Reading a finished run folder (what ``cellsim run`` writes) for rendering and plots.

A run folder DIR holds:

* ``model.xml``: the compiled cell (``mujoco.MjModel.from_xml_path``);
* ``summary.json``: ``scenario``, ``robot``, ``joints`` (names), ``phases``
  (``[{"name", "kind", "t0", "t1"}]``), ``duration_s``, ...;
* ``trajectory.npz``: ``t`` (N,) s, ``phase`` (N,) phase index, ``qpos`` (N, nq) full MuJoCo
  qpos, ``q_ref``/``qd_ref``/``qdd_ref``/``qddd_ref``/``q``/``qd``/``tau``/``tau_id``
  (N, n_joints) in rad, rad/s, rad/s^2, rad/s^3, N m, ``tcp_pos``/``tcp_pos_ref`` (N, 3) m in the
  world frame, ``tcp_quat`` (N, 4), ``arc_on``/``suction`` (N,) bool, ``knot_t`` (K,) s.

:class:`RunRecord` can also be built from arrays in memory (:meth:`RunRecord.from_arrays`),
so the runner can render without writing and reading the folder back.
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sim.errors import RunFolderError

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
    missing = [n for n in ("model.xml", "trajectory.npz") if not (folder / n).is_file()]
    if missing:
        raise RunFolderError(
            f"{where} lacks {', '.join(missing)} (a run folder holds model.xml, summary.json and "
            "trajectory.npz)"
        )
    try:
        with np.load(folder / "trajectory.npz", allow_pickle=False) as npz:
            arrays = {name: npz[name] for name in npz.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise RunFolderError(f"{where}: trajectory.npz does not load ({exc})") from exc
    summary: Any = {}
    if (folder / "summary.json").is_file():
        try:
            summary = json.loads((folder / "summary.json").read_text())
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
        model_path=folder / "model.xml",
        summary=summary,
        source=folder,
    )
    record.validate()
    return record


def as_record(run: str | Path | RunRecord) -> RunRecord:
    """A :class:`RunRecord` from a run folder path or a record (returned as is)."""
    return run if isinstance(run, RunRecord) else load_run(run)
