"""Metrics of a simulated run: tracking, weld seams, placed parts, singularities; the summary.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from planners.weave import WeavingTrajectory, measure_weave
from sim.core.intervals import true_runs
from sim.scenario import Scenario
from sim.simulation.compile import BuiltCell
from sim.simulation.motion import Motion
from sim.simulation.simulate import SimulationRecord


def _distance_to_path(p: NDArray[np.float64], cart: Any, T: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distance of world points ``p`` (N,3) from the ideal ADNIA path (frame 0 -> world ``T``)."""
    # sample the path densely (every 10 um, at least 2000 points) by time: the path is
    # traversed monotonically, so nearest samples plus chord projection give the distance
    n = max(2000, int(cart.length / 1e-5))
    tt = np.linspace(0.0, cart.duration, n)
    pts = cart.at(tt).position @ T[:3, :3].T + T[:3, 3]
    # nearest dense sample, refined by projection on the neighbouring chords

    tree = cKDTree(pts)
    _, idx = tree.query(p)
    best = np.full(p.shape[0], np.inf)
    for off in (-1, 0):
        i0 = np.clip(idx + off, 0, pts.shape[0] - 2)
        a, b = pts[i0], pts[i0 + 1]
        ab = b - a
        u = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab),
                                                                  1e-30), 0.0, 1.0)
        d = np.linalg.norm(p - (a + u[:, None] * ab), axis=1)
        best = np.minimum(best, d)
    return best


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
    lon = cart.frame(np.clip(ts, 0.0, cart.duration))[1] @ T[:3, :3].T
    travel = p - _weave_offset(cart, ts, T)
    return np.einsum("ij,ij->i", np.gradient(travel, ts, axis=0), lon)


def _woven_cruise(cart: Any, ts: NDArray[np.float64], p: NDArray[np.float64],
                  T: NDArray[np.float64]) -> float:
    """A weaving phase's travel speed between its ramps, m/s: the mean of the travel-direction
    velocity (progress over time, so the rounding of the pattern's corners averages out)."""
    v = _woven_travel_speed(cart, ts, p, T)
    ramp = float(cart.profile.ramp_time)
    lo, hi = cart.steady if cart.steady is not None else (ramp, cart.duration - ramp)
    mid = (ts >= lo) & (ts <= hi)
    return float(np.mean(v[mid] if np.count_nonzero(mid) > 2 else v))


def weave_metrics(arrays: dict[str, NDArray[Any]], motion: Motion, built: BuiltCell
                  ) -> list[dict[str, Any]]:
    """Per weaving phase: the tool point's lateral offset from the phase's own path (seam),
    measured on the simulated tcp over the full-amplitude part: amplitude (half the peak to
    peak), frequency (FFT peak, :func:`planners.weave.measure_weave`), centre line (mean
    offset over whole cycles), against the set values."""
    t = arrays["t"]
    T = built.context.world_from_frame0
    out = []
    for k, pm in enumerate(motion.phases):
        cart = pm.cartesian
        if not isinstance(cart, WeavingTrajectory):
            continue
        sel = arrays["phase"] == k
        tl = t[sel] - pm.t0
        full = (tl >= cart.fade) & (tl <= cart.duration - cart.fade)
        if np.count_nonzero(full) < 16:
            continue
        tl = tl[full]
        p = arrays["tcp_pos"][sel][full]
        base = cart.base.at(tl).position @ T[:3, :3].T + T[:3, 3]
        lat, lon = cart.frame(tl)
        lateral = np.einsum("ij,ij->i", p - base, lat @ T[:3, :3].T)
        m = measure_weave(tl, lateral)
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
                 torch_axis: int) -> list[dict[str, Any]]:
    """Per weld phase (a Cartesian phase with the arc on): seam length, travel speed and its
    coefficient of variation on the constant-speed part, path deviation and torch angle error."""
    t = arrays["t"]
    T = built.context.world_from_frame0
    out = []
    for k, pm in enumerate(motion.phases):
        if pm.cartesian is None:
            continue
        sel = (arrays["phase"] == k)
        inside = sel & (t > pm.t0 + 1e-9) & (t < pm.t1 - 1e-9)  # not just a boundary sample
        if not np.any(arrays["arc_on"][inside]):
            continue
        cart = pm.cartesian
        p = arrays["tcp_pos"][sel]
        ts = t[sel]
        share = cart.constant_speed_fraction
        ramp = float(cart.profile.ramp_time)
        tc0, tc1 = pm.t0 + ramp, pm.t1 - ramp
        if getattr(cart, "steady", None) is not None:  # a blended phase: between its corners
            tc0, tc1 = pm.t0 + cart.steady[0], pm.t0 + cart.steady[1]
        cs = (ts >= tc0 + 1e-9) & (ts <= tc1 - 1e-9)
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
        R_act = Rotation.from_quat(arrays["tcp_quat"][sel], scalar_first=True).as_matrix()
        R_ref = T[:3, :3] @ cart.at(np.clip(ts - pm.t0, 0.0, cart.duration)).rotation
        a_act, a_ref = R_act[:, :, torch_axis], R_ref[:, :, torch_axis]
        cosang = np.clip(np.einsum("ij,ij->i", a_act, a_ref), -1.0, 1.0)
        out.append({
            "phase": pm.name,
            "seam_length_mm": float(cart.length * 1e3),
            "set_speed_mm_s": float(cart.speed * 1e3),
            "travel_speed_mm_s": float(np.mean(vc) * 1e3),
            "travel_speed_cv": float(np.std(vc) / max(np.mean(vc), 1e-12)),
            "constant_speed_share": float(share.time),
            "max_path_deviation_mm": float(np.max(dev) * 1e3),
            "torch_angle_error_deg": float(np.degrees(np.max(np.arccos(cosang)))),
        })
    return out


def pick_metrics(arrays: dict[str, NDArray[Any]], built: BuiltCell, tol_mm: float = 5.0
                 ) -> dict[str, Any] | None:
    """For pick cells: final part positions against their slots."""
    slots = np.asarray(built.cell.slots, dtype=float)
    if "part_pos" not in arrays or slots.size == 0:
        return None
    final = arrays["part_pos"][-1]
    err = np.linalg.norm(final[: slots.shape[0]] - slots, axis=1) * 1e3
    return {"placed": [bool(e <= tol_mm) for e in err], "place_error_mm": [float(e) for e in err]}


def make_summary(scenario: Scenario, built: BuiltCell, motion: Motion, rec: SimulationRecord,
                 feedforward: bool) -> dict[str, Any]:
    a = rec.arrays
    sim_time = rec.steps * rec.timestep
    track = np.max(np.abs(a["q"] - a["q_ref"]), axis=0)
    dev = np.linalg.norm(a["tcp_pos"] - a["tcp_pos_ref"], axis=1)
    peak_id = np.max(np.abs(a["tau_id"]), axis=0)
    rms_diff = np.sqrt(np.mean((a["tau"] - a["tau_id"]) ** 2, axis=0))
    torch_axis = scenario.robot.family.approach_column
    summary: dict[str, Any] = {
        "scenario": scenario.name,
        "robot": scenario.robot.name,
        "cell": None if scenario.cell is None else scenario.cell.name,
        "tool": None if scenario.tool is None else scenario.tool.name,
        "mount": scenario.mount,
        "payload_kg": scenario.payload_kg,
        "joints": list(scenario.robot.joints),
        "phases": [{"name": pm.name, "kind": pm.kind, "t0": pm.t0, "t1": pm.t1}
                   for pm in motion.phases],
        "duration_s": motion.duration,
        "timestep_s": rec.timestep,
        "steps": rec.steps,
        "wall_s": rec.wall_s,
        "realtime_factor": sim_time / rec.wall_s if rec.wall_s > 0 else None,
        "feedforward": feedforward,
        "max_tracking_error_rad": [float(x) for x in track],
        "max_tracking_error_deg": [float(np.degrees(x)) for x in track],
        "max_tcp_deviation_mm": float(np.max(dev) * 1e3),
        "torque_rms_diff_pct_of_peak": [float(100 * d / p) if p > 0 else 0.0
                                        for d, p in zip(rms_diff, peak_id)],
        "actions": [{"t": t, "action": act} for t, act in motion.actions],
        "weld": weld_metrics(a, motion, built, torch_axis),
        "cartesian_speed": cartesian_speeds(a, motion, built.context.world_from_frame0),
        "weave": weave_metrics(a, motion, built),
        "program_warnings": list(scenario.program_warnings),
    }
    summary["saturation"] = saturation_intervals(a, motion, built, feedforward=feedforward)
    summary["singularity"] = singularity_summary(a, motion, built, rec.timestep)
    pick = pick_metrics(a, built)
    if pick is not None:
        summary.update(pick)
    return summary


#: A Cartesian phase keeps its set speed when its reference tool point's cruise speed is within
#: this fraction of it.
SPEED_TOLERANCE = 0.01


def cartesian_speeds(arrays: dict[str, NDArray[Any]], motion: Motion,
                     world_from_frame0: NDArray[np.float64] | None = None
                     ) -> list[dict[str, Any]]:
    """Per Cartesian phase: the set travel speed and the reference tool point's cruise speed,
    mm/s (the median speed over the samples faster than 95 % of the phase's peak, so the ramps
    are left out), and the deviation in percent. A phase sampled too coarsely for its move
    (``sample_period_s`` near the move's duration) misses its set speed: the verdict fails it
    past :data:`SPEED_TOLERANCE`. A weaving phase's travel speed is that of the tool point
    with the weave's planned displacement taken out."""
    t, p = arrays["t"], arrays["tcp_pos_ref"]
    T = np.eye(4) if world_from_frame0 is None else world_from_frame0
    out = []
    for pm in motion.phases:
        if pm.cartesian is None:
            continue
        sel = np.flatnonzero((t >= pm.t0 - 1e-12) & (t <= pm.t1 + 1e-12))
        if sel.size < 3:
            speed = 0.0
        else:
            steady = getattr(pm.cartesian, "steady", None)
            if isinstance(pm.cartesian, WeavingTrajectory):
                speed = _woven_cruise(pm.cartesian, t[sel] - pm.t0, p[sel], T)
            elif steady is not None:  # a blended phase: its speed between its corners
                tl = t[sel] - pm.t0
                v = np.linalg.norm(np.gradient(p[sel], t[sel], axis=0), axis=1)
                mid = (tl >= steady[0] - 1e-9) & (tl <= steady[1] + 1e-9)
                speed = float(np.median(v[mid] if np.count_nonzero(mid) > 2 else v))
            else:
                v = np.linalg.norm(np.diff(p[sel], axis=0), axis=1) / np.diff(t[sel])
                cruise = v[v >= 0.95 * v.max()] if v.max() > 0 else v
                speed = float(np.median(cruise))
        want = float(pm.phase.speed)
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
    joints = built.cell.robot.joints
    out = []
    for j, name in enumerate(joints):
        tol = 1e-9 * max(1.0, float(built.force_limits[j, 1]))
        for i0, stop in true_runs(excess[:, j] > tol):
            i1 = stop - 1
            out.append({"joint": name, "t0": float(t[i0]), "t1": float(t[i1]),
                        "phase": motion.phases[int(arrays["phase"][i0])].name,
                        "worst_excess_nm": float(np.max(excess[i0:i1 + 1, j]))})
    return sorted(out, key=lambda s: (s["t0"], s["joint"]))


def singularity_summary(arrays: dict[str, NDArray[Any]], motion: Motion, built: BuiltCell,
                        dt: float) -> dict[str, Any]:
    """Closest approach of the reference to a singularity (sampled every 10 ms).

    ``min_sigma`` is the smallest singular value of the task Jacobian (0 at a singularity,
    mixed units; :func:`sim.robots.jacobian.singularity_measures`), with its time and
    phase; ``min_abs_<factor>`` are the explicit factors of det J (200iC: ``wrist`` = sin
    theta5, ``elbow``, ``shoulder`` = wrist-centre distance from the J1 axis in m; 5R:
    ``elbow`` = cos q3, ``shoulder`` = reach in m).
    """
    from sim.robots.jacobian import singularity_measures

    step = max(1, int(round(0.01 / dt)))
    t = arrays["t"][::step]
    m = singularity_measures(built.context.kinematics, arrays["q_ref"][::step])
    i = int(np.argmin(m["sigma_min"]))
    out: dict[str, Any] = {"min_sigma": float(m["sigma_min"][i]), "t": float(t[i]),
                           "phase": motion.phases[int(np.atleast_1d(motion.phase_index(t[i]))[0])].name,
                           "min_manipulability": float(np.min(m["manipulability"]))}
    for factor in ("wrist", "elbow", "shoulder"):
        if factor in m:
            out[f"min_abs_{factor}"] = float(np.min(np.abs(m[factor])))
    return out
