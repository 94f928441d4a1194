"""``cellsim export``: a scenario's motion as a FANUC TP program (``.ls``).

The scenario is planned as for a run (no simulation), and each phase becomes TP instructions
that :mod:`sim.scenario.program` reads back to the same tool path at every programmed point:

* a joint phase: ``J P[n] x% FINE`` to its end, a joint position in the controller's
  convention (:mod:`sim.robots.maker`), ``x`` the phase's largest peak joint speed as a share
  of that joint's limit (rounded up to a whole percent, at least 1); its via knots are not
  written (the program gives the points, the planner joins them);
* a linear or circular phase: ``L P[n] v mm/sec`` or ``C P[via] : P[n] v mm/sec`` per move (a
  polyline seam gives one per segment) to a Cartesian position in user frame 0 (frame 0), tool
  1 (the scenario's tool), with its CONFIG (:func:`sim.scenario.program.config_of`), ``FINE``
  or ``CNTx`` for a blend (``x = 100 r / (0.45 * the shorter move)``, what the import maps
  back); a weave is not written (TP weaving is a controller option cellsim does not read);
* a hold phase: ``WAIT t(sec)``;
* ``arc_on`` / ``arc_off`` actions at phase starts and ends: ``Arc Start[1]`` / ``Arc End[1]``
  (other tool actions are written as comments).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim.errors import CellsimError, ScenarioError
from sim.scenario import Scenario
from sim.scenario.fanuc_ls import LSMotion, LSOther, LSPosition, write_ls
from sim.scenario.model import CartesianPhase, HoldPhase, JointPhase


def export_fanuc_ls(scenario: Scenario) -> tuple[str, list[str]]:
    """The TP program text of ``scenario`` and notes on what it leaves out.

    Raises:
        ScenarioError: A motion the TP form cannot hold (one line).
    """
    from sim.core.rotations import matrix_to_euler_zyx
    from sim.robots.ik import solve_ik
    from sim.robots.maker import to_maker
    from sim.scenario.program import CNT_SHARE, config_of
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion, check_motion_limits

    built = build(scenario)
    motion = build_motion(scenario, built.context)
    check_motion_limits(scenario, motion)
    kin = built.context.kinematics
    robot = scenario.robot
    notes: list[str] = []
    ins: list = [LSOther("uframe", 0), LSOther("utool", 1)]
    positions: dict[int, LSPosition] = {}
    vmax = np.asarray(robot.max_speed, dtype=float)

    def add_pos(**kw) -> int:
        k = len(positions) + 1
        positions[k] = LSPosition(k, 0, 1, **kw)
        return k

    def cart_pos(T: np.ndarray, q_near: np.ndarray, what: str) -> int:
        try:
            sols = [s for s in solve_ik(kin, T, current=q_near) if s.within_limits]
        except CellsimError as exc:
            raise ScenarioError(f"{scenario.source.name}: export: {what}: {exc}") from None
        if not sols:
            raise ScenarioError(f"{scenario.source.name}: export: {what}: no IK solution in the "
                                "joint ranges")
        best = min(sols, key=lambda s: float(np.abs(s.q - q_near).max()))
        a, b, g = (math.degrees(v) for v in matrix_to_euler_zyx(T[:3, :3]))
        x, y, z = (float(v) * 1e3 for v in T[:3, 3])
        return add_pos(xyzwpr=(x, y, z, g, b, a), config=config_of(robot, best.q, best.branch))

    acts = [(t, a) for t, a in motion.actions]
    bounds = [pm.t0 for pm in motion.phases] + [motion.t1]
    for t, a in acts:
        if not any(abs(t - b) < 1e-9 for b in bounds):
            notes.append(f"{a} at {t:.3f} s is not at a phase start or end: not written")
    for pm in motion.phases:
        for t, a in acts:
            if abs(t - pm.t0) >= 1e-9:
                continue
            if a == "arc_on":
                ins.append(LSOther("arc", "start"))
            elif a != "arc_off":
                ins.append(LSOther("comment", f"{a}: not written"))
                notes.append(f"{a}: suction actions are not written")
        ph = pm.phase
        q_end = np.asarray(motion.at(pm.t1).q[0], dtype=float)
        if isinstance(ph, HoldPhase):
            ins.append(LSOther("wait", ph.duration))
        elif isinstance(ph, JointPhase):
            ts = np.linspace(pm.t0, pm.t1, 401)
            peak = np.abs(pm.trajectory.at(ts).qd).max(axis=0)
            pct = float(np.max(peak / vmax)) * 100.0
            if pct > 100.0 + 1e-9:
                notes.append(f"{ph.name}: peak joint speed {pct:.1f} % of the limit written as "
                             "100 %")
            pct = min(100, max(1, math.ceil(pct - 1e-9)))
            k = add_pos(joints_deg=tuple(float(v) for v in np.rad2deg(to_maker(robot, q_end))))
            if ph.blend > 0 or ph.blend_fraction > 0:
                notes.append(f"{ph.name}: its joint blend is written as FINE")
            if len(ph.q) > 3 or (len(ph.q) == 3 and ph.target is None):
                notes.append(f"{ph.name}: its via knots are not written (J to the end point)")
            ins.append(LSMotion("J", ("P", k), float(pct), "%", None, line=0))
        elif isinstance(ph, CartesianPhase):
            if ph.weave is not None:
                notes.append(f"{ph.name}: its weave is not written")
            q_near = np.asarray(motion.at(pm.t0).q[0], dtype=float)
            for j, mv in enumerate(pm.programmed):
                k = cart_pos(mv.end, q_end if mv.blend == 0 else q_near, f"{ph.name} end")
                cnt = None
                if mv.blend > 0:
                    share = mv.blend / (CNT_SHARE * min(mv.length, mv.next_length))
                    cnt = int(min(100, max(1, round(100 * share))))
                speed = round(mv.speed * 1e3, 3)
                if mv.kind == "circular":
                    kv = cart_pos(mv.via, q_near, f"{ph.name} via")
                    ins.append(LSMotion("C", ("P", k), speed, "mm/sec", cnt, via=("P", kv)))
                else:
                    ins.append(LSMotion("L", ("P", k), speed, "mm/sec", cnt))
        for t, a in acts:
            if abs(t - pm.t1) < 1e-9 and a == "arc_off":
                ins.append(LSOther("arc", "end"))
    name = "".join(c if c.isalnum() else "_" for c in scenario.name)[:36] or "PROG"
    return write_ls(name, ins, positions, comment=scenario.name), notes


def write_program(scenario: Scenario, out: str | Path) -> list[str]:
    """Write the TP program of ``scenario`` to ``out`` (refusing to replace an existing file),
    atomically. Returns the notes.

    Raises:
        ScenarioError: ``out`` exists, or its folder does not.
    """
    import os
    import tempfile

    out = Path(out)
    if out.exists():
        raise ScenarioError(f"{out}: exists; cellsim does not overwrite files it did not write "
                            "(choose another --out)")
    if not out.parent.is_dir():
        raise ScenarioError(f"{out.parent}: no such folder")
    text, notes = export_fanuc_ls(scenario)
    fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=f".{out.name}.", suffix=".tmp")
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(text)
    try:
        os.link(tmp, out)  # fails if out appeared meanwhile: never replaced
    except FileExistsError:
        os.unlink(tmp)
        raise ScenarioError(f"{out}: exists; cellsim does not overwrite files it did not "
                            "write") from None
    except OSError:
        os.replace(tmp, out)
    else:
        os.unlink(tmp)
    return notes


__all__ = ["export_fanuc_ls", "write_program"]
