"""Writing files so that nothing half-written looks complete, and errors name the file.

``write_atomic`` writes through a temporary file in the same folder and ``os.replace``: a
reader sees the old file or the new one, never a part (a full disk leaves the old file). Both
helpers give an operating-system error the path being written when it has none (a write on an
open file, numpy's and zipfile's writers: "No space left on device" alone names nothing).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def naming(path: str | Path) -> Iterator[None]:
    """Re-raise an ``OSError`` without a file name as the same error naming ``path``."""
    try:
        yield
    except OSError as exc:
        if exc.filename is None and exc.errno is not None:
            raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from exc
        raise


def new_file_mode() -> int:
    """The mode ``open`` gives a new file: ``0o666`` less the process's umask (a file written
    through a temporary one, created ``0o600``, gets it before it takes its name)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


def write_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` through a temporary file and ``os.replace``.

    Args:
        path: Destination; its folder is created when missing.
        data: Bytes, or text (written as UTF-8).

    Returns:
        The destination path.

    Raises:
        OSError: The folder or the file cannot be written (the error names ``path``); the
            previous file, if any, is unchanged and no temporary file is left.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    raw = data.encode("utf-8") if isinstance(data, str) else data
    with naming(path):  # a read-only folder: the error names the file asked for
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with naming(path), os.fdopen(fd, "wb") as fh:
            fh.write(raw)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, new_file_mode())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


#: The largest text input cellsim reads (a scenario, cell, tool, robot.toml, URDF, TP program
#: or catalogue), bytes: a thousand times the largest shipped one, checked before reading.
MAX_TEXT_BYTES = 16 * 1024 * 1024


def read_input(path: str | Path, error: Callable[[str], BaseException],
               what: str = "file",
               max_bytes: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of an input file: a regular file (a FIFO, a device such as ``/dev/zero`` or a
    folder is refused before a byte is read: opened without blocking, checked with ``fstat``),
    at most ``max_bytes`` (its size checked before reading, and the read bounded too).

    Raises:
        error: One line naming the file: missing, not a regular file, too large, unreadable.
    """

    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    try:
        _refuse(os.fstat(fd), path, error, what, max_bytes)
        chunks, left = [], max_bytes + 1
        while left > 0:
            chunk = os.read(fd, min(left, 1 << 20))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        data = b"".join(chunks)
        if len(data) > max_bytes:  # it grew while read
            raise error(f"{path}: more than the {max_bytes:,} bytes a {what} may have")
        return data
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    finally:
        os.close(fd)


def check_input(path: str | Path, error: Callable[[str], BaseException],
                what: str = "file",
                max_bytes: int = MAX_TEXT_BYTES) -> int:
    """Refuse what :func:`read_input` refuses (missing, not a regular file, larger than
    ``max_bytes``) without opening the file (``stat`` does not block on a FIFO), for files a
    library reads itself; returns the size in bytes."""

    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    _refuse(st, path, error, what, max_bytes)
    return int(st.st_size)


def _refuse(st: os.stat_result, path: Path, error: Callable[[str], BaseException], what: str,
            max_bytes: int) -> None:
    """Raise ``error`` for what is not a regular file of at most ``max_bytes``."""
    import stat

    if not stat.S_ISREG(st.st_mode):
        kind = ("a folder" if stat.S_ISDIR(st.st_mode) else "a FIFO"
                if stat.S_ISFIFO(st.st_mode) else "a device" if stat.S_ISCHR(st.st_mode)
                or stat.S_ISBLK(st.st_mode) else "not a regular file")
        raise error(f"{path}: {kind}, not a {what} (cellsim reads regular files only)")
    if st.st_size > max_bytes:
        raise error(f"{path}: {st.st_size:,} bytes, more than the {max_bytes:,} a {what} may "
                    "have")


def read_input_text(path: str | Path, error: Callable[[str], BaseException],
                    what: str = "file",
                    max_bytes: int = MAX_TEXT_BYTES, errors: str = "strict") -> str:
    """:func:`read_input` decoded as UTF-8 (one line naming the file when it is not UTF-8)."""
    data = read_input(path, error, what, max_bytes)
    try:
        return data.decode("utf-8", errors=errors)
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
