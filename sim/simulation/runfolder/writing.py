"""Writing a run folder's files: its text files, ``summary.json``, ``trajectory.npz`` and
``trajectory.csv``, and what of the recorded samples ``trajectory.npz`` keeps.

Owns the files' formats as written (one-space-indented JSON, deflated npz, the CSV's
columns); the marker, lock and the folder's place are :mod:`~sim.simulation.runfolder.place`'s.
May import: :mod:`sim.core.files` and the run folder's schema.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sim.core.files import naming
from sim.simulation.runfolder.schema import SUMMARY_JSON, TRAJECTORY_CSV, TRAJECTORY_NPZ


def write_text(folder: str | Path, name: str, text: str) -> Path:
    """Write one of the folder's text files (``MODEL_XML``, ``SCENARIO_TOML``, ...)."""
    path = Path(folder) / name
    path.write_text(text)
    return path


def write_summary(folder: str | Path, summary: Mapping[str, Any]) -> Path:
    """Write ``summary.json`` (one-space indent, trailing newline)."""
    return write_text(folder, SUMMARY_JSON, json.dumps(summary, indent=1) + "\n")


#: zlib level of ``trajectory.npz``'s members: level 1 writes the default weld cycle's 50 MB in
#: less than half the time of numpy's ``savez_compressed`` (level 6), 1.5 % larger.
NPZ_LEVEL = 1


def write_trajectory(folder: str | Path, arrays: Mapping[str, np.ndarray]) -> Path:
    """Write ``trajectory.npz`` from the recorded arrays (see ``ARRAYS``): an ``.npz`` as
    :func:`numpy.savez_compressed` writes it (one deflated ``NAME.npy`` per array, read by
    :func:`numpy.load`), at zlib level :data:`NPZ_LEVEL`."""
    import zipfile

    path = Path(folder) / TRAJECTORY_NPZ
    with naming(path), zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED,
                                       compresslevel=NPZ_LEVEL, allowZip64=True) as zf:
        for name, value in arrays.items():
            with zf.open(f"{name}.npy", "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.asanyarray(value), allow_pickle=False)
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
    """The median sampling rate of a time array, Hz, to 9 significant digits (a 1 ms record
    is 1000 Hz, not the 999.9999999999991 its float steps give)."""
    dt = np.diff(np.asarray(t, float))
    return float(f"{1.0 / np.median(dt):.9g}") if dt.size else 0.0


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
