"""Cells with external axes for the acceptance tests of issue 28, written from numbers, and the
independent geometry and mass oracles that judge their runs.

Writers: :func:`positioner_cell` (the LR Mate 200iC/5L with the MIG torch and a MotoPos D500
placed in front of it carrying generated workpieces), :func:`track_cell` (the robot standing on
the 4 m floor track beside a long workpiece) and :func:`toml_text` (a dict as TOML). Each cell
is written as a user writes it and read back by cellsim's own loader.

Oracles, from first principles and the files' own numbers (nothing from ``sim``):

* :func:`mechanism_file` / :func:`chain_poses`: a mechanism file read with ``tomllib`` and its
  forward kinematics (docs/mechanism-format.md: each link frame its parent's translated by
  ``pos_mm`` and turned about ``axis`` by Rodrigues' formula; the mount
  ``Trans(pos) Rz Ry Rx``), for any stack of axis values;
* :class:`Solid`: a box's or cylinder's mass, centre of mass and inertia (solid steel of
  7850 kg/m^3 unless a mass is given; ``m (b^2 + c^2) / 12`` ... for a box,
  ``m (3 r^2 + L^2) / 12`` and ``m r^2 / 2`` for a cylinder along its z), and
  :func:`combined` for several solids about their common centre (parallel axes).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from support.seam_oracle import rot_zyx
from support.toml_values import toml_value

Array = NDArray[np.float64]

ROOT = Path(__file__).resolve().parents[2]
D500_FILE = ROOT / "models" / "positioners" / "motopos_d500" / "mechanism.toml"
TRACK_FILE = ROOT / "models" / "tracks" / "floor_track_4m" / "mechanism.toml"
ROBOT_XML = ROOT / "models" / "fanuc_lrmate200ic" / "lrmate200ic5l.xml"
TORCH_FILE = ROOT / "models" / "tools" / "mig_torch.toml"
#: Density of a carried object without ``mass_kg`` (solid steel), kg/m^3.
STEEL = 7850.0
#: The LR Mate 200iC/5L's home, deg.
HOME_DEG = (0.0, 0.0, 0.0, 0.0, -90.0, 0.0)


# ------------------------------------------------------------------------------ TOML
_value = toml_value  # the shared writer (toml_values.py)


def toml_text(doc: Mapping[str, Any]) -> str:
    """``doc`` as TOML: plain keys first (a plain mapping as an inline table), then a
    ``[key]`` table for each value that is a :class:`Table`, then ``[[key]]`` arrays of tables
    for lists of mappings."""
    lines = [f"{k} = {_value(v)}" for k, v in doc.items()
             if not isinstance(v, Table) and not _tables(v)]
    for k, v in doc.items():
        if isinstance(v, Table):
            lines += ["", f"[{k}]", *(f"{kk} = {_value(x)}" for kk, x in v.items())]
    for k, v in doc.items():
        if _tables(v):
            for item in v:
                lines += ["", f"[[{k}]]", *(f"{kk} = {_value(x)}" for kk, x in item.items())]
    return "\n".join(lines) + "\n"


class Table(dict):
    """A mapping written as a ``[table]`` by :func:`toml_text` (a plain dict is inline)."""


def _tables(v: Any) -> bool:
    return (isinstance(v, list) and bool(v) and all(isinstance(x, Mapping) for x in v)
            and not isinstance(v, Table))


# ------------------------------------------------------------------------------ kinematics
def mechanism_file(path: Path) -> dict[str, Any]:
    """A mechanism file read with ``tomllib`` (its own numbers, mm and deg)."""
    return tomllib.loads(path.read_text())


def rodrigues(axis: Sequence[float], angle: Array) -> Array:
    """Rotations by ``angle`` (N,) rad about the unit direction of ``axis``: ``cos I + sin [k]x
    + (1 - cos) k k^T``, (N, 3, 3)."""
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    c = np.cos(np.asarray(angle, dtype=float))[:, None, None]
    s = np.sin(np.asarray(angle, dtype=float))[:, None, None]
    return c * np.eye(3) + s * K + (1.0 - c) * np.outer(k, k)


def pose(pos_mm: Sequence[float], euler_zyx_deg: Sequence[float] = (0.0, 0.0, 0.0)) -> Array:
    """``Trans(pos_mm) Rz Ry Rx`` as a 4x4 in metres."""
    T = np.eye(4)
    T[:3, :3] = rot_zyx(tuple(euler_zyx_deg))
    T[:3, 3] = np.asarray(pos_mm, dtype=float) * 1e-3
    return T


def chain_poses(mech: Mapping[str, Any], q: Array) -> tuple[list[Array], Array]:
    """The link frames and the mount in the mechanism's base frame for axis values ``q``
    (N, n) (rad, m): ``T_i = T_(i-1) Trans(pos_i) R(axis_i, q_i)`` (revolute) or
    ``T_(i-1) Trans(pos_i + q_i axis_i)`` (prismatic); mount ``T_last Trans Rz Ry Rx``.
    Returns ([(N, 4, 4) per axis], (N, 4, 4))."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    N = len(q)
    T = np.broadcast_to(np.eye(4), (N, 4, 4)).copy()
    links = []
    for i, ax in enumerate(mech["axes"]):
        step = np.broadcast_to(np.eye(4), (N, 4, 4)).copy()
        step[:, :3, 3] = np.asarray(ax.get("pos_mm", (0, 0, 0)), dtype=float) * 1e-3
        u = np.asarray(ax["axis"], dtype=float)
        u = u / np.linalg.norm(u)
        if ax["kind"] == "revolute":
            step[:, :3, :3] = rodrigues(u, q[:, i])
        else:
            step[:, :3, 3] += q[:, i, None] * u
        T = T @ step
        links.append(T)
    m = mech.get("mount", {})
    return links, T @ pose(m.get("pos_mm", (0, 0, 0)), m.get("euler_zyx_deg", (0, 0, 0)))


def inverse(T: Array) -> Array:
    """Inverse of rigid transforms (..., 4, 4)."""
    out = np.zeros_like(T)
    R = np.swapaxes(T[..., :3, :3], -1, -2)
    out[..., :3, :3] = R
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", R, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


# ------------------------------------------------------------------------------ masses
@dataclass(frozen=True)
class Solid:
    """A box (``size_mm``) or cylinder (``radius_mm``, ``length_mm`` along its z) at
    ``pos_mm`` / ``euler_zyx_deg`` in its parent frame (the mount), of ``mass_kg`` or solid
    steel."""

    shape: str
    pos_mm: tuple[float, float, float]
    euler_zyx_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    size_mm: tuple[float, float, float] | None = None
    radius_mm: float | None = None
    length_mm: float | None = None
    mass_kg: float | None = None

    @property
    def volume(self) -> float:
        if self.shape == "box":
            assert self.size_mm is not None
            return float(np.prod(np.asarray(self.size_mm) * 1e-3))
        assert self.radius_mm is not None and self.length_mm is not None
        return math.pi * (self.radius_mm * 1e-3) ** 2 * self.length_mm * 1e-3

    @property
    def mass(self) -> float:
        return self.volume * STEEL if self.mass_kg is None else float(self.mass_kg)

    def inertia_own(self) -> Array:
        """Principal inertia at the centre, along the solid's own axes, kg m^2 (3, 3)."""
        m = self.mass
        if self.shape == "box":
            a, b, c = np.asarray(self.size_mm) * 1e-3
            return np.diag([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)]) / 12
        r, L = self.radius_mm * 1e-3, self.length_mm * 1e-3
        return np.diag([m * (3 * r * r + L * L) / 12, m * (3 * r * r + L * L) / 12, m * r * r / 2])

    def inertia(self) -> Array:
        """Inertia at the centre in the parent frame (3, 3)."""
        R = rot_zyx(self.euler_zyx_deg)
        return R @ self.inertia_own() @ R.T

    def fields(self) -> dict[str, Any]:
        """The cell file's keys of the solid's shape, pose and mass."""
        out: dict[str, Any] = {"shape": self.shape}
        if self.shape == "box":
            out["size_mm"] = list(self.size_mm or ())
        else:
            out["radius_mm"] = self.radius_mm
            out["length_mm"] = self.length_mm
        out["pos_mm"] = list(self.pos_mm)
        out["euler_zyx_deg"] = list(self.euler_zyx_deg)
        if self.mass_kg is not None:
            out["mass_kg"] = self.mass_kg
        return out


def combined(solids: Sequence[Solid], scale_mass: float = 1.0) -> tuple[float, Array, Array]:
    """Mass, centre of mass and inertia at it (parent frame) of rigidly joined solids (every
    mass times ``scale_mass``: a planted fault): ``I = sum I_k + m_k (|d|^2 1 - d d^T)``."""
    ms = np.array([s.mass for s in solids]) * scale_mass
    cs = np.array([np.asarray(s.pos_mm, dtype=float) * 1e-3 for s in solids])
    m = float(ms.sum())
    c = (ms[:, None] * cs).sum(axis=0) / m
    inertia = np.zeros((3, 3))
    for mk, ck, s in zip(ms, cs, solids, strict=True):
        d = ck - c
        inertia += s.inertia() * scale_mass + mk * ((d @ d) * np.eye(3) - np.outer(d, d))
    return m, c, inertia


# ------------------------------------------------------------------------------ cells
def positioner_cell(pos_mm: Sequence[float], turn: float | Sequence[float],
                    objects: Sequence[Mapping[str, Any]],
                    seams: Sequence[Mapping[str, Any]] = (), *, name: str = "positioner",
                    model: str = "motopos_d500", home: Mapping[str, float] | None = None
                    ) -> str:
    """A cell file: the LR Mate 200iC/5L at the origin with the MIG torch, a D500 (or
    ``model``) called ``name`` at ``pos_mm`` turned ``turn`` (a yaw about z, or Z-Y-X angles;
    deg), the ``objects`` (their ``on`` given by the caller) and ``seams``."""
    euler = [float(turn), 0.0, 0.0] if isinstance(turn, (int, float)) else list(turn)
    mech: dict[str, Any] = {"name": name, "model": model, "pos_mm": list(pos_mm),
                            "euler_zyx_deg": euler}
    if home:
        mech["home"] = dict(home)
    doc: dict[str, Any] = {
        "name": "axes_cell", "description": "generated cell with a positioner",
        "tool": "mig_torch", "robot": Table(model="lrmate200ic5l", base_pos_mm=[0, 0, 0]),
        "mechanisms": [mech], "objects": list(objects), "seams": list(seams)}
    return toml_text(doc)


def track_cell(track_pos_mm: Sequence[float], home_travel_mm: float,
               objects: Sequence[Mapping[str, Any]], seams: Sequence[Mapping[str, Any]] = ()
               ) -> str:
    """A cell file: the LR Mate 200iC/5L with the MIG torch on the 4 m floor track's carriage
    (track ``track`` at ``track_pos_mm``, home ``home_travel_mm``), the ``objects`` and
    ``seams``."""
    doc: dict[str, Any] = {
        "name": "track_cell", "description": "generated cell with a robot on a track",
        "tool": "mig_torch",
        "robot": Table(model="lrmate200ic5l", on="track", base_pos_mm=[0, 0, 0]),
        "mechanisms": [{"name": "track", "model": "floor_track_4m",
                        "pos_mm": list(track_pos_mm), "home": {"travel_mm": home_travel_mm}}],
        "objects": list(objects), "seams": list(seams)}
    return toml_text(doc)


def robot_mass_kg() -> float:
    """What a track carries besides its carriage: the LR Mate 200iC/5L's bodies (every
    ``inertial`` of its MJCF file, the base included: it stands on the carriage) and the MIG
    torch (the sum of its shapes' ``mass_kg`` where every shape gives one, else its
    ``mass_kg``)."""
    import xml.etree.ElementTree as ET

    robot = sum(float(e.get("mass")) for e in ET.parse(ROBOT_XML).getroot().iter("inertial"))
    torch = tomllib.loads(TORCH_FILE.read_text())
    shapes = [s.get("mass_kg") for s in torch.get("shapes", [])]
    tool = sum(shapes) if shapes and None not in shapes else float(torch["mass_kg"])
    return robot + tool


# ------------------------------------------------------------------------------ weld judge
def quat_matrix(q: Array) -> Array:
    """Rotation matrices of unit quaternions ``(w, x, y, z)`` (N, 4) -> (N, 3, 3)."""
    q = np.asarray(q, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], -2)


def part_in_world(mech: Mapping[str, Any], base: Array, part_local: Array, q: Array) -> Array:
    """A mounted object's frame in the world at axis values ``q`` (N, n): ``base chain(q)
    mount local``, (N, 4, 4)."""
    return base @ chain_poses(mech, q)[1] @ part_local


@dataclass
class PartFrameWeld:
    """A weld seen from the part: tool points and torch axes in the part's frame, and the weld
    normal (``sin(w) n + cos(w) e``: the commanded torch axis at zero travel angle, reversed)
    in the world at each sample."""

    frames: Any
    normal_from_vertical_deg: Array
    verdict: Any


def judge_part_frame_weld(seam: Any, t: Array, tcp_pos: Array, tcp_quat: Array, T_part: Array,
                          t0: float, t1: float, speed_m_s: float, *, pos_tol_m: float = 0.1e-3,
                          angle_tol_deg: float = 0.5, speed_tol: float = 0.01
                          ) -> PartFrameWeld:
    """Judge a weld on a moving part in the part's frame (issue 28): the recorded tool points
    and torch axes (the tcp's z) carried into the part frame ``T_part`` (N, 4, 4; world from
    part at each sample), then :func:`support.seam_oracle.judge_weld` against ``seam`` (a
    :class:`~support.seam_oracle.SeamGeom` in the part frame) with issue 28's tolerances, and
    the angle of the weld normal from the world's vertical over ``[t0, t1]``."""
    from support import seam_oracle as so

    Tinv = inverse(T_part)
    p = np.einsum("nij,nj->ni", Tinv[:, :3, :3], tcp_pos) + Tinv[:, :3, 3]
    a = np.einsum("nij,nj->ni", Tinv[:, :3, :3], quat_matrix(tcp_quat)[:, :, 2])
    fr = so.Frames(np.asarray(t, dtype=float), p, a)
    verdict = so.judge_weld(seam, fr, t0, t1, speed_m_s, None, pos_tol=pos_tol_m,
                            angle_tol=angle_tol_deg, speed_tol=speed_tol, end_tol=pos_tol_m)
    sel = (fr.t >= t0 - 1e-9) & (fr.t <= t1 + 1e-9)
    s = seam.progress(p[sel] + seam.standoff * so.unit(a[sel]))
    _, n, e = seam.frame(s)
    w = math.radians(seam.work_deg)
    up_local = math.sin(w) * n + math.cos(w) * e
    up = np.einsum("nij,nj->ni", T_part[sel, :3, :3], up_local)
    ang = np.degrees(np.arccos(np.clip(up[:, 2] / np.linalg.norm(up, axis=1), -1.0, 1.0)))
    return PartFrameWeld(fr, ang, verdict)


__all__ = ["D500_FILE", "HOME_DEG", "ROBOT_XML", "STEEL", "TORCH_FILE", "TRACK_FILE",
           "PartFrameWeld", "Solid", "Table", "chain_poses", "combined", "inverse",
           "judge_part_frame_weld", "mechanism_file", "part_in_world", "pose",
           "positioner_cell", "quat_matrix", "robot_mass_kg", "rodrigues", "toml_text",
           "track_cell"]
