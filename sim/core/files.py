"""Writing files so that nothing half-written looks complete, and errors name the file.

``write_atomic`` writes through a temporary file in the same folder and ``os.replace``: a
reader sees the old file or the new one, never a part (a full disk leaves the old file). Both
helpers give an operating-system error the path being written when it has none (a write on an
open file, numpy's and zipfile's writers: "No space left on device" alone names nothing).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
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
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path
