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

from sim.errors import CellError

#: CoACD concavity threshold (its default: 0.05 of the mesh's bounding-box diagonal).
COACD_THRESHOLD = 0.05
#: At most this many convex pieces per mesh.
MAX_PIECES = 64
UNITS = {"mm": 1e-3, "m": 1.0}
#: A mesh larger than this is refused (it would make every model.xml huge).
MAX_FACES = 500_000
#: The largest mesh file read, bytes: an ASCII STL of MAX_FACES triangles takes about 130 MB.
MAX_MESH_BYTES = 160 * 1024 * 1024


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
        mesh = trimesh.load(str(path), force="mesh", process=True)
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

    A mesh that is already convex (its volume within 0.1 % of its hull's) is one piece; any
    other is decomposed with CoACD, cached next to the file (module docstring).
    """
    import trimesh

    verts, faces = read_mesh(path, unit, where)
    mesh = trimesh.Trimesh(verts, faces, process=False)
    try:
        hull = mesh.convex_hull
        if mesh.is_watertight and abs(mesh.volume) >= 0.999 * hull.volume:
            return [np.asarray(hull.vertices, dtype=float)]
    except Exception:  # a degenerate (flat) mesh has no hull volume: decompose anyway
        pass
    cache = _cache_path(Path(path), unit)
    if cache.is_file():
        try:
            with np.load(cache) as z:
                return [z[k] for k in sorted(z.files, key=lambda k: int(k[1:]))]
        except Exception:  # a damaged cache is recomputed (and rewritten)
            pass
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(verts, faces), threshold=COACD_THRESHOLD,
                            max_convex_hull=MAX_PIECES, seed=0)
    pieces = [np.asarray(v, dtype=float) for v, _ in parts if len(v) >= 4]
    if not pieces:
        raise CellError(f"{where}: {Path(path).name}: the convex decomposition found no solid "
                        "pieces (is the mesh closed?)")
    tmp = None
    try:  # atomically: a concurrent load never reads half a cache
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
    return pieces


def point_mesh_distance(p: NDArray[np.float64], verts: NDArray[np.float64],
                        faces: NDArray[np.int64]) -> float:
    """Distance from a point (3,) to a triangle mesh's surface, m."""
    from trimesh.triangles import closest_point

    tris = verts[faces]
    pts = np.broadcast_to(np.asarray(p, dtype=float), (len(tris), 3))
    return float(np.min(np.linalg.norm(closest_point(tris, pts) - pts, axis=1)))


__all__ = ["convex_pieces", "point_mesh_distance", "read_mesh"]
