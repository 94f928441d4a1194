"""The reference motion of a scenario: every phase planned and placed on one clock.

Joint phases are planned with their 4-3-4 or 5-4-6 polynomial; hold phases keep the pose;
Cartesian phases (``linear``, ``circular``) are interpolated with ADNIA (seed 003) at the
phase's sampling period, turned into joint via points by the robot's analytic inverse
kinematics (branch-continuous), and joined by the phase's polynomial, so that position,
velocity and acceleration stay continuous (as seed 001 phase II does).

Cartesian targets are given in the robot's frame 0 (the seeds' base frame); cell seams are
given in the world frame and converted with the cell's ``world_from_frame0``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.base import JointState, sample_times
from planners.errors import PlannerError
from sim.errors import CellsimError, ReachError, ScenarioError
from sim.scenario import (
    CartesianPhase,
    HoldPhase,
    JointPhase,
    Phase,
    Scenario,
    plan_phase,
)

#: Continuity tolerance between consecutive phases (rad, rad/s, rad/s^2).
_CONTINUITY_TOL = 1e-6


class HoldTrajectory:
    """Constant joint position over ``[start, start + duration]`` (zero derivatives)."""

    planner = "hold"

    def __init__(self, start: float, duration: float, q: ArrayLike) -> None:
        self.start = float(start)
        self.end = float(start + duration)
        self.q = np.asarray(q, dtype=float).copy()
        self.knots = np.array([self.start, self.end])

    @property
    def duration(self) -> float:
        return self.end - self.start

    @property
    def n_joints(self) -> int:
        return self.q.size

    def at(self, t: ArrayLike) -> JointState:
        t = np.asarray(t, dtype=float)
        shape = t.shape + (self.q.size,)
        z = np.zeros(shape)
        return JointState(np.broadcast_to(self.q, shape).copy(), z, z.copy(), z.copy())

    def sample(self, dt: float) -> tuple[NDArray[np.float64], JointState]:
        t = sample_times(self.start, self.end, dt)
        return t, self.at(t)


@dataclass
class PhaseMotion:
    """One planned phase on the scenario clock.

    Attributes:
        phase: The scenario phase.
        t0, t1: Start and end time, s.
        trajectory: Joint trajectory (``at(t)`` on the scenario clock).
        cartesian: For Cartesian phases, the ADNIA tool trajectory in frame 0 (its own clock
            starts at 0, i.e. at ``t0``); ``None`` otherwise.
        seam: The cell seam the phase follows, or ``None``.
        knot_times: Knot times of the joint polynomial, s.
        programmed: Cartesian phases: the moves as programmed, one per move (a polyline seam
            has one per segment): :class:`ProgrammedMove`.
        corner_zones: Phases along a seam: the stretches of the seam, as arc-length intervals
            ``(s0, s1)`` in m from the seam's start, where the torch turns from one leg's
            posture to the next (a polyline's blended corners); outside them the torch holds
            the seam's work and travel angles. Empty for a line, an arc or a circle.
    """

    phase: Phase
    t0: float
    t1: float
    trajectory: Any
    cartesian: Any = None
    seam: Any = None
    knot_times: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    programmed: list = field(default_factory=list)
    corner_zones: list[tuple[float, float]] = field(default_factory=list)

    @property
    def name(self) -> str:
        return self.phase.name

    @property
    def kind(self) -> str:
        return self.phase.kind


@dataclass(frozen=True)
class ProgrammedMove:
    """A Cartesian move as programmed (frame 0): its end pose (and via pose for an arc), the
    blend radius into the next move (m, 0: it stops there), its length and the next move's.
    What ``cellsim export`` writes as a TP motion line."""

    kind: str
    end: NDArray[np.float64]
    via: NDArray[np.float64] | None
    speed: float
    blend: float = 0.0
    length: float = 0.0
    next_length: float = 0.0


def _programmed(cart: Any, kind: str, speed: float, blend: float = 0.0,
                next_length: float = 0.0) -> list[ProgrammedMove]:
    """The move as programmed: one entry, or for an arc of more than 170 deg one per piece of
    at most 170 deg (a TP circular move through three points cannot close a circle), the
    pieces stopping at their ends and the last keeping the blend."""
    L = cart.length
    sweep = float(getattr(cart.path, "sweep", 0.0))
    pieces = max(1, int(np.ceil(np.degrees(sweep) / 170.0 - 1e-9))) if kind == "circular" else 1

    def pose(s: float) -> NDArray[np.float64]:
        T = np.eye(4)
        T[:3, 3] = cart.path.evaluate(np.array([s]))[0][0]
        T[:3, :3] = cart.orientation.evaluate(np.array([s / L]))[0][0]
        return T

    out = []
    for k in range(pieces):
        s0, s1 = L * k / pieces, L * (k + 1) / pieces
        last = k == pieces - 1
        out.append(ProgrammedMove(kind, pose(s1), pose(0.5 * (s0 + s1)) if kind == "circular"
                                  else None, speed, blend if last else 0.0, s1 - s0,
                                  next_length if last else 0.0))
    return out


@dataclass
class Motion:
    """All phases of a scenario on one clock, plus the tool actions.

    Attributes:
        phases: Planned phases in order; ``phases[k].t1 == phases[k+1].t0``.
        actions: ``(time, action)`` pairs sorted by time (``arc_on``, ``suction_off``, ...).
        n_joints: Number of robot joints.
    """

    phases: list[PhaseMotion]
    actions: list[tuple[float, str]]
    n_joints: int

    @property
    def t0(self) -> float:
        return self.phases[0].t0

    @property
    def t1(self) -> float:
        return self.phases[-1].t1

    @property
    def duration(self) -> float:
        return self.t1 - self.t0

    @property
    def boundaries(self) -> NDArray[np.float64]:
        return np.array([p.t0 for p in self.phases] + [self.t1])

    def phase_index(self, t: ArrayLike) -> NDArray[np.int64]:
        """Index of the phase each time belongs to (a boundary belongs to the later phase)."""
        idx = np.searchsorted(self.boundaries, np.asarray(t, dtype=float), side="right") - 1
        return np.clip(idx, 0, len(self.phases) - 1)

    def at(self, t: ArrayLike) -> JointState:
        """Reference joint state at time(s) ``t``, s; times past the end hold the last pose."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = [np.zeros((t.size, self.n_joints)) for _ in range(4)]
        idx = self.phase_index(t)
        for k, pm in enumerate(self.phases):
            sel = idx == k
            if not np.any(sel):
                continue
            ts = np.clip(t[sel], pm.t0, pm.t1)
            st = pm.trajectory.at(ts)
            for arr, val in zip(out, (st.q, st.qd, st.qdd, st.qddd)):
                arr[sel] = val
        past = t > self.t1
        for arr in out[1:]:
            arr[past] = 0.0
        return JointState(*out)

    def tool_state(self, t: ArrayLike, tool: str) -> NDArray[np.bool_]:
        """Whether the arc (``tool="arc"``) or suction (``"suction"``) is on at each time."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        on = np.zeros(t.shape, dtype=bool)
        for time, action in self.actions:
            if action == f"{tool}_on":
                on[t >= time - 1e-12] = True
            elif action == f"{tool}_off":
                on[t >= time - 1e-12] = False
        return on

    def knot_times(self) -> NDArray[np.float64]:
        """All knot times of all phases, sorted, s."""
        ts = np.concatenate([pm.knot_times for pm in self.phases] or [np.zeros(0)])
        return np.unique(ts)


# --------------------------------------------------------------------------------------------
# Building
# --------------------------------------------------------------------------------------------


@dataclass
class CartesianContext:
    """What Cartesian phases need from the cell and the robot.

    Attributes:
        kinematics: A :class:`sim.robots.model.KinematicModel` of the robot with its tool
            (``fk(q)`` gives the tcp pose in frame 0; used by ``ik_path``).
        seams: Cell seams by name (world frame).
        world_from_frame0: Pose of frame 0 in the world, (4, 4).
        frames: Poses of the cell's objects in the world by name, (4, 4) each: scenario points
            may be given in them (``frame = "<object>"``).
        home_q: The cell's home configuration, rad (where a TP program starts).
        flange_to_tcp: The tcp in the flange frame, (4, 4) (a TP program's UT 0 poses are the
            flange's).
        robot: The robot's registry entry (its maker's joint convention, for TP CONFIG).
    """

    kinematics: Any
    seams: dict[str, Any] = field(default_factory=dict)
    world_from_frame0: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    frames: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    home_q: NDArray[np.float64] | None = None
    flange_to_tcp: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    robot: Any = None

    def frame0_from(self, frame: str, label: str) -> NDArray[np.float64]:
        """Pose of a named frame in frame 0, (4, 4): ``frame0`` (the robot's), ``world`` or a
        cell object (:attr:`frames`: each object's pose in world).

        Raises:
            ScenarioError: Unknown frame (the message lists the valid ones).
        """
        if frame == "frame0":
            return np.eye(4)
        if frame == "world":
            return self.frame0_from_world
        if frame not in self.frames:
            from sim.errors import UnknownNameError

            raise ScenarioError(f"{label}.frame: "
                                f"{UnknownNameError('frame', frame, ['frame0', 'world', *self.frames])}")
        return self.frame0_from_world @ self.frames[frame]

    @property
    def frame0_from_world(self) -> NDArray[np.float64]:
        from sim.core.rotations import invert_transform

        return invert_transform(self.world_from_frame0)

    def to_frame0(self, p: ArrayLike) -> NDArray[np.float64]:
        T = self.frame0_from_world
        return T[:3, :3] @ np.asarray(p, dtype=float) + T[:3, 3]

    def rot_to_frame0(self, R: ArrayLike) -> NDArray[np.float64]:
        return self.frame0_from_world[:3, :3] @ np.asarray(R, dtype=float)


def build_motion(scenario: Scenario, context: CartesianContext | None = None) -> Motion:
    """Plan every phase of ``scenario`` and place it on one clock.

    Args:
        scenario: A loaded scenario.
        context: Kinematics and seams for Cartesian phases (required if it has any).

    Raises:
        ScenarioError: A phase cannot be planned (names the phase and the reason), including
            unreachable Cartesian points (which point, how far) and velocity/acceleration
            jumps between phases.
    """
    where = scenario.source.name
    phases: list[PhaseMotion] = []
    t = 0.0
    q = None
    todo = list(scenario.phases)
    pending: tuple[NDArray[np.float64], dict[str, NDArray[np.float64]],
                   NDArray[np.float64] | None] | None = None
    while todo:
        phase = todo.pop(0)
        label = f"{where}: phases[{phase.index}] ({phase.name})"
        if isinstance(phase, CartesianPhase):
            _check_seam_blends(phase, todo[0] if todo else None, context, label)
        if isinstance(phase, CartesianPhase) and (_blends(phase)
                                                  or _is_polyline(phase, context)):
            if context is None:
                raise ScenarioError(f"{label}: Cartesian phases need the robot's kinematics")
            group = [phase]
            while _blends(group[-1]) and todo and isinstance(todo[0], CartesianPhase):
                group.append(todo.pop(0))
            if len(group) == 1 and _blends(phase) and not _is_polyline(phase, context):
                raise ScenarioError(f"{label}.blend_mm: the next phase is not a linear or "
                                    "circular move to blend into (leave blend_mm out)")
            labels = [f"{where}: phases[{ph.index}] ({ph.name})" for ph in group]
            for pm, lb in zip(_plan_blended(group, t, q, context, labels), labels,
                              strict=True):
                if phases:
                    _check_phase_continuity(phases[-1], pm, label, scenario.robot.joints)
                _check_end_config(pm, context, lb)
                phases.append(pm)
            t = phases[-1].t1
            q = phases[-1].trajectory.at(phases[-1].t1).q
            continue
        if isinstance(phase, JointPhase):
            if q is None and np.isnan(phase.q[0]).any():  # a TP program starts at home
                if context is None or context.home_q is None:
                    raise ScenarioError(f"{label}: the start pose needs the cell's home")
                qs = phase.q.copy()
                qs[0] = context.home_q
                phase = dataclasses.replace(phase, q=qs)
                q = np.asarray(context.home_q, dtype=float)
            placed = phase.with_start(t, q)
            solved_end = None
            if pending is not None:  # the previous joint phase blends into this one
                qs = placed.q.copy()
                qs[0] = pending[0]
                placed = dataclasses.replace(placed, q=qs,
                                             boundary={**placed.boundary, **pending[1]})
                solved_end = pending[2]  # its pose target, solved by the blend
                pending = None
            if phase.target is not None:
                if context is None:
                    raise ScenarioError(f"{label}: a pose target needs the robot's kinematics")
                placed = placed.with_end(solved_end if solved_end is not None
                                         else _solve_target(phase, placed.q[0], context, label))
            if phase.speed_pct is not None:
                placed = _timed_by_speed(placed, scenario.robot)
            if phase.blend > 0 or phase.blend_fraction > 0:
                placed, pending = _joint_blend(placed, todo[0] if todo else None, context, label,
                                               scenario.robot)
            traj = plan_phase(placed, where)
            pm = PhaseMotion(placed, placed.t0, placed.t1, traj, knot_times=placed.times.copy())
        elif isinstance(phase, HoldPhase):
            traj = HoldTrajectory(t, phase.duration, q)
            pm = PhaseMotion(phase, t, t + phase.duration, traj, knot_times=np.array([t]))
        elif isinstance(phase, CartesianPhase):
            if context is None:
                raise ScenarioError(f"{label}: Cartesian phases need the robot's kinematics")
            pm = _plan_cartesian(phase, t, q, context, label)
            _check_end_config(pm, context, label)
        else:  # pragma: no cover - the loader only makes the kinds above
            raise ScenarioError(f"{label}: unknown phase kind {phase.kind!r}")
        if phases:
            _check_phase_continuity(phases[-1], pm, label, scenario.robot.joints)
        phases.append(pm)
        t = pm.t1
        q = pm.trajectory.at(pm.t1).q
    motion = Motion(phases=phases, actions=[], n_joints=scenario.robot.n_joints)
    motion.actions = _resolve_actions(scenario, motion)
    return motion


def _timed_by_speed(placed: JointPhase, robot: Any) -> JointPhase:
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
        nq = _timed_by_speed(nq, robot)
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


#: Most inverse-kinematics samples of one Cartesian phase.
MAX_PHASE_SAMPLES = 1_000_000
#: Most physics steps of one run (about 1 KB recorded per step: 2 GB).
MAX_STEPS = 2_000_000


def check_size(scenario: Scenario, motion: Motion, timestep: float) -> int:
    """The number of physics steps a run of ``motion`` takes, if it is within
    :data:`MAX_STEPS` and no phase is shorter than one timestep.

    Raises:
        ScenarioError: A phase shorter than the timestep; or the count (cycle plus
            ``simulation.settle_s`` over the timestep) and the limit, naming the keys that set
            it.
    """
    for k, pm in enumerate(motion.phases):
        if pm.t1 - pm.t0 < timestep:
            raise ScenarioError(f"{scenario.source.name}: phases[{k}] ({pm.name}) lasts "
                                f"{pm.t1 - pm.t0:.3g} s, shorter than one timestep "
                                f"({timestep:g} s, simulation.timestep_s): the drives could not "
                                "follow it; make it longer or drop it")
    total = motion.duration + scenario.simulation.settle_s
    steps = total / timestep if timestep > 0 else float("inf")
    if not np.isfinite(steps) or steps > MAX_STEPS:
        raise ScenarioError(
            f"{scenario.source.name}: the cycle lasts {motion.duration:.4g} s plus "
            f"simulation.settle_s {scenario.simulation.settle_s:g} s; at a timestep of "
            f"{timestep:g} s (simulation.timestep_s) that is {steps:.3g} steps, more than "
            f"{MAX_STEPS:,}: shorten the phases (durations_s, time_s, speed_mm_s) or the "
            "settling, or raise the timestep")
    return int(np.ceil(steps))


def limit_violations(scenario: Scenario, motion: Motion, *, speed: bool = True,
                     accel: bool = True) -> list[str]:
    """One line per joint limit the reference motion exceeds (position range from the MJCF,
    speed and acceleration limits from the robot registry), naming the phase, joint, time,
    value and limit."""
    from planners.limits import find_limit_violations
    from sim.robots.registry import joint_ranges

    rng = joint_ranges(scenario.robot)
    where = scenario.source.name
    # blended phases share one trajectory: each trajectory is checked once (once per phase
    # made the check grow as the square of the number of blended moves) and a violation is
    # named after the phase whose window holds its time
    groups: dict[int, list[PhaseMotion]] = {}
    for pm in motion.phases:
        if not isinstance(pm.trajectory, HoldTrajectory):
            groups.setdefault(id(pm.trajectory), []).append(pm)
    out = []
    for group in groups.values():
        found = find_limit_violations(
            group[0].trajectory, lower=rng[:, 0], upper=rng[:, 1],
            max_velocity=np.asarray(scenario.robot.max_speed) if speed else None,
            max_acceleration=(np.asarray(scenario.robot.max_accel)
                              if accel and scenario.robot.max_accel else None),
            joint_names=scenario.robot.joints)
        for v in found:
            pm = next((p for p in group if p.t0 <= v.time <= p.t1), group[0])
            out.append(f"{where}: phases[{pm.phase.index}] ({pm.name}): {v.message()}")
    return out


def check_motion_limits(scenario: Scenario, motion: Motion) -> None:
    """Raise on the first joint-limit violation of the reference motion.

    Position ranges are always enforced (the joint cannot go there); speed and acceleration
    limits unless the scenario sets ``simulation.enforce_speed_limits`` /
    ``enforce_accel_limits = false`` (the run's verdict then fails on that check and the
    sizing report shows by how much each joint is over its limit).

    Raises:
        ScenarioError: One line naming the phase, joint, time, value and limit.
    """
    found = limit_violations(scenario, motion,
                             speed=scenario.simulation.enforce_speed_limits,
                             accel=scenario.simulation.enforce_accel_limits)
    if found:
        more = f" (and {len(found) - 1} more)" if len(found) > 1 else ""
        raise ScenarioError(found[0] + more)


def _check_phase_continuity(prev: PhaseMotion, pm: PhaseMotion, label: str,
                            joints: tuple[str, ...]) -> None:
    a = prev.trajectory.at(prev.t1)
    b = pm.trajectory.at(pm.t0)
    for what, x, y, unit in (("position", a.q, b.q, "deg"), ("velocity", a.qd, b.qd, "deg/s"),
                             ("acceleration", a.qdd, b.qdd, "deg/s^2")):
        gap = np.abs(np.asarray(x) - np.asarray(y))
        if np.any(gap > _CONTINUITY_TOL):
            j = int(np.argmax(gap))
            raise ScenarioError(
                f"{label}: joint {joints[j]} {what} jumps from {np.rad2deg(x[j]):.6g} to "
                f"{np.rad2deg(y[j]):.6g} {unit} at {pm.t0:g} s where phase {prev.name!r} ends; "
                "consecutive phases must meet (set matching start/end boundary values)")


def _resolve_actions(scenario: Scenario, motion: Motion) -> list[tuple[float, str]]:
    by_name = {pm.name: pm for pm in motion.phases}
    out = []
    for k, a in enumerate(scenario.actions):
        if a.time is not None:
            time = a.time
            if not (motion.t0 <= time <= motion.t1):
                raise ScenarioError(f"{scenario.source.name}: actions[{k}].time_s: {time:g} s is "
                                    f"outside the cycle ({motion.t0:g} to {motion.t1:.6g} s)")
        else:
            pm = by_name[a.phase]
            time = pm.t0 if a.at == "start" else pm.t1
        out.append((float(time), a.action))
    out.sort(key=lambda x: x[0])
    return out


def _seam(ctx: CartesianContext, name: str, label: str) -> Any:
    if name not in ctx.seams:
        from sim.errors import UnknownNameError

        raise ScenarioError(f"{label}: {UnknownNameError('seam', name, ctx.seams)}")
    return ctx.seams[name]


def _solve_target(phase: JointPhase, q0: NDArray[np.float64], ctx: CartesianContext,
                  label: str) -> NDArray[np.float64]:
    """Joint values of a joint phase's pose target: the in-limits IK solution closest to
    the phase's start (weighted by joint speed limits, see ``sim.robots.ik``)."""
    from sim.robots.ik import solve_ik

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


def _seam_pose(tgt: Any, ctx: CartesianContext, label: str) -> NDArray[np.float64]:
    """The tcp pose (frame 0) of a seam target: the seam's start or end tool point in its
    torch posture there, moved ``tgt.offset`` back along the torch axis (``approach_mm``,
    ``retract_mm``)."""
    seam = _seam(ctx, tgt.seam, f"{label}.to_seam")
    s = 0.0 if tgt.seam_end == "start" else seam.length()
    if ctx.kinematics.family.five_axis:
        _check_five_axis_torch(seam, label, "to_seam", at=(s,))
    T = np.eye(4)
    T[:3, 3] = ctx.to_frame0(seam.tcp_point(s) - tgt.offset * seam.torch_axis(s))
    T[:3, :3] = ctx.rot_to_frame0(seam.torch_rotation(s))
    return T


#: A joint this close to a boundary of the FANUC configuration (J5 at 0 deg for the flip) matches
#: the labels of both sides, deg.
CONFIG_TOLERANCE_DEG = 0.5


def _check_end_config(pm: PhaseMotion, ctx: CartesianContext, label: str) -> None:
    """A TP program's linear or circular move keeps the arm's configuration along its path
    (branch-continuous IK), so the configuration it ends in is where its start leads, not a
    choice: where its flip, elbow (up/down) or front/back is not the one its position names,
    the program says one thing and the arm would do another, and the move is refused, naming
    both (never the CONFIG ignored). Its turn numbers are where the path's wrist rotation
    leads, as a controller's linear move takes the wrist the short way (J6 passing 180 deg
    along a seam ends at turn -1 or 1): they bind joint moves only.

    Raises:
        ReachError: The configurations differ.
    """
    phase = pm.phase
    if not isinstance(phase, CartesianPhase) or phase.config is None:
        return
    from sim.robots.ik import solve_ik
    from sim.scenario.program import config_of

    q_end = np.asarray(pm.trajectory.at(pm.t1).q, dtype=float)
    sols = solve_ik(ctx.kinematics, np.asarray(ctx.kinematics.fk(q_end), dtype=float),
                    current=q_end)
    same = [s for s in sols if np.max(np.abs(np.asarray(s.q) - q_end)) < 1e-4]
    if not same:  # the solver did not list this posture: its branch is unknown
        return
    have = config_of(ctx.robot, q_end, same[0].branch)
    # J5 on the flip's boundary (0 deg) has either label: the flips a nudge of
    # CONFIG_TOLERANCE_DEG gives are all accepted
    nudge = np.radians(CONFIG_TOLERANCE_DEG)
    near = {config_of(ctx.robot, q_end + d, same[0].branch)[:3]
            for d in np.vstack([np.zeros(len(q_end)), np.diag(np.full(len(q_end), nudge)),
                                np.diag(np.full(len(q_end), -nudge))])}
    want = tuple(phase.config)
    if want[:3] not in near:
        move = "linear" if phase.kind == "linear" else "circular"
        shown = have[:3] + want[3:]  # the turn numbers are not compared
        raise ReachError(
            f"{label}: the {move} move ends in CONFIG '{_config_text(shown)}' but its position "
            f"says '{_config_text(want)}': a {move} move keeps the arm's configuration "
            "along its path; teach the position in the configuration the path reaches it in, "
            "or reach it with a J move")


def _config_text(c: tuple) -> str:
    return f"{c[0]} {c[1]} {c[2]}, {c[3]}, {c[4]}, {c[5]}"


def default_ramp(phase: CartesianPhase, p0: NDArray[np.float64], seam: Any,
                 ctx: CartesianContext) -> float:
    """Default duration of the smooth start and stop of a Cartesian move, s.

    Three sampling periods and at least 0.3 s, so the joint polynomial through the ADNIA via
    points resolves the ramp; at most half the move's duration at full speed.
    """
    if seam is not None:
        length = float(seam.length())
    elif phase.kind == "linear":
        length = float(np.linalg.norm(np.asarray(phase.to) - p0))
    elif phase.via is not None:
        length = float(np.linalg.norm(np.asarray(phase.via) - p0)
                       + np.linalg.norm(np.asarray(phase.to) - np.asarray(phase.via)))
    else:
        radius = float(np.linalg.norm(np.cross(p0 - phase.center, phase.axis)))
        length = abs(phase.sweep) * radius
    return min(max(3.0 * phase.sample_period, 0.3), 0.5 * length / phase.speed)


def _phase_cart(phase: CartesianPhase, p0: NDArray[np.float64], R0: NDArray[np.float64],
                ctx: CartesianContext, label: str, *, corner: bool = False,
                roll: float | None = None) -> tuple[Any, Any]:
    """The phase's ADNIA move (``CartesianTrajectory``, frame 0) from the tool pose ``p0``,
    ``R0``, with its seam (or ``None``).

    A move along a seam with ``orientation = "seam"`` takes the seam's torch frame at every
    point (:class:`sim.simulation.seam_orientation.SeamOrientation`), keeping the roll about
    the torch axis it arrives with. ``corner``: the move is a polyline's next leg, entered
    through a corner that turns the torch (``R0`` is the previous leg's frame, not this leg's
    start); ``roll`` is then the first leg's roll, kept on every leg."""
    from planners import adnia

    F = ctx.frame0_from(phase.frame, label)  # the phase's points are in this frame

    def pt(v: Any) -> Any:
        return None if v is None else F[:3, :3] @ np.asarray(v, dtype=float) + F[:3, 3]

    to, via, center = pt(phase.to), pt(phase.via), pt(phase.center)
    axis = None if phase.axis is None else F[:3, :3] @ np.asarray(phase.axis, dtype=float)
    seam_end_pose = None
    if phase.target is not None:  # to_seam, with approach_mm / retract_mm
        seam_end_pose = _seam_pose(phase.target, ctx, label)
        to = seam_end_pose[:3, 3]
    if phase.flange and phase.euler_zyx is not None:  # UT 0: flange points to tcp points
        from sim.core.rotations import euler_zyx_to_matrix

        R_end = F[:3, :3] @ euler_zyx_to_matrix(*phase.euler_zyx)
        R_via = (R_end if phase.via_euler_zyx is None
                 else F[:3, :3] @ euler_zyx_to_matrix(*phase.via_euler_zyx))
        off = ctx.flange_to_tcp[:3, 3]
        to = None if to is None else to + R_end @ off
        via = None if via is None else via + R_via @ off
    if phase.move_time is not None:  # the move's time (its ramps included) sets its speed
        if phase.kind == "linear":
            length = float(np.linalg.norm(to - p0))
        else:
            from planners.adnia import CirclePath

            try:
                length = float(CirclePath.through(p0, via, to).length)
            except PlannerError as exc:
                raise ScenarioError(f"{label}: {exc}") from None
        ramp = min(max(3.0 * phase.sample_period, 0.3), phase.move_time / 3.0)
        phase = dataclasses.replace(phase, ramp=ramp, speed=max(length, 1e-6)
                                    / (phase.move_time - ramp))

    seam = None
    if phase.seam is not None:
        seam = phase.seam_as_welded(_seam(ctx, phase.seam, f"{label}.seam"))
        if seam.kind != ("line" if phase.kind == "linear" else "arc"):
            raise ScenarioError(f"{label}.seam: {phase.seam!r} is a {seam.kind} seam; a "
                                f"{phase.kind} phase needs a {'line' if phase.kind == 'linear' else 'arc'}")
        start = ctx.to_frame0(seam.tcp_point(0.0))
        gap = float(np.linalg.norm(start - p0))
        if corner:  # a polyline's next leg: its tool path starts back along its own torch axis
            p0, gap = start, 0.0
        if gap > 5e-4:
            raise ScenarioError(
                f"{label}.seam: the tool is at {np.round(p0 * 1e3, 2).tolist()} mm (frame 0) but seam "
                f"{phase.seam!r} starts at {np.round(start * 1e3, 2).tolist()} mm, {gap * 1e3:.2f} mm "
                "away; end the previous phase at the seam start")

    if seam is not None and phase.orientation == "seam" and ctx.kinematics.family.five_axis:
        _check_five_axis_torch(seam, label)

    rot_end = None
    mode = {"keep": "geodesic", "euler": "geodesic", "seam": "geodesic", "follow": "carry"}[
        phase.orientation]
    if phase.orientation == "euler":
        from sim.core.rotations import euler_zyx_to_matrix

        rot_end = F[:3, :3] @ euler_zyx_to_matrix(*phase.euler_zyx)
        if phase.flange:
            rot_end = rot_end @ ctx.flange_to_tcp[:3, :3]
    elif phase.orientation == "seam" and seam_end_pose is not None:
        rot_end = seam_end_pose[:3, :3]
    elif phase.orientation == "seam":
        rot_end = ctx.rot_to_frame0(seam.torch_rotation(seam.length()))
    kw: dict[str, Any] = dict(rotation_start=R0, orientation=mode,
                              ramp_time=phase.ramp if phase.ramp is not None
                              else default_ramp(dataclasses.replace(
                                  phase, to=to, via=via, center=center, axis=axis), p0, seam, ctx))
    if mode != "carry":
        kw["rotation_end"] = rot_end
    try:
        if phase.kind == "linear":
            end = ctx.to_frame0(seam.tcp_points()[1]) if seam is not None else to
            cart = adnia.linear_move(p0, end, phase.speed, **kw)
        elif seam is not None:
            via, end = ctx.to_frame0(seam.tcp_points()[1]), ctx.to_frame0(seam.tcp_points()[2])
            cart = adnia.arc_move(p0, via, end, phase.speed, **kw)
        elif via is not None:
            cart = adnia.arc_move(p0, via, to, phase.speed, **kw)
        else:
            cart = adnia.circle_move(center, axis, p0, phase.sweep, phase.speed, **kw)
    except PlannerError as exc:
        raise ScenarioError(f"{label}: {exc}") from None
    if seam is not None and phase.orientation == "seam":
        cart = _along_seam(cart, seam, R0, ctx, label, corner=corner, roll=roll)
    return cart, seam


def _along_seam(cart: Any, seam: Any, R0: NDArray[np.float64], ctx: CartesianContext,
                label: str, *, corner: bool, roll: float | None) -> Any:
    """``cart`` with the seam's torch frame at every point (:func:`_phase_cart`)."""
    from planners.adnia import CartesianTrajectory
    from sim.simulation.seam_orientation import (
        MAX_START_MISALIGNMENT_DEG,
        SeamOrientation,
        roll_about,
    )

    column = int(ctx.kinematics.family.approach_column)
    to0 = ctx.frame0_from_world[:3, :3]
    if roll is None:
        roll = (roll_about(to0 @ seam.torch_rotation(0.0), R0, column) if column == 2 and not corner
                else 0.0)
    ramp_share = 0.5 * cart.speed * float(cart.profile.ramp_time) / cart.length
    law = SeamOrientation(seam, to0, 0.0, seam.length(), column=column, roll=roll,
                          start=None if corner else R0, settle=min(0.5, ramp_share))
    if law.start_misalignment_deg > MAX_START_MISALIGNMENT_DEG:
        raise ScenarioError(
            f"{label}.seam: the torch arrives {law.start_misalignment_deg:.2f} deg off seam "
            f"{seam.name!r}'s posture at its start (at most {MAX_START_MISALIGNMENT_DEG:g} deg "
            "is corrected on the start ramp); end the previous phase in the seam's posture "
            "(to_seam, with approach_mm to stop short of it)")
    return CartesianTrajectory(cart.path, law, cart.profile)


def _check_five_axis_torch(seam: Any, label: str, key: str = "seam",
                           at: tuple[float, ...] | None = None) -> None:
    """A 5-axis arm holds its torch in the vertical plane through J1 and the tool point: a
    seam's work and travel angles that leave that plane somewhere along it cannot be held.
    The error names the angle (work, travel or both), the seam point, and the nearest angles
    the arm can hold there (the torch axis projected into the plane)."""
    from sim.robots.families.five_r import PLANE_TOL

    limit = float(np.degrees(np.arcsin(PLANE_TOL)))
    for s in (at if at is not None else np.linspace(0.0, seam.length(), 41)):
        dev = seam.plane_deviation_deg(float(s))
        if dev <= limit:
            continue
        T = seam.world_from_frame0
        k1, o1 = T[:3, 2], T[:3, 3]
        p = seam.point(float(s))
        d = p - o1
        rho = d - (d @ k1) * k1
        m = np.cross(k1, rho / np.linalg.norm(rho))
        a = seam.torch_axis(float(s))
        a2 = a - (a @ m) * m
        a2 /= np.linalg.norm(a2)
        t = seam.tangent(float(s))
        n = seam.surface_normal - (seam.surface_normal @ t) * t
        n /= np.linalg.norm(n)
        e = seam.torch_side * np.cross(n, t)
        tau = float(np.degrees(np.arcsin(np.clip(a2 @ t, -1.0, 1.0))))
        perp = a2 - (a2 @ t) * t
        w_int = float(np.degrees(np.arctan2(-(perp @ e), -(perp @ n))))
        work, work_set = 90.0 - w_int, 90.0 - seam.torch_work_angle_deg
        travel_set = seam.torch_travel_angle_deg
        which = [name for name, have, want in (("work", work, work_set),
                                               ("travel", tau, travel_set))
                 if abs(have - want) > 0.05]
        raise ReachError(
            f"{label}.{key}: a 5-axis arm cannot hold the {' and '.join(which) or 'work/travel'}"
            f" angle{'s' if len(which) > 1 else ''} of seam {seam.name!r} at {s * 1e3:.1f} mm "
            "from its start: "
            f"its torch stays in the vertical plane through J1 (the seam's posture is "
            f"{dev:.2f} deg out of it); there it can hold work {work:.1f} deg, travel "
            f"{tau:.1f} deg (set: work {work_set:.1f}, travel {travel_set:.1f})")


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
    from sim.robots.ik import ik_path

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


def _plan_cartesian(phase: CartesianPhase, t0: float, q0: NDArray[np.float64],
                    ctx: CartesianContext, label: str) -> PhaseMotion:
    kin = ctx.kinematics
    T0 = np.asarray(kin.fk(q0), dtype=float)
    cart, seam = _phase_cart(phase, T0[:3, 3], T0[:3, :3], ctx, label)
    extra = np.zeros(0)
    period = _turn_limited_period(cart, phase.sample_period, label)
    if phase.weave is not None:
        from planners.weave import WeavingTrajectory

        cart = WeavingTrajectory(cart, phase.weave, kin.family.approach_column)
        extra = cart.breakpoints()
        period = min(period, _weave_period(phase.weave))
    ts = _sample_times(cart.duration, period, extra, label)
    ts, q_via = _ik_knots_refined(kin, ts, lambda x: _poses(cart.at(x)), q0, label, ctx.robot)
    times = t0 + ts
    placed = JointPhase(index=phase.index, name=phase.name, planner=phase.planner, times=times,
                        durations=np.diff(times), q=q_via)
    traj = plan_phase(placed, "")
    base = cart.base if phase.weave is not None else cart
    return PhaseMotion(phase, float(times[0]), float(times[-1]), traj, cartesian=cart, seam=seam,
                       knot_times=times,
                       programmed=_programmed(base, phase.kind, base.speed))


#: An exported polyline's points where its corner zones begin and end blend over this share
#: of the shorter adjacent move (CNT20: the rounding stays near the zone's ends).
ZONE_POINT_CNT = 0.2
#: Moves an exported polyline takes across each corner zone (to its planned poses there).
ZONE_POINTS = 1


def _programmed_legs(path: Any, t_start: float, t_end: float,
                     corners: list[tuple[float, float]], speed: float) -> list[ProgrammedMove]:
    """A polyline phase as TP moves, from its planned tool path (``path.at(t)``, the phase's
    window ``[t_start, t_end]`` and its corners' time windows, on the path's clock): each leg
    to where its corner zone begins at the set speed, then :data:`ZONE_POINTS` moves across
    the zone to poses of the plan there, each timed as planned (slower where the corner was
    slowed for the turn), and a ``FINE`` stop on the seam's end. A TP linear move turns the
    torch evenly between its ends, so one point per corner would turn it over the whole next
    leg; these points keep each leg's posture and turn it inside the zone, as planned."""
    times = [float(t) for ta, tb in corners
             for t in ta + (tb - ta) * np.arange(ZONE_POINTS + 1) / ZONE_POINTS] + [t_end]
    st = path.at(np.array([t_start, *times]))
    out = []
    for j, t in enumerate(times):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = st.rotation[j + 1], st.position[j + 1]
        length = float(np.linalg.norm(st.position[j + 1] - st.position[j]))
        t_prev = t_start if j == 0 else times[j - 1]
        in_zone = any(ta + 1e-12 < t <= tb + 1e-12 for ta, tb in corners)
        v = min(speed, length / max(t - t_prev, 1e-9)) if in_zone else speed
        nxt = (float(np.linalg.norm(st.position[j + 2] - st.position[j + 1]))
               if j + 1 < len(times) else 0.0)
        blend = ZONE_POINT_CNT * CNT_SHARE * min(length, nxt) if nxt > 0 else 0.0
        out.append(ProgrammedMove("linear", T, None, v, blend, length, nxt))
    return out


#: A TP program's CNT100 blends over this share of the shorter of the two moves.
CNT_SHARE = 0.45
#: Largest turn of the path a corner blend may round at speed, deg (a near reversal would
#: be a cusp).
MAX_BLEND_TURN = 150.0
#: Smallest corner zone, m: below it the joint polynomial through the inverse kinematics
#: samples cannot follow the corner curve (a CNT on such short moves gets this).
MIN_BLEND = 1e-4
#: Corner blend of a polyline seam welded without ``blend_mm``, m.
POLYLINE_BLEND = 0.002


def _blends(phase: CartesianPhase) -> bool:
    """Whether the phase blends into the next one (a seam phase never does: it ends on its
    seam's last point; a polyline's ``blend_mm`` rounds its own corners)."""
    return phase.seam is None and (phase.blend > 0 or phase.blend_fraction > 0)


def _check_seam_blends(phase: CartesianPhase, nxt: Phase | None,
                       ctx: CartesianContext | None, label: str) -> None:
    """A seam phase starts and ends on its seam's end points: no blend may cut them.

    Raises:
        ScenarioError: A line or arc seam phase with ``blend_mm``, or a phase blending into a
            seam phase.
    """
    if phase.seam is not None and (phase.blend > 0 or phase.blend_fraction > 0) \
            and not _is_polyline(phase, ctx):
        raise ScenarioError(
            f"{label}.blend_mm: a seam phase ends on its seam's last point (the arc goes off "
            "there); a blend would cut it. To weld round a corner without stopping, make the "
            "seam one polyline (its blend_mm rounds the inner corners); else leave blend_mm out")
    if _blends(phase) and isinstance(nxt, CartesianPhase) and nxt.seam is not None:
        raise ScenarioError(
            f"{label}.blend_mm: the next phase {nxt.name!r} welds seam {nxt.seam!r}, which "
            "starts on its first point; a blend into it would cut that point (leave blend_mm "
            "out: the tool stops on the seam's start)")


def _is_polyline(phase: CartesianPhase, ctx: CartesianContext | None) -> bool:
    seam = None if ctx is None or phase.seam is None else ctx.seams.get(phase.seam)
    return phase.kind == "linear" and seam is not None and seam.kind == "polyline"


def _segments(phase: CartesianPhase, ctx: CartesianContext, label: str
              ) -> list[CartesianPhase]:
    """A linear phase along a polyline seam as one linear move per segment (the seam's
    ``<name>/<i>`` line seams), blended at the inner corners by ``blend_mm`` (default
    :data:`POLYLINE_BLEND`, at most 45 % of the shorter segment at each corner). The seam's
    last point is never cut: the last segment stops there (blend 0)."""
    seam = ctx.seams[phase.seam]
    segs = seam.segments()
    corner = phase.blend if phase.blend > 0 else POLYLINE_BLEND
    out = []
    for i, sg in enumerate(segs):
        r = 0.0
        if i + 1 < len(segs):
            r = min(corner, 0.45 * min(sg.length(), segs[i + 1].length()))
        out.append(dataclasses.replace(phase, seam=sg.name, blend=r, blend_fraction=0.0,
                                       weave=None))
    return out


#: Share of a joint's speed and acceleration limits a blended corner may use; a corner whose
#: joint motion needs more (the torch turning fast in a small blend) is passed more slowly.
CORNER_LIMIT_SHARE = 0.8
#: Slowest a corner may be passed, as a share of the set speed, before it is refused as too
#: sharp for its blend.
MIN_CORNER_SPEED_SHARE = 0.02


def _corner_load(joint: Any, t0: float, windows: dict[int, tuple[float, float]],
                 robot: Any) -> dict[int, float]:
    """Per corner (piece index -> its time window on the path's clock): the largest share of a
    joint's speed or acceleration limit the joint reference uses there (acceleration as the
    square root of its share, so both scale with the corner's speed)."""
    if robot is None:
        return {}
    vlim = np.asarray(robot.max_speed, dtype=float)
    alim = np.asarray(robot.max_accel, dtype=float) if robot.max_accel else None
    out = {}
    for i, (ta, tb) in windows.items():
        pad = 0.25 * (tb - ta)
        t = np.clip(t0 + np.linspace(ta - pad, tb + pad, 401), joint.start, joint.end)
        st = joint.at(t)
        load = float(np.max(np.abs(st.qd) / vlim))
        if alim is not None:
            load = max(load, float(np.sqrt(np.max(np.abs(st.qdd) / alim))))
        out[i] = load
    return out


def _plan_blended(phases: list[CartesianPhase], t0: float, q0: NDArray[np.float64],
                  ctx: CartesianContext, labels: list[str]) -> list[PhaseMotion]:
    """Consecutive Cartesian phases that blend into each other (``blend_mm``) as one tool path
    (:mod:`planners.blend`): one speed law without stops, one joint polynomial through the
    inverse kinematics of the whole path, each phase a time window of it (ending where its
    corner blend joins the next phase). A phase along a polyline seam is one window over its
    segments, blended at the corners (:func:`_segments`): each leg holds the seam's torch
    frame, and the torch turns from one leg's frame to the next inside the corner only
    (:class:`planners.blend.CornerOrientation`). A corner whose joint motion would need more
    than :data:`CORNER_LIMIT_SHARE` of a joint's speed or acceleration limit at the set speed
    is passed more slowly (the speed dips inside the corner zone, and only there)."""
    # the moves: the phases, a polyline phase one move per segment (of: move -> its phase)
    moves, move_labels, of = [], [], []
    for j, (ph, lb) in enumerate(zip(phases, labels, strict=True)):
        parts = _segments(ph, ctx, lb) if _is_polyline(ph, ctx) else [ph]
        moves += parts
        move_labels += [lb] * len(parts)
        of += [j] * len(parts)
    ctx_seams = dict(ctx.seams)
    welded = [None if ph.seam is None else ph.seam_as_welded(ctx.seams[ph.seam])
              for ph in phases]
    for ph, seam in zip(phases, welded, strict=True):
        if _is_polyline(ph, ctx):
            for sg in seam.segments():
                ctx_seams[sg.name] = sg
    ctx = dataclasses.replace(ctx, seams=ctx_seams)
    rolls: dict[int, float] = {}
    for _ in range(len(moves)):  # first the legs' rolls, at the set speed
        geo = _blend_geometry(moves, move_labels, of, ctx, q0, rolls)
        trial = _time_blended(phases, labels, moves, of, geo, {}, t0, q0, ctx, one_branch=False)
        fix = _wrist_roll(trial, geo, of, t0, ctx)
        if not fix:
            break
        rolls.update(fix)
    plan = _time_with_corner_speeds(phases, labels, moves, move_labels, of, geo, t0, q0, ctx)
    carts, radii = geo.carts, geo.radii
    n = len(moves)
    out = []
    times, bounds, windows = plan.times, plan.bounds, plan.windows
    seams = welded
    for k in range(len(phases)):
        ta, tb = t0 + bounds[k], t0 + bounds[k + 1]
        knots = times[(times >= ta - 1e-12) & (times <= tb + 1e-12)]
        programmed = [mv for i, c in enumerate(carts) if of[i] == k
                      for mv in _programmed(c, moves[i].kind, c.speed, radii[i],
                                            carts[i + 1].length if i + 1 < len(carts) else 0.0)]
        zones = []
        if _is_polyline(phases[k], ctx):
            win = windows[k].base if hasattr(windows[k], "weave") else windows[k]
            mine = [plan.blend_t[i] for i in sorted(plan.blend_t)
                    if of[geo.owner[i]] == k and of[geo.owner[i] + 1] == k]
            programmed = _programmed_legs(win.base, bounds[k], bounds[k + 1], mine,
                                          phases[k].speed)
            cum = np.r_[0.0, np.cumsum([sg.length() for sg in seams[k].segments()])]
            legs = [i for i in range(n) if of[i] == k]
            zones = [(float(cum[m + 1] - radii[i]), float(cum[m + 1] + radii[i]))
                     for m, i in enumerate(legs[:-1])]
        out.append(PhaseMotion(phases[k], float(ta), float(tb), plan.joint,
                               cartesian=windows[k], seam=seams[k], knot_times=knots,
                               programmed=programmed, corner_zones=zones))
    return out


@dataclass
class _BlendGeometry:
    carts: list[Any]
    radii: list[float]
    pieces: list[Any]
    laws: list[Any]
    owner: list[int]
    path: Any


def _blend_geometry(moves: list[CartesianPhase], move_labels: list[str], of: list[int],
                    ctx: CartesianContext, q0: NDArray[np.float64],
                    rolls: dict[int, float]) -> _BlendGeometry:
    """The moves of a blended path (each a polyline leg's roll from ``rolls`` where given),
    trimmed at their corners, the corner curves and the orientation laws."""
    from planners.blend import (
        BlendCurve,
        CompositePath,
        CornerOrientation,
        SubOrientation,
        SubPath,
    )
    from planners.rotations import angular_velocity

    T0 = np.asarray(ctx.kinematics.fk(q0), dtype=float)
    p, R = T0[:3, 3], T0[:3, :3]
    carts = []
    roll = None
    for k, (move, label) in enumerate(zip(moves, move_labels, strict=True)):
        leg = k > 0 and of[k] == of[k - 1]  # a polyline's next leg, entered through a corner
        cart, _ = _phase_cart(move, p, R, ctx, label, corner=leg,
                              roll=rolls.get(k, roll) if leg else None)
        roll = getattr(cart.orientation, "roll", None)
        carts.append(cart)
        p = cart.path.evaluate(np.array([cart.length]))[0][0]
        R = cart.orientation.evaluate(np.array([1.0]))[0][0]
    n = len(moves)
    radii = [(moves[k].blend if moves[k].blend > 0 else
              max(MIN_BLEND, moves[k].blend_fraction * CNT_SHARE
                  * min(carts[k].length, carts[k + 1].length)))
             if k < n - 1 else 0.0 for k in range(n)]
    for k, r in enumerate(radii[:-1]):
        if r < MIN_BLEND - 1e-15:
            raise ScenarioError(f"{move_labels[k]}.blend_mm: {r * 1e3:.4g} mm is too small to blend "
                                f"(at least {MIN_BLEND * 1e3:g} mm; leave it out to stop)")
    pieces, laws, owner = [], [], []
    for k, cart in enumerate(carts):
        L = cart.length
        r_in = radii[k - 1] if k else 0.0
        r_out = radii[k]
        for r, who in ((r_in, k - 1), (r_out, k)):
            if r > 0 and r > 0.5 * L + 1e-12:
                raise ScenarioError(
                    f"{move_labels[who]}.blend_mm: {r * 1e3:.4g} mm is more than half of "
                    f"{moves[k].name!r} ({L * 1e3:.4g} mm long)")
        pieces.append(SubPath(cart.path, r_in, L - r_out))
        laws.append(SubOrientation(cart.orientation, r_in / L, (L - r_out) / L))
        owner.append(k)
        if r_out > 0:
            nxt = carts[k + 1]
            pa, ta = (v[0] for v in cart.path.evaluate(np.array([L - r_out]))[:2])
            pb, tb = (v[0] for v in nxt.path.evaluate(np.array([r_out]))[:2])
            turn = float(np.degrees(np.arccos(np.clip(ta @ tb, -1.0, 1.0))))
            if turn > MAX_BLEND_TURN:
                raise ScenarioError(
                    f"{move_labels[k]}.blend_mm: the path turns {turn:.1f} deg at the corner into "
                    f"{moves[k + 1].name!r}, too sharp to pass at speed (at most "
                    f"{MAX_BLEND_TURN:g} deg); stop there (leave the blend out)")
            try:
                pieces.append(BlendCurve(pa, ta, pb, tb, r_out / 4))
            except PlannerError as exc:
                raise ScenarioError(f"{move_labels[k]}.blend_mm: {exc}") from None
            # each move's turning rate where the corner meets it (rad/m), carried into the
            # corner so the tool's angular velocity stays continuous there
            Ra, dRa = (v[0] for v in cart.orientation.evaluate(np.array([(L - r_out) / L])))
            Rb, dRb = (v[0] for v in nxt.orientation.evaluate(np.array([r_out / nxt.length])))
            laws.append(CornerOrientation(Ra, Rb, angular_velocity(Ra, dRa) / L,
                                          angular_velocity(Rb, dRb) / nxt.length,
                                          pieces[-1].length))
            owner.append(k)
    return _BlendGeometry(carts, radii, pieces, laws, owner, CompositePath(pieces))


def _time_with_corner_speeds(phases: list[CartesianPhase], labels: list[str],
                             moves: list[CartesianPhase], move_labels: list[str], of: list[int],
                             geo: _BlendGeometry, t0: float, q0: NDArray[np.float64],
                             ctx: CartesianContext) -> _BlendedPlan:
    """:func:`_time_blended`, each corner slowed until its joints stay within
    :data:`CORNER_LIMIT_SHARE` of their limits (at most a few passes). A corner whose load does
    not fall as it slows is not what overloads the joints there (the moves beside it are: the
    run's limit check reports them); it keeps its speed."""
    corner_speed: dict[int, float] = {}
    before: dict[int, tuple[float, float | None]] = {}  # corner -> (load, speed) last pass
    settled: set[int] = set()
    plan = _time_blended(phases, labels, moves, of, geo, corner_speed, t0, q0, ctx)
    for _ in range(12):
        load = _corner_load(plan.joint, t0, plan.blend_t, ctx.robot)
        over = {i: x for i, x in load.items()
                if x > CORNER_LIMIT_SHARE * (1 + 1e-6) and i not in settled}
        for i in list(over):
            if i in before and over[i] > 0.9 * before[i][0]:  # slowing did not help
                settled.add(i)
                del over[i]
                if before[i][1] is None:
                    corner_speed.pop(i, None)
                else:
                    corner_speed[i] = before[i][1]  # type: ignore[assignment]
        if not over:
            if settled:
                plan = _time_blended(phases, labels, moves, of, geo, corner_speed, t0, q0, ctx)
            break
        for i, x in over.items():
            k = geo.owner[i]
            before[i] = (x, corner_speed.get(i))
            v = corner_speed.get(i, min(moves[k].speed, moves[k + 1].speed))
            v_new = v * max(0.25, CORNER_LIMIT_SHARE / x * 0.98)  # a quarter at most a pass
            if v_new < MIN_CORNER_SPEED_SHARE * min(moves[k].speed, moves[k + 1].speed):
                turn = float(np.degrees(geo.laws[i].angle))
                raise ScenarioError(
                    f"{move_labels[k]}.blend_mm: the corner into {moves[k + 1].name!r} is too "
                    f"sharp for its {geo.radii[k] * 1e3:.3g} mm blend: the torch turns "
                    f"{turn:.1f} deg there, which the joints cannot follow at "
                    f"{MIN_CORNER_SPEED_SHARE * 100:g} % of the set speed; give a larger "
                    "blend_mm (or stop at the corner)")
            corner_speed[i] = v_new
        plan = _time_blended(phases, labels, moves, of, geo, corner_speed, t0, q0, ctx)
    return plan


#: A polyline leg whose wrist comes closer than this to its singularity (|sin theta5|) is
#: given another roll about the torch axis, where one keeps the wrist farther from it.
WRIST_CLEARANCE = float(np.sin(np.radians(10.0)))
#: Largest joint change between neighbouring samples of a corner before it counts as a wrist
#: flip, rad.
MAX_SAMPLE_STEP = float(np.radians(20.0))
#: Rolls about the torch axis tried for such a leg, deg (relative to the roll it has).
ROLL_CANDIDATES_DEG = (30.0, -30.0, 60.0, -60.0, 90.0, -90.0, 120.0, -120.0, 150.0, -150.0, 180.0)


def _wrist_roll(plan: _BlendedPlan, geo: _BlendGeometry, of: list[int], t0: float,
                ctx: CartesianContext) -> dict[int, float]:
    """The roll about the torch axis is free on a 6-axis arm (the seam fixes the torch axis
    only). A polyline leg entered through a corner whose joints pass near the wrist
    singularity (the torch turning through it makes the wrist spin) gets the roll, among
    :data:`ROLL_CANDIDATES_DEG`, that keeps the wrist farthest from it over the corner and
    the leg (and no wrist flip, where the branch the inverse kinematics had would take a
    joint out of its range). Returns the first such leg's new roll (move index -> rad), or
    nothing."""
    from planners.blend import CornerOrientation
    from sim.robots.ik import ik_path
    from sim.robots.jacobian import singularity_measures
    from sim.simulation.seam_orientation import SeamOrientation

    kin = ctx.kinematics
    if kin.family.five_axis:
        return {}

    def clearance(q: NDArray[np.float64]) -> float:
        """The wrist's least distance from its singularity along ``q`` (|sin theta5|), less
        1 where the joints jump between neighbouring samples (a wrist flip: the branch the
        inverse kinematics had runs into a joint's range)."""
        m = singularity_measures(kin, q)
        c = float(np.min(np.abs(m["wrist"]))) if "wrist" in m else 1.0
        return c - float(np.max(np.abs(np.diff(q, axis=0))) > MAX_SAMPLE_STEP)

    for i, (ta, _) in plan.blend_t.items():
        k = geo.owner[i]
        if of[k] != of[k + 1] or getattr(geo.carts[k + 1].orientation, "name", "") != "seam":
            continue
        t_leg_end = plan.blend_t.get(i + 2, (None,))[0]
        if t_leg_end is None:
            t_leg_end = float(plan.times[-1] - t0)
        tb = plan.blend_t[i][1]
        ts = np.r_[np.linspace(ta, tb, 81), np.linspace(tb, t_leg_end, 81)]
        if clearance(plan.joint.at(t0 + ts).q) >= WRIST_CLEARANCE:
            continue
        q_a = plan.joint.at(t0 + ta).q
        cart, nxt = geo.carts[k], geo.carts[k + 1]
        law = nxt.orientation
        r = geo.radii[k]
        pa = geo.pieces[i].evaluate(np.array([0.0]))[0][0]
        pb = geo.pieces[i].evaluate(np.array([geo.pieces[i].length]))[0][0]
        Ra = cart.orientation.evaluate(np.array([(cart.length - r) / cart.length]))[0][0]
        best, best_c = None, clearance(plan.joint.at(t0 + ts).q)
        for d in ROLL_CANDIDATES_DEG:
            cand = SeamOrientation(law.seam, law.to_frame0, law.s0, law.s1, column=2,
                                   roll=law.roll + np.radians(d))
            u = np.linspace(0.0, 1.0, 41)
            corner = CornerOrientation(Ra, cand.evaluate(np.array([r / nxt.length]))[0][0])
            poses = np.zeros((82, 4, 4))
            poses[:, 3, 3] = 1.0
            poses[:41, :3, :3] = corner.evaluate(u)[0]
            poses[:41, :3, 3] = pa + u[:, None] * (pb - pa)
            poses[41:, :3, :3] = cand.evaluate(u)[0]
            poses[41:, :3, 3] = nxt.path.evaluate(u * nxt.length)[0]
            try:
                c = clearance(ik_path(kin, poses, q_start=q_a))
            except CellsimError:
                continue
            if c > best_c + 1e-3:
                best, best_c = law.roll + np.radians(d), c
        if best is not None:
            return {k + 1: float(best)}
    return {}


@dataclass
class _BlendedPlan:
    joint: Any
    times: NDArray[np.float64]
    bounds: list[float]
    windows: list[Any]
    blend_t: dict[int, tuple[float, float]]


def _time_blended(phases: list[CartesianPhase], labels: list[str], moves: list[CartesianPhase],
                  of: list[int], geo: _BlendGeometry, corner_speed: dict[int, float],
                  t0: float, q0: NDArray[np.float64], ctx: CartesianContext,
                  one_branch: bool = True) -> _BlendedPlan:
    """The time law of a blended path (each corner at ``corner_speed`` where given: the speed
    dips over the corner's first third, holds, and recovers over its last third), the
    phases' time windows, and the joint polynomial through the inverse kinematics of its
    samples."""
    from planners import adnia
    from planners.blend import CompositeOrientation, PiecewiseProfile, TimeWindow

    kin = ctx.kinematics
    carts, pieces, laws, owner, path = geo.carts, geo.pieces, geo.laws, geo.owner, geo.path
    lengths = [pc.length for pc in pieces]
    changes = [(0.0, 0.0, moves[0].speed, float(carts[0].profile.ramp_time))]
    for i, pc in enumerate(pieces):
        if pc.kind == "blend":
            k = owner[i]
            va, vb = moves[k].speed, moves[k + 1].speed
            vc = corner_speed.get(i)
            s0, ell = float(path.starts[i]), pc.length
            if vc is not None and vc < min(va, vb):
                changes.append((s0 + ell / 6, va, vc, 2.0 * (ell / 3) / (va + vc)))
                changes.append((s0 + 5 * ell / 6, vc, vb, 2.0 * (ell / 3) / (vc + vb)))
            elif va != vb:
                changes.append((s0 + ell / 2, va, vb, 2.0 * ell / (va + vb)))
    changes.append((path.length, moves[-1].speed, 0.0, float(carts[-1].profile.ramp_time)))
    try:
        profile = PiecewiseProfile(changes, path.length)
        traj = adnia.CartesianTrajectory(path, CompositeOrientation(laws, path.starts[:-1],
                                                                   lengths), profile)
    except PlannerError as exc:
        raise ScenarioError(f"{labels[0]}: {exc}") from None
    # each phase's window ends in the middle of its last corner (where the tool
    # "reaches" the programmed point it blends past)
    m = len(phases)
    blend_t = {i: (profile.time_at(path.starts[i]), profile.time_at(path.starts[i + 1]))
               for i, pc in enumerate(pieces) if pc.kind == "blend"}
    last = [max(i for i in range(len(pieces)) if of[owner[i]] == j) for j in range(m)]
    bounds = [0.0]
    for j in range(m - 1):
        i = last[j]
        bounds.append(0.5 * sum(blend_t[i]) if i in blend_t
                      else profile.time_at(path.starts[i + 1]))
    bounds.append(profile.duration)
    windows = []
    for j in range(m):
        ramp_in = float(carts[0].profile.ramp_time) if j == 0 else 0.0
        ramp_out = float(carts[-1].profile.ramp_time) if j == m - 1 else 0.0
        # the part at the set speed: after the start ramp or the incoming corner, before the
        # stop ramp or the outgoing corner
        first = min(i for i in range(len(pieces)) if of[owner[i]] == j)
        a = ramp_in if j == 0 else blend_t[first - 1][1] - bounds[j] if first - 1 in blend_t \
            else 0.0
        b = (bounds[j + 1] - bounds[j] - ramp_out if j == m - 1 else
             blend_t[last[j]][0] - bounds[j] if last[j] in blend_t else bounds[j + 1] - bounds[j])
        win = TimeWindow(traj, bounds[j], bounds[j + 1], phases[j].speed, ramp_in, ramp_out,
                         steady=(max(a, 0.0), max(b, max(a, 0.0))))
        if phases[j].weave is not None:
            from planners.weave import WeavingTrajectory

            # a weave carries on into and out of the phases beside it that weave alike
            first_j = j
            while first_j > 0 and phases[first_j - 1].weave == phases[j].weave:
                first_j -= 1
            win = WeavingTrajectory(
                win, phases[j].weave, kin.family.approach_column,
                clock=bounds[j] - bounds[first_j], fade_in=first_j == j,
                fade_out=j == m - 1 or phases[j + 1].weave != phases[j].weave)
        windows.append(win)
    # samples: every period (finer where the tool turns fast), at the phase ends, and at the
    # weaves' turns
    period = _turn_limited_period(traj, min(ph.sample_period for ph in phases), labels[0])
    extra = [np.array(bounds[1:-1])]
    for i, (t_a, t_b) in blend_t.items():  # each corner sampled on its own, finer as it turns
        turn = float(np.degrees(getattr(laws[i], "angle", 0.0)))
        n_c = max(SAMPLES_PER_BLEND, int(np.ceil(turn / DEG_PER_CORNER_SAMPLE)))
        extra.append(np.linspace(t_a, t_b, n_c + 1))
    for k, win in enumerate(windows):
        if phases[k].weave is not None:
            period = min(period, _weave_period(phases[k].weave))
            extra.append(bounds[k] + win.breakpoints())
    ts = _sample_times(profile.duration, period, np.concatenate(extra), labels[0])

    def poses_at(ts: NDArray[np.float64]) -> NDArray[np.float64]:
        which = np.clip(np.searchsorted(np.array(bounds), ts, side="right") - 1, 0, m - 1)
        poses = np.zeros((len(ts), 4, 4))
        for k, win in enumerate(windows):
            sel = which == k
            if np.any(sel):
                poses[sel] = _poses(win.at(ts[sel] - bounds[k]))
        if kin.family.five_axis:  # a 5-axis arm: corners in its plane
            poses = _into_j1_plane(poses)
        return poses

    ts, q_via = _ik_knots_refined(kin, ts, poses_at, q0, labels[0], ctx.robot, one_branch)
    times = t0 + ts
    placed = JointPhase(index=phases[0].index, name=phases[0].name, planner=phases[0].planner,
                        times=times, durations=np.diff(times), q=q_via)
    return _BlendedPlan(plan_phase(placed, ""), times, bounds, windows, blend_t)
