"""Checks of a planned motion: its size, its joint limits, continuity between phases, and
a Cartesian move's end configuration.

Owns :func:`check_size` (the physics steps a run takes, at most :data:`MAX_STEPS`),
:func:`limit_violations` and :func:`check_motion_limits` (joint position, speed and
acceleration limits), :func:`_check_phase_continuity` (consecutive phases meet in position,
velocity and acceleration) and :func:`_check_end_config` (a TP linear or circular move ends
in the CONFIG its position names).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from sim.errors import ReachError, ScenarioError
from sim.scenario import CartesianPhase, Scenario
from sim.scenario.model import phase_label
from sim.simulation.motion.context import CartesianContext
from sim.simulation.motion.timeline import HoldTrajectory, Motion, PhaseMotion

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
            raise ScenarioError(f"{phase_label(scenario.source.name, pm.phase)} lasts "
                                f"{pm.t1 - pm.t0:.3g} s, shorter than one timestep "
                                f"({timestep:g} s, simulation.timestep_s): the drives could not "
                                "follow it; make it longer or drop it")
    total = motion.duration + scenario.simulation.settle_s
    steps = total / timestep if timestep > 0 else float("inf")
    if not np.isfinite(steps) or steps > MAX_STEPS:
        longest = max(motion.phases, key=lambda pm: pm.t1 - pm.t0)
        what = phase_label("", longest.phase)[2:]
        if not getattr(longest.phase, "origin", ""):  # a scenario's phase: its keys
            what += {"hold": ": duration_s", "joint": ": durations_s or time_s"}.get(
                longest.kind, ": speed_mm_s")
        raise ScenarioError(
            f"{scenario.source.name}: the cycle lasts {motion.duration:.4g} s plus "
            f"simulation.settle_s {scenario.simulation.settle_s:g} s; at a timestep of "
            f"{timestep:g} s (simulation.timestep_s) that is {steps:.3g} steps, more than "
            f"{MAX_STEPS:,}: shorten the phases (the longest, "
            f"{longest.t1 - longest.t0:.4g} s: {what}) or the settling, or raise the "
            "timestep")
    return int(np.ceil(steps))


def limit_violations(scenario: Scenario, motion: Motion, *, speed: bool = True,
                     accel: bool = True) -> list[str]:
    """One line per joint limit the reference motion exceeds (position range from the MJCF,
    speed and acceleration limits from the robot registry), naming the phase, joint, time,
    value and limit."""
    from planners.limits import find_limit_violations
    from sim.robots.registry import joint_ranges

    system = scenario.system  # the robot's joints and the cell's external axes
    rng = joint_ranges(system)
    where = scenario.source.name
    k = motion.n_lead  # the other robots' joints follow: their lanes are checked below
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
            group[0].trajectory, lower=rng[:k, 0], upper=rng[:k, 1],
            max_velocity=np.asarray(system.max_speed[:k]) if speed else None,
            max_acceleration=(np.asarray(system.max_accel[:k])
                              if accel and system.max_accel else None),
            joint_names=system.joints[:k],
            linear=list(system.linear[:k]))
        for v in found:
            pm = next((p for p in group if p.t0 <= v.time <= p.t1), group[0])
            out.append(f"{phase_label(where, pm.phase)}: {v.message()}")
    for work, (name, lane) in zip(scenario.partners, motion.lanes, strict=True):
        sub = scenario.partner_scenario(work)
        sub = dataclasses.replace(sub, source=scenario.source.with_name(
            f"{where}: robots.{name}"))
        out += limit_violations(sub, lane, speed=speed, accel=accel)
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


#: Continuity tolerance between consecutive phases (rad, rad/s, rad/s^2).
_CONTINUITY_TOL = 1e-6


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
    from sim.robots.kinematics.ik import solve_ik
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
