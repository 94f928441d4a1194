"""Cameras that frame what matters, computed from the run.

* ``overview``: keeps the direction of the cell's ``overview`` camera (its azimuth, and at least
  :data:`MIN_ELEVATION_DEG` looking down, so an arm behind the robot's base stays in view) and
  computes its target and distance so that the robot's whole swept volume over the cycle
  (every link's bounding sphere at :data:`SWEEP_SAMPLES` times) and the cell's objects (their
  bounding boxes; the floor excepted) fit the image with a :data:`MARGIN` on every side.
* ``tool``: follows the tool point: it looks at the tcp from the direction of the cell's
  ``tool`` camera, at a distance that shows :data:`TOOL_VIEW_M` around it.

Both are MuJoCo free cameras (:class:`mujoco.MjvCamera`): ``lookat``, ``distance``,
``azimuth`` and ``elevation``, with the model's ``visual/global/fovy``. Other camera names
render the model's camera as it is.

Geometry of the run only (``mj_kinematics`` of the recorded ``qpos``, no OpenGL): the video
(:mod:`sim.render.frames`) and the 3D replay's first view
(:func:`sim.analysis.replay.payload.framed_overview`) share it.
May import: numpy and mujoco.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Times along the cycle at which the robot's links are collected for the swept volume.
SWEEP_SAMPLES = 120
#: Free margin on each side of the image, as a fraction of its half-size.
MARGIN = 0.08
#: The overview looks down at least this much, deg.
MIN_ELEVATION_DEG = 25.0
#: The tool camera shows this far around the tool point (half the image height), m.
TOOL_VIEW_M = 0.35
#: The framed cameras' vertical field of view, deg.
FOVY_DEG = 45.0


@dataclass
class FreeView:
    """A free camera: where it looks and from where (MuJoCo's mjvCamera convention)."""

    lookat: NDArray[np.float64]
    distance: float
    azimuth: float
    elevation: float
    track_site: int | None = None  # follow this site (the tool point)

    def camera(self) -> Any:
        import mujoco

        cam = mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        cam.lookat[:] = self.lookat
        cam.distance = self.distance
        cam.azimuth = self.azimuth
        cam.elevation = self.elevation
        return cam

    def forward(self) -> NDArray[np.float64]:
        """Unit viewing direction (from the camera to ``lookat``)."""
        return direction(self.azimuth, self.elevation)

    def position(self) -> NDArray[np.float64]:
        return np.asarray(self.lookat, float) - self.distance * self.forward()


def direction(azimuth_deg: float, elevation_deg: float) -> NDArray[np.float64]:
    """MuJoCo's free-camera viewing direction for an azimuth and an elevation, deg."""
    a, e = math.radians(azimuth_deg), math.radians(elevation_deg)
    return np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])


def angles(forward: NDArray[np.float64]) -> tuple[float, float]:
    """Azimuth and elevation, deg, of a viewing direction."""
    f = np.asarray(forward, float) / np.linalg.norm(forward)
    return math.degrees(math.atan2(f[1], f[0])), math.degrees(math.asin(np.clip(f[2], -1, 1)))


def model_camera_forward(model: Any, cam_id: int, data: Any) -> NDArray[np.float64]:
    """Viewing direction of a model camera (its -z axis) at the current state."""
    return -np.asarray(data.cam_xmat[cam_id]).reshape(3, 3)[:, 2]


def fit(points: NDArray[np.float64], forward: NDArray[np.float64], fovy_deg: float,
        aspect: float, margin: float = MARGIN) -> tuple[NDArray[np.float64], float]:
    """Target and distance of a camera looking along ``forward`` that sees every point.

    With ``x``, ``y`` the image axes and the camera at ``c - d f``, a point ``q`` is in view when
    ``|x.(q - c)| <= tx (f.(q - c) + d)`` and likewise for ``y``, ``tx`` and ``ty`` the tangents
    of the half fields of view less the margin; the smallest ``d`` follows for each point. The
    target is moved to centre the projected extents, and ``d`` computed again.
    """
    f = np.asarray(forward, float) / np.linalg.norm(forward)
    up = np.array([0.0, 0.0, 1.0])
    x = np.cross(f, up)
    if np.linalg.norm(x) < 1e-9:
        x = np.array([1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(x, f)
    ty = math.tan(math.radians(fovy_deg) / 2) * (1 - margin)
    tx = ty * aspect
    c = 0.5 * (points.min(axis=0) + points.max(axis=0))
    d = 0.0
    for _ in range(4):
        rel = points - c
        a, b, s = rel @ x, rel @ y, rel @ f
        d = float(np.max(np.maximum(np.abs(a) / tx, np.abs(b) / ty) - s))
        z = s + d
        # centre the view: shift the target by the mean of the extreme projections
        ua, ub = a / z, b / z
        shift_x = 0.5 * (ua.max() + ua.min()) * d
        shift_y = 0.5 * (ub.max() + ub.min()) * d
        c = c + shift_x * x + shift_y * y
    rel = points - c
    d = float(np.max(np.maximum(np.abs(rel @ x) / tx, np.abs(rel @ y) / ty) - rel @ f))
    return c, max(d, 1e-3)


def swept_points(model: Any, qpos: NDArray[np.float64], samples: int = SWEEP_SAMPLES
                 ) -> NDArray[np.float64]:
    """Points bounding the robot over the cycle and the cell's objects (world, m).

    Robot geoms (bodies named ``robot/...``, visual groups 0-2) as the 8 corners of the cube
    around their bounding sphere at ``samples`` times; static geoms but planes as the corners
    of their bounding boxes; parts where they start.
    """
    import mujoco

    data = mujoco.MjData(model)
    names = [model.body(int(b)).name for b in model.geom_bodyid]
    robot = np.array([n.startswith("robot/") and model.geom_group[g] <= 2
                      and model.geom_rgba[g, 3] > 0 for g, n in enumerate(names)])
    static = (~robot) & (model.geom_type != mujoco.mjtGeom.mjGEOM_PLANE) & (
        model.geom_rgba[:, 3] > 0) & (model.geom_group <= 2)
    cube = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)],
                    dtype=float)
    pts = []
    idx = np.unique(np.linspace(0, len(qpos) - 1, min(samples, len(qpos))).astype(int))
    r = model.geom_rbound[robot]
    for i in idx:
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        centres = data.geom_xpos[robot]
        pts.append((centres[:, None, :] + r[:, None, None] * cube[None]).reshape(-1, 3))
    data.qpos[:] = qpos[0]
    mujoco.mj_kinematics(model, data)
    for g in np.flatnonzero(static):
        half = model.geom_aabb[g, 3:]
        centre = model.geom_aabb[g, :3]
        R = data.geom_xmat[g].reshape(3, 3)
        corners = (centre + cube * half) @ R.T + data.geom_xpos[g]
        pts.append(corners)
    return np.vstack(pts) if pts else np.zeros((0, 3))


def overview_view(model: Any, qpos: NDArray[np.float64], cam_id: int | None, aspect: float
                  ) -> FreeView | None:
    """The framed overview (module docstring); None when the model has no robot (``robot/``
    bodies) to frame: its own camera is used as it is."""
    import mujoco

    if not any(model.body(b).name.startswith("robot/") for b in range(model.nbody)):
        return None
    data = mujoco.MjData(model)
    data.qpos[:] = qpos[0]
    mujoco.mj_kinematics(model, data)
    mujoco.mj_camlight(model, data)
    forward = (model_camera_forward(model, cam_id, data) if cam_id is not None
               else direction(140.0, -30.0))
    az, el = angles(forward)
    el = min(el, -MIN_ELEVATION_DEG)
    forward = direction(az, el)
    target, dist = fit(swept_points(model, qpos), forward, FOVY_DEG, aspect)
    return FreeView(target, dist, az, el)


def tool_view(model: Any, qpos: NDArray[np.float64], cam_id: int | None, tcp_site: int,
              ) -> FreeView:
    """The camera that follows the tool point (module docstring)."""
    import mujoco

    data = mujoco.MjData(model)
    data.qpos[:] = qpos[0]
    mujoco.mj_kinematics(model, data)
    mujoco.mj_camlight(model, data)
    if cam_id is not None:
        forward = data.site_xpos[tcp_site] - data.cam_xpos[cam_id]
    else:
        forward = direction(120.0, -30.0)
    az, el = angles(forward)
    el = min(el, -10.0)
    dist = TOOL_VIEW_M / math.tan(math.radians(FOVY_DEG) / 2)
    return FreeView(data.site_xpos[tcp_site].copy(), dist, az, el, track_site=tcp_site)
