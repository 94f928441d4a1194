"""A small synthetic run folder: a 4-axis demo welding arm and a 3-phase trajectory.

Used by the rendering/plot tests and benchmarks so that they do not depend on the robot
models or on the simulator. The folder has the layout ``cellsim run`` writes
(``model.xml``, ``summary.json``, ``trajectory.npz``; see :mod:`sim.simulation.runfolder`):

* model: a table with a cylindrical part on a free joint (listed first, so the arm's joints
  do not start at ``qpos[0]``), a 4R arm (``j1`` about z, ``j2``/``j3`` about y, ``j4`` about
  x) with a torch whose tip is the ``tcp`` site, cameras ``overview`` (world) and ``tool``
  (on the last link);
* trajectory: phases ``approach`` / ``weld`` / ``return``; the reference ``q_ref`` is a
  quintic interpolating spline through the knots, at rest at both ends; the "actual" ``q``
  lags it by :data:`LAG_S`; ``tau_id`` is MuJoCo's inverse dynamics of the reference
  (``mj_inverse``) and ``tau`` adds a small ripple; the part turns about its axis at
  :data:`PART_SPIN` rad/s (as on a positioner), so ``qpos`` holds a moving free joint;
  ``arc_on`` is true during ``weld``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.interpolate import make_interp_spline

from sim.simulation import runfolder

#: Joint names of the demo arm.
JOINTS: tuple[str, ...] = ("j1", "j2", "j3", "j4")
#: Time lag of the "actual" joint path behind the reference, s.
LAG_S = 0.03
#: Spin rate of the part's free joint about world z, rad/s.
PART_SPIN = 1.5
#: Knot positions of the reference (rad), one row per knot, at normalized times KNOT_U.
KNOT_Q = np.array(
    [
        [0.0, -0.90, 1.50, 0.0],
        [-0.32, -1.00, 1.10, 0.10],
        [-0.14, -0.71, 0.775, 0.0],
        [0.0, -0.71, 0.775, 0.0],
        [0.14, -0.71, 0.775, 0.0],
        [0.20, -0.83, 0.67, -0.10],
        [0.0, -0.90, 1.50, 0.0],
    ]
)
#: Knot times as fractions of the duration; phases: [0, 0.3], [0.3, 0.7], [0.7, 1].
KNOT_U = np.array([0.0, 0.15, 0.3, 0.5, 0.7, 0.85, 1.0])
PHASES: tuple[tuple[str, str, float, float], ...] = (
    ("approach", "joint", 0.0, 0.3),
    ("weld", "cartesian", 0.3, 0.7),
    ("return", "joint", 0.7, 1.0),
)


def _xyaxes(pos: np.ndarray, target: np.ndarray) -> str:
    """MJCF ``xyaxes`` of a camera at ``pos`` looking at ``target`` with world z up."""
    forward = target - pos
    forward /= np.linalg.norm(forward)
    x = np.cross(forward, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(x, forward)
    return " ".join(f"{v:.6f}" for v in (*x, *y))


def demo_model_xml(offwidth: int = 1280, offheight: int = 720) -> str:
    """MJCF of the demo cell.

    Args:
        offwidth: Offscreen framebuffer width, pixels.
        offheight: Offscreen framebuffer height, pixels.

    Returns:
        The XML text.
    """
    overview_pos = np.array([1.25, -1.05, 1.0])
    overview = _xyaxes(overview_pos, np.array([0.38, 0.0, 0.35]))
    # Tool camera on link4 (frame aligned with the world at q = 0), looking at the torch tip.
    tool_pos = np.array([0.28, -0.26, 0.02])
    tool = _xyaxes(tool_pos, np.array([0.06, 0.0, -0.16]))
    over_p, tool_p = (" ".join(f"{v:g}" for v in p) for p in (overview_pos, tool_pos))
    return f"""<mujoco model="demo_cell">
  <compiler angle="radian"/>
  <option timestep="0.002"/>
  <visual>
    <global offwidth="{offwidth}" offheight="{offheight}"/>
    <quality shadowsize="1024"/>
  </visual>
  <asset>
    <texture name="grid" type="2d" builtin="checker" rgb1=".22 .24 .28" rgb2=".28 .30 .34"
             width="128" height="128"/>
    <material name="grid" texture="grid" texrepeat="6 6"/>
  </asset>
  <default>
    <geom contype="0" conaffinity="0" rgba=".72 .74 .78 1"/>
    <joint damping="0.5" armature="0.01"/>
  </default>
  <worldbody>
    <light pos="0.5 -0.5 2.5" dir="0 0.2 -1" diffuse=".8 .8 .8"/>
    <camera name="overview" pos="{over_p}" xyaxes="{overview}"/>
    <geom name="floor" type="plane" size="2 2 0.05" material="grid"/>
    <geom name="table" type="box" pos="0.62 0 0.15" size="0.22 0.32 0.15" rgba=".30 .36 .48 1"/>
    <body name="part" pos="0.62 0 0.36">
      <freejoint name="part"/>
      <geom name="part" type="cylinder" size="0.1 0.06" rgba=".55 .57 .62 1" mass="2"/>
      <geom name="part_mark" type="box" pos="0.08 0 0.061" size="0.012 0.008 0.002"
            rgba=".1 .1 .1 1" mass="0.01"/>
    </body>
    <body name="base">
      <geom type="cylinder" pos="0 0 0.05" size="0.12 0.05" rgba=".25 .25 .28 1"/>
      <body name="link1" pos="0 0 0.1">
        <joint name="j1" axis="0 0 1" range="-3 3"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.055" mass="4"/>
        <body name="link2" pos="0 0 0.3">
          <joint name="j2" axis="0 1 0" range="-2 2"/>
          <geom type="capsule" fromto="0 0 0 0.35 0 0" size="0.045" mass="3"/>
          <body name="link3" pos="0.35 0 0">
            <joint name="j3" axis="0 1 0" range="-2.5 2.5"/>
            <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.035" mass="2"/>
            <body name="link4" pos="0.3 0 0">
              <joint name="j4" axis="1 0 0" range="-3 3"/>
              <geom type="cylinder" fromto="0 0 0 0.06 0 0" size="0.04" mass="0.8"/>
              <geom name="torch" type="capsule" fromto="0.06 0 0 0.06 0 -0.15" size="0.012"
                    rgba=".85 .85 .2 1" mass="0.3"/>
              <site name="tcp" pos="0.06 0 -0.165" size="0.008"/>
              <camera name="tool" pos="{tool_p}" xyaxes="{tool}"/>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="j1" joint="j1"/>
    <motor name="j2" joint="j2"/>
    <motor name="j3" joint="j3"/>
    <motor name="j4" joint="j4"/>
  </actuator>
</mujoco>
"""


def _spin_quat(angle: np.ndarray) -> np.ndarray:
    """Unit quaternions (w, x, y, z) of rotations by ``angle`` (N,) about world z, (N, 4)."""
    half = 0.5 * np.asarray(angle, dtype=float)
    return np.stack([np.cos(half), np.zeros_like(half), np.zeros_like(half), np.sin(half)], 1)


def write_synthetic_run(
    folder: str | Path,
    *,
    duration: float = 2.0,
    rate: float = 100.0,
    offwidth: int = 1280,
    offheight: int = 720,
) -> Path:
    """Writes a synthetic run folder (``model.xml``, ``summary.json``, ``trajectory.npz``).

    Args:
        folder: Folder to create (parents too); existing files are overwritten.
        duration: Cycle time, s.
        rate: Recording rate, Hz (samples at ``k / rate``).
        offwidth: Offscreen framebuffer width written into the model, pixels.
        offheight: Offscreen framebuffer height written into the model, pixels.

    Returns:
        The folder's path.
    """
    import mujoco

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    xml = demo_model_xml(offwidth, offheight)
    runfolder.write_text(folder, runfolder.MODEL_XML, xml)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)

    n = int(np.floor(duration * rate + 1e-9)) + 1
    t = np.arange(n) / rate
    knot_t = KNOT_U * duration
    rest = [(1, np.zeros(len(JOINTS))), (2, np.zeros(len(JOINTS)))]
    spline = make_interp_spline(knot_t, KNOT_Q, k=5, bc_type=(rest, rest))
    derivs = [spline.derivative(k) if k else spline for k in range(4)]
    q_ref, qd_ref, qdd_ref, qddd_ref = (d(t) for d in derivs)
    t_lag = np.clip(t - LAG_S, 0.0, duration)
    q = spline(t_lag)
    qd = derivs[1](t_lag) * (t - LAG_S >= 0.0)[:, None]

    jnt = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) for name in JOINTS]
    qadr = np.array([model.jnt_qposadr[j] for j in jnt])
    vadr = np.array([model.jnt_dofadr[j] for j in jnt])
    part = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "part")
    padr = model.jnt_qposadr[part]
    tcp = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tcp")

    qpos = np.tile(model.qpos0, (n, 1))
    qpos[:, qadr] = q
    qpos[:, padr + 3 : padr + 7] = _spin_quat(PART_SPIN * t)

    tcp_pos = np.empty((n, 3))
    tcp_pos_ref = np.empty((n, 3))
    tcp_quat = np.empty((n, 4))
    tau_id = np.empty((n, len(JOINTS)))
    for i in range(n):
        data.qpos[:] = qpos[i]
        data.qpos[qadr] = q_ref[i]
        data.qvel[:] = 0.0
        data.qvel[vadr] = qd_ref[i]
        data.qacc[:] = 0.0
        data.qacc[vadr] = qdd_ref[i]
        mujoco.mj_inverse(model, data)
        tau_id[i] = data.qfrc_inverse[vadr]
        tcp_pos_ref[i] = data.site_xpos[tcp]
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        tcp_pos[i] = data.site_xpos[tcp]
        mujoco.mju_mat2Quat(tcp_quat[i], data.site_xmat[tcp])
    ripple = 0.4 * np.sin(2 * np.pi * 7.0 * t)[:, None] * np.array([1.0, 0.8, 0.6, 0.2])
    tau = tau_id + ripple

    phase = np.zeros(n, dtype=np.int64)
    phases = []
    for index, (name, kind, u0, u1) in enumerate(PHASES):
        t0, t1 = u0 * duration, u1 * duration
        phase[t >= t0 - 1e-12] = index
        phases.append({"name": name, "kind": kind, "t0": t0, "t1": t1})
    weld = PHASES[1]
    arc_on = (t >= weld[2] * duration) & (t <= weld[3] * duration)
    suction = np.zeros(n, dtype=bool)

    runfolder.write_trajectory(folder, dict(
        t=t,
        phase=phase,
        qpos=qpos,
        q_ref=q_ref,
        qd_ref=qd_ref,
        qdd_ref=qdd_ref,
        qddd_ref=qddd_ref,
        q=q,
        qd=qd,
        tau=tau,
        tau_id=tau_id,
        tcp_pos=tcp_pos,
        tcp_pos_ref=tcp_pos_ref,
        tcp_quat=tcp_quat,
        arc_on=arc_on,
        suction=suction,
        knot_t=knot_t,
    ))
    summary = {
        "scenario": "synthetic_demo",
        "robot": "demo_arm",
        "joints": list(JOINTS),
        "phases": phases,
        "duration_s": duration,
    }
    runfolder.write_summary(folder, summary)
    return folder
