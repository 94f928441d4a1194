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
    """

    phase: Phase
    t0: float
    t1: float
    trajectory: Any
    cartesian: Any = None
    seam: Any = None
    knot_times: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    @property
    def name(self) -> str:
        return self.phase.name

    @property
    def kind(self) -> str:
        return self.phase.kind


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
    """

    kinematics: Any
    seams: dict[str, Any] = field(default_factory=dict)
    world_from_frame0: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    frames: dict[str, NDArray[np.float64]] = field(default_factory=dict)

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
    for phase in scenario.phases:
        label = f"{where}: phases[{phase.index}] ({phase.name})"
        if isinstance(phase, JointPhase):
            placed = phase.with_start(t, q)
            if phase.target is not None:
                if context is None:
                    raise ScenarioError(f"{label}: a pose target needs the robot's kinematics")
                placed = placed.with_end(_solve_target(phase, placed.q[0], context, label))
            traj = plan_phase(placed, where)
            pm = PhaseMotion(placed, placed.t0, placed.t1, traj, knot_times=placed.times.copy())
        elif isinstance(phase, HoldPhase):
            traj = HoldTrajectory(t, phase.duration, q)
            pm = PhaseMotion(phase, t, t + phase.duration, traj, knot_times=np.array([t]))
        elif isinstance(phase, CartesianPhase):
            if context is None:
                raise ScenarioError(f"{label}: Cartesian phases need the robot's kinematics")
            pm = _plan_cartesian(phase, t, q, context, label)
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
    out = []
    for pm in motion.phases:
        if isinstance(pm.trajectory, HoldTrajectory):
            continue
        found = find_limit_violations(
            pm.trajectory, lower=rng[:, 0], upper=rng[:, 1],
            max_velocity=np.asarray(scenario.robot.max_speed) if speed else None,
            max_acceleration=(np.asarray(scenario.robot.max_accel)
                              if accel and scenario.robot.max_accel else None),
            joint_names=scenario.robot.joints)
        out += [f"{where}: phases[{pm.phase.index}] ({pm.name}): {v.message()}" for v in found]
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
        seam = _seam(ctx, tgt.seam, f"{label}.to_seam")
        T[:3, 3] = ctx.to_frame0(seam.tcp_point(0.0))
        T[:3, :3] = ctx.rot_to_frame0(seam.torch_rotation(0.0))
    else:
        F = ctx.frame0_from(tgt.frame, label)
        T[:3, 3] = F[:3, :3] @ tgt.position + F[:3, 3]
        T[:3, :3] = (F[:3, :3] @ tgt.rotation if tgt.rotation is not None
                     else np.asarray(ctx.kinematics.fk(q0), dtype=float)[:3, :3])
    key = "to_seam" if tgt.seam is not None else "to_mm"
    try:
        sols = solve_ik(ctx.kinematics, T, current=q0)
    except CellsimError as exc:
        raise ReachError(f"{label}.{key}: {exc}") from None
    good = [s for s in sols if s.within_limits]
    if not good:
        raise ReachError(f"{label}.{key}: the pose is reachable only outside the joint "
                         "ranges")
    return np.asarray(good[0].q, dtype=float)


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


def _plan_cartesian(phase: CartesianPhase, t0: float, q0: NDArray[np.float64],
                    ctx: CartesianContext, label: str) -> PhaseMotion:
    from planners import adnia
    from sim.robots.ik import ik_path

    kin = ctx.kinematics
    T0 = np.asarray(kin.fk(q0), dtype=float)
    p0, R0 = T0[:3, 3], T0[:3, :3]
    F = ctx.frame0_from(phase.frame, label)  # the phase's points are in this frame

    def pt(v: Any) -> Any:
        return None if v is None else F[:3, :3] @ np.asarray(v, dtype=float) + F[:3, 3]

    to, via, center = pt(phase.to), pt(phase.via), pt(phase.center)
    axis = None if phase.axis is None else F[:3, :3] @ np.asarray(phase.axis, dtype=float)

    seam = None
    if phase.seam is not None:
        seam = _seam(ctx, phase.seam, f"{label}.seam")
        if seam.kind != ("line" if phase.kind == "linear" else "arc"):
            raise ScenarioError(f"{label}.seam: {phase.seam!r} is a {seam.kind} seam; a "
                                f"{phase.kind} phase needs a {'line' if phase.kind == 'linear' else 'arc'}")
        start = ctx.to_frame0(seam.tcp_point(0.0))
        gap = float(np.linalg.norm(start - p0))
        if gap > 5e-4:
            raise ScenarioError(
                f"{label}.seam: the tool is at {np.round(p0 * 1e3, 2).tolist()} mm (frame 0) but seam "
                f"{phase.seam!r} starts at {np.round(start * 1e3, 2).tolist()} mm, {gap * 1e3:.2f} mm "
                "away; end the previous phase at the seam start")

    rot_end = None
    mode = {"keep": "geodesic", "euler": "geodesic", "seam": "geodesic", "follow": "carry"}[
        phase.orientation]
    if phase.orientation == "euler":
        from sim.core.rotations import euler_zyx_to_matrix

        rot_end = F[:3, :3] @ euler_zyx_to_matrix(*phase.euler_zyx)
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

    count = cart.duration / phase.sample_period
    if not np.isfinite(count) or count > MAX_PHASE_SAMPLES:
        raise ScenarioError(
            f"{label}: the move lasts {cart.duration:.4g} s; sampled every "
            f"{phase.sample_period:.4g} s (sample_period_s) that is "
            f"{count:.3g} inverse-kinematics samples, more than {MAX_PHASE_SAMPLES:,} "
            "(raise speed_mm_s or sample_period_s)")
    n = max(2, int(np.ceil(count - 1e-9)))
    ts = np.linspace(0.0, cart.duration, n + 1)
    st = cart.at(ts)
    poses = np.zeros((n + 1, 4, 4))
    poses[:, :3, :3] = st.rotation
    poses[:, :3, 3] = st.position
    poses[:, 3, 3] = 1.0
    try:
        q_via = np.asarray(ik_path(kin, poses, q_start=q0), dtype=float)
    except CellsimError as exc:
        raise ReachError(f"{label}: {exc}") from None
    jump = np.abs(q_via[0] - q0)
    if np.any(jump > 1e-6):
        j = int(np.argmax(jump))
        raise ScenarioError(f"{label}: inverse kinematics of the start pose changes joint j{j + 1} "
                            f"by {np.rad2deg(jump[j]):.3g} deg (another branch); check the "
                            "previous phase's end pose")
    q_via[0] = q0
    times = t0 + ts
    placed = JointPhase(index=phase.index, name=phase.name, planner=phase.planner, times=times,
                        durations=np.diff(times), q=q_via)
    traj = plan_phase(placed, "")
    return PhaseMotion(phase, float(times[0]), float(times[-1]), traj, cartesian=cart, seam=seam,
                       knot_times=times)
