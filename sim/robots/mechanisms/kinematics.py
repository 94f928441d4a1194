"""Kinematics of a mechanism (turntable, tilt-rotate positioner, track): where its links and its
mount are at given axis values (:func:`link_poses`, :func:`mount_pose`), and which axis values
turn a direction fixed to the mount (a seam's normal) onto a direction of the base (up):
:func:`orient` for one sample, closed form, and :func:`orient_path` along a sampled seam,
branch-continuous.

The chain's convention is :mod:`sim.robots.mechanisms.spec`'s: each axis's link frame is the
parent frame translated by ``AxisSpec.pos`` (no rotation at zero); a revolute axis turns its
link about ``AxisSpec.axis`` (in the parent frame) through the link frame's origin, a prismatic
axis moves it along ``axis``. Because no frame is rotated at zero, every axis direction is also
its direction in the base frame at zero, and the mount's orientation is the product of
exponentials ``exp(w1 q1) exp(w2 q2) ... R_mount`` over the revolute axes (prismatic axes turn
nothing).

Orientation inverse kinematics is Paden-Kahan: subproblem 1 (one revolute axis: a turntable) and
subproblem 2 (two revolute axes of any non-parallel directions: a tilt-rotate positioner),
with the closest solution (least angle error) where no exact one exists and its residual angle
reported.

Forward kinematics only (no Jacobian, no MuJoCo). May import: numpy, ``sim.core``,
``sim.errors`` and :mod:`sim.robots.mechanisms.spec`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import KinematicsError, UnreachableError
from sim.robots.mechanisms.spec import MechanismSpec

#: Below this length a vector's component perpendicular to an axis is taken as none: the vector
#: lies along the axis and the axis's angle does not move it (the axis is free).
FREE_AXIS_TOL = 1e-10
#: Below this sine of the angle between two revolute axes they count as parallel.
PARALLEL_TOL = 1e-9
#: Slack on the axis ranges (rad or m) for values a round-off outside them.
RANGE_TOL = 1e-9
_TWO_PI = 2.0 * np.pi


# ----------------------------------------------------------------------------------------------
# forward kinematics


def _unit(v: ArrayLike, what: str) -> NDArray[np.float64]:
    v = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(v)) if v.shape == (3,) else 0.0
    if not np.isfinite(n) or n < 1e-12:
        raise KinematicsError(f"{what} must be a finite non-zero 3-vector, got {v.tolist()}")
    return v / n


def axis_rotation(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation by ``angle`` (rad, any shape) about the unit vector ``axis`` (3,) (Rodrigues:
    ``I + sin(a) K + (1 - cos(a)) K^2``), shape ``angle.shape + (3, 3)``."""
    w = np.asarray(axis, dtype=float)
    a = np.asarray(angle, dtype=float)[..., None, None]
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    return np.eye(3) + np.sin(a) * K + (1.0 - np.cos(a)) * (K @ K)


def _axis_values(mech: MechanismSpec, q: ArrayLike) -> NDArray[np.float64]:
    q = np.asarray(q, dtype=float)
    if q.ndim == 0 or q.shape[-1] != mech.n_axes:
        raise KinematicsError(f"mechanism '{mech.name}': axis values must have shape "
                              f"(..., {mech.n_axes}), got {q.shape}")
    return q


def link_poses(mech: MechanismSpec, q: ArrayLike) -> NDArray[np.float64]:
    """Pose of every link frame in the mechanism's base frame.

    Args:
        mech: The mechanism.
        q: Axis values, rad or m, shape (..., n_axes).

    Returns:
        Shape (..., n_axes, 4, 4): entry ``[..., i]`` is axis i's link frame. (Axis
        directions are normalised here, as in :func:`orient`.)
    """
    q = _axis_values(mech, q)
    lead = q.shape[:-1]
    out = np.zeros(lead + (mech.n_axes, 4, 4))
    R = np.broadcast_to(np.eye(3), lead + (3, 3))
    p = np.zeros(lead + (3,))
    for i, ax in enumerate(mech.axes):
        w = _unit(ax.axis, f"mechanism '{mech.name}': axis '{ax.name}' direction")
        p = p + R @ np.asarray(ax.pos, dtype=float)
        if ax.kind == "revolute":
            R = R @ axis_rotation(w, q[..., i])
        else:
            p = p + (R @ w) * q[..., i, None]
        out[..., i, :3, :3] = R
        out[..., i, :3, 3] = p
        out[..., i, 3, 3] = 1.0
    return out


def mount_pose(mech: MechanismSpec, q: ArrayLike) -> NDArray[np.float64]:
    """Pose of the mount (faceplate, carriage top) in the base frame, shape (..., 4, 4), for
    axis values ``q`` of shape (..., n_axes)."""
    q = _axis_values(mech, q)
    last = link_poses(mech, q)[..., -1, :, :] if mech.n_axes else np.eye(4)
    return last @ np.asarray(mech.mount, dtype=float)


def direction_error(mech: MechanismSpec, q: ArrayLike, v_mount: ArrayLike,
                    target: ArrayLike) -> NDArray[np.float64]:
    """Angle (rad) between ``v_mount`` (mount frame) carried by the mechanism at ``q`` and
    ``target`` (base frame); ``q`` (..., n_axes), vectors (3,) or broadcasting (..., 3)."""
    R = mount_pose(mech, q)[..., :3, :3]
    v = (R @ np.asarray(v_mount, dtype=float)[..., None])[..., 0]
    y = np.broadcast_to(np.asarray(target, dtype=float), v.shape)
    return np.arctan2(np.linalg.norm(np.cross(v, y), axis=-1), np.sum(v * y, axis=-1))


# ----------------------------------------------------------------------------------------------
# orientation inverse kinematics: Paden-Kahan subproblems


@dataclass(frozen=True)
class Orientation:
    """A solution of :func:`orient`.

    Attributes:
        q: Axis values, rad or m, (n_axes,), inside the axis ranges (to :data:`RANGE_TOL`)
            (prismatic axes and free revolute axes: the nearby configuration's values).
        residual_rad: Angle left between the turned direction and the target, rad: 0 (to
            round-off) where the mechanism can reach the target, else the least angle error
            it can achieve (a turntable asked to tilt, a positioner whose tilt cannot reach).
        branch: Which of two exact solutions of a two-axis mechanism this is (+1 or -1: the
            side of the plane of the two axes that the direction lies on between the two
            turns); 0 where there is only one (a turntable, a touching or closest solution, a
            free axis).
    """

    q: NDArray[np.float64]
    residual_rad: float
    branch: int = 0


def _angle(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    return float(np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b))


def _subproblem1(w: NDArray[np.float64], p: NDArray[np.float64],
                 y: NDArray[np.float64]) -> float:
    """The angle about unit ``w`` that brings ``p``'s component perpendicular to ``w`` onto
    ``y``'s (exact where ``w.p == w.y``, else the closest); NaN where either component is
    nil (the angle is free)."""
    pp = p - w * (w @ p)
    yp = y - w * (w @ y)
    if np.linalg.norm(pp) < FREE_AXIS_TOL or np.linalg.norm(yp) < FREE_AXIS_TOL:
        return float("nan")
    return float(np.arctan2(w @ np.cross(pp, yp), pp @ yp))


def _subproblem2(w1: NDArray[np.float64], w2: NDArray[np.float64], u: NDArray[np.float64],
                 y: NDArray[np.float64]) -> list[tuple[float, float, int]]:
    """The ``(t1, t2, branch)`` with ``exp(w1 t1) exp(w2 t2) u = y`` (unit vectors, ``w1`` not
    parallel to ``w2``).

    The vector ``c = exp(w2 t2) u = exp(-w1 t1) y`` lies on the circle of ``u`` about ``w2``
    (polar angle ``b = angle(w2, u)``) and on the circle of ``y`` about ``w1`` (polar angle
    ``g = angle(w1, y)``). Written ``c = cos(b) w2 + sin(b) (cos(phi) e + sin(phi) f)`` with
    ``e`` the unit vector perpendicular to ``w2`` towards ``w1`` and ``f = w2 x e``, the
    spherical triangle ``w1, w2, c`` (sides ``a = angle(w1, w2)``, ``b``, ``g``; angle ``phi``
    at ``w2``) gives, by the haversine law::

        sin^2(phi/2) = sin((g - |a-b|)/2) sin((g + |a-b|)/2) / (sin a sin b) = h
        cos^2(phi/2) = sin((a+b - g)/2) sin((a+b + g)/2) / (sin a sin b)     = h'

    (``h + h' = 1``), so ``phi = 2 atan2(sqrt h, sqrt h')``, accurate to round-off everywhere,
    also where the circles touch or ``y`` lies near ``w1`` (where ``acos`` of a dot product
    loses half the digits). Two solutions ``+-phi`` (branches +1, -1: the side of the axes'
    plane ``c`` lies on) where both are positive, one (branch 0) where the circles touch. Where
    they do not meet the one closest solution: ``phi = 0`` (``h < 0``) or ``pi`` (``h' < 0``),
    the point of ``u``'s circle whose polar angle about ``w1`` is nearest ``g`` (the angle from
    a point to ``y``'s circle is the difference of their polar angles). ``t2`` turns ``u``'s
    ``phi`` to ``c``'s; ``t1`` is subproblem 1 on the turned ``u``. A free angle (``u`` along
    ``w2``, ``y`` along ``w1``) is NaN."""
    n = np.cross(w1, w2)
    sin_a = float(np.linalg.norm(n))
    a = float(np.arctan2(sin_a, w1 @ w2))
    e = (w1 - (w1 @ w2) * w2) / sin_a
    f = np.cross(w2, e)
    u_perp = u - (w2 @ u) * w2
    sin_b = float(np.linalg.norm(u_perp))
    if sin_b < FREE_AXIS_TOL:  # u along w2: the second axis does not move it
        return [(_subproblem1(w1, u, y), float("nan"), 0)]
    b = float(np.arctan2(sin_b, w2 @ u))
    g = float(np.arctan2(np.linalg.norm(np.cross(w1, y)), w1 @ y))
    d, sigma = abs(a - b), a + b
    h = np.sin((g - d) / 2) * np.sin((g + d) / 2) / (sin_a * sin_b)
    h_c = np.sin((sigma - g) / 2) * np.sin((sigma + g) / 2) / (sin_a * sin_b)
    phi_u = float(np.arctan2(f @ u_perp, e @ u_perp))
    if h <= 0.0:
        branches = [(0.0, 0)]
    elif h_c <= 0.0:
        branches = [(np.pi, 0)]
    else:
        phi = float(2.0 * np.arctan2(np.sqrt(h), np.sqrt(h_c)))
        branches = [(phi, 1), (-phi, -1)]
    out = []
    for phi, branch in branches:
        t2 = phi - phi_u
        out.append((_subproblem1(w1, axis_rotation(w2, t2) @ u, y), t2, branch))
    return out


def _revolute(mech: MechanismSpec) -> list[int]:
    idx = [i for i, a in enumerate(mech.axes) if a.kind == "revolute"]
    if len(idx) > 2:
        raise KinematicsError(f"mechanism '{mech.name}': orienting takes at most two revolute "
                              f"axes, it has {len(idx)}")
    return idx


def _raw_solutions(mech: MechanismSpec, rev: list[int], v_mount: NDArray[np.float64],
                   target: NDArray[np.float64]) -> list[tuple[NDArray[np.float64], int]]:
    """The revolute axes' angles (NaN: free), not yet shifted by 2 pi, each with its branch
    (+1, -1: one of subproblem 2's two solutions; 0: the only one)."""
    u = np.asarray(mech.mount, dtype=float)[:3, :3] @ v_mount
    if not rev:
        return [(np.zeros(0), 0)]
    ws = [_unit(mech.axes[i].axis, f"mechanism '{mech.name}': axis '{mech.axes[i].name}' "
                "direction") for i in rev]
    if len(rev) == 1:
        return [(np.array([_subproblem1(ws[0], u, target)]), 0)]
    w1, w2 = ws
    if np.linalg.norm(np.cross(w1, w2)) < PARALLEL_TOL:  # one axis in effect: the 2nd is free
        return [(np.array([_subproblem1(w1, u, target), np.nan]), 0)]
    return [(np.array([t1, t2]), b) for t1, t2, b in _subproblem2(w1, w2, u, target)]


def _place(t: float, lo: float, hi: float, near: float) -> float | None:
    """``t + 2 pi k`` inside ``[lo, hi]`` nearest ``near``; None where no k fits."""
    k_lo = np.ceil((lo - RANGE_TOL - t) / _TWO_PI)
    k_hi = np.floor((hi + RANGE_TOL - t) / _TWO_PI)
    if k_lo > k_hi:
        return None
    k = min(max(np.round((near - t) / _TWO_PI), k_lo), k_hi)
    return float(t + _TWO_PI * k)


def _fill(rev: list[int], sol: NDArray[np.float64],
          near: NDArray[np.float64]) -> NDArray[np.float64]:
    """Full axis values: ``near`` with the revolute angles ``sol`` (a free one keeps ``near``)."""
    q = near.copy()
    for j, i in enumerate(rev):
        if not np.isnan(sol[j]):
            q[i] = sol[j]
    return q


def _near(mech: MechanismSpec, q_near: ArrayLike, what: str) -> NDArray[np.float64]:
    q = np.asarray(q_near, dtype=float)
    if q.shape != (mech.n_axes,) or not np.all(np.isfinite(q)):
        raise KinematicsError(f"mechanism '{mech.name}': {what} must be {mech.n_axes} finite "
                              f"values, got {q.tolist()}")
    return q


def _fmt(mech: MechanismSpec, i: int, value: float) -> str:
    ax = mech.axes[i]
    if ax.kind == "revolute":
        lo, hi = np.rad2deg(ax.range)
        return f"axis '{ax.name}' at {np.rad2deg(value):.2f} deg, range [{lo:.1f}, {hi:.1f}] deg"
    return f"axis '{ax.name}' at {value:.4f} m, range [{ax.range[0]:.4f}, {ax.range[1]:.4f}] m"


def orient(mech: MechanismSpec, v_mount: ArrayLike, target: ArrayLike,
           q_near: ArrayLike) -> Orientation:
    """Axis values that turn the direction ``v_mount`` (mount frame) onto ``target`` (base
    frame), closed form.

    Two revolute axes (tilt-rotate positioner): Paden-Kahan subproblem 2 on
    ``exp(w1 t1) exp(w2 t2) R_mount v = target`` for any non-parallel axis directions, up to
    two solutions; one revolute axis (turntable): subproblem 1, the angle bringing ``v``'s
    component perpendicular to the axis onto ``target``'s. Where no exact solution exists the
    closest one (least angle error) is returned with its residual. A revolute axis that does
    not move the direction (``v`` along it, or the target along the first axis) is free and
    keeps its ``q_near`` value (clipped into its range); prismatic axes keep ``q_near``'s values.
    Each angle may be shifted by a multiple of 2 pi into its range, nearest ``q_near``; of the
    solutions inside the ranges the one nearest ``q_near`` is returned.

    Args:
        mech: The mechanism (at most two revolute axes).
        v_mount: Direction in the mount frame (normalised here), (3,).
        target: Direction in the base frame (normalised here), (3,).
        q_near: The configuration to stay near, (n_axes,).

    Returns:
        :class:`Orientation`: the axis values and the residual angle (rad).

    Raises:
        KinematicsError: Bad input (zero vector, wrong size, more than two revolute axes).
        UnreachableError: Every solution lies outside an axis range (the message names the
            axis; ``distance`` is how far outside, rad or m).
    """
    near = _near(mech, q_near, "q_near")
    v = _unit(v_mount, "v_mount")
    y = _unit(target, "target")
    q, branch = _nearest_in_range(mech, _raw_solutions(mech, _revolute(mech), v, y), near)
    return Orientation(q, float(direction_error(mech, q, v, y)), branch)


def _nearest_in_range(mech: MechanismSpec, sols: list[tuple[NDArray[np.float64], int]],
                      near: NDArray[np.float64]) -> tuple[NDArray[np.float64], int]:
    """Of the solutions, each angle shifted by 2 pi k into its range nearest ``near``, the one
    nearest ``near``, with its branch; UnreachableError where none fits the ranges."""
    rev = _revolute(mech)
    best, best_d, worst_out = None, np.inf, (np.inf, "")
    for sol, branch in sols:
        placed: NDArray[np.float64] | None = sol.copy()
        for j, i in enumerate(rev):
            lo, hi = mech.axes[i].range
            t = np.clip(near[i], lo, hi) if np.isnan(sol[j]) else _place(sol[j], lo, hi, near[i])
            if t is None:
                wrapped = (sol[j] - lo) % _TWO_PI + lo  # the nearest miss, for the message
                miss = min(wrapped - hi, lo + _TWO_PI - wrapped)
                if miss < worst_out[0]:
                    worst_out = (miss, _fmt(mech, i, wrapped))
                placed = None
                break
            placed[j] = t
        if placed is None:
            continue
        q = _fill(rev, placed, near)
        d = float(np.linalg.norm(q - near))
        if d < best_d:
            best, best_d = (q, branch), d
    if best is None:
        raise UnreachableError(f"mechanism '{mech.name}': no orientation inside the axis "
                               f"ranges: {worst_out[1]}", float(worst_out[0]))
    return best


def orient_path(mech: MechanismSpec, v_mount_samples: ArrayLike, target: ArrayLike,
                q_start: ArrayLike) -> NDArray[np.float64]:
    """Axis values along a sampled path turning each ``v_mount_samples[k]`` onto ``target``,
    branch-continuous.

    The first sample is :func:`orient` near ``q_start``. Each next one stays on the previous
    sample's branch (:attr:`Orientation.branch`: of a positioner's two solutions, the one on
    the same side of the axes' plane, whatever the sample spacing); where the previous had no
    branch (the solutions touch, none is exact, an axis is free) it is the solution nearest the
    previous values. Its angles are unwrapped onto the previous ones (no 2 pi jumps: a rotate
    axis turning a circumferential seam round advances past +-pi where its range allows). A free
    axis keeps the previous value. Residuals are not returned: :func:`direction_error` gives
    them.

    Args:
        mech: The mechanism (at most two revolute axes).
        v_mount_samples: Directions in the mount frame, (N, 3).
        target: Direction in the base frame, (3,), or one per sample, (N, 3).
        q_start: The configuration to start near, (n_axes,).

    Returns:
        Axis values, (N, n_axes).

    Raises:
        KinematicsError: Bad input.
        UnreachableError: The branch must jump: the continuous solution leaves an axis range at
            a sample (the positioner would have to flip); the message names the sample index and
            the axis.
    """
    V = np.asarray(v_mount_samples, dtype=float)
    if V.ndim != 2 or V.shape[1] != 3 or V.shape[0] == 0:
        raise KinematicsError(f"mechanism '{mech.name}': v_mount_samples must have shape "
                              f"(N, 3), got {V.shape}")
    Y = np.broadcast_to(np.asarray(target, dtype=float), V.shape)
    rev = _revolute(mech)
    try:
        first = orient(mech, V[0], Y[0], q_start)
    except UnreachableError as exc:
        raise UnreachableError(f"sample 0: {exc}", exc.distance) from None
    out = np.empty((V.shape[0], mech.n_axes))
    out[0] = prev = first.q
    branch = first.branch
    for k in range(1, V.shape[0]):
        v = _unit(V[k], f"v_mount_samples[{k}]")
        y = _unit(Y[k], f"target[{k}]")
        sols = _raw_solutions(mech, rev, v, y)
        same = [(sol, b) for sol, b in sols if branch != 0 and b == branch]
        best, best_d, best_b = prev, np.inf, branch
        for sol, b in same or sols:
            for j, i in enumerate(rev):
                if not np.isnan(sol[j]):
                    sol[j] += _TWO_PI * np.round((prev[i] - sol[j]) / _TWO_PI)
            q = _fill(rev, sol, prev)
            d = float(np.linalg.norm(q - prev))
            if d < best_d:
                best, best_d, best_b = q, d, b
        for i in rev:
            lo, hi = mech.axes[i].range
            if not lo - RANGE_TOL <= best[i] <= hi + RANGE_TOL:
                raise UnreachableError(
                    f"mechanism '{mech.name}': sample {k}: the orientation branch must jump: "
                    f"{_fmt(mech, i, best[i])}", float(max(lo - best[i], best[i] - hi)))
        out[k] = prev = best
        branch = best_b
    return out


__all__ = ["FREE_AXIS_TOL", "PARALLEL_TOL", "RANGE_TOL", "Orientation", "axis_rotation",
           "direction_error", "link_poses", "mount_pose", "orient", "orient_path"]
