"""Serial chains of revolute joints: from a DH table or a URDF, forward kinematics, Jacobian.

A :class:`Chain` is the kinematics every other description reduces to: for each joint the
constant transform from the previous joint's frame (URDF ``<origin>``) and its unit axis in its
own frame, then a constant transform to the flange. Its forward kinematics is the plain product
``T = prod_i (origin_i Rot(axis_i, q_i)) @ flange`` (the URDF semantics), which this module
also builds from DH tables (standard ``dh``: ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``; modified
``mdh``, Craig: ``Rx(alpha) Tx(a) Rz(theta) Tz(d)``; joint value ``q = theta - theta_offset``)
and from URDF files (the chain from the root link to ``tool0`` when present, else to the last
link; fixed joints fold into the next origin).

Lengths in metres, angles in radians.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError


def rot_axis(axis: NDArray[np.float64], angle: float) -> NDArray[np.float64]:
    """Rotation matrix (3, 3) by ``angle`` (rad) about the unit ``axis`` (Rodrigues)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    C = 1.0 - c
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def rpy_matrix(r: float, p: float, y: float) -> NDArray[np.float64]:
    """URDF ``rpy``: ``Rz(y) Ry(p) Rx(r)``."""
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y),
                              math.sin(y))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _T(R: NDArray[np.float64] | None = None, p: ArrayLike = (0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


@dataclass(frozen=True)
class Chain:
    """A serial chain of revolute joints (module docstring).

    Attributes:
        name: For messages.
        origins: Transform from the previous joint's frame (the base for the first) to each
            joint's frame at q = 0, (n, 4, 4).
        axes: Each joint's unit axis in its own frame, (n, 3).
        flange: Transform from the last joint's frame to the flange, (4, 4).
        lower, upper: Joint limits, rad, (n,) (+-inf where none).
        joint_names: Joint names, in order.
        max_speed: Joint speed limits, rad/s, (n,) (inf where none given).
    """

    name: str
    origins: NDArray[np.float64]
    axes: NDArray[np.float64]
    flange: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    joint_names: tuple[str, ...]
    max_speed: NDArray[np.float64] | None = None

    @property
    def n(self) -> int:
        return len(self.axes)

    def frames(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                            NDArray[np.float64]]:
        """Joint axes (n, 3) and anchors (n, 3) in the base frame, and the flange pose (4, 4),
        at joint values ``q`` (rad, (n,))."""
        q = np.asarray(q, dtype=float)
        T = np.eye(4)
        axes = np.empty((self.n, 3))
        points = np.empty((self.n, 3))
        for i in range(self.n):
            T = T @ self.origins[i]
            axes[i] = T[:3, :3] @ self.axes[i]
            points[i] = T[:3, 3]
            T = T @ _T(rot_axis(self.axes[i], float(q[i])))
        return axes, points, T @ self.flange

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Flange pose in the base frame, (4, 4)."""
        return self.frames(q)[2]

    def jacobian(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Geometric Jacobian (6, n) (linear rows first, base frame) and the flange pose."""
        axes, points, T = self.frames(q)
        J = np.empty((6, self.n))
        J[:3] = np.cross(axes, T[:3, 3] - points).T
        J[3:] = axes.T
        return J, T


# ---------------------------------------------------------------------------- DH tables
def chain_from_dh(rows: ArrayLike, convention: str = "dh", *, name: str = "arm",
                  lower: ArrayLike | None = None, upper: ArrayLike | None = None,
                  flange: ArrayLike | None = None) -> Chain:
    """A chain from DH rows ``[a (m), alpha (rad), d (m), theta_offset (rad)]``.

    Args:
        rows: (n, 4).
        convention: ``"dh"`` (standard: joint i turns about z_{i-1}) or ``"mdh"`` (modified,
            Craig: joint i turns about z_i, the row holding a_{i-1}, alpha_{i-1}).
        lower, upper: Joint limits, rad.
        flange: Extra transform after the last frame, (4, 4).

    Raises:
        KinematicsError: A row of the wrong length, or an unknown convention.
    """
    R = [list(r) for r in np.asarray(rows, dtype=object)] if len(rows) else []
    for i, r in enumerate(R):
        if len(r) != 4:
            raise KinematicsError(f"{name}: dh[{i}]: {len(r)} values; a row is "
                                  "[a_mm, alpha_deg, d_mm, theta_offset_deg]")
    rows_a = np.asarray(R, dtype=float).reshape(-1, 4)
    if convention not in ("dh", "mdh"):
        raise KinematicsError(f"{name}: convention must be 'dh' or 'mdh', got {convention!r}")
    # the table rows of sim.robots.builder (the MJCF chain builder) give each row's constant
    # transform; the joint turns about the z axis before (dh) or after (mdh) it
    from sim.robots.builder import DHRow, MDHRow

    n = len(rows_a)
    z = np.array([0.0, 0.0, 1.0])
    if convention == "dh":
        fixed = [DHRow(theta=off, d=d, a=a, alpha=al).fixed() for a, al, d, off in rows_a]
        origins = np.array([np.eye(4), *fixed[:-1]]).reshape(n, 4, 4)
        end = fixed[-1] if n else np.eye(4)
    else:
        origins = np.array([MDHRow(alpha=al, d=a, theta=off, r=d).fixed()
                            for a, al, d, off in rows_a]).reshape(n, 4, 4)
        end = np.eye(4)
    fl = np.eye(4) if flange is None else np.asarray(flange, dtype=float)
    lo = np.full(n, -np.inf) if lower is None else np.asarray(lower, dtype=float)
    hi = np.full(n, np.inf) if upper is None else np.asarray(upper, dtype=float)
    return Chain(name, origins, np.tile(z, (n, 1)), end @ fl, lo, hi,
                 tuple(f"j{i + 1}" for i in range(n)))


# ---------------------------------------------------------------------------- URDF
def chain_from_urdf(path: str | Path, tip: str | None = None) -> Chain:
    """The serial chain of a URDF file from its root link to ``tip`` (default: ``tool0`` when
    the file has it, else the last link of the chain).

    Fixed joints fold into the next joint's origin (or the flange); MuJoCo's compiler would fuse
    them, which is why the chain is read here.

    Raises:
        KinematicsError: Missing or malformed file, no single chain, a prismatic, continuous,
            planar or floating joint on the chain, limits with lower > upper (one line naming the
            file and the joint).
    """
    path = Path(path)
    if not path.is_file():
        raise KinematicsError(f"{path}: no such URDF file")
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as exc:
        raise KinematicsError(f"{path}: not a readable URDF ({exc})") from None
    if root.tag != "robot":
        raise KinematicsError(f"{path}: not a URDF (the root element is <{root.tag}>, not <robot>)")
    links = [ln.get("name") for ln in root.findall("link")]
    joints = {}
    child_of = {}
    for j in root.findall("joint"):
        name = j.get("name", "?")
        parent, child = j.find("parent"), j.find("child")
        if parent is None or child is None:
            raise KinematicsError(f"{path}: joint {name!r}: needs <parent> and <child>")
        joints[name] = j
        child_of[child.get("link")] = (name, parent.get("link"))
    roots = [ln for ln in links if ln not in child_of]
    if len(roots) != 1:
        raise KinematicsError(f"{path}: expected one root link, found {roots}")
    if tip is None:
        tip = "tool0" if "tool0" in links else None
    if tip is None:  # the last link of the single chain
        parents = {p for _, p in child_of.values()}
        leaves = [ln for ln in links if ln not in parents]
        if len(leaves) != 1:
            raise KinematicsError(f"{path}: the links branch ({', '.join(leaves)} are ends); "
                                  "name the tip link")
        tip = leaves[0]
    if tip not in links:
        raise KinematicsError(f"{path}: no link named {tip!r}")
    path_joints = []
    link = tip
    while link in child_of:
        jname, link = child_of[link]
        path_joints.append(jname)
    path_joints.reverse()

    def num(text: str | None, n: int, what: str) -> list[float]:
        vals = (text or " ".join(["0"] * n)).split()
        try:
            out = [float(v) for v in vals]
        except ValueError:
            raise KinematicsError(f"{path}: {what}: not numbers: {text!r}") from None
        if len(out) != n or not all(math.isfinite(v) for v in out):
            raise KinematicsError(f"{path}: {what}: needs {n} finite numbers, got {text!r}")
        return out

    origins, axes, names, lo, hi, vel = [], [], [], [], [], []
    pending = np.eye(4)
    for jname in path_joints:
        j = joints[jname]
        o = j.find("origin")
        xyz = num(None if o is None else o.get("xyz"), 3, f"joint {jname!r} origin xyz")
        rpy = num(None if o is None else o.get("rpy"), 3, f"joint {jname!r} origin rpy")
        T = pending @ _T(rpy_matrix(*rpy), xyz)
        jtype = j.get("type")
        if jtype == "fixed":
            pending = T
            continue
        if jtype != "revolute":
            raise KinematicsError(f"{path}: joint {jname!r}: type {jtype!r} is not supported "
                                  "(revolute and fixed joints only)")
        a = j.find("axis")
        axis = np.array(num("1 0 0" if a is None else a.get("xyz"), 3,
                            f"joint {jname!r} axis"))
        if np.linalg.norm(axis) < 1e-12:
            raise KinematicsError(f"{path}: joint {jname!r}: axis is zero")
        lim = j.find("limit")
        if lim is None or lim.get("lower") is None or lim.get("upper") is None:
            raise KinematicsError(f"{path}: joint {jname!r}: a revolute joint needs "
                                  "<limit lower=... upper=...>")
        lower = num(lim.get("lower"), 1, f"joint {jname!r} limit lower")[0]
        upper = num(lim.get("upper"), 1, f"joint {jname!r} limit upper")[0]
        if lower > upper:
            raise KinematicsError(f"{path}: joint {jname!r}: limit lower {lower:g} > upper "
                                  f"{upper:g}")
        v = lim.get("velocity")
        origins.append(T)
        axes.append(axis / np.linalg.norm(axis))
        names.append(jname)
        lo.append(lower)
        hi.append(upper)
        vel.append(num(v, 1, f"joint {jname!r} limit velocity")[0] if v else np.inf)
        pending = np.eye(4)
    if not names:
        raise KinematicsError(f"{path}: no revolute joint between the root and {tip!r}")
    return Chain(root.get("name", path.stem), np.array(origins), np.array(axes), pending,
                 np.array(lo), np.array(hi), tuple(names), np.array(vel))


__all__ = ["Chain", "chain_from_dh", "chain_from_urdf", "rot_axis", "rpy_matrix"]
