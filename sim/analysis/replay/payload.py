"""The replay's data: a run (model and recorded arrays) turned into the JSON the page reads.

Arrays travel as base64 of little-endian float32 (``{"f32": "..."}``) or int32 / uint8;
everything else is plain JSON. The size is bounded: the body poses are taken at the display
rate (``DISPLAY_FPS``, lower for long runs so that frames x moving bodies stays within
``POSE_BUDGET``), charts are min/max per pixel column, tool paths at most
:data:`~sim.analysis.replay.series.PATH_POINTS` points.

May import: :mod:`sim.analysis.replay.scene`, :mod:`sim.analysis.replay.series`,
:mod:`sim.simulation.runfolder` (the run as read), :mod:`sim.analysis.framing` (the video's
framed overview, the replay's first view).
"""

from __future__ import annotations

import base64
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.analysis.replay.scene import (
    body_poses,
    cameras,
    clearance_points,
    frame_indices,
    geoms_and_meshes,
    moving_bodies,
)
from sim.analysis.replay.series import minmax_bins, path_indices

#: Display frames per second of the replay (fewer for long runs, see POSE_BUDGET).
DISPLAY_FPS = 25.0

#: Most (frame, moving body) poses stored: 7 float32 each (28 bytes, 37 in base64).
POSE_BUDGET = 120_000

#: Charts: (id, title, unit, how the series is made from the arrays).
CHARTS = (("torque", "Joint torque", "N·m"), ("speed", "Joint speed", "rad/s"),
          ("error", "Tracking error", "deg"))


def b64(a: NDArray[Any], dtype: str = "<f4") -> dict[str, str]:
    """An array as base64 of its little-endian bytes, tagged with its type."""
    kind = {"<f4": "f32", "<i4": "i32", "u1": "u8"}[dtype]
    raw = np.ascontiguousarray(np.asarray(a).astype(dtype)).tobytes()
    return {kind: base64.b64encode(raw).decode("ascii")}


def _num(v: Any) -> float | None:
    """A finite number, or None (JSON has no NaN)."""
    return float(v) if isinstance(v, (int, float)) and np.isfinite(v) else None


def chart_series(arrays: Mapping[str, NDArray[Any]]) -> dict[str, NDArray[np.float64]]:
    """The charted quantities per joint (n, k), from what the run recorded."""
    out: dict[str, NDArray[np.float64]] = {}
    tau = arrays.get("tau")
    if tau is not None:
        out["torque"] = np.asarray(tau, np.float64)
    if "qd" in arrays:
        out["speed"] = np.asarray(arrays["qd"], np.float64)
    if "q_ref" in arrays and "q" in arrays:
        out["error"] = np.degrees(np.asarray(arrays["q_ref"], np.float64)
                                  - np.asarray(arrays["q"], np.float64))
    return out


def tool_paths(arrays: Mapping[str, NDArray[Any]]) -> list[dict[str, Any]]:
    """Each recorded tool point's path (``tcp_pos`` and per-robot ``<name>_tcp_pos``) with
    its times and the arc-on flags (the bead)."""
    t = np.asarray(arrays["t"], np.float64)
    keys = sorted(k for k in arrays if k == "tcp_pos" or k.endswith("_tcp_pos"))
    out = []
    for k in keys:
        p = np.asarray(arrays[k], np.float64)
        if p.ndim != 2 or p.shape != (t.size, 3):
            continue
        prefix = k[: -len("tcp_pos")]
        arc = arrays.get(f"{prefix}arc_on", arrays.get("arc_on"))
        arc_on = (np.asarray(arc, bool) if arc is not None and np.shape(arc) == t.shape
                  else np.zeros(t.size, bool))
        idx = path_indices(t.size)
        out.append({"name": prefix.rstrip("_") or "tool", "t": b64(t[idx]),
                    "pos": b64(p[idx]), "arc": b64(arc_on[idx], "u1")})
    return out


#: Width over height the framed overview is fitted for (the page's canvas is its width by 480 px).
OVERVIEW_ASPECT = 2.0


def framed_overview(model: Any, qpos: NDArray[np.float64]) -> list[dict[str, Any]]:
    """The video's framed overview (:func:`sim.analysis.framing.overview_view`: the cell's
    ``overview`` direction, the robot's swept volume and the cell's objects in the image) as
    a world camera preset named ``framed overview``, the replay's first view; none for a
    model without a robot (``robot/`` bodies)."""
    import mujoco

    from sim.analysis.framing import FOVY_DEG, direction, overview_view

    cid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "overview")
    view = overview_view(model, qpos, cid if cid >= 0 else None, OVERVIEW_ASPECT)
    if view is None:
        return []
    forward = direction(view.azimuth, view.elevation)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rot = np.column_stack([right, up, -forward])  # a camera looks along its -z, y up
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, rot.reshape(-1))
    pos = np.asarray(view.lookat, float) - view.distance * forward
    return [{"name": "framed overview", "body": 0, "pos": [float(v) for v in pos],
             "quat": [float(v) for v in quat], "fovy": FOVY_DEG}]


def build_payload(model: Any, arrays: Mapping[str, NDArray[Any]], summary: Mapping[str, Any],
                  joints: list[str], *, fps: float = DISPLAY_FPS,
                  budget: int = POSE_BUDGET) -> dict[str, Any]:
    """The page's data for a compiled model and a run's recorded arrays.

    Args:
        model: The run's ``MjModel``.
        arrays: The recorded arrays (``t`` and ``qpos`` needed; ``qpos`` width ``model.nq``).
        summary: The run's summary (phases, collisions, clearance, scenario name).
        joints: Joint names (chart legends).
        fps: Display rate, frames per second.
        budget: Most (frame, moving body) poses.

    Raises:
        ValueError: ``qpos`` is missing or does not match the model.
    """
    t = np.asarray(arrays["t"], np.float64)
    qpos = np.asarray(arrays.get("qpos", np.zeros((0, 0))), np.float64)
    if qpos.ndim != 2 or qpos.shape != (t.size, model.nq):
        raise ValueError(f"qpos has shape {qpos.shape}, the model needs ({t.size}, {model.nq})")
    geoms, meshes = geoms_and_meshes(model)
    first = frame_indices(t, fps, 2)
    pos0, quat0 = body_poses(model, qpos[first])
    moving = moving_bodies(*body_poses(model, qpos[frame_indices(t, 2.0, 400)]))
    max_frames = max(2, budget // max(1, moving.size))
    idx = frame_indices(t, fps, max_frames)
    pos, quat = body_poses(model, qpos[idx])
    moving = np.union1d(moving, moving_bodies(pos, quat)).astype(np.int64)
    charts = []
    for cid, title, unit in CHARTS:
        series = chart_series(arrays).get(cid)
        if series is None or series.shape[0] != t.size:
            continue
        x, y = minmax_bins(t, series)
        charts.append({"id": cid, "title": title, "unit": unit, "x": b64(x),
                       "y": [b64(row) for row in y],
                       "labels": [joints[i] if i < len(joints) else f"j{i + 1}"
                                  for i in range(y.shape[0])]})
    clear = summary.get("clearance")
    from sim.simulation.collision_model import painted_geoms

    def page_names(names: Any) -> list[str]:
        """The page's names (as :func:`~sim.analysis.replay.scene.geoms_and_meshes` gives them) of the geoms a finding paints:
        a robot link's visible geoms, as the video paints it (its collision geoms are hidden)."""
        ids = painted_geoms(model, [str(g) for g in names])
        return [model.geom(g).name or f"geom{g}" for g in sorted(ids)]

    collisions = [{"t0": float(c["t0"]), "t1": float(c["t1"]),
                   "geoms": page_names(c.get("all_geoms", c.get("geoms", []))),
                   "bodies": [str(b) for b in c.get("bodies", [])],
                   "depth_mm": _num(c.get("depth_mm"))}
                  for c in summary.get("collisions") or [] if isinstance(c, Mapping)
                  and isinstance(c.get("t0"), (int, float))
                  and isinstance(c.get("t1"), (int, float))]
    return {
        "title": str(summary.get("scenario", "run")),
        "duration": float(t[-1] - t[0]) if t.size else 0.0, "t0": float(t[0]) if t.size else 0.0,
        "bodies": [model.body(b).name or f"body{b}" for b in range(model.nbody)],
        "geoms": geoms,
        "meshes": [{"vert": b64(m["vert"]), "face": b64(m["face"], "<i4")} for m in meshes],
        "static": {"pos": b64(pos0[0]), "quat": b64(quat0[0])},
        "frames": {"t": b64(t[idx]), "bodies": [int(b) for b in moving],
                   "pos": b64(pos[:, moving]), "quat": b64(quat[:, moving]),
                   "fps": float((idx.size - 1) / (t[-1] - t[0])) if idx.size > 1 else 0.0},
        "cameras": framed_overview(model, qpos) + cameras(model),
        "paths": tool_paths(arrays),
        "charts": charts,
        "phases": [{"name": str(p.get("name", "")), "t0": float(p.get("t0", 0.0)),
                    "t1": float(p.get("t1", 0.0))}
                   for p in summary.get("phases") or [] if isinstance(p, Mapping)],
        "collisions": collisions,
        "clearance": clearance_points(model, t, qpos, clear) if isinstance(clear, list) else [],
    }
