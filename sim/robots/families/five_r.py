"""The 5R family (FANUC LR Mate 100iB, the 5R welding robot): seed 000.

Seed 000 Table 1 screw axes, product of exponentials (identical to seed 000 eq. 5,
:func:`sim.robots.kinematics.closed_form.fk_5r`); dimensions ``l1, d1, l2, l3`` (l3 = J4 axis to the tool
point). The seed tool frame's x axis is the approach axis (the torch axis).

Inverse kinematics: seed 000 eq. (13)-(17), with eq. (14) derived again (it is garbled as
printed). From eq. (5), with ``r = c1 p_x + s1 p_y`` the signed distance of the tool point from
the J1 axis in the arm plane, the wrist point (on the J4 axis) is
``w = p - l3 (c1 c_beta, s1 c_beta, -s_beta)`` and, relative to J2,

    u = r - l1 - l3 cos(beta) = d1 sin q2 + l2 cos(q2 + q3)
    v = p_z + l3 sin(beta)    = d1 cos q2 - l2 sin(q2 + q3)

a planar two-link arm whose first link d1 points "up" at q2 = 0. Squaring and adding:
``u^2 + v^2 = d1^2 + l2^2 - 2 d1 l2 sin q3``, hence (the corrected eq. 14)

    sin q3 = (d1^2 + l2^2 - u^2 - v^2) / (2 d1 l2),  q3 = atan2(sin q3, +-sqrt(1 - sin^2 q3))

(the sign of ``cos q3`` picks the elbow; the seed's eq. 15 keeps ``+``). With ``a = d1 - l2 sin q3``
and ``b = l2 cos q3``: ``v + i u = (a + i b) e^{i q2}``, so ``q2 = atan2(u, v) - atan2(b, a)``
(eq. 16), then ``q4 = beta - q2 - q3`` and ``q5 = gamma`` (eq. 17). The orientation of a 5-axis
tool is ``R = Rz(q1) Ry(q2+q3+q4) Rx(q5)`` (eq. 6): alpha is not free, the tool x axis lies in
the arm plane through the J1 axis. The shoulder-flip solution uses ``q1 + pi`` with the
equivalent Euler triple ``(alpha + pi, pi - beta, gamma + pi)`` of the same rotation.

Singularities (seed 000): ``det J_task = reach * d1 * l2 * c3`` with
``reach = l1 + d1 s2 + l2 c23 + l3 c234`` (tool point distance from the J1 axis, signed) and
``c3 = cos q3`` (elbow stretched when ``q3 = +-90 deg``).
"""

from __future__ import annotations

import warnings
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.core.rotations import (
    euler_zyx_to_matrix,
    make_transform,
    matrix_to_euler_zyx,
    rot_z,
    wrap_to_pi,
)
from sim.core.text import mm_text
from sim.errors import KinematicsError, SingularityWarning, UnreachableError
from sim.robots.families.base import KinematicFamily, annulus_gap
from sim.robots.kinematics.closed_form import fk_5r

#: Distance from the J1 axis (m) below which the pose is singular.
SINGULAR_TOL = 1e-9

#: A requested tool x axis at most this far (sine of the angle, 0.05 deg) out of the arm plane
#: is accepted and the solution takes the nearest reachable orientation (the in-plane part);
#: typed-in or rounded angles are never exactly in the plane.
PLANE_TOL = float(np.sin(np.deg2rad(0.05)))


def rodrigues(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation by ``angle`` (rad, shape (...)) about unit ``axis`` (shape (3,)): (..., 3, 3)."""
    k = np.asarray(axis, dtype=float)
    a = np.asarray(angle, dtype=float)[..., None, None]
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * (K @ K)


def screw_table_5r(dims: dict[str, float]) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                     NDArray[np.float64]]:
    """Seed 000 Table 1: joint axes ``k`` (5, 3), points ``p`` (5, 3) at q = 0, and tool point (3,).

    All in frame 0, metres. Row 6 of the table is the tool point ``(l1+l2+l3, 0, d1)``.
    """
    l1, d1, l2, l3 = dims["l1"], dims["d1"], dims["l2"], dims["l3"]
    k = np.array([[0, 0, 1], [0, 1, 0], [0, 1, 0], [0, 1, 0], [1, 0, 0]], dtype=float)
    p = np.array([[0, 0, 0], [l1, 0, 0], [l1, 0, d1], [l1 + l2, 0, d1], [l1 + l2, 0, d1]],
                 dtype=float)
    return k, p, np.array([l1 + l2 + l3, 0.0, d1])


class FiveR(KinematicFamily):
    """Seed 000's 5-axis arm: J1 vertical, J2-J4 parallel horizontal, J5 along the tool.

    Args:
        dims: ``l1`` (J1 to J2 offset), ``d1`` (upper arm), ``l2`` (forearm), ``l3`` (J4 axis to
            the tool point), m.
    """

    name: ClassVar[str] = "5r"
    n_joints: ClassVar[int] = 5
    dim_names: ClassVar[tuple[str, ...]] = ("l1", "d1", "l2", "l3")
    wrist_joint: ClassVar[int] = 3
    wrist_centre_index: ClassVar[int] = 3
    approach_column: ClassVar[int] = 0
    reach_free_joints: ClassVar[tuple[int, ...]] = (1, 2, 3)
    joint_symbol: ClassVar[str] = "q"
    section_shows_tcp: ClassVar[bool] = True
    five_axis: ClassVar[bool] = True

    # ------------------------------------------------------------------ forward
    def joint_frames(self, Q: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                            NDArray[np.float64],
                                                            NDArray[np.float64]]:
        N = Q.shape[0]
        axes = np.empty((N, self.n_joints, 3))
        points = np.empty((N, self.n_joints, 3))
        k, p, tool = screw_table_5r(self._dims)
        G = np.tile(np.eye(4), (N, 1, 1))
        for i in range(5):
            axes[:, i] = G[:, :3, :3] @ k[i]
            points[:, i] = (G[:, :3, :3] @ p[i]) + G[:, :3, 3]
            R = rodrigues(k[i], Q[:, i])
            E = make_transform(R, p[i] - (R @ p[i]))
            G = G @ E
        T = G @ make_transform(np.eye(3), tool)
        return axes, points, T

    def home_approach(self) -> NDArray[np.float64]:
        return fk_5r(np.zeros(self.n_joints), self._dims)[0][:, 0]

    # ------------------------------------------------------------------ inverse
    def ik(self, T: NDArray[np.float64], current: NDArray[np.float64]
           ) -> list[tuple[NDArray[np.float64], str]]:
        d = self._dims
        l1, d1, l2, l3 = d["l1"], d["d1"], d["l2"], d["l3"]
        q1_current = float(current[0])
        R, p = T[:3, :3], T[:3, 3]
        rho = float(np.hypot(p[0], p[1]))
        x_h = float(np.hypot(R[0, 0], R[1, 0]))  # horizontal part of the tool x axis
        if rho > SINGULAR_TOL:
            base = float(np.arctan2(p[1], p[0]))
        elif x_h > SINGULAR_TOL:
            base = float(np.arctan2(R[1, 0], R[0, 0]))
        else:
            base = float(q1_current)
            warnings.warn("5-axis IK: tool point and tool x axis on the J1 axis (singular): "
                          f"J1 kept at its current value {np.rad2deg(base):.3f} deg",
                          SingularityWarning, stacklevel=3)
        # The tool x axis must lie in the arm plane (eq. 6: alpha = q1 or q1 + pi).
        normal = np.array([-np.sin(base), np.cos(base), 0.0])
        off_plane = float(R[:, 0] @ normal)
        if abs(off_plane) > PLANE_TOL:
            raise UnreachableError(
                f"orientation not reachable by a 5-axis arm: the tool x axis is "
                f"{np.rad2deg(np.arcsin(min(1.0, abs(off_plane)))):.4f} deg out of the vertical "
                "plane through the J1 axis and the tool point (alpha is implied by the position; "
                f"up to {np.rad2deg(np.arcsin(PLANE_TOL)):.2f} deg is accepted)",
                float("nan"))
        sols: list[tuple[NDArray[np.float64], str]] = []
        gaps = []
        for shoulder, q1 in (("front", base), ("back", base + np.pi)):
            M = rot_z(q1).T @ R  # = Ry(beta) Rx(gamma)
            beta = float(np.arctan2(-M[2, 0], M[0, 0]))
            gamma = float(np.arctan2(-M[1, 2], M[1, 1]))
            r = float(np.cos(q1) * p[0] + np.sin(q1) * p[1])
            u = r - l1 - l3 * np.cos(beta)
            v = p[2] + l3 * np.sin(beta)
            s3 = (d1**2 + l2**2 - u**2 - v**2) / (2 * d1 * l2)
            gaps.append(annulus_gap(float(np.hypot(u, v)), abs(d1 - l2), d1 + l2))
            if abs(s3) > 1.0 + 1e-12:
                continue
            s3 = float(np.clip(s3, -1.0, 1.0))
            for elbow, sign in (("up", 1.0), ("down", -1.0)):
                c3 = sign * np.sqrt(1.0 - s3**2)
                q3 = np.arctan2(s3, c3)
                a, b = d1 - l2 * s3, l2 * c3
                q2 = np.arctan2(u, v) - np.arctan2(b, a)
                q4 = beta - q2 - q3
                sols.append((np.array([q1, q2, q3, q4, gamma]), f"{shoulder}/{elbow}"))
        if not sols:
            gap = min(gaps)
            raise UnreachableError(
                f"pose unreachable: the wrist point (J4 axis) is {mm_text(gap)} mm outside the "
                f"arm's reach (J2 to J4 between {1e3 * abs(d1 - l2):.1f} and "
                f"{1e3 * (d1 + l2):.1f} mm)", gap)
        return sols

    # ------------------------------------------------------------------ Jacobian
    def task_jacobian(self, J: NDArray[np.float64]) -> NDArray[np.float64]:
        """Jacobian of seed 000's task vector ``[p_x, p_y, p_z, beta_y, gamma_x]`` (eq. 7-8),
        (..., 5, 5): ``beta = q2 + q3 + q4``, ``gamma = q5`` (``alpha = q1`` is not free)."""
        out = np.zeros(J.shape[:-2] + (5, 5))
        out[..., :3, :] = J[..., :3, :]
        out[..., 3, 1:4] = 1.0  # beta = q2 + q3 + q4
        out[..., 4, 4] = 1.0  # gamma = q5
        return out

    def singular_factors(self, Q: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        d = self._dims
        q2, q3, q4 = Q[..., 1], Q[..., 2], Q[..., 3]
        return {
            "elbow": np.cos(q3),
            "shoulder": (d["l1"] + d["d1"] * np.sin(q2) + d["l2"] * np.cos(q2 + q3)
                         + d["l3"] * np.cos(q2 + q3 + q4)),
        }

    def singular_curves(self, T2: NDArray[np.float64], T3: NDArray[np.float64]
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64], str, str]:
        d = self._dims
        elbow = np.cos(T3)
        shoulder = d["l1"] + d["d1"] * np.sin(T2) + d["l2"] * np.cos(T2 + T3)
        return elbow, shoulder, "cos q3 = 0 (elbow stretched)", "wrist point on J1 axis (shoulder)"

    # ------------------------------------------------------------------ tool and reach
    @property
    def wrist_to_tcp(self) -> float:
        return self._dims["l3"]

    def with_tool(self, wrist_to_tcp: float) -> FiveR:
        return FiveR({**self._dims, "l3": wrist_to_tcp})

    def tool_from_home_tcp(self, p: NDArray[np.float64]) -> FiveR:
        d = self._dims
        return FiveR({**d, "l3": float(p[0] - d["l1"] - d["l2"])})

    def reach(self) -> float:
        d = self._dims
        return abs(d["l1"]) + abs(d["d1"]) + abs(d["l2"])

    # ------------------------------------------------------------------ tcp frame
    def check_tcp_offset(self, robot: str, offset: NDArray[np.float64]) -> None:
        off = offset[:3, 3]
        if np.hypot(off[1], off[2]) > 1e-9:
            raise KinematicsError(
                f"robot {robot!r}: the tcp is {1e3 * np.hypot(off[1], off[2]):.3f} mm off "
                "the J5 axis; the 5R analytic kinematics needs it on that axis")

    def default_orientation(self, R_home: NDArray[np.float64], p: NDArray[np.float64]
                            ) -> NDArray[np.float64]:
        """The home orientation turned into the arm plane of the target."""
        if np.hypot(p[0], p[1]) <= 1e-12:
            return R_home
        alpha, beta, gamma = matrix_to_euler_zyx(R_home)
        return euler_zyx_to_matrix(np.arctan2(p[1], p[0]) + alpha, beta, gamma)

    def reachable_alpha(self, p: NDArray[np.float64], alpha: float, beta: float) -> float:
        """alpha is implied by the position: the nearest of the arm plane's two directions."""
        if np.hypot(p[0], p[1]) <= 1e-12:
            return alpha
        implied = float(np.arctan2(p[1], p[0]))
        off_plane = np.cos(beta) * np.sin(alpha - implied)
        if abs(off_plane) <= 1e-9:
            return alpha
        cands = [implied, implied + np.pi]
        return min(cands, key=lambda c: abs(np.angle(np.exp(1j * (alpha - c)))))


def ik_5r_seed(p: ArrayLike, beta: float, gamma: float, dims: dict[str, float],
               q1_current: float = 0.0) -> list[NDArray[np.float64]]:
    """Seed 000 eq. (13)-(17) with the seed's inputs ``X = [p_x, p_y, p_z, beta_y, gamma_x]``.

    Args:
        p: Tool point in frame 0, m, shape (3,).
        beta: Euler angle beta_y = q2 + q3 + q4, rad.
        gamma: Euler angle gamma_x = q5, rad.
        dims: ``l1, d1, l2, l3``, m.
        q1_current: J1 value used when q1 is undetermined (point on the J1 axis), rad.

    Returns:
        Up to four solutions ``q`` (5,), rad, wrapped to [-pi, pi): front shoulder elbow
        up/down, then the shoulder-flip pair. No joint limits are applied.

    Raises:
        UnreachableError: The wrist point is out of reach; ``distance`` in metres.
    """
    p = np.asarray(p, dtype=float)
    alpha = np.arctan2(p[1], p[0]) if np.hypot(p[0], p[1]) > SINGULAR_TOL else q1_current
    T = make_transform(euler_zyx_to_matrix(alpha, beta, gamma), p)
    current = np.zeros(5)
    current[0] = q1_current
    return [wrap_to_pi(q) for q, _ in FiveR(dims).ik(T, current)]
