"""The replay's scene: what a run's compiled model looks like and where its bodies are.

Reads a compiled ``MjModel`` (the run's ``model.xml``) and the recorded ``qpos``: the visible
geoms (type, size, colour, pose in their body), the meshes they use (vertices and faces, each
mesh once), the cameras (preset views) and each body's world pose at the display frames,
computed with ``mj_kinematics`` from the recorded ``qpos`` (no OpenGL). Bodies that never move
are stored once. Closest clearance points are computed with ``mj_geomDistance`` at their times.

May import: numpy and mujoco (no other cellsim layer: the caller reads the run folder).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Geom groups shown (MuJoCo's viewer shows 0-2 by default; 3+ are collision-only pieces).
VISIBLE_GROUPS = 3

#: Size used for an infinite plane (MuJoCo size 0), metres (half extent).
PLANE_HALF_M = 4.0

_DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)


def geoms_and_meshes(model: Any) -> tuple[list[dict[str, Any]], list[dict[str, NDArray[Any]]]]:
    """Visible geoms (in model order) and the meshes they use (each once, float32/int32).

    A geom is ``{"name", "body", "type", "size", "pos", "quat", "rgba", "mesh"}`` with the
    MuJoCo type number, ``quat`` as (w, x, y, z) in its body's frame and ``mesh`` an index into
    the returned mesh list (-1 for primitives). Meshes are ``{"vert": (n,3), "face": (m,3)}``.
    """
    import mujoco

    geoms: list[dict[str, Any]] = []
    mesh_index: dict[int, int] = {}
    meshes: list[dict[str, NDArray[Any]]] = []
    for g in range(model.ngeom):
        if int(model.geom_group[g]) >= VISIBLE_GROUPS:
            continue
        rgba = [float(v) for v in model.geom_rgba[g]]
        mat = int(model.geom_matid[g])
        if mat >= 0 and tuple(rgba) == _DEFAULT_RGBA:
            rgba = [float(v) for v in model.mat_rgba[mat]]
        if rgba[3] <= 0.0:
            continue
        gtype = int(model.geom_type[g])
        mid = -1
        if gtype == int(mujoco.mjtGeom.mjGEOM_MESH):
            src = int(model.geom_dataid[g])
            if src not in mesh_index:
                v0, nv = int(model.mesh_vertadr[src]), int(model.mesh_vertnum[src])
                f0, nf = int(model.mesh_faceadr[src]), int(model.mesh_facenum[src])
                mesh_index[src] = len(meshes)
                meshes.append({"vert": np.asarray(model.mesh_vert[v0:v0 + nv], np.float32),
                               "face": np.asarray(model.mesh_face[f0:f0 + nf], np.int32)})
            mid = mesh_index[src]
        elif gtype not in _PRIMITIVES:
            continue  # heightfields, SDFs: not drawn
        size = [float(v) for v in model.geom_size[g]]
        if gtype == int(mujoco.mjtGeom.mjGEOM_PLANE):
            size = [s if s > 0 else PLANE_HALF_M for s in size[:2]] + [size[2]]
        geoms.append({"name": model.geom(g).name or f"geom{g}", "id": g,
                      "body": int(model.geom_bodyid[g]), "type": gtype, "size": size,
                      "pos": [float(v) for v in model.geom_pos[g]],
                      "quat": [float(v) for v in model.geom_quat[g]],
                      "rgba": rgba, "mesh": mid})
    return geoms, meshes


#: MuJoCo primitive geom types the page draws: plane, sphere, capsule, ellipsoid, cylinder, box.
_PRIMITIVES = frozenset({0, 2, 3, 4, 5, 6})


def frame_indices(t: NDArray[np.float64], fps: float, max_frames: int) -> NDArray[np.int64]:
    """Indices of the recorded samples shown as display frames: one per ``1/fps`` seconds
    (the recorded sample at or just after each frame time), at most ``max_frames``, the first
    and last sample always included (so at least two frames when the run lasts)."""
    t = np.asarray(t, np.float64)
    if t.size == 0:
        return np.zeros(0, np.int64)
    duration = float(t[-1] - t[0])
    n = int(np.floor(duration * fps)) + 1 if duration > 0 else 1
    n = max(2 if duration > 0 else 1, min(n, max_frames))
    want = np.linspace(t[0], t[-1], n) if n > 1 else t[:1]
    idx = np.searchsorted(t, want, side="left").clip(0, t.size - 1)
    idx[-1] = t.size - 1
    return np.unique(idx)


def body_poses(model: Any, qpos: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                                 NDArray[np.float64]]:
    """World position (F, nbody, 3) and quaternion (F, nbody, 4; w, x, y, z) of every body at
    each row of ``qpos`` (``mj_kinematics``)."""
    import mujoco

    data = mujoco.MjData(model)
    frames = qpos.shape[0]
    pos = np.empty((frames, model.nbody, 3))
    quat = np.empty((frames, model.nbody, 4))
    for i in range(frames):
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        pos[i] = data.xpos
        quat[i] = data.xquat
    return pos, quat


def moving_bodies(pos: NDArray[np.float64], quat: NDArray[np.float64]) -> NDArray[np.int64]:
    """Bodies whose pose changes over the frames (the others are drawn at their first pose)."""
    if pos.shape[0] < 2:
        return np.zeros(0, np.int64)
    dp = np.ptp(pos, axis=0).max(axis=1)
    dq = np.ptp(quat, axis=0).max(axis=1)
    return np.flatnonzero((dp > 0) | (dq > 0)).astype(np.int64)


def cameras(model: Any) -> list[dict[str, Any]]:
    """The model's cameras as preset views: body, pose in the body, vertical field of view."""
    return [{"name": model.camera(c).name or f"camera{c}", "body": int(model.cam_bodyid[c]),
             "pos": [float(v) for v in model.cam_pos[c]],
             "quat": [float(v) for v in model.cam_quat[c]],
             "fovy": float(model.cam_fovy[c])} for c in range(model.ncam)]


def clearance_points(model: Any, t: NDArray[np.float64], qpos: NDArray[np.float64],
                     entries: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The closest points of each clearance entry of ``summary.json`` (``tool_pair``/``tool_t``,
    ``arm_pair``/``arm_t``), recomputed at the recorded sample nearest its time."""
    import mujoco

    data = mujoco.MjData(model)
    out: list[dict[str, Any]] = []
    for e in entries:
        for grp in ("tool", "arm"):
            pair, when = e.get(f"{grp}_pair"), e.get(f"{grp}_t")
            if not isinstance(pair, list) or len(pair) != 2 or not isinstance(when, (int, float)):
                continue
            ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, str(n)) for n in pair]
            if min(ids) < 0:
                continue
            i = int(np.clip(np.searchsorted(t, float(when)), 0, t.size - 1))
            data.qpos[:] = qpos[i]
            mujoco.mj_kinematics(model, data)
            fromto = np.zeros(6)
            dist = mujoco.mj_geomDistance(model, data, ids[0], ids[1], 1.0, fromto)
            out.append({"t": float(t[i]), "group": grp, "phase": str(e.get("phase", "")),
                        "pair": [str(n) for n in pair], "mm": float(dist) * 1e3,
                        "a": [float(v) for v in fromto[:3]], "b": [float(v) for v in fromto[3:]]})
    return out
