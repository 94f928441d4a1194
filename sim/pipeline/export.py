"""``cellsim export``: a scenario's motion as a FANUC TP program (``.ls``).

The scenario is planned as for a run (no simulation), and each phase becomes TP instructions
that :mod:`sim.scenario.program` reads back to the same tool path at every programmed point:

* a joint phase that does not move (a hold where a program must start with a move):
  ``J P[n] t sec FINE`` to where it is, ``t`` its duration;
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

In a cell with external axes (positioners, tracks) every position holds the axes' values where
it is, as GP1's extended axes ``E1 .. En`` in the cell's axis order (``deg`` on a revolute
axis, ``mm`` on a prismatic one: what :mod:`sim.scenario.program` maps back). A joint phase's
``J`` carries its end values. A Cartesian phase whose axes move (a coordinated weld:
``downhand``, ``follow``; a move with ``axes``) is written as ``COORD`` moves in a user frame of
the part (the seam's object, or the phase's frame object), ``UFRAME_NUM = k`` before them and
``UFRAME_NUM = 0`` after: the phase sampled into pieces (:func:`coordinated_pieces`), each an
``L`` (a line) or ``C`` (an arc, through its middle) ``FINE`` to the pose the planned motion has
relative to the part there, with the axes' values there. Relative to the part, a piece's path is
the original's (a line or arc of the part frame) and its orientation turns evenly; the axes go
linearly in the path between the pieces' ends, so a piece is split until the original axes'
law deviates from that by at most :data:`LAW_TOL_RAD` / :data:`LAW_TOL_M` and its orientation
from the even turn by at most :data:`TURN_TOL_DEG` (an arc's pieces span at most
:data:`MAX_PIECE_DEG`). The user frames' cell objects are a note (``program_frames = { "1" =
"head" }``: the scenario that runs the program gives it) and a comment in the program.

In a cell with other robots (a cell file's ``[[robots]]``) each one with work (``[robots.<name>]``
phases or program) gets a program of its own, written the same way from its own planned motion
(:attr:`sim.simulation.motion.Motion.lanes`): its positions in its own frame 0 (its user frame 0:
its base) and joints, its own tool (tool 1), no extended axes (the cell's axes move with the
first robot). It goes beside the first robot's (:func:`program_path`: ``prog.ls`` ->
``prog_r2.ls``; its weave table ``prog_r2.weave.toml``), and its notes start with
``robots.<name>:``; ``[robots.<name>] program = "prog_<name>.ls"`` runs it back. Each program
starts where its robot is at the cycle's start (its home in the cell), all at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

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

if TYPE_CHECKING:
    from planners.weave import Weave
    from sim.cells.spec import Cell
    from sim.simulation.motion.context import CartesianContext
    from sim.simulation.motion.timeline import Motion, PhaseMotion

#: The axes' law of a coordinated phase may deviate this far from linear in the path within a
#: written piece, rad (revolute) and m (prismatic).
LAW_TOL_RAD = np.radians(0.05)
LAW_TOL_M = 0.05e-3
#: Its orientation relative to the part may deviate this far from an even turn, deg.
TURN_TOL_DEG = 0.1
#: An arc's pieces span at most this much of it, deg.
MAX_PIECE_DEG = 30.0
#: Most pieces a coordinated phase is written in.
MAX_PIECES = 256


@dataclass(frozen=True)
class RobotProgram:
    """One robot's exported TP program.

    Attributes:
        robot: The robot's name in the cell: None for the first robot (the scenario's
            ``robot``), else one of the cell's other robots (``[robots.<name>]``).
        text: The program (``.ls``).
        notes: What it leaves out, and what the scenario that runs it back must give.
        table: Its weave table's text, or None when no phase weaves.
    """

    robot: str | None
    text: str
    notes: list[str]
    table: str | None


def export_fanuc_ls(scenario: Scenario) -> tuple[str, list[str], str | None]:
    """The TP program text of ``scenario``'s first robot, notes on what it leaves out, and the
    text of its weave table (None when no phase weaves); the cell's other robots' programs:
    :func:`export_programs`.

    Raises:
        ScenarioError: A motion the TP form cannot hold (one line).
    """
    first = export_programs(scenario)[0]
    return first.text, first.notes, first.table


def export_programs(scenario: Scenario) -> list[RobotProgram]:
    """The TP program of each robot of ``scenario``: the first robot's, then each of the
    cell's other robots' that has work (``[robots.<name>]`` phases or program), in the cell's
    order; each written in its own robot's frame 0 (its user frame 0) and joints, from the
    motion planned for the run. One without work stays home and has no program.

    Raises:
        ScenarioError: A motion the TP form cannot hold (one line).
    """
    from sim.simulation.compile import build
    from sim.simulation.motion import build_motion, check_motion_limits
    from sim.simulation.motion.timeline import Motion

    built = build(scenario)
    motion = build_motion(scenario, built.context)
    check_motion_limits(scenario, motion)
    lead = Motion(phases=motion.phases, actions=motion.actions, n_joints=motion.n_lead)
    base = _program_name(scenario.name)
    out = [RobotProgram(None, *_export_robot(
        scenario, scenario, lead, built.context, built.cell, base))]
    lanes = dict(motion.lanes)
    for work in scenario.partners:
        if not work.phases:
            continue
        suffix = f"_{_program_name(work.name)}"
        text, notes, table = _export_robot(
            scenario, scenario.partner_scenario(work), lanes[work.name],
            built.context.partners[work.name], built.cell,
            base[:max(1, 36 - len(suffix))] + suffix, f"robots.{work.name}: ")
        out.append(RobotProgram(work.name, text, notes, table))
    return out


def _program_name(name: str) -> str:
    """A program name from a scenario's or robot's name (letters, digits, ``_``; 36 at
    most)."""
    return "".join(c if c.isalnum() else "_" for c in name)[:36] or "PROG"


def _export_robot(scenario: Scenario, work: Scenario, motion: Motion, ctx: CartesianContext,
                  cell: Cell, name: str, what_prefix: str = ""
                  ) -> tuple[str, list[str], str | None]:
    """One robot's program: ``work`` its scenario (the scenario itself for the first robot,
    :meth:`Scenario.partner_scenario` for another), ``motion`` its planned motion alone (its
    joints, then the cell's axes for the first robot), ``ctx`` its planning context; its
    text, notes and weave table (:func:`export_fanuc_ls`). ``what_prefix`` starts its error
    messages' subject (``robots.r2: ``)."""
    from sim.core.rotations import matrix_to_euler_zyx
    from sim.robots.kinematics.ik import solve_ik
    from sim.robots.maker import to_maker
    from sim.scenario.program import CNT_SHARE, TP_WEAVE_PATTERNS, config_of

    kin = ctx.kinematics
    robot = work.robot
    n = robot.n_joints
    notes: list[str] = []
    ins: list = [LSOther("uframe", 0), LSOther("utool", 1)]
    positions: dict[int, LSPosition] = {}
    vmax = np.asarray(work.system.max_speed, dtype=float)[:motion.n_joints]  # and the axes
    units = tuple("deg" if a.kind == "revolute" else "mm"
                  for pm in ctx.mechanisms for a in pm.spec.axes)
    user_frames: dict[str, int] = {}  # cell object -> its user frame number

    schedules: dict[int, WeaveSchedule] = {}
    tp_pattern = {v: k for k, v in TP_WEAVE_PATTERNS.items()}

    def schedule_of(weave: Weave) -> int:
        """The number of the weave's schedule (a new one for a weave not yet written)."""
        sch = WeaveSchedule(weave.frequency, weave.amplitude * 1e3, weave.dwell, weave.dwell)
        for k, other in schedules.items():
            if other == sch:
                return k
        schedules[len(schedules) + 1] = sch
        return len(schedules)

    def add_pos(qe: np.ndarray, uf: int = 0, **kw: Any) -> int:
        k = len(positions) + 1
        positions[k] = LSPosition(k, uf, 1, ext=tuple(float(v) for v in qe), ext_units=units,
                                  **kw)
        return k

    def cart_pos(T: np.ndarray, q_near: np.ndarray, what: str, qe: np.ndarray, uf: int = 0,
                 T_written: np.ndarray | None = None) -> int:
        """A Cartesian position: ``T`` the tool in frame 0 (its CONFIG), written as
        ``T_written`` (in user frame ``uf``) when given."""
        try:
            sols = [s for s in solve_ik(kin, T, current=q_near) if s.within_limits]
        except CellsimError as exc:
            raise ScenarioError(f"{scenario.source.name}: export: {what_prefix}{what}: "
                                f"{exc}") from None
        if not sols:
            raise ScenarioError(f"{scenario.source.name}: export: {what_prefix}{what}: no IK "
                                "solution in the "
                                "joint ranges")
        best = min(sols, key=lambda s: float(np.abs(s.q - q_near).max()))
        W = T if T_written is None else T_written
        a, b, g = (math.degrees(v) for v in matrix_to_euler_zyx(W[:3, :3]))
        x, y, z = (float(v) * 1e3 for v in W[:3, 3])
        return add_pos(qe, uf, xyzwpr=(x, y, z, g, b, a),
                       config=config_of(robot, best.q, best.branch))

    def coordinated(pm: PhaseMotion, ph: CartesianPhase) -> None:
        """A phase whose axes move, as COORD moves in its part's user frame (module
        docstring)."""
        part = _part_of(ph, cell, ctx)
        if part is None:
            raise ScenarioError(f"{scenario.source.name}: export: {what_prefix}{ph.name}: its "
                                "axes move, "
                                "but its points are in no cell object's frame (a COORD move's "
                                "user frame)")
        uf = user_frames.setdefault(part, len(user_frames) + 1)
        ins.append(LSOther("uframe", uf))
        pieces = coordinated_pieces(motion, pm, ctx, part)
        if len(pieces) > 1:
            notes.append(f"{ph.name}: written as {len(pieces)} COORD moves (FINE) in user frame "
                         f"{uf} ({part})")
        speed = round(pm.cartesian.speed * 1e3, 3)
        for t_mid, t_end in pieces:
            ks = []
            for t in ((t_mid, t_end) if ph.kind == "circular" else (t_end,)):
                q = np.asarray(motion.at(t).q[0], dtype=float)
                T0 = np.asarray(kin.fk(q[:n]), dtype=float)
                ks.append(cart_pos(T0, q[:n], f"{ph.name} at {t:.3f} s", q[n:], uf,
                                   part_pose(ctx, part, q[n:], T0)))
            if ph.kind == "circular":
                ins.append(LSMotion("C", ("P", ks[1]), speed, "mm/sec", None, via=("P", ks[0]),
                                    options=("COORD",)))
            else:
                ins.append(LSMotion("L", ("P", ks[0]), speed, "mm/sec", None,
                                    options=("COORD",)))
        ins.append(LSOther("uframe", 0))

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
        elif isinstance(ph, JointPhase) and _still(pm):
            # a joint phase that does not move (a hold at the start, where a program must
            # begin with a move; a robot's wait for another's): J to where it is, in its time
            k = add_pos(q_end[n:], joints_deg=tuple(
                float(v) for v in np.rad2deg(to_maker(robot, q_end[:n]))))
            ins.append(LSMotion("J", ("P", k), float(f"{pm.t1 - pm.t0:.6g}"), "sec", None,
                                line=0))
        elif isinstance(ph, JointPhase):
            ts = np.linspace(pm.t0, pm.t1, 401)
            peak = np.abs(pm.trajectory.at(ts).qd).max(axis=0)
            pct = float(np.max(peak / vmax)) * 100.0
            if pct > 100.0 + 1e-9:
                notes.append(f"{ph.name}: peak joint speed {pct:.1f} % of the limit written as "
                             "100 %")
            pct = min(100, max(1, math.ceil(pct - 1e-9)))
            k = add_pos(q_end[n:], joints_deg=tuple(
                float(v) for v in np.rad2deg(to_maker(robot, q_end[:n]))))
            if ph.blend > 0 or ph.blend_fraction > 0:
                notes.append(f"{ph.name}: its joint blend is written as FINE")
            if len(ph.q) > 3 or (len(ph.q) == 3 and ph.target is None):
                notes.append(f"{ph.name}: its via knots are not written (J to the end point)")
            ins.append(LSMotion("J", ("P", k), float(pct), "%", None, line=0))
        elif isinstance(ph, CartesianPhase) and ctx.mechanisms and _axes_move(motion, pm, n):
            coordinated(pm, ph)
        elif isinstance(ph, CartesianPhase):
            k_weave = None
            if ph.weave is not None and ph.weave.pattern not in tp_pattern:
                notes.append(f"{ph.name}: its {ph.weave.pattern} weave has no TP weave pattern "
                             f"({', '.join(TP_WEAVE_PATTERNS)}): not written")
            elif ph.weave is not None:
                k_weave = schedule_of(ph.weave)
                ins.append(LSOther("weave", LSWeave(tp_pattern[ph.weave.pattern], k_weave)))
            q_near = np.asarray(motion.at(pm.t0).q[0], dtype=float)[:n]
            for mv in pm.programmed:
                k = cart_pos(mv.end, q_end[:n] if mv.blend == 0 else q_near, f"{ph.name} end",
                             q_end[n:])
                cnt = None
                if mv.blend > 0:
                    share = mv.blend / (CNT_SHARE * min(mv.length, mv.next_length))
                    cnt = int(min(100, max(1, round(100 * share))))
                speed = round(mv.speed * 1e3, 3)
                if mv.kind == "circular":
                    kv = cart_pos(mv.via, q_near, f"{ph.name} via", q_end[n:])
                    ins.append(LSMotion("C", ("P", k), speed, "mm/sec", cnt, via=("P", kv)))
                else:
                    ins.append(LSMotion("L", ("P", k), speed, "mm/sec", cnt))
            if k_weave is not None:
                ins.append(LSOther("weave_end", k_weave))
        for t, a in acts:
            if abs(t - pm.t1) < 1e-9 and a == "arc_off":
                ins.append(LSOther("arc", "end"))
    if user_frames:
        frames = ", ".join(f'"{k}" = "{obj}"' for obj, k in user_frames.items())
        notes.append(f"program_frames = {{ {frames} }}: the user frames of the COORD moves; "
                     "give it in the scenario that runs the program")
        ins[0:0] = [LSOther("comment", f"UF {k} = {obj} (program_frames)")
                    for obj, k in user_frames.items()]
    table = write_weave_schedules(schedules, name.upper()) if schedules else None
    return write_ls(name, ins, positions, comment=work.name), notes, table


#: A joint phase whose joints (and axes) stay within this of where it starts, rad (m), is a
#: hold: exported as ``J P[n] t sec`` to where it is.
STILL_TOL = 1e-9


def _still(pm: PhaseMotion) -> bool:
    """Whether a joint phase's robot joints and axes stay where the phase starts (sampled at
    401 instants, within :data:`STILL_TOL`)."""
    q = np.asarray(pm.trajectory.at(np.linspace(pm.t0, pm.t1, 401)).q, dtype=float)
    return bool(np.max(np.abs(q - q[0])) <= STILL_TOL)


def _axes_move(motion: Motion, pm: PhaseMotion, n: int) -> bool:
    """Whether the external axes move during planned phase ``pm``."""
    ts = np.linspace(pm.t0, pm.t1, 65)
    qe = np.asarray(motion.at(ts).q, dtype=float)[:, n:]
    return bool(qe.size) and float(np.ptp(qe, axis=0).max()) > 1e-9


def _part_of(ph: CartesianPhase, cell: Cell, ctx: CartesianContext) -> str | None:
    """The cell object a coordinated phase's points are relative to: its seam's object, or its
    frame when that is a cell object; None otherwise."""
    if ph.seam is not None:
        objs = cell.seam_objects.get(ph.seam, ())
        if objs and objs[0] in ctx.frames:
            return objs[0]
    return ph.frame if ph.frame in ctx.frames else None


def part_pose(ctx: CartesianContext, part: str, qe: np.ndarray, T0: np.ndarray) -> np.ndarray:
    """A tool pose ``T0`` in frame 0 (the robot's, carried by its track at axes ``qe``) in the
    frame of cell object ``part`` (carried by its mechanism at ``qe``), (4, 4)."""
    from sim.simulation.motion.axes import displacement, world_from_frame0

    F = displacement(ctx, ctx.frame_mechanism.get(part), qe) @ ctx.frames[part]
    return np.linalg.inv(F) @ world_from_frame0(ctx, qe) @ T0


def coordinated_pieces(motion: Motion, pm: PhaseMotion, ctx: CartesianContext, part: str
                       ) -> list[tuple[float, float]]:
    """The pieces a coordinated phase (``pm`` of ``motion``) is written in, relative to cell
    object ``part``: ``(t_mid, t_end)`` for each, the times at the middle of its path and at
    its end (module docstring)."""
    from scipy.spatial.transform import Rotation, Slerp

    kin = ctx.kinematics
    n = kin.n_joints
    cart = pm.cartesian
    tau = np.linspace(0.0, cart.duration, 4001)
    s_of = np.asarray(cart.at(tau).path_length, dtype=float)
    length = float(s_of[-1])

    def t_at(s: float) -> float:
        return pm.t0 + float(np.interp(s, s_of, tau))

    kinds = [a.kind for m in ctx.mechanisms for a in m.spec.axes]
    tol = np.array([LAW_TOL_RAD if k == "revolute" else LAW_TOL_M for k in kinds])

    def state(s: float) -> tuple[np.ndarray, np.ndarray]:
        q = np.asarray(motion.at(t_at(s)).q[0], dtype=float)
        T0 = np.asarray(kin.fk(q[:n]), dtype=float)
        return q[n:], part_pose(ctx, part, q[n:], T0)[:3, :3]

    def fine(sa: float, sb: float) -> bool:
        qa, Ra = state(sa)
        qb, Rb = state(sb)
        turn = Slerp([0.0, 1.0], Rotation.from_matrix([Ra, Rb]))
        for u in (0.25, 0.5, 0.75):
            qe, R = state(sa + u * (sb - sa))
            if np.any(np.abs(qe - (qa + u * (qb - qa))) > tol):
                return False
            off = (turn([u]).inv() * Rotation.from_matrix(R)).magnitude()[0]
            if np.degrees(off) > TURN_TOL_DEG:
                return False
        return True

    sweep = float(getattr(cart.path, "sweep", 0.0)) if pm.phase.kind == "circular" else 0.0
    first = max(1, int(np.ceil(np.degrees(sweep) / MAX_PIECE_DEG - 1e-9)))
    todo = [(length * k / first, length * (k + 1) / first) for k in range(first)]
    done: list[tuple[float, float]] = []
    while todo:
        sa, sb = todo.pop(0)
        if len(done) + len(todo) + 1 < MAX_PIECES and not fine(sa, sb):
            todo[0:0] = [(sa, 0.5 * (sa + sb)), (0.5 * (sa + sb), sb)]
        else:
            done.append((sa, sb))
    return [(t_at(0.5 * (sa + sb)), t_at(sb) if sb < length else pm.t1) for sa, sb in done]


def program_path(out: str | Path, robot: str | None) -> Path:
    """Where the program of ``robot`` goes when the first robot's goes to ``out``: ``out``
    itself for the first robot (None), ``prog_<name>.ls`` beside it for another."""
    out = Path(out)
    return out if robot is None else out.with_name(f"{out.stem}_{robot}{out.suffix}")


def write_program(scenario: Scenario, out: str | Path) -> tuple[list[str], list[Path]]:
    """Write the TP program of ``scenario``'s first robot to ``out``, each other robot's with
    work beside it (:func:`program_path`: ``prog_r2.ls``), and each program's weave table
    beside it when one of its phases weaves (:func:`sim.scenario.fanuc_ls.weave_table_path`),
    each atomically, refusing to replace an existing file (none is written when one of them
    exists). Returns the notes (another robot's start with ``robots.<name>: ``) and the files
    written.

    Raises:
        ScenarioError: ``out``, another robot's program or a weave table exists, or the folder
            does not.
    """
    def refuse_existing(path: Path) -> None:
        if path.is_dir():
            raise ScenarioError(f"{path}: is a folder; --out names the .ls file to write")
        if path.exists() or path.is_symlink():
            raise ScenarioError(f"{path}: exists; cellsim export never replaces a file "
                                "(choose another --out, or remove it)")

    out = Path(out)
    refuse_existing(out)
    if not out.parent.is_dir():
        raise ScenarioError(f"{out.parent}: no such folder")
    for work in scenario.partners:  # before the planning: the other programs' places too
        if work.phases:
            refuse_existing(program_path(out, work.name))
    programs = export_programs(scenario)
    files: list[tuple[Path, str]] = []  # (path, text): the tables first, each before its program
    notes: list[str] = []
    paths, tables = [], []
    for prog in programs:
        path = program_path(out, prog.robot)
        if prog.table is not None:
            files.append((weave_table_path(path), prog.table))
            tables.append(weave_table_path(path))
        files.append((path, prog.text))
        paths.append(path)
        if prog.robot is None:
            notes += prog.notes
            continue
        notes += [f"robots.{prog.robot}: {n}" for n in prog.notes]
        notes.append(f"robots.{prog.robot}: {path.name}: run it back with [robots.{prog.robot}] "
                     f'program = "{path.name}" in the scenario')
    for path, _ in files:
        refuse_existing(path)
    written: list[Path] = []
    try:
        for path, text in files:  # a table first: its program never runs without it
            _write_new(path, text)
            written.append(path)
    except ScenarioError:
        for path in written:
            path.unlink()
        raise
    return notes, paths + tables


def _write_new(path: Path, text: str) -> None:
    """Write ``text`` to a new file ``path`` atomically (a temporary file linked into place);
    a file that appeared there meanwhile is never replaced."""
    import os
    import tempfile

    from sim.core.files import new_file_mode

    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(text)
    os.chmod(tmp, new_file_mode())  # the umask's mode, not mkstemp's 0o600
    try:
        os.link(tmp, path)  # fails if path appeared meanwhile: never replaced
    except FileExistsError:
        os.unlink(tmp)
        raise ScenarioError(f"{path}: exists; cellsim export never replaces a file "
                            "(choose another --out, or remove it)") from None
    except OSError:
        os.replace(tmp, path)
    else:
        os.unlink(tmp)


__all__ = ["LAW_TOL_M", "LAW_TOL_RAD", "MAX_PIECES", "MAX_PIECE_DEG", "TURN_TOL_DEG",
           "RobotProgram", "coordinated_pieces", "export_fanuc_ls", "export_programs",
           "part_pose", "program_path", "write_program"]
