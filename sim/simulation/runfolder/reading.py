"""Reading a run folder: :func:`load_run` (the whole run as a :class:`RunRecord`) and the
bounded, confined readers of its files (``trajectory.npz`` without numpy's loader,
``summary.json``), each damage one :class:`~sim.errors.RunFolderError`.

Owns how a run folder is read; nothing outside the folder is read and every file is bounded in
size (the bounds are in :mod:`~sim.simulation.runfolder.schema`).
May import: :mod:`sim.core.files`, :mod:`sim.errors` and the rest of the run-folder package.
"""

from __future__ import annotations

import json
import math
import os
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from sim.core.files import check_input, read_input
from sim.errors import RunFolderError
from sim.simulation.runfolder.confine import confine_model_files
from sim.simulation.runfolder.place import marker_state
from sim.simulation.runfolder.record import RunRecord, _interval, _phase
from sim.simulation.runfolder.schema import (
    JOINT_ARRAYS,
    MAX_MODEL_BYTES,
    MAX_SUMMARY_BYTES,
    MAX_TRAJECTORY_ARRAYS,
    MAX_TRAJECTORY_BYTES,
    MODEL_XML,
    SUMMARY_JSON,
    TRAJECTORY_NPZ,
    file_error,
    short_repr,
)


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
    check_input(path, file_error(path, f"{where}: {name}"), "file", max_bytes)
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
                    raise RunFolderError(f"{where}: trajectory.npz member {short_repr(member)} is not "
                                         "an array (.npy)")
                if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
                    raise RunFolderError(f"{where}: trajectory.npz member {short_repr(member)} is "
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
                        raise RunFolderError(f"{where}: trajectory.npz {short_repr(member[:-4])} has "
                                             f"dtype {short_repr(str(dtype))}, expected numbers")
                    if any(not isinstance(d, int) or d < 0 for d in shape):
                        raise ValueError(f"invalid shape {short_repr(shape)}")
                    count = math.prod(shape)
                    left = info.file_size - fp.tell()
                    if count * dtype.itemsize != left:
                        raise RunFolderError(
                            f"{where}: trajectory.npz {short_repr(member[:-4])}: its header claims shape "
                            f"{short_repr(shape)} of {dtype} ({count * dtype.itemsize:,} bytes) but "
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
                             f"{short_repr(member)})") from None
    except damaged as exc:
        detail = str(exc).splitlines()[0] if str(exc).strip() else type(exc).__name__
        inside = f"member {short_repr(member)} is " if member != "?" else ""
        raise RunFolderError(f"{where}: trajectory.npz does not load ({inside}damaged: "
                             f"{type(exc).__name__}: {short_repr(detail, 160)})") from None
    return arrays


def _read_summary(path: Path, where: str) -> dict[str, Any]:
    """``summary.json`` (or another JSON file of the run) as a dict (UTF-8, at most
    :data:`MAX_SUMMARY_BYTES`, a JSON object)."""
    data = read_input(path, file_error(path, f"{where}: {path.name}"), "file",
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
                             f"({short_repr(str(exc), 160)})") from None
    if not isinstance(summary, dict):
        raise RunFolderError(f"{where}: {path.name} must hold a JSON object, not "
                             f"{type(summary).__name__}")
    return summary


def _check_collisions(collisions: Any, where: str) -> None:
    """``summary.json``'s ``collisions`` as the video reads them: a list of objects with
    finite ``t0`` <= ``t1`` and ``geoms``/``all_geoms`` lists of names."""
    if not isinstance(collisions, list):
        raise RunFolderError(f"{where} must be a list, not {type(collisions).__name__}")
    for i, c in enumerate(collisions):
        if not isinstance(c, dict):
            raise RunFolderError(f"{where}[{i}] must be an object, not {short_repr(c)}")
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




def read_run_trajectory(run_dir: str | Path) -> dict[str, np.ndarray] | None:
    """The arrays of a run folder's ``trajectory.npz`` as :func:`load_run` reads them (confined
    to the folder, bounded, checked member by member), without the model or the summary; None
    when the folder has no ``trajectory.npz``.

    Raises:
        RunFolderError: The file is outside the folder, not a regular file, too large or
            damaged (one line naming the folder).
    """
    folder = Path(run_dir)
    where = f"run folder {str(folder)!r}"
    path = _run_file(folder, TRAJECTORY_NPZ, where, MAX_TRAJECTORY_BYTES)
    return None if path is None else _read_trajectory(path, where)


def read_run_summary(run_dir: str | Path) -> dict[str, Any]:
    """A run folder's ``summary.json`` as :func:`load_run` reads it (confined, bounded, a JSON
    object); {} when the folder has none.

    Raises:
        RunFolderError: The file is outside the folder, not a regular file, too large, not UTF-8
            or not a JSON object.
    """
    folder = Path(run_dir)
    where = f"run folder {str(folder)!r}"
    path = _run_file(folder, SUMMARY_JSON, where, MAX_SUMMARY_BYTES)
    return {} if path is None else _read_summary(path, where)


def read_run_json(run_dir: str | Path, name: str) -> dict[str, Any] | None:
    """A JSON file of a run folder (``summary.json``, ``sizing.json``) as a dict, read under
    the bounds :func:`load_run` reads ``summary.json`` with; None when the folder has no such
    file.

    Raises:
        RunFolderError: The file is a link out of the folder, not a regular file, too large,
            not UTF-8 or not a JSON object (one line naming the folder and the file).
    """
    folder = Path(run_dir)
    where = f"run folder {str(folder)!r}"
    path = _run_file(folder, name, where, MAX_SUMMARY_BYTES)
    return None if path is None else _read_summary(path, where)
