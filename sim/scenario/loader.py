"""Scenario files: loading and validation (TOML -> :class:`Scenario`).

A scenario is a TOML file (stdlib :mod:`tomllib`) that names a robot and a list of phases.
The structure is declared once, with pydantic models below, so that unknown keys, wrong types
and NaN are rejected with one line naming the key; the format reference
(``docs/scenario-format.md``) documents the same keys and a test keeps the two in step.

Inside cellsim everything is SI; the file may use degrees or millimetres where the key says so
(``joints_deg``, ``points_mm``). Every error is a :class:`sim.errors.ScenarioError` whose message
starts with the file name and the dotted path of the offending key, e.g.
``bugnar.toml: phases[0].time_s: knot times must increase (index 2: 3.33 s after 6.67 s)``.

The phases themselves are built by :mod:`sim.scenario.phases`, and planned by
:mod:`sim.scenario.planning`.
"""

from __future__ import annotations

import difflib
import os
import tomllib
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from pydantic import BaseModel, ValidationError

from sim.cells import BARE, resolve_cell, resolve_tool
from sim.core.files import read_input_text
from sim.core.resources import shipped_scenarios
from sim.core.tomlschema import describe, model_at
from sim.errors import CellsimError, ScenarioError, UnknownNameError
from sim.robots.registry import resolve_robot
from sim.scenario.fanuc_ls import read_ls
from sim.scenario.model import Action, HoldPhase, JointPhase, Phase, RobotWork, Scenario
from sim.scenario.phases import (
    build_cartesian_phase,
    build_joint_phase,
    check_axes,
    check_continuity,
    with_ctwd,
)
from sim.scenario.program import (
    frames_from_scenario,
    program_phases,
    registers_from_scenario,
)
from sim.scenario.schema import (
    PHASE_KINDS,
    ActionSpec,
    CircularPhaseSpec,
    DriveOverrideSpec,
    ExpectSpec,
    JointPhaseSpec,
    LinearPhaseSpec,
    RobotWorkSpec,
    ScenarioSpec,
    WeaveSpec,
)

if TYPE_CHECKING:
    from sim.cells import CellSpec
    from sim.cells.tools import ToolSpec
    from sim.robots.spec import RobotSpec


def resolve_scenario(ref: str | os.PathLike[str]) -> Path:
    """Path of a scenario given as a file path or as a shipped scenario's name.

    Raises:
        UnknownNameError: Neither an existing file nor a shipped scenario; lists the shipped ones.
    """
    path = Path(ref)
    if path.is_file() or (path.exists() and not path.is_dir()):
        return path  # a FIFO or device too: read_input refuses it in one line
    shipped = shipped_scenarios()
    if path.is_dir() and str(ref) not in shipped:
        raise ScenarioError(f"{ref}: a folder, not a scenario file")
    if str(ref) not in shipped and (path.suffix == ".toml" or path.parent != Path(".")):
        raise ScenarioError(f"{ref}: no such scenario file")
    return shipped.get(str(ref))


def load_scenario(ref: str | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario file (path or shipped name).

    Raises:
        ScenarioError: Unreadable or malformed file, or inconsistent content; one line naming
            the file and the key.
        UnknownNameError: Unknown scenario name or robot.
    """
    from sim.core.arguments import path_argument

    path_argument(ref, "scenario", error=ScenarioError)  # a path or a name, not empty
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
    cell_axes = {} if cell is None else {
        n: (a.kind, a.range) for pm in cell.mechanisms
        for n, a in zip(pm.joint_names, pm.spec.axes, strict=True)}
    kinds = {pm.name: pm.spec.kind for pm in (() if cell is None else cell.mechanisms)}
    tracks = {name for name, kind in kinds.items() if kind == "track"}
    for i, pspec in enumerate(spec.phases):
        if isinstance(pspec, JointPhaseSpec):
            check_axes(pspec.axes, cell_axes, f"{where}: phases[{i}]")
        elif isinstance(pspec, (LinearPhaseSpec, CircularPhaseSpec)):
            if pspec.follow is not None and pspec.follow not in tracks:
                what = (f"{pspec.follow!r} is a {kinds[pspec.follow]}; a robot follows a seam on "
                        "a track" if pspec.follow in kinds
                        else UnknownNameError('track', pspec.follow, sorted(tracks)) if tracks
                        else f"no track {pspec.follow!r}: the cell has none")
                raise ScenarioError(f"{where}: phases[{i}].follow: {what}")
    try:
        tool = resolve_tool(BARE if cell is None else cell, spec.tool, base)
    except CellsimError as exc:
        raise ScenarioError(f"{where}: tool: {exc}") from None
    drives: dict[str, dict[str, float]] = {}
    others = () if cell is None else tuple(n for p in cell.partners for n in p.system_names)
    joints = robot.joints + tuple(cell_axes) + others
    for joint, override in spec.drives.items():
        if joint not in joints:
            close = difflib.get_close_matches(joint, joints, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            axes = f" and the cell's axes {', '.join(cell_axes)}" if cell_axes else ""
            axes += f" and the other robots' {', '.join(others)}" if others else ""
            raise ScenarioError(f"{where}: drives.{joint}: unknown joint{hint}; robot "
                                f"{robot.name} has {', '.join(robot.joints)}{axes}")
        drives[joint] = {k: v for k, v in override.model_dump().items() if v is not None}
    phases, actions, program_warnings = _work(spec, robot, tool, cell, base, where)
    partners = _partners(spec, cell, base, where)
    _check_expect(spec.expect, where)
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
        expect=spec.expect,
        partners=partners,
    )


def _work(spec: ScenarioSpec | RobotWorkSpec, robot: RobotSpec, tool: ToolSpec | None,
          cell: CellSpec | None, base: Path, where: str, no_axes: str | None = None
          ) -> tuple[list[Phase], list[Action], tuple[str, ...]]:
    """One robot's work: its phases (or its TP program's) and its tool actions.

    ``where`` starts every error (``file.toml`` for the first robot, ``file.toml: robots.r2``
    for another); ``no_axes`` says why a program's extended-axis values have no axes to move
    (:func:`~sim.scenario.program.program_phases`).
    """
    tool_kind = None if tool is None else tool.kind
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
            phase = build_joint_phase(i, pspec, robot, key)
            if (isinstance(prev, JointPhase) and prev.times is not None and phase.times is not None
                    and prev.target is None):
                check_continuity(prev, phase, key, robot)
        elif prev is None:
            raise ScenarioError(f"{key}.kind: the first phase must be a joint phase (it sets the "
                                "start pose)")
        elif isinstance(pspec, (LinearPhaseSpec, CircularPhaseSpec)):
            phase = build_cartesian_phase(i, pspec, key)
        else:
            phase = HoldPhase(index=i, name=pspec.name, duration=pspec.duration_s)
        phases.append(phase)

    program_warnings: tuple[str, ...] = ()
    actions = []
    if spec.program is not None:
        if spec.actions:
            raise ScenarioError(f"{where}: actions: not with program (the program's Arc "
                                "Start/End are its actions)")
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
            has_tool=tool_kind == "torch", weld_speed=spec.program_weld_speed_mm_s,
            mechanisms=() if cell is None else cell.mechanisms, no_axes=no_axes)
        program_warnings = tuple(warns)
        seen = {ph.name: k for k, ph in enumerate(phases)}
    phases = with_ctwd(phases, spec, tool, where)
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
    return phases, actions, program_warnings


def _partners(spec: ScenarioSpec, cell: CellSpec | None, base: Path, where: str
              ) -> tuple[RobotWork, ...]:
    """The work of the cell's other robots (``[robots.<name>]``); one not named stays at its
    home all cycle."""
    placed = {} if cell is None else {p.name: p for p in cell.partners}
    for name in spec.robots:
        if name in placed:
            continue
        if cell is None:
            what = ("a scenario without a cell has one robot (a cell file's [[robots]] places "
                    "the others)")
        elif not placed:
            what = (f"cell {cell.name} has no other robots (a cell file's [[robots]] places "
                    "them)")
        else:
            close = difflib.get_close_matches(name, list(placed), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            what = (f"cell {cell.name} has no other robot {name!r}{hint}; its [[robots]]: "
                    f"{', '.join(placed)}")
        raise ScenarioError(f"{where}: robots.{name}: {what}")
    out = []
    for name, pr in placed.items():
        ws = spec.robots.get(name)
        if ws is None:
            out.append(RobotWork(name, pr.robot, pr.tool))
            continue
        key = f"{where}: robots.{name}"
        for i, ph in enumerate(ws.phases):
            moved = [k for k in ("axes", "downhand", "follow") if getattr(ph, k, None)]
            if moved:
                raise ScenarioError(f"{key}: phases[{i}].{moved[0]}: the cell's axes move with "
                                    "its first robot's phases (a second robot's phases move "
                                    "its own joints)")
        try:
            tool = pr.tool if ws.tool is None else resolve_tool(BARE, ws.tool, base)
        except CellsimError as exc:
            raise ScenarioError(f"{key}.tool: {exc}") from None
        if tool is not None and tool.suction_gain_n > 0.0:
            raise ScenarioError(f"{key}.tool: {tool.name!r} is a suction gripper; a cell's "
                                "other robots carry torches or tools without suction")
        phases, actions, warns = _work(
            ws, pr.robot, tool, None, base, key,
            no_axes="the cell's axes move with its first robot's program or phases; another "
                    "robot's positions hold no extended values")
        out.append(RobotWork(name, pr.robot, tool, tuple(phases), tuple(actions), warns))
    return tuple(out)


def _check_expect(expect: ExpectSpec, where: str) -> None:
    """``[expect]`` is consistent: a failed verdict names its failed checks (and failed checks
    fail the verdict), and whatever is expected to fail says why.

    Raises:
        ScenarioError: One line naming ``expect.<key>``.
    """
    if expect.failed_checks and expect.verdict == "pass":
        raise ScenarioError(f"{where}: expect.verdict: a failed check fails the verdict; give "
                            'verdict = "fail" with failed_checks')
    if expect.verdict == "fail" and not expect.failed_checks:
        raise ScenarioError(f"{where}: expect.failed_checks: name the checks that fail the "
                            'verdict ("speed j2", ...)')
    if (expect.verdict == "fail" or expect.check_findings) and not expect.reason:
        raise ScenarioError(f"{where}: expect.reason: say why the scenario is expected to fail")


def _describe_validation_error(exc: ValidationError, raw: Any) -> str:
    """One line for the first pydantic error: dotted key path and what is wrong
    (:func:`sim.core.tomlschema.describe`, with the phases' tagged union)."""
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


def _model_at(loc: tuple[Any, ...], raw: Any,
              root: type[BaseModel] = ScenarioSpec) -> type[BaseModel] | None:
    """The pydantic model class that validates the table at ``loc`` (for key suggestions);
    ``robots.<name>`` is a :class:`RobotWorkSpec`, whose phases and actions are looked up as
    the top level's."""
    loc = _strip_tags(loc)
    if not loc:
        return root
    head = loc[0]
    table = raw if isinstance(raw, dict) else {}
    if head == "robots" and root is ScenarioSpec:
        if len(loc) < 2:
            return None
        robots = table.get("robots")
        work = robots.get(loc[1]) if isinstance(robots, dict) else None
        return _model_at(loc[2:], work, RobotWorkSpec)
    if head == "phases" and len(loc) in (2, 3) and isinstance(loc[1], int):
        try:
            kind = table["phases"][loc[1]].get("kind", "joint")
        except (KeyError, IndexError, TypeError, AttributeError):
            return None
        model = PHASE_KINDS.get(kind) if isinstance(kind, str) else None
        if len(loc) == 3:  # a phase's own table: its weave
            weaves = model is not None and loc[2] == "weave" and "weave" in model.model_fields
            return WeaveSpec if weaves else None
        return model
    if head == "actions" and len(loc) == 2:
        return ActionSpec
    if root is not ScenarioSpec:
        return None
    if head == "drives" and len(loc) == 2:
        return DriveOverrideSpec
    if len(loc) == 1:  # a table of the top level: [simulation], [video], [sizing], [expect]
        return model_at(root, loc)
    return None


__all__ = ["load_scenario", "parse_scenario", "resolve_scenario"]
