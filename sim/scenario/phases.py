"""A scenario's phases built from their file entries, in SI units: joint phases (knots in any of
the file's units, boundary conditions, knot times checked), Cartesian phases (lines, arcs and
seams, with their weave) and the checks between phases (continuity, the seams' contact-tip
distance)."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planners.errors import PlannerError
from planners.weave import Weave
from sim.core.rotations import euler_zyx_to_matrix
from sim.errors import CellsimError, ScenarioError
from sim.robots.maker import from_maker
from sim.robots.registry import RobotSpec
from sim.scenario.model import CartesianPhase, JointPhase, Phase, PoseTarget
from sim.scenario.schema import (
    _BOUNDARY_KEYS,
    CircularPhaseSpec,
    JointPhaseSpec,
    LinearPhaseSpec,
    ScenarioSpec,
)

#: Knot times and segment durations a joint phase may have, s: a segment from a microsecond
#: to 10^6 s (11.6 days; a run is bounded far below by its step count), knot times within
#: 10^6 s of 0. Outside them the knot system's powers of the durations overflow or vanish.
MIN_SEGMENT_S, MAX_TIME_S = 1e-6, 1e6


def check_times(times: np.ndarray, durations: np.ndarray, key: str) -> None:
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


def build_joint_phase(index: int, spec: JointPhaseSpec, robot: RobotSpec, where: str) -> JointPhase:
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
        check_times(times, durations, f"{where}.time_s")
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
        check_times(np.zeros(1), durations, f"{where}.durations_s")

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
    if spec.downhand and (target is None or target.seam is None):
        raise ScenarioError(f"{where}.downhand: goes with to_seam (the seam to weld downhand)")
    return JointPhase(index=index, name=spec.name, planner=spec.planner, times=times,
                      durations=durations, q=q, boundary=boundary, target=target,
                      blend=math.radians(spec.blend_deg or 0.0),
                      axes=_axes_values(spec.axes or {}), downhand=spec.downhand)


def _axes_values(values: dict[str, float]) -> dict[str, float]:
    """A joint phase's ``axes`` in SI, by axis name (the unit suffix dropped; the names and
    units are checked against the cell by :func:`check_axes`)."""
    out = {}
    for key, v in values.items():
        name, _, unit = key.rpartition("_")
        out[key] = float(v)
        out[name] = float(math.radians(v) if unit == "deg" else v * 1e-3)
        del out[key]
    return out


def check_axes(spec_values: dict[str, float] | None, axes: dict[str, tuple[str, tuple[float, float]]],
               where: str) -> None:
    """Check a joint phase's ``axes`` table against the cell's external axes
    (``name -> (kind, range)``): known names, the unit of each axis's kind, within range.

    Raises:
        ScenarioError: One line naming ``<phase>.axes.<key>``.
    """
    for key, v in (spec_values or {}).items():
        name, _, unit = key.rpartition("_")
        if name not in axes:
            valid = [f"{n}_{'deg' if k == 'revolute' else 'mm'}" for n, (k, _) in axes.items()]
            hint = ", ".join(valid) if valid else "none: the cell has no mechanisms"
            raise ScenarioError(f"{where}.axes.{key}: no such external axis; the cell's: {hint}")
        kind, (lo, hi) = axes[name]
        want = "deg" if kind == "revolute" else "mm"
        if unit != want:
            raise ScenarioError(f"{where}.axes.{key}: axis {name!r} is {kind}; give {name}_{want}")
        value = math.radians(v) if unit == "deg" else v * 1e-3
        if not (math.isfinite(value) and lo - 1e-12 <= value <= hi + 1e-12):
            scale = math.degrees(1.0) if unit == "deg" else 1e3
            raise ScenarioError(f"{where}.axes.{key}: {v!r} is outside the axis's range "
                                f"[{lo * scale:g}, {hi * scale:g}] {unit}")


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


def with_ctwd(phases: list[Phase], spec: ScenarioSpec, tool: Any, where: str) -> list[Phase]:
    """The phases with the stand-off of each weld phase that gives ``ctwd_mm``: that distance
    less the torch's nominal stick-out (:mod:`sim.cells.seam`).

    Raises:
        ScenarioError: ``ctwd_mm`` without a seam, without a torch, or shorter than the torch's
            nominal stick-out (its modelled wire would reach into the work).
    """
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


def build_cartesian_phase(index: int, spec: LinearPhaseSpec | CircularPhaseSpec,
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
    if (spec.downhand or spec.follow is not None) and spec.seam is None:
        key = "downhand" if spec.downhand else "follow"
        raise ScenarioError(f"{where}.{key}: goes with seam (coordinated motion along a seam)")
    common = dict(index=index, name=spec.name, kind=spec.kind, planner=spec.planner,
                  speed=spec.speed_mm_s * 1e-3, sample_period=spec.sample_period_s,
                  ramp=spec.ramp_s, orientation=spec.orientation, seam=spec.seam,
                  euler_zyx=None if spec.euler_zyx_deg is None
                  else np.deg2rad(np.asarray(spec.euler_zyx_deg, dtype=float)),
                  frame=spec.frame, blend=(spec.blend_mm or 0.0) * 1e-3,
                  weave=_weave(spec, where), downhand=spec.downhand, follow=spec.follow)
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


def check_continuity(prev: JointPhase, phase: JointPhase, where: str, robot: RobotSpec) -> None:
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


__all__ = ["MAX_TIME_S", "MIN_SEGMENT_S", "build_cartesian_phase", "build_joint_phase",
           "check_continuity", "check_times", "with_ctwd"]
