"""Metrics of a simulated run: tracking, weld seams, placed parts, singularities; the summary.

Weld phases along a cell seam are measured from the recorded tool frames and the seam's own
geometry, never from the planner's trajectory (:func:`measure_seam`): a torch off the seam's
angles, a tool point off the seam, a weave that slows the progress all show in the figures.

A cell with other robots (``[[robots]]``, :attr:`Motion.lanes`): each robot's weld phases,
Cartesian speeds and weaves are measured exactly as the first robot's, on its own recorded tool
frames (``<name>_tcp_pos``/``_tcp_quat``, ``<name>_arc_on``), its own phases and the seams as its
tool follows them (``context.partners[name]``); their entries join ``summary["weld"]``,
``["cartesian_speed"]`` and ``["weave"]`` with ``"robot": "<name>"`` (the first robot's get
``"robot": "robot"``), and ``summary["robots"]`` gives each robot's model, tool, frame 0, joints,
phases, cycle end, tool point deviation, tracking errors and closest approach to a singularity
(a cell with one robot gets neither: its summary as before, key for key).

Owns which phases are measured and the run's summary; the measurement along one seam is
:mod:`sim.simulation.seam_measure`'s (importable from here as before). May import: planners,
:mod:`sim.core`, :mod:`sim.scenario`, the simulation modules.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from planners.weave import WeavingTrajectory, measure_weave
from sim.core.intervals import true_runs
from sim.scenario import Scenario
from sim.simulation.compile import BuiltCell
from sim.simulation.motion import Motion, PhaseMotion
from sim.simulation.seam_measure import (  # measure_seam & co: importable from here as before
    CURVE_SAGITTA,  # noqa: F401
    SeamMeasurement,
    ToolPointPath,  # noqa: F401
    angle_deg,
    in_zones,
    measure_seam,
    nearest_on_polyline,
    progress_speed,
    seam_progress,
)
from sim.simulation.simulate import SimulationRecord


def _distance_to_path(p: NDArray[np.float64], cart: Any, T: NDArray[np.float64]
                      ) -> NDArray[np.float64]:
    """Distance of world points ``p`` (N,3) from the ideal ADNIA path (frame 0 -> world ``T``)."""
    # sample the path densely (every 10 um, at least 2000 points) by time: the path is
    # traversed monotonically, so nearest samples plus chord projection give the distance
    n = max(2000, int(cart.length / 1e-5))
    tt = np.linspace(0.0, cart.duration, n)
    pts = cart.at(tt).position @ T[:3, :3].T + T[:3, 3]
    return nearest_on_polyline(p, pts)[2]


def _weave_offset(cart: Any, ts: NDArray[np.float64], T: NDArray[np.float64]
                  ) -> NDArray[np.float64]:
    """The planned weave displacement (world, m) of a phase at its own times ``ts``; zero for
    a phase without weave."""
    if not isinstance(cart, WeavingTrajectory):
        return np.zeros((len(ts), 3))
    return cart.offset(np.clip(ts, 0.0, cart.duration)) @ T[:3, :3].T


def _woven_travel_speed(cart: Any, ts: NDArray[np.float64], p: NDArray[np.float64],
                        T: NDArray[np.float64]) -> NDArray[np.float64]:
    """Travel speed along the path of a weaving phase, m/s: the tool point's velocity along the
    travel direction, the weave's planned longitudinal motion taken out (the lateral motion,
    which the joints' polynomial rounds between its samples, does not count)."""
    lon = cart.travel_direction(np.clip(ts, 0.0, cart.duration)) @ T[:3, :3].T
    travel = p - _weave_offset(cart, ts, T)
    return np.einsum("ij,ij->i", np.gradient(travel, ts, axis=0), lon)


def _cruise_window(cart: Any) -> tuple[float, float]:
    """The part of a Cartesian phase at its set speed, on its own clock, s: between its corners
    (a blended phase) or its start and stop ramps."""
    steady = getattr(cart, "steady", None)
    if steady is not None:
        return float(steady[0]), float(steady[1])
    ramp = float(cart.profile.ramp_time)
    return ramp, float(cart.duration) - ramp


def _phase_samples(arrays: Mapping[str, NDArray[Any]], pm: PhaseMotion) -> NDArray[np.intp]:
    """Indices of the samples in ``[t0, t1]`` of a phase, both ends included (the sample at
    ``t1`` is where the phase ends, though it counts for the next phase)."""
    return np.flatnonzero((arrays["t"] >= pm.t0 - 1e-12) & (arrays["t"] <= pm.t1 + 1e-12))


def measure_seam_phases(arrays: Mapping[str, NDArray[Any]], motion: Motion,
                        world_from_frame0: NDArray[np.float64], torch_axis: int,
                        context: Any = None) -> dict[int, SeamMeasurement]:
    """:func:`measure_seam` of every Cartesian phase along a seam, by phase index, on the
    simulated tool frames (``tcp_pos``, ``tcp_quat``) of the phase's samples; the constant-speed
    part and a weave's programmed offset, period and full-amplitude part are the phase's own.

    A seam on a positioner or turntable (``context``'s mechanisms) moves: the tool frames are
    measured in the part's frame, carried back by the part's motion the recorded axes give
    (:func:`_in_part_frame`)."""
    R0 = world_from_frame0[:3, :3]
    out = {}
    for k, pm in enumerate(motion.phases):
        cart = pm.cartesian
        if cart is None or pm.seam is None:
            continue
        idx = _phase_samples(arrays, pm)
        if idx.size < 3:
            continue
        ts = arrays["t"][idx]
        lo, hi = _cruise_window(cart)
        kw: dict[str, Any] = {}
        if isinstance(cart, WeavingTrajectory):
            kw = {"weave_offset": lambda tt, c=cart, t0=pm.t0: c.offset(
                      np.clip(tt - t0, 0.0, c.duration)) @ R0.T,
                  "weave_period": cart.weave.period,
                  "weave_window": (pm.t0 + cart.fade_in, pm.t1 - cart.fade_out)}
        rot = Rotation.from_quat(arrays["tcp_quat"][idx], scalar_first=True).as_matrix()
        pos = arrays["tcp_pos"][idx]
        if context is not None and context.seam_mechanism.get(pm.seam.name):
            pos, rot = _in_part_frame(context, pm, arrays["q"][idx], pos, rot)
        out[k] = measure_seam(ts, pos, rot, pm.seam, axis_column=torch_axis,
                              corner_zones=pm.corner_zones, cruise=(pm.t0 + lo, pm.t0 + hi),
                              **kw)
    return out


def _carrier(context: Any, pm: Any) -> str | None:
    """The mechanism carrying what a Cartesian phase's path is relative to: its seam's part,
    or, for a coordinated move in a frame (``phase.axes``, a TP program's COORD), the object
    its points are given in; None for a fixed one (or a context without mechanisms)."""
    if context is None or not context.mechanisms:
        return None
    if pm.seam is not None:
        return context.seam_mechanism.get(pm.seam.name)
    if getattr(pm.phase, "axes", None):
        return context.frame_mechanism.get(getattr(pm.phase, "frame", ""))
    return None


def _in_part_frame(context: Any, pm: Any, q: NDArray[np.float64], pos: NDArray[np.float64],
                   rot: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Recorded tool frames (world) in the frame the phase's seam was placed in (``pm.seam``:
    the part at the axes' values where the phase starts, ``qe0``): carried back by
    ``D(qe0) D(q)^-1``, ``D`` the part's motion at the recorded axes ``q`` (N, n_joints)."""
    from sim.simulation.motion.axes import displacement

    n = context.kinematics.n_joints
    mech = _carrier(context, pm)
    qe0 = np.asarray(pm.trajectory.at(pm.t0).q, dtype=float)[n:]
    back = displacement(context, mech, qe0) @ np.linalg.inv(displacement(context, mech, q[:, n:]))
    return (np.einsum("nij,nj->ni", back[:, :3, :3], pos) + back[:, :3, 3],
            back[:, :3, :3] @ rot)


def mechanism_summary(arrays: Mapping[str, NDArray[Any]], built: BuiltCell
                      ) -> dict[str, dict[str, Any]]:
    """Per mechanism: its kind and model, what it carries and the mass of it (from the compiled
    model: the mount's subtree, kg) against its rating, and per axis (``<mechanism>_<axis>``)
    the recorded travel (deg or mm) and the largest speed."""
    model = built.model
    names = list(built.cell.joint_names)
    out = {}
    for pm in built.cell.mechanisms:
        axes = {}
        for name, ax in zip(pm.joint_names, pm.spec.axes, strict=True):
            k = names.index(name)
            scale, unit = (np.degrees(1.0), "deg") if ax.kind == "revolute" else (1e3, "mm")
            q = np.asarray(arrays["q"][:, k])
            axes[name] = {"kind": ax.kind, "unit": unit, "min": float(scale * q.min()),
                          "max": float(scale * q.max()),
                          "max_speed": float(scale * np.abs(arrays["qd"][:, k]).max())}
        out[pm.name] = {"kind": pm.spec.kind, "model": pm.spec.name, "carries": list(pm.carries),
                        "carried_kg": float(model.body(pm.mount_body).subtreemass[0]),
                        "rated_payload_kg": float(pm.spec.payload_kg), "axes": axes}
    return out


def _normal_from_vertical(context: Any, pm: Any, q: NDArray[np.float64],
                          s: NDArray[np.float64]) -> float:
    """Largest angle from vertical of the seam's local normal (:meth:`Seam.weld_normal`) at
    the tool point's measured place ``s`` along it, with the part where the recorded axes
    ``q`` (N, n_joints) put it, deg."""
    from sim.simulation.motion.axes import displacement

    n = context.kinematics.n_joints
    mech = context.seam_mechanism[pm.seam.name]
    qe0 = np.asarray(pm.trajectory.at(pm.t0).q, dtype=float)[n:]
    R = (displacement(context, mech, q[:, n:])
         @ np.linalg.inv(displacement(context, mech, qe0)))[:, :3, :3]
    normals = np.array([pm.seam.weld_normal(float(x)) for x in s])
    up = np.einsum("nij,nj->ni", R, normals)[:, 2]
    return float(np.degrees(np.arccos(np.clip(up, -1.0, 1.0))).max())


def weave_metrics(arrays: dict[str, NDArray[Any]], motion: Motion, built: BuiltCell,
                  measured: Mapping[int, SeamMeasurement]) -> list[dict[str, Any]]:
    """Per weaving phase: the tool point's lateral offset, measured on the simulated tcp over
    the full-amplitude part: amplitude (half the peak to peak), frequency (FFT peak,
    :func:`planners.weave.measure_weave`), centre line (mean offset over whole cycles), against
    the set values. Along a seam the offset is from the seam's nearest tool point
    (:func:`measure_seam`, corner zones left out); without one, from the phase's own path."""
    return _weave_entries(arrays, motion, built.context, measured)


def _weave_entries(arrays: Mapping[str, NDArray[Any]], motion: Motion, context: Any,
                   measured: Mapping[int, SeamMeasurement]) -> list[dict[str, Any]]:
    """:func:`weave_metrics` of one robot's ``motion`` with its own ``context``."""
    t = arrays["t"]
    T = context.world_from_frame0
    out = []
    for k, pm in enumerate(motion.phases):
        cart = pm.cartesian
        if not isinstance(cart, WeavingTrajectory):
            continue
        if k in measured:
            m = measured[k].weave
            if m is None:
                continue
        else:
            sel = arrays["phase"] == k
            tl = t[sel] - pm.t0
            full = (tl >= cart.fade_in) & (tl <= cart.duration - cart.fade_out)
            # two whole cycles at least (as along a seam): a shorter window, such as a TP
            # program's move across a corner zone, cannot tell the weave's frequency
            if np.count_nonzero(full) < 16 or np.ptp(tl[full]) < 2.0 * cart.weave.period:
                continue
            tl = tl[full]
            p = arrays["tcp_pos"][sel][full]
            base = cart.base.at(tl).position @ T[:3, :3].T + T[:3, 3]
            lat = cart.frame(tl)[0]
            m = measure_weave(tl, np.einsum("ij,ij->i", p - base, lat @ T[:3, :3].T))
        w = cart.weave
        out.append({
            "phase": pm.name, "pattern": w.pattern,
            "set_amplitude_mm": w.amplitude * 1e3, "amplitude_mm": m["amplitude_m"] * 1e3,
            "amplitude_error_pct": (m["amplitude_m"] / w.amplitude - 1.0) * 100.0,
            "set_frequency_hz": w.frequency, "frequency_hz": m["frequency_hz"],
            "frequency_error_pct": (m["frequency_hz"] / w.frequency - 1.0) * 100.0,
            "centre_line_mm": m["centre_m"] * 1e3,
        })
    return out


def weld_metrics(arrays: dict[str, NDArray[Any]], motion: Motion, built: BuiltCell,
                 torch_axis: int, measured: Mapping[int, SeamMeasurement]
                 ) -> list[dict[str, Any]]:
    """Per weld phase (a Cartesian phase with the arc on): seam length, travel speed and its
    coefficient of variation on the constant-speed part, path deviation and torch angle error.

    Along a seam every figure is measured (:func:`measure_seam`, ``measured``): the travel
    speed is the progress along the seam, the path deviation the tool point's distance from
    the seam (net of the programmed weave; ``corner_path_deviation_mm`` inside the corner
    zones), the torch angle error the torch axis against the seam's commanded axis
    (``work_angle_error_deg``, ``travel_angle_error_deg`` against its work and travel angles,
    ``t_worst_angle_s`` the time of the worst axis error), the corner zones left out (there
    ``corner_torch_excess_deg``, the torch's swing out of its turn from leg to leg);
    ``start_error_mm`` / ``end_error_mm`` are the first and last samples' distances from the
    seam's ends. A phase without a seam is measured against its programmed path."""
    return _weld_entries(arrays, motion, built.context, torch_axis, measured)


def _weld_entries(arrays: Mapping[str, NDArray[Any]], motion: Motion, context: Any,
                  torch_axis: int, measured: Mapping[int, SeamMeasurement]
                  ) -> list[dict[str, Any]]:
    """:func:`weld_metrics` of one robot's ``motion`` (its recorded ``tcp_pos``/``tcp_quat``,
    ``arc_on`` and ``phase`` in ``arrays``) with its own ``context``."""
    t = arrays["t"]
    T = context.world_from_frame0
    out = []
    for k, pm in enumerate(motion.phases):
        if pm.cartesian is None:
            continue
        sel = (arrays["phase"] == k)
        inside = sel & (t > pm.t0 + 1e-9) & (t < pm.t1 - 1e-9)  # not just a boundary sample
        if not np.any(arrays["arc_on"][inside]):
            continue
        cart = pm.cartesian
        set_speed = float(cart.speed)
        if pm.seam is not None and pm.seam.kind == "arc" and \
                abs(cart.length / pm.seam.length() - 1.0) > 1e-4:
            # a stand-off arc's tool point runs a coaxial arc (motion.cartesian): the set speed
            # is the seam's (not a blended polyline's, whose path is only shorter)
            set_speed *= pm.seam.length() / cart.length
        entry: dict[str, Any] = {
            "phase": pm.name, "seam": None if pm.seam is None else pm.seam.name,
            "set_speed_mm_s": set_speed * 1e3,
            "constant_speed_share": float(cart.constant_speed_fraction.time)}
        if k in measured:
            m = measured[k]
            entry.update({
                "seam_length_mm": float(pm.seam.length() * 1e3),
                "travel_speed_mm_s": m.travel_speed * 1e3,
                "travel_speed_cv": m.travel_speed_cv,
                "max_path_deviation_mm": m.max_deviation * 1e3,
                "corner_path_deviation_mm": (None if m.corner_deviation is None
                                             else m.corner_deviation * 1e3),
                "torch_angle_error_deg": m.torch_angle_error_deg,
                "corner_torch_excess_deg": m.corner_torch_excess_deg,
                "work_angle_error_deg": m.work_angle_error_deg,
                "travel_angle_error_deg": m.travel_angle_error_deg,
                "t_worst_angle_s": m.t_worst_angle,
                "start_error_mm": m.start_error * 1e3, "end_error_mm": m.end_error * 1e3})
            ctx = context
            if ctx.seam_mechanism.get(pm.seam.name):
                entry["carried_by"] = ctx.seam_mechanism[pm.seam.name]
                entry["normal_from_vertical_deg"] = _normal_from_vertical(
                    ctx, pm, arrays["q"][_phase_samples(arrays, pm)], m.s)
                entry["downhand"] = bool(getattr(pm.phase, "downhand", False))
            out.append(entry)
            continue
        p = arrays["tcp_pos"][sel]
        ts = t[sel]
        T = context.world_from_frame0
        R_act = Rotation.from_quat(arrays["tcp_quat"][sel], scalar_first=True).as_matrix()
        if _carrier(context, pm) is not None:  # a coordinated move: in the part's frame
            from sim.simulation.motion.axes import world_from_frame0

            n = context.kinematics.n_joints
            p, R_act = _in_part_frame(context, pm, arrays["q"][sel], p, R_act)
            T = world_from_frame0(context,
                                  np.asarray(pm.trajectory.at(pm.t0).q, dtype=float)[n:])
        lo, hi = _cruise_window(cart)
        cs = (ts >= pm.t0 + lo + 1e-9) & (ts <= pm.t0 + hi - 1e-9)
        if isinstance(cart, WeavingTrajectory):
            # progress along the seam over whole cycles (the pattern's corners average out)
            v = _woven_travel_speed(cart, ts - pm.t0, p, T)
            vc = v[cs] if np.count_nonzero(cs) > 2 else v
            cycles = max(1, int(len(vc) * (ts[1] - ts[0]) * cart.weave.frequency))
            vc = np.array([c.mean() for c in np.array_split(vc, cycles)])
        else:
            v = np.linalg.norm(np.gradient(p, ts, axis=0), axis=1)
            vc = v[cs] if np.count_nonzero(cs) > 2 else v
        dev = _distance_to_path(p, cart, T)
        ref = cart.at(np.clip(ts - pm.t0, 0.0, cart.duration))
        R_ref = T[:3, :3] @ ref.rotation
        ang = angle_deg(R_act[:, :, torch_axis], R_ref[:, :, torch_axis])
        ends = cart.at(np.array([0.0, cart.duration])).position @ T[:3, :3].T + T[:3, 3]
        ends_idx = _phase_samples(arrays, pm)[[0, -1]]
        first, last = arrays["tcp_pos"][ends_idx]
        if _carrier(context, pm) is not None:
            (first, last), _ = _in_part_frame(context, pm, arrays["q"][ends_idx],
                                              arrays["tcp_pos"][ends_idx],
                                              np.broadcast_to(np.eye(3), (2, 3, 3)))
        entry.update({
            "seam_length_mm": float(cart.length * 1e3),
            "travel_speed_mm_s": float(np.mean(vc) * 1e3),
            "travel_speed_cv": float(np.std(vc) / max(np.mean(vc), 1e-12)),
            "max_path_deviation_mm": float(np.max(dev) * 1e3),
            "corner_path_deviation_mm": None, "corner_torch_excess_deg": None,
            "torch_angle_error_deg": float(np.max(ang)),
            "work_angle_error_deg": None, "travel_angle_error_deg": None,
            "t_worst_angle_s": float(ts[int(np.argmax(ang))]),
            "start_error_mm": float(np.linalg.norm(first - ends[0]) * 1e3),
            "end_error_mm": float(np.linalg.norm(last - ends[1]) * 1e3)})
        out.append(entry)
    return out


#: A part is placed when its centre ends within this distance of its slot, mm.
PLACE_TOLERANCE_MM = 5.0


def pick_metrics(arrays: dict[str, NDArray[Any]], built: BuiltCell,
                 tol_mm: float = PLACE_TOLERANCE_MM) -> dict[str, Any] | None:
    """For cells with parts and slots: where each part ends, from the recorded part positions,
    against its slot (part k goes to slot k; slots beyond the parts, or parts beyond the
    slots, are not counted)."""
    slots = np.asarray(built.cell.slots, dtype=float).reshape(-1, 3)
    if "part_pos" not in arrays or slots.size == 0:
        return None
    final = np.asarray(arrays["part_pos"], dtype=float)[-1].reshape(-1, 3)
    n = min(len(final), len(slots))
    err = [float(e) for e in np.linalg.norm(final[:n] - slots[:n], axis=1) * 1e3]
    return {"placed": [e <= tol_mm for e in err], "place_error_mm": err,
            "place_tolerance_mm": float(tol_mm)}


def make_summary(scenario: Scenario, built: BuiltCell, motion: Motion, rec: SimulationRecord,
                 feedforward: bool) -> dict[str, Any]:
    a = rec.arrays
    sim_time = rec.steps * rec.timestep
    track = np.max(np.abs(a["q"] - a["q_ref"]), axis=0)
    system = scenario.system  # a linear axis's (a track's) tracking error in m, shown in mm
    units = ["mm" if lin else "deg" for lin in system.linear]
    dev = np.linalg.norm(a["tcp_pos"] - a["tcp_pos_ref"], axis=1)
    peak_id = np.max(np.abs(a["tau_id"]), axis=0)
    rms_diff = np.sqrt(np.mean((a["tau"] - a["tau_id"]) ** 2, axis=0))
    torch_axis = scenario.robot.family.approach_column
    measured = measure_seam_phases(a, motion, built.context.world_from_frame0, torch_axis,
                                   built.context)
    summary: dict[str, Any] = {
        "scenario": scenario.name, "robot": scenario.robot.name,
        "cell": None if scenario.cell is None else scenario.cell.name,
        "tool": None if scenario.tool is None else scenario.tool.name,
        "mount": scenario.mount,
        "payload_kg": scenario.payload_kg,
        "joints": list(scenario.system.joints),
        **({"joint_units": units} if system.external else {}),
        "phases": [{"name": pm.name, "kind": pm.kind, "t0": pm.t0, "t1": pm.t1}
                   for pm in motion.phases],
        "duration_s": motion.duration,
        "timestep_s": rec.timestep,
        "steps": rec.steps,
        "wall_s": rec.wall_s,
        "realtime_factor": sim_time / rec.wall_s if rec.wall_s > 0 else None,
        "feedforward": feedforward,
        "max_tracking_error_rad": [float(x) for x in track],
        "max_tracking_error_deg": [float(x * 1e3 if u == "mm" else np.degrees(x))
                                   for x, u in zip(track, units, strict=True)],
        "max_tcp_deviation_mm": float(np.max(dev) * 1e3),
        "torque_rms_diff_pct_of_peak": [float(100 * d / p) if p > 1e-6 * max(peak_id) else None
                                        for d, p in zip(rms_diff, peak_id, strict=True)],
        "actions": [{"t": t, "action": act} for t, act in motion.actions],
        "weld": weld_metrics(a, motion, built, torch_axis, measured),
        "cartesian_speed": cartesian_speeds(a, motion, built.context.world_from_frame0,
                                            built.context),
        "weave": weave_metrics(a, motion, built, measured),
        "program_warnings": list(scenario.program_warnings) + [
            f"robots.{w.name}: {x}" for w in scenario.partners for x in w.program_warnings],
    }
    if built.cell.mechanisms:
        summary["mechanisms"] = mechanism_summary(a, built)
    summary["saturation"] = saturation_intervals(a, motion, built, feedforward=feedforward)
    summary["singularity"] = singularity_summary(a, motion, built, rec.timestep)
    pick = pick_metrics(a, built)
    if pick is not None:
        summary.update(pick)
    return summary



#: A Cartesian phase keeps its set speed when its reference tool point's cruise speed is within
#: this fraction of it.
SPEED_TOLERANCE = 0.01


def _woven_cruise(cart: Any, ts: NDArray[np.float64], p: NDArray[np.float64],
                  T: NDArray[np.float64]) -> float:
    """A weaving phase's travel speed between its ramps, m/s: the mean of the travel-direction
    velocity (progress over time, so the rounding of the pattern's corners averages out)."""
    v = _woven_travel_speed(cart, ts, p, T)
    lo, hi = _cruise_window(cart)
    mid = (ts >= lo) & (ts <= hi)
    return float(np.mean(v[mid] if np.count_nonzero(mid) > 2 else v))


def _seam_cruise(pm: PhaseMotion, ts: NDArray[np.float64], p: NDArray[np.float64]) -> float:
    """The cruise speed of a phase along a seam, m/s, from the progress ``s*`` of the points
    ``p`` at times ``ts`` (:func:`seam_progress`), the corner zones left out: a weaving
    phase's mean over whole cycles between its ramps or corners, a blended phase's median
    between its corners, otherwise the median over the samples faster than 95 % of the peak."""
    cart = pm.cartesian
    s = seam_progress(pm.seam, p)
    keep = ~in_zones(s, pm.corner_zones)
    lo, hi = _cruise_window(cart)
    tl = ts - pm.t0
    mid = keep & (tl >= lo - 1e-9) & (tl <= hi + 1e-9)
    if np.count_nonzero(mid) < 3:
        mid = keep
    if isinstance(cart, WeavingTrajectory):
        speed = progress_speed(ts, s, mid, cart.weave.period)[0]
        return speed if np.isfinite(speed) else progress_speed(ts, s, mid)[0]
    v = np.gradient(s, ts)
    if getattr(cart, "steady", None) is not None:
        return float(np.median(v[mid]))
    v = v[keep]
    return float(np.median(v[v >= 0.95 * v.max()] if v.max() > 0 else v))


def cartesian_speeds(arrays: Mapping[str, NDArray[Any]], motion: Motion,
                     world_from_frame0: NDArray[np.float64] | None = None,
                     context: Any = None) -> list[dict[str, Any]]:
    """Per Cartesian phase: the set travel speed and the reference tool point's cruise speed,
    mm/s (the median speed over the samples faster than 95 % of the phase's peak, so the ramps
    are left out), and the deviation in percent. A phase sampled too coarsely for its move
    (``sample_period_s`` near the move's duration) misses its set speed: the verdict fails it
    past :data:`SPEED_TOLERANCE`. Along a seam the speed is the progress along it
    (:func:`_seam_cruise`: a weave's lateral motion does not count, nor do the corner zones);
    a weaving phase without a seam has the travel speed of the tool point with the weave's
    planned displacement taken out. Along a seam a positioner moves, the speed is relative to
    the part (the reference tool point carried back by the part's reference motion)."""
    t, p = arrays["t"], arrays["tcp_pos_ref"]
    T = np.eye(4) if world_from_frame0 is None else world_from_frame0
    out = []
    for pm in motion.phases:
        if pm.cartesian is None:
            continue
        sel = _phase_samples(arrays, pm)
        if sel.size < 3:
            speed = 0.0
        elif pm.seam is not None and _carrier(context, pm) is not None:
            rel, _ = _in_part_frame(context, pm, arrays["q_ref"][sel], p[sel],
                                    np.broadcast_to(np.eye(3), (sel.size, 3, 3)))
            speed = _seam_cruise(pm, t[sel], rel)
        elif pm.seam is not None:
            speed = _seam_cruise(pm, t[sel], p[sel])
        else:
            steady = getattr(pm.cartesian, "steady", None)
            ps = p[sel]
            if _carrier(context, pm) is not None:  # a coordinated move: relative to the part
                ps, _ = _in_part_frame(context, pm, arrays["q_ref"][sel], ps,
                                       np.broadcast_to(np.eye(3), (sel.size, 3, 3)))
            if isinstance(pm.cartesian, WeavingTrajectory):
                speed = _woven_cruise(pm.cartesian, t[sel] - pm.t0, ps, T)
            elif steady is not None:  # a blended phase: its speed between its corners
                tl = t[sel] - pm.t0
                v = np.linalg.norm(np.gradient(ps, t[sel], axis=0), axis=1)
                mid = (tl >= steady[0] - 1e-9) & (tl <= steady[1] + 1e-9)
                speed = float(np.median(v[mid] if np.count_nonzero(mid) > 2 else v))
            else:
                v = np.linalg.norm(np.diff(ps, axis=0), axis=1) / np.diff(t[sel])
                cruise = v[v >= 0.95 * v.max()] if v.max() > 0 else v
                speed = float(np.median(cruise))
        want = float(pm.cartesian.speed if getattr(pm.phase, "move_time", None) is not None
                     else pm.phase.speed)  # a TP move in 'sec': the speed its time sets
        out.append({"phase": pm.name, "set_mm_s": want * 1e3, "cruise_mm_s": speed * 1e3,
                    "deviation_pct": (speed - want) / want * 100.0 if want > 0 else 0.0})
    return out


def saturation_intervals(arrays: dict[str, NDArray[Any]], motion: Motion, built: BuiltCell,
                         *, feedforward: bool = True) -> list[dict[str, Any]]:
    """Intervals in which a drive delivered its limit instead of what the servo asked.

    The servo's demand is ``kp (q_ref - q) + kv (qd_ref - qd) + tau_ff`` with feed-forward and
    ``kp (q_ref - q) - kv qd`` without (the drive's force before its clamp,
    :mod:`sim.simulation.simulate`); a sample is saturated when the demand
    exceeds the drive's limit at that step (``tau_limit``: its ``forcerange``, or its peak
    torque-speed curve at speed). Each interval gives the joint, ``t0``/``t1`` (s), the phase
    at ``t0`` and the worst excess of the demand over the limit, N m.
    """
    model = built.model
    kp = model.actuator_gainprm[built.robot_act, 0]
    kv = -model.actuator_biasprm[built.robot_act, 2]
    demand = kp * (arrays["q_ref"] - arrays["q"]) - kv * arrays["qd"]
    if feedforward:
        demand = demand + kv * arrays["qd_ref"] + arrays["tau_ff"]
    excess = np.abs(demand) - arrays["tau_limit"]
    t = arrays["t"]
    joints = list(built.cell.robot.joints + built.cell.axis_names)
    # each joint's phases: the first robot's (and the axes'), or its own robot's lane's
    lanes: list[Motion] = [motion] * len(joints)
    robots = [""] * len(joints)
    for cr, (name, lane) in zip(built.cell.partners, motion.lanes, strict=True):
        joints += [f"{name}_{j}" for j in cr.robot.joints]
        lanes += [lane] * cr.robot.n_joints
        robots += [name] * cr.robot.n_joints
    out = []
    for j, name in enumerate(joints):
        tol = 1e-9 * max(1.0, float(built.force_limits[j, 1]))
        for i0, stop in true_runs(excess[:, j] > tol):
            i1 = stop - 1
            own = lanes[j]
            k = (int(arrays["phase"][i0]) if own is motion
                 else int(np.atleast_1d(own.phase_index(t[i0]))[0]))
            entry = {"joint": name, "t0": float(t[i0]), "t1": float(t[i1]),
                     "phase": own.phases[k].name,
                     "worst_excess_nm": float(np.max(excess[i0:i1 + 1, j]))}
            if own is not motion:
                entry["robot"] = robots[j]
            out.append(entry)
    return sorted(out, key=lambda s: (s["t0"], s["joint"]))


def singularity_summary(arrays: dict[str, NDArray[Any]], motion: Motion, built: BuiltCell,
                        dt: float) -> dict[str, Any]:
    """Closest approach of the reference to a singularity (sampled every 10 ms).

    ``min_sigma`` is the smallest singular value of the task Jacobian (0 at a singularity,
    mixed units; :func:`sim.robots.kinematics.jacobian.singularity_measures`), with its time and
    phase; ``min_abs_<factor>`` are the explicit factors of det J (200iC: ``wrist`` = sin
    theta5, ``elbow``, ``shoulder`` = wrist-centre distance from the J1 axis in m; 5R:
    ``elbow`` = cos q3, ``shoulder`` = reach in m).
    """
    return _singularity(arrays["t"], arrays["q_ref"], motion, built.context.kinematics, dt)


def _singularity(t: NDArray[np.float64], q_ref: NDArray[np.float64], motion: Motion,
                 kin: Any, dt: float) -> dict[str, Any]:
    """:func:`singularity_summary` of one robot: its reference joints ``q_ref`` (its arm's
    first), its ``motion`` and kinematics."""
    from sim.simulation.singularity_cache import singularity_measures  # the plan's, kept

    step = max(1, int(round(0.01 / dt)))
    t = t[::step]
    m = singularity_measures(kin, q_ref[::step, :kin.n_joints])  # the arm's joints
    i = int(np.argmin(m["sigma_min"]))
    out: dict[str, Any] = {"min_sigma": float(m["sigma_min"][i]), "t": float(t[i]),
                           "phase": motion.phases[
                               int(np.atleast_1d(motion.phase_index(t[i]))[0])].name,
                           "min_manipulability": float(np.min(m["manipulability"]))}
    for factor in ("wrist", "elbow", "shoulder"):
        if factor in m:
            out[f"min_abs_{factor}"] = float(np.min(np.abs(m[factor])))
    return out
