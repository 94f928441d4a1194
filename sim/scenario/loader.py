"""Scenario files: loading, validation and planning (TOML -> :class:`Scenario`).

A scenario is a TOML file (stdlib :mod:`tomllib`) that names a robot and a list of phases.
The structure is declared once, with pydantic models below, so that unknown keys, wrong types
and NaN are rejected with one line naming the key; the format reference
(``docs/scenario-format.md``) documents the same keys and a test keeps the two in step.

Inside cellsim everything is SI; the file may use degrees or millimetres where the key says so
(``joints_deg``, ``points_mm``). Every error is a :class:`sim.errors.ScenarioError` whose message
starts with the file name and the dotted path of the offending key, e.g.
``bugnar.toml: phases[0].time_s: knot times must increase (index 2: 3.33 s after 6.67 s)``.
"""

from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ValidationError

from planners.errors import PlannerError
from planners.registry import get_planner
from sim.core.resources import shipped_scenarios
from sim.errors import CellsimError, ScenarioError
from sim.robots.registry import RobotSpec, resolve_robot
from sim.scenario.model import (
    Action,
    CartesianPhase,
    HoldPhase,
    JointPhase,
    Phase,
    PoseTarget,
    Scenario,
)
from sim.scenario.schema import (
    _BOUNDARY_KEYS,
    PHASE_KINDS,
    ActionSpec,
    CircularPhaseSpec,
    DriveOverrideSpec,
    JointPhaseSpec,
    LinearPhaseSpec,
    ScenarioSpec,
    SimulationSpec,
    VideoSpec,
)

# --------------------------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------------------------


def resolve_scenario(ref: str | Path) -> Path:
    """Path of a scenario given as a file path or as a shipped scenario's name.

    Raises:
        UnknownNameError: Neither an existing file nor a shipped scenario; lists the shipped ones.
    """
    path = Path(ref)
    if path.is_file() or (path.exists() and not path.is_dir()):
        return path  # a FIFO or device too: read_input refuses it in one line
    shipped = shipped_scenarios()
    if str(ref) not in shipped and (path.suffix == ".toml" or path.parent != Path(".")):
        raise ScenarioError(f"{ref}: no such scenario file")
    return shipped.get(str(ref))


def load_scenario(ref: str | Path) -> Scenario:
    """Load and validate a scenario file (path or shipped name).

    Raises:
        ScenarioError: Unreadable or malformed file, or inconsistent content; one line naming
            the file and the key.
        UnknownNameError: Unknown scenario name or robot.
    """
    from sim.core.files import read_input_text

    path = resolve_scenario(ref)
    return parse_scenario(read_input_text(path, ScenarioError, "scenario file"), source=path)


def parse_scenario(text: str, source: str | Path = "<scenario>") -> Scenario:
    """Validate scenario TOML text; see :func:`load_scenario`."""
    where = Path(source).name if str(source) != "<scenario>" else "<scenario>"
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{where}: invalid TOML: {exc}") from None
    try:
        spec = ScenarioSpec.model_validate(raw)
    except ValidationError as exc:
        raise ScenarioError(f"{where}: {_describe_validation_error(exc, raw)}") from None
    try:
        robot = resolve_robot(
            spec.robot, Path(source).parent if str(source) != "<scenario>" else None)
    except CellsimError as exc:  # unknown name, or a robot folder's own error
        raise ScenarioError(f"{where}: robot: {exc}") from None

    phases: list[Phase] = []
    seen: dict[str, int] = {}
    if (spec.program is None) == (not spec.phases):
        raise ScenarioError(f"{where}: give phases (at least one) or program (a FANUC TP "
                            "program), not both" if spec.phases else
                            f"{where}: phases: at least one phase (or program = \"prog.ls\")")
    if spec.program is None and (spec.program_frames or spec.program_registers
                                 or spec.program_weld_speed_mm_s is not None):
        raise ScenarioError(f"{where}: program_frames, program_registers and "
                            "program_weld_speed_mm_s go with program")
    for i, pspec in enumerate(spec.phases):
        key = f"{where}: phases[{i}]"
        if pspec.name in seen:
            raise ScenarioError(
                f"{key}.name: {pspec.name!r} is already the name of phases[{seen[pspec.name]}]")
        seen[pspec.name] = i
        phase: Phase
        prev = phases[-1] if phases else None
        if isinstance(pspec, JointPhaseSpec):
            timed_prev = prev is None or (isinstance(prev, JointPhase) and prev.times is not None)
            if pspec.time_s is not None and not timed_prev:
                assert prev is not None
                raise ScenarioError(
                    f"{key}.time_s: after a {prev.kind} phase the start time is only known once "
                    "the motion is planned; give durations_s (and the knots after the start)")
            phase = _build_joint_phase(i, pspec, robot, key)
            if (isinstance(prev, JointPhase) and prev.times is not None and phase.times is not None
                    and prev.target is None):
                _check_continuity(prev, phase, key, robot)
        elif prev is None:
            raise ScenarioError(f"{key}.kind: the first phase must be a joint phase (it sets the "
                                "start pose)")
        elif isinstance(pspec, (LinearPhaseSpec, CircularPhaseSpec)):
            phase = _build_cartesian_phase(i, pspec, key)
        else:
            phase = HoldPhase(index=i, name=pspec.name, duration=pspec.duration_s)
        phases.append(phase)

    # imported here: sim.cells imports mujoco, and the command line must be able to choose the
    # OpenGL backend (MUJOCO_GL) after loading a scenario
    from sim.cells import BARE, resolve_cell, resolve_tool

    base = Path(source).parent if str(source) != "<scenario>" else Path.cwd()
    try:
        cell = None if spec.cell is None else resolve_cell(spec.cell, base)
    except CellsimError as exc:  # a cell file's own error names its file and key
        raise ScenarioError(f"{where}: cell: {exc}") from None
    mount = spec.mount
    if cell is not None and cell.source is not None:
        file_mount = cell.mounts[0]
        if "mount" in spec.model_fields_set and spec.mount != file_mount:
            raise ScenarioError(f"{where}: mount: {spec.mount!r}, but cell file {cell.source.name} "
                                f"mounts the robot on the {file_mount} ([robot] mount); leave "
                                "mount out or make the two agree")
        mount = file_mount
        if not cell.any_robot and robot.name not in cell.robots:
            raise ScenarioError(f"{where}: robot: cell file {cell.source.name} is laid out for "
                                f"{cell.robots[0]} ([robot] model), not {robot.name}")
    try:
        tool = resolve_tool(BARE if cell is None else cell, spec.tool, base)
    except CellsimError as exc:
        raise ScenarioError(f"{where}: tool: {exc}") from None
    tool_kind = None if tool is None else tool.kind
    drives: dict[str, dict[str, float]] = {}
    for joint, override in spec.drives.items():
        if joint not in robot.joints:
            close = difflib.get_close_matches(joint, robot.joints, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ScenarioError(f"{where}: drives.{joint}: unknown joint{hint}; robot "
                                f"{robot.name} has {', '.join(robot.joints)}")
        drives[joint] = {k: v for k, v in override.model_dump().items() if v is not None}
    program_warnings: tuple[str, ...] = ()
    actions = []
    if spec.program is not None:
        if spec.actions:
            raise ScenarioError(f"{where}: actions: not with program (the program's Arc "
                                "Start/End are its actions)")
        from sim.scenario.fanuc_ls import read_ls
        from sim.scenario.program import (
            frames_from_scenario,
            program_phases,
            registers_from_scenario,
        )

        try:
            prog = read_ls(base / spec.program)
        except ScenarioError as exc:  # names the program file and line
            raise ScenarioError(f"{where}: program: {exc}") from None
        frames = frames_from_scenario(spec.program_frames, where)
        registers = registers_from_scenario(spec.program_registers, where)
        # the program starts at the cell's home (the compiled cell's, filled in when the
        # motion is planned: CartesianContext.home_q); the robot's own home keyframe until then
        phases, actions, warns = program_phases(
            prog, robot, np.full(robot.n_joints, np.nan), frames, registers, where,
            has_tool=tool_kind == "torch", weld_speed=spec.program_weld_speed_mm_s)
        program_warnings = tuple(warns)
        seen = {ph.name: k for k, ph in enumerate(phases)}
    phases = _with_ctwd(phases, spec, tool, where)
    for i, a in enumerate(spec.actions):
        if (a.time_s is None) == (a.phase is None):
            raise ScenarioError(f"{where}: actions[{i}]: give exactly one of time_s or phase")
        if a.phase is not None and a.phase not in seen:
            close = difflib.get_close_matches(a.phase, list(seen), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ScenarioError(f"{where}: actions[{i}].phase: no phase named {a.phase!r}{hint}; "
                                f"phases: {', '.join(seen)}")
        need = "gripper" if a.action.startswith("suction") else "torch"
        if tool_kind != need:
            raise ScenarioError(f"{where}: actions[{i}].action: {a.action} needs a {need} tool "
                                f"(the tool is {'none' if tool is None else tool.name})")
        actions.append(Action(a.action, a.time_s, a.phase, a.at))
    return Scenario(
        name=spec.name,
        description=spec.description,
        robot=robot,
        phases=tuple(phases),
        source=Path(source),
        text=text,
        cell=cell,
        tool=tool,
        mount=mount,
        payload_kg=spec.payload_kg,
        simulation=spec.simulation,
        video=spec.video,
        drives=drives,
        program_warnings=program_warnings,
        actions=tuple(actions),
        sizing=spec.sizing,
    )


#: Knot times and segment durations a joint phase may have, s: a segment from a microsecond
#: to 10^6 s (11.6 days; a run is bounded far below by its step count), knot times within
#: 10^6 s of 0. Outside them the knot system's powers of the durations overflow or vanish.
MIN_SEGMENT_S, MAX_TIME_S = 1e-6, 1e6


def _check_times(times: np.ndarray, durations: np.ndarray, key: str) -> None:
    """Refuses knot times or segment durations outside :data:`MIN_SEGMENT_S` ..
    :data:`MAX_TIME_S`, naming the key and the index."""
    for values, what, low in ((np.abs(times), "knot time", -np.inf),
                              (durations, "segment", MIN_SEGMENT_S)):
        bad = np.flatnonzero((values > MAX_TIME_S) | (values < low))
        if bad.size:
            k = int(bad[0])
            raise ScenarioError(
                f"{key}[{k + (1 if what == 'segment' and key.endswith('time_s') else 0)}]: "
                f"{what} of {values[k]:g} s; cellsim takes {what}s "
                + (f"of {MIN_SEGMENT_S:g} to {MAX_TIME_S:g} s" if what == "segment"
                   else f"within {MAX_TIME_S:g} s of 0"))


def _build_joint_phase(index: int, spec: JointPhaseSpec, robot: RobotSpec, where: str) -> JointPhase:
    if (spec.time_s is None) == (spec.durations_s is None):
        raise ScenarioError(f"{where}: give exactly one of time_s or durations_s")
    if spec.time_s is not None:
        times = np.asarray(spec.time_s, dtype=float)
        if times.size < 2:
            raise ScenarioError(
                f"{where}.time_s: {times.size} knot time given; a phase needs at least 2 "
                "(start and end; a single move's joint-space midpoint becomes its via point)")
        steps = np.diff(times)
        if np.any(steps <= 0):
            k = int(np.argmax(steps <= 0)) + 1
            raise ScenarioError(
                f"{where}.time_s: knot times must increase (index {k}: {times[k]:g} s after "
                f"{times[k - 1]:g} s)")
        durations = steps
        n_rows = times.size
        _check_times(times, durations, f"{where}.time_s")
    else:
        durations = np.asarray(spec.durations_s, dtype=float)
        times = None
        if durations.size < 1:
            raise ScenarioError(f"{where}.durations_s: empty; give at least one segment duration")
        if np.any(durations <= 0):
            k = int(np.argmax(durations <= 0))
            raise ScenarioError(f"{where}.durations_s[{k}]: segment durations must be positive, "
                                f"got {durations[k]:g} s")
        n_rows = durations.size  # the start knot is the previous phase's end
        _check_times(np.zeros(1), durations, f"{where}.durations_s")

    target = _pose_target(spec, where)
    if target is not None:
        n_rows -= 1  # the last knot comes from the pose target
    n = robot.n_joints
    given = [k for k in ("joints_deg", "joints_rad", "joints_maker_deg")
             if getattr(spec, k) is not None]
    if len(given) > 1:
        raise ScenarioError(f"{where}: give exactly one of joints_deg, joints_rad or "
                            f"joints_maker_deg (got {' and '.join(given)})")
    if spec.joints_maker_deg is not None and not robot.maker_matrix:
        raise ScenarioError(f"{where}.joints_maker_deg: robot {robot.name} has no maker's joint "
                            "convention of its own (its joint values are the seed's); use "
                            "joints_deg")
    if not given:
        if target is None:
            raise ScenarioError(f"{where}: give joints_deg (or joints_rad, joints_maker_deg), or a pose target "
                                "(to_mm or to_seam)")
        if times is not None:
            raise ScenarioError(f"{where}.joints_deg: required: its first row is the start knot")
        rows_q = np.zeros((0, n))
    else:
        key, rows, scale = {
            "joints_deg": ("joints_deg", spec.joints_deg, math.pi / 180.0),
            "joints_rad": ("joints_rad", spec.joints_rad, 1.0),
            "joints_maker_deg": ("joints_maker_deg", spec.joints_maker_deg, math.pi / 180.0),
        }[given[0]]
        assert rows is not None
        if len(rows) != n_rows:
            if target is not None:
                what = ("rows (the start knot and the via points; the end is the pose target)"
                        if times is not None else "rows (the via points; the start is the previous "
                        "phase's end and the end is the pose target)")
                raise ScenarioError(f"{where}.{key}: {len(rows)} rows, expected {n_rows} {what}")
            what = ("knot times; give one row per time" if times is not None else
                    "segments; give one row per segment end (the start is the previous phase's end)")
            raise ScenarioError(f"{where}.{key}: {len(rows)} rows for {n_rows} {what}")
        for r, row in enumerate(rows):
            if len(row) != n:
                raise ScenarioError(
                    f"{where}.{key}[{r}]: {len(row)} values; robot {robot.name} has {n} joints "
                    f"({', '.join(robot.joints)})")
        rows_q = np.asarray(rows, dtype=float).reshape(-1, n) * scale
        if key == "joints_maker_deg":  # the controller's joint values -> the seed's
            from sim.robots.maker import from_maker

            rows_q = from_maker(robot, rows_q)
    if target is None and rows_q.shape[0] == 0:
        raise ScenarioError(f"{where}: no knots")
    blocks = []
    if times is None:
        blocks.append(np.full((1, n), np.nan))  # start: the previous phase's end
    blocks.append(rows_q)
    if target is not None:
        blocks.append(np.full((1, n), np.nan))  # end: solved from the pose target
    q = np.vstack(blocks)
    if durations.size == 1:
        # a single segment: the joint-space midpoint is the via point (4-4 / 5-6 polynomial),
        # filled in once start and end are known (JointPhase.with_start / with_end)
        durations = np.array([durations[0] / 2, durations[0] / 2])
        if times is not None:
            times = np.array([times[0], times[0] + durations[0], times[1]])
        q = np.vstack([q[:1], np.full((1, n), np.nan), q[1:]])
    if target is not None and times is not None and np.isnan(q[0]).any():
        raise ScenarioError(f"{where}.joints_deg: the first row is the start knot")

    boundary: dict[str, NDArray[np.float64]] = {}
    for bkey, (kw, bscale) in _BOUNDARY_KEYS.items():
        values = getattr(spec, bkey)
        if values is None:
            continue
        if kw in boundary:
            raise ScenarioError(f"{where}.{bkey}: the same boundary value is also given in other units")
        if kw.startswith("j") and spec.planner != "546":
            raise ScenarioError(
                f"{where}.{bkey}: the {spec.planner} planner has no jerk boundary conditions "
                "(only 546 does)")
        if len(values) != n:
            raise ScenarioError(
                f"{where}.{bkey}: {len(values)} values; robot {robot.name} has {n} joints")
        boundary[kw] = np.asarray(values, dtype=float) * bscale
    if spec.blend_deg and ("vf" in boundary or "af" in boundary):
        raise ScenarioError(f"{where}.blend_deg: not with end_velocity/end_acceleration (the "
                            "blend sets them)")
    return JointPhase(index=index, name=spec.name, planner=spec.planner, times=times,
                      durations=durations, q=q, boundary=boundary, target=target,
                      blend=math.radians(spec.blend_deg or 0.0))


def _pose_target(spec: JointPhaseSpec, where: str) -> PoseTarget | None:
    if spec.to_mm is not None and spec.to_seam is not None:
        raise ScenarioError(f"{where}: give one of to_mm or to_seam")
    if spec.euler_zyx_deg is not None and spec.to_mm is None:
        raise ScenarioError(f"{where}.euler_zyx_deg: only used with to_mm")
    if spec.to_seam is not None:
        if spec.frame != "frame0":
            raise ScenarioError(f"{where}.frame: only used with to_mm (a seam is in its cell)")
        return _seam_target(spec, where)
    for key in ("approach_mm", "retract_mm"):
        if getattr(spec, key) is not None:
            raise ScenarioError(f"{where}.{key}: only used with to_seam")
    if spec.to_mm is None:
        if spec.frame != "frame0":
            raise ScenarioError(f"{where}.frame: only used with to_mm")
        return None
    rot = None
    if spec.euler_zyx_deg is not None:
        from sim.core.rotations import euler_zyx_to_matrix

        rot = euler_zyx_to_matrix(*np.deg2rad(np.asarray(spec.euler_zyx_deg, dtype=float)))
    return PoseTarget(position=np.asarray(spec.to_mm, dtype=float) * 1e-3, rotation=rot,
                      frame=spec.frame)


def _seam_target(spec: JointPhaseSpec | LinearPhaseSpec, where: str) -> PoseTarget:
    """``to_seam`` with ``approach_mm`` (before its start) or ``retract_mm`` (back from its
    end) along the seam's torch axis."""
    if spec.approach_mm is not None and spec.retract_mm is not None:
        raise ScenarioError(f"{where}: give one of approach_mm (before the seam's start) or "
                            "retract_mm (back from its end)")
    end = "end" if spec.retract_mm is not None else "start"
    mm = spec.retract_mm if spec.retract_mm is not None else spec.approach_mm or 0.0
    return PoseTarget(seam=spec.to_seam, seam_end=end, offset=mm * 1e-3)


def _with_ctwd(phases: list[Phase], spec: ScenarioSpec, tool: Any, where: str) -> list[Phase]:
    """The phases with the stand-off of each weld phase that gives ``ctwd_mm``: that distance
    less the torch's nominal stick-out (:mod:`sim.cells.seam`).

    Raises:
        ScenarioError: ``ctwd_mm`` without a seam, without a torch, or shorter than the torch's
            nominal stick-out (its modelled wire would reach into the work).
    """
    import dataclasses

    out = list(phases)
    for i, pspec in enumerate(spec.phases):
        ctwd = getattr(pspec, "ctwd_mm", None)
        if ctwd is None:
            continue
        key = f"{where}: phases[{i}].ctwd_mm"
        if getattr(pspec, "seam", None) is None:
            raise ScenarioError(f"{key}: only used with seam (the contact-tip-to-work distance "
                                "of a pass along a seam)")
        if tool is None or tool.kind != "torch":
            raise ScenarioError(f"{key}: needs a torch (the tool is "
                                f"{'none' if tool is None else tool.name})")
        try:
            standoff = tool.standoff(ctwd * 1e-3)
        except CellsimError as exc:
            raise ScenarioError(f"{key}: {exc}") from None
        out[i] = dataclasses.replace(out[i], standoff=standoff)
    return out


def _weave(spec: LinearPhaseSpec | CircularPhaseSpec, where: str):
    """The phase's :class:`planners.weave.Weave` (SI), or None."""
    w = spec.weave
    if w is None:
        return None
    from planners.weave import Weave

    if (w.frequency_hz is None) == (w.wavelength_mm is None):
        raise ScenarioError(f"{where}.weave: give exactly one of frequency_hz or wavelength_mm")
    freq = w.frequency_hz if w.frequency_hz is not None else spec.speed_mm_s / w.wavelength_mm
    if freq > 20.0:
        raise ScenarioError(f"{where}.weave.wavelength_mm: {w.wavelength_mm:g} mm at "
                            f"{spec.speed_mm_s:g} mm/s is {freq:.4g} Hz; weaves run at most "
                            "20 Hz")
    try:
        return Weave(w.pattern, w.amplitude_mm * 1e-3, freq, w.dwell_s)
    except PlannerError as exc:
        raise ScenarioError(f"{where}.{exc}") from None


def _build_cartesian_phase(index: int, spec: LinearPhaseSpec | CircularPhaseSpec,
                           where: str) -> CartesianPhase:
    def vec_m(v: list[float] | None) -> NDArray[np.float64] | None:
        return None if v is None else np.asarray(v, dtype=float) * 1e-3

    if spec.orientation == "euler" and spec.euler_zyx_deg is None:
        raise ScenarioError(f"{where}.euler_zyx_deg: required with orientation = \"euler\"")
    if spec.euler_zyx_deg is not None and spec.orientation != "euler":
        raise ScenarioError(f"{where}.euler_zyx_deg: only used with orientation = \"euler\"")
    if spec.orientation == "seam" and spec.seam is None and getattr(spec, "to_seam", None) is None:
        raise ScenarioError(f"{where}.orientation: \"seam\" needs a seam to follow (seam = ...)"
                            " or to go to (to_seam = ...)")
    common = dict(index=index, name=spec.name, kind=spec.kind, planner=spec.planner,
                  speed=spec.speed_mm_s * 1e-3, sample_period=spec.sample_period_s,
                  ramp=spec.ramp_s, orientation=spec.orientation, seam=spec.seam,
                  euler_zyx=None if spec.euler_zyx_deg is None
                  else np.deg2rad(np.asarray(spec.euler_zyx_deg, dtype=float)),
                  frame=spec.frame, blend=(spec.blend_mm or 0.0) * 1e-3,
                  weave=_weave(spec, where))
    if spec.seam is not None and spec.frame != "frame0":
        raise ScenarioError(f"{where}.frame: not used with seam (a seam is in its cell)")
    if isinstance(spec, LinearPhaseSpec):
        given = [k for k in ("seam", "to_mm", "to_seam") if getattr(spec, k) is not None]
        if len(given) != 1:
            raise ScenarioError(f"{where}: give exactly one of seam, to_mm or to_seam"
                                + (f" (got {' and '.join(given)})" if given else ""))
        if spec.to_seam is None:
            for key in ("approach_mm", "retract_mm"):
                if getattr(spec, key) is not None:
                    raise ScenarioError(f"{where}.{key}: only used with to_seam")
            return CartesianPhase(**common, to=vec_m(spec.to_mm))
        if spec.frame != "frame0":
            raise ScenarioError(f"{where}.frame: not used with to_seam (a seam is in its cell)")
        if spec.weave is not None:
            raise ScenarioError(f"{where}.weave: not used with to_seam (a move to or from a "
                                "seam does not weave)")
        return CartesianPhase(**common, target=_seam_target(spec, where))
    if spec.seam is not None:
        extra = [k for k in ("to_mm", "via_mm", "center_mm", "axis", "sweep_deg")
                 if getattr(spec, k) is not None]
        if extra:
            raise ScenarioError(f"{where}.{extra[0]}: not used with seam (the seam gives the arc)")
        return CartesianPhase(**common)
    if spec.via_mm is not None:
        if spec.to_mm is None:
            raise ScenarioError(f"{where}.to_mm: required with via_mm (arc through 3 points)")
        if spec.center_mm is not None or spec.sweep_deg is not None or spec.axis is not None:
            raise ScenarioError(f"{where}: give either via_mm and to_mm, or center_mm, axis and "
                                "sweep_deg")
        return CartesianPhase(**common, to=vec_m(spec.to_mm), via=vec_m(spec.via_mm))
    if spec.center_mm is not None:
        missing = [k for k in ("axis", "sweep_deg") if getattr(spec, k) is None]
        if missing:
            raise ScenarioError(f"{where}.{missing[0]}: required with center_mm")
        axis = np.asarray(spec.axis, dtype=float)
        norm = float(np.linalg.norm(axis))
        if norm < 1e-12:
            raise ScenarioError(f"{where}.axis: must be a non-zero vector")
        if spec.sweep_deg == 0 or spec.to_mm is not None:
            raise ScenarioError(f"{where}.sweep_deg: must be non-zero (and to_mm is not used "
                                "with center_mm)")
        return CartesianPhase(**common, center=vec_m(spec.center_mm), axis=axis / norm,
                              sweep=math.radians(spec.sweep_deg))
    raise ScenarioError(f"{where}: give seam, or via_mm and to_mm, or center_mm, axis and "
                        "sweep_deg")


def _check_continuity(prev: JointPhase, phase: JointPhase, where: str, robot: RobotSpec) -> None:
    if abs(phase.t0 - prev.t1) > 1e-9:
        raise ScenarioError(
            f"{where}.time_s: starts at {phase.t0:g} s but phases[{prev.index}] ({prev.name}) ends "
            f"at {prev.t1:g} s; each phase starts where the previous one ended")
    gap = np.abs(phase.q[0] - prev.q[-1])
    if np.any(gap > 1e-9):
        j = int(np.argmax(gap))
        raise ScenarioError(
            f"{where}: first knot of joint {robot.joints[j]} is {np.rad2deg(phase.q[0, j]):.6g} deg "
            f"but phases[{prev.index}] ({prev.name}) ends at {np.rad2deg(prev.q[-1, j]):.6g} deg; "
            "each phase starts where the previous one ended")


def _describe_validation_error(exc: ValidationError, raw: Any) -> str:
    """One line for the first pydantic error: dotted key path and what is wrong
    (:func:`sim.core.tomlschema.describe`, with the phases' tagged union)."""
    from sim.core.tomlschema import describe

    return describe(exc, ScenarioSpec, locate=lambda loc: _model_at(loc, raw), strip=_strip_tags,
                    union_hint=f"kind: must be one of {', '.join(repr(k) for k in PHASE_KINDS)}")


def _strip_tags(loc: tuple[Any, ...]) -> tuple[Any, ...]:
    """Drop pydantic's union tags (``phases, 0, "joint", key`` -> ``phases, 0, key``)."""
    out: list[Any] = []
    for i, part in enumerate(loc):
        if (i >= 2 and loc[i - 2] == "phases" and isinstance(loc[i - 1], int)
                and part in PHASE_KINDS):
            continue
        out.append(part)
    return tuple(out)


def _model_at(loc: tuple[Any, ...], raw: Any) -> type[BaseModel] | None:
    """The pydantic model class that validates the table at ``loc`` (for key suggestions)."""
    loc = _strip_tags(loc)
    if not loc:
        return ScenarioSpec
    head = loc[0]
    if head == "phases" and len(loc) == 2 and isinstance(loc[1], int):
        try:
            kind = raw["phases"][loc[1]].get("kind", "joint")
        except (KeyError, IndexError, TypeError, AttributeError):
            return None
        return PHASE_KINDS.get(kind) if isinstance(kind, str) else None
    if head == "actions" and len(loc) == 2:
        return ActionSpec
    if head == "drives" and len(loc) == 2:
        return DriveOverrideSpec
    if len(loc) == 1:
        return {"simulation": SimulationSpec, "video": VideoSpec}.get(head)
    return None


# --------------------------------------------------------------------------------------------
# Planning
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlannedPhase:
    """A phase with its trajectory."""

    phase: JointPhase
    trajectory: Any  # planners.trajectory.PiecewisePolynomialTrajectory


def plan_phase(phase: JointPhase, where: str = "") -> Any:
    """Plan one joint phase with its planner.

    Raises:
        ScenarioError: The planner rejected the phase (message prefixed with ``where``).
    """
    try:
        return get_planner(phase.planner)(phase.times, phase.q, **phase.boundary)
    except PlannerError as exc:
        prefix = f"{where}: " if where else ""
        raise ScenarioError(f"{prefix}phases[{phase.index}] ({phase.name}): {exc}") from None


def plan_scenario(scenario: Scenario) -> list[PlannedPhase]:
    """Plan every phase of a scenario, in order."""
    where = scenario.source.name
    return [PlannedPhase(p, plan_phase(p, where)) for p in scenario.phases]
