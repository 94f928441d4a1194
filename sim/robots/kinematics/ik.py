"""Analytic inverse kinematics of the cellsim robots, and branch-continuous IK along a path.

The closed-form solutions live with their kinematic family (:meth:`KinematicFamily.ik
<sim.robots.families.KinematicFamily.ik>`: seed 000 eq. 13-17 for
:class:`~sim.robots.families.FiveR`, seed 004 eq. 9-18 for
:class:`~sim.robots.families.Fanuc6`); this module maps a tcp pose to the family's tool frame,
offers every joint in each ``theta + 2 k pi`` representation that its range allows (e.g. J4
+-190 deg, J6 +-360 deg on the 200iC), and ranks the solutions.

Ranking (documented criterion): solutions inside the joint ranges first, then by the
joint-space distance to the current configuration weighted by each joint's maximum speed,
``sqrt(sum(((q_i - q_cur_i) / v_max_i)^2))`` (seconds: a proxy for motion time).

Singularities: at the wrist singularity (200iC ``theta5 = 0``; only ``theta4 + theta6`` is
defined) J4 keeps its current value and a :class:`SingularityWarning` is issued; likewise J1
when the wrist centre (200iC) or the tool point and tool x axis (5R) lie on the J1 axis.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.core.rotations import invert_transform, wrap_to_pi
from sim.errors import KinematicsError, SingularityWarning, UnreachableError
from sim.robots.families.five_r import PLANE_TOL, SINGULAR_TOL, ik_5r_seed
from sim.robots.kinematics.model import KinematicModel

__all__ = ["IKSolution", "PLANE_TOL", "SINGULAR_TOL", "SingularityWarning", "ik_5r_seed",
           "ik_path", "listed", "ranking_cost", "solve_ik"]


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
    raw = model.family.ik(T_seed, cur)
    out: list[IKSolution] = []
    kept = np.empty((0, model.n_joints))  # the q of ``out``, stacked: one test per candidate
    for q, branch in raw:
        for rep in _representations(model, q, cur):
            if len(kept) and bool((np.abs(kept - rep).max(axis=1) < 1e-9).any()):
                continue
            kept = np.vstack([kept, rep])
            out.append(IKSolution(q=rep, within_limits=bool(model.within_limits(rep)),
                                  branch=branch, cost=ranking_cost(model, rep, cur)))
    out.sort(key=lambda s: (not s.within_limits, s.cost))
    return out


def listed(solutions: Sequence[IKSolution]) -> list[IKSolution]:
    """The solutions as ``cellsim ik`` lists them: every one inside the joint ranges; of those
    outside, one per posture (the first, so the best ranked, of the whole-turn variants of a
    joint that :func:`solve_ik` gives for each, which are the same posture), as
    :meth:`sim.robots.arm.Arm.ik` lists an arm given as data (the same arm by name listed 24
    solutions and by its file 14: found by a session's trial)."""
    out: list[IKSolution] = []
    seen: list[NDArray[np.float64]] = []
    for s in solutions:
        if not s.within_limits:
            w = wrap_to_pi(np.asarray(s.q, dtype=float))
            if any(np.abs(wrap_to_pi(w - v)).max() < 1e-9 for v in seen):
                continue
            seen.append(w)
        out.append(s)
    return out


def ik_path(model: KinematicModel, poses: Sequence[ArrayLike] | NDArray[np.float64],
            q_start: ArrayLike | None = None, respect_limits: bool = True) -> NDArray[np.float64]:
    """Branch-continuous IK along a sequence of tcp poses.

    At each point the solution closest (ranking criterion) to the previous point's solution is
    taken; the first point is compared with ``q_start`` (default home). An arm solved
    numerically continues from the previous point by one local Newton run where that lands
    near it (:meth:`~sim.robots.families.KinematicFamily.ik_continue`), and searches every
    branch elsewhere.

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
    if prev.shape != (model.n_joints,):
        raise KinematicsError(f"current configuration must have {model.n_joints} values")
    bad = ~np.all(np.isfinite(P), axis=(1, 2))
    if np.any(bad):
        raise KinematicsError(f"path point {int(np.argmax(bad))}: pose must be a finite 4x4 "
                              "transform")
    R = P[:, :3, :3]
    skewed = np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max(axis=(1, 2)) > 1e-6
    if np.any(skewed):
        raise KinematicsError(f"path point {int(np.argmax(skewed))}: pose rotation is not "
                              "orthonormal")
    seeds = P @ invert_transform(model.tcp_offset)
    out = np.empty((P.shape[0], model.n_joints))
    for k, T_seed in enumerate(seeds):
        # a numeric arm continues its branch locally where it can (one Newton run, not a
        # global search); a closed form lists every branch
        q = None
        near = model.family.ik_continue(T_seed, prev) if k > 0 else None
        if near is not None:
            q = _nearest_representation(model, [near], prev, respect_limits)
        if q is None:
            try:
                raw = model.family.ik_branches(T_seed, prev)
            except UnreachableError as exc:
                raise UnreachableError(f"path point {k} {_at(P[k])}: {exc}",
                                       exc.distance) from None
            q = _nearest_representation(model, raw, prev, respect_limits)
        if q is None:
            raise UnreachableError(f"path point {k} {_at(P[k])}: no IK solution inside the "
                                   "joint ranges", 0.0)
        out[k] = q
        prev = q
    return out


def _at(T: NDArray[np.float64]) -> str:
    """Where a path point's tool point is: ``(X Y Z = x y z mm in frame 0)``."""
    x, y, z = 1e3 * T[:3, 3]
    return f"(X Y Z = {x:.1f} {y:.1f} {z:.1f} mm in frame 0)"


#: Whole turns tried for a joint with a finite range (as :func:`_representations`).
_TURNS = 2.0 * np.pi * np.arange(-3, 4)


def _nearest_representation(model: KinematicModel, raw: list[NDArray[np.float64]],
                            current: NDArray[np.float64], respect_limits: bool
                            ) -> NDArray[np.float64] | None:
    """The nearest of :func:`solve_ik`'s solutions (least ranking cost; with
    ``respect_limits`` among those inside the ranges, None when there is none) from ``raw``
    (the family's solutions), in O(n) per solution: the ranking cost is a sum over the
    joints, so each joint takes on its own the in-range ``theta + 2 k pi`` nearest
    ``current`` (the nearest one where the range is unknown)."""
    if not raw:
        return None
    lo, hi = model.lower, model.upper
    W = wrap_to_pi(np.asarray(raw, dtype=float))  # (b, n)
    rep = W + 2 * np.pi * np.round((current - W) / (2 * np.pi))  # nearest turn, any range
    if lo is not None and hi is not None:
        finite = np.isfinite(lo) & np.isfinite(hi)
        cands = W[..., None] + _TURNS  # (b, n, 7)
        inside = (cands >= lo[:, None] - 1e-9) & (cands <= hi[:, None] + 1e-9)
        dist = np.where(inside, np.abs(cands - current[:, None]), np.inf)
        pick = np.take_along_axis(cands, np.argmin(dist, axis=2)[..., None], axis=2)[..., 0]
        rep = np.where(finite, np.where(inside.any(axis=2), pick, W), rep)
        within = np.all((rep >= lo - 1e-9) & (rep <= hi + 1e-9), axis=1)
    else:
        within = np.ones(len(rep), dtype=bool)
    cost = np.sqrt(np.sum(((rep - current) / model.max_speed) ** 2, axis=1))
    if respect_limits:
        if not np.any(within):
            return None
        cost = np.where(within, cost, np.inf)
    return rep[int(np.argmin(cost))]
