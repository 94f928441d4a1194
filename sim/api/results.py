"""The typed result of a run: :class:`RunResult` and the records it holds.

A :class:`RunResult` is what :func:`sim.evaluate` and :func:`sim.run` return and what
:meth:`RunResult.load` reads back from a finished run folder. Its fields are the run's
``summary.json`` (and ``sizing.json``) in typed form: the verdict, every check, collisions,
saturation intervals, every robot's welds (:class:`WeldResult`; :class:`RobotResult` per robot
of a cell with several), per-joint sizing and the actuator selection, the cell's mechanisms
(positioners, turntables, tracks: what they carry, their axes' travel), the stage timings; the
recorded arrays come from memory, or from ``trajectory.npz`` on first use for a loaded run.
``to_dict()`` gives ``summary.json``'s content back unchanged.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, cast

from numpy.typing import NDArray

from sim.analysis.verdict import RunCheck
from sim.errors import RunFolderError

#: One check of the verdict (``summary.json``'s ``"checks"``): ``name``, ``joint``,
#: ``subject``, ``value`` against ``limit`` in ``unit``, ``passed``, ``severity``.
Check = RunCheck

Verdict = Literal["pass", "fail"]


@dataclass(frozen=True)
class Collision:
    """A collision interval: two bodies touching from ``t0`` to ``t1`` (s), deepest at
    ``t_worst`` by ``depth_mm``; ``kind`` is ``"robot-cell"``, ``"self"``, ... as in
    ``summary.json``."""

    t0: float
    t1: float
    phase: str
    kind: str
    bodies: tuple[str, str]
    depth_mm: float
    t_worst: float

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Collision:
        a, b = d["bodies"]
        return cls(float(d["t0"]), float(d["t1"]), str(d["phase"]), str(d.get("kind", "")),
                   (str(a), str(b)), float(d["depth_mm"]), float(d.get("t_worst", d["t0"])))


@dataclass(frozen=True)
class Saturation:
    """An interval in which a joint's drive could not give what its servo asked for: the
    worst excess of the demand over the drive's limit, N m."""

    joint: str
    t0: float
    t1: float
    phase: str
    worst_excess_nm: float

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Saturation:
        return cls(str(d["joint"]), float(d["t0"]), float(d["t1"]), str(d.get("phase", "")),
                   float(d["worst_excess_nm"]))


@dataclass(frozen=True)
class SizingCheck:
    """One sizing limit of a joint: ``used`` against ``limit`` in ``unit``, from the source
    (``"id"``: inverse dynamics of the reference, ``"sim"``: the simulation) that was worse,
    at ``time_s`` (None for a whole-cycle figure such as an RMS)."""

    key: str
    title: str
    used: float
    limit: float
    unit: str
    margin_pct: float
    passed: bool
    source: str
    time_s: float | None

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> SizingCheck:
        return cls(str(d["key"]), str(d.get("title", d["key"])), _num(d["used"]),
                   _num(d["limit"]), str(d.get("unit", "")), _num(d["margin_pct"]),
                   bool(d["passed"]), str(d.get("source", "")),
                   None if d.get("time") is None else float(d["time"]))


@dataclass(frozen=True)
class SizedJoint:
    """One joint's actuator sizing (``sizing.json``'s ``"joints"`` entry).

    The peak and RMS figures are the worse of the sources sizing was asked to use (its
    ``basis``: both the inverse dynamics and the simulation by default), joint side in N m and
    rad/s, motor side in N m and rpm (None for a joint without drive data). A prismatic joint
    (``kind``: a track's axis) has its joint-side figures in :attr:`torque_unit` ``"N"`` and
    :attr:`speed_unit` ``"m/s"`` (the ``_nm`` and ``_rad_s`` fields hold them).
    """

    joint: str
    passed: bool
    margin_pct: float
    limiting: str | None
    saturated: bool
    torque_range_nm: tuple[float, float]
    peak_torque_nm: float
    rms_torque_nm: float
    peak_speed_rad_s: float
    motor_peak_torque_nm: float | None
    motor_rms_torque_nm: float | None
    motor_peak_speed_rpm: float | None
    checks: tuple[SizingCheck, ...]
    kind: str = "revolute"

    @property
    def torque_unit(self) -> str:
        """``"N m"``, or ``"N"`` for a prismatic joint."""
        return "N" if self.kind == "prismatic" else "N m"

    @property
    def speed_unit(self) -> str:
        """``"rad/s"``, or ``"m/s"`` for a prismatic joint."""
        return "m/s" if self.kind == "prismatic" else "rad/s"

    def check(self, key: str) -> SizingCheck | None:
        """The check ``key`` (``"joint_torque"``, ``"motor_rms_torque"``, ...), or None."""
        return next((c for c in self.checks if c.key == key), None)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], basis: str = "worst") -> SizedJoint:
        def worst(sides: Mapping[str, Mapping[str, Any]], key: str) -> float | None:
            values = [abs(_num(s[key])) for name, s in sides.items()
                      if (basis == "worst" or name == basis) and s.get(key) is not None]
            return max(values) if values else None

        joint_side = d.get("joint_side", {})
        motor_side = d.get("motor_side", {})
        lo, hi = d.get("torque_range_nm", [-math.inf, math.inf])
        return cls(
            joint=str(d["joint"]), passed=bool(d["pass"]), margin_pct=_num(d["margin_pct"]),
            limiting=d.get("limiting"), saturated=bool(d.get("saturated", False)),
            torque_range_nm=(-math.inf if lo is None else float(lo), _num(hi)),
            peak_torque_nm=worst(joint_side, "peak_torque") or 0.0,
            rms_torque_nm=worst(joint_side, "rms_torque") or 0.0,
            peak_speed_rad_s=worst(joint_side, "peak_speed") or 0.0,
            motor_peak_torque_nm=worst(motor_side, "peak_torque"),
            motor_rms_torque_nm=worst(motor_side, "rms_torque"),
            motor_peak_speed_rpm=worst(motor_side, "peak_speed_rpm"),
            checks=tuple(SizingCheck.from_dict(c) for c in d.get("checks", [])),
            kind=str(d.get("kind", "revolute")))


@dataclass(frozen=True)
class MechanismAxis:
    """One axis of a mechanism over the run (``summary.json``'s
    ``mechanisms[<name>]["axes"][<axis>]``): its ``kind`` (``"revolute"`` or ``"prismatic"``),
    the ``unit`` of the figures (``"deg"`` for a revolute axis, ``"mm"`` for a prismatic one),
    the recorded travel ``min`` and ``max``, and the largest recorded speed ``max_speed`` (in
    ``unit``/s)."""

    name: str
    kind: Literal["revolute", "prismatic"]
    unit: Literal["deg", "mm"]
    min: float
    max: float
    max_speed: float

    @property
    def travel(self) -> float:
        """``max - min``, in :attr:`unit`."""
        return self.max - self.min

    @classmethod
    def from_dict(cls, name: str, d: Mapping[str, Any]) -> MechanismAxis:
        kind, unit = str(d["kind"]), str(d["unit"])
        if (kind, unit) not in (("revolute", "deg"), ("prismatic", "mm")):
            raise ValueError(f"mechanism axis {name!r}: kind {kind!r} in unit {unit!r} (a "
                             "revolute axis is in deg, a prismatic one in mm)")
        return cls(name, cast(Literal["revolute", "prismatic"], kind),
                   cast(Literal["deg", "mm"], unit), float(d["min"]), float(d["max"]),
                   float(d["max_speed"]))


@dataclass(frozen=True)
class MechanismResult:
    """A turntable, positioner or track of the cell over the run (``summary.json``'s
    ``"mechanisms"`` entry).

    Attributes:
        name: The cell's name for it (its axes are ``<name>_<axis>``).
        kind: ``"turntable"``, ``"positioner"`` or ``"track"``.
        model: The mechanism's model (``motopos_d500``, or a file's name).
        carries: What is mounted on it: object names, ``"robot"`` for a robot on a track.
        carried_kg: The mass on its mount (what it carries), kg.
        rated_payload_kg: Its rated payload, kg.
        axes: Its axes by the cell's name (``positioner_tilt``), in chain order.
    """

    name: str
    kind: str
    model: str
    carries: tuple[str, ...]
    carried_kg: float
    rated_payload_kg: float
    axes: Mapping[str, MechanismAxis]

    @property
    def payload_ratio(self) -> float:
        """``carried_kg / rated_payload_kg`` (inf for a mechanism rated 0 kg)."""
        if self.rated_payload_kg <= 0:
            return math.inf
        return self.carried_kg / self.rated_payload_kg

    @classmethod
    def from_dict(cls, name: str, d: Mapping[str, Any]) -> MechanismResult:
        return cls(name=name, kind=str(d["kind"]), model=str(d["model"]),
                   carries=tuple(str(c) for c in d.get("carries", [])),
                   carried_kg=float(d["carried_kg"]),
                   rated_payload_kg=float(d["rated_payload_kg"]),
                   axes={str(a): MechanismAxis.from_dict(str(a), v)
                         for a, v in d.get("axes", {}).items()})


#: The name of a cell's first robot in :attr:`RunResult.robots` and :attr:`WeldResult.robot`
#: (its model's prefix; the cell's other robots have their own names, ``r2``).
FIRST_ROBOT = "robot"


@dataclass(frozen=True)
class WeldResult:
    """One weld phase of one robot (``summary.json``'s ``"weld"`` entry), measured on the
    simulated tool frames: along a seam, its progress and distance from the seam, the torch
    axis against the seam's commanded axis.

    Attributes:
        robot: The robot that welds it: :data:`FIRST_ROBOT` for the cell's first robot, else
            the cell's name for it (``r2``).
        phase: Its phase's name (the robot's own phases).
        seam: The seam's name, or None for a weld along a programmed path.
        set_speed_mm_s, travel_speed_mm_s, travel_speed_cv: The set and measured travel
            speed (cruise part), mm/s, and the measured speed's coefficient of variation.
        seam_length_mm: The seam's (or path's) length, mm.
        max_path_deviation_mm: The tool point's largest distance from the seam, mm, outside
            a polyline's corner zones.
        torch_angle_error_deg: The torch axis's largest angle from the commanded axis, deg,
            outside the corner zones; ``work_angle_error_deg``/``travel_angle_error_deg`` its
            parts (None off a seam).
        start_error_mm, end_error_mm: The first and last samples' distances from the seam's
            ends, mm.
        corner_path_deviation_mm: Inside the corner zones, the tool point's largest distance
            from the seam, mm (the blend's rounding); None without corners.
        corner_torch_excess_deg: Inside the corner zones, how far the torch swings out of its
            turn from one leg's commanded axis to the next, deg (the ``corner_torch`` check);
            None without corners.
    """

    robot: str
    phase: str
    seam: str | None
    set_speed_mm_s: float
    travel_speed_mm_s: float
    travel_speed_cv: float
    seam_length_mm: float
    max_path_deviation_mm: float
    torch_angle_error_deg: float
    work_angle_error_deg: float | None
    travel_angle_error_deg: float | None
    start_error_mm: float
    end_error_mm: float
    corner_path_deviation_mm: float | None = None
    corner_torch_excess_deg: float | None = None

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> WeldResult:
        def opt(key: str) -> float | None:
            return None if d.get(key) is None else float(d[key])

        def num(key: str) -> float:  # a figure an older run did not write: nan
            return math.nan if d.get(key) is None else float(d[key])

        return cls(robot=str(d.get("robot") or FIRST_ROBOT), phase=str(d["phase"]),
                   seam=None if d.get("seam") is None else str(d["seam"]),
                   set_speed_mm_s=num("set_speed_mm_s"),
                   travel_speed_mm_s=num("travel_speed_mm_s"),
                   travel_speed_cv=num("travel_speed_cv"), seam_length_mm=num("seam_length_mm"),
                   max_path_deviation_mm=num("max_path_deviation_mm"),
                   torch_angle_error_deg=num("torch_angle_error_deg"),
                   work_angle_error_deg=opt("work_angle_error_deg"),
                   travel_angle_error_deg=opt("travel_angle_error_deg"),
                   start_error_mm=num("start_error_mm"), end_error_mm=num("end_error_mm"),
                   corner_path_deviation_mm=opt("corner_path_deviation_mm"),
                   corner_torch_excess_deg=opt("corner_torch_excess_deg"))


@dataclass(frozen=True)
class RobotResult:
    """One robot of a cell with several (``summary.json``'s ``"robots"`` entry).

    Attributes:
        name: :data:`FIRST_ROBOT` for the cell's first robot, else the cell's name for it.
        model: Its robot model's name.
        tool: Its tool's name, or None.
        joints: Its joints' names in :attr:`RunResult.joints` (``r2_j1``, ...).
        phases: Its phases' names in order.
        t_end_s: When its last phase ends, s.
        max_tcp_deviation_mm: Its simulated tool point's largest distance from its reference,
            mm.
        welds: Its weld phases.
    """

    name: str
    model: str
    tool: str | None
    joints: tuple[str, ...]
    phases: tuple[str, ...]
    t_end_s: float
    max_tcp_deviation_mm: float
    welds: tuple[WeldResult, ...]

    @classmethod
    def from_dict(cls, name: str, d: Mapping[str, Any], welds: tuple[WeldResult, ...]
                  ) -> RobotResult:
        return cls(name=name, model=str(d["model"]),
                   tool=None if d.get("tool") is None else str(d["tool"]),
                   joints=tuple(str(j) for j in d["joints"]),
                   phases=tuple(str(p["name"]) for p in d.get("phases", [])),
                   t_end_s=float(d["t_end_s"]),
                   max_tcp_deviation_mm=float(d["max_tcp_deviation_mm"]),
                   welds=tuple(w for w in welds if w.robot == name))


@dataclass(frozen=True)
class SelectedDrive:
    """The motor and reducer chosen from a catalogue for one joint (both None when no pair of
    the catalogue serves it)."""

    joint: str
    motor: str | None
    reducer: str | None

    @property
    def served(self) -> bool:
        return self.motor is not None and self.reducer is not None


@dataclass
class RunResult:
    """A run's results (``summary.json`` typed), from :func:`sim.evaluate`, :func:`sim.run` or
    :meth:`RunResult.load`.

    Attributes:
        scenario: The scenario's name.
        robot: The robot's name.
        verdict: ``"pass"`` when every check of severity ``"error"`` passed, else ``"fail"``.
        checks: Every check of the verdict, in ``summary.json``'s order.
        warnings: How many checks of severity ``"warning"`` failed.
        joints: The robot's joint names, the columns of the joint arrays.
        duration_s: The cycle's duration, s.
        collisions: The collision intervals (empty when none).
        saturation: The drives' saturation intervals (empty when none).
        sizing: Per-joint actuator sizing by joint name (empty when sizing was off).
        sizing_passed: Whether sizing passed on every joint (None when sizing was off).
        selection: The chosen motor and reducer by joint name (empty unless a catalogue
            selection was asked for).
        mechanisms: The cell's turntables, positioners and tracks by name, in the cell's order
            (empty for a cell without any).
        timings_s: Wall time of each stage, s.
        path: The run folder (None for a run evaluated in memory).
        welds: Every robot's weld phases (:class:`WeldResult`; the first robot's first).
        robots: In a cell with other robots, each robot by name (:data:`FIRST_ROBOT` first):
            model, tool, joints, cycle end, its welds; empty for a cell with one robot.
    """

    scenario: str
    robot: str
    verdict: Verdict
    checks: tuple[Check, ...]
    warnings: int
    joints: tuple[str, ...]
    duration_s: float
    collisions: tuple[Collision, ...]
    saturation: tuple[Saturation, ...]
    sizing: Mapping[str, SizedJoint]
    sizing_passed: bool | None
    selection: Mapping[str, SelectedDrive]
    timings_s: Mapping[str, float]
    path: Path | None = None
    mechanisms: Mapping[str, MechanismResult] = field(default_factory=dict)
    welds: tuple[WeldResult, ...] = ()
    robots: Mapping[str, RobotResult] = field(default_factory=dict)
    _summary: dict[str, Any] = field(default_factory=dict, repr=False)
    _arrays: dict[str, NDArray[Any]] | None = field(default=None, repr=False)

    # ------------------------------------------------------------------------ derived views
    @property
    def passed(self) -> bool:
        """Whether the verdict is ``"pass"``."""
        return self.verdict == "pass"

    @property
    def failed_checks(self) -> tuple[Check, ...]:
        """The failed checks of severity ``"error"`` (the reasons of a ``"fail"``)."""
        return tuple(c for c in self.checks if not c.passed and c.severity == "error")

    @property
    def warning_checks(self) -> tuple[Check, ...]:
        """The failed checks of severity ``"warning"`` (``warnings`` counts them)."""
        return tuple(c for c in self.checks if not c.passed and c.severity == "warning")

    @property
    def arrays(self) -> Mapping[str, NDArray[Any]]:
        """The recorded arrays by name (``t``, ``q``, ``qd``, ``tau``, ``tcp_pos``, ...; see
        :mod:`sim.simulation.runfolder`): every simulated sample for a run in memory, what
        ``trajectory.npz`` kept (at the scenario's ``record_hz``) for a loaded run, read and
        validated on first use.

        Raises:
            RunFolderError: The loaded run's ``trajectory.npz`` or ``model.xml`` is damaged.
        """
        if self._arrays is None:
            if self.path is None:
                raise RunFolderError("this result has no recorded arrays")
            from sim.simulation.runfolder import load_run

            self._arrays = load_run(self.path).arrays
        return self._arrays

    def welds_of(self, robot: str = FIRST_ROBOT) -> tuple[WeldResult, ...]:
        """The weld phases of one robot (:data:`FIRST_ROBOT`: the cell's first)."""
        return tuple(w for w in self.welds if w.robot == robot)

    def to_dict(self) -> dict[str, Any]:
        """``summary.json``'s content (a deep copy)."""
        return copy.deepcopy(self._summary)

    # ---------------------------------------------------------------------------- builders
    @classmethod
    def from_summary(cls, summary: Mapping[str, Any], sizing: Mapping[str, Any] | None = None,
                     *, path: Path | None = None,
                     arrays: dict[str, NDArray[Any]] | None = None) -> RunResult:
        """A result from a ``summary.json`` dict and a ``sizing.json`` dict (None without
        sizing).

        Raises:
            RunFolderError: The summary lacks a key every run writes, or holds a wrong type.
        """
        where = f"run folder {str(path)!r}: summary.json" if path is not None else "summary"
        try:
            verdict = str(summary["verdict"])
            if verdict not in ("pass", "fail"):
                raise ValueError(f"verdict {verdict!r}")
            checks = tuple(Check(name=str(c["name"]), joint=str(c.get("joint", "")),
                                 value=_num(c["value"]), limit=_num(c["limit"]),
                                 unit=str(c.get("unit", "")), passed=bool(c["pass"]),
                                 severity=str(c.get("severity", "error")),
                                 subject=str(c.get("subject", "")))
                           for c in summary["checks"])
            basis = str(sizing.get("basis", "worst")) if sizing else "worst"
            sized = ({str(j["joint"]): SizedJoint.from_dict(j, basis)
                      for j in sizing.get("joints", [])} if sizing else {})
            chosen = (summary.get("selection") or {}).get("joints", {})
            welds = tuple(WeldResult.from_dict(w) for w in summary.get("weld", []))
            return cls(
                scenario=str(summary["scenario"]), robot=str(summary.get("robot", "")),
                verdict=cast(Verdict, verdict), checks=checks,
                warnings=int(summary.get("warnings", 0)),
                joints=tuple(str(j) for j in summary["joints"]),
                duration_s=float(summary["duration_s"]),
                collisions=tuple(Collision.from_dict(c) for c in summary.get("collisions", [])),
                saturation=tuple(Saturation.from_dict(s)
                                 for s in summary.get("saturation", [])),
                sizing=sized,
                sizing_passed=None if not sizing else bool(sizing.get("pass")),
                selection={str(j): SelectedDrive(str(j), d.get("motor"), d.get("reducer"))
                           for j, d in chosen.items()},
                timings_s={str(k): float(v) for k, v in summary.get("timings_s", {}).items()},
                mechanisms={str(n): MechanismResult.from_dict(str(n), m)
                            for n, m in summary.get("mechanisms", {}).items()},
                welds=welds,
                robots={str(n): RobotResult.from_dict(str(n), r, welds)
                        for n, r in summary.get("robots", {}).items()},
                path=path, _summary=dict(summary), _arrays=arrays)
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise RunFolderError(f"{where}: not a finished run's summary "
                                 f"({type(exc).__name__}: {exc})") from None

    @classmethod
    def from_evaluation(cls, evaluation: Any, path: Path | None = None) -> RunResult:
        """A result from an in-memory :class:`~sim.pipeline.run.Evaluation`."""
        sizing = evaluation.sizing.to_dict() if evaluation.sizing is not None else None
        return cls.from_summary(evaluation.summary, sizing, path=path,
                                arrays=evaluation.record.arrays)

    @classmethod
    def load(cls, path: str | Path) -> RunResult:
        """A finished run folder's result (``summary.json`` and ``sizing.json`` read now, the
        arrays on first use of :attr:`arrays`).

        Raises:
            RunFolderError: Not a finished run folder, or a damaged ``summary.json``.
        """
        from sim.core.arguments import path_argument
        from sim.simulation import runfolder

        folder = path_argument(path, "path", error=RunFolderError)
        where = f"run folder {str(folder)!r}"
        if not folder.is_dir():
            raise RunFolderError(f"{where} does not exist or is not a folder", file=str(folder))
        if runfolder.marker_state(folder) == "writing":
            raise RunFolderError(f"{where} is a run that was still being written, not a result",
                                 file=str(folder))
        summary = runfolder.read_run_json(folder, runfolder.SUMMARY_JSON)
        if summary is None:
            raise RunFolderError(f"{where} has no summary.json (not a finished run)",
                                 file=str(folder))
        sizing = runfolder.read_run_json(folder, runfolder.SIZING_JSON)
        return cls.from_summary(summary, sizing, path=folder)


def _num(value: Any) -> float:
    """A JSON number (``null`` stands for an infinite limit or margin in cellsim's files)."""
    return math.inf if value is None else float(value)
