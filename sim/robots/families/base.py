"""The interface every kinematic family implements.

A kinematic family is one arm structure with its dimensions: the seeds' closed-form forward
kinematics, analytic inverse kinematics, the square Jacobian and the explicit factors of its
determinant, the wrist, the reach bound, and :meth:`KinematicFamily.with_tool` (the same arm
with a straight tool). :class:`sim.robots.registry.RobotSpec` holds its family object; code
that needs something family-specific asks the object (never tests a family name).

Frames: everything is in the seed's base frame 0 (on the J1 axis at the height of J2) and
ends in the seed's tool frame; units are metres and radians. Batched methods take joint
arrays of shape (N, n) and return a matching leading dimension.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError


def annulus_gap(rho: float, r_in: float, r_out: float) -> float:
    """How far (m) a planar distance ``rho`` is outside the annulus [r_in, r_out] (<= 0 inside):
    how far a two-link arm with that reach range misses a point at distance ``rho``."""
    return max(rho - r_out, r_in - rho)


def geometric_from_frames(axes: NDArray[np.float64], points: NDArray[np.float64],
                          T: NDArray[np.float64]) -> NDArray[np.float64]:
    """Geometric Jacobian from joint axes (..., n, 3), points on them (..., n, 3) and the tool
    frame (..., 4, 4): column ``i = [z_i x (p - o_i); z_i]``, shape (..., 6, n)."""
    p = T[..., :3, 3]
    lin = np.cross(axes, p[..., None, :] - points)
    return np.concatenate([np.swapaxes(lin, -1, -2), np.swapaxes(axes, -1, -2)], axis=-2)


class KinematicFamily(ABC):
    """One arm structure and its dimensions (metres).

    Class attributes:
        name: Short label (``"5r"``, ``"fanuc6"``) for listings and messages only.
        n_joints: Number of joints.
        dim_names: Names of the dimensions the family needs.
        wrist_joint: 0-based index of the joint whose axis the flange distance is measured from
            (the tool's reach starts there).
        wrist_centre_index: Index, in :meth:`joint_frames`' points, of the wrist centre.
        approach_column: Column of the seed tool frame that points along the tool (the torch
            axis of a straight tool).
        five_axis: Whether the arm has five axes and holds its tool axis in the vertical plane
            through J1 and the tool point (the 5R family): it cannot take a torch posture out
            of that plane, and the roll about the torch axis is not free.
        reach_free_joints: Joints a reach search varies (J1 and the last joint do not change the
            tcp's distance from the J1 axis).
        joint_symbol: ``"q"`` or ``"theta"``, as the family's seed writes its joints.
    """

    name: ClassVar[str]
    n_joints: ClassVar[int]
    dim_names: ClassVar[tuple[str, ...]]
    wrist_joint: ClassVar[int]
    wrist_centre_index: ClassVar[int]
    approach_column: ClassVar[int]
    reach_free_joints: ClassVar[tuple[int, ...]]
    joint_symbol: ClassVar[str]
    #: Whether the workspace section also scatters the tcp (5-axis arms: the tool point, not
    #: the wrist, is what a 5-axis task constrains).
    section_shows_tcp: ClassVar[bool] = False
    five_axis: ClassVar[bool] = False

    def __init__(self, dims: Mapping[str, float]) -> None:
        missing = [k for k in self.dim_names if k not in dims]
        extra = [k for k in dims if k not in self.dim_names]
        if missing or extra:
            raise KinematicsError(
                f"{self.name} kinematics needs dimensions {', '.join(self.dim_names)}; "
                + (f"missing {', '.join(missing)}" if missing else f"unknown {', '.join(extra)}"))
        self._dims = {k: float(dims[k]) for k in self.dim_names}

    # ------------------------------------------------------------------ data
    @property
    def dims(self) -> dict[str, float]:
        """The dimensions by name, m (a copy)."""
        return dict(self._dims)

    def __eq__(self, other: object) -> bool:
        return type(other) is type(self) and self._state() == other._state()  # type: ignore[attr-defined]

    def __hash__(self) -> int:
        return hash((type(self), tuple(sorted(self._state().items()))))

    def _state(self) -> dict[str, float]:
        return dict(self._dims)

    def __repr__(self) -> str:
        body = ", ".join(f"{k}={v!r}" for k, v in self._state().items())
        return f"{type(self).__name__}({body})"

    # ------------------------------------------------------------------ forward
    @abstractmethod
    def joint_frames(self, Q: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                            NDArray[np.float64],
                                                            NDArray[np.float64]]:
        """Joint axes (N, n, 3), a point on each axis (N, n, 3) and the tool frame (N, 4, 4).

        Args:
            Q: Joint values, rad, shape (N, n).
        """

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """Seed tool frame in frame 0: (4, 4) or (N, 4, 4) for q of shape (n,) or (N, n)."""
        Q = np.asarray(q, dtype=float)
        T = self.joint_frames(np.atleast_2d(Q))[2]
        return T[0] if Q.ndim == 1 else T

    def jacobian(self, q: ArrayLike) -> NDArray[np.float64]:
        """Geometric Jacobian of the seed tool frame in frame 0, rows ``[v; omega]``:
        (6, n) or (N, 6, n) for q of shape (n,) or (N, n)."""
        Q = np.asarray(q, dtype=float)
        J = geometric_from_frames(*self.joint_frames(np.atleast_2d(Q)))
        return J[0] if Q.ndim == 1 else J

    @abstractmethod
    def home_approach(self) -> NDArray[np.float64]:
        """Approach axis of the seed tool frame at q = 0, in frame 0, shape (3,)."""

    # ------------------------------------------------------------------ inverse
    @abstractmethod
    def ik(self, T: NDArray[np.float64], current: NDArray[np.float64]
           ) -> list[tuple[NDArray[np.float64], str]]:
        """Every analytic solution ``(q, branch)`` for a seed tool-frame pose ``T`` (4, 4).

        Args:
            T: Pose of the seed tool frame in frame 0.
            current: Current configuration, rad, (n,): decides the joints a singular pose
                leaves undetermined (a :class:`sim.errors.SingularityWarning` says so).

        Raises:
            UnreachableError: Out of reach (``distance`` in metres) or, for arms with fewer
                than six axes, an orientation the arm cannot take.
        """

    def ik_branches(self, T: NDArray[np.float64], current: NDArray[np.float64]
                    ) -> list[NDArray[np.float64]]:
        """The joints of :meth:`ik`'s solutions, at least one per branch (whole-turn variants
        may be left out: path inverse kinematics picks each joint's turn itself); a family
        whose :meth:`ik` expands turns overrides this with a cheaper one.

        Raises:
            UnreachableError: As :meth:`ik`.
        """
        return [q for q, _ in self.ik(T, current)]

    def ik_continue(self, T: NDArray[np.float64], current: NDArray[np.float64]
                    ) -> NDArray[np.float64] | None:
        """The solution that continues ``current`` to the nearby pose ``T``, found locally, or
        None to have path inverse kinematics search every branch (:meth:`ik_branches`). A
        closed form needs no shortcut; a numeric solver's global search costs tens of Newton
        runs per pose, so it overrides this."""
        return None

    # ------------------------------------------------------------------ Jacobian
    @abstractmethod
    def task_jacobian(self, J: NDArray[np.float64]) -> NDArray[np.float64]:
        """The square Jacobian (manipulability, singularities) from the geometric one.

        Args:
            J: Geometric Jacobian, shape (..., 6, n).
        """

    @abstractmethod
    def singular_factors(self, Q: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        """The explicit factors of the task Jacobian's determinant, each shape (...,).

        Keys among ``wrist``, ``elbow``, ``shoulder``; each factor vanishes on that singularity.
        """

    @abstractmethod
    def singular_curves(self, T2: NDArray[np.float64], T3: NDArray[np.float64]
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64], str, str]:
        """``(elbow, shoulder, elbow_label, shoulder_label)`` over a (J2, J3) grid, rad.

        The workspace map draws each factor's zero line.
        """

    # ------------------------------------------------------------------ tool and reach
    @property
    @abstractmethod
    def wrist_to_tcp(self) -> float:
        """Distance from the wrist (``wrist_joint``'s axis) to the tool point along the
        approach axis, m."""

    @abstractmethod
    def with_tool(self, wrist_to_tcp: float) -> KinematicFamily:
        """The same arm with its tool point ``wrist_to_tcp`` (m) out along the approach axis
        from the wrist (a straight tool: the tcp stays on the flange axis)."""

    @abstractmethod
    def tool_from_home_tcp(self, p: NDArray[np.float64]) -> KinematicFamily:
        """The same arm with the tool point where ``p`` (m, (3,), frame 0) says it is at q = 0.
        """

    @abstractmethod
    def reach(self) -> float:
        """Upper bound of the wrist's distance from frame 0: the sum of the link lengths, m.

        (:func:`sim.robots.kinematics.workspace.compute_reach` finds the reach inside the joint ranges.)
        """

    # ------------------------------------------------------------------ tcp frame
    def check_tcp_offset(self, robot: str, offset: NDArray[np.float64]) -> None:
        """Raise :class:`KinematicsError` if the analytic IK cannot handle this constant
        seed-tool-frame -> tcp transform (4, 4). Six-axis arms handle any offset."""

    def default_orientation(self, R_home: NDArray[np.float64], p: NDArray[np.float64]
                            ) -> NDArray[np.float64]:
        """The tool orientation ``cellsim ik`` uses when none is given: the home one (3, 3)."""
        return R_home

    def reachable_alpha(self, p: NDArray[np.float64], alpha: float, beta: float) -> float:
        """Z-Y-X Euler angle alpha (rad) the arm can take at position ``p`` (m) with ``beta``;
        six-axis arms take any."""
        return alpha
