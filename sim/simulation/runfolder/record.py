"""The run in memory: :class:`RunRecord` (the recorded arrays, joints, phases, the model) and
its checks, the :class:`Phase` of a work cycle and how a phase is read from ``summary.json``.

Owns what a run *is* once read; :mod:`~sim.simulation.runfolder.reading` reads one from a
folder, the runner builds one with :meth:`RunRecord.from_arrays`.
May import: :mod:`sim.errors` and the run folder's schema and confinement.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sim.errors import RunFolderError
from sim.simulation.runfolder.confine import confine_model_files
from sim.simulation.runfolder.schema import ARRAYS, JOINT_ARRAYS, short_repr


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
    _model_xml: str | Callable[[], str] | None = field(default=None, repr=False)
    summary: dict[str, Any] = field(default_factory=dict)
    source: Path | None = None

    @property
    def model_xml(self) -> str | None:
        """MJCF text of the cell, or None (then ``model_path``); a record made in memory
        writes it when first asked for (a metrics-only sweep variant never asks)."""
        if callable(self._model_xml):
            self._model_xml = self._model_xml()
        return self._model_xml

    @model_xml.setter
    def model_xml(self, text: str | None) -> None:
        self._model_xml = text

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
        model_xml: str | Callable[[], str] | None = None,
        summary: dict[str, Any] | None = None,
    ) -> RunRecord:
        """Builds a record from arrays in memory (same names and shapes as trajectory.npz).

        Args:
            arrays: Per-sample arrays by name; at least ``t`` (N,).
            joints: Joint names (columns of the joint arrays).
            phases: Phases as :class:`Phase` or summary-style dicts.
            model_path: Path of the cell's MJCF, or None with ``model_xml``.
            model_xml: MJCF text, alternative to ``model_path`` (or what writes it when
                first asked for).
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
            _model_xml=model_xml,
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
                                 f"{short_repr(value)}")
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
                             f"{short_repr(item)}")
    if not isinstance(item.get("name"), str):
        raise RunFolderError(f"{where}.name must be a string, not {short_repr(item.get('name'))}")
    kind = item.get("kind", "")
    if not isinstance(kind, str):
        raise RunFolderError(f"{where}.kind must be a string, not {short_repr(kind)}")
    t0, t1 = _interval(item, where)
    return Phase(item["name"], kind, t0, t1)
