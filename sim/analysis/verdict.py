"""The run's verdict: the checks a physically possible run passes, and pass or fail.

A simulation that tracks badly, saturates a drive, drives a joint past its speed or
acceleration limit, or oversteps a sizing limit is a result to report, not a pass. Each check
is per joint:

* ``tracking``: the largest joint tracking error, deg, against the scenario's
  ``simulation.tracking_tolerance_deg``;
* ``saturation``: the worst excess of the servo's demand over the drive's limit, N m, against
  0 (any saturation fails; the intervals are in ``summary["saturation"]``);
* ``range``: how far the simulated joint goes past its position range (the robot's MJCF, a
  mechanism's file), deg (mm for a linear axis), against the tracking tolerance (a reference at
  its limit may overshoot it by the servo's allowed error; beyond that the joint is on its hard
  stop: a drive too weak to hold the arm lets it fall there);
* ``speed``: the largest simulated joint speed, deg/s, against the robot's speed limit;
* ``acceleration``: the largest reference joint acceleration, deg/s^2, against the robot's
  acceleration limit (derived from its drive train, :mod:`sim.robots.accel_limits`);
* the sizing checks (:mod:`sim.analysis.sizing`: joint torque, motor RMS and peak torque,
  motor speed, torque-speed envelope), the joint speed excepted (it is ``speed`` above);
* ``collision``: one per collision interval (:mod:`sim.simulation.collisions`; ``subject``
  names the phase and the two bodies), the penetration in mm against 0; one passed check with
  value 0 when there is none;
* ``clearance`` (a *warning*): per phase, the smaller of the tool's and the arm's clearance to
  the cell, mm, against the scenario's ``simulation.clearance_mm``;
* ``cartesian_speed``: per Cartesian phase, how far the reference tool point's cruise speed is
  from the set speed, %, against 1 % (a phase sampled too coarsely for its move misses it;
  along a seam the speed is the progress along the seam, a weave's lateral motion left out);
* ``torch_angle``: per weld phase along a seam, the largest angle of the simulated torch axis
  from the seam's commanded axis (its work and travel angles at the nearest seam point, the
  corner zones left out: :func:`sim.simulation.metrics.measure_seam`), deg, against the
  scenario's ``simulation.torch_angle_tolerance_deg``;
* ``corner_torch``: per weld phase along a polyline seam with corner zones, how far the
  simulated torch swings out of its turn from one leg's commanded axis to the next inside
  them (``corner_torch_excess_deg``: 0 for a torch that turns steadily from the one to the
  other), deg, against the same tolerance: the corner zones are left out of ``torch_angle``,
  not out of the verdict;
* ``selection`` (when actuators were chosen from a catalogue, :mod:`sim.analysis.selection`):
  per joint, the chosen pair's smallest margin, %; fails when no pair serves the joint;
* ``payload``: the mass at the flange, the tool's, the scenario's payload and, for a gripper,
  the heaviest part of the cell (it carries each part in turn), kg, against the robot's rated
  payload (``[mass] payload_kg``; not checked for a robot that gives none): a robot carrying
  three times its rating is no result to size from;
* ``tool_payload``: for a tool with a rating (``max_payload_kg``: the vacuum gripper's is its
  40 N over twice a part's weight), the mass it holds (the scenario's payload and the
  heaviest part of the cell), kg, against that rating.
* ``part_placed``: in a cell with slots, per slot, how far the centre of its part (part k goes
  to slot k) ends from it, mm, against 5 mm (``summary["place_tolerance_mm"]``): a pick cycle
  that drops a part or never lifts it fails.

In a cell with other robots (``[[robots]]``) every check covers them too: their joints
(``r2_j1``...: tracking, saturation, speed, acceleration, sizing) and their Cartesian phases,
weld torch angles and weaves (``summary["weld"]`` etc. entries with ``"robot"``; the check's
subject starts with the robot's name).

``summary.json`` holds ``"checks"`` (each ``name``, ``joint`` ("" when the check is not a
joint's), ``subject``, ``value``, ``limit``, ``unit``, ``pass``, ``severity``) and
``"verdict"``: ``"pass"`` when every check of severity ``error`` passed, else ``"fail"``. A
failed warning does not fail the run; ``"warnings"`` counts them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.analysis.sizing import SizingResult
from sim.robots.registry import RobotSpec, joint_ranges

#: Largest deviation of a measured weave amplitude / frequency from the set value (warning), %.
WEAVE_AMPLITUDE_PCT = 2.0
WEAVE_FREQUENCY_PCT = 1.0


@dataclass(frozen=True)
class RunCheck:
    """One check: ``value`` against ``limit`` (both in ``unit``), of a joint or a ``subject``."""

    name: str
    joint: str
    value: float
    limit: float
    unit: str
    passed: bool
    severity: str = "error"
    subject: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "joint": self.joint, "subject": self.subject or self.joint,
                "value": self.value, "limit": self.limit, "unit": self.unit,
                "pass": self.passed, "severity": self.severity}


def run_checks(arrays: Mapping[str, NDArray[Any]], summary: Mapping[str, Any], spec: RobotSpec,
               tracking_tolerance_deg: float, sizing: SizingResult | None = None,
               clearance_mm: float = 5.0, selection: Any = None, *,
               torch_angle_tolerance_deg: float,
               flange_load_kg: tuple[float, float] | None = None,
               tool_load: tuple[str, float, float] | None = None,
               tracking_tolerance_mm: float = 0.5,
               partner_loads: Sequence[tuple[str, RobotSpec, float]] = (),
               held_part_kg: float = 0.0) -> list[RunCheck]:
    """Every check of a run (module docstring): joint by joint, then collisions, clearance,
    the Cartesian phases' speeds, the weld phases' torch angles, the weaves, the actuator
    selection when one was made, and the payload (``flange_load_kg``: the tool's mass and the
    scenario's payload, kg) with the heaviest part a gripper carries (``held_part_kg``)
    against the robot's rating, and the mass the tool holds against
    the tool's (``tool_load``: the tool's name, the mass it holds and its rating, kg), and each
    of a cell's other robots' tool against its rating (``partner_loads``: name, robot, kg)."""
    checks: list[RunCheck] = []
    if tool_load is not None:
        name, held, rating = tool_load
        checks.append(RunCheck("tool_payload", "", float(held), float(rating), "kg",
                               held <= rating * (1 + 1e-9),
                               subject=f"the {name} holds {held:g} kg, rated {rating:.3g} kg"))
    if flange_load_kg is not None and spec.payload_kg > 0:
        tool, payload = flange_load_kg
        load = float(tool) + float(payload) + float(held_part_kg)
        part = f" + part {held_part_kg:g} kg" if held_part_kg > 0 else ""
        checks.append(RunCheck("payload", "", load, float(spec.payload_kg), "kg",
                               load <= spec.payload_kg * (1 + 1e-9),
                               subject=f"tool {tool:g} kg + payload {payload:g} kg{part} on the "
                               f"{spec.name}, rated {spec.payload_kg:g} kg"))
    for name, robot, tool_kg in partner_loads:  # a cell's other robots carry their tools
        if robot.payload_kg > 0:
            checks.append(RunCheck("payload", "", float(tool_kg), float(robot.payload_kg), "kg",
                                   tool_kg <= robot.payload_kg * (1 + 1e-9),
                                   subject=f"{name}: tool {tool_kg:g} kg on the {robot.name}, "
                                   f"rated {robot.payload_kg:g} kg"))
    # a linear axis (a track's) in mm, N; a joint in deg, N m
    linear = np.array(spec.linear)
    scale = np.where(linear, 1e3, np.degrees(1.0))
    track = scale * np.max(np.abs(np.asarray(arrays["q"]) - arrays["q_ref"]), axis=0)
    speed = scale * np.max(np.abs(np.asarray(arrays["qd"])), axis=0)
    q = np.asarray(arrays["q"])
    rng = joint_ranges(spec)
    past = scale * np.maximum(np.max(q - rng[:, 1], axis=0), np.max(rng[:, 0] - q, axis=0))
    past = np.maximum(past, 0.0)
    accel = scale * np.max(np.abs(np.asarray(arrays["qdd_ref"])), axis=0)
    excess = {j: 0.0 for j in spec.joints}
    for s in summary.get("saturation", ()):
        excess[s["joint"]] = max(excess[s["joint"]], float(s["worst_excess_nm"]))
    for k, joint in enumerate(spec.joints):
        unit = "mm" if linear[k] else "deg"
        tol = float(tracking_tolerance_mm if linear[k] else tracking_tolerance_deg)
        checks.append(RunCheck("tracking", joint, float(track[k]), tol, unit,
                               bool(track[k] <= tol)))
        checks.append(RunCheck("range", joint, float(past[k]), tol, unit,
                               bool(past[k] <= tol)))
        checks.append(RunCheck("saturation", joint, excess[joint], 0.0,
                               "N" if linear[k] else "N m", excess[joint] <= 0.0))
        vmax = float(scale[k] * spec.max_speed[k])
        checks.append(RunCheck("speed", joint, float(speed[k]), vmax, f"{unit}/s",
                               bool(speed[k] <= vmax * (1 + 1e-9))))
        if spec.max_accel:
            amax = float(scale[k] * spec.max_accel[k])
            checks.append(RunCheck("acceleration", joint, float(accel[k]), amax, f"{unit}/s^2",
                                   bool(accel[k] <= amax * (1 + 1e-9))))
    checks += mechanism_checks(summary)
    if sizing is not None:
        for j in sizing.joints:
            for c in j.checks:
                if c.key == "joint_speed" or not np.isfinite(c.limit):
                    continue
                checks.append(RunCheck(c.key, j.joint, float(c.used), float(c.limit), c.unit,
                                       bool(c.passed)))
    checks += motion_checks(summary, clearance_mm)
    for c in summary.get("cartesian_speed", ()):
        dev = abs(float(c["deviation_pct"]))
        checks.append(RunCheck("cartesian_speed", "", dev, 1.0, "% off the set speed",
                               dev <= 1.0, subject=f"{_who(c)}{c['phase']}: "
                               f"{c['cruise_mm_s']:.4g} mm/s for {c['set_mm_s']:.4g} mm/s"))
    checks += torch_angle_checks(summary, torch_angle_tolerance_deg)
    checks += placement_checks(summary)
    for w in summary.get("weave", ()):
        # a weave the arm does not reproduce (too fast for the joints' polynomial or the
        # servos): warnings, the weld still ran
        for key, err, lim in (("weave_amplitude", w["amplitude_error_pct"], WEAVE_AMPLITUDE_PCT),
                              ("weave_frequency", w["frequency_error_pct"], WEAVE_FREQUENCY_PCT)):
            checks.append(RunCheck(key, "", abs(float(err)), lim, "% off the set value",
                                   abs(float(err)) <= lim, severity="warning",
                                   subject=f"{_who(w)}{w['phase']}: {w['amplitude_mm']:.3f} mm at "
                                   f"{w['frequency_hz']:.3f} Hz for {w['set_amplitude_mm']:.3f} "
                                   f"mm at {w['set_frequency_hz']:.3f} Hz"))
    if selection is not None:
        for j in selection.joints:
            pair = j.chosen or j.closest
            margin = pair.min_margin_pct if pair is not None else -100.0
            subject = (f"{j.joint}: {j.chosen.motor.id} + {j.chosen.reducer.id}" if j.chosen
                       else f"{j.joint}: {j.reason}")
            checks.append(RunCheck("selection", j.joint, float(margin), 0.0, "% margin",
                                   j.chosen is not None, subject=subject))
            # the chosen pair's warnings are the run's warnings (counted and listed with them)
            for c in (j.chosen.checks if j.chosen is not None else ()):
                if c.severity == "warning" and not c.passed:
                    checks.append(RunCheck(f"selection_{c.name}", j.joint, float(c.value),
                                           float(c.limit), c.unit, False, severity="warning",
                                           subject=f"{subject}"))
    return checks


def motion_checks(summary: Mapping[str, Any], clearance_mm: float) -> list[RunCheck]:
    """The ``collision`` checks (errors) and the per-phase ``clearance`` checks (warnings) of
    a summary's ``"collisions"`` and ``"clearance"`` (none when the summary has neither)."""
    checks: list[RunCheck] = []
    if "collisions" in summary:
        for c in summary["collisions"]:
            subject = f"{c['phase']}: {c['bodies'][0]} / {c['bodies'][1]} ({c['t0']:.3f}-{c['t1']:.3f} s)"
            checks.append(RunCheck("collision", "", float(c["depth_mm"]), 0.0, "mm", False,
                                   subject=subject))
        if not summary["collisions"]:
            checks.append(RunCheck("collision", "", 0.0, 0.0, "mm", True, subject="whole cycle"))
    for c in summary.get("clearance", ()):
        values = [v for v in (c.get("tool_mm"), c.get("arm_mm")) if v is not None]
        if not values:
            continue
        value = min(values)
        checks.append(RunCheck("clearance", "", float(value), float(clearance_mm), "mm",
                               bool(value >= clearance_mm), severity="warning",
                               subject=str(c["phase"])))
    return checks


def placement_checks(summary: Mapping[str, Any]) -> list[RunCheck]:
    """The ``part_placed`` checks (errors): one per slot of the summary's ``"place_error_mm"``
    (none for a cell without slots)."""
    tol = float(summary.get("place_tolerance_mm", 5.0))
    checks = []
    for k, err in enumerate(summary.get("place_error_mm", ())):
        checks.append(RunCheck("part_placed", "", float(err), tol, "mm", float(err) <= tol,
                               subject=f"part {k + 1} in slot {k + 1}"))
    return checks


#: A downhand weld's seam normal may be at most this far from vertical, deg.
DOWNHAND_TOLERANCE_DEG = 2.0


def mechanism_checks(summary: Mapping[str, Any]) -> list[RunCheck]:
    """Per mechanism (``summary["mechanisms"]``): ``mechanism_payload``, the mass it carries
    against its rating (a positioner's part and fixtures, a track's robot, kg); per downhand
    weld (``summary["weld"]``): ``downhand``, the largest angle of the seam's normal from
    vertical at the tool point, measured with the part where the recorded axes put it, against
    :data:`DOWNHAND_TOLERANCE_DEG`."""
    checks = []
    for name, m in summary.get("mechanisms", {}).items():
        carried, rated = float(m["carried_kg"]), float(m["rated_payload_kg"])
        if rated > 0:
            checks.append(RunCheck("mechanism_payload", "", carried, rated, "kg",
                                   carried <= rated * (1 + 1e-9),
                                   subject=f"{name} ({m['model']}) carries {carried:.4g} kg, "
                                   f"rated {rated:g} kg"))
    for w in summary.get("weld", ()):
        if w.get("downhand"):
            err = float(w["normal_from_vertical_deg"])
            checks.append(RunCheck("downhand", "", err, DOWNHAND_TOLERANCE_DEG, "deg",
                                   err <= DOWNHAND_TOLERANCE_DEG,
                                   subject=f"{_who(w)}{w['phase']}: seam {w['seam']} turned by "
                                   f"{w['carried_by']}"))
    return checks


def torch_angle_checks(summary: Mapping[str, Any], tolerance_deg: float) -> list[RunCheck]:
    """The ``torch_angle`` checks (errors): one per weld phase along a seam in the summary's
    ``"weld"``, its worst torch axis error outside the corner zones against ``tolerance_deg``;
    and a ``corner_torch`` check per such phase with corner zones, the torch's swing out of
    its turn inside them (``corner_torch_excess_deg``) against the same tolerance."""
    checks = []
    for w in summary.get("weld", ()):
        if w.get("seam") is None:
            continue
        err = float(w["torch_angle_error_deg"])
        at = "" if w["t_worst_angle_s"] is None else f" at {w['t_worst_angle_s']:.3f} s"
        checks.append(RunCheck(
            "torch_angle", "", err, float(tolerance_deg), "deg", err <= tolerance_deg,
            subject=f"{_who(w)}{w['phase']}: seam {w['seam']}, worst{at}; work angle up to "
            f"{w['work_angle_error_deg']:.3g} deg off, travel angle up to "
            f"{w['travel_angle_error_deg']:.3g} deg off"))
        excess = w.get("corner_torch_excess_deg")
        if excess is not None:
            checks.append(RunCheck(
                "corner_torch", "", float(excess), float(tolerance_deg), "deg",
                float(excess) <= tolerance_deg,
                subject=f"{_who(w)}{w['phase']}: seam {w['seam']}, the torch's swing out of its "
                "turn from one leg's axis to the next in the corner zones"))
    return checks


def _who(entry: Mapping[str, Any]) -> str:
    """``"<robot>: "`` for a summary entry of a cell with other robots (its ``"robot"``: the
    checks of every robot's welds, speeds and weaves name it), else ``""``."""
    return f"{entry['robot']}: " if entry.get("robot") else ""


def check_line(check: Mapping[str, Any]) -> str:
    """One failed check of ``summary.json`` in words: its name, what it is about, and its value
    against its limit; a drive's saturation as how far the demand went over the drive's limit
    (its limit is no torque over it), a collision as its depth (none is allowed), a joint's
    failed actuator selection as its closest pair's least margin (the limit is 0 % margin)."""
    who = check.get("subject") or check.get("joint") or ""
    head = f"{check['name']} {who}".rstrip()
    value, unit = float(check["value"]), check["unit"]
    if check["name"] == "saturation":
        return f"{head}: demand up to {value:.4g} {unit} over the drive's limit"
    if check["name"] == "collision":
        return f"{head}: {value:.1f} {unit} deep"
    if check["name"] == "range":
        return (f"{head}: {value:.4g} {unit} past the joint's position range (at most "
                f"{float(check['limit']):.4g} {unit})")
    if check["name"] == "selection":  # no pair passes: the closest pair's least margin
        return f"{head}; {value:.4g} {unit} at its worst"
    return f"{head}: {value:.4g} {unit} against the limit {float(check['limit']):.4g} {unit}"


def verdict(checks: Sequence[RunCheck]) -> str:
    """``"pass"`` when every check of severity ``error`` passed, else ``"fail"``."""
    return "pass" if all(c.passed for c in checks if c.severity == "error") else "fail"


def warnings_count(checks: Sequence[RunCheck]) -> int:
    """Number of failed warning checks."""
    return sum(1 for c in checks if c.severity == "warning" and not c.passed)
