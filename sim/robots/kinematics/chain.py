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

from sim.core.files import read_input
from sim.core.tomlschema import (
    ANGLE_RAD,
    INERTIA_KG_M2,
    JOINT_RAD,
    JOINT_SPEED_RAD_S,
    LENGTH_M,
    MASS_KG,
    MIN_PRINCIPAL_INERTIA_KG_M2,
    TORQUE_NM,
    Quantity,
)
from sim.errors import KinematicsError
from sim.robots.kinematics.dh import DHRow, MDHRow

#: A component of a URDF joint axis (normalised when read; a zero axis is refused).
AXIS_COMPONENT = Quantity("an axis component", "", -1e6, 1e6)
#: The numbers a URDF reader takes, by (element, attribute), with their physical ranges
#: (:mod:`sim.core.tomlschema`); an ``<inertia>`` takes ``ixx`` ... ``izz``.
URDF_QUANTITIES: dict[tuple[str, str], Quantity] = {
    ("origin", "xyz"): LENGTH_M, ("origin", "rpy"): ANGLE_RAD, ("axis", "xyz"): AXIS_COMPONENT,
    ("limit", "lower"): JOINT_RAD, ("limit", "upper"): JOINT_RAD,
    ("limit", "velocity"): JOINT_SPEED_RAD_S, ("limit", "effort"): TORQUE_NM,
    ("mass", "value"): MASS_KG,
    **{("inertia", k): INERTIA_KG_M2 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")},
}
#: The URDF numbers for which 0 means "not given" (a massless link, a joint without an
#: effort or velocity limit) rather than a value out of range.
URDF_ZERO_IS_NONE = frozenset({("limit", "velocity"), ("limit", "effort"), ("mass", "value")})
#: The most whole-turn variants one pose may have over a robot's joint ranges (the product over
#: the joints of how many turns each range holds: +-360 deg on all six joints gives 3^6 = 729).
#: The inverse kinematics lists every variant, so wider ranges would make it run for hours.
MAX_TURN_VARIANTS = 1024


def inertia_problem(inertia: NDArray[np.float64]) -> str:
    """Why the inertia tensor about the centre of mass (3, 3) of a body with a mass is not
    physical ("" when it is): its principal moments must be positive, at least
    :data:`~sim.core.tomlschema.MIN_PRINCIPAL_INERTIA_KG_M2` (a zero tensor is a point mass,
    which MuJoCo refuses for a moving body), and satisfy the triangle inequality."""
    ev = np.sort(np.linalg.eigvalsh(inertia))
    if ev[0] < MIN_PRINCIPAL_INERTIA_KG_M2 or ev[0] + ev[1] < ev[2] * (1 - 1e-9):
        return (f"inertia is not physical (principal moments "
                f"{', '.join(f'{v:.4g}' for v in ev)} kg m^2: each must be at least "
                f"{MIN_PRINCIPAL_INERTIA_KG_M2:g} and no one larger than the sum of the other "
                "two)")
    return ""


def range_problem(lower: float, upper: float) -> str:
    """Why ``[lower, upper]`` is not a joint range ("" when it is): lower above upper, or an
    empty range (a joint that cannot move, which MuJoCo's compiler refuses)."""
    if lower > upper:
        return f"lower {lower:g} > upper {upper:g}"
    if lower == upper:
        return f"lower {lower:g} = upper {upper:g} (an empty range: the joint cannot move)"
    return ""


def turns_problem(lower: ArrayLike, upper: ArrayLike) -> str:
    """Why joint ranges (rad) hold too many whole-turn variants of a pose ("" when they do
    not): more than :data:`MAX_TURN_VARIANTS`, counting ``floor(width / 2 pi) + 1`` per joint
    with a finite range."""
    counts = [int((hi - lo) // (2 * math.pi)) + 1
              for lo, hi in zip(np.asarray(lower, float), np.asarray(upper, float), strict=True)
              if math.isfinite(lo) and math.isfinite(hi)]
    total = math.prod(counts)
    if total <= MAX_TURN_VARIANTS:
        return ""
    return (f"the ranges give a pose up to {total} whole-turn variants ({' x '.join(map(str, counts))}"
            f" over the joints), more than the {MAX_TURN_VARIANTS} the inverse kinematics lists: "
            "narrow the ranges")


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
        max_effort: Joint torque limits, N m, (n,) (a URDF's ``effort``; 0 where none given).
        inertials: Per moving body (joint i's frame): ``(mass kg, centre of mass (3,) m,
            inertia about the centre of mass (3, 3) kg m^2)``, with everything attached to it
            off the chain fused in (fixed links, a gripper past the tip; joints off the chain
            at zero); None when the source gives no inertials (a DH table, a URDF without),
            and ``no_inertials_why`` says which.
    """

    name: str
    origins: NDArray[np.float64]
    axes: NDArray[np.float64]
    flange: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    joint_names: tuple[str, ...]
    max_speed: NDArray[np.float64] | None = None
    max_effort: NDArray[np.float64] | None = None
    inertials: tuple[tuple[float, NDArray[np.float64], NDArray[np.float64]], ...] | None = None
    no_inertials_why: str = ""

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

    def fk_many(self, Q: ArrayLike) -> NDArray[np.float64]:
        """Flange poses of many configurations at once, (m, 4, 4), from ``Q`` (m, n) rad (the
        product of :meth:`frames`, each joint's rotation for all rows by Rodrigues)."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        T = np.broadcast_to(np.eye(4), (len(Q), 4, 4))
        for i in range(self.n):
            x, y, z = self.axes[i]
            K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
            th = Q[:, i][:, None, None]
            J = np.zeros((len(Q), 4, 4))
            J[:, :3, :3] = np.eye(3) + np.sin(th) * K + (1.0 - np.cos(th)) * (K @ K)
            J[:, 3, 3] = 1.0
            T = T @ self.origins[i] @ J
        return T @ self.flange

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
    # the table rows of sim.robots.kinematics.dh (also the MJCF chain builder's) give each
    # row's constant transform; the joint turns about the z axis before (dh) or after (mdh) it
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
    data = read_input(path, KinematicsError, "URDF file")
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise KinematicsError(f"{path}: not a readable URDF ({exc})") from None
    if root.tag != "robot":
        raise KinematicsError(f"{path}: not a URDF (the root element is <{root.tag}>, not <robot>)")
    links = [ln.get("name") for ln in root.findall("link")]
    for kind, names in (("link", links), ("joint", [j.get("name") for j in root.findall("joint")])):
        seen: set[str | None] = set()
        for name in names:
            if name in seen:  # a second one would silently replace the first
                raise KinematicsError(f"{path}: two {kind}s named {name!r} (names must be "
                                      "unique)")
            seen.add(name)
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

    def num(text: str | None, n: int, what: str, key: tuple[str, str]) -> list[float]:
        """The ``n`` numbers of an attribute (0 where it is absent), each in the range of
        :data:`URDF_QUANTITIES` (0 too where :data:`URDF_ZERO_IS_NONE` says it means none)."""
        vals = (text or " ".join(["0"] * n)).split()
        try:
            out = [float(v) for v in vals]
        except ValueError:
            raise KinematicsError(f"{path}: {what}: not numbers: {text!r}") from None
        if len(out) != n or not all(math.isfinite(v) for v in out):
            raise KinematicsError(f"{path}: {what}: needs {n} finite numbers, got {text!r}")
        quantity = URDF_QUANTITIES[key]
        for v in out:
            if v == 0.0 and key in URDF_ZERO_IS_NONE:
                continue
            bad = quantity.problem(v)
            if bad:
                zero = " (or 0: none)" if key in URDF_ZERO_IS_NONE else ""
                raise KinematicsError(f"{path}: {what}: {bad}{zero}")
        return out

    link_el = {ln.get("name"): ln for ln in root.findall("link")}

    def inertial(link: str, where: NDArray[np.float64]):
        """The link's inertial in the moving body's frame (``where``: the link's frame in it),
        or None when it has none."""
        el = link_el.get(link)
        el = None if el is None else el.find("inertial")
        if el is None:
            return None
        o = el.find("origin")
        xyz = num(None if o is None else o.get("xyz"), 3, f"link {link!r} inertial origin xyz",
                  ("origin", "xyz"))
        rpy = num(None if o is None else o.get("rpy"), 3, f"link {link!r} inertial origin rpy",
                  ("origin", "rpy"))
        m_el, i_el = el.find("mass"), el.find("inertia")
        mass = num(None if m_el is None else m_el.get("value"), 1, f"link {link!r} mass value",
                   ("mass", "value"))[0]
        if mass > 0 and i_el is None:
            raise KinematicsError(f"{path}: link {link!r}: <inertial> has a mass but no <inertia>")
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        vals = [num(None if i_el is None else i_el.get(k), 1, f"link {link!r} inertia {k}",
                    ("inertia", k))[0] for k in keys]
        ixx, ixy, ixz, iyy, iyz, izz = vals
        Ic = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        problem = inertia_problem(Ic) if mass > 0 else ""  # a massless link is left out
        if problem:
            raise KinematicsError(f"{path}: link {link!r}: {problem}")
        T = where @ _T(rpy_matrix(*rpy), xyz)
        return mass, T[:3, 3], T[:3, :3] @ Ic @ T[:3, :3].T

    children: dict[str, list] = {}
    for jn, j in joints.items():
        children.setdefault(j.find("parent").get("link"), []).append(jn)
    on_path = set(path_joints)

    def hanging(link: str, where: NDArray[np.float64], seen: frozenset = frozenset()) -> list:
        """The inertials of ``link`` and of everything attached to it off the chain (fixed
        links, a gripper past the tip, side branches; joints off the chain held at zero), in
        the moving body's frame (``where``: the link's frame in it)."""
        if link in seen:
            raise KinematicsError(f"{path}: link {link!r} is in a loop")
        parts = [inertial(link, where)]
        for jn in children.get(link, []):
            if jn in on_path:
                continue
            j = joints[jn]
            o = j.find("origin")
            xyz = num(None if o is None else o.get("xyz"), 3, f"joint {jn!r} origin xyz",
                      ("origin", "xyz"))
            rpy = num(None if o is None else o.get("rpy"), 3, f"joint {jn!r} origin rpy",
                      ("origin", "rpy"))
            parts += hanging(j.find("child").get("link"), where @ _T(rpy_matrix(*rpy), xyz),
                             seen | {link})
        return parts

    def fuse(parts):
        parts = [p for p in parts if p is not None and p[0] > 0]
        if not parts:
            return None
        m = sum(p[0] for p in parts)
        c = sum(p[0] * p[1] for p in parts) / m
        Itot = np.zeros((3, 3))
        for mk, ck, Ik in parts:
            r = ck - c
            Itot += Ik + mk * (r @ r * np.eye(3) - np.outer(r, r))
        return m, c, Itot

    origins, axes, names, lo, hi, vel, eff = [], [], [], [], [], [], []
    bodies: list[list] = []  # per moving body: the inertials of its links
    has_inertial: list[bool] = []
    pending = np.eye(4)
    for jname in path_joints:
        j = joints[jname]
        o = j.find("origin")
        xyz = num(None if o is None else o.get("xyz"), 3, f"joint {jname!r} origin xyz",
                  ("origin", "xyz"))
        rpy = num(None if o is None else o.get("rpy"), 3, f"joint {jname!r} origin rpy",
                  ("origin", "rpy"))
        T = pending @ _T(rpy_matrix(*rpy), xyz)
        jtype = j.get("type")
        child = j.find("child").get("link")
        if jtype == "fixed":
            pending = T
            if bodies:  # a link fixed to the last moving body, with what hangs off it
                parts = hanging(child, T)
                bodies[-1] += parts
                has_inertial[-1] = has_inertial[-1] or any(p is not None for p in parts)
            continue
        if jtype != "revolute":
            raise KinematicsError(f"{path}: joint {jname!r}: type {jtype!r} is not supported "
                                  "(revolute and fixed joints only)")
        a = j.find("axis")
        axis = np.array(num("1 0 0" if a is None else a.get("xyz"), 3,
                            f"joint {jname!r} axis xyz", ("axis", "xyz")))
        if np.linalg.norm(axis) < 1e-12:
            raise KinematicsError(f"{path}: joint {jname!r}: axis is zero")
        lim = j.find("limit")
        if lim is None or lim.get("lower") is None or lim.get("upper") is None:
            raise KinematicsError(f"{path}: joint {jname!r}: a revolute joint needs "
                                  "<limit lower=... upper=...>")
        lower = num(lim.get("lower"), 1, f"joint {jname!r} limit lower", ("limit", "lower"))[0]
        upper = num(lim.get("upper"), 1, f"joint {jname!r} limit upper", ("limit", "upper"))[0]
        bad = range_problem(lower, upper)
        if bad:
            raise KinematicsError(f"{path}: joint {jname!r}: limit {bad}")
        v = lim.get("velocity")
        e = lim.get("effort")
        eff.append(num(e, 1, f"joint {jname!r} limit effort", ("limit", "effort"))[0]
                   if e else 0.0)
        parts = hanging(child, np.eye(4))
        bodies.append(parts)
        has_inertial.append(any(p is not None for p in parts))
        origins.append(T)
        axes.append(axis / np.linalg.norm(axis))
        names.append(jname)
        lo.append(lower)
        hi.append(upper)
        speed = num(v, 1, f"joint {jname!r} limit velocity", ("limit", "velocity"))[0] \
            if v else 0.0
        vel.append(speed if speed > 0 else np.inf)  # 0: none given
        pending = np.eye(4)
    if not names:
        raise KinematicsError(f"{path}: no revolute joint between the root and {tip!r}")
    bad = turns_problem(lo, hi)
    if bad:
        raise KinematicsError(f"{path}: joint limits: {bad}")
    fused = [fuse(b) for b in bodies]
    inertials = tuple(fused) if all(has_inertial) and all(f is not None for f in fused) else None
    note = "the moving links have no <inertial> (mass and inertia)"
    if any(has_inertial) and inertials is None:
        i = next(k for k, f in enumerate(fused) if f is None)
        note = (f"joint {names[i]!r}: the links it moves (up to the next joint) have no mass "
                "(no <inertial>, or mass 0)")
    return Chain(root.get("name", path.stem), np.array(origins), np.array(axes), pending,
                 np.array(lo), np.array(hi), tuple(names), np.array(vel), np.array(eff),
                 inertials, "" if inertials is not None else note)


__all__ = ["MAX_TURN_VARIANTS", "URDF_QUANTITIES", "Chain", "chain_from_dh", "chain_from_urdf",
           "inertia_problem", "range_problem", "rot_axis", "rpy_matrix", "turns_problem"]
