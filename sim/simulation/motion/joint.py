"""Joint phases: a pose target solved to joint values, timing by a share of the joint speed
limits, and a joint move that blends into the next one.

Owns :func:`_solve_target` (a joint phase's pose target: the in-limits inverse kinematics
solution closest to its start, with its CONFIG), :func:`_timed_by_speed` (``speed_pct``) and
:func:`_joint_blend` (``blend_deg``).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import CellsimError, ReachError, ScenarioError
from sim.scenario import JointPhase, Phase, plan_phase
from sim.scenario.phases import MAX_TIME_S
from sim.simulation.motion.checks import _config_text
from sim.simulation.motion.context import CartesianContext
from sim.simulation.motion.seams import _seam_pose


def _timed_by_speed(placed: JointPhase, robot: Any, label: str = "") -> JointPhase:
    """A phase timed like a controller's joint move at ``speed_pct`` of the joint speed limits:
    the duration makes the peak speed of the joint that takes longest ``speed_pct`` times its
    limit, and no joint's acceleration over its limit (the knots keep their shares of the
    time; with a blend's boundary speed the duration grows until both hold)."""
    share = placed.times - placed.t0
    total = float(share[-1])
    vlim = placed.speed_pct * np.asarray(robot.max_speed, dtype=float)
    alim = (np.asarray(robot.max_accel, dtype=float) if robot.max_accel
            else np.full(len(vlim), np.inf))
    # rest to rest, 1 s: peak speeds scale as 1/T and accelerations as 1/T^2
    rest = {k: v for k, v in placed.boundary.items() if k not in ("v0", "a0", "vf", "af")}
    trial = dataclasses.replace(placed, times=share / total, durations=np.diff(share / total),
                                boundary=rest)
    ts = np.linspace(0.0, 1.0, 801)
    st = plan_phase(trial, "").at(ts)
    T = max(float(np.max(np.abs(st.qd).max(axis=0) / vlim)),
            float(np.sqrt(np.max(np.abs(st.qdd).max(axis=0) / alim))), 1e-3)
    if not T * (1.0 + 1e-3) <= MAX_TIME_S:  # planned at that length, its powers overflow
        raise ScenarioError(f"{label}: at {placed.speed_pct * 100:g} % of the joint speeds the "
                            f"move takes {T:.3g} s, over the {MAX_TIME_S:g} s a phase may last; "
                            "give a larger speed")
    for _ in range(8):  # with the phase's own boundary speeds (a blend): scale until inside
        times = placed.t0 + share / total * T
        out = dataclasses.replace(placed, times=times, durations=np.diff(times))
        st = plan_phase(out, "").at(np.linspace(out.t0, out.t1, 801))
        over = max(float(np.max(np.abs(st.qd).max(axis=0) / vlim)),
                   float(np.sqrt(np.max(np.abs(st.qdd).max(axis=0) / alim))))
        if over <= 1.0 + 1e-9:
            return out
        T *= over * (1.0 + 1e-6)
    return out


def _joint_blend(placed: JointPhase, nxt: Phase | None, ctx: CartesianContext | None,
                 label: str, robot: Any = None
                 ) -> tuple[JointPhase, tuple[NDArray[np.float64], dict, Any]]:
    """A joint phase that blends into the next joint phase (``blend_deg``): instead of stopping
    at its last knot ``q_c`` it passes the corner without stopping. The incoming and outgoing
    chords are cut where each has moved ``r`` (the largest joint change, at most half the
    chord) from the corner, at ``a`` and ``b``; the phases meet at their midpoint (within ``r``
    of ``q_c`` on every joint) with the velocity ``(b - a) / (t_b - t_a)`` and no acceleration.

    Returns:
        The phase with its new end, and the next phase's start: its first knot, boundary
        values, and its end solved from its pose target (None without one), which the next
        phase reuses.
    """
    if not isinstance(nxt, JointPhase):
        raise ScenarioError(f"{label}.blend_deg: the next phase is not a joint phase to blend "
                            "into (leave blend_deg out)")
    nq = nxt.with_start(placed.t1, placed.q[-1])
    end = None
    if nxt.target is not None:
        if ctx is None:
            raise ScenarioError(f"{label}: a pose target needs the robot's kinematics")
        end = _solve_target(nxt, nq.q[0], ctx, label)
        nq = nq.with_end(end)
    if nxt.speed_pct is not None and robot is not None:
        nq = _timed_by_speed(nq, robot, label)
    q_p, q_c, q_n = placed.q[-2], placed.q[-1], nq.q[1]
    t_p, t_c, t_n = placed.times[-2], placed.times[-1], nq.times[1]
    d_in, d_out = np.abs(q_c - q_p).max(), np.abs(q_n - q_c).max()
    if d_in < 1e-12 or d_out < 1e-12:
        raise ScenarioError(f"{label}.blend_deg: the corner knot repeats its neighbour (nothing "
                            "to blend)")
    r = (min(placed.blend, 0.5 * d_in, 0.5 * d_out) if placed.blend > 0
         else placed.blend_fraction * 0.5 * min(d_in, d_out))
    a = q_c - r / d_in * (q_c - q_p)
    b = q_c + r / d_out * (q_n - q_c)
    t_a = t_c - r / d_in * (t_c - t_p)
    t_b = t_c + r / d_out * (t_n - t_c)
    q_b = 0.5 * (a + b)
    v_b = (b - a) / (t_b - t_a)
    zero = np.zeros_like(v_b)
    q = placed.q.copy()
    q[-1] = q_b
    out = dataclasses.replace(placed, q=q, boundary={**placed.boundary, "vf": v_b, "af": zero})
    return out, (q_b, {"v0": v_b, "a0": zero}, end)


def _solve_target(phase: JointPhase, q0: NDArray[np.float64], ctx: CartesianContext,
                  label: str) -> NDArray[np.float64]:
    """Joint values of a joint phase's pose target: the in-limits IK solution closest to
    the phase's start (weighted by joint speed limits, see ``sim.robots.kinematics.ik``)."""
    from sim.robots.kinematics.ik import solve_ik

    tgt = phase.target
    assert tgt is not None
    T = np.eye(4)
    if tgt.seam is not None:
        T = _seam_pose(tgt, ctx, label)
    else:
        F = ctx.frame0_from(tgt.frame, label)
        T[:3, 3] = F[:3, :3] @ tgt.position + F[:3, 3]
        T[:3, :3] = (F[:3, :3] @ tgt.rotation if tgt.rotation is not None
                     else np.asarray(ctx.kinematics.fk(q0), dtype=float)[:3, :3])
        if tgt.flange:
            T = T @ ctx.flange_to_tcp
    key = "to_seam" if tgt.seam is not None else "to_mm"
    try:
        sols = solve_ik(ctx.kinematics, T, current=q0)
    except CellsimError as exc:
        raise ReachError(f"{label}.{key}: {exc}") from None
    good = [s for s in sols if s.within_limits]
    if not good:
        raise ReachError(f"{label}.{key}: the pose is reachable only outside the joint "
                         "ranges")
    if tgt.config is not None:
        from sim.scenario.program import config_of

        robot = ctx.robot
        match = [s for s in good if config_of(robot, s.q, s.branch) == tuple(tgt.config)]
        if not match:
            have = sorted({_config_text(config_of(robot, s.q, s.branch)) for s in good})
            raise ReachError(f"{label}: no solution in the joint ranges has CONFIG "
                             f"'{_config_text(tgt.config)}' (in range: {', '.join(have)})")
        good = match
    return np.asarray(good[0].q, dtype=float)
