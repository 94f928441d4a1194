"""A cell file's objects as solids: their poses, bounding radii, signed distances (for the
load-time checks) and, for meshes, the visual mesh and its convex collision pieces."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from sim.cells import meshes
from sim.cells.cellfile.schema import PART_MASS_KG, ObjectBlock
from sim.core.rotations import euler_zyx_to_matrix
from sim.errors import CellError


def object_pose(pos_mm: list[float], euler_deg: list[float]) -> NDArray[np.float64]:
    T = np.eye(4)
    T[:3, :3] = euler_zyx_to_matrix(*np.deg2rad(np.asarray(euler_deg, dtype=float)))
    T[:3, 3] = np.asarray(pos_mm, dtype=float) * 1e-3
    return T


@dataclass
class Solid:
    """One cell object's geometry in its own frame, for the load-time checks and the build.

    Attributes:
        block: The file's entry. index: Its index in ``objects``.
        pose: World pose, (4, 4).
        pieces: Mesh objects: convex collision pieces (vertex arrays, m, object frame).
        verts, faces: Mesh objects: the visual mesh (m, object frame).
        radius: Bounding radius about the object's origin, m.
    """

    block: ObjectBlock
    index: int
    pose: NDArray[np.float64]
    pieces: list[NDArray[np.float64]] = field(default_factory=list)
    verts: NDArray[np.float64] | None = None
    faces: NDArray[np.int64] | None = None
    radius: float = 0.0
    _halfspaces: list[NDArray[np.float64]] = field(default_factory=list)

    def distance(self, p_world: NDArray[np.float64]) -> float:
        """Signed distance of a world point from the object (negative inside), m; for a mesh
        the distance to its surface, negative inside one of its convex pieces."""
        T = self.pose
        p = T[:3, :3].T @ (np.asarray(p_world, dtype=float) - T[:3, 3])
        b = self.block
        if b.shape == "box":
            h = np.asarray(b.size_mm) * 0.5e-3
            q = np.abs(p) - h
            return float(np.linalg.norm(np.maximum(q, 0.0)) + min(q.max(), 0.0))
        if b.shape == "cylinder":
            d = np.array([np.hypot(p[0], p[1]) - b.radius_mm * 1e-3,
                          abs(p[2]) - b.length_mm * 0.5e-3])
            return float(min(d.max(), 0.0) + np.linalg.norm(np.maximum(d, 0.0)))
        if b.shape == "sphere":
            return float(np.linalg.norm(p) - b.radius_mm * 1e-3)
        if b.shape == "ring":
            return ring_distance(p, b)
        assert self.verts is not None and self.faces is not None
        surf = meshes.point_mesh_distance(p, self.verts, self.faces)
        inside = any(np.all(H[:, :3] @ p + H[:, 3] <= 1e-9) for H in self._halfspaces)
        return -surf if inside else surf


def _volume(points: NDArray[np.float64]) -> float:
    from scipy.spatial import ConvexHull, QhullError

    try:
        return float(ConvexHull(points).volume)
    except (QhullError, ValueError):
        return 0.0


def ring_distance(p: NDArray[np.float64], b: ObjectBlock) -> float:
    """Signed distance from a ring sector (annulus r_in..r_out, |z| <= L/2, angles a0..a1 from
    the object's x axis), m: exact for the cut faces too."""
    r_in, r_out = (b.inner_radius_mm or 0.0) * 1e-3, b.radius_mm * 1e-3
    half = b.length_mm * 0.5e-3
    a0, a1 = np.deg2rad(b.arc_deg) if b.arc_deg is not None else (0.0, 2 * np.pi)
    sweep = a1 - a0
    rho = float(np.hypot(p[0], p[1]))
    phi = float(np.mod(np.arctan2(p[1], p[0]) - a0, 2 * np.pi))
    dz = abs(p[2]) - half
    inside_angle = sweep >= 2 * np.pi - 1e-12 or phi <= sweep
    if inside_angle:
        d = [max(r_in - rho, rho - r_out), dz]
        if sweep < 2 * np.pi - 1e-12:  # distance to the nearer cut face (a half-plane)
            to_face = min(rho * np.sin(min(phi, np.pi / 2)),
                          rho * np.sin(min(sweep - phi, np.pi / 2)))
            d.append(-to_face)
        dd = np.array(d)
        return float(min(dd.max(), 0.0) + np.linalg.norm(np.maximum(dd, 0.0)))
    # outside the angles: the distance to the nearer cut face (a rectangle r_in..r_out x z)
    best = np.inf
    for a in (a0, a1):
        u = np.array([np.cos(a), np.sin(a)])
        t = float(np.clip(p[:2] @ u, r_in, r_out))
        d2 = float(np.linalg.norm(p[:2] - t * u))
        best = min(best, float(np.hypot(d2, max(dz, 0.0))))
    return best


def geom_names(b: ObjectBlock, pieces: int) -> list[str]:
    """The names of the geoms an object becomes in the model."""
    if b.shape == "ring":
        return [f"{b.name}{k}" for k in range(b.segments or 72)]
    if b.shape == "mesh":
        return [f"{b.name}_visual", *(f"{b.name}_c{k}" for k in range(pieces))]
    return [b.name]


#: Convex pieces smaller than this are left out of a mesh's collision geoms, m^3 (1 mm^3:
#: MuJoCo's compiler refuses a mesh whose volume is too small to compute its inertia).
MIN_PIECE_VOLUME = 1e-9


def read_solid(block: ObjectBlock, index: int, base: Path, where: str) -> Solid:
    key = f"{where}: objects[{index}]"
    shape = block.shape
    need = {"box": ("size_mm",), "cylinder": ("radius_mm", "length_mm"),
            "sphere": ("radius_mm",), "mesh": ("file",),
            "ring": ("radius_mm", "inner_radius_mm", "length_mm")}[shape]
    optional = {"ring": ("arc_deg", "segments")}.get(shape, ())
    for k in need:
        if getattr(block, k) is None:
            raise CellError(f"{key}.{k}: required for a {shape}")
    extra = [k for k in ("size_mm", "radius_mm", "inner_radius_mm", "length_mm", "file",
                         "arc_deg", "segments")
             if k not in need and k not in optional and getattr(block, k) is not None]
    if extra:
        raise CellError(f"{key}.{extra[0]}: not used with shape = {shape!r} (it takes "
                        f"{', '.join(need)})")
    if shape == "ring":
        if block.inner_radius_mm >= block.radius_mm:
            raise CellError(f"{key}.inner_radius_mm: must be less than radius_mm")
        if block.arc_deg is not None and not 0 < block.arc_deg[1] - block.arc_deg[0] <= 360:
            raise CellError(f"{key}.arc_deg: [from, to] with 0 < to - from <= 360")
    if block.size_mm is not None and min(block.size_mm) <= 0:
        raise CellError(f"{key}.size_mm: full extents must be positive (mm)")
    if block.role == "part" and shape == "ring":
        raise CellError(f"{key}.shape: a part cannot be a ring (a part is one free body: a box, "
                        "cylinder, sphere or mesh)")
    if block.role == "part" and block.mass_kg is None:
        raise CellError(f"{key}.mass_kg: required for a part (a free body)")
    if block.role == "part" and block.mass_kg > PART_MASS_KG.hi:
        raise CellError(f"{key}.mass_kg: must be between {PART_MASS_KG.lo:g} and "
                        f"{PART_MASS_KG.hi:g} kg (a part's mass), got {block.mass_kg!r}")
    if block.role != "part" and block.mass_kg is not None and block.on is None:
        raise CellError(f"{key}.mass_kg: only parts and objects on a mechanism have a mass "
                        f"(role = \"part\", or on = ...); {block.role}s are static")
    s = Solid(block, index, object_pose(block.pos_mm, block.euler_zyx_deg))
    if shape == "box":
        s.radius = float(np.linalg.norm(block.size_mm)) * 0.5e-3
    elif shape == "cylinder":
        s.radius = float(np.hypot(block.radius_mm, block.length_mm / 2)) * 1e-3
    elif shape == "sphere":
        s.radius = float(block.radius_mm) * 1e-3
    elif shape == "ring":
        s.radius = float(np.hypot(block.radius_mm, block.length_mm / 2)) * 1e-3
    else:
        from scipy.spatial import ConvexHull

        path = (base / str(block.file)).resolve()
        s.verts, s.faces = meshes.read_mesh(path, block.mesh_unit, where=f"{key}.file")
        pieces = meshes.convex_pieces(path, block.mesh_unit, where=f"{key}.file")
        s.pieces = [pc for pc in pieces if _volume(pc) >= MIN_PIECE_VOLUME]
        if not s.pieces:
            raise CellError(f"{key}.file: {path.name}: the mesh encloses less than 1 mm^3 "
                            "(check mesh_unit: the file's coordinates are read as "
                            f"{block.mesh_unit})")
        s._halfspaces = [ConvexHull(pc).equations for pc in s.pieces]
        s.radius = float(np.max(np.linalg.norm(s.verts, axis=1)))
    return s


__all__ = ["MIN_PIECE_VOLUME", "Solid", "geom_names", "object_pose", "read_solid", "ring_distance"]
