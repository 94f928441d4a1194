"""``cellsim plan SCENARIO``: the planned polynomial coefficients of every phase.

Prints, per phase and joint (hold phases have no polynomial and are left out), each
segment's duration and its coefficients in normalized time
(t in [0, 1], the last segment in t_bar = t - 1 in [-1, 0]) and in real time (powers of the
absolute time tau, s), like seed 000 Tables 4-5. Text output is in degrees as the seeds print
them; ``--json`` gives radians, ascending powers, in this shape::

    {"scenario": str, "phases": [{"name": str, "planner": "434"|"546", "time_s": [..],
      "joints": [{"index": int, "segments": [{"t0": s, "t1": s, "normalized": [a0, a1, ..],
      "real": [b0, b1, ..]}]}]}]}
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

import numpy as np

from sim.scenario import CartesianPhase, JointPhase, Scenario, load_scenario
from sim.simulation.motion import (
    HoldTrajectory,
    Motion,
    PhaseMotion,
    build_motion,
    limit_violations,
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "plan",
        help="print the planned polynomial coefficients of a scenario",
        description="Plan every phase of SCENARIO and print, per phase and joint, each "
                    "segment's duration and coefficients in normalized and real time "
                    "(degrees in text, radians with --json).",
    )
    p.add_argument("scenario", metavar="SCENARIO",
                   help="a scenario file, or a shipped scenario's name (see `cellsim list`)")
    p.add_argument("--json", action="store_true",
                   help="print JSON (coefficients in radians, metres on a linear axis such "
                        "as a track's; ascending powers; each joint's name and unit given)")
    p.set_defaults(func=run)


def planned_motion(scenario: Scenario) -> Motion:
    """The scenario's motion on one clock (Cartesian phases through the cell's IK; a cell's
    other robots' in :attr:`Motion.lanes`); limit violations warned on stderr."""
    context = None
    # the cell is built where a phase needs it: a Cartesian move or a pose target (its IK), a
    # joint move that starts from the cell's home (a TP program's first move, a phase with
    # durations_s and no start), other robots, or the cell's axes (mechanisms)
    if scenario.partners or scenario.system.external or any(
            isinstance(p, CartesianPhase) or (isinstance(p, JointPhase) and (
                p.target is not None or bool(np.isnan(p.q[0]).any())))
            for p in scenario.phases):
        from sim.simulation.compile import build

        context = build(scenario).context
    motion: Motion = build_motion(scenario, context)
    for line in limit_violations(scenario, motion,
                                 speed=True):
        print(f"cellsim: warning: {line}", file=sys.stderr)
    return motion


def _polynomial(phases: list[PhaseMotion]) -> list[PhaseMotion]:
    return [pm for pm in phases if not isinstance(pm.trajectory, HoldTrajectory)]


def planned_phases(scenario: Scenario) -> list[PhaseMotion]:
    """The scenario's (its first robot's) polynomial phases on one clock (Cartesian ones
    through the cell's IK)."""
    return _polynomial(planned_motion(scenario).phases)


def planned_lanes(motion: Motion) -> list[tuple[str, list[PhaseMotion]]]:
    """A cell's other robots' polynomial phases, ``(name, phases)`` each, on the same clock."""
    return [(name, _polynomial(lane.phases)) for name, lane in motion.lanes]


def plan_json(scenario: Scenario, planned: list[PhaseMotion],
              lanes: list[tuple[str, list[PhaseMotion]]] | None = None) -> dict[str, Any]:
    """The ``--json`` document of a planned scenario (coefficients in radians, metres on a
    linear axis; each joint named, with its unit); with a cell's
    other robots (``lanes``), ``"robots"``: ``[{"name": str, "phases": [...]}]`` (their
    phases as the first robot's, joints indexed from 1 in their own robot)."""
    first = scenario.system
    out: dict[str, Any] = {"scenario": scenario.name, "phases": _phases_json(
        planned, list(first.joints), list(first.linear))}
    if lanes:
        work = {w.name: w for w in scenario.partners}
        out["robots"] = [{"name": name, "phases": _phases_json(
            ph, list(work[name].robot.joints) if name in work else [],
            list(work[name].robot.linear) if name in work else [])} for name, ph in lanes]
    return out


def _phases_json(planned: list[PhaseMotion], names: list[str], linear: list[bool]
                 ) -> list[dict[str, Any]]:
    """The phases' segments; each joint with its name and its coefficients' unit (``rad``,
    ``m`` on a linear axis) where ``names`` has it."""
    phases = []
    for pp in planned:
        traj = pp.trajectory
        knots = np.asarray(traj.knots, dtype=float)
        inside = _window(pp)
        joints = []
        for j in range(traj.n_joints):
            segments = []
            for s in inside:
                segments.append({
                    "t0": float(knots[s]),
                    "t1": float(knots[s + 1]),
                    "normalized": [float(c) for c in traj.normalized_coefficients[s][j]],
                    "real": [float(c) for c in traj.real_coefficients[s][j]],
                })
            joint: dict[str, Any] = {"index": j + 1}
            if j < len(names):
                joint["name"] = names[j]
                joint["unit"] = "m" if j < len(linear) and linear[j] else "rad"
            joints.append({**joint, "segments": segments})
        phases.append({
            "name": pp.phase.name,
            "planner": pp.phase.planner,
            "time_s": [float(t) for t in knots[inside[0]:inside[-1] + 2]],
            "joints": joints,
        })
    return phases


def _window(pp: PhaseMotion) -> range:
    """The segments of a phase's trajectory inside its time window: blended phases share
    one trajectory, and each lists its own part of it (listing the whole one for each made
    the output grow as the square of the number of moves)."""
    knots = np.asarray(pp.trajectory.knots, dtype=float)
    tol = 1e-9 * max(1.0, abs(pp.t1))
    first = int(np.searchsorted(knots, pp.t0 + tol, side="right")) - 1
    last = int(np.searchsorted(knots, pp.t1 - tol, side="left"))
    first = min(max(first, 0), len(knots) - 2)
    return range(first, max(last, first + 1))


def _poly_text(coeffs: np.ndarray, var: str) -> str:
    terms = []
    for k in range(len(coeffs) - 1, -1, -1):
        c = float(coeffs[k])
        if c == 0.0:
            continue
        power = "" if k == 0 else (f" {var}" if k == 1 else f" {var}^{k}")
        terms.append(f"{c:+.6g}{power}")
    return " ".join(terms) if terms else "0"


def format_plan(scenario: Scenario, planned: list[PhaseMotion],
                lanes: list[tuple[str, list[PhaseMotion]]] | None = None) -> str:
    """Human-readable tables (degrees), one block per phase and joint; a cell's other
    robots' phases (``lanes``) follow, each headed by its robot, joints ``<name>_<joint>``."""
    axes = len(scenario.system.external)
    lines = [f"scenario {scenario.name}: robot {scenario.robot.name} "
             f"({scenario.robot.n_joints} joints"
             + (f" and {axes} external axes" if axes else "")
             + f"), {len(planned)} polynomial phase(s)",
             "coefficients in degrees (a linear axis's in mm); normalized time "
             "t = (tau - tau_k-1)/t_k, "
             "last segment in t_bar = t - 1; real time in powers of tau [s]"]
    linear = {n for n, a in scenario.system.external if a.kind == "prismatic"}
    lines += _phase_blocks(planned, scenario.system.joints, linear)
    works = {w.name: w for w in scenario.partners}
    for name, phases in lanes or []:
        robot = works[name].robot
        lines += ["", f"robot {name} ({robot.name}, {robot.n_joints} joints), "
                  f"{len(phases)} polynomial phase(s)"]
        lines += _phase_blocks(phases, tuple(f"{name}_{j}" for j in robot.joints), set())
    return "\n".join(lines)


def _phase_blocks(planned: list[PhaseMotion], joint_names: tuple[str, ...],
                  linear: set[str]) -> list[str]:
    lines: list[str] = []
    deg = 180.0 / np.pi
    for pp in planned:
        traj = pp.trajectory
        knots = np.asarray(traj.knots, dtype=float)
        lines.append("")
        inside = _window(pp)
        lines.append(f"phase {pp.phase.index + 1} {pp.phase.name!r}: planner {pp.phase.planner}, "
                     f"knots at {', '.join(f'{t:g}' for t in knots[inside[0]:inside[-1] + 2])} s")
        for j, jname in enumerate(joint_names[: traj.n_joints]):
            scale = 1e3 if jname in linear else deg
            lines.append(f"  joint {jname}" + (" (mm)" if jname in linear else ""))
            for s in inside:
                var = traj.segment_variable(s)
                lines.append(f"    segment {s + 1}: {knots[s]:g} -> {knots[s + 1]:g} s "
                             f"(t_{s + 1} = {knots[s + 1] - knots[s]:g} s)")
                lines.append("      normalized: "
                             + _poly_text(np.asarray(traj.normalized_coefficients[s][j]) * scale,
                                          var))
                lines.append("      real:       "
                             + _poly_text(np.asarray(traj.real_coefficients[s][j]) * scale, "tau"))
    return lines


def run(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario)
    motion = planned_motion(scenario)
    planned = _polynomial(motion.phases)
    lanes = planned_lanes(motion)
    if args.json:
        json.dump(plan_json(scenario, planned, lanes), sys.stdout, indent=1)
        sys.stdout.write("\n")
    else:
        print(format_plan(scenario, planned, lanes))
    return 0
