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
  back);
* a weave (``sine`` or ``circle``) of a linear or circular phase: ``Weave Sine[n]`` (``Weave
  Circle[n]``) before its moves and ``Weave End[n]`` after them, ``n`` a schedule of the weave
  table written beside the program (``prog.weave.toml``,
  :func:`sim.scenario.fanuc_ls.weave_table_path`), one schedule per distinct weave. A zigzag
  or triangle weave has no TP pattern and is not written; a weave over a polyline seam's
  several moves runs back on each move on its own (a note says so for both);
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
from sim.scenario.fanuc_ls import (
    LSMotion,
    LSOther,
    LSPosition,
    LSWeave,
    WeaveSchedule,
    weave_table_path,
    write_ls,
    write_weave_schedules,
)
from sim.scenario.model import CartesianPhase, HoldPhase, JointPhase


def export_fanuc_ls(scenario: Scenario) -> tuple[str, list[str], str | None]:
    """The TP program text of ``scenario``, notes on what it leaves out, and the text of its
    weave table (None when no phase weaves).

    Raises:
        ScenarioError: A motion the TP form cannot hold (one line).
    """
    from sim.core.rotations import matrix_to_euler_zyx
    from sim.robots.kinematics.ik import solve_ik
    from sim.robots.maker import to_maker
    from sim.scenario.program import CNT_SHARE, TP_WEAVE_PATTERNS, config_of
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

    schedules: dict[int, WeaveSchedule] = {}
    tp_pattern = {v: k for k, v in TP_WEAVE_PATTERNS.items()}

    def schedule_of(weave) -> int:
        """The number of the weave's schedule (a new one for a weave not yet written)."""
        sch = WeaveSchedule(weave.frequency, weave.amplitude * 1e3, weave.dwell, weave.dwell)
        for k, other in schedules.items():
            if other == sch:
                return k
        schedules[len(schedules) + 1] = sch
        return len(schedules)

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
            k_weave = None
            if ph.weave is not None and ph.weave.pattern not in tp_pattern:
                notes.append(f"{ph.name}: its {ph.weave.pattern} weave has no TP weave pattern "
                             f"({', '.join(TP_WEAVE_PATTERNS)}): not written")
            elif ph.weave is not None:
                k_weave = schedule_of(ph.weave)
                ins.append(LSOther("weave", LSWeave(tp_pattern[ph.weave.pattern], k_weave)))
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
            if k_weave is not None:
                ins.append(LSOther("weave_end", k_weave))
        for t, a in acts:
            if abs(t - pm.t1) < 1e-9 and a == "arc_off":
                ins.append(LSOther("arc", "end"))
    name = "".join(c if c.isalnum() else "_" for c in scenario.name)[:36] or "PROG"
    table = write_weave_schedules(schedules, name.upper()) if schedules else None
    return write_ls(name, ins, positions, comment=scenario.name), notes, table


def write_program(scenario: Scenario, out: str | Path) -> tuple[list[str], list[Path]]:
    """Write the TP program of ``scenario`` to ``out``, and its weave table beside it when a
    phase weaves (:func:`sim.scenario.fanuc_ls.weave_table_path`), each atomically, refusing
    to replace an existing file. Returns the notes and the files written.

    Raises:
        ScenarioError: ``out`` or its weave table exists, or the folder does not.
    """
    def refuse_existing(path: Path) -> None:
        if path.exists():
            raise ScenarioError(f"{path}: exists; cellsim does not overwrite files it did not "
                                "write (choose another --out)")

    out = Path(out)
    refuse_existing(out)
    if not out.parent.is_dir():
        raise ScenarioError(f"{out.parent}: no such folder")
    text, notes, table = export_fanuc_ls(scenario)
    if table is None:
        _write_new(out, text)
        return notes, [out]
    table_path = weave_table_path(out)
    refuse_existing(table_path)
    _write_new(table_path, table)  # the table first: the program never runs without it
    try:
        _write_new(out, text)
    except ScenarioError:
        table_path.unlink()
        raise
    return notes, [out, table_path]


def _write_new(path: Path, text: str) -> None:
    """Write ``text`` to a new file ``path`` atomically (a temporary file linked into place);
    a file that appeared there meanwhile is never replaced."""
    import os
    import tempfile

    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(text)
    try:
        os.link(tmp, path)  # fails if path appeared meanwhile: never replaced
    except FileExistsError:
        os.unlink(tmp)
        raise ScenarioError(f"{path}: exists; cellsim does not overwrite files it did not "
                            "write") from None
    except OSError:
        os.replace(tmp, path)
    else:
        os.unlink(tmp)


__all__ = ["export_fanuc_ls", "write_program"]
