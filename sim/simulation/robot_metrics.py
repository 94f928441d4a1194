"""A cell's other robots measured as its first robot is: :func:`add_robots` (each robot's
welds, Cartesian speeds and weaves from its own recorded tool point, phases and seams, entries
tagged ``"robot"``, and ``summary["robots"]``) and :func:`robot_arrays` (one robot's recorded
columns as a run's own). The first robot's measurements are :mod:`sim.simulation.metrics`."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from sim.scenario import Scenario
from sim.simulation.compile import BuiltCell
from sim.simulation.metrics import (
    _singularity,
    _weave_entries,
    _weld_entries,
    cartesian_speeds,
    measure_seam_phases,
)
from sim.simulation.motion import Motion
from sim.simulation.simulate import SimulationRecord

#: The first robot's name in a cell with other robots (its MJCF prefix): the ``"robot"`` of
#: its entries in ``summary["weld"]``, ``["cartesian_speed"]``, ``["weave"]`` and its key in
#: ``summary["robots"]``.
FIRST_ROBOT = "robot"


def robot_arrays(arrays: Mapping[str, NDArray[Any]], built: BuiltCell, name: str,
                 lane: Motion) -> dict[str, NDArray[Any]]:
    """One of a cell's other robots' recorded arrays as a run's own (what the first robot's
    measurements read): ``t``, its joints' columns of ``q``, ``q_ref``, ``qd``, ``qd_ref``,
    ``qdd_ref``, its ``<name>_tcp_pos``/``_tcp_quat``/``_tcp_pos_ref``/``_arc_on`` as
    ``tcp_pos``... and ``phase``, the index of its own phase (``lane``'s) at each sample."""
    cols = built.partner_cols[name]
    t = np.asarray(arrays["t"])
    out: dict[str, NDArray[Any]] = {"t": t, "phase": lane.phase_index(t).astype(np.int32)}
    for key in ("q", "q_ref", "qd", "qd_ref", "qdd_ref"):
        if key in arrays:
            out[key] = np.asarray(arrays[key])[:, cols]
    for key in ("tcp_pos", "tcp_quat", "tcp_pos_ref", "arc_on"):
        out[key] = np.asarray(arrays[f"{name}_{key}"])
    return out


def add_robots(summary: dict[str, Any], scenario: Scenario, built: BuiltCell,
                  motion: Motion, rec: SimulationRecord) -> None:
    """A cell with other robots: each robot's weld phases, Cartesian speeds and weaves
    measured as the first robot's are (its own recorded tool frames, seams as its tool follows
    them, its own phases), appended to ``summary["weld"]``, ``["cartesian_speed"]`` and
    ``["weave"]`` with ``"robot"`` naming the robot (the first robot's entries get
    ``"robot": "robot"``), and ``summary["robots"]``: per robot its model, tool, frame 0,
    joints (their names in the joint vector), phases, cycle end, largest tool point deviation
    from its reference, tracking errors and closest approach to a singularity."""
    a = rec.arrays
    keys = ("weld", "cartesian_speed", "weave")
    for key in keys:
        for e in summary[key]:
            e["robot"] = FIRST_ROBOT
    n_lead = motion.n_lead
    track = summary["max_tracking_error_deg"]
    robots: dict[str, Any] = {FIRST_ROBOT: {
        "model": scenario.robot.name,
        "tool": None if scenario.tool is None else scenario.tool.name,
        **_frame0(built.context.world_from_frame0),
        "joints": list(scenario.system.joints[:scenario.system.n_arm]),
        "phases": summary["phases"],
        "t_end_s": float(motion.phases[-1].t1),
        "max_tcp_deviation_mm": summary["max_tcp_deviation_mm"],
        "max_tracking_error_deg": track[:scenario.system.n_arm],
        "singularity": summary["singularity"]}}
    col = n_lead
    for cr, work, (name, lane) in zip(built.cell.partners, scenario.partners, motion.lanes,
                                      strict=True):
        sub = robot_arrays(a, built, name, lane)
        ctx = built.context.partners[name]
        axis = cr.robot.family.approach_column
        measured = measure_seam_phases(sub, lane, ctx.world_from_frame0, axis, ctx)
        summary["weld"] += [{**e, "robot": name}
                            for e in _weld_entries(sub, lane, ctx, axis, measured)]
        summary["cartesian_speed"] += [{**e, "robot": name} for e in cartesian_speeds(
            sub, lane, ctx.world_from_frame0, ctx)]
        summary["weave"] += [{**e, "robot": name}
                             for e in _weave_entries(sub, lane, ctx, measured)]
        n = cr.robot.n_joints
        dev = np.linalg.norm(sub["tcp_pos"] - sub["tcp_pos_ref"], axis=1)
        robots[name] = {
            "model": cr.robot.name, "tool": None if cr.tool is None else cr.tool.name,
            **_frame0(ctx.world_from_frame0),
            "base_pos_mm": [float(x) for x in np.asarray(cr.placed.base_pose)[:3, 3] * 1e3],
            "joints": list(scenario.system.joints[col:col + n]),
            "phases": [{"name": pm.name, "kind": pm.kind, "t0": pm.t0, "t1": pm.t1}
                       for pm in lane.phases],
            "t_end_s": float(lane.t1),
            "max_tcp_deviation_mm": float(np.max(dev) * 1e3),
            "max_tracking_error_deg": track[col:col + n],
            "actions": [{"t": t, "action": act} for t, act in lane.actions],
            "program_warnings": list(work.program_warnings),
            "singularity": _singularity(sub["t"], sub["q_ref"], lane, ctx.kinematics,
                                        rec.timestep)}
        col += n
    summary["robots"] = robots


def _frame0(T: NDArray[np.float64]) -> dict[str, Any]:
    """A robot's frame 0 in world: position, mm, and ZYX Euler angles, deg."""
    T = np.asarray(T, dtype=float)
    zyx = Rotation.from_matrix(T[:3, :3]).as_euler("ZYX", degrees=True)
    return {"frame0_pos_mm": [float(x) for x in T[:3, 3] * 1e3],
            "frame0_euler_zyx_deg": [float(x) for x in zyx]}


__all__ = ["FIRST_ROBOT", "add_robots", "robot_arrays"]
