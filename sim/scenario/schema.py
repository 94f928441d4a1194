"""The scenario file's declared schema: every key, its type and its unit.

The structure is declared once, with pydantic models, so that unknown keys, wrong types and NaN
are rejected with one line naming the key; the format reference (``docs/scenario-format.md``)
documents the same keys and a test keeps the two in step. Keys carry their units in their names
(``joints_deg``, ``points_mm``, ``speed_mm_s``); :mod:`sim.scenario.loader` converts them to SI.
Planner names come from the planner registry (``planners.registry.PLANNERS``).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Union

from pydantic import AfterValidator, BaseModel, ConfigDict, Discriminator, Field, Tag

from planners.registry import PLANNERS
from sim.core.text import PlainText
from sim.core.tomlschema import (
    EFFICIENCY,
    FPS,
    GEAR_RATIO,
    ROTOR_INERTIA_KG_M2,
    SPEED_RPM,
    TORQUE_NM,
)

#: Names (scenario, phases) are plain folder names: letters, digits, ``_ . -``, not starting
#: with a dot (``.`` and ``..`` would make the default run folder the working directory or
#: ``runs/`` itself).
_NAME_PATTERN = r"^[A-Za-z0-9_-][A-Za-z0-9_.-]*$"

#: Boundary-condition keys of a joint phase: (quantity, end, unit suffix) -> planner keyword.
_BOUNDARY_KEYS: dict[str, tuple[str, float]] = {}
for _end, _kw in (("start", "0"), ("end", "f")):
    for _qty, _sym, _order in (("velocity", "v", 1), ("acceleration", "a", 2), ("jerk", "j", 3)):
        _unit = "_s" if _order == 1 else f"_s{_order}"
        _BOUNDARY_KEYS[f"{_end}_{_qty}_deg{_unit}"] = (f"{_sym}{_kw}", math.pi / 180.0)
        _BOUNDARY_KEYS[f"{_end}_{_qty}_rad{_unit}"] = (f"{_sym}{_kw}", 1.0)


#: The largest payload a scenario or sweep takes, kg (the heaviest industrial robots carry
#: 2.3 t; 10^308 kg made the simulation blow up at its first step).
MAX_PAYLOAD_KG = 10_000.0


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, frozen=True)


Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
#: Planner names the schema accepts: the planner registry's (``planners.registry.PLANNERS``).
PlannerName = Literal[PLANNERS.names()]  # type: ignore[valid-type]


#: ``approach_mm`` / ``retract_mm`` of a phase that goes ``to_seam`` (joint or linear).
ApproachMm = Annotated[float | None, Field(ge=0, le=5000, description="with to_seam: stop this "
                                           "far before the seam's start, back along its torch "
                                           "axis, mm")]
RetractMm = Annotated[float | None, Field(ge=0, le=5000, description="with to_seam: go this far "
                                          "back from the seam's end along its torch axis, mm")]


class JointPhaseSpec(_Strict):
    """A joint-space phase: via points, joined by a piecewise polynomial."""

    name: str = Field(pattern=_NAME_PATTERN, description="phase name, unique in the scenario")
    kind: Literal["joint"] = Field("joint", description='phase kind: "joint"')
    planner: PlannerName = Field(description='"434" (seed 001) or "546" (seed 000)')
    time_s: list[float] | None = Field(None, description="absolute knot times, s")
    durations_s: list[float] | None = Field(None, description="segment durations, s")
    joints_deg: list[list[float]] | None = Field(None, description="one row per knot, deg")
    joints_rad: list[list[float]] | None = Field(None, description="one row per knot, rad")
    joints_maker_deg: list[list[float]] | None = Field(
        None, description="one row per knot, deg, in the maker's joint convention")
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
    to_mm: Vec3 | None = None
    to_seam: str | None = None
    approach_mm: ApproachMm = None
    retract_mm: RetractMm = None
    euler_zyx_deg: Vec3 | None = None
    frame: str = Field("frame0", description='frame of to_mm and euler_zyx_deg: "frame0", '
                       '"world" or a cell object')
    blend_deg: float | None = Field(None, ge=0, description="pass the last knot without "
                                    "stopping into the next joint phase, deg")
    axes: dict[str, float] | None = Field(None, description="external axes' values at the "
                                          "phase's end: <mechanism>_<axis>_deg or _mm")
    downhand: bool = Field(False, description="with to_seam: the positioner ends where the "
                           "seam's start is welded downhand")
    note: PlainText | None = Field(None, description="free text (e.g. which seed value was "
                                   "chosen)")


class WeaveSpec(_Strict):
    """A weave across the seam over a Cartesian phase (:mod:`planners.weave`)."""

    pattern: Literal["sine", "zigzag", "triangle", "circle"]
    amplitude_mm: float = Field(gt=0)
    frequency_hz: float | None = Field(None, gt=0, le=20)
    wavelength_mm: float | None = Field(None, gt=0)
    dwell_s: float = Field(0.0, ge=0)


#: The fastest a tool point may be asked to travel, mm/s: industrial arms reach a few m/s; a
#: larger value is a typo, and 1e308 overflowed the planner's arithmetic.
MAX_TCP_SPEED_MM_S = 10_000.0


class _CartesianSpec(_Strict):
    name: str = Field(pattern=_NAME_PATTERN)
    planner: PlannerName = "434"
    seam: str | None = None
    to_mm: Vec3 | None = None
    speed_mm_s: float = Field(gt=0, le=MAX_TCP_SPEED_MM_S)
    sample_period_s: float = Field(0.1, gt=0)
    ramp_s: float | None = Field(None, gt=0)
    euler_zyx_deg: Vec3 | None = None
    frame: str = Field("frame0", description='frame of the points, axis and euler_zyx_deg: '
                       '"frame0", "world" or a cell object')
    blend_mm: float | None = Field(None, ge=0, description="corner zone radius into the next "
                                   "Cartesian phase, mm (the tool does not stop)")
    weave: WeaveSpec | None = None
    ctwd_mm: float | None = Field(None, gt=0, le=100, description="with seam: the "
                                  "contact-tip-to-work distance of this pass, mm (default: "
                                  "the seam's)")
    downhand: bool = Field(False, description="with seam: the positioner carrying the seam "
                           "turns it so that its normal points up while it is welded")
    follow: str | None = Field(None, description="with seam: a track (its mechanism's name) "
                               "carries the robot along the seam")
    note: PlainText | None = None


class LinearPhaseSpec(_CartesianSpec):
    """A straight move of the tool point at constant speed (ADNIA, seed 003 eq. 1-7)."""

    kind: Literal["linear"]
    orientation: Literal["keep", "seam", "euler"] = "keep"
    to_seam: str | None = Field(None, description="end at a seam's start (or, with "
                                "retract_mm, back from its end) in its torch posture")
    approach_mm: ApproachMm = None
    retract_mm: RetractMm = None


class CircularPhaseSpec(_CartesianSpec):
    """A circular arc of the tool point at constant tangential speed (ADNIA, seed 003)."""

    kind: Literal["circular"]
    via_mm: Vec3 | None = None
    center_mm: Vec3 | None = None
    axis: Vec3 | None = None
    sweep_deg: float | None = None
    orientation: Literal["keep", "follow", "seam", "euler"] = "follow"


class HoldPhaseSpec(_Strict):
    """The robot holds its pose (e.g. while suction builds up, or to measure static torques)."""

    name: str = Field(pattern=_NAME_PATTERN)
    kind: Literal["hold"]
    duration_s: float = Field(gt=0)
    note: PlainText | None = None


def _phase_kind(value: Any) -> str | None:
    if isinstance(value, dict):
        kind = value.get("kind", "joint")
        return kind if isinstance(kind, str) else None
    return getattr(value, "kind", None)


PhaseSpec = Annotated[
    Union[
        Annotated[JointPhaseSpec, Tag("joint")],
        Annotated[LinearPhaseSpec, Tag("linear")],
        Annotated[CircularPhaseSpec, Tag("circular")],
        Annotated[HoldPhaseSpec, Tag("hold")],
    ],
    Discriminator(_phase_kind),
]
PHASE_KINDS: dict[str, type[BaseModel]] = {
    "joint": JointPhaseSpec, "linear": LinearPhaseSpec, "circular": CircularPhaseSpec,
    "hold": HoldPhaseSpec,
}


class ActionSpec(_Strict):
    """A tool action at a time: absolute ``time_s``, or at the start/end of a named phase."""

    action: Literal["arc_on", "arc_off", "suction_on", "suction_off"]
    time_s: float | None = None
    phase: str | None = None
    at: Literal["start", "end"] = "start"


class SimulationSpec(_Strict):
    """Simulation settings."""

    timestep_s: float | None = Field(None, gt=0, le=0.01)
    feedforward: bool = True
    settle_s: float = Field(0.0, ge=0)
    record_hz: float | None = Field(None, gt=0, le=1e6)
    enforce_speed_limits: bool = True
    enforce_accel_limits: bool = True
    motor_speed_limits: bool = True
    tracking_tolerance_deg: float = Field(0.1, gt=0, le=180)
    tracking_tolerance_mm: float = Field(0.5, gt=0, le=1000)
    torch_angle_tolerance_deg: float = Field(2.0, gt=0, le=180)
    clearance_mm: float = Field(5.0, ge=0, le=1000)


def _even_pixels(value: int | None) -> int | None:
    if value is not None and value % 2:
        raise ValueError(f"must be even for H.264 yuv420p, got {value} (try {value - 1} or "
                         f"{value + 1})")
    return value


#: A video tile's side, pixels: 16 to sim.render.frames.MAX_SIDE (a test keeps them equal),
#: even (yuv420p); refused when the scenario is read, as the command line's are before a run.
VideoSide = Annotated[int, Field(ge=16, le=8192), AfterValidator(_even_pixels)]


class VideoSpec(_Strict):
    """Default video settings (command-line flags override them)."""

    cameras: list[str] | None = Field(None, min_length=1)
    width: VideoSide | None = None
    height: VideoSide | None = None
    fps: FPS.type | None = None
    speed: float | None = Field(None, gt=0)


class DriveOverrideSpec(_Strict):
    """Drive-train values of one joint that replace the robot's defaults."""

    # the ranges of a robot file's [[drives]] (docs/robot-format.md)
    gear_ratio: GEAR_RATIO.type | None = None
    efficiency: EFFICIENCY.type | None = None
    rotor_inertia_kg_m2: ROTOR_INERTIA_KG_M2.type | None = None
    rated_torque_nm: TORQUE_NM.type | None = None
    peak_torque_nm: TORQUE_NM.type | None = None
    max_speed_rpm: SPEED_RPM.type | None = None


class SizingSpec(_Strict):
    """Actuator selection from catalogues (``cellsim size --select``, ``cellsim run --select``)."""

    select: bool = Field(False, description="choose motors and reducers on every run")
    catalog: str | None = Field(None, description="catalogue file, relative to the scenario "
                                                 "file (default: the shipped starter)")
    life_h: float = Field(20000.0, gt=0, description="reducer L10 life target, h")
    dwell_s: float = Field(0.0, ge=0, le=1e6, description="standstill after each cycle, s")
    rank: Literal["mass", "inertia", "margin"] = "mass"
    inertia_ratio_max: float = Field(10.0, gt=0, description="largest load-to-rotor inertia "
                                     "ratio a pair may have")
    inertia_ratio: Literal["error", "warning"] = Field(
        "error", description="a pair over inertia_ratio_max fails (error) or passes with a "
        "warning")


#: The kinds of finding ``cellsim check`` reports (:mod:`sim.pipeline.check`).
CheckFindingKind = Literal["reach", "limit", "singular", "collision"]


class ExpectSpec(_Strict):
    """What a run of the scenario is expected to give (``[expect]``): a scenario that documents
    a known failure (a published motion past a robot's limits, say) declares it here, with the
    reason; the tests read it. It changes no verdict and no exit code."""

    verdict: Literal["pass", "fail"] = Field("pass", description="the run's verdict")
    failed_checks: list[Annotated[str, Field(pattern=r"^[a-z_]+ \S+$")]] = Field(
        [], description='the checks of severity error the run fails, "name subject" '
        '(e.g. "speed j2")')
    check_findings: list[CheckFindingKind] = Field(
        [], description="the kinds of finding `cellsim check` reports")
    reason: PlainText | None = Field(None, description="why; required when anything is "
                                     "expected to fail")


class _WorkSpec(_Strict):
    """A robot's work: its phases or its TP program, and its tool actions (the top level's
    keys for the first robot, ``[robots.<name>]``'s for another)."""

    actions: list[ActionSpec] = []
    phases: list[PhaseSpec] = Field([], description="the work cycle, in order")
    program: str | None = Field(None, description="a FANUC TP program (.ls) to run instead "
                                "of phases, relative to the scenario file")
    program_frames: dict[str, str] = Field({}, description="user frame number -> cell object")
    program_registers: dict[str, list[float]] = Field(
        {}, description="position register number -> [X, Y, Z, W, P, R] (mm, deg)")
    program_weld_speed_mm_s: float | None = Field(None, gt=0, le=MAX_TCP_SPEED_MM_S,
                                                  description="the speed of the "
                                                  "program's WELD_SPEED moves, mm/s")


class RobotWorkSpec(_WorkSpec):
    """``[robots.<name>]``: the work of one of the cell's other robots (its phases or its TP
    program, its tool actions); the keys mean what they mean at the top level."""

    tool: str | None = Field(None, description="its tool (default: the cell file's for it)")


class ScenarioSpec(_WorkSpec):
    """Top level of a scenario file."""

    name: str = Field(pattern=_NAME_PATTERN, description="scenario name")
    description: PlainText = Field(description="one paragraph shown by `cellsim list`")
    robot: str = Field(description="robot name (`cellsim list` shows them)")
    note: PlainText | None = Field(None, description="free text: sources, choices made")
    cell: str | None = None
    tool: str | None = None
    mount: Literal["floor", "ceiling"] = "floor"
    payload_kg: float = Field(0.0, ge=0, le=MAX_PAYLOAD_KG, description="mass at the tool point, "
                              "kg (at most MAX_PAYLOAD_KG: the heaviest industrial robots "
                              "carry 2.3 t)")
    simulation: SimulationSpec = SimulationSpec()
    video: VideoSpec = VideoSpec()
    drives: dict[str, DriveOverrideSpec] = {}
    sizing: SizingSpec = SizingSpec()
    expect: ExpectSpec = Field(ExpectSpec(), description="what a run is expected to give "
                               "(a documented failure, with its reason)")
    robots: dict[str, RobotWorkSpec] = Field({}, description="the work of the cell's other "
                                             "robots, by name (a cell file's [[robots]])")
