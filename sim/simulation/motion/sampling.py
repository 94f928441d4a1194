"""A Cartesian move turned into joint via points: where it is sampled, and the inverse
kinematics of the samples.

Owns the sample times of a move (every sampling period, finer where the tool turns fast or
weaves, at a pattern's corners: :func:`_sample_times`, :func:`_turn_limited_period`,
:func:`_weave_period`), the branch-continuous inverse kinematics of the samples, refined
where a joint turns fast and where the joint polynomial through them leaves the move between
them (:func:`_ik_knots`, :func:`_ik_knots_refined`, :func:`_off_path`), the tool poses of a
state (:func:`_poses`) and a 5-axis arm's poses turned into its plane
(:func:`_into_j1_plane`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import CellsimError, ReachError, ScenarioError
from sim.simulation.motion.checks import MAX_STEPS

#: Least number of inverse-kinematics samples per weave cycle and per corner blend. Patterns
#: with corners (zigzag, triangle, dwells) get twice as many: the joint polynomial rounds a
#: corner over about one sample spacing, overshooting by about 1 % of the amplitude at 48.
SAMPLES_PER_WEAVE_CYCLE = 24
SAMPLES_PER_BLEND = 8
#: A corner that turns the torch gets an inverse-kinematics sample at least every this many
#: degrees of the turn, so the joints follow the commanded frame through it.
DEG_PER_CORNER_SAMPLE = 2.0


def _smooth_weave(weave: Any) -> bool:
    """Whether a weave's pattern has no corners (a sine or a circle without dwells)."""
    return weave is None or (weave.pattern in ("sine", "circle") and weave.dwell == 0.0)


def _weave_period(weave: Any) -> float:
    """Sample spacing for a weave, s."""
    return weave.period / (SAMPLES_PER_WEAVE_CYCLE * (1 if _smooth_weave(weave) else 2))


#: Most the tool frame or the path's direction may turn between neighbouring inverse-kinematics
#: samples, deg: the joint polynomial through them follows a tool turning fast (a small
#: circle) only if they are this close.
MAX_TURN_PER_SAMPLE_DEG = 3.0


def _turn_limited_period(cart: Any, period: float, label: str,
                         longest: float = np.inf) -> float:
    """``period`` shortened where the tool frame or the path's direction turns more than
    :data:`MAX_TURN_PER_SAMPLE_DEG` between samples (the weave left out: it has its own);
    ``longest``: as for :func:`_sample_times`."""
    ts = _sample_times(cart.duration, period, np.zeros(0), label, longest)
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
                  label: str, longest: float = np.inf) -> NDArray[np.float64]:
    """Sample times over ``[0, duration]``: every ``period`` and at the ``extra`` times (the
    corners of a pattern, phase ends), points closer than a quarter period to one of those
    dropped. A move longer than ``longest`` s (what a run can simulate:
    :attr:`CartesianContext.max_phase_s`) is refused before it is sampled (a speed typed a
    thousand times too slow would otherwise be solved for minutes first)."""
    if duration > longest:
        raise ScenarioError(
            f"{label}: the move lasts {duration:.4g} s, longer than a run can simulate "
            f"({longest:.4g} s: {MAX_STEPS:,} steps of the cell's timestep, "
            "simulation.timestep_s); raise its speed or split it")
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
    return _one_branch(ts, q_via, q0, label, robot, one_branch)


def _one_branch(ts: NDArray[np.float64], q_via: NDArray[np.float64], q0: NDArray[np.float64],
                label: str, robot: Any, one_branch: bool) -> NDArray[np.float64]:
    """``q_via`` checked for jumps between branches (:func:`_ik_knots`) and its first sample
    for a jump away from ``q0``; the first sample set to ``q0``."""
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


#: How far the joint polynomial through a Cartesian move's samples may leave the move between
#: two samples, judged at the middle of each interval on the polynomial's own forward
#: kinematics against the move's pose there (:func:`_off_path`): the tool point's distance,
#: m; the tool frame's turn, deg (a 6-axis arm; a 5-axis arm holds the orientation its plane
#: allows); the tool point's mean speed over each half interval, as a share of the move's top
#: speed. A cubic polynomial (4-3-4) through samples every 0.1 s rang for a few samples after
#: a ramp (where the programmed acceleration steps): the LR Mate's 8 mm/s welds ran 1.5 %
#: fast there, its 100 mm/s moves 33 um off their line (new-user trial).
PATH_TOL_M = 1e-5
TURN_TOL_DEG = 0.05
SPEED_TOL = 0.0025
#: ... and at least this, m/s (a move of the axes that carry the arm, the tool still in the
#: arm's frame: its speed there is rounding).
SPEED_FLOOR_M_S = 1e-6
#: Times the intervals off the move are halved (each adds a sample at its middle).
PATH_REFINEMENTS = 6


@dataclass(frozen=True)
class Carried:
    """A coordinated move's axes, which carry the arm or the part (:mod:`~sim.simulation.
    motion.axes`): one polynomial moves the arm's joints and the axes, so the tool's path is
    judged in the move's own frame."""

    #: The axes' values at times ``t``: (k,) -> (k, n_axes).
    axes_at: Callable[[NDArray[np.float64]], NDArray[np.float64]]
    #: Frame-0 tool poses (k, 4, 4) at axes' values (k, n_axes), in the move's frame.
    in_move_frame: Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]
    #: The move's tool poses at times ``t``, in its frame: (k,) -> (k, 4, 4).
    move_at: Callable[[NDArray[np.float64]], NDArray[np.float64]]


def _off_path(kin: Any, ts: NDArray[np.float64], q: NDArray[np.float64],
              poses_at: Callable[[Any], Any], planner: str,
              carried: Carried | None = None) -> NDArray[np.int64]:
    """The intervals ``[ts[k], ts[k + 1]]`` in which the joint polynomial of ``planner``
    through ``(ts, q)`` (at rest at both ends, as a phase's) leaves the move's poses
    (``poses_at``) at the interval's middle by more than :data:`PATH_TOL_M` or
    :data:`TURN_TOL_DEG`, or runs its halves at a mean speed more than :data:`SPEED_TOL` (at
    least :data:`SPEED_FLOOR_M_S`) off the move's. At the samples both are the forward
    kinematics of ``q``. With ``carried`` the axes' values join the polynomial and the tool
    point is judged in the move's frame (:class:`Carried`)."""
    from planners.registry import get_planner

    n = kin.n_joints
    dt = np.diff(ts)
    mid = ts[:-1] + 0.5 * dt
    q_all = q if carried is None else np.hstack([q, carried.axes_at(ts)])
    q_mid = np.asarray(get_planner(planner)(ts, q_all).at(mid).q, dtype=float)
    got = np.asarray(kin.fk(q_mid[:, :n]), dtype=float)
    want = np.asarray(poses_at(mid), dtype=float)
    knots = np.asarray(kin.fk(q), dtype=float)
    if carried is None:
        p_got, p_want, at = got[:, :3, 3], want[:, :3, 3], knots[:, :3, 3]
    else:
        p_got = carried.in_move_frame(q_mid[:, n:], got)[:, :3, 3]
        p_want = carried.move_at(mid)[:, :3, 3]
        at = carried.in_move_frame(q_all[:, n:], knots)[:, :3, 3]
    bad = np.linalg.norm(p_got - p_want, axis=1) > PATH_TOL_M
    half = 0.5 * dt[:, None]
    v_got = np.hstack([np.linalg.norm(p_got - at[:-1], axis=1)[:, None],
                       np.linalg.norm(at[1:] - p_got, axis=1)[:, None]]) / half
    v_want = np.hstack([np.linalg.norm(p_want - at[:-1], axis=1)[:, None],
                        np.linalg.norm(at[1:] - p_want, axis=1)[:, None]]) / half
    top = float(v_want.max()) if v_want.size else 0.0
    tol = max(SPEED_TOL * top, SPEED_FLOOR_M_S)
    bad |= (np.abs(v_got - v_want) > tol).any(axis=1)
    if not kin.family.five_axis:
        cos_turn = (np.einsum("kij,kij->k", got[:, :3, :3], want[:, :3, :3]) - 1.0) / 2.0
        bad |= cos_turn < np.cos(np.radians(TURN_TOL_DEG))
    return np.flatnonzero(bad)


def _ik_knots_refined(kin: Any, ts: NDArray[np.float64], poses_at: Callable[[Any], Any],
                      q0: NDArray[np.float64], label: str, robot: Any = None,
                      one_branch: bool = True, planner: str | None = None,
                      carried: Carried | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`_ik_knots` at ``ts``, with the intervals in which a joint turns more than
    :data:`MAX_JOINT_STEP_DEG` subdivided (``poses_at(times)`` gives the poses) until none
    does, then (given the phase's ``planner``; not for a trial plan, ``one_branch = False``,
    nor for a weave with corners, which the polynomial rounds: :func:`_smooth_weave`) each
    interval in which its joint polynomial leaves the move (:func:`_off_path`) halved
    until none does, at most :data:`PATH_REFINEMENTS` times (a coordinated move's axes judged
    with the arm, ``carried``): ``(times, joint via points)``.
    A halving's samples continue the branch of the sample before them."""
    ts, q = _joint_refined(kin, ts, poses_at, q0, label, robot, one_branch)
    if planner is None or not one_branch:
        return ts, q
    for _ in range(PATH_REFINEMENTS):
        off = _off_path(kin, ts, q, poses_at, planner, carried)
        if off.size == 0:
            break
        _check_count(ts.size + off.size, label)
        new = 0.5 * (ts[off] + ts[off + 1])
        q_new = _ik_between(kin, poses_at(new), q[off], label)
        order = np.argsort(np.concatenate([ts, new]), kind="stable")
        ts = np.concatenate([ts, new])[order]
        q = _one_branch(ts, np.concatenate([q, q_new])[order], q0, label, robot, one_branch)
    return ts, q


def _ik_between(kin: Any, poses: NDArray[np.float64], q_before: NDArray[np.float64],
                label: str) -> NDArray[np.float64]:
    """Inverse kinematics of each pose, in the branch of its ``q_before`` (the sample before
    it)."""
    from sim.robots.kinematics.ik import ik_path

    out = np.empty((poses.shape[0], q_before.shape[1]))
    for k in range(poses.shape[0]):
        try:
            out[k] = ik_path(kin, poses[k:k + 1], q_start=q_before[k])[0]
        except CellsimError as exc:
            raise ReachError(f"{label}: {exc}") from None
    return out


def _check_count(n: int, label: str) -> None:
    if n > MAX_PHASE_SAMPLES:
        raise ScenarioError(f"{label}: its joints turn so fast along the path that it needs "
                            f"more than {MAX_PHASE_SAMPLES:,} inverse-kinematics samples "
                            "(a wrist singularity on the path?)")


def _joint_refined(kin: Any, ts: NDArray[np.float64], poses_at: Callable[[Any], Any],
                   q0: NDArray[np.float64], label: str, robot: Any, one_branch: bool
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`_ik_knots` at ``ts``, subdivided where a joint turns more than
    :data:`MAX_JOINT_STEP_DEG` between samples."""
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
        _check_count(ts.size + new.size, label)
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
