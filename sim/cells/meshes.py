"""CAD meshes of cell objects and tools: reading STL/OBJ, convex decomposition for collisions.

MuJoCo collides a mesh geom through its convex hull, so a concave part (a bracket, a frame,
a part with a slot) would collide as if filled in. A cell file's mesh object is therefore
decomposed into convex pieces with CoACD (approximate convex decomposition, Wei et al.,
SIGGRAPH 2022; the ``coacd`` package), each piece a collision geom; the visual geom keeps the
mesh as given. The decomposition takes seconds to minutes, so it is cached next to the mesh
file as ``<file>.coacd-<hash>.npz``: the hash covers the mesh file's bytes, its unit and the
decomposition settings, so a changed file or setting makes a new cache and a stale one is never
read. A cache that cannot be written (a read-only folder) is not an error: the decomposition is
then redone on each load.

The decomposition runs under a budget: in a child process limited to
:data:`DECOMPOSITION_CPU_S` seconds of CPU and :data:`DECOMPOSITION_MEMORY` bytes of address
space, so no mesh can hang a load or exhaust the machine's memory (CoACD loops without end on
an open surface and on some concave meshes). An open mesh (an edge with one triangle: a
missing face) is not decomposed at all. In both cases the object collides as its convex hull
and a :class:`MeshHullWarning` says so, naming the file and why; the hull is not cached, so a
repaired file or a larger budget is decomposed on the next load.

Meshes are read with trimesh (binary and ASCII STL, OBJ) and passed to MuJoCo as vertex and
face arrays in metres, so a compiled cell (a run folder's ``model.xml``) carries its meshes
inline and never refers to a file outside the folder.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from sim.errors import CellError, CellsimWarning

#: CoACD concavity threshold (its default: 0.05 of the mesh's bounding-box diagonal).
COACD_THRESHOLD = 0.05
#: At most this many convex pieces per mesh.
MAX_PIECES = 64
UNITS = {"mm": 1e-3, "m": 1.0}
#: A mesh larger than this is refused (it would make every model.xml huge).
MAX_FACES = 500_000
#: The largest mesh file read, bytes: an ASCII STL of MAX_FACES triangles takes about 130 MB.
MAX_MESH_BYTES = 160 * 1024 * 1024
#: CPU time one convex decomposition may take, s (module docstring).
DECOMPOSITION_CPU_S = 120.0
#: Address space of the decomposition's child process, bytes.
DECOMPOSITION_MEMORY = 4 * 1024**3


class MeshHullWarning(CellsimWarning):
    """A mesh collides as its convex hull: it is open, or its decomposition ran past the
    budget or failed; the message names the file and says which."""


def read_mesh(path: Path, unit: str = "mm", where: str = "") -> tuple[NDArray[np.float64],
                                                                     NDArray[np.int64]]:
    """Vertices (V, 3) in metres and triangles (F, 3) of an STL or OBJ file.

    Raises:
        CellError: Missing, unreadable or empty file, or not STL/OBJ (one line with ``where``).
    """
    import trimesh

    prefix = f"{where}: " if where else ""
    path = Path(path)
    if path.suffix.lower() not in (".stl", ".obj"):
        raise CellError(f"{prefix}{path.name}: mesh files must be .stl or .obj")
    from sim.core.files import check_input

    size = check_input(path, lambda m: CellError(prefix + m), "mesh file", MAX_MESH_BYTES)
    _check_stl_count(path, size, prefix)
    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
        raw = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=float)
        if raw.ndim == 2 and not np.all(np.isfinite(raw)):
            # trimesh's processing would drop these vertices' triangles silently
            tri = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
            bad = np.flatnonzero(~np.all(np.isfinite(raw[tri]), axis=(1, 2))) if len(tri) else []
            at = f"triangle {int(bad[0]) + 1} of {len(tri)}" if len(bad) else "a vertex"
            raise CellError(f"{prefix}{path.name}: {at} has a coordinate that is not finite "
                            "(NaN or inf)")
        if hasattr(mesh, "process"):
            mesh.process()
    except CellError:
        raise
    except Exception as exc:  # trimesh raises many kinds for a damaged file
        raise CellError(f"{prefix}{path.name}: cannot read the mesh ({exc})") from None
    verts = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=float)
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    if len(faces) == 0 or len(verts) < 4 or not np.all(np.isfinite(verts)):
        raise CellError(f"{prefix}{path.name}: the mesh has no triangles (or non-finite vertices)")
    if len(faces) > MAX_FACES:
        raise CellError(f"{prefix}{path.name}: {len(faces)} triangles, more than {MAX_FACES}; "
                        "simplify the mesh")
    return verts * UNITS[unit], faces


def _check_stl_count(path: Path, size: int, prefix: str) -> None:
    """A binary STL's triangle count from its header, against :data:`MAX_FACES`, before the
    file is loaded (a binary STL is 84 + 50 n bytes; an ASCII one starts with ``solid`` and is
    bounded by its size)."""
    if path.suffix.lower() != ".stl" or size < 84:
        return
    with open(path, "rb") as fh:
        head = fh.read(84)
    n = int.from_bytes(head[80:84], "little")
    if head[:5].lower() == b"solid" and size != 84 + 50 * n:
        return  # ASCII
    if n > MAX_FACES:
        raise CellError(f"{prefix}{path.name}: {n} triangles (its header), more than "
                        f"{MAX_FACES}; simplify the mesh")
    if size < 84 + 50 * n:
        raise CellError(f"{prefix}{path.name}: a binary STL of {n} triangles (its header) "
                        f"needs {84 + 50 * n:,} bytes, it has {size:,}: a truncated file")


def _cache_path(path: Path, unit: str) -> Path:
    h = hashlib.sha256(path.read_bytes())
    h.update(f"{unit}|{COACD_THRESHOLD}|{MAX_PIECES}|coacd".encode())
    return path.with_name(f"{path.name}.coacd-{h.hexdigest()[:16]}.npz")


def convex_pieces(path: Path, unit: str = "mm", where: str = ""
                  ) -> list[NDArray[np.float64]]:
    """Convex pieces of a mesh for collisions, each a vertex array (k, 3) in metres.

    A mesh that is already convex (its volume within 0.1 % of its hull's) is one piece; an
    open one is its convex hull (with a :class:`MeshHullWarning`); any other is decomposed
    with CoACD under the budget (module docstring), cached next to the file.
    """
    import trimesh

    verts, faces = read_mesh(path, unit, where)
    mesh = trimesh.Trimesh(verts, faces, process=False)
    name = f"{where}: {Path(path).name}" if where else Path(path).name
    try:
        hull = mesh.convex_hull
        if mesh.is_watertight and abs(mesh.volume) >= 0.999 * hull.volume:
            return [np.asarray(hull.vertices, dtype=float)]
    except Exception:  # a degenerate (flat) mesh has no hull volume: decompose anyway
        pass
    open_edges = _open_edges(faces)
    if open_edges:
        return _hull(verts, name, f"the mesh is open ({open_edges} edge(s) with one triangle: "
                     "a missing face), so it has no inside to decompose")
    cache = _cache_path(Path(path), unit)
    if cache.is_file():
        try:
            with np.load(cache) as z:
                return [z[k] for k in sorted(z.files, key=lambda k: int(k[1:]))]
        except Exception:  # a damaged cache is recomputed (and rewritten)
            pass
    parts, why = decompose_bounded(verts, faces)
    if parts is None:
        return _hull(verts, name, why)
    pieces = [p for p in parts if len(p) >= 4]
    if not pieces:
        return _hull(verts, name, "the convex decomposition found no solid pieces")
    _write_cache(cache, pieces)
    return pieces


def _open_edges(faces: NDArray[np.int64]) -> int:
    """How many edges of a triangle mesh belong to one triangle only (0 for a closed mesh)."""
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int(np.count_nonzero(counts == 1))


def _hull(verts: NDArray[np.float64], name: str, why: str) -> list[NDArray[np.float64]]:
    """The fallback: the mesh's convex hull as its one collision piece, said so."""
    import warnings

    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = verts[ConvexHull(verts).vertices]
    except (QhullError, ValueError) as exc:
        raise CellError(f"{name}: the mesh has no volume (flat or degenerate: {exc})".splitlines()[0]
                        ) from None
    warnings.warn(MeshHullWarning(
        f"{name}: {why}; it collides as its convex hull (a concave part is filled in: close "
        "the mesh, simplify it, or split it into several mesh objects)"), stacklevel=3)
    return [np.asarray(hull, dtype=float)]


#: The child process of :func:`decompose_bounded`: reads the mesh, runs CoACD, writes pieces.
_CHILD = """
import signal, sys, numpy as np
signal.setitimer(signal.ITIMER_PROF, float(sys.argv[3]))  # SIGPROF ends the child at the budget
import coacd
with np.load(sys.argv[1]) as z:
    v, f, thr, n = z["v"], z["f"], float(z["threshold"]), int(z["pieces"])
coacd.set_log_level("error")
parts = coacd.run_coacd(coacd.Mesh(v, f), threshold=thr, max_convex_hull=n, seed=0)
np.savez(sys.argv[2], **{f"p{i}": np.asarray(p[0], dtype=float) for i, p in enumerate(parts)})
"""


def decompose_bounded(verts: NDArray[np.float64], faces: NDArray[np.int64],
                      cpu_s: float | None = None, memory: int | None = None
                      ) -> tuple[list[NDArray[np.float64]] | None, str]:
    """CoACD's convex pieces of a mesh, computed in a child process limited to ``cpu_s``
    seconds of CPU and ``memory`` bytes of address space (defaults: the module's budget).

    Returns:
        ``(pieces, "")``, or ``(None, why)`` when the decomposition ran past the budget or
        failed.
    """
    import resource
    import signal
    import subprocess
    import sys

    cpu = float(DECOMPOSITION_CPU_S if cpu_s is None else cpu_s)
    mem = int(DECOMPOSITION_MEMORY if memory is None else memory)

    def limits() -> None:  # in the child, before it runs anything (a backstop of the timer)
        whole = int(np.ceil(cpu)) + 1
        resource.setrlimit(resource.RLIMIT_CPU, (whole, whole + 1))
        resource.setrlimit(resource.RLIMIT_AS, (mem, mem))

    with tempfile.TemporaryDirectory(prefix="cellsim-coacd-") as tmp:
        src, dst = Path(tmp) / "mesh.npz", Path(tmp) / "pieces.npz"
        np.savez(src, v=verts, f=faces, threshold=COACD_THRESHOLD, pieces=MAX_PIECES)
        try:
            # the wall-clock limit is a last resort (a child stopped by a debugger); the CPU
            # limit is the budget
            proc = subprocess.run([sys.executable, "-c", _CHILD, str(src), str(dst), repr(cpu)],
                                  preexec_fn=limits, capture_output=True, check=False,
                                  timeout=60.0 + 20.0 * cpu)
        except subprocess.TimeoutExpired:
            return None, f"the convex decomposition did not finish ({cpu:g} s of CPU budget)"
        if proc.returncode != 0 or not dst.is_file():
            if -proc.returncode in (signal.SIGPROF, signal.SIGXCPU, signal.SIGKILL):
                return None, (f"the convex decomposition ran past its budget of {cpu:g} s of "
                              "CPU")
            if b"MemoryError" in proc.stderr or b"bad_alloc" in proc.stderr:
                return None, (f"the convex decomposition ran past its memory budget of "
                              f"{mem / 1024**3:g} GiB")
            last = proc.stderr.decode(errors="replace").strip().splitlines()
            return None, ("the convex decomposition failed"
                          + (f" ({last[-1]})" if last else f" (exit {proc.returncode})"))
        with np.load(dst) as z:
            return [z[k] for k in sorted(z.files, key=lambda k: int(k[1:]))], ""


def _write_cache(cache: Path, pieces: list[NDArray[np.float64]]) -> None:
    """Writes the pieces next to the mesh atomically (a concurrent load never reads half a
    cache); a folder that cannot be written is no error."""
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=cache.parent, prefix=f".{cache.name}.", suffix=".tmp")
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, **{f"p{i}": p for i, p in enumerate(pieces)})
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # as any file the user writes (mkstemp makes 0600)
        os.replace(tmp, cache)
        tmp = None
    except OSError:
        pass
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass


def point_mesh_distance(p: NDArray[np.float64], verts: NDArray[np.float64],
                        faces: NDArray[np.int64]) -> float:
    """Distance from a point (3,) to a triangle mesh's surface, m."""
    from trimesh.triangles import closest_point

    tris = verts[faces]
    pts = np.broadcast_to(np.asarray(p, dtype=float), (len(tris), 3))
    return float(np.min(np.linalg.norm(closest_point(tris, pts) - pts, axis=1)))


__all__ = ["MeshHullWarning", "convex_pieces", "decompose_bounded", "point_mesh_distance",
           "read_mesh"]
