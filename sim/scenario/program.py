"""A FANUC TP program (:mod:`sim.scenario.fanuc_ls`) as scenario phases and tool actions.

``program = "weld1.ls"`` in a scenario (instead of ``phases``) runs the program from the robot's
``home`` keyframe:

* ``J P[n] x%``: a joint phase to the position, timed as the controller does: the joint whose
  move takes longest at ``x %`` of its speed limit sets the duration (the phase's peak speed
  on that joint is ``x %`` of its limit; the scenario's 4-3-4 polynomial joins the points). A
  Cartesian position is solved by inverse kinematics on the branch its ``CONFIG`` names; a joint
  position is in the controller's joint convention (the robot's maker map,
  :mod:`sim.robots.maker`). ``sec`` instead of ``%``: the move's time.
* ``L P[n] v mm/sec`` (or ``cm/min``, ``inch/min``; ``sec``: the move's time, its ramps
  included; ``WELD_SPEED``: the scenario's ``program_weld_speed_mm_s``): a linear phase at that
  speed, the orientation turned evenly (in proportion to the path) from the start's to the
  position's; where a CNT rounds the corner into the next move the two moves' turns are
  blended (each carried on at its rate, :class:`planners.blend.CornerOrientation`), so the
  wrist's speed does not jump there, and a corner whose joints would pass their limits at the
  programmed speed is slowed inside its rounding only.
* ``C P[via] : P[end] v``: a circular phase through the via point.
* ``FINE``: the move ends at rest on the point. ``CNTx``: the move blends into the next move of
  the same kind without stopping: for L and C moves a corner zone of radius
  ``x / 100 * 0.45 * the shorter of the two moves`` (``blend_mm``), for J moves the joint blend
  with ``blend_deg = x / 100 * half the shorter chord``; a CNT between a J and an L or C move
  runs as FINE (a warning says so).
* ``Arc Start[..]`` / ``Arc End[..]``: the arc on or off there: on at the start of the next
  motion, off at the end of the motion before (as a motion option: when that motion reaches
  its point).
* ``UFRAME_NUM = n``: the user frame of the following positions: 0 is the robot's world frame
  (FANUC's world frame is cellsim's frame 0); others through the scenario's
  ``program_frames = { "1" = "<cell object>" }``. ``UTOOL_NUM = n``: 0 the flange, 1 the
  scenario's tool. A position taught in another frame or tool than the program's current ones
  is an error, as on the controller.
* ``PR[n]``: from the scenario's ``program_registers = { "1" = [X, Y, Z, W, P, R] }`` (mm,
  deg; configuration ``N U T, 0, 0, 0``).
* ``WAIT x(sec)``: a hold phase.
* ``Weave Sine[n]`` / ``Weave Circle[n]`` ... ``Weave End``: the L and C moves between them
  weave (:class:`planners.weave.Weave`, ``"sine"`` / ``"circle"``) with schedule ``n`` of the
  program's weave table (``prog.weave.toml``, :func:`sim.scenario.fanuc_ls.weave_table_path`) or
  the values written in the instruction. Moves that blend into each other (CNT) carry the
  weave on without a break (one cycle clock, no fade where they join); it fades in where
  the weaving starts and out where it stops or the robot stops (FINE), over the ramps or
  half a cycle, as a scenario phase's does. The left and right dwells must be equal
  (cellsim's weave holds one dwell at both extremes). J moves in between do not weave, and the
  other patterns (``Figure 8``, ``Sine 2``, ``L``) are not run; a warning says so.

Extended axes (``E1= ..`` after GP1's values, a ``GP2:`` group's ``J1= ..``): a program's
extended values -- GP1's ``E1 .. En``, then each further group's ``J1 .. Jk`` (and its own
``E1 ..``) -- map in that order onto the cell's external axes (its mechanisms' axes in cell
order, ``Cell.axis_names``), each in ``deg`` on a revolute axis and ``mm`` on a prismatic one
(:func:`sim.scenario.fanuc_pos.extended_values`). A position without any leaves the axes where
they are. A position with another count than the cell has axes, a unit that does not fit its
axis's kind, a value outside the axis's range, a Cartesian group (a second robot), or extended
values in a cell without mechanisms is one line naming the program file and the position's
line.

* ``J``: the axes move to the position's values with the robot (``JointPhase.axes``).
* ``L`` / ``C``: values equal to where the axes are (within 1e-9) move nothing; other values
  move the axes only with ``COORD`` (a coordinated move, ``CartesianPhase.axes``: the axes go
  to the values in proportion to the path, the points and orientation relative to the user
  frame the program runs, :func:`sim.simulation.motion.axes.plan_coordinated`); that frame is
  a cell object (``program_frames``) carried by a mechanism that moves, or, where the robot
  stands on a track that moves, any cell object. Without ``COORD`` it is one line ("an L move
  that moves external axes needs COORD").
* CNT does not blend in a cell with external axes where axes move: a J move's CNT, and a CNT on
  or into an L or C move that moves axes, run as FINE (a warning says so).

CONFIG: ``N``/``F`` the sign of the controller's J5 (``F``: J5 < 0), ``U``/``D`` the elbow up
or down, ``T``/``B`` the wrist centre in front of J1 or behind (the branch labels of
:mod:`sim.robots.kinematics.ik`), and the turn numbers of J4, J5, J6 (the controller's joint
value is its value in (-180, 180] deg plus 360 deg times the turn number).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from sim.core.rotations import euler_zyx_to_matrix
from sim.errors import PlannerError, ScenarioError
from sim.scenario.fanuc_ls import (
    LSMotion,
    LSOther,
    LSPosition,
    LSProgram,
    LSWeave,
    weave_table_path,
)
from sim.scenario.fanuc_pos import AXIS_KIND, cartesian_group, extended_values, from_si
from sim.scenario.model import Action, CartesianPhase, HoldPhase, JointPhase, PoseTarget

#: Speed units of L and C moves in m/s per unit.
SPEED_UNITS = {"mm/sec": 1e-3, "cm/min": 1e-2 / 60.0, "inch/min": 0.0254 / 60.0}
#: CNT100 blends over this share of the shorter of the two moves.
CNT_SHARE = 0.45
#: ArcTool weave patterns cellsim runs, as the TP instruction writes them -> cellsim's pattern.
TP_WEAVE_PATTERNS = {"Sine": "sine", "Circle": "circle"}
#: Extended values this close to the axes' values (rad or m) move nothing.
AXES_EQUAL = 1e-9
#: The unit a program writes an axis of each kind in.
KIND_UNIT = {kind: unit for unit, kind in AXIS_KIND.items()}


def home_keyframe(robot) -> NDArray[np.float64]:
    """The robot's ``home`` keyframe (its MJCF), rad, (n,)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(robot.robot_path).getroot()
    for key in root.iter("key"):
        if key.get("name") == "home":
            return np.array([float(v) for v in key.get("qpos").split()][:robot.n_joints])
    return np.zeros(robot.n_joints)


def rotation_wpr(w: float, p: float, r: float) -> NDArray[np.float64]:
    """FANUC's W, P, R (deg): ``Rz(R) Ry(P) Rx(W)``."""
    return euler_zyx_to_matrix(*np.deg2rad([r, p, w]))


def program_phases(prog: LSProgram, robot, start_q: NDArray[np.float64],
                   frames: dict[int, str], registers: dict[int, LSPosition], where: str,
                   has_tool: bool, weld_speed: float | None = None,
                   mechanisms: tuple = (), no_axes: str | None = None
                   ) -> tuple[list, list[Action], list[str]]:
    """The phases, tool actions and warnings of a TP program (module docstring);
    ``mechanisms``: the cell's (:class:`sim.cells.mechanisms.PlacedMechanism`, in cell order),
    whose axes the program's extended values drive, starting at their home. ``no_axes``: why
    the program drives no axes where that is not for want of mechanisms (a cell's other robot:
    its program's positions hold no extended values), said where a position has some.

    Raises:
        ScenarioError: One line naming the program file and line.
    """
    from sim.robots.maker import from_maker

    src = prog.path.name if prog.path is not None else "<program>"
    phases: list = []
    actions: list[Action] = []
    warnings = [f"{src}: line {ln}: {text}" for ln, text in prog.warnings]
    uf, ut = 0, 1
    n = robot.n_joints
    pending_start = False  # an Arc Start instruction waits for the next motion
    weave = None  # the weave of the L and C moves, between Weave <pattern>[..] and Weave End

    def err(line: int, text: str) -> ScenarioError:
        return ScenarioError(f"{where}: program: {src}: line {line}: {text}")

    def position(ref: tuple[str, int], line: int) -> LSPosition:
        kind, k = ref
        if kind == "P":
            if k not in prog.positions:
                raise err(line, f"P[{k}] is not in the /POS section")
            pos = prog.positions[k]
        else:
            if k not in registers:
                raise err(line, f"PR[{k}]: no value; give it in the scenario's "
                          f"program_registers = {{ \"{k}\" = [X, Y, Z, W, P, R] }}")
            pos = registers[k]
            pos = LSPosition(k, uf, ut, pos.xyzwpr, pos.config, pos.joints_deg, line)
        if (pos.uf, pos.ut) != (uf, ut):
            raise err(line, f"{kind}[{k}] was taught with UF {pos.uf}, UT {pos.ut} but the "
                      f"program runs UFRAME_NUM = {uf}, UTOOL_NUM = {ut}")
        return pos

    cell_axes = _CellAxes(mechanisms, no_axes)

    def axes_of(pos: LSPosition) -> dict[str, float]:
        """The position's extended values on the cell's axes (SI), {} when it has none."""
        try:
            return cell_axes.values(pos)
        except ValueError as exc:
            raise err(pos.line, str(exc)) from None

    def frame_name(line: int) -> str:
        if uf == 0:
            return "frame0"
        if uf not in frames:
            raise err(line, f"UFRAME_NUM = {uf}: no frame for it; map it in the scenario "
                      f"(program_frames = {{ \"{uf}\" = \"<cell object>\" }})")
        return frames[uf]

    def cart(pos: LSPosition, line: int) -> tuple[NDArray, NDArray]:
        if pos.xyzwpr is None:
            raise err(line, f"P[{pos.index}] is a joint position; an L or C move needs a "
                      "Cartesian one")
        x, y, z, w, p, r = pos.xyzwpr
        return np.array([x, y, z]) * 1e-3, rotation_wpr(w, p, r)

    def weave_of(w: LSWeave, line: int):
        """The :class:`planners.weave.Weave` of a weave instruction (None: not run)."""
        from planners.weave import Weave

        what = f"Weave {w.pattern}[{w.schedule}]" if w.values is None else f"Weave {w.pattern}"
        if w.pattern not in TP_WEAVE_PATTERNS:
            warnings.append(f"{src}: line {line}: {what}: pattern not simulated (cellsim runs "
                            f"{', '.join(TP_WEAVE_PATTERNS)}); the moves until Weave End do not "
                            "weave")
            return None
        sch = w.values if w.values is not None else prog.weave_schedules.get(w.schedule)
        if sch is None and prog.weave_table is None:
            raise err(line, f"{what}: no weave table {weave_table_path(src).name} next to the "
                      f"program to hold schedule {w.schedule} (docs/scenario-format.md, FANUC "
                      "TP programs)")
        if sch is None:
            have = ", ".join(map(str, sorted(prog.weave_schedules))) or "none"
            raise err(line, f"{what}: no weave schedule {w.schedule} in "
                      f"{prog.weave_table.name} (it has {have})")
        if sch.dwell_left_s != sch.dwell_right_s:
            raise err(line, f"{what}: right dwell {sch.dwell_right_s:g} s and left dwell "
                      f"{sch.dwell_left_s:g} s differ; cellsim's weave holds one dwell at both "
                      "extremes")
        try:
            return Weave(TP_WEAVE_PATTERNS[w.pattern], sch.amplitude_mm * 1e-3,
                         sch.frequency_hz, sch.dwell_right_s)
        except PlannerError as exc:
            raise err(line, f"{what}: {exc}") from None

    motions = [ins for ins in prog.instructions if isinstance(ins, LSMotion)]
    if not motions:
        raise err(1, "no motion instruction")
    index = 0
    lines: dict[int, int] = {}  # phase index -> its motion's line
    coord: set[int] = set()  # the phases of L and C moves that move the axes
    for pos_i, ins in enumerate(prog.instructions):
        if isinstance(ins, LSOther):
            if ins.what == "uframe":
                uf = int(ins.value)
            elif ins.what == "utool":
                ut = int(ins.value)
                if ut > 1:
                    raise err(ins.line, f"UTOOL_NUM = {ut}: cellsim runs UT 0 (the flange) and "
                              "UT 1 (the scenario's tool)")
                if ut == 0 and has_tool:
                    warnings.append(f"{src}: line {ins.line}: UT 0: positions are flange poses")
            elif ins.what == "wait":
                if not phases:
                    raise err(ins.line, "WAIT before the first motion (the program starts "
                              "with a move)")
                if float(ins.value) <= 0.0:  # WAIT 0: nothing to hold
                    continue
                phases.append(HoldPhase(index=index, name=f"line{ins.line:03d}_wait",
                                        duration=float(ins.value),
                                        origin=f"{src}: line {ins.line} (WAIT)"))
                index += 1
                if pending_start:  # the arc starts while the robot waits (a start dwell)
                    actions.append(Action("arc_on", None, phases[-1].name, "start"))
                    pending_start = False
            elif ins.what == "weave":
                weave = weave_of(ins.value, ins.line)
            elif ins.what == "weave_end":
                weave = None
            elif ins.what == "arc":
                if not has_tool:
                    raise err(ins.line, "Arc Start/End needs a torch tool (the scenario's tool)")
                if ins.value == "start":  # on where the robot is: the next motion starts
                    pending_start = True
                else:
                    if not phases:
                        raise err(ins.line, "Arc End before any motion")
                    actions.append(Action("arc_off", None, phases[-1].name, "end"))
            continue
        mo: LSMotion = ins
        name = f"line{mo.line:03d}_{mo.kind}"
        target = position(mo.target, mo.line)
        nxt, waits = None, False
        for m in prog.instructions[pos_i + 1:]:
            if isinstance(m, LSMotion):
                nxt = m
                break
            waits = waits or (m.what == "wait" and float(m.value) > 0)
        cnt = mo.cnt
        if cnt is not None and cnt > 0:
            same = nxt is not None and (nxt.kind == "J") == (mo.kind == "J")
            if nxt is None:
                cnt = None
            elif waits:
                warnings.append(f"{src}: line {mo.line}: CNT{mo.cnt} before a WAIT runs as FINE "
                                "(the robot waits at the point)")
                cnt = None
            elif not same:
                warnings.append(f"{src}: line {mo.line}: CNT{mo.cnt} between a {mo.kind} and "
                                f"a {nxt.kind} move runs as FINE")
                cnt = None
            elif mo.kind == "J" and cell_axes.names:
                warnings.append(f"{src}: line {mo.line}: CNT{mo.cnt} between J moves runs as "
                                "FINE in a cell with external axes")
                cnt = None
        fraction = 0.0 if not cnt else cnt / 100.0
        if mo.kind == "J":
            if weave is not None:
                warnings.append(f"{src}: line {mo.line}: a J move between Weave and Weave End "
                                "does not weave")
            pct = mo.speed / 100.0 if mo.unit == "%" else None
            move_time = mo.speed if mo.unit == "sec" else None
            q = np.full((3, n), np.nan)
            if not phases:
                q[0] = start_q
            times = np.array([0.0, 0.5, 1.0]) if not phases else None
            durations = np.array([0.5, 0.5]) if move_time is None else np.full(2, move_time / 2)
            if target.joints_deg is not None:
                if len(target.joints_deg) != n:
                    raise err(mo.line, f"P[{target.index}] has {len(target.joints_deg)} joint "
                              f"values; robot {robot.name} has {n}")
                q[-1] = from_maker(robot, np.deg2rad(target.joints_deg))
                ptarget = None
            else:
                p, R = cart(target, mo.line)
                ptarget = PoseTarget(position=p, rotation=R, frame=frame_name(mo.line),
                                     config=target.config, flange=ut == 0)
            if times is not None and move_time is not None:
                times = np.array([0.0, move_time / 2, move_time])
            moved = axes_of(target)
            cell_axes.current.update(moved)
            phase = JointPhase(index=index, name=name, planner="434", times=times,
                               durations=durations, q=q, target=ptarget,
                               speed_pct=pct, blend_fraction=fraction, axes=moved,
                               origin=_origin(src, mo))
        else:
            if not phases:
                raise err(mo.line, "the program's first motion must be a J move (it leaves "
                          "the robot's home)")
            p, R = cart(target, mo.line)
            speed, move_time = 1.0, None
            if mo.unit == "sec":
                move_time = mo.speed
            elif mo.unit == "weld":
                if weld_speed is None:
                    raise err(mo.line, "WELD_SPEED: the arc schedule's speed, which the program "
                              "does not hold; give it in the scenario "
                              "(program_weld_speed_mm_s = ...)")
                speed = weld_speed * 1e-3
            else:
                speed = mo.speed * SPEED_UNITS[mo.unit]
            moved = axes_of(target)
            moving = cell_axes.moving(moved)
            if moving and "COORD" not in mo.options:
                first = next(k for k in cell_axes.names if k in moving)
                raise err(mo.line, f"an {mo.kind} move that moves external axes needs COORD "
                          f"(P[{target.index}] moves {first} from "
                          f"{cell_axes.written(first, cell_axes.current[first])} to "
                          f"{cell_axes.written(first, moved[first])})")
            if moving:
                msg = cell_axes.frame_fault(moving, uf, frame_name(mo.line))
                if msg:
                    raise err(mo.line, msg)
                cell_axes.current.update(moved)
                coord.add(index)
            common = dict(index=index, name=name, kind="linear" if mo.kind == "L" else "circular",
                          planner="434", speed=speed, sample_period=0.1, ramp=None,
                          orientation="euler", to=p, frame=frame_name(mo.line),
                          euler_zyx=_zyx(R), blend_fraction=fraction, move_time=move_time,
                          flange=ut == 0, weave=weave, config=target.config,
                          axes=moved if moving else {}, origin=_origin(src, mo))
            if mo.kind == "C":
                via = position(mo.via, mo.line)
                axes_of(via)  # checked; the axes follow the path to the end point
                pv, Rv = cart(via, mo.line)
                prev_end = _last_point(phases)
                if prev_end is not None and np.linalg.norm(prev_end - p) < 1e-3:
                    raise err(mo.line, "a C move ends where it starts (a full circle): split it "
                              "into two C moves")
                phase = CartesianPhase(**common, via=pv, via_euler_zyx=_zyx(Rv))
            else:
                phase = CartesianPhase(**common)
        phases.append(phase)
        lines[index] = mo.line
        index += 1
        if pending_start:
            actions.append(Action("arc_on", None, phase.name, "start"))
            pending_start = False
        if mo.arc == "start":  # on when the motion reaches its point: the next one starts
            pending_start = True
        elif mo.arc == "end":
            actions.append(Action("arc_off", None, phase.name, "end"))
    if pending_start:
        actions.append(Action("arc_on", None, phases[-1].name, "end"))
    if not isinstance(phases[0], JointPhase):
        raise err(motions[0].line, "the program's first motion must be a J move")
    return _unblend_coordinated(phases, coord, lines, src, warnings), actions, warnings


def _origin(src: str, mo: LSMotion) -> str:
    """Where a move is written: ``prog.ls: line 12 (C P[5] P[6])`` (a C move's via point,
    then its end)."""
    points = ([mo.via] if mo.via is not None else []) + [mo.target]
    return f"{src}: line {mo.line} ({mo.kind} {' '.join(f'{k}[{n}]' for k, n in points)})"


def _unblend_coordinated(phases: list, coord: set[int], lines: dict[int, int], src: str,
                         warnings: list[str]) -> list:
    """The phases with no CNT on or into an L or C move that moves the axes (phase indices
    ``coord``; such a move is planned on its own: it ends at rest), a warning for each naming
    its motion's line (``lines``)."""
    import dataclasses

    out = list(phases)
    for k in sorted(coord):
        for j in (k - 1, k):
            ph = out[j] if j >= 0 else None
            if isinstance(ph, CartesianPhase) and ph.blend_fraction > 0:
                warnings.append(f"{src}: line {lines[j]}: CNT on or into a move that moves "
                                "external axes (COORD) runs as FINE")
                out[j] = dataclasses.replace(ph, blend_fraction=0.0)
    return out


class _CellAxes:
    """The cell's external axes as a program drives them: names, kinds, ranges, carriers, and
    where the axes are (``current``, from their home)."""

    def __init__(self, mechanisms: tuple, no_axes: str | None = None) -> None:
        self.no_axes = no_axes
        self.names = tuple(n for pm in mechanisms for n in pm.joint_names)
        self.kinds = {n: a.kind for pm in mechanisms
                      for n, a in zip(pm.joint_names, pm.spec.axes, strict=True)}
        self.ranges = {n: a.range for pm in mechanisms
                       for n, a in zip(pm.joint_names, pm.spec.axes, strict=True)}
        self.mechanism = {n: pm.name for pm in mechanisms for n in pm.joint_names}
        self.carrier = {obj: pm.name for pm in mechanisms for obj in pm.carries if obj != "robot"}
        self.robot_on = next((pm.name for pm in mechanisms if "robot" in pm.carries), None)
        self.current = {n: float(v) for pm in mechanisms
                        for n, v in zip(pm.joint_names, pm.home, strict=True)}

    def written(self, name: str, value: float) -> str:
        """An axis value as a program writes it (``12.5 deg``, ``1500.000 mm``)."""
        unit = KIND_UNIT[self.kinds[name]]
        return f"{from_si(value, unit):.3f} {unit}"

    def values(self, pos: LSPosition) -> dict[str, float]:
        """``pos``'s extended values by axis name (SI); {} for none.

        Raises:
            ValueError: The fault, as one line's text (module docstring).
        """
        vals = extended_values(pos)
        cart = cartesian_group(pos)
        if cart is not None:
            raise ValueError(f"P[{pos.index}]: GP{cart.number} is a Cartesian position (a second "
                             "robot); cellsim maps a group's joint values (J1 ..) onto the "
                             "cell's external axes")
        if not vals:
            return {}
        labels = ", ".join(v[0] for v in vals)
        if self.no_axes is not None:
            raise ValueError(f"P[{pos.index}] has extended axis values ({labels}); "
                             f"{self.no_axes}")
        if not self.names:
            raise ValueError(f"P[{pos.index}] has extended axis values ({labels}), but the cell "
                             "has no external axes (no [[mechanisms]])")
        if len(vals) != len(self.names):
            raise ValueError(f"P[{pos.index}] has {len(vals)} extended axis values ({labels}); "
                             f"the cell has {len(self.names)} external axes "
                             f"({', '.join(self.names)}, in this order)")
        out = {}
        for (label, value, unit), name in zip(vals, self.names, strict=True):
            kind = self.kinds[name]
            if AXIS_KIND[unit] != kind:
                raise ValueError(f"P[{pos.index}]: {label} is in {unit}, but it maps onto "
                                 f"{name}, a {kind} axis (in {KIND_UNIT[kind]})")
            lo, hi = self.ranges[name]
            if not lo - AXES_EQUAL <= value <= hi + AXES_EQUAL:
                raise ValueError(f"P[{pos.index}]: {label} = {from_si(value, unit):.3f} {unit} is "
                                 f"outside the range of {name}, [{from_si(lo, unit):g}, "
                                 f"{from_si(hi, unit):g}] {unit}")
            out[name] = value
        return out

    def moving(self, values: dict[str, float]) -> dict[str, float]:
        """The values that differ from where the axes are (by more than :data:`AXES_EQUAL`)."""
        return {n: v for n, v in values.items() if abs(v - self.current[n]) > AXES_EQUAL}

    def frame_fault(self, moving: dict[str, float], uf: int, frame: str) -> str | None:
        """Why a move's points cannot be in ``frame`` (UF ``uf``) while ``moving`` axes move,
        or None (module docstring)."""
        mechs = {self.mechanism[n] for n in moving}
        if uf == 0:
            return ("a COORD move that moves external axes has its points in a user frame of "
                    "the part (UFRAME_NUM = n, program_frames = { \"n\" = \"<cell object>\" }), "
                    "not UF 0")
        if self.carrier.get(frame) in mechs or self.robot_on in mechs:
            return None
        held_by = self.carrier.get(frame)
        what = f"carried by {held_by!r}, which does not move" if held_by else "fixed"
        return (f"UF {uf} is {frame!r}, {what}; a COORD move that moves "
                f"{', '.join(sorted(mechs))} has its points in the frame of a part it carries")


def _last_point(phases: list) -> NDArray[np.float64] | None:
    """Where the previous Cartesian move ended (its programmed point), if the last phase is
    one in the same frame; None otherwise."""
    last = phases[-1] if phases else None
    if isinstance(last, CartesianPhase):
        return np.asarray(last.to, dtype=float)
    if isinstance(last, JointPhase) and last.target is not None \
            and last.target.position is not None:
        return np.asarray(last.target.position, dtype=float)
    return None


def _zyx(R: NDArray[np.float64]) -> NDArray[np.float64]:
    from sim.core.rotations import matrix_to_euler_zyx

    return np.asarray(matrix_to_euler_zyx(R), dtype=float)


def registers_from_scenario(values: dict[str, list[float]], where: str) -> dict[int, LSPosition]:
    """``program_registers`` of a scenario as positions (mm, deg; config ``N U T, 0, 0, 0``)."""
    out = {}
    for key, v in values.items():
        if not key.isdigit():
            raise ScenarioError(f"{where}: program_registers.{key}: register numbers are "
                                "whole numbers (\"1\", \"2\", ...)")
        if len(v) != 6 or not all(math.isfinite(x) for x in v):
            raise ScenarioError(f"{where}: program_registers.{key}: [X, Y, Z, W, P, R] in mm "
                                "and deg (6 numbers)")
        out[int(key)] = LSPosition(int(key), 0, 1, tuple(float(x) for x in v),
                                   ("N", "U", "T", 0, 0, 0))
    return out


def frames_from_scenario(values: dict[str, str], where: str) -> dict[int, str]:
    out = {}
    for key, v in values.items():
        if not key.isdigit() or int(key) == 0:
            raise ScenarioError(f"{where}: program_frames.{key}: user frame numbers are 1, 2, "
                                "... (UF 0 is the robot's world frame)")
        out[int(key)] = v
    return out


__all__ = ["CNT_SHARE", "SPEED_UNITS", "TP_WEAVE_PATTERNS", "frames_from_scenario",
           "home_keyframe", "program_phases", "registers_from_scenario", "rotation_wpr"]


def config_of(robot, q: NDArray[np.float64], branch: str) -> tuple:
    """The FANUC configuration ``(flip, up, front, turn4, turn5, turn6)`` of joint values ``q``
    (rad) on the IK branch ``branch`` (module docstring). A 5-axis robot has no flip and one
    wrist turn (J4's place stays 0)."""
    import re as _re

    from sim.robots.maker import to_maker

    words = set(_re.split(r"[^a-z]+", branch.lower()))
    maker = np.rad2deg(to_maker(robot, np.asarray(q, dtype=float)))
    n = len(maker)
    flip = "F" if n >= 6 and maker[4] < 0 else "N"
    up = "D" if "down" in words else "U"
    front = "B" if "back" in words else "T"
    wrist = maker[3:6] if n >= 6 else np.r_[0.0, maker[3:5]]
    turns = tuple(int(math.ceil((float(v) - 180.0) / 360.0 - 1e-9)) for v in wrist)
    return (flip, up, front) + turns


__all__ += ["config_of"]
