"""The FANUC 6-axis family (LR Mate 200iC/5L): seed 004.

Seed 004 Table 1 modified DH (Khalil-Dombre) with dimensions ``d2, d3, d4, R4, R6``; the tool
frame E is frame 6 moved ``R6 + r`` along z6 (``r`` the tool length), identical to seed 004
eq. (6)-(7) (:func:`sim.robots.kinematics.closed_form.fk_fanuc6`). The approach axis is ``a = z6``.

Inverse kinematics: Pieper's method (seed 004 eq. 9-18) on the wrist centre
``w = p - (R6 + r) a`` (the seed's eq. 9-10 mix R6 into the position equations; we subtract it
along the approach vector a, as eq. 3 implies). ``theta1 = atan2(w_y, w_x)`` or ``+ pi``
(eq. 10); with ``A = c1 w_x + s1 w_y - d2`` (eq. 11), the J3 equation reduces to
``R4 s3 + d4 c3 = (A^2 + w_z^2 - d3^2 - R4^2 - d4^2) / (2 d3)`` (two roots: elbow up/down;
equivalent to eq. 14's quadratic in C23) and ``A + i w_z = (m + i (d3 + n)) e^{i theta2}`` with
``m = R4 c3 - d4 s3``, ``n = R4 s3 + d4 c3`` (eq. 12-15). The wrist: ``3R6 = Rx(90deg)
Rz(theta4) Ry(theta5) Rz(theta6)``, i.e. Z-Y-Z Euler angles (eq. 16-18), with the flip
``(theta4 + pi, -theta5, theta6 + pi)``. Up to 8 solutions.

Singularities (seed 004 eq. 22-25): ``det J = -d3 * (R4 c3 - d4 s3) * rho_w * s5`` where
``rho_w = d2 - d3 s2 + R4 c23 - d4 s23`` is the signed distance of the wrist centre from the J1
axis. Wrist: ``s5`` (eq. 23), elbow: ``R4 c3 - d4 s3`` (eq. 24, zero at
``theta3 = atan2(R4, d4)`` and that +pi), shoulder: ``rho_w`` (eq. 25; as printed, eq. 25 has
theta2 of the opposite sign, see :mod:`sim.robots.kinematics.jacobian`).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from sim.core.rotations import rot_x, rot_y, rot_z
from sim.core.text import mm_text
from sim.errors import SingularityWarning, UnreachableError
from sim.robots.families.base import KinematicFamily, annulus_gap
from sim.robots.kinematics.closed_form import fk_fanuc6

#: |sin theta5| or distance of the wrist centre from the J1 axis (m) below which the pose is
#: singular.
SINGULAR_TOL = 1e-9


def _mdh_batch(alpha: float, d: float, theta: NDArray[np.float64], r: float) -> NDArray[np.float64]:
    """Vectorized :func:`sim.robots.kinematics.closed_form.mdh_transform` over ``theta`` (N,): (N, 4, 4)."""
    T = np.zeros(theta.shape + (4, 4))
    ca, sa = np.cos(alpha), np.sin(alpha)
    ct, st = np.cos(theta), np.sin(theta)
    T[..., 0, 0], T[..., 0, 1], T[..., 0, 3] = ct, -st, d
    T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = ca * st, ca * ct, -sa, -r * sa
    T[..., 2, 0], T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = sa * st, sa * ct, ca, r * ca
    T[..., 3, 3] = 1.0
    return T


class Fanuc6(KinematicFamily):
    """Seed 004's 6-axis arm with a spherical wrist (FANUC LR Mate 200iC/5L).

    Args:
        dims: ``d2``, ``d3``, ``d4``, ``R4``, ``R6`` (seed 004 Table 1), m.
        tool_length: Tool length ``r`` beyond R6 along z6, m.
    """

    name: ClassVar[str] = "fanuc6"
    n_joints: ClassVar[int] = 6
    dim_names: ClassVar[tuple[str, ...]] = ("d2", "d3", "d4", "R4", "R6")
    wrist_joint: ClassVar[int] = 4
    wrist_centre_index: ClassVar[int] = 4
    approach_column: ClassVar[int] = 2
    reach_free_joints: ClassVar[tuple[int, ...]] = (1, 2, 3, 4)
    joint_symbol: ClassVar[str] = "theta"

    def __init__(self, dims: Mapping[str, float], tool_length: float = 0.0) -> None:
        super().__init__(dims)
        self.tool_length = float(tool_length)

    def _state(self) -> dict[str, float]:
        return {**self._dims, "tool_length": self.tool_length}

    # ------------------------------------------------------------------ forward
    def joint_frames(self, Q: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                            NDArray[np.float64],
                                                            NDArray[np.float64]]:
        N = Q.shape[0]
        axes = np.empty((N, self.n_joints, 3))
        points = np.empty((N, self.n_joints, 3))
        T = np.tile(np.eye(4), (N, 1, 1))
        d = self._dims
        h = np.pi / 2
        rows = [(0.0, 0.0, 0.0, 0.0), (h, d["d2"], h, 0.0), (0.0, d["d3"], 0.0, 0.0),
                (h, d["d4"], 0.0, d["R4"]), (-h, 0.0, 0.0, 0.0), (h, 0.0, 0.0, 0.0)]
        for i, (alpha, dd, theta0, r) in enumerate(rows):
            T = T @ _mdh_batch(alpha, dd, theta0 + Q[:, i], r)
            axes[:, i] = T[:, :3, 2]
            points[:, i] = T[:, :3, 3]
        E = np.eye(4)
        E[2, 3] = self._dims["R6"] + self.tool_length
        return axes, points, T @ E

    def home_approach(self) -> NDArray[np.float64]:
        return fk_fanuc6(np.zeros(self.n_joints), self._dims)[0][:, 2]

    # ------------------------------------------------------------------ inverse
    def ik(self, T: NDArray[np.float64], current: NDArray[np.float64]
           ) -> list[tuple[NDArray[np.float64], str]]:
        dims = self._dims
        d2, d3, d4, R4, R6 = dims["d2"], dims["d3"], dims["d4"], dims["R4"], dims["R6"]
        R, p = T[:3, :3], T[:3, 3]
        w = p - (R6 + self.tool_length) * R[:, 2]
        L = float(np.hypot(R4, d4))
        phi = float(np.arctan2(d4, R4))
        rho = float(np.hypot(w[0], w[1]))
        if rho > SINGULAR_TOL:
            t1_base = float(np.arctan2(w[1], w[0]))
        else:
            t1_base = float(current[0])
            warnings.warn("6-axis IK: wrist centre on the J1 axis (shoulder singularity): J1 kept "
                          f"at its current value {np.rad2deg(t1_base):.3f} deg",
                          SingularityWarning, stacklevel=3)
        sols: list[tuple[NDArray[np.float64], str]] = []
        gaps = []
        for shoulder, t1 in (("front", t1_base), ("back", t1_base + np.pi)):
            c1, s1 = np.cos(t1), np.sin(t1)
            A = c1 * w[0] + s1 * w[1] - d2
            gaps.append(annulus_gap(float(np.hypot(A, w[2])), abs(d3 - L), d3 + L))
            K = (A**2 + w[2] ** 2 - d3**2 - L**2) / (2 * d3 * L)
            if abs(K) > 1.0 + 1e-12:
                continue
            asK = float(np.arcsin(np.clip(K, -1.0, 1.0)))
            for elbow, t3 in (("up", asK - phi), ("down", np.pi - asK - phi)):
                m = R4 * np.cos(t3) - d4 * np.sin(t3)
                n = R4 * np.sin(t3) + d4 * np.cos(t3)
                t2 = np.arctan2(w[2], A) - np.arctan2(d3 + n, m)
                R03 = (rot_z(t1) @ rot_x(np.pi / 2) @ rot_z(np.pi / 2 + t2) @ rot_z(t3))
                W = rot_x(np.pi / 2).T @ R03.T @ R  # = Rz(t4) Ry(t5) Rz(t6)
                s5 = float(np.hypot(W[0, 2], W[1, 2]))
                if s5 < SINGULAR_TOL:
                    t5 = 0.0 if W[2, 2] > 0 else np.pi
                    t4 = float(current[3])
                    X = (rot_z(t4) @ rot_y(t5)).T @ W
                    t6 = float(np.arctan2(X[1, 0], X[0, 0]))
                    warnings.warn("6-axis IK: wrist singularity (theta5 = 0, J4 and J6 aligned): "
                                  f"J4 kept at its current value {np.rad2deg(t4):.3f} deg",
                                  SingularityWarning, stacklevel=3)
                    sols.append((np.array([t1, t2, t3, t4, t5, t6]),
                                 f"{shoulder}/{elbow}/singular"))
                    continue
                t4 = float(np.arctan2(W[1, 2], W[0, 2]))
                t5 = float(np.arctan2(s5, W[2, 2]))
                t6 = float(np.arctan2(W[2, 1], -W[2, 0]))
                sols.append((np.array([t1, t2, t3, t4, t5, t6]), f"{shoulder}/{elbow}/noflip"))
                sols.append((np.array([t1, t2, t3, t4 + np.pi, -t5, t6 + np.pi]),
                             f"{shoulder}/{elbow}/flip"))
        if not sols:
            gap = min(gaps)
            raise UnreachableError(
                f"pose unreachable: the wrist centre is {mm_text(gap)} mm outside the arm's "
                f"reach (J2 to wrist centre between {1e3 * abs(d3 - L):.1f} and "
                f"{1e3 * (d3 + L):.1f} mm)", gap)
        return sols

    # ------------------------------------------------------------------ Jacobian
    def task_jacobian(self, J: NDArray[np.float64]) -> NDArray[np.float64]:
        """The 6 x 6 geometric Jacobian itself."""
        return J

    def singular_factors(self, Q: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        """``wrist`` = sin theta5, ``elbow`` = (R4 c3 - d4 s3) / sqrt(R4^2 + d4^2)
        (dimensionless), ``shoulder`` = rho_w (m)."""
        d = self._dims
        q2, q3 = Q[..., 1], Q[..., 2]
        L = np.hypot(d["R4"], d["d4"])
        return {
            "wrist": np.sin(Q[..., 4]),
            "elbow": (d["R4"] * np.cos(q3) - d["d4"] * np.sin(q3)) / L,
            "shoulder": (d["d2"] - d["d3"] * np.sin(q2) + d["R4"] * np.cos(q2 + q3)
                         - d["d4"] * np.sin(q2 + q3)),
        }

    def singular_curves(self, T2: NDArray[np.float64], T3: NDArray[np.float64]
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64], str, str]:
        d = self._dims
        L = np.hypot(d["R4"], d["d4"])
        elbow = (d["R4"] * np.cos(T3) - d["d4"] * np.sin(T3)) / L
        shoulder = (d["d2"] - d["d3"] * np.sin(T2) + d["R4"] * np.cos(T2 + T3)
                    - d["d4"] * np.sin(T2 + T3))
        return (elbow, shoulder, "eq. 24: R4 c3 - d4 s3 = 0 (elbow)",
                "eq. 25: wrist centre on J1 axis (shoulder)")

    # ------------------------------------------------------------------ tool and reach
    @property
    def wrist_to_tcp(self) -> float:
        return self._dims["R6"] + self.tool_length

    def with_tool(self, wrist_to_tcp: float) -> Fanuc6:
        return Fanuc6(self._dims, tool_length=wrist_to_tcp - self._dims["R6"])

    def tool_from_home_tcp(self, p: NDArray[np.float64]) -> Fanuc6:
        d = self._dims
        return Fanuc6(d, tool_length=float(p[0] - d["d2"] - d["R4"] - d["R6"]))

    def reach(self) -> float:
        d = self._dims
        return abs(d["d2"]) + abs(d["d3"]) + float(np.hypot(d["R4"], d["d4"]))
