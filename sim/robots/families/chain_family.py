"""The kinematic family of an arm given as data (a DH table or a URDF, :mod:`sim.robots.arm`).

The seed tool frame is the arm's flange frame (z out of the flange, the approach axis) moved
``tool`` metres along its z axis: a straight tool, as for the seeds' families. Inverse
kinematics is the arm's: the OPW closed form (all branches) when the arm is ortho-parallel with
a spherical wrist, the offset-wrist closed form (all branches) for a UR-type arm, seed 000's 5R
closed form for a 5-axis arm of that structure, the numeric solver otherwise. Singular factors:
for an OPW arm ``wrist`` = sin(theta5), ``elbow`` = sin(theta3 + atan2(a2, c3)) (upper arm and
the line to the wrist centre aligned), ``shoulder`` = the wrist centre's distance from the J1
axis less ``|b|`` (m), in the model's angles (``theta = sign * q - offset``); for an
offset-wrist arm those of :func:`sim.robots.kinematics.offset_wrist.singular_factors` (their
product is ``det J`` up to a constant); a numeric arm has none beyond the Jacobian's smallest
singular value.

Along a path (:func:`sim.robots.kinematics.ik.ik_path`) a closed form lists every branch at
every point (microseconds to a millisecond), and the path takes the one nearest the point
before; a numeric arm continues from the point before by one local Newton run
(:meth:`ChainFamily.ik_continue`) and searches globally only where that leaves its branch.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from sim.core.text import mm_text
from sim.errors import KinematicsError, UnreachableError
from sim.robots.families.base import KinematicFamily

#: Largest joint change, rad, a numeric arm's path point may take from the one before when
#: found locally (:meth:`ChainFamily.ik_continue`); a larger one is searched globally.
CONTINUE_STEP = 0.1


class ChainFamily(KinematicFamily):
    """A 6-axis (or other) arm from its chain (module docstring)."""

    name: ClassVar[str] = "chain"
    dim_names: ClassVar[tuple[str, ...]] = ("tool",)
    approach_column: ClassVar[int] = 2
    joint_symbol: ClassVar[str] = "q"

    def __init__(self, arm, tool: float = 0.0) -> None:  # arm: sim.robots.arm.Arm
        self.arm = arm
        self._dims = {"tool": float(tool)}
        n = arm.chain.n
        self.n_joints = n  # type: ignore[misc]
        self.wrist_joint = max(n - 2, 0)  # type: ignore[misc]
        self.wrist_centre_index = max(n - 2, 0)  # type: ignore[misc]
        self.reach_free_joints = tuple(range(1, n - 1))  # type: ignore[misc]

    def _state(self) -> dict:
        return {"tool": self._dims["tool"], "arm": str(self.arm.source), "name": self.arm.name}

    def __hash__(self) -> int:
        return hash((type(self), self.arm.name, str(self.arm.source), self._dims["tool"]))

    def _tool_T(self) -> NDArray[np.float64]:
        T = np.eye(4)
        T[2, 3] = self._dims["tool"]
        return T

    # ------------------------------------------------------------------ forward
    def joint_frames(self, Q):
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        n = self.arm.chain.n
        axes = np.empty((len(Q), n, 3))
        points = np.empty((len(Q), n, 3))
        T = np.empty((len(Q), 4, 4))
        tool = self._tool_T()
        for k, q in enumerate(Q):
            a, p, F = self.arm.chain.frames(q)
            axes[k], points[k], T[k] = a, p, F @ tool
        return axes, points, T

    def home_approach(self) -> NDArray[np.float64]:
        return self.arm.chain.fk(np.zeros(self.arm.chain.n))[:3, 2].copy()

    # ------------------------------------------------------------------ inverse
    def _flange(self, T) -> NDArray[np.float64]:
        return np.asarray(T, dtype=float) @ np.linalg.inv(self._tool_T())

    def _none(self, flange: NDArray[np.float64]) -> UnreachableError:
        """No solution: for an OPW arm, how far the wrist centre is out of reach (as the
        shipped FANUC family says it)."""
        head = f"{self.arm.name}: no inverse-kinematics solution ({self.arm.solver} solver)"
        if self.arm.opw is not None:
            from sim.robots.kinematics.opw import reach_gap

            gap, inner, outer = reach_gap(self.arm.opw, flange)
            if gap > 1e-9:
                return UnreachableError(
                    f"{head}: the wrist centre is {mm_text(gap)} mm outside the arm's reach "
                    f"(J2 to wrist centre between {mm_text(inner)} and {mm_text(outer)} mm)",
                    gap)
        return UnreachableError(head, 0.0)

    def ik(self, T, current):
        # an offset-wrist arm gives its branches only: solve_ik lists each joint's turns (its
        # UR-style +-360 deg ranges give each branch 32 of them)
        flange = self._flange(T)
        sols = self.arm.labelled_branches(flange, current)
        if not sols:
            raise self._none(flange)
        return sols

    def ik_continue(self, T, current):
        """A numeric arm's next path point: damped Newton from ``current``, kept when it
        converges within :data:`CONTINUE_STEP` of it on every joint (the branch it is on);
        otherwise None (the global search decides). A closed-form arm returns None: its
        "global search" is the closed form itself, every branch at once, as cheap as a
        Newton run, and the path picks among them exactly as before."""
        if self.arm.solver != "numeric":
            return None
        from sim.robots.kinematics.numeric_ik import solve_one

        cur = np.asarray(current, dtype=float)
        q, err = solve_one(self.arm.chain, self._flange(T), cur)
        if err < 1e-12 and float(np.max(np.abs(q - cur))) <= CONTINUE_STEP:
            return q
        return None

    def ik_branches(self, T, current):
        flange = self._flange(T)
        sols = self.arm.branches(flange, current)
        if not sols:
            raise self._none(flange)
        return sols

    # ------------------------------------------------------------------ Jacobian
    def task_jacobian(self, J):
        return J

    def singular_factors(self, Q):
        if self.arm.offset is not None:
            from sim.robots.kinematics.offset_wrist import singular_factors

            return singular_factors(self.arm.offset, Q)
        p = self.arm.opw
        if p is None:
            return {}
        th = np.asarray(Q, dtype=float) * np.asarray(p.signs, dtype=float) - np.asarray(
            p.offsets, dtype=float)
        t2, t3, t5 = th[..., 1], th[..., 2], th[..., 4]
        psi3 = np.arctan2(p.a2, p.c3)
        k = np.hypot(p.a2, p.c3)
        rho = p.a1 + p.c2 * np.sin(t2) + k * np.sin(t2 + t3 + psi3)
        return {"wrist": np.sin(t5), "elbow": np.sin(t3 + psi3), "shoulder": np.abs(rho)}

    def singular_curves(self, T2, T3):
        raise KinematicsError(f"{self.arm.name}: the workspace map's singular curves are drawn "
                              "for the seeds' families only")

    # ------------------------------------------------------------------ tool and reach
    def _flange_axial(self) -> float:
        """Wrist (the ``wrist_joint`` axis anchor) to flange along the approach axis at q = 0."""
        a, p, F = self.arm.chain.frames(np.zeros(self.arm.chain.n))
        return float((F[:3, 3] - p[self.wrist_joint]) @ F[:3, 2])

    @property
    def wrist_to_tcp(self) -> float:
        return self._flange_axial() + self._dims["tool"]

    def with_tool(self, wrist_to_tcp: float) -> ChainFamily:
        return ChainFamily(self.arm, wrist_to_tcp - self._flange_axial())

    def tool_from_home_tcp(self, p: NDArray[np.float64]) -> ChainFamily:
        F = self.arm.chain.fk(np.zeros(self.arm.chain.n))
        return ChainFamily(self.arm, float((np.asarray(p, dtype=float) - F[:3, 3]) @ F[:3, 2]))

    def reach(self) -> float:
        c = self.arm.chain
        return float(sum(np.linalg.norm(o[:3, 3]) for o in c.origins)
                     + np.linalg.norm(c.flange[:3, 3]) + abs(self._dims["tool"]))


__all__ = ["ChainFamily"]
