"""Every phase of a scenario planned and placed on one clock: :func:`build_motion`.

Joint phases are planned with their polynomial (:mod:`~sim.simulation.motion.joint` for pose
targets, speed shares and joint blends), hold phases keep the pose, Cartesian phases are
planned alone (:mod:`~sim.simulation.motion.cartesian`) or as a blended group
(:mod:`~sim.simulation.motion.blending`); consecutive phases are checked to meet and the
scenario's tool actions are put on the clock.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from sim.errors import KinematicsError, LimitError, ScenarioError
from sim.scenario import CartesianPhase, HoldPhase, JointPhase, Scenario, plan_phase
from sim.scenario.model import phase_label
from sim.simulation.motion import axes
from sim.simulation.motion.blending import (
    _blends,
    _check_seam_blends,
    _is_polyline,
    _plan_blended,
)
from sim.simulation.motion.cartesian import _plan_cartesian
from sim.simulation.motion.checks import (
    _check_end_config,
    _check_phase_continuity,
    limit_violations,
)
from sim.simulation.motion.context import CartesianContext
from sim.simulation.motion.joint import _joint_blend, _solve_target, _timed_by_speed
from sim.simulation.motion.timeline import HoldTrajectory, Motion, PhaseMotion


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
    # the first robot's joints and the cell's axes (the other robots' lanes are built apart)
    system = scenario.system.without_partners
    joints = system.joints
    # a cell with external axes: the joint vector is the robot's joints, then the axes
    # (sim.simulation.motion.axes); n is the robot's share of it
    n_axes = 0 if context is None else context.n_axes
    n = system.n_joints - n_axes
    if n_axes and context is not None:
        q_axes_home = np.concatenate([pm.home for pm in context.mechanisms])
    todo = list(scenario.phases)
    pending: tuple[NDArray[np.float64], dict[str, NDArray[np.float64]],
                   NDArray[np.float64] | None] | None = None
    try:
        while todo:
            phase = todo.pop(0)
            label = phase_label(where, phase)
            if not system.external:  # the cell's own axes, whether or not it was built
                _no_axes_to_move(phase, label)
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
                labels = [phase_label(where, ph) for ph in group]
                if n_axes:
                    assert q is not None
                    _no_coordination(group, labels)
                    ctx_p = axes.posed(context, q[n:])
                    planned = [axes.held(pm, q[n:]) for pm in
                               _plan_blended(group, t, q[:n], ctx_p, labels)]
                else:
                    ctx_p, planned = context, _plan_blended(group, t, q, context, labels)
                for pm, lb in zip(planned, labels, strict=True):
                    if phases:
                        _check_phase_continuity(phases[-1], pm, label, joints)
                    _check_end_config(_robot_part(pm, n), ctx_p, lb)
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
                    if n_axes:
                        q = np.concatenate([q, q_axes_home])
                if n_axes:
                    pm = _joint_phase_with_axes(phase, t, q, n, q_axes_home, context, system, label,
                                                todo)
                    if phases:
                        _check_phase_continuity(phases[-1], pm, label, joints)
                    phases.append(pm)
                    t = pm.t1
                    q = pm.trajectory.at(pm.t1).q
                    continue
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
                    placed = _timed_by_speed(placed, scenario.robot, label)
                if phase.blend > 0 or phase.blend_fraction > 0:
                    placed, pending = _joint_blend(placed, todo[0] if todo else None, context,
                                                   label, scenario.robot)
                traj = plan_phase(placed, where)
                pm = PhaseMotion(placed, placed.t0, placed.t1, traj, knot_times=placed.times.copy())
            elif isinstance(phase, HoldPhase):
                traj = HoldTrajectory(t, phase.duration, q)
                pm = PhaseMotion(phase, t, t + phase.duration, traj, knot_times=np.array([t]))
            elif isinstance(phase, CartesianPhase):
                if context is None:
                    raise ScenarioError(f"{label}: Cartesian phases need the robot's kinematics")
                if n_axes and (phase.downhand or phase.follow is not None or phase.axes):
                    pm = axes.plan_coordinated(phase, t, q, context, label)
                elif n_axes:
                    ctx_p = axes.posed(context, q[n:])
                    pm = _plan_cartesian(phase, t, q[:n], ctx_p, label)
                    _check_end_config(pm, ctx_p, label)
                    pm = axes.held(pm, q[n:])
                else:
                    pm = _plan_cartesian(phase, t, q, context, label)
                    _check_end_config(pm, context, label)
            else:  # pragma: no cover - the loader only makes the kinds above
                raise ScenarioError(f"{label}: unknown phase kind {phase.kind!r}")
            if phases:
                _check_phase_continuity(phases[-1], pm, label, joints)
            phases.append(pm)
            t = pm.t1
            q = pm.trajectory.at(pm.t1).q
    except (ScenarioError, KinematicsError):
        # a phase that cannot be planned from where an earlier one left a joint past its
        # range: the range is the mistake to name (the later phase's IK or branch error
        # only follows from it)
        _earlier_limit(scenario, phases, system.n_joints)
        raise
    motion = Motion(phases=phases, actions=[], n_joints=system.n_joints)
    motion.actions = _resolve_actions(scenario, motion)
    if scenario.partners:
        motion.lanes = _plan_partners(scenario, context, motion.t0)
        motion.n_joints = scenario.system.n_joints  # the other robots' joints after
    return motion


def _earlier_limit(scenario: Scenario, phases: list[PhaseMotion], n_lead: int) -> None:
    """Raise :class:`LimitError` with every joint-range violation of the ``phases`` planned
    so far (the first robot's; positions only), if any."""
    if not phases:
        return
    found = limit_violations(dataclasses.replace(scenario, partners=()),
                             Motion(phases=list(phases), actions=[], n_joints=n_lead),
                             speed=False, accel=False)
    if found:
        raise LimitError(found) from None


def _plan_partners(scenario: Scenario, context: CartesianContext | None, t0: float
                   ) -> list[tuple[str, Motion]]:
    """The cell's other robots' motions, each planned alone with its own kinematics and seams
    on the cycle's clock (from ``t0``); one without work holds its home."""
    if context is None:
        raise ScenarioError(f"{scenario.source.name}: robots: a cell's other robots need the "
                            "compiled cell")
    lanes = []
    for work in scenario.partners:
        ctx = context.partners[work.name]
        assert ctx.home_q is not None
        if not work.phases:
            hold = HoldPhase(index=0, name="home", duration=0.0)
            lane = Motion([PhaseMotion(hold, t0, t0, HoldTrajectory(t0, 0.0, ctx.home_q),
                                       knot_times=np.array([t0]))], [], work.robot.n_joints)
        else:
            sub = scenario.partner_scenario(work)
            for ph in work.phases:
                _check_still(ph, context, f"{scenario.source.name}: robots.{work.name}: "
                                          f"phases[{ph.index}]")
            lane = build_motion(dataclasses.replace(
                sub, source=scenario.source.with_name(
                    f"{scenario.source.name}: robots.{work.name}")), ctx)
        lanes.append((work.name, lane))
    return lanes


def _robot_part(pm: PhaseMotion, n: int) -> PhaseMotion:
    """A phase with held axes as the robot's alone (for the checks of its arm)."""
    traj = pm.trajectory
    return dataclasses.replace(pm, trajectory=traj.robot) if isinstance(traj, axes.HeldAxes) \
        else pm


def _no_axes_to_move(phase: object, label: str) -> None:
    """Refuse what only a cell's axes can do (``downhand``, ``follow``, ``axes``) in a cell
    without them: silently ignored, the user would believe the weld turned downhand."""
    if getattr(phase, "downhand", False):
        raise ScenarioError(f"{label}.downhand: the cell has no positioner or turntable to turn "
                            "the seam downhand (leave downhand out)")
    if getattr(phase, "follow", None) is not None:
        raise ScenarioError(f"{label}.follow: the cell has no track to follow the weld with "
                            "(leave follow out)")
    if getattr(phase, "axes", None):
        raise ScenarioError(f"{label}.axes: the cell has no external axes to move (leave axes "
                            "out)")


def _no_coordination(group: list, labels: list[str]) -> None:
    for ph, lb in zip(group, labels, strict=True):
        if ph.downhand or ph.follow is not None or ph.axes:
            key = "downhand" if ph.downhand else "follow" if ph.follow is not None else "axes"
            raise ScenarioError(f"{lb}.{key}: not with blend_mm or a polyline seam (coordinated "
                                "motion welds one line or arc seam per phase)")


def _joint_phase_with_axes(phase: JointPhase, t: float, q: NDArray[np.float64] | None, n: int,
                           q_axes_home: NDArray[np.float64], context: CartesianContext,
                           system: object, label: str, todo: list) -> PhaseMotion:
    """A joint phase in a cell with external axes (:func:`axes.joint_with_axes`)."""
    if phase.blend > 0 or phase.blend_fraction > 0:
        raise ScenarioError(f"{label}.blend_deg: not yet in a cell with external axes (stop "
                            "at the phase's last knot)")
    qe = q_axes_home if q is None else q[n:]
    placed = phase.with_start(t, None if q is None else q[:n])
    placed = axes.joint_with_axes(placed, qe, context, tuple(system.joints[n:]), label,
                                  _solve_target)
    if phase.speed_pct is not None:
        placed = _timed_by_speed(placed, system, label)
    traj = plan_phase(placed, "")
    return PhaseMotion(placed, placed.t0, placed.t1, traj, knot_times=placed.times.copy())


def _check_still(phase: object, context: CartesianContext, label: str) -> None:
    """A cell's other robot works only on what stands still: a seam (``seam``, ``to_seam``)
    or a frame (``frame``) a mechanism carries is refused (its motion is planned with the
    cell at home; the first robot's phases move the axes)."""
    target = getattr(phase, "target", None)
    seams = [("seam", getattr(phase, "seam", None)),
             ("to_seam", None if target is None else target.seam)]
    frames = [("frame", getattr(phase, "frame", None)),
              ("frame", None if target is None else target.frame)]
    for key, seam in seams:
        if seam is not None and seam in context.seam_mechanism:
            raise ScenarioError(f"{label}.{key}: {seam!r} is carried by "
                                f"{context.seam_mechanism[seam]!r}; a cell's other robots weld "
                                "seams that stand still (the first robot welds with the cell's "
                                "axes)")
    for key, frame in frames:
        if frame is not None and frame in context.frame_mechanism:
            raise ScenarioError(f"{label}.{key}: {frame!r} is carried by "
                                f"{context.frame_mechanism[frame]!r}; a cell's other robots "
                                "move in frames that stand still")


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
