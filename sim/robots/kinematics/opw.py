"""Ortho-parallel arms with a spherical wrist (OPW): parameters, forward and inverse kinematics.

Most 6-axis industrial arms (FANUC, ABB, KUKA, Yaskawa, Staubli) are *ortho-parallel*: J1
vertical, J2 and J3 parallel and perpendicular to J1, and a spherical wrist (J4, J5, J6 meet
in one point). Brandstoetter, Angerer and Hofbaur ("An analytical solution of the inverse
kinematics problem of industrial serial manipulators with an ortho-parallel basis and a
spherical wrist", Austrian Robotics Workshop 2014) give their kinematics with seven lengths
and, per joint, a sign and an offset between the maker's joint value and the model's angle;
ROS-Industrial's ``opw_kinematics`` implements it, and this module follows that
implementation (``opw_kinematics_impl.h``, commit 8a32bda), vectorised with numpy.

The seven parameters (m), in the model's zero pose (arm straight up, wrist straight):

* ``c1``: height of the J2 axis above the base; ``a1``: its offset from the J1 axis;
* ``b``: sideways offset of the arm plane (of the wrist centre) from J1, along y;
* ``c2``: J2 axis to J3 axis; ``c3``: J3 axis to the wrist centre along the forearm;
  ``a2``: offset of the forearm from J3, perpendicular to it in the arm plane;
* ``c4``: wrist centre to the flange along J6.

The model's angle of joint ``i`` is ``theta_i = sign_i * q_i - offset_i`` (``q``: the maker's
or URDF's joint value).

:func:`opw_from_axes` derives the parameters, signs and offsets from an arm's joint screw axes at
``q = 0`` (a URDF's, a DH table's), or says why the arm is not OPW.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError

#: Tolerance of the structure tests of :func:`opw_from_axes` (parallel, perpendicular,
#: intersecting axes), m and rad.
STRUCTURE_TOL = 1e-9


@dataclass(frozen=True)
class OPWParameters:
    """The OPW parameters of one arm (module docstring), m and rad.

    Attributes:
        a1, a2, b, c1, c2, c3, c4: Lengths, m.
        offsets: Joint offsets, rad, (6,): ``theta = sign * q - offset``.
        signs: Joint signs, +1 or -1, (6,).
        flange: Constant transform from the model's end frame to the arm's flange frame, (4, 4)
            (identity when the flange frame is the model's: z along J6, x along the arm's
            zero-pose forearm offset direction).
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    offsets: tuple[float, ...] = (0.0,) * 6
    signs: tuple[int, ...] = (1,) * 6
    flange: NDArray[np.float64] = field(default_factory=lambda: np.eye(4), compare=False)

    def lengths(self) -> dict[str, float]:
        """The seven lengths by name, m."""
        return {k: float(getattr(self, k)) for k in ("a1", "a2", "b", "c1", "c2", "c3", "c4")}


def _theta(p: OPWParameters, q: NDArray[np.float64]) -> NDArray[np.float64]:
    return q * np.asarray(p.signs, dtype=float) - np.asarray(p.offsets, dtype=float)


def forward(p: OPWParameters, q: ArrayLike) -> NDArray[np.float64]:
    """Flange pose in the base frame for joint values ``q`` (rad, (6,) or (N, 6)); (4, 4) or
    (N, 4, 4)."""
    Q = np.asarray(q, dtype=float)
    single = Q.ndim == 1
    th = _theta(p, np.atleast_2d(Q))
    t1, t2, t3, t4, t5, t6 = th.T
    psi3 = np.arctan2(p.a2, p.c3)
    k = np.hypot(p.a2, p.c3)
    cx1 = p.c2 * np.sin(t2) + k * np.sin(t2 + t3 + psi3) + p.a1
    cy1 = np.full_like(cx1, p.b)
    cz1 = p.c2 * np.cos(t2) + k * np.cos(t2 + t3 + psi3)
    s1, c1 = np.sin(t1), np.cos(t1)
    c = np.stack([cx1 * c1 - cy1 * s1, cx1 * s1 + cy1 * c1, cz1 + p.c1], axis=-1)
    s23, c23 = np.sin(t2 + t3), np.cos(t2 + t3)
    n = len(t1)
    R0c = np.zeros((n, 3, 3))
    R0c[:, 0] = np.stack([c1 * c23, -s1, c1 * s23], axis=-1)
    R0c[:, 1] = np.stack([s1 * c23, c1, s1 * s23], axis=-1)
    R0c[:, 2] = np.stack([-s23, np.zeros(n), c23], axis=-1)
    s4, c4, s5, c5, s6, c6 = (np.sin(t4), np.cos(t4), np.sin(t5), np.cos(t5), np.sin(t6),
                              np.cos(t6))
    Rce = np.zeros((n, 3, 3))
    Rce[:, 0] = np.stack([c4 * c5 * c6 - s4 * s6, -c4 * c5 * s6 - s4 * c6, c4 * s5], axis=-1)
    Rce[:, 1] = np.stack([s4 * c5 * c6 + c4 * s6, -s4 * c5 * s6 + c4 * c6, s4 * s5], axis=-1)
    Rce[:, 2] = np.stack([-s5 * c6, s5 * s6, c5], axis=-1)
    R = R0c @ Rce
    T = np.zeros((n, 4, 4))
    T[:, :3, :3] = R
    T[:, :3, 3] = c + p.c4 * R[:, :, 2]
    T[:, 3, 3] = 1.0
    T = T @ p.flange
    return T[0] if single else T


def inverse(p: OPWParameters, T: ArrayLike) -> NDArray[np.float64]:
    """The 8 joint solutions (rad, (8, 6), in the maker's joint values wrapped to (-pi, pi]) of
    a flange pose (4, 4); a row of NaN where a branch has no solution (out of reach).

    Order (as ``opw_kinematics``): shoulder front/back x elbow up/down for rows 0-3, the same
    with the wrist flipped for rows 4-7.
    """
    T = np.asarray(T, dtype=float) @ np.linalg.inv(p.flange)
    R = T[:3, :3]
    c = T[:3, 3] - p.c4 * R[:, 2]
    with np.errstate(invalid="ignore", divide="ignore"):  # NaN rows: out of reach
        nx1 = np.sqrt(c[0] ** 2 + c[1] ** 2 - p.b**2) - p.a1
        tmp1 = np.arctan2(c[1], c[0])
        tmp2 = np.arctan2(p.b, nx1 + p.a1)
        t1_i, t1_ii = tmp1 - tmp2, tmp1 + tmp2 - np.pi
        tmp3 = c[2] - p.c1
        s1_2 = nx1**2 + tmp3**2
        tmp4 = nx1 + 2.0 * p.a1
        s2_2 = tmp4**2 + tmp3**2
        kappa_2 = p.a2**2 + p.c3**2
        c2_2 = p.c2**2
        s1, s2 = np.sqrt(s1_2), np.sqrt(s2_2)
        tmp13 = _acos((s1_2 + c2_2 - kappa_2) / (2.0 * s1 * p.c2))
        tmp14 = np.arctan2(nx1, tmp3)
        t2 = [-tmp13 + tmp14, tmp13 + tmp14]
        tmp15 = _acos((s2_2 + c2_2 - kappa_2) / (2.0 * s2 * p.c2))
        tmp16 = np.arctan2(nx1 + 2.0 * p.a1, tmp3)
        t2 += [-tmp15 - tmp16, tmp15 - tmp16]
        tmp9 = 2.0 * p.c2 * np.sqrt(kappa_2)
        tmp10 = np.arctan2(p.a2, p.c3)
        tmp11 = _acos((s1_2 - c2_2 - kappa_2) / tmp9)
        tmp12 = _acos((s2_2 - c2_2 - kappa_2) / tmp9)
        t3 = [tmp11 - tmp10, -tmp11 - tmp10, tmp12 - tmp10, -tmp12 - tmp10]
    t1 = [t1_i, t1_i, t1_ii, t1_ii]
    sols = np.full((8, 6), np.nan)
    for i in range(4):
        if not (np.isfinite(t1[i]) and np.isfinite(t2[i]) and np.isfinite(t3[i])):
            continue
        s1_, c1_ = np.sin(t1[i]), np.cos(t1[i])
        s23, c23 = np.sin(t2[i] + t3[i]), np.cos(t2[i] + t3[i])
        m = R[0, 2] * s23 * c1_ + R[1, 2] * s23 * s1_ + R[2, 2] * c23
        t5 = np.arctan2(np.sqrt(max(0.0, 1.0 - m * m)), m)
        if abs(t5) < 1e-6:  # wrist singular: J4 and J6 aligned, put it all on J6
            t4 = 0.0
            xe = R[:, 0]
            yc = np.array([-s1_, c1_, 0.0])
            zc = R[:, 2]
            xc = np.cross(yc, zc)
            t6 = np.arctan2(xe @ yc, xe @ xc)
        else:
            t4 = np.arctan2(R[1, 2] * c1_ - R[0, 2] * s1_,
                            R[0, 2] * c23 * c1_ + R[1, 2] * c23 * s1_ - R[2, 2] * s23)
            t6 = np.arctan2(R[0, 1] * s23 * c1_ + R[1, 1] * s23 * s1_ + R[2, 1] * c23,
                            -R[0, 0] * s23 * c1_ - R[1, 0] * s23 * s1_ - R[2, 0] * c23)
        sols[i] = [t1[i], t2[i], t3[i], t4, t5, t6]
        sols[i + 4] = [t1[i], t2[i], t3[i], t4 + np.pi, -t5, t6 - np.pi]
    offsets = np.asarray(p.offsets, dtype=float)
    signs = np.asarray(p.signs, dtype=float)
    q = (sols + offsets) * signs
    return np.where(np.isnan(q), np.nan, np.mod(q + np.pi, 2 * np.pi) - np.pi)


def reach_gap(p: OPWParameters, T: ArrayLike) -> tuple[float, float, float]:
    """How far a flange pose's wrist centre lies outside the arm's reach, m (0 inside it), and
    the reach from J2's axis to the wrist centre, ``(gap, inner, outer)``, m: the wrist centre
    must be ``inner`` to ``outer`` from J2's axis (J3 folds the forearm, ``sqrt(a2^2 + c3^2)``
    long, against the upper arm, ``c2``), with the shoulder in front of J1 or behind it, and
    at least ``b`` from J1's axis."""
    T = np.asarray(T, dtype=float) @ np.linalg.inv(p.flange)
    c = T[:3, 3] - p.c4 * T[:3, 2]
    k = float(np.hypot(p.a2, p.c3))
    inner, outer = abs(p.c2 - k), p.c2 + k
    radial = float(np.hypot(c[0], c[1]))
    if radial < abs(p.b):
        return abs(p.b) - radial, inner, outer
    nx1 = float(np.sqrt(radial**2 - p.b**2)) - p.a1
    gaps = []
    for x in (nx1, nx1 + 2.0 * p.a1):  # the shoulder in front of J1, behind it
        d = float(np.hypot(x, c[2] - p.c1))
        gaps.append(max(d - outer, inner - d, 0.0))
    return min(gaps), inner, outer


def configuration(p: OPWParameters, q: ArrayLike) -> str:
    """The posture of a solution: ``front``/``back`` (the wrist centre ahead of J1 or behind,
    along the arm's own direction), ``up``/``down`` (the elbow above or below the line from J2
    to the wrist centre), ``noflip``/``flip`` (the model's theta5 >= 0 or < 0)."""
    t1, t2, t3, _, t5, _ = _theta(p, np.asarray(q, dtype=float))
    psi3 = np.arctan2(p.a2, p.c3)
    k = np.hypot(p.a2, p.c3)
    ex, ez = p.a1 + p.c2 * np.sin(t2), p.c2 * np.cos(t2)
    wx, wz = ex + k * np.sin(t2 + t3 + psi3), ez + k * np.cos(t2 + t3 + psi3)
    front = wx >= 0.0
    cross = (wx - p.a1) * ez - wz * (ex - p.a1)
    up = cross * (1.0 if wx - p.a1 >= 0 else -1.0) > 0
    return (f"{'front' if front else 'back'} {'up' if up else 'down'} "
            f"{'noflip' if np.mod(t5 + np.pi, 2 * np.pi) - np.pi >= 0 else 'flip'}")


def _acos(x: float) -> float:
    """arccos that accepts round-off just outside [-1, 1] (NaN farther out: out of reach)."""
    if np.isfinite(x) and 1.0 < abs(x) < 1.0 + 1e-12:
        x = float(np.sign(x))
    return float(np.arccos(x)) if np.isfinite(x) and abs(x) <= 1.0 else float("nan")


# ---------------------------------------------------------------------------- derivation
def _unit(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return v / np.linalg.norm(v)


def _closest(p1: NDArray[np.float64], w1: NDArray[np.float64], p2: NDArray[np.float64],
             w2: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
    """Distance between two lines and the point on line 1 closest to line 2."""
    n = np.cross(w1, w2)
    if np.linalg.norm(n) < STRUCTURE_TOL:  # parallel
        d = p2 - p1
        return float(np.linalg.norm(d - (d @ w1) * w1)), p1
    d = p2 - p1
    dist = abs(d @ n) / np.linalg.norm(n)
    t = np.cross(d, w2) @ n / (n @ n)
    return float(dist), p1 + t * w1


def opw_from_axes(axes: ArrayLike, points: ArrayLike, flange: ArrayLike,
                  name: str = "arm") -> OPWParameters:
    """OPW parameters, signs and offsets of a 6-axis arm from its joint axes at ``q = 0``.

    Args:
        axes: Unit joint axes in the base frame, (6, 3) (the positive rotation direction).
        points: A point on each axis, base frame, m, (6, 3).
        flange: Flange pose at ``q = 0`` in the base frame, (4, 4).
        name: For messages.

    Returns:
        The parameters; ``forward(p, q)`` equals the arm's flange pose for every ``q``.

    Raises:
        KinematicsError: The arm is not ortho-parallel with a spherical wrist (the message says
            which condition fails), or its base frame does not have J1 along z through the
            origin.
    """
    w = np.array([_unit(np.asarray(a, dtype=float)) for a in axes])
    P = np.asarray(points, dtype=float)
    F = np.asarray(flange, dtype=float)
    tol = 1e-7
    z = np.array([0.0, 0.0, 1.0])
    y = np.array([0.0, 1.0, 0.0])
    if w.shape != (6, 3):
        raise KinematicsError(f"{name}: OPW needs 6 revolute joints, got {len(w)}")
    if abs(abs(w[0] @ z) - 1.0) > tol or np.hypot(P[0, 0], P[0, 1]) > tol:
        raise KinematicsError(f"{name}: not OPW in this base frame: J1 is not the z axis")
    sign1 = 1 if w[0] @ z > 0 else -1
    for j in (1, 2):
        if abs(abs(w[j] @ y) - 1.0) > tol:
            raise KinematicsError(f"{name}: not OPW: J{j + 1} is not along y at q = 0 (the arm "
                                  "must lie in the x-z plane)")
    sign2, sign3 = (1 if w[1] @ y > 0 else -1), (1 if w[2] @ y > 0 else -1)
    # spherical wrist: J4, J5, J6 meet in one point
    d45, W = _closest(P[3], w[3], P[4], w[4])
    d56, _ = _closest(P[4], w[4], P[5], w[5])
    d46, _ = _closest(P[3], w[3], P[5], w[5])
    if max(d45, d56, d46) > tol or np.linalg.norm(np.cross(w[3], w[4])) < tol:
        raise KinematicsError(f"{name}: not OPW: the wrist axes J4, J5, J6 do not meet in one "
                              f"point (distances {d45:.3g}, {d56:.3g}, {d46:.3g} m)")
    if abs(w[3] @ w[4]) > tol or abs(w[4] @ w[5]) > tol:
        raise KinematicsError(f"{name}: not OPW: J5 is not perpendicular to J4 and J6")
    # arm plane quantities, in the x-z plane
    a1, c1 = float(P[1, 0]), float(P[1, 2])
    b = float(W[1])
    j2, j3 = P[1], P[2]
    v23 = j3 - j2
    v23 = v23 - (v23 @ y) * y
    c2 = float(np.linalg.norm(v23))
    th2 = float(np.arctan2(v23[0], v23[2]))  # from +z towards +x: the model's theta2 at q = 0
    u = w[3] * (1.0 if w[3] @ (W - j3) >= 0 else -1.0)  # forearm direction, J3 side to wrist
    u = u - (u @ y) * y
    u = _unit(u)
    e = np.array([u[2], 0.0, -u[0]])  # u turned +90 deg about y: the a2 direction
    vw = W - j3
    c3, a2 = float(vw @ u), float(vw @ e)
    th23 = float(np.arctan2(u[0], u[2]))
    th3 = th23 - th2
    sign4 = 1 if w[3] @ u > 0 else -1
    # J5 along the model's y turned by theta1 = 0 and theta4: straight wrist at q = 0
    y5 = y
    sign5 = 1 if w[4] @ y5 > 0 else -1
    if abs(abs(w[4] @ y5) - 1.0) > tol:
        raise KinematicsError(f"{name}: the wrist is turned at q = 0 (J5 not along y); "
                              "not handled")
    if abs(abs(w[5] @ u) - 1.0) > tol:
        raise KinematicsError(f"{name}: the wrist is bent at q = 0 (J6 not along J4); "
                              "not handled")
    sign6 = 1 if w[5] @ u > 0 else -1
    c4 = float((F[:3, 3] - W) @ u)
    p = OPWParameters(a1=a1, a2=a2, b=b, c1=c1, c2=c2, c3=c3, c4=c4,
                      offsets=(0.0, -th2, -th3, 0.0, 0.0, 0.0),
                      signs=(sign1, sign2, sign3, sign4, sign5, sign6))
    # the flange frame against the model's end frame at q = 0
    E = forward(p, np.zeros(6))
    X = np.linalg.solve(E, F)
    X[np.abs(X) < 1e-15] = 0.0
    if np.linalg.norm(X[:3, 3]) > tol or abs(abs(X[2, 2]) - 1.0) > tol:
        raise KinematicsError(f"{name}: the flange is not on the J6 axis")
    return OPWParameters(a1=a1, a2=a2, b=b, c1=c1, c2=c2, c3=c3, c4=c4, offsets=p.offsets,
                         signs=p.signs, flange=X)


__all__ = ["OPWParameters", "configuration", "forward", "inverse", "opw_from_axes"]
