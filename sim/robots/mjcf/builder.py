"""Build an MJCF serial chain from a kinematic table (the rows of :mod:`sim.robots.kinematics.dh`:
:class:`DHRow`, :class:`MDHRow`, :class:`ScrewAxis`; revolute ``"R"`` and prismatic ``"P"``
joints; screws: ``T(q) = exp([xi_1] q_1) ... exp([xi_n] q_n) M`` with ``M`` the tool's home
pose).

:class:`KinematicChain` holds the table, a ``base`` transform (frame 0 in the MJCF world) and a
``tool`` transform (DH/MDH: tool frame in the last joint frame; screws: the home pose ``M``). Its
:meth:`~KinematicChain.fk` is the plain matrix product of the table (the builder's own forward
model) and :meth:`~KinematicChain.to_mjcf` writes the MJCF (plain XML): one body per joint, a
``hinge``/``slide`` joint ``j1..jn``, capsule links for inertia and looks, sites ``frame0`` and
``tcp``. The examples of seed 002 (RTT, eq. 2.12-2.19, and the RRRT exercise) are built by
:func:`rtt_chain` and :func:`rrrt_chain`. (A robot folder's model is the other MJCF writer,
:mod:`sim.robots.mjcf.generate`, from a chain of the same rows.)

Units: metres, radians.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.core.resources import models_dir
from sim.core.rotations import make_transform, rot_x
from sim.errors import KinematicsError
from sim.robots.kinematics.dh import DHRow, MDHRow, ScrewAxis, check_joint

if TYPE_CHECKING:  # imported where used: reading a DH table must not import mujoco (the
    import mujoco  # command line chooses its OpenGL backend after loading a scenario)

@dataclass
class KinematicChain:
    """A serial chain described by a kinematic table.

    Attributes:
        convention: ``"dh"``, ``"mdh"`` or ``"screw"``.
        rows: One row per joint (:class:`DHRow`, :class:`MDHRow` or :class:`ScrewAxis`).
        tool: Tool frame in the last joint frame (DH, MDH) or home pose M (screws), (4, 4).
        base: Frame 0 in the MJCF world, (4, 4).
        name: Model name.
        link_radius: Radius of the capsule links, m (looks and inertia only).
    """

    convention: str
    rows: Sequence[DHRow | MDHRow | ScrewAxis]
    tool: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    base: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    name: str = "chain"
    link_radius: float = 0.02

    def __post_init__(self) -> None:
        kinds = {"dh": DHRow, "mdh": MDHRow, "screw": ScrewAxis}
        if self.convention not in kinds:
            raise KinematicsError(
                f"unknown table convention {self.convention!r}; known: dh, mdh, screw")
        for i, row in enumerate(self.rows):
            if not isinstance(row, kinds[self.convention]):
                raise KinematicsError(f"row {i + 1} is a {type(row).__name__}, expected "
                                      f"{kinds[self.convention].__name__}")
            check_joint(row.joint)
        self.tool = np.asarray(self.tool, dtype=float)
        self.base = np.asarray(self.base, dtype=float)

    @property
    def n_joints(self) -> int:
        return len(self.rows)

    @property
    def joints(self) -> tuple[str, ...]:
        return tuple(f"j{i + 1}" for i in range(self.n_joints))

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Tool pose in frame 0: the product of the table's transforms, (4, 4).

        Args:
            q: Joint values (rad for R, m for P), shape (n,).
        """
        q = np.asarray(q, dtype=float)
        if q.shape != (self.n_joints,):
            raise KinematicsError(f"expected {self.n_joints} joint values, got shape {q.shape}")
        T = np.eye(4)
        if self.convention == "screw":
            for row, qi in zip(self.rows, q):
                T = T @ row.exp(qi)
        else:
            for row, qi in zip(self.rows, q):
                T = T @ row.transform(qi)
        return T @ self.tool

    # ------------------------------------------------------------------ MJCF
    def _body_frames(self) -> tuple[list[NDArray[np.float64]], list[NDArray[np.float64]],
                                    NDArray[np.float64]]:
        """Body j pose in its parent (frame 0 for j = 1), joint axis in body j, tcp pose."""
        n = self.n_joints
        if self.convention == "dh":
            fixed = [self.base] + [r.fixed() for r in self.rows]
            rel = [np.eye(4)] + fixed[1:n]  # body j sits at the end of row j-1's fixed part
            axes = [np.array([0.0, 0.0, 1.0])] * n
            return rel, axes, fixed[n] @ self.tool
        if self.convention == "mdh":
            rel = [r.fixed() for r in self.rows]
            axes = [np.array([0.0, 0.0, 1.0])] * n
            return rel, axes, self.tool
        # screws: bodies aligned with frame 0 at q = 0, placed on the axis points
        pts = [np.asarray(r.p, dtype=float) for r in self.rows]
        rel = []
        prev = np.zeros(3)
        for p in pts:
            rel.append(make_transform(np.eye(3), p - prev))
            prev = p
        axes = [np.asarray(r.k, dtype=float) / np.linalg.norm(r.k) for r in self.rows]
        tcp = self.tool.copy()
        tcp[:3, 3] -= prev
        return rel, axes, tcp

    def to_mjcf(self) -> str:
        """MJCF text of the chain: sites ``frame0``/``tcp``, joints ``j1..jn`` (SI units, rad)."""
        rel, axes, tcp = self._body_frames()
        root = ET.Element("mujoco", model=self.name)
        ET.SubElement(root, "compiler", angle="radian", autolimits="true")
        ET.SubElement(root, "option", integrator="implicitfast")
        default = ET.SubElement(root, "default")
        ET.SubElement(default, "geom", type="capsule", size=_fmt([self.link_radius]),
                      density="1000", rgba="0.8 0.6 0.2 1")
        ET.SubElement(default, "joint", damping="0.1", armature="0.01")
        world = ET.SubElement(root, "worldbody")
        frame = ET.SubElement(world, "body", name="base", **_pose_attrs(self.base))
        ET.SubElement(frame, "site", name="frame0", size="0.01")
        ET.SubElement(frame, "geom", type="cylinder", size=_fmt([0.05, 0.01]), pos="0 0 -0.01",
                      contype="0", conaffinity="0")
        parent = frame
        for i, row in enumerate(self.rows):
            body = ET.SubElement(parent, "body", name=f"link{i + 1}", **_pose_attrs(rel[i]))
            attrs = {"name": f"j{i + 1}", "type": "hinge" if row.joint == "R" else "slide",
                     "axis": _fmt(axes[i])}
            if row.limits is not None:
                attrs["range"] = _fmt(row.limits)
            ET.SubElement(body, "joint", **attrs)
            nxt = rel[i + 1][:3, 3] if i + 1 < self.n_joints else tcp[:3, 3]
            if np.linalg.norm(nxt) > 1e-9:
                ET.SubElement(body, "geom", fromto=_fmt(np.r_[np.zeros(3), nxt]),
                              contype="0", conaffinity="0")
            else:
                ET.SubElement(body, "geom", type="sphere", size=_fmt([self.link_radius]),
                              contype="0", conaffinity="0")
            parent = body
        ET.SubElement(parent, "site", name="tcp", size="0.01", **_pose_attrs(tcp))
        ET.indent(root)
        return ET.tostring(root, encoding="unicode") + "\n"

    def compile(self) -> mujoco.MjModel:
        import mujoco

        """The compiled MuJoCo model of :meth:`to_mjcf`."""
        return mujoco.MjModel.from_xml_string(self.to_mjcf())


def _fmt(values: ArrayLike) -> str:
    # repr is the shortest text that reads back as the same double
    return " ".join(repr(float(v)) if abs(float(v)) > 1e-15 else "0" for v in np.ravel(values))


def _pose_attrs(T: NDArray[np.float64]) -> dict[str, str]:
    import mujoco

    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).ravel())
    attrs = {"pos": _fmt(T[:3, 3])}
    if np.abs(quat - np.array([1.0, 0, 0, 0])).max() > 1e-15:
        attrs["quat"] = _fmt(quat)
    return attrs


# ---------------------------------------------------------------------------- seed tables
def fanuc6_chain(dims: dict[str, float], tool_length: float = 0.0) -> KinematicChain:
    """Seed 004 Table 1 (LR Mate 200iC) as an MDH chain; tool E = ``R6 + r`` along z6."""
    h = np.pi / 2
    rows = [MDHRow(0.0, 0.0, 0.0, 0.0), MDHRow(h, dims["d2"], h, 0.0),
            MDHRow(0.0, dims["d3"], 0.0, 0.0), MDHRow(h, dims["d4"], 0.0, dims["R4"]),
            MDHRow(-h, 0.0, 0.0, 0.0), MDHRow(h, 0.0, 0.0, 0.0)]
    tool = make_transform(np.eye(3), [0.0, 0.0, dims["R6"] + tool_length])
    return KinematicChain("mdh", rows, tool=tool, name="fanuc6_mdh")


def five_r_chain(dims: dict[str, float]) -> KinematicChain:
    """Seed 000 Table 1 (5R) as screw axes; home pose M = tool point, identity rotation."""
    l1, d1, l2, l3 = dims["l1"], dims["d1"], dims["l2"], dims["l3"]
    rows = [ScrewAxis((0, 0, 1), (0, 0, 0)), ScrewAxis((0, 1, 0), (l1, 0, 0)),
            ScrewAxis((0, 1, 0), (l1, 0, d1)), ScrewAxis((0, 1, 0), (l1 + l2, 0, d1)),
            ScrewAxis((1, 0, 0), (l1 + l2, 0, d1))]
    return KinematicChain("screw", rows, tool=make_transform(np.eye(3), [l1 + l2 + l3, 0, d1]),
                          name="five_r_screw")


#: Seed 002 gives no value for the RTT's L1 nor the RRRT's lengths (its figures are not in the
#: text): these examples take L1 = 0.5 m, and for the RRRT a base height H = 0.5 m, upper arm
#: L2 = 0.4 m, forearm L3 = 0.3 m; the exercise's q4 = 10 is read as 10 cm = 0.10 m.
RTT_L1 = 0.5
RRRT_DIMS = {"H": 0.5, "L2": 0.4, "L3": 0.3}
RRRT_Q4 = 0.10


def rtt_chain(L1: float = RTT_L1, convention: str = "screw") -> KinematicChain:
    """Seed 002's RTT robot (eq. 2.12-2.14): ``T = Rz(q1) Tz(q2) Ty(q3 + L1)``.

    Args:
        L1: Offset of the second slide, m.
        convention: ``"screw"`` (J1 about z, J2 along z, J3 along y; M = Ty(L1)) or ``"dh"``
            (standard DH rows with the tool rotated back so that R = Rz(q1) as in eq. 2.19).
    """
    lim = (-0.5, 0.5)
    if convention == "screw":
        rows = [ScrewAxis((0, 0, 1)), ScrewAxis((0, 0, 1), joint="P", limits=(0.0, 1.0)),
                ScrewAxis((0, 1, 0), joint="P", limits=lim)]
        return KinematicChain("screw", rows, tool=make_transform(np.eye(3), [0, L1, 0]),
                              name="rtt")
    if convention == "dh":
        rows = [DHRow(0.0, 0.0, 0.0, 0.0), DHRow(0.0, 0.0, 0.0, -np.pi / 2, "P", (0.0, 1.0)),
                DHRow(0.0, L1, 0.0, 0.0, "P", lim)]
        return KinematicChain("dh", rows, tool=make_transform(rot_x(np.pi / 2), np.zeros(3)),
                              name="rtt_dh")
    raise KinematicsError(
        f"unknown convention {convention!r} for the RTT example; known: dh, screw")


def rrrt_chain(H: float = RRRT_DIMS["H"], L2: float = RRRT_DIMS["L2"],
               L3: float = RRRT_DIMS["L3"]) -> KinematicChain:
    """Seed 002's RRRT exercise robot (assumed geometry, see :data:`RRRT_DIMS`), as screws.

    J1 about the vertical z0; J2 and J3 about horizontal axes parallel to y0 at height H, J3 at
    L2 from J2 along x0 at q = 0; J4 slides along the forearm (x0 at q = 0); tool point at
    L3 + q4 from J3. Forward model: ``p = Rz(q1) (L2 c2 + (L3 + q4) c23, 0,
    H - L2 s2 - (L3 + q4) s23)``.
    """
    rows = [ScrewAxis((0, 0, 1)), ScrewAxis((0, 1, 0), (0, 0, H)),
            ScrewAxis((0, 1, 0), (L2, 0, H)), ScrewAxis((1, 0, 0), (L2, 0, H), "P", (0.0, 0.3))]
    return KinematicChain("screw", rows, tool=make_transform(np.eye(3), [L2 + L3, 0, H]),
                          name="rrrt")


def rrrt_exercise_q(t: ArrayLike) -> NDArray[np.float64]:
    """Seed 002 exercise (c): ``q1 = 0, q2 = -t pi/20, q3 = t pi/20, q4 = 10`` (t in s), (N, 4)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    return np.stack([np.zeros_like(t), -t * np.pi / 20, t * np.pi / 20,
                     np.full_like(t, RRRT_Q4)], -1)


def example_chains() -> dict[str, KinematicChain]:
    """The example chains shipped as ``models/examples/<name>.xml``."""
    return {"rtt": rtt_chain(), "rrrt": rrrt_chain()}


def write_examples(folder: str | None = None) -> list[str]:
    """Write :func:`example_chains` as ``<folder>/<name>.xml`` (default ``models/examples``).

    Returns:
        The paths written.
    """
    out = Path(folder) if folder is not None else models_dir() / "examples"
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, chain in example_chains().items():
        path = out / f"{name}.xml"
        path.write_text(f"<!-- generated by `python -m sim.robots.mjcf.builder` "
                        f"(sim/robots/mjcf/builder.py, {name}_chain); do not edit -->\n"
                        + chain.to_mjcf())
        written.append(str(path))
    return written


if __name__ == "__main__":
    for p in write_examples():
        print(f"wrote {p}")
