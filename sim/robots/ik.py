"""Analytic inverse kinematics of the cellsim robots, and branch-continuous IK along a path.

5R robots (LR Mate 100iB, 5R welding robot): seed 000 eq. (13)-(17), with eq. (14) derived
again (it is garbled as printed). From eq. (5), with ``r = c1 p_x + s1 p_y`` the signed distance of
the tool point from the J1 axis in the arm plane, the wrist point (on the J4 axis) is
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

200iC/5L: Pieper's method (seed 004 eq. 9-18) on the wrist centre ``w = p - (R6 + r) a``
(the seed's eq. 9-10 mix R6 into the position equations; we subtract it along the approach
vector a, as eq. 3 implies). ``theta1 = atan2(w_y, w_x)`` or ``+ pi`` (eq. 10); with
``A = c1 w_x + s1 w_y - d2`` (eq. 11), the J3 equation reduces to
``R4 s3 + d4 c3 = (A^2 + w_z^2 - d3^2 - R4^2 - d4^2) / (2 d3)`` (two roots: elbow up/down;
equivalent to eq. 14's quadratic in C23) and ``A + i w_z = (m + i (d3 + n)) e^{i theta2}`` with
``m = R4 c3 - d4 s3``, ``n = R4 s3 + d4 c3`` (eq. 12-15). The wrist: ``3R6 = Rx(90deg)
Rz(theta4) Ry(theta5) Rz(theta6)``, i.e. Z-Y-Z Euler angles (eq. 16-18), with the flip
``(theta4 + pi, -theta5, theta6 + pi)``. Up to 8 solutions; every joint is then also offered
in each ``theta + 2 k pi`` representation that its range allows (J4 +-190 deg, J6 +-360 deg).

Ranking (documented criterion): solutions inside the joint ranges first, then by the
joint-space distance to the current configuration weighted by each joint's maximum speed,
``sqrt(sum(((q_i - q_cur_i) / v_max_i)^2))`` (seconds: a proxy for motion time).

Singularities: at the wrist singularity (200iC ``theta5 = 0``; only ``theta4 + theta6`` is
defined) J4 keeps its current value and a :class:`SingularityWarning` is issued; likewise J1
when the wrist centre (200iC) or the tool point and tool x axis (5R) lie on the J1 axis.
"""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError, SingularityWarning, UnreachableError
from sim.robots.model import KinematicModel
from sim.core.rotations import (euler_zyx_to_matrix, invert_transform, make_transform,
                                      rot_z, wrap_to_pi)

#: |sin theta5| (200iC) or distance from the J1 axis (m) below which the pose is singular.
SINGULAR_TOL = 1e-9

#: 5-axis robots: a requested tool x axis at most this far (sine of the angle, 0.05 deg) out of
#: the arm plane is accepted and the solution takes the nearest reachable orientation (the
#: in-plane part); typed-in or rounded angles are never exactly in the plane.
PLANE_TOL = float(np.sin(np.deg2rad(0.05)))


@dataclass(frozen=True)
class IKSolution:
    """One inverse-kinematics solution.

    Attributes:
        q: Joint values, rad, shape (n,).
        within_limits: Inside every joint range (True when the ranges are unknown).
        branch: Which analytic branch, e.g. ``"front/up/noflip"``.
        cost: Ranking distance to the current configuration (see module docstring), s.
    """

    q: NDArray[np.float64]
    within_limits: bool
    branch: str
    cost: float


def _annulus_gap(rho: float, r_in: float, r_out: float) -> float:
    """How far (m) a planar distance ``rho`` is outside the annulus [r_in, r_out] (<= 0 inside)."""
    return max(rho - r_out, r_in - rho)


# ---------------------------------------------------------------------------- 5R (seed 000)
def _ik_5r_raw(T: NDArray[np.float64], dims: dict[str, float], q1_current: float
               ) -> list[tuple[NDArray[np.float64], str]]:
    l1, d1, l2, l3 = dims["l1"], dims["d1"], dims["l2"], dims["l3"]
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
        gaps.append(_annulus_gap(float(np.hypot(u, v)), abs(d1 - l2), d1 + l2))
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
            f"pose unreachable: the wrist point (J4 axis) is {1e3 * gap:.1f} mm outside the "
            f"arm's reach (J2 to J4 between {1e3 * abs(d1 - l2):.1f} and {1e3 * (d1 + l2):.1f} mm)",
            gap)
    return sols


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
    return [wrap_to_pi(q) for q, _ in _ik_5r_raw(T, dims, q1_current)]


# ---------------------------------------------------------------------------- 200iC (seed 004)
def _ik_fanuc6_raw(T: NDArray[np.float64], dims: dict[str, float], tool_length: float,
                   current: NDArray[np.float64]) -> list[tuple[NDArray[np.float64], str]]:
    d2, d3, d4, R4, R6 = dims["d2"], dims["d3"], dims["d4"], dims["R4"], dims["R6"]
    R, p = T[:3, :3], T[:3, 3]
    w = p - (R6 + tool_length) * R[:, 2]
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
        gaps.append(_annulus_gap(float(np.hypot(A, w[2])), abs(d3 - L), d3 + L))
        K = (A**2 + w[2] ** 2 - d3**2 - L**2) / (2 * d3 * L)
        if abs(K) > 1.0 + 1e-12:
            continue
        asK = float(np.arcsin(np.clip(K, -1.0, 1.0)))
        for elbow, t3 in (("up", asK - phi), ("down", np.pi - asK - phi)):
            m = R4 * np.cos(t3) - d4 * np.sin(t3)
            n = R4 * np.sin(t3) + d4 * np.cos(t3)
            t2 = np.arctan2(w[2], A) - np.arctan2(d3 + n, m)
            R03 = (rot_z(t1) @ _rx(np.pi / 2) @ rot_z(np.pi / 2 + t2) @ rot_z(t3))
            W = _rx(np.pi / 2).T @ R03.T @ R  # = Rz(t4) Ry(t5) Rz(t6)
            s5 = float(np.hypot(W[0, 2], W[1, 2]))
            if s5 < SINGULAR_TOL:
                t5 = 0.0 if W[2, 2] > 0 else np.pi
                t4 = float(current[3])
                X = (rot_z(t4) @ _ry(t5)).T @ W
                t6 = float(np.arctan2(X[1, 0], X[0, 0]))
                warnings.warn("6-axis IK: wrist singularity (theta5 = 0, J4 and J6 aligned): "
                              f"J4 kept at its current value {np.rad2deg(t4):.3f} deg",
                              SingularityWarning, stacklevel=3)
                sols.append((np.array([t1, t2, t3, t4, t5, t6]), f"{shoulder}/{elbow}/singular"))
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
            f"pose unreachable: the wrist centre is {1e3 * gap:.1f} mm outside the arm's reach "
            f"(J2 to wrist centre between {1e3 * abs(d3 - L):.1f} and {1e3 * (d3 + L):.1f} mm)",
            gap)
    return sols


def _rx(a: float) -> NDArray[np.float64]:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _ry(a: float) -> NDArray[np.float64]:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


# ---------------------------------------------------------------------------- public API
def ranking_cost(model: KinematicModel, q: ArrayLike, current: ArrayLike) -> float:
    """Weighted joint distance ``sqrt(sum(((q - current) / v_max)^2))``, s (ranking criterion)."""
    dq = (np.asarray(q, dtype=float) - np.asarray(current, dtype=float)) / model.max_speed
    return float(np.sqrt(np.sum(dq**2)))


def _representations(model: KinematicModel, q: NDArray[np.float64], current: NDArray[np.float64]
                     ) -> list[NDArray[np.float64]]:
    """Each ``q_i + 2 k pi`` inside the ranges; the one nearest ``current`` if ranges are unknown."""
    choices = []
    for i, qi in enumerate(wrap_to_pi(q)):
        if model.lower is None or model.upper is None or not np.isfinite(model.lower[i]) \
                or not np.isfinite(model.upper[i]):
            choices.append([qi + 2 * np.pi * np.round((current[i] - qi) / (2 * np.pi))])
            continue
        cands = [qi + 2 * np.pi * k for k in range(-3, 4)]
        inside = [c for c in cands if model.lower[i] - 1e-9 <= c <= model.upper[i] + 1e-9]
        choices.append(inside or [qi])
    return [np.array(c) for c in itertools.product(*choices)]


def solve_ik(model: KinematicModel, pose: ArrayLike, current: ArrayLike | None = None
             ) -> list[IKSolution]:
    """Every analytic IK solution of a tcp pose, best first.

    Args:
        model: The robot's kinematic model (its tcp frame is the one the pose refers to).
        pose: Homogeneous transform of the tcp in frame 0, shape (4, 4), metres.
        current: Current configuration, rad, shape (n,); default zeros (home).

    Returns:
        Solutions ranked as the module docstring says (inside-limits first, then weighted
        distance to ``current``); duplicates (e.g. at a stretched elbow) removed.

    Raises:
        UnreachableError: The position is out of reach (``distance`` in metres), or a
            5-axis robot cannot take the orientation.
        KinematicsError: Malformed pose (shape, NaN, not a rotation).
    """
    T = np.asarray(pose, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise KinematicsError(f"pose must be a finite 4x4 transform, got shape {T.shape}")
    if np.abs(T[:3, :3] @ T[:3, :3].T - np.eye(3)).max() > 1e-6:
        raise KinematicsError("pose rotation is not orthonormal")
    cur = np.zeros(model.n_joints) if current is None else np.asarray(current, dtype=float)
    if cur.shape != (model.n_joints,):
        raise KinematicsError(f"current configuration must have {model.n_joints} values")
    T_seed = T @ invert_transform(model.tcp_offset)
    if model.family == "5r":
        raw = _ik_5r_raw(T_seed, model.dims, float(cur[0]))
    else:
        raw = _ik_fanuc6_raw(T_seed, model.dims, model.tool_length, cur)
    out: list[IKSolution] = []
    for q, branch in raw:
        for rep in _representations(model, q, cur):
            if any(np.abs(rep - s.q).max() < 1e-9 for s in out):
                continue
            out.append(IKSolution(q=rep, within_limits=bool(model.within_limits(rep)),
                                  branch=branch, cost=ranking_cost(model, rep, cur)))
    out.sort(key=lambda s: (not s.within_limits, s.cost))
    return out


def ik_path(model: KinematicModel, poses: Sequence[ArrayLike] | NDArray[np.float64],
            q_start: ArrayLike | None = None, respect_limits: bool = True) -> NDArray[np.float64]:
    """Branch-continuous IK along a sequence of tcp poses.

    At each point the solution closest (ranking criterion) to the previous point's solution is
    taken; the first point is compared with ``q_start`` (default home).

    Args:
        model: The robot's kinematic model.
        poses: tcp poses in frame 0, shape (N, 4, 4), metres.
        q_start: Configuration before the first point, rad, shape (n,).
        respect_limits: Only accept solutions inside the joint ranges.

    Returns:
        Joint values, rad, shape (N, n).

    Raises:
        UnreachableError: A point is unreachable (or has no in-range solution); the message
            names its index.
    """
    P = np.asarray(poses, dtype=float)
    if P.ndim != 3 or P.shape[1:] != (4, 4):
        raise KinematicsError(f"poses must have shape (N, 4, 4), got {P.shape}")
    prev = np.zeros(model.n_joints) if q_start is None else np.asarray(q_start, dtype=float)
    out = np.empty((P.shape[0], model.n_joints))
    for k, T in enumerate(P):
        try:
            sols = solve_ik(model, T, prev)
        except UnreachableError as exc:
            raise UnreachableError(f"path point {k}: {exc}", exc.distance) from None
        if respect_limits:
            sols = [s for s in sols if s.within_limits]
            if not sols:
                raise UnreachableError(f"path point {k}: no IK solution inside the joint ranges",
                                       0.0)
        best = min(sols, key=lambda s: s.cost)
        out[k] = best.q
        prev = best.q
    return out
