"""A Cartesian move turned into joint via points: where it is sampled, and the inverse
kinematics of the samples.

Owns the sample times of a move (every sampling period, finer where the tool turns fast or
weaves, at a pattern's corners: :func:`_sample_times`, :func:`_turn_limited_period`,
:func:`_weave_period`), the branch-continuous inverse kinematics of the samples, refined
where a joint turns fast (:func:`_ik_knots`, :func:`_ik_knots_refined`), the tool poses of
a state (:func:`_poses`) and a 5-axis arm's poses turned into its plane
(:func:`_into_j1_plane`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import CellsimError, ReachError, ScenarioError

#: Least number of inverse-kinematics samples per weave cycle and per corner blend. Patterns
#: with corners (zigzag, triangle, dwells) get twice as many: the joint polynomial rounds a
#: corner over about one sample spacing, overshooting by about 1 % of the amplitude at 48.
SAMPLES_PER_WEAVE_CYCLE = 24
SAMPLES_PER_BLEND = 8
#: A corner that turns the torch gets an inverse-kinematics sample at least every this many
#: degrees of the turn, so the joints follow the commanded frame through it.
DEG_PER_CORNER_SAMPLE = 2.0


def _weave_period(weave: Any) -> float:
    """Sample spacing for a weave, s."""
    smooth = weave.pattern in ("sine", "circle") and weave.dwell == 0.0
    return weave.period / (SAMPLES_PER_WEAVE_CYCLE * (1 if smooth else 2))


#: Most the tool frame or the path's direction may turn between neighbouring inverse-kinematics
#: samples, deg: the joint polynomial through them follows a tool turning fast (a small
#: circle) only if they are this close.
MAX_TURN_PER_SAMPLE_DEG = 3.0


def _turn_limited_period(cart: Any, period: float, label: str) -> float:
    """``period`` shortened where the tool frame or the path's direction turns more than
    :data:`MAX_TURN_PER_SAMPLE_DEG` between samples (the weave left out: it has its own)."""
    ts = _sample_times(cart.duration, period, np.zeros(0), label)
    st = cart.at(ts)
    R = st.rotation
    cos_r = (np.einsum("kij,kij->k", R[:-1], R[1:]) - 1.0) / 2.0
    turn = np.arccos(np.clip(cos_r, -1.0, 1.0))
    v = st.velocity
    sp = np.linalg.norm(v, axis=1)
    moving = (sp[:-1] > 1e-9) & (sp[1:] > 1e-9)
    if np.any(moving):
        d = np.einsum("ki,ki->k", v[:-1], v[1:]) / np.maximum(sp[:-1] * sp[1:], 1e-300)
        turn = np.maximum(turn, np.where(moving, np.arccos(np.clip(d, -1.0, 1.0)), 0.0))
    worst = float(np.degrees(turn.max())) if turn.size else 0.0
    if worst <= MAX_TURN_PER_SAMPLE_DEG:
        return period
    return period / float(np.ceil(worst / MAX_TURN_PER_SAMPLE_DEG))


#: Most inverse-kinematics samples of one Cartesian phase.
MAX_PHASE_SAMPLES = 1_000_000


def _sample_times(duration: float, period: float, extra: NDArray[np.float64],
                  label: str) -> NDArray[np.float64]:
    """Sample times over ``[0, duration]``: every ``period`` and at the ``extra`` times (the
    corners of a pattern, phase ends), points closer than a quarter period to one of those
    dropped."""
    count = duration / period
    if not np.isfinite(count) or count > MAX_PHASE_SAMPLES:
        raise ScenarioError(
            f"{label}: the move lasts {duration:.4g} s; sampled every {period:.4g} s that is "
            f"{count:.3g} inverse-kinematics samples, more than {MAX_PHASE_SAMPLES:,} "
            "(raise speed_mm_s or sample_period_s)")
    n = max(2, int(np.ceil(count - 1e-9)))
    ts = np.linspace(0.0, duration, n + 1)
    extra = np.unique(np.asarray(extra, dtype=float))
    extra = extra[(extra > 1e-9) & (extra < duration - 1e-9)]
    if extra.size:
        # drop grid points closer than a quarter period to an extra time (searchsorted: no
        # grid x extra matrix)
        k = np.clip(np.searchsorted(extra, ts), 1, extra.size) if extra.size > 1 else \
            np.zeros(ts.size, dtype=int)
        lo = extra[np.clip(k - 1, 0, extra.size - 1)]
        hi = extra[np.clip(k, 0, extra.size - 1)]
        gap = np.minimum(np.abs(ts - lo), np.abs(ts - hi))
        near = gap < 0.25 * duration / n
        near[[0, -1]] = False
        ts = np.unique(np.r_[ts[~near], extra])
    return ts


#: Least joint change between neighbouring inverse-kinematics samples that counts as a change
#: of branch (a wrist flip, a whole turn) rather than motion, deg; larger where the joint's
#: speed limit covers more in the samples' spacing.
BRANCH_JUMP_DEG = 90.0


def _ik_knots(kin: Any, ts: NDArray[np.float64], poses: NDArray[np.float64],
              q0: NDArray[np.float64], label: str, robot: Any = None,
              one_branch: bool = True) -> NDArray[np.float64]:
    """Joint via points of the tool poses ``poses`` at times ``ts``, continuing from ``q0``
    (``one_branch = False``: a trial plan, jumps between branches let through).

    Raises:
        ReachError: A pose is out of reach, or the path cannot be followed in one branch: the
            inverse kinematics jumps between neighbouring samples (the branch the arm is in
            runs into a joint's range, and another takes over): the error names the joint,
            the time and the jump.
    """
    from sim.robots.kinematics.ik import ik_path

    try:
        q_via = np.asarray(ik_path(kin, poses, q_start=q0), dtype=float)
    except CellsimError as exc:
        raise ReachError(f"{label}: {exc}") from None
    step = np.abs(np.diff(q_via, axis=0))
    allowed = np.full(step.shape, np.radians(BRANCH_JUMP_DEG))
    if robot is not None and robot.max_speed:
        allowed = np.maximum(allowed, 1.5 * np.diff(ts)[:, None]
                             * np.asarray(robot.max_speed, dtype=float)[None, :])
    if one_branch and np.any(step > allowed):
        k, j = np.unravel_index(int(np.argmax(step - allowed)), step.shape)
        raise ReachError(
            f"{label}: the path cannot be followed in one arm configuration: joint j{j + 1} "
            f"jumps {np.degrees(step[k, j]):.0f} deg between {ts[k]:.3f} and {ts[k + 1]:.3f} s "
            "of the move (its branch runs into a joint range there and another takes over: a "
            "wrist flip or a whole turn); turn the part or the seam, or change the torch "
            "posture or the start configuration")
    jump = np.abs(q_via[0] - q0)
    if np.any(jump > 1e-6):
        j = int(np.argmax(jump))
        raise ScenarioError(f"{label}: inverse kinematics of the start pose changes joint j{j + 1} "
                            f"by {np.rad2deg(jump[j]):.3g} deg (another branch); check the "
                            "previous phase's end pose")
    q_via[0] = q0
    return q_via


#: Most any joint may turn between neighbouring inverse-kinematics samples, deg: the joint
#: polynomial through the samples leaves the tool's path between them by about the square of
#: the step (near a wrist singularity J4 and J6 turn fast while the tool hardly turns: an
#: IRB 2400 arc at 16 mm/s with J4 at 330 deg/s came out 2.7 % fast between 0.1 s samples).
MAX_JOINT_STEP_DEG = 10.0
#: Times an interval whose joints turn more than that is subdivided.
JOINT_REFINEMENTS = 4


def _ik_knots_refined(kin: Any, ts: NDArray[np.float64], poses_at: Callable[[Any], Any],
                      q0: NDArray[np.float64], label: str, robot: Any = None,
                      one_branch: bool = True
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`_ik_knots` at ``ts``, with the intervals in which a joint turns more than
    :data:`MAX_JOINT_STEP_DEG` subdivided (``poses_at(times)`` gives the poses) until none
    does: ``(times, joint via points)``."""
    q = _ik_knots(kin, ts, poses_at(ts), q0, label, robot, one_branch)
    limit = np.radians(MAX_JOINT_STEP_DEG)
    for _ in range(JOINT_REFINEMENTS):
        step = np.abs(np.diff(q, axis=0)).max(axis=1)
        coarse = np.nonzero(step > limit)[0]
        if coarse.size == 0:
            break
        parts = np.ceil(step[coarse] / limit).astype(int)
        new = np.concatenate([np.linspace(ts[k], ts[k + 1], n + 1)[1:-1]
                              for k, n in zip(coarse, parts, strict=True)])
        if ts.size + new.size > MAX_PHASE_SAMPLES:
            raise ScenarioError(f"{label}: its joints turn so fast along the path that it needs "
                                f"more than {MAX_PHASE_SAMPLES:,} inverse-kinematics samples "
                                "(a wrist singularity on the path?)")
        ts = np.union1d(ts, new)
        q = _ik_knots(kin, ts, poses_at(ts), q0, label, robot, one_branch)
    return ts, q


def _into_j1_plane(poses: NDArray[np.float64]) -> NDArray[np.float64]:
    """Poses (frame 0) with the tool's x axis (the 5-axis family's approach) turned by the
    least rotation into the vertical plane through J1 and the tool point: what a 5-axis arm
    can hold. A blended corner interpolates orientations between two such planes; this keeps
    the corner's torch in the arm's plane at every point."""
    out = poses.copy()
    for k, T in enumerate(poses):
        rho = np.array([T[0, 3], T[1, 3], 0.0])
        if np.linalg.norm(rho) < 1e-9:
            continue
        m = np.cross([0.0, 0.0, 1.0], rho / np.linalg.norm(rho))
        a = T[:3, 0]
        b = a - (a @ m) * m
        nb = np.linalg.norm(b)
        if nb < 1e-9 or abs(a @ m) < 1e-12:
            continue
        b /= nb
        v, c = np.cross(a, b), float(a @ b)
        V = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
        out[k, :3, :3] = (np.eye(3) + V + V @ V / (1.0 + c)) @ T[:3, :3]
    return out


def _poses(states: Any) -> NDArray[np.float64]:
    n = states.position.shape[0]
    poses = np.zeros((n, 4, 4))
    poses[:, :3, :3] = states.rotation
    poses[:, :3, 3] = states.position
    poses[:, 3, 3] = 1.0
    return poses
