"""Simulate a reference motion with the robot's position actuators and record it.

With feed-forward on (the default) the drives also apply ``tau_id``, the inverse dynamics of
the reference (``mj_inverse``), and the set-point carries the velocity feed-forward
``ctrl = q_ref + (kv/kp) qd_ref``, so the servo force ``kp (q_ref - q) + kv (qd_ref - qd)``
only corrects errors. Without feed-forward the arm lags by about ``(kv/kp) qd`` plus
``tau/kp``. Steps run in C through ``mujoco.rollout`` in chunks, with the controls precomputed
(they do not depend on the state), and every chunk is checked for NaN and MuJoCo warnings.

Recorded torque ``tau`` is what the joint's drive delivers: the position actuator's force plus
the feed-forward torque. ``tau_id`` is the inverse dynamics of the reference motion.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from numpy.typing import NDArray

from sim.errors import SimulationError
from sim.simulation.compile import BuiltCell
from sim.simulation.motion import Motion

#: Steps per rollout chunk (checked for instability after each).
CHUNK_STEPS = 2000


@dataclass
class SimulationRecord:
    """What the simulation recorded, N samples at the physics rate (SI units, world frame)."""

    arrays: dict[str, NDArray[Any]]
    wall_s: float
    steps: int
    timestep: float


# --------------------------------------------------------------------------------------------
# Simulation
# --------------------------------------------------------------------------------------------


def inverse_dynamics(model: Any, built: BuiltCell, q: NDArray[np.float64],
                     qd: NDArray[np.float64], qdd: NDArray[np.float64]) -> NDArray[np.float64]:
    """Joint torques that realise the reference exactly (``mj_inverse``), (N, n_joints), N m.

    The robot's own dynamics with its tool and payload: gravity, inertia (with armature),
    joint damping and friction. Contacts are switched off for the computation (a reference
    that touches a part would otherwise count the contact's push as the robot's torque), the
    rest of the model (parts) stays at its initial pose and at rest, and a part held by
    suction is not included (it is in the simulated torque).
    """
    import mujoco

    data = mujoco.MjData(model)
    mujoco.mj_resetData(model, data)
    out = np.zeros_like(q)
    flags = model.opt.disableflags
    model.opt.disableflags = flags | int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    try:
        for k in range(q.shape[0]):
            data.qpos[built.robot_qpos] = q[k]
            data.qvel[:] = 0.0
            data.qvel[built.robot_dof] = qd[k]
            data.qacc[:] = 0.0
            data.qacc[built.robot_dof] = qdd[k]
            mujoco.mj_inverse(model, data)
            out[k] = data.qfrc_inverse[built.robot_dof]
    finally:
        model.opt.disableflags = flags
    return out


def simulate(built: BuiltCell, motion: Motion, *, feedforward: bool, settle_s: float = 0.0,
             progress: bool = True,
             on_failure: Callable[[dict[str, NDArray[Any]], str], None] | None = None
             ) -> SimulationRecord:
    """Simulate the reference motion with position actuators; see the module docstring.

    Raises:
        SimulationError: NaN or a MuJoCo warning; the message names the time and the joint.
            ``on_failure(partial_arrays, message)`` is called first with what was recorded.
    """
    import mujoco
    from mujoco import rollout

    model = built.model
    dt = float(model.opt.timestep)
    n_steps = int(round((motion.duration + settle_s) / dt))
    t = motion.t0 + dt * np.arange(n_steps + 1)
    ref = motion.at(t)
    kp = model.actuator_gainprm[built.robot_act, 0]
    kv = -model.actuator_biasprm[built.robot_act, 2]

    tau_id = inverse_dynamics(model, built, ref.q, ref.qd, ref.qdd)
    ff = tau_id if feedforward else np.zeros_like(tau_id)

    nu, nv = model.nu, model.nv
    controls = np.zeros((n_steps + 1, nu + nv))
    # A position actuator's force is kp (ctrl - q) - kv qd. With feed-forward the set-point is
    # shifted by (kv/kp) qd_ref, so the servo acts on the velocity error too and its own force
    # stays a small correction (the damping term alone would saturate forcerange at speed).
    controls[:, built.robot_act] = ref.q + (kv / kp) * ref.qd if feedforward else ref.q
    if built.suction_act is not None:
        controls[:, built.suction_act] = motion.tool_state(t, "suction").astype(float)
    controls[:, nu + built.robot_dof] = ff

    data = mujoco.MjData(model)
    mujoco.mj_resetData(model, data)
    data.qpos[built.robot_qpos] = ref.q[0]
    data.qvel[built.robot_dof] = ref.qd[0]
    data.time = motion.t0
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    qpos_slice = slice(1, 1 + model.nq)  # FULLPHYSICS = time, qpos, qvel, act, ...
    qvel_slice = slice(1 + model.nq, 1 + model.nq + nv)

    qpos = np.zeros((n_steps + 1, model.nq))
    qvel = np.zeros((n_steps + 1, nv))
    sens = np.zeros((n_steps + 1, model.nsensordata))
    qpos[0], qvel[0] = data.qpos, data.qvel
    control_spec = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED
    scratch = mujoco.MjData(model)

    from tqdm import tqdm

    bar = tqdm(total=n_steps, unit="step", desc="simulate", leave=False,
               disable=not progress or not sys.stderr.isatty())
    wall = 0.0
    k = 0
    try:
        while k < n_steps:
            m = min(CHUNK_STEPS, n_steps - k)
            for w in scratch.warning:
                w.number = 0
            t_start = time.perf_counter()
            st, sd = rollout.rollout(model, scratch, state, controls[k:k + m][None],
                                     control_spec=control_spec)
            wall += time.perf_counter() - t_start
            st, sd = st[0], sd[0]
            qpos[k + 1:k + m + 1] = st[:, qpos_slice]
            qvel[k + 1:k + m + 1] = st[:, qvel_slice]
            sens[k:k + m] = sd
            problem = _instability(model, scratch, st, t[k], dt, built, qpos_slice)
            if problem is not None:
                bad_step, message = problem
                partial = _arrays(built, motion, t[:k + bad_step + 1], ref, tau_id, ff,
                                  qpos[:k + bad_step + 1], qvel[:k + bad_step + 1],
                                  sens[:k + bad_step + 1])
                if on_failure is not None:
                    on_failure(partial, message)
                raise SimulationError(message)
            state = st[-1].copy()
            k += m
            bar.update(m)
    finally:
        bar.close()
    # sensors of the final state
    mujoco.mj_setState(model, scratch, state, spec)
    mujoco.mj_forward(model, scratch)
    sens[n_steps] = scratch.sensordata
    arrays = _arrays(built, motion, t, ref, tau_id, ff, qpos, qvel, sens)
    return SimulationRecord(arrays=arrays, wall_s=wall, steps=n_steps, timestep=dt)


def _instability(model: Any, scratch: Any, st: NDArray[np.float64], t0: float, dt: float,
                 built: BuiltCell, qpos_slice: slice) -> tuple[int, str] | None:
    import mujoco

    bad_rows = ~np.all(np.isfinite(st), axis=1)
    times = st[:, 0]
    resets = np.nonzero(np.diff(times) < 0)[0]
    warned = [(i, w) for i, w in enumerate(scratch.warning) if w.number > 0]
    if not warned and not bad_rows.any() and resets.size == 0:
        return None
    step = int(np.argmax(bad_rows)) if bad_rows.any() else (int(resets[0]) + 1 if resets.size else 0)
    names = {int(v): k for k, v in mujoco.mjtWarning.__members__.items()}
    joint = "?"
    detail = "NaN in the state"
    if warned:
        i, w = warned[0]
        detail = f"MuJoCo warning {names.get(i, i)}"
        if i in (int(mujoco.mjtWarning.mjWARN_BADQACC), int(mujoco.mjtWarning.mjWARN_BADQVEL),
                 int(mujoco.mjtWarning.mjWARN_BADQPOS)) and 0 <= w.lastinfo < model.nv:
            jid = model.dof_jntid[w.lastinfo]
            joint = model.joint(jid).name or f"dof {w.lastinfo}"
    if joint == "?" and bad_rows.any():
        row = st[step, qpos_slice]
        bad = np.nonzero(~np.isfinite(row))[0]
        if bad.size:
            jid = int(np.searchsorted(model.jnt_qposadr, bad[0], side="right") - 1)
            joint = model.joint(jid).name
    return step, (f"simulation unstable at t = {t0 + dt * (step + 1):.4f} s, joint {joint}: "
                  f"{detail}; try a smaller simulation.timestep_s")


def _arrays(built: BuiltCell, motion: Motion, t: NDArray[np.float64], ref: Any,
            tau_id: NDArray[np.float64], ff: NDArray[np.float64], qpos: NDArray[np.float64],
            qvel: NDArray[np.float64], sens: NDArray[np.float64]) -> dict[str, NDArray[Any]]:
    n = t.size
    nj = motion.n_joints
    tau_act = np.column_stack([sens[:, built.sensor_slices[f"tau{i}"]] for i in range(nj)]) \
        if nj else np.zeros((n, 0))
    kin = built.context.kinematics
    T0 = built.context.world_from_frame0
    poses = np.asarray(kin.fk(ref.q[:n]), dtype=float).reshape(n, 4, 4)
    tcp_ref = poses[:, :3, 3] @ T0[:3, :3].T + T0[:3, 3]
    out: dict[str, NDArray[Any]] = {
        "t": t,
        "phase": motion.phase_index(t).astype(np.int32),
        "q_ref": ref.q[:n], "qd_ref": ref.qd[:n], "qdd_ref": ref.qdd[:n],
        "qddd_ref": ref.qddd[:n],
        "q": qpos[:, built.robot_qpos], "qd": qvel[:, built.robot_dof],
        "qdd": _sim_acceleration(qvel[:, built.robot_dof], t),
        "tau": tau_act + ff[:n], "tau_actuator": tau_act, "tau_ff": ff[:n],
        "tau_id": tau_id[:n],
        "tcp_pos": sens[:, built.sensor_slices["tcp_pos"]],
        "tcp_pos_ref": tcp_ref,
        "tcp_quat": sens[:, built.sensor_slices["tcp_quat"]],
        "qpos": qpos,
        "arc_on": motion.tool_state(t, "arc"),
        "suction": motion.tool_state(t, "suction"),
        "knot_t": motion.knot_times(),
    }
    if built.part_qpos:
        out["part_pos"] = np.stack([qpos[:, a[:3]] for a in built.part_qpos], axis=1)
        out["part_quat"] = np.stack([qpos[:, a[3:]] for a in built.part_qpos], axis=1)
    return out


def _sim_acceleration(qd: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """Simulated joint acceleration: the integrator's own velocity increments over each step
    (``(qd[k+1] - qd[k]) / dt``, the last row repeated), rad/s^2."""
    if qd.shape[0] < 2:
        return np.zeros_like(qd)
    acc = np.diff(qd, axis=0) / np.diff(t)[:, None]
    return np.vstack([acc, acc[-1:]])

