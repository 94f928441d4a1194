"""An arm given as data (a URDF, or a ``robot.toml`` with a DH table): its chain and its IK.

:func:`load_arm` reads ``*.urdf`` files and ``robot.toml`` files (or the folder holding one);
:class:`Arm` solves inverse kinematics with the closed form when the arm is ortho-parallel with
a spherical wrist (:mod:`sim.robots.kinematics.opw`: all 8 branches, plus the whole-turn variants of
joints whose range exceeds 360 deg), with the offset-wrist closed form when J2-J4 are parallel
and J5, J6 meet off them (UR-type, :mod:`sim.robots.kinematics.offset_wrist`: 8 branches and
their whole-turn variants), with seed 000's 5R closed form when a 5-axis arm has its
structure (:mod:`sim.robots.kinematics.five_axis`: 4 branches), and numerically otherwise
(:mod:`sim.robots.kinematics.numeric_ik`).

``robot.toml`` (this slice reads its kinematics and joint tables)::

    name = "my_arm"
    description = "..."
    [kinematics]
    convention = "dh"            # "dh" | "mdh" | "urdf"
    dh = [[a_mm, alpha_deg, d_mm, theta_offset_deg], ...]   # joint value q = theta - offset
    # urdf = "arm.urdf"          # with convention = "urdf", relative to robot.toml
    [joints]
    range_deg = [[-170, 170], ...]
    max_speed_deg_s = [...]

For a robot given by a DH table, frame 0 (``cellsim ik``) is the table's base frame.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.core.tomlschema import load_toml
from sim.errors import KinematicsError
from sim.robots.kinematics import offset_wrist, opw
from sim.robots.kinematics.chain import (
    Chain,
    chain_from_dh,
    chain_from_urdf,
    range_problem,
    turns_problem,
)
from sim.robots.kinematics.five_axis import FiveAxisMap, five_axis_from_chain
from sim.robots.kinematics.numeric_ik import solve_ik as numeric_solve
from sim.robots.schema import DH_COLUMNS, RobotFolderSpec


@dataclass(frozen=True)
class Solution:
    """One IK solution: joint values (rad, (n,)), its branch label, within the limits."""

    q: NDArray[np.float64]
    branch: str
    within_limits: bool


@dataclass
class Arm:
    """A chain with its inverse kinematics (module docstring).

    Attributes:
        name: The arm's name. chain: Its kinematics. opw: OPW parameters when it is one (else
        None, and ``why_numeric`` says why). source: The file it came from. five: seed 000's
        5R map when it is one. offset: The offset-wrist parameters when it is one (UR-type).
    """

    name: str
    chain: Chain
    opw: opw.OPWParameters | None
    why_numeric: str = ""
    source: Path | None = None
    five: FiveAxisMap | None = None
    offset: offset_wrist.OffsetWristParameters | None = None

    @property
    def solver(self) -> str:
        """``"opw"`` (6 axes), ``"offset_wrist"`` (6 axes, UR-type), ``"five_r"`` (5 axes,
        seed 000's closed form) or ``"numeric"``."""
        if self.opw is not None:
            return "opw"
        if self.offset is not None:
            return "offset_wrist"
        return "five_r" if self.five is not None else "numeric"

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Flange pose in frame 0 (the chain's base), (4, 4)."""
        return self.chain.fk(q)

    def branches(self, T: ArrayLike, current: ArrayLike | None = None
                 ) -> list[NDArray[np.float64]]:
        """The solutions of a flange pose, one per branch (no whole-turn variants, unsorted):
        for path inverse kinematics, which picks each joint's turn itself."""
        cur = np.zeros(self.chain.n) if current is None else np.asarray(current, dtype=float)
        return _branch_solutions(self, np.asarray(T, dtype=float), cur)

    def labelled_branches(self, T: ArrayLike, current: ArrayLike | None = None
                          ) -> list[tuple[NDArray[np.float64], str]]:
        """An offset-wrist arm's solutions of a flange pose, one per branch with its label
        (no whole-turn variants): what :func:`sim.robots.kinematics.ik.solve_ik` expands
        (each joint's turns in its range) and ranks. Other solvers: :meth:`ik`'s."""
        cur = np.zeros(self.chain.n) if current is None else np.asarray(current, dtype=float)
        if self.offset is not None:
            return _offset_solutions(self, np.asarray(T, dtype=float), cur)
        return [(s.q, s.branch) for s in self.ik(T, cur)]

    def ik(self, T: ArrayLike, current: ArrayLike | None = None) -> list[Solution]:
        """Every solution of a flange pose: in the limits first, then nearest ``current``.

        The closed form gives its 8 branches and, for joints with a range over 360 deg, each
        whole-turn variant inside the range; the numeric solver the distinct solutions its seeds
        reach. Solutions outside the limits are kept (flagged) when no variant is inside.
        """
        T = np.asarray(T, dtype=float)
        lo, hi = self.chain.lower, self.chain.upper
        cur = np.zeros(self.chain.n) if current is None else np.asarray(current, dtype=float)
        out: list[Solution] = []
        def add_with_turns(q: NDArray[np.float64], label: str) -> None:
            """Every whole-turn variant inside the ranges; the solution itself, flagged, when
            no variant is."""
            variants = [_turns(q[i], lo[i], hi[i]) for i in range(len(q))]
            if all(variants):
                for combo in itertools.product(*variants):
                    out.append(Solution(np.array(combo), label, True))
            else:
                out.append(Solution(q, label, False))

        if self.opw is not None:
            for q in opw.inverse(self.opw, T):
                if np.isnan(q).any():
                    continue
                if np.max(np.abs(self.chain.fk(q) - T)) > 1e-7:
                    continue  # a branch the arm's geometry makes spurious
                add_with_turns(q, opw.configuration(self.opw, q))
        elif self.offset is not None:
            for q, label in _offset_solutions(self, T, cur):
                add_with_turns(q, label)
        elif self.five is not None:
            for q, label in self.five.inverse(T):
                if np.abs(self.chain.fk(q)[:3, 3] - T[:3, 3]).max() > 1e-7:
                    continue
                add_with_turns(q, label)
        else:
            for q in numeric_solve(self.chain, T, cur):
                out.append(Solution(q, "numeric", True))
        out = _dedupe(out)
        out.sort(key=lambda s: (not s.within_limits, float(np.sum(np.abs(s.q - cur)))))
        return out


def _branch_solutions(arm: Arm, T: NDArray[np.float64], current: NDArray[np.float64]
                      ) -> list[NDArray[np.float64]]:
    """The arm's solutions of a flange pose as its solver gives them (one per branch, no
    whole-turn variants, unsorted): what :meth:`Arm.ik` expands and ranks. The closed form's
    branches are checked against the forward kinematics all at once."""
    if arm.opw is not None:
        Q = opw.inverse(arm.opw, T)
        Q = Q[~np.isnan(Q).any(axis=1)]
        if len(Q) == 0:
            return []
        ok = np.abs(arm.chain.fk_many(Q) - T).max(axis=(1, 2)) <= 1e-7
        return list(Q[ok])
    if arm.offset is not None:
        return [q for q, _ in _offset_solutions(arm, T, current)]
    if arm.five is not None:
        return [q for q, _ in arm.five.inverse(T)
                if np.abs(arm.chain.fk(q)[:3, 3] - T[:3, 3]).max() <= 1e-7]
    return list(numeric_solve(arm.chain, T, current))


def _offset_solutions(arm: Arm, T: NDArray[np.float64], current: NDArray[np.float64]
                      ) -> list[tuple[NDArray[np.float64], str]]:
    """The offset-wrist closed form's solutions with their branch labels, each checked against
    the forward kinematics (a joint a singular pose leaves free keeps ``current``'s value)."""
    assert arm.offset is not None
    Q = offset_wrist.inverse(arm.offset, T, current)
    keep = np.flatnonzero(~np.isnan(Q).any(axis=1))
    if len(keep) == 0:
        return []
    ok = np.abs(arm.chain.fk_many(Q[keep]) - T).max(axis=(1, 2)) <= 1e-7
    return [(Q[i], offset_wrist.LABELS[i]) for i in keep[ok]]


def _turns(q: float, lo: float, hi: float) -> list[float]:
    """``q + 2 pi k`` for every whole k that lands in [lo, hi]."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return [q] if lo - 1e-9 <= q <= hi + 1e-9 else []
    k0 = math.ceil((lo - q) / (2 * math.pi) - 1e-12)
    out = []
    k = k0
    while q + 2 * math.pi * k <= hi + 1e-9:
        out.append(q + 2 * math.pi * k)
        k += 1
    return out


def _dedupe(sols: list[Solution]) -> list[Solution]:
    """``sols`` without any within 1e-9 (every joint) of one kept before it."""
    out: list[Solution] = []
    kept: list[NDArray[np.float64]] = []
    for s in sols:
        if not kept or not bool((np.abs(np.array(kept) - s.q).max(axis=1) < 1e-9).any()):
            out.append(s)
            kept.append(s.q)
    return out


def arm_from_chain(chain: Chain, source: Path | None = None) -> Arm:
    """An :class:`Arm`: OPW when its axes at q = 0 make one, else offset-wrist (UR-type) when
    they make that, else numeric.

    Raises:
        KinematicsError: Two neighbouring joints turn about one axis line (a zero-length link
            between them: the two are one joint, and no solver can split a turn between them).
    """
    _check_distinct_axes(chain, source)
    if chain.n == 6:
        axes, points, F = chain.frames(np.zeros(6))
        try:
            return Arm(chain.name, chain, opw.opw_from_axes(axes, points, F, chain.name),
                       source=source)
        except KinematicsError as exc:
            why_opw = str(exc)
        try:
            return Arm(chain.name, chain, None, source=source,
                       offset=offset_wrist.offset_wrist_from_axes(axes, points, F, chain.name))
        except KinematicsError as exc:
            return Arm(chain.name, chain, None, why_numeric=f"{why_opw}; {exc}", source=source)
    if chain.n == 5:
        try:
            return Arm(chain.name, chain, None, source=source, five=five_axis_from_chain(chain))
        except KinematicsError as exc:
            return Arm(chain.name, chain, None, why_numeric=str(exc), source=source)
    return Arm(chain.name, chain, None, why_numeric=f"{chain.n} joints (the closed forms are "
               "for 5 and 6)", source=source)


def _check_distinct_axes(chain: Chain, source: Path | None) -> None:
    """Refuse neighbouring joints on one axis line (parallel axes through a common point)."""
    axes, points, _ = chain.frames(np.zeros(chain.n))
    for i in range(chain.n - 1):
        a, b = axes[i] / np.linalg.norm(axes[i]), axes[i + 1] / np.linalg.norm(axes[i + 1])
        offset = np.linalg.norm(np.cross(points[i + 1] - points[i], a))
        if np.linalg.norm(np.cross(a, b)) < opw.STRUCTURE_TOL and offset < opw.STRUCTURE_TOL:
            where = f"{source}: " if source is not None else ""
            raise KinematicsError(
                f"{where}J{i + 1} and J{i + 2} turn about one axis line (a zero-length link "
                "between them: nothing moves one axis off the other), so they act as one "
                "joint; give the link between them its length")


def chain_from_robot_file(spec: RobotFolderSpec, path: Path) -> Chain:
    """The chain of a ``robot.toml`` (:class:`sim.robots.schema.RobotFolderSpec`) that gives
    a DH table or a URDF.

    Raises:
        KinematicsError: One line naming the file and the key.
    """
    k = spec.kinematics
    where = str(path)
    if k.convention == "urdf":
        if k.urdf is None:
            raise KinematicsError(f"{where}: kinematics.urdf: required with convention = \"urdf\"")
        chain = chain_from_urdf(path.parent / k.urdf)
    else:
        if not k.dh:
            raise KinematicsError(f"{where}: kinematics.dh: required with convention = "
                                  f"\"{k.convention}\" (rows [a_mm, alpha_deg, d_mm, "
                                  "theta_offset_deg])")
        names = ("a_mm", "alpha_deg", "d_mm", "theta_offset_deg")
        for i, row in enumerate(k.dh):
            if len(row) != 4:
                raise KinematicsError(f"{where}: kinematics.dh[{i}]: {len(row)} values; a row is "
                                      "[a_mm, alpha_deg, d_mm, theta_offset_deg]")
            for j, (value, quantity) in enumerate(zip(row, DH_COLUMNS.quantities, strict=True)):
                quantity.read(value, f"{where}: kinematics.dh[{i}][{j}] ({names[j]})",
                              KinematicsError)
        rows = np.array(k.dh, dtype=float)
        _check_angles_in_degrees(rows, where)
        rows[:, 0] /= 1000.0
        rows[:, 2] /= 1000.0
        rows[:, 1] = np.deg2rad(rows[:, 1])
        rows[:, 3] = np.deg2rad(rows[:, 3])
        n = len(rows)
        _check_row_counts(spec, n, where)
        lo = np.full(n, -np.inf)
        hi = np.full(n, np.inf)
        j = spec.joints
        if j.range_deg is not None:
            if len(j.range_deg) != n:
                raise KinematicsError(f"{where}: joints.range_deg: {len(j.range_deg)} rows for "
                                      f"{n} joints")
            for i, r in enumerate(j.range_deg):
                if len(r) != 2:
                    raise KinematicsError(f"{where}: joints.range_deg[{i}]: give [lower, upper]")
                bad = range_problem(r[0], r[1])
                if bad:
                    raise KinematicsError(f"{where}: joints.range_deg[{i}]: {bad}")
            lo, hi = np.deg2rad(np.array(j.range_deg, dtype=float)).T
            bad = turns_problem(lo, hi)
            if bad:
                raise KinematicsError(f"{where}: joints.range_deg: {bad}")
        chain = chain_from_dh(rows, k.convention, name=spec.name, lower=lo, upper=hi)
    return dataclasses.replace(chain, name=spec.name)


#: Angles in radians that a DH table's degrees are never: +-pi/2, +-pi (to 2e-3: 1.57, 3.14).
_RADIAN_ANGLES = (math.pi / 2, math.pi)


def _check_angles_in_degrees(rows: NDArray[np.float64], where: str) -> None:
    """Refuse a DH angle (``alpha_deg``, ``theta_offset_deg``) that is a right or straight
    angle in radians (1.5708, 3.1416): typed in radians, the arm is another arm, and the
    mistake surfaced far away ("no inverse-kinematics solution" on a scenario's path)."""
    for i, row in enumerate(rows):
        for j, name in ((1, "alpha_deg"), (3, "theta_offset_deg")):
            v = float(row[j])
            hit = next((a for a in _RADIAN_ANGLES if abs(abs(v) - a) < 2e-3), None)
            if hit is not None:
                deg = math.copysign(math.degrees(hit), v)
                raise KinematicsError(f"{where}: kinematics.dh[{i}][{j}] ({name}): {v:g} is "
                                      f"{deg:+g} deg in radians; the DH angles are degrees "
                                      f"(give {deg:g})")


def _check_row_counts(spec: RobotFolderSpec, n: int, where: str) -> None:
    """The DH table is the one to blame when the robot file's other per-joint keys agree on
    another number of joints than its rows (a row left out of ``kinematics.dh`` read as
    "joints.range_deg: 6 rows for 5 joints", sending the user to the one key that was right)."""
    j = spec.joints
    counts = {key: len(v) for key, v in (
        ("joints.range_deg", j.range_deg), ("joints.home_deg", j.home_deg),
        ("joints.max_speed_deg_s", j.max_speed_deg_s),
        ("joints.max_accel_deg_s2", j.max_accel_deg_s2),
        ("[[drives]]", spec.drives or None), ("[[links]]", spec.links or None)) if v is not None}
    others = set(counts.values())
    if len(counts) >= 2 and len(others) == 1 and n not in others:
        m = others.pop()
        raise KinematicsError(f"{where}: kinematics.dh: {n} rows, while "
                              f"{', '.join(counts)} give {m} joints: one DH row per joint")


def load_arm(path: str | Path) -> Arm:
    """An arm from a URDF file, a ``robot.toml`` or a folder holding one.

    Raises:
        KinematicsError: One line naming the file and the key or joint: missing file, a DH row
            of the wrong length, an unsupported joint type, limits with lower > upper.
    """
    path = Path(path)
    if path.is_dir():
        path = path / "robot.toml"
    if path.suffix.lower() == ".urdf":
        return arm_from_chain(chain_from_urdf(path), path)
    spec, _ = load_toml(path, RobotFolderSpec, KinematicsError)
    if spec.kinematics.convention is None:
        raise KinematicsError(f"{path}: kinematics.convention: this robot uses one of the "
                              "seeds' families; name it as a robot")
    return arm_from_chain(chain_from_robot_file(spec, path), path)


def is_arm_path(ref: str) -> bool:
    """A robot reference that names an arm given as data (a URDF, or a robot.toml with a DH
    table or a URDF) rather than a shipped robot or a robot folder with one of the seeds' closed
    forms (``[kinematics] family``, :mod:`sim.robots.robotfile`)."""
    p = Path(ref)
    if not (ref.endswith((".urdf", ".toml")) or "/" in ref or p.is_dir()):
        return False
    toml = p / "robot.toml" if p.is_dir() else p
    if toml.suffix == ".toml" and toml.is_file():
        try:
            raw = tomllib.loads(toml.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
            return True  # load_arm reports it
        kin = raw.get("kinematics")
        return not (isinstance(kin, dict) and "family" in kin)
    return True


__all__ = ["Arm", "Solution", "arm_from_chain", "is_arm_path", "load_arm"]
