"""Scenario files: loading, validation and planning.

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
import hashlib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from planners.errors import PlannerError
from sim.errors import ScenarioError, UnknownNameError
from sim.resources import shipped_scenarios
from sim.robots import RobotSpec, get_robot

# --------------------------------------------------------------------------------------------
# Declared structure (what the file may contain)
# --------------------------------------------------------------------------------------------

_NAME_PATTERN = r"^[A-Za-z0-9_.-]+$"

#: Boundary-condition keys of a joint phase: (quantity, end, unit suffix) -> planner keyword.
_BOUNDARY_KEYS: dict[str, tuple[str, float]] = {}
for _end, _kw in (("start", "0"), ("end", "f")):
    for _qty, _sym, _order in (("velocity", "v", 1), ("acceleration", "a", 2), ("jerk", "j", 3)):
        _unit = "_s" if _order == 1 else f"_s{_order}"
        _BOUNDARY_KEYS[f"{_end}_{_qty}_deg{_unit}"] = (f"{_sym}{_kw}", math.pi / 180.0)
        _BOUNDARY_KEYS[f"{_end}_{_qty}_rad{_unit}"] = (f"{_sym}{_kw}", 1.0)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


class JointPhaseSpec(_Strict):
    """A joint-space phase: via points at absolute times, joined by a piecewise polynomial."""

    name: str = Field(pattern=_NAME_PATTERN, description="phase name, unique in the scenario")
    kind: Literal["joint"] = Field("joint", description='phase kind: "joint"')
    planner: Literal["434", "546"] = Field(description='"434" (seed 001) or "546" (seed 000)')
    time_s: list[float] = Field(description="absolute knot times, s, strictly increasing")
    joints_deg: list[list[float]] | None = Field(None, description="one row per knot, deg")
    joints_rad: list[list[float]] | None = Field(None, description="one row per knot, rad")
    start_velocity_deg_s: list[float] | None = None
    start_velocity_rad_s: list[float] | None = None
    end_velocity_deg_s: list[float] | None = None
    end_velocity_rad_s: list[float] | None = None
    start_acceleration_deg_s2: list[float] | None = None
    start_acceleration_rad_s2: list[float] | None = None
    end_acceleration_deg_s2: list[float] | None = None
    end_acceleration_rad_s2: list[float] | None = None
    start_jerk_deg_s3: list[float] | None = None
    start_jerk_rad_s3: list[float] | None = None
    end_jerk_deg_s3: list[float] | None = None
    end_jerk_rad_s3: list[float] | None = None
    note: str | None = Field(None, description="free text (e.g. which seed value was chosen)")


class ScenarioSpec(_Strict):
    """Top level of a scenario file."""

    name: str = Field(pattern=_NAME_PATTERN, description="scenario name")
    description: str = Field(description="one paragraph shown by `cellsim list`")
    robot: str = Field(description="robot name (`cellsim list` shows them)")
    note: str | None = Field(None, description="free text: sources, choices made")
    phases: list[JointPhaseSpec] = Field(min_length=1, description="the work cycle, in order")


# --------------------------------------------------------------------------------------------
# Validated, SI-unit result
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class JointPhase:
    """A validated joint-space phase in SI units.

    Attributes:
        index: Position of the phase in the scenario (0-based).
        name: Phase name.
        planner: ``"434"`` or ``"546"``.
        times: Knot times, s, shape (m+1,).
        q: Knot values, rad, shape (m+1, n_joints).
        boundary: Planner keywords (``v0``, ``vf``, ``a0``, ``af``, ``j0``, ``jf``) with arrays
            of shape (n_joints,) in rad/s^k; absent keys default to 0 in the planner.
    """

    index: int
    name: str
    planner: str
    times: NDArray[np.float64]
    q: NDArray[np.float64]
    boundary: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    kind: str = "joint"

    @property
    def t0(self) -> float:
        return float(self.times[0])

    @property
    def t1(self) -> float:
        return float(self.times[-1])


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.

    Attributes:
        name: Scenario name.
        description: Free text.
        robot: The robot's registry entry.
        phases: Phases in order; consecutive phases meet in time and joint values.
        source: File the scenario came from.
        text: The file's text (copied into run folders, hashed into manifests).
    """

    name: str
    description: str
    robot: RobotSpec
    phases: tuple[JointPhase, ...]
    source: Path
    text: str

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.text.encode()).hexdigest()

    @property
    def duration(self) -> float:
        return self.phases[-1].t1 - self.phases[0].t0


# --------------------------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------------------------


def resolve_scenario(ref: str | Path) -> Path:
    """Path of a scenario given as a file path or as a shipped scenario's name.

    Raises:
        UnknownNameError: Neither an existing file nor a shipped scenario; lists the shipped ones.
    """
    path = Path(ref)
    if path.is_file():
        return path
    shipped = shipped_scenarios()
    if str(ref) in shipped:
        return shipped[str(ref)]
    if path.suffix == ".toml" or path.parent != Path("."):
        raise ScenarioError(f"{ref}: no such scenario file")
    raise UnknownNameError("scenario", str(ref), shipped)


def load_scenario(ref: str | Path) -> Scenario:
    """Load and validate a scenario file (path or shipped name).

    Raises:
        ScenarioError: Unreadable or malformed file, or inconsistent content; one line naming
            the file and the key.
        UnknownNameError: Unknown scenario name or robot.
    """
    path = resolve_scenario(ref)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"{path}: cannot read scenario file ({exc})") from None
    return parse_scenario(text, source=path)


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
        robot = get_robot(spec.robot)
    except UnknownNameError as exc:
        raise ScenarioError(f"{where}: robot: {exc}") from None

    phases: list[JointPhase] = []
    seen: dict[str, int] = {}
    for i, pspec in enumerate(spec.phases):
        key = f"phases[{i}]"
        if pspec.name in seen:
            raise ScenarioError(
                f"{where}: {key}.name: {pspec.name!r} is already the name of phases[{seen[pspec.name]}]")
        seen[pspec.name] = i
        phase = _build_joint_phase(i, pspec, robot, f"{where}: {key}")
        if phases:
            _check_continuity(phases[-1], phase, f"{where}: {key}", robot)
        phases.append(phase)
    return Scenario(
        name=spec.name,
        description=spec.description,
        robot=robot,
        phases=tuple(phases),
        source=Path(source),
        text=text,
    )


def _build_joint_phase(index: int, spec: JointPhaseSpec, robot: RobotSpec, where: str) -> JointPhase:
    times = np.asarray(spec.time_s, dtype=float)
    if times.size < 3:
        raise ScenarioError(
            f"{where}.time_s: {times.size} knot time(s) given; a {spec.planner} phase needs at "
            "least 3 (start, one via point, end)")
    steps = np.diff(times)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0)) + 1
        raise ScenarioError(
            f"{where}.time_s: knot times must increase (index {k}: {times[k]:g} s after "
            f"{times[k - 1]:g} s)")

    if (spec.joints_deg is None) == (spec.joints_rad is None):
        raise ScenarioError(f"{where}: give exactly one of joints_deg or joints_rad")
    key, rows, scale = (("joints_deg", spec.joints_deg, math.pi / 180.0) if spec.joints_deg is not None
                        else ("joints_rad", spec.joints_rad, 1.0))
    assert rows is not None
    if len(rows) != times.size:
        raise ScenarioError(
            f"{where}.{key}: {len(rows)} rows for {times.size} knot times; give one row per time")
    n = robot.n_joints
    for r, row in enumerate(rows):
        if len(row) != n:
            raise ScenarioError(
                f"{where}.{key}[{r}]: {len(row)} values; robot {robot.name} has {n} joints "
                f"({', '.join(robot.joints)})")
    q = np.asarray(rows, dtype=float) * scale

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
    return JointPhase(index=index, name=spec.name, planner=spec.planner, times=times, q=q,
                      boundary=boundary)


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
    """One line for the first pydantic error: dotted key path and what is wrong."""
    errors = exc.errors(include_url=False)
    # A misspelt key also makes the right key "missing": report the unknown key first.
    err = min(errors, key=lambda e: e["type"] != "extra_forbidden")
    loc = err["loc"]
    path = _format_loc(loc)
    kind = err["type"]
    if kind == "extra_forbidden":
        parent_model = _model_at(loc[:-1], raw)
        valid = sorted(parent_model.model_fields) if parent_model else []
        close = difflib.get_close_matches(str(loc[-1]), valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{path}: unknown key{hint}; valid keys: {', '.join(valid)}"
    if kind == "missing":
        return f"{path}: required key is missing"
    if kind == "finite_number":
        return f"{path}: must be a finite number (NaN and inf are not allowed)"
    msg = err["msg"]
    if kind == "literal_error":
        msg = msg.replace("Input should be", "must be")
    elif kind in ("float_type", "int_type", "string_type", "list_type", "bool_type", "model_type"):
        expected = {"float_type": "a number", "int_type": "an integer", "string_type": "a string",
                    "list_type": "an array", "bool_type": "true or false",
                    "model_type": "a table"}[kind]
        msg = f"must be {expected}, got {_toml_type(err.get('input'))}"
    return f"{path}: {msg}"


def _format_loc(loc: tuple[Any, ...]) -> str:
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "(top level)"


def _model_at(loc: tuple[Any, ...], raw: Any) -> type[BaseModel] | None:
    """The pydantic model class that validates the table at ``loc`` (for key suggestions)."""
    model: type[BaseModel] | None = ScenarioSpec
    for part in loc:
        if isinstance(part, int):
            continue
        if model is None:
            return None
        if model is ScenarioSpec and part == "phases":
            model = JointPhaseSpec
        else:
            return None
    return model


def _toml_type(value: Any) -> str:
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, str):
        return f"the string {value!r}"
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return type(value).__name__


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
    from planners.registry import get_planner

    try:
        return get_planner(phase.planner)(phase.times, phase.q, **phase.boundary)
    except PlannerError as exc:
        prefix = f"{where}: " if where else ""
        raise ScenarioError(f"{prefix}phases[{phase.index}] ({phase.name}): {exc}") from None


def plan_scenario(scenario: Scenario) -> list[PlannedPhase]:
    """Plan every phase of a scenario, in order."""
    where = scenario.source.name
    return [PlannedPhase(p, plan_phase(p, where)) for p in scenario.phases]
