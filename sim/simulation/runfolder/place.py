"""The place a run is written: the marker that makes a folder cellsim's (and its state), the
lock on a run folder's place, the leftovers of killed runs, the check of a requested
``--out`` and the folder a failed run keeps.

Owns what makes writing a run folder safe: cellsim replaces only what it wrote, never writes
through a symbolic link or over the working directory, and one run at a time writes a place.
May import: :mod:`sim.errors` and the run folder's schema and writers.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from sim.errors import RunFolderError
from sim.simulation.runfolder.schema import FAILED_SUFFIX, MANIFEST_JSON, MARKER
from sim.simulation.runfolder.writing import write_text


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

    if state == "complete":  # what the folder holds now is all cellsim's
        write_text(folder, INVENTORY, "".join(f"{e}\n" for e in _entries(Path(folder))))
    return write_text(folder, MARKER, json.dumps({"written_by": "cellsim",
                                                  "cellsim": __version__, "state": state,
                                                  "pid": os.getpid()}) + "\n")


#: The files and folders a complete run or sweep folder held when cellsim finished writing it,
#: one relative path a line (a folder's with a trailing ``/``): what a later run may delete.
INVENTORY = ".cellsim-files"


def _entries(folder: Path) -> list[str]:
    """Every file and folder under ``folder`` as relative paths (folders end in ``/``),
    sorted; the marker and the inventory left out. Symbolic links are entries, not followed."""
    out = []
    for root, dirs, files in os.walk(folder):
        rel = Path(root).relative_to(folder)
        out += [f"{(rel / d).as_posix()}/" for d in dirs]
        out += [(rel / f).as_posix() for f in files]
    return sorted(e for e in out if e not in (MARKER, INVENTORY))


def foreign_entries(folder: str | Path) -> list[str]:
    """What a run folder cellsim wrote holds now that cellsim did not write (a colleague's
    notes, an annotated plot): the entries missing from its :data:`INVENTORY`, a new
    folder's contents named by the folder; [] for a folder without an inventory (written
    before it was kept)."""
    folder = Path(folder)
    try:
        known = set((folder / INVENTORY).read_text(encoding="utf-8").splitlines())
    except (OSError, UnicodeDecodeError):
        return []
    extra = [e for e in _entries(folder) if e not in known]
    dirs = [e for e in extra if e.endswith("/")]
    return [e for e in extra if not any(e != d and e.startswith(d) for d in dirs)]


def written_by_cellsim(path: str | Path, run_dir: str | Path) -> bool:
    """Whether ``path`` (inside the run folder ``run_dir``) is a file cellsim wrote there: in
    the folder's :data:`INVENTORY` (a folder without one: its own ``video.mp4`` and plots)."""
    run, p = Path(run_dir).resolve(), Path(path).resolve()
    if not is_run_folder(run) or run not in p.parents:
        return False
    rel = p.relative_to(run).as_posix()
    try:
        known = set((run / INVENTORY).read_text(encoding="utf-8").splitlines())
    except (OSError, UnicodeDecodeError):
        return rel == "video.mp4" or rel.startswith("plots/")
    return rel in known


def note_written(run_dir: str | Path, paths: list[Path]) -> None:
    """Add files cellsim wrote into a finished run folder later (``cellsim render``'s video
    and plots) to its :data:`INVENTORY`, so that they count as cellsim's."""
    run = Path(run_dir).resolve()
    inventory = run / INVENTORY
    if not inventory.is_file():
        return
    known = inventory.read_text(encoding="utf-8").splitlines()
    new = []
    for path in paths:
        p = Path(path).resolve()
        if run not in p.parents:
            continue
        rel = p.relative_to(run)
        new += [f"{a.as_posix()}/" for a in reversed(rel.parents) if a != Path(".")]
        new.append(rel.as_posix())
    merged = sorted(set(known) | set(new))
    if merged != sorted(known):
        write_text(run, INVENTORY, "".join(f"{e}\n" for e in merged))


def make_folder(prefix: str, parent: Path) -> Path:
    """A new hidden folder next to a run folder's place (:func:`tempfile.mkdtemp`), with the
    permissions a folder made with ``mkdir`` gets (mkdtemp's are 0700: colleagues could not
    open the run moved into place)."""
    import tempfile

    path = Path(tempfile.mkdtemp(prefix=prefix, dir=parent))
    mask = os.umask(0)
    os.umask(mask)
    path.chmod(0o777 & ~mask)
    return path


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
    foreign = foreign_entries(target) if target.is_dir() else []
    if foreign:
        shown = ", ".join(foreign[:3]) + (f" and {len(foreign) - 3} more" if len(foreign) > 3
                                          else "")
        raise RunFolderError(f"run folder {str(target)!r} holds what cellsim did not write "
                             f"({shown}); replacing the folder would delete it: move it out, or "
                             "choose another --out")
    return target



def failed_folder(out_dir: Path) -> Path:
    """Where a run that failed mid-simulation keeps what it recorded."""
    return out_dir.with_name(out_dir.name + FAILED_SUFFIX)
