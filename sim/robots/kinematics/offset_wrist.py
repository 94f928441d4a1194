"""Arms with three parallel axes and an offset wrist (UR-type): structure and closed-form IK.

Universal Robots' arms (UR3/5/10/16, and their copies) are not ortho-parallel with a spherical
wrist (:mod:`sim.robots.kinematics.opw`): J2, J3 and J4 are parallel, and J5 and J6 meet in a
point off the J4 axis. Hawkins ("Analytic Inverse Kinematics for the Universal Robots UR-5/UR-10
Arms", 2013) and Andersen ("Kinematics of a UR5", 2018) solve them in closed form from the DH
table: theta1 from the J5/J6 point's offset along the parallel axes, theta5 from the J6 axis's
component along them, theta6 from the parallel-axis direction seen in the flange frame, then a
planar 3R problem for theta2, theta3, theta4: up to 8 solutions.

This module solves the same equations written on the joints' screw axes at ``q = 0`` (product
of exponentials, Paden-Kahan subproblems), so that any base frame, flange frame, joint
direction and zero offset of a DH table or a URDF chain is handled without a separate
convention. Structure (:func:`offset_wrist_from_axes`, each within :data:`STRUCTURE_TOL`):

* J2, J3 and J4 parallel (direction ``u``), J2-J3 and J3-J4 apart (two links in the plane
  normal to ``u``); J1 not parallel to them;
* J5 not parallel to ``u``; J5 and J6 meet in one point ``W`` and are perpendicular.

With ``R_i`` the rotation of joint ``i`` about its axis (``w_i``, through ``p_i``) and
``g = T M^-1`` (``M``: the flange pose at ``q = 0``):

1. ``q1``: rotations about the parallel axes keep a point's ``u`` component, so
   ``u . R1^-1 (g W - p1) = u . (W - p1)``: ``A cos q1 + B sin q1 = c``, 2 roots (*shoulder*);
2. ``q5``: the J6 axis ``g w6`` seen from link 1 has ``u`` component ``u . R5 w6``:
   ``a cos q5 + b sin q5 = u . R1^-1 R_g w6``, 2 roots (*wrist*);
3. ``q6``: ``u^T R1^-1 R_g = u^T R5 R6`` fixes ``R6`` (subproblem 1 about ``w6``; free at the
   wrist singularity, where J6 is parallel to ``u``: then ``q6`` keeps the given value);
4. the rotation left, ``R1^-1 R_g R6^-1 R5^-1``, turns about ``u`` by ``phi = sum s_i q_i``
   (``s_i`` = +-1: J2-J4's directions along ``u``);
5. the J4 axis point ``p4`` carried back through joints 6, 5 and 1 is where J2 and J3 put it:
   the distance from J2 gives ``q3`` (subproblem 3, 2 roots: *elbow*), then ``q2``
   (subproblem 1), and ``q4 = s4 (phi - s2 q2 - s3 q3)``.

A root whose equation has no solution (out of reach) gives fewer solutions, never an
exception; a joint a singular pose leaves undetermined (J6 at the wrist singularity, J1 with
the J5/J6 point on its axis, J2 with the arm folded onto it) keeps the given ``free`` value.
Where two roots meet (the wrist or the elbow singularity) the angle comes from ``atan2`` of
exact components (the angle between ``u`` and the J6 axis; the half-angle form of the elbow
triangle) rather than ``arccos``, which would lose half the digits there; the shoulder's
double root keeps ``arccos`` (its error moves the pose only to second order).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError
from sim.robots.kinematics.opw import _closest

#: Tolerance of the structure tests of :func:`offset_wrist_from_axes` (parallel,
#: perpendicular, intersecting axes), m and rad.
STRUCTURE_TOL = 1e-9
#: Smallest link length (J2-J3, J3-J4 axis distance), m, and smallest sine between axes that
#: must not be parallel, for the closed form to be well posed.
MIN_LINK_M, MIN_SINE = 1e-6, 1e-6
#: The branch labels of :func:`inverse`'s rows, in order.
LABELS: tuple[str, ...] = tuple(
    f"shoulder {s} wrist {w} elbow {e}"
    for s in ("left", "right") for w in ("up", "down") for e in ("up", "down"))


@dataclass(frozen=True, eq=False)
class OffsetWristParameters:
    """An offset-wrist arm's screw axes at ``q = 0`` (module docstring), base frame, m.

    Attributes:
        w: Unit joint axes, (6, 3). p: A point on each axis, (6, 3). M: Flange pose at
        ``q = 0``, (4, 4). u: The parallel axes' direction (J2's). s: ``w_i . u`` for J2-J4
        (+-1), (3,). W: The point where J5 and J6 meet. v: A unit vector normal to ``u``.
    """

    w: NDArray[np.float64]
    p: NDArray[np.float64]
    M: NDArray[np.float64]
    u: NDArray[np.float64]
    s: NDArray[np.float64]
    W: NDArray[np.float64]
    v: NDArray[np.float64]

    # constants of the equations (module docstring), derived from the above
    @functools.cached_property
    def Minv(self) -> NDArray[np.float64]:
        return _inv(self.M)

    @functools.cached_property
    def w1xu(self) -> NDArray[np.float64]:
        return np.cross(self.w[0], self.u)

    @functools.cached_property
    def w1_u(self) -> float:
        return float(self.w[0] @ self.u)

    @functools.cached_property
    def W_u(self) -> float:
        return float(self.u @ (self.W - self.p[0]))

    @functools.cached_property
    def q5_coef(self) -> tuple[float, float, float]:
        w, u = self.w, self.u
        return (float(u @ w[5]), float(u @ np.cross(w[4], w[5])),
                float((w[4] @ w[5]) * (w[4] @ u)))

    @functools.cached_property
    def e(self) -> NDArray[np.float64]:
        """J2 axis to J3 axis, normal to ``u``."""
        e = self.p[2] - self.p[1]
        return e - (e @ self.u) * self.u

    @functools.cached_property
    def r(self) -> NDArray[np.float64]:
        """J3 axis to J4 axis, normal to ``u``."""
        r = self.p[3] - self.p[2]
        return r - (r @ self.u) * self.u

    @functools.cached_property
    def w3r(self) -> NDArray[np.float64]:
        return np.cross(self.w[2], self.r)

    @functools.cached_property
    def q3_coef(self) -> tuple[float, float]:
        """``e . R3 r = a cos q3 + b sin q3``: (a, b)."""
        return float(self.e @ self.r), float(self.e @ self.w3r)

    @functools.cached_property
    def e_len(self) -> float:
        return float(np.linalg.norm(self.e))

    @functools.cached_property
    def r_len(self) -> float:
        return float(np.linalg.norm(self.r))


def _rot(w: NDArray[np.float64], c: float, s: float) -> NDArray[np.float64]:
    """Rotation (3, 3) about the unit ``w`` by the angle of cosine ``c``, sine ``s``."""
    x, y, z = w
    C = 1.0 - c
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def _cross(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """``a x b`` of two 3-vectors (np.cross costs ten times more on one pair)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _roots(a: float, b: float, c: float) -> list[float]:
    """The two ``x`` with ``a cos x + b sin x = c`` (plus root first), [] when none.
    Round-off just past the domain is taken as the double root."""
    r = math.hypot(a, b)
    if r < 1e-300:
        return []
    x = c / r
    if abs(x) > 1.0:
        if abs(x) > 1.0 + 1e-10:
            return []
        x = math.copysign(1.0, x)
    base, d = math.acos(x), math.atan2(b, a)
    return [d + base, d - base]


def _elbow(prm: OffsetWristParameters, dist: float) -> list[float]:
    """The two q3 (plus root first, as :func:`_roots`) that put the J4 axis ``dist`` from
    J2's: the triangle of sides |e|, |r| (J2-J3, J3-J4) and ``dist`` has the angle
    ``gamma`` at J3, from the half-angle form (exact at a stretched or folded arm, where
    arccos would lose 1e-8 rad), and ``e . R3 r = -|e| |r| cos gamma``; [] out of reach."""
    a, b = prm.e_len, prm.r_len
    num = (dist - (a - b)) * (dist + (a - b))  # dist^2 - (a - b)^2
    den = ((a + b) - dist) * ((a + b) + dist)  # (a + b)^2 - dist^2
    if min(num, den) < -1e-10 * a * b:
        return []
    half = math.atan2(math.sqrt(max(num, 0.0)), math.sqrt(max(den, 0.0)))
    beta = math.atan2(prm.q3_coef[1], prm.q3_coef[0])
    return [beta + (math.pi - 2.0 * half), beta - (math.pi - 2.0 * half)]


def _angle_about(w: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]
                 ) -> float | None:
    """Subproblem 1: the angle about the unit ``w`` that turns ``a`` onto ``b`` (their parts
    normal to ``w``); None when ``a`` lies along ``w`` (any angle)."""
    a1 = a - float(a @ w) * w
    b1 = b - float(b @ w) * w
    if a1 @ a1 < 1e-24 or b1 @ b1 < 1e-24:
        return None
    return math.atan2(float(w @ _cross(a1, b1)), float(a1 @ b1))


def inverse(prm: OffsetWristParameters, T: ArrayLike, free: ArrayLike | None = None
            ) -> NDArray[np.float64]:
    """The 8 solutions of a flange pose (4, 4) in the chain's joint values (rad, (8, 6),
    wrapped to (-pi, pi]), a row of NaN where a branch has none; rows in :data:`LABELS`'
    order.

    ``free`` (rad, (6,), default zeros; the current configuration): the values of the joints
    a singular pose leaves undetermined: J6 at the wrist singularity (only q4 + q6 is fixed),
    J1 where the J5/J6 point lies on the J1 axis with the offset along ``u`` zero, J2 where
    the J4 axis lies on J2's (the arm folded onto itself).
    """
    w, p, u, s = prm.w, prm.p, prm.u, prm.s
    q1_free, q2_free, q6_free = (0.0, 0.0, 0.0) if free is None else (
        float(np.asarray(free)[0]), float(np.asarray(free)[1]), float(np.asarray(free)[5]))
    g = np.asarray(T, dtype=float) @ prm.Minv
    Rg, tg = g[:3, :3], g[:3, 3]
    out = np.full((8, 6), np.nan)
    # 1. q1 from the J5/J6 point's component along u
    P = Rg @ prm.W + tg - p[0]
    C = prm.w1_u * float(w[0] @ P)
    a1, b1, c1 = float(P @ u) - C, float(P @ prm.w1xu), prm.W_u - C
    if math.hypot(a1, b1) < 1e-12:  # the J5/J6 point on the J1 axis: q1 free or none
        q1s = [q1_free] if abs(c1) < 1e-12 else []
    else:
        q1s = _roots(a1, b1, c1)
    z6 = Rg @ w[5]
    a5, b5, c5 = prm.q5_coef
    e, r, w3r = prm.e, prm.r, prm.w3r
    for i1, q1 in enumerate(q1s):
        R1 = _rot(w[0], math.cos(q1), math.sin(q1))
        N = R1.T @ Rg
        Nu = N.T @ u
        # 2. q5 from the J6 axis's component along u
        z1 = R1.T @ z6
        if abs(math.hypot(a5, b5) - 1.0) < 1e-12:  # J5 normal to u: the angle between u and
            # the J6 axis, by atan2, exact where the roots meet (acos would lose 1e-8 there)
            base5 = math.atan2(float(np.linalg.norm(_cross(u, z1))), float(u @ z1))
            q5s = [math.atan2(b5, a5) + base5, math.atan2(b5, a5) - base5]
        else:
            q5s = _roots(a5 - c5, b5, float(u @ z1) - c5)
        for i5, q5 in enumerate(q5s):
            R5 = _rot(w[4], math.cos(q5), math.sin(q5))
            # 3. q6: R6^T (R5^T u) = N^T u
            q6 = _angle_about(w[5], Nu, R5.T @ u)
            if q6 is None:
                q6 = q6_free
            R6 = _rot(w[5], math.cos(q6), math.sin(q6))
            # 4. phi: the rotation left turns about u
            phi = _angle_about(u, prm.v, N @ (R6.T @ (R5.T @ prm.v)))
            if phi is None:  # cannot happen: v is normal to u
                continue
            # 5. the J4 axis point where J2 and J3 put it
            x = p[4] + R5.T @ (p[3] - p[4])
            x = p[5] + R6.T @ (x - p[5])
            d = p[0] + R1.T @ (Rg @ x + tg - p[0]) - p[1]
            d = d - float(d @ u) * u
            q3s = _elbow(prm, math.sqrt(float(d @ d)))
            for i3, q3 in enumerate(q3s):
                X = e + math.cos(q3) * r + math.sin(q3) * w3r
                q2 = _angle_about(w[1], X, d)
                if q2 is None:  # the J4 axis on J2's: q2 free
                    q2 = q2_free
                q4 = s[2] * (phi - s[0] * q2 - s[1] * q3)
                out[4 * i1 + 2 * i5 + i3] = [q1, q2, q3, q4, q5, q6]
    return np.where(np.isnan(out), np.nan, np.mod(out + np.pi, 2 * np.pi) - np.pi)


def _inv(T: NDArray[np.float64]) -> NDArray[np.float64]:
    out = np.eye(4)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return out


def singular_factors(prm: OffsetWristParameters, Q: ArrayLike) -> dict[str, NDArray[np.float64]]:
    """The factors of ``det J`` for joint values ``Q`` (rad, (..., 6)), each 0 at its
    singularity:

    * ``wrist``: the sine of the angle between the J6 axis and the parallel axes (J6 parallel
      to J2-J4: only q4 + q6 is fixed);
    * ``elbow``: the sine of the angle between the J2-J3 and J3-J4 links in the plane normal to
      the parallel axes (the arm stretched or folded);
    * ``shoulder``: the J5/J6 point's distance, m, from the plane through the J1 axis and
      along the parallel axes (for J1 normal to them: the two shoulder roots of q1 meet).
    """
    Q = np.asarray(Q, dtype=float)
    w, p, u, s = prm.w, prm.p, prm.u, prm.s
    q5 = Q[..., 4]
    a = float(u @ w[5])
    b = float(u @ np.cross(w[4], w[5]))
    c = float((w[4] @ w[5]) * (w[4] @ u))
    along = a * np.cos(q5) + b * np.sin(q5) + c * (1.0 - np.cos(q5))
    e = p[2] - p[1]
    e = e - (e @ u) * u
    r = p[3] - p[2]
    r = r - (r @ u) * u
    k = np.linalg.norm(e) * np.linalg.norm(r)
    q3 = s[1] * Q[..., 2]
    elbow = (float(u @ np.cross(e, r)) * np.cos(q3)
             + float(u @ np.cross(e, np.cross(u, r))) * np.sin(q3)) / k

    def turn(x: NDArray[np.float64], ang: NDArray[np.float64]) -> NDArray[np.float64]:
        """Vectors ``x`` (..., 3) turned about ``u`` by ``ang`` (...)."""
        ca, sa = np.cos(ang)[..., None], np.sin(ang)[..., None]
        return x * ca + np.cross(u, x) * sa + (1.0 - ca) * (x @ u)[..., None] * u

    x = turn(np.broadcast_to(prm.W - p[3], Q.shape[:-1] + (3,)), s[2] * Q[..., 3])
    x = turn(p[3] - p[2] + x, q3)
    x = turn(p[2] - p[1] + x, s[0] * Q[..., 1])
    n = np.cross(w[0], u)
    shoulder = (p[1] - p[0] + x) @ (n / np.linalg.norm(n))
    return {"wrist": np.sqrt(np.clip(1.0 - along**2, 0.0, None)), "elbow": elbow,
            "shoulder": np.abs(shoulder)}


# ---------------------------------------------------------------------------- structure
def _distance(p1: NDArray[np.float64], w1: NDArray[np.float64], p2: NDArray[np.float64],
              w2: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
    """Distance between two lines and the point on line 2 closest to line 1 (OPW's
    :func:`~sim.robots.kinematics.opw._closest` with the lines swapped)."""
    return _closest(p2, w2, p1, w1)


def offset_wrist_from_axes(axes: ArrayLike, points: ArrayLike, flange: ArrayLike,
                           name: str = "arm") -> OffsetWristParameters:
    """The offset-wrist parameters of a 6-axis arm from its joint axes at ``q = 0``.

    Args:
        axes: Unit joint axes in the base frame, (6, 3) (the positive rotation direction).
        points: A point on each axis, base frame, m, (6, 3).
        flange: Flange pose at ``q = 0`` in the base frame, (4, 4).
        name: For messages.

    Raises:
        KinematicsError: The arm does not have this structure (the message says which
            condition fails).
    """
    w = np.asarray(axes, dtype=float)
    w = w / np.linalg.norm(w, axis=-1, keepdims=True)
    P = np.asarray(points, dtype=float)
    if w.shape != (6, 3) or P.shape != (6, 3):
        raise KinematicsError(f"{name}: the offset-wrist closed form needs 6 revolute joints, "
                              f"got {len(w)}")
    tol = STRUCTURE_TOL * 100
    u = w[1]
    for j in (2, 3):
        if np.linalg.norm(np.cross(w[j], u)) > tol:
            raise KinematicsError(f"{name}: not an offset-wrist arm: J{j + 1} is not parallel "
                                  "to J2")
    for j, what in ((0, "J1"), (4, "J5")):
        if np.linalg.norm(np.cross(w[j], u)) < MIN_SINE:
            raise KinematicsError(f"{name}: not an offset-wrist arm: {what} is parallel to "
                                  "J2-J4")
    for j in (1, 2):
        d, _ = _distance(P[j], u, P[j + 1], u)
        if d < MIN_LINK_M:
            raise KinematicsError(f"{name}: not an offset-wrist arm: the J{j + 1} and "
                                  f"J{j + 2} axes coincide")
    d56, W = _distance(P[4], w[4], P[5], w[5])
    if d56 > tol:
        raise KinematicsError(f"{name}: not an offset-wrist arm: J5 and J6 do not meet "
                              f"({d56:.3g} m apart)")
    if abs(w[4] @ w[5]) > tol:
        raise KinematicsError(f"{name}: not an offset-wrist arm: J5 is not perpendicular to "
                              "J6")
    v = np.cross(u, w[0])
    v /= np.linalg.norm(v)
    return OffsetWristParameters(w=w, p=P.copy(), M=np.asarray(flange, dtype=float).copy(),
                                 u=u.copy(), s=np.sign(w[1:4] @ u), W=W, v=v)


__all__ = ["LABELS", "OffsetWristParameters", "inverse", "offset_wrist_from_axes",
           "singular_factors"]
