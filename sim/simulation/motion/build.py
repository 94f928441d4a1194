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

from sim.errors import ScenarioError
from sim.scenario import CartesianPhase, HoldPhase, JointPhase, Scenario, plan_phase
from sim.simulation.motion.blending import (
    _blends,
    _check_seam_blends,
    _is_polyline,
    _plan_blended,
)
from sim.simulation.motion.cartesian import _plan_cartesian
from sim.simulation.motion.checks import _check_end_config, _check_phase_continuity
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
                placed = _timed_by_speed(placed, scenario.robot, label)
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
