"""Simulate a reference motion with the robot's drives and record it.

Each robot joint has one drive: a MuJoCo position actuator whose force is limited by its
``forcerange`` (the drive's peak torque at the joint, ``peak motor torque x ratio x
efficiency``). The whole servo torque passes through it: with feed-forward on (the default)
the control is ``ctrl = q_ref + (kv/kp) qd_ref + tau_ff / kp``, so the drive's force is
``kp (q_ref - q) + kv (qd_ref - qd) + tau_ff``, clamped to the force range. An overloaded
robot therefore sags and lags in the simulation itself. ``tau_ff`` is the inverse dynamics of
the reference with MuJoCo's discrete-time correction for its implicit integrator
(``invdiscrete``: it adds ``h (damping + kv) qdd``), which makes tracking exact; it is never
reported as a torque. Steps run in C through ``mujoco.rollout`` in chunks, with the controls
precomputed (they do not depend on the state), and every chunk is checked for NaN and MuJoCo
warnings.

The drive's limit is its motor's: :class:`~sim.simulation.motor_limit.MotorLimit` checks every
chunk with the motor torque sizing computes (:meth:`sim.robots.registry.Drive.motor_torque`:
the gear's efficiency on the load torque, the rotor's inertia on the motor side) against the
peak torque-speed curve at the motor's own speed, and runs a chunk that passed it again a step
at a time, each drive past its peak held at the joint torque where its motor gives exactly its
peak.

Recorded torques are continuous-time joint torques (what a drive must deliver, independent of
the timestep):

* ``tau_id``, the inverse dynamics of the reference: ``M(q) qdd + c(q, qd) + g(q)`` with the
  armature in ``M``, plus viscous damping ``b qd`` and Coulomb friction
  ``F s(qd)``, where ``s(qd) = clip(qd / COULOMB_SPEED, -1, 1)`` is ``sign(qd)`` for
  ``|qd| >= 1e-3 rad/s`` and linear inside (:func:`sim.robots.registry.coulomb`; the simulation
  applies the same law with one friction actuator per joint, :mod:`sim.cells.compose`);
* ``tau``, the torque the drive applied in the simulated motion. MuJoCo's implicit step
  evaluates the drive's velocity term at the end-of-step speed, ``-kv qd[k+1]``; the actuator
  force it reports is evaluated at ``qd[k]``, so ``tau = actuator force - h kv qdd_sim`` with
  ``qdd_sim = (qd[k+1] - qd[k]) / h`` the step's own acceleration (exactly the force the step
  applied); a saturated drive delivers its limit.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from numpy.typing import NDArray

from sim.errors import SimulationError
from sim.robots.registry import Drive, coulomb
from sim.simulation.compile import BuiltCell
from sim.simulation.motion import Motion
from sim.simulation.motor_limit import MotorLimit

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


def _inverse_model(model: Any, built: BuiltCell, discrete: bool) -> Any:
    """A copy of ``model`` set up for :func:`inverse_dynamics` (the caller's model untouched)."""
    import copy

    import mujoco

    m = copy.copy(model)
    off = int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    invdiscrete = int(mujoco.mjtEnableBit.mjENBL_INVDISCRETE)
    if discrete:
        m.opt.enableflags |= invdiscrete
        # invdiscrete would count the friction actuators' velocity slope (F / COULOMB_SPEED) as
        # an implicit damping even where they are clamped (everywhere but |qd| < 1e-3 rad/s),
        # where the forward step leaves it out: remove it for the computation
        m.actuator_biasprm[built.friction_act, 2] = 0.0
    else:
        m.opt.enableflags &= ~invdiscrete
        off |= int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)  # friction added exactly, below
    m.opt.disableflags |= off
    return m


def _as_index(ids: Any) -> Any:
    """Indices as a slice where they are consecutive (a view instead of a copy), else as they
    are."""
    a = np.asarray(ids, dtype=int).ravel()
    if a.size and np.array_equal(a, np.arange(a[0], a[0] + a.size)):
        return slice(int(a[0]), int(a[0]) + a.size)
    return ids


def inverse_dynamics(model: Any, built: BuiltCell, q: NDArray[np.float64],
                     qd: NDArray[np.float64], qdd: NDArray[np.float64], *,
                     discrete: bool | tuple[bool, ...] = False
                     ) -> NDArray[np.float64] | tuple[NDArray[np.float64], ...]:
    """Joint torques that realise a joint motion, (N, n_joints), N m.

    The robot's own dynamics with its tool and payload; contacts are switched off (a reference
    that touches a part would otherwise count the contact's push as the robot's torque), the
    rest of the model (parts) stays at its initial pose and at rest, and a part held by
    suction is not included (it is in the simulated torque).

    Args:
        discrete: False (what is recorded and sized): continuous-time torques
            ``M qdd + c + g + b qd + F s(qd)`` (module docstring), nothing from the integrator.
            True (the feed-forward only): MuJoCo's ``mj_inverse`` with ``invdiscrete``, the
            force that makes the implicit step reproduce ``qdd`` exactly, plus the friction.
            A tuple of these computes each in one pass over the samples and returns a tuple.
    """
    import mujoco

    modes = discrete if isinstance(discrete, tuple) else (discrete,)
    models = [_inverse_model(model, built, d) for d in modes]
    data = mujoco.MjData(model)
    mujoco.mj_resetData(model, data)
    data.qvel[:] = 0.0
    data.qacc[:] = 0.0
    outs = [np.zeros_like(q) for _ in modes]
    # the arrays' views and indices fetched once: the loop runs once per sample (160 000 times
    # for the default weld cycle), and each attribute access builds a new view
    qpos, qvel, qacc, qfrc = data.qpos, data.qvel, data.qacc, data.qfrc_inverse
    pos_i, dof_i = _as_index(built.robot_qpos), _as_index(built.robot_dof)
    inverse = mujoco.mj_inverse
    pairs = list(zip(models, outs))
    for k in range(q.shape[0]):
        qpos[pos_i] = q[k]
        qvel[dof_i] = qd[k]
        qacc[dof_i] = qdd[k]
        for m, out in pairs:
            inverse(m, data)
            out[k] = qfrc[dof_i]
    # the joints' Coulomb friction is applied by friction actuators (sim.cells.compose), which
    # mj_inverse does not count: the drive overcomes it
    friction = coulomb(built.cell.frictionloss, qd)
    result = tuple(out + friction for out in outs)
    return result if isinstance(discrete, tuple) else result[0]


def vacuum(command: NDArray[np.bool_], dt: float,
           time_constant: float | None = None) -> NDArray[np.float64]:
    """Suction level in [0, 1] at each sample: a first-order lag of the valve ``command``
    (exact for a command held over each step), time constant
    :data:`sim.cells.tools.VACUUM_TIME_CONSTANT_S`."""
    from scipy.signal import lfilter

    from sim.cells.tools import VACUUM_TIME_CONSTANT_S

    tau = VACUUM_TIME_CONSTANT_S if time_constant is None else time_constant
    a = float(np.exp(-dt / tau))
    u = np.asarray(command, dtype=float)
    # y[k] = a y[k-1] + (1 - a) u[k-1], y[0] = 0
    y = lfilter([0.0, 1.0 - a], [1.0, -a], u)
    return np.clip(y, 0.0, 1.0)


#: Steps between updates of the drives' speed-dependent torque limit while it binds, s / h.
ENVELOPE_STEPS = 10
#: Times a short chunk is run again when its joint sped past the speed its limit was set for.
ENVELOPE_RETRIES = 3


def _joint_peak(drives: Sequence[Drive], speed: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each drive's peak torque at the joint at joint speeds ``speed`` (..., n), N m."""
    return np.stack([d.joint_peak_torque_at(speed[..., j]) for j, d in enumerate(drives)],
                    axis=-1)


def simulate(built: BuiltCell, motion: Motion, *, feedforward: bool, settle_s: float = 0.0,
             progress: bool = True,
             on_failure: Callable[[dict[str, NDArray[Any]], str], None] | None = None,
             drives: Sequence[Drive] | None = None) -> SimulationRecord:
    """Simulate the reference motion with the robot's drives; see the module docstring.

    Args:
        drives: The drive of each joint. When given, each drive's limit follows its peak
            torque-speed curve at the motor's own speed
            (:meth:`sim.robots.registry.Drive.joint_peak_torque_at`, never above the
            actuator's ``forcerange``): where the curve binds, the limit is set every
            :data:`ENVELOPE_STEPS` steps from the joint's speed at the chunk's start, and a
            chunk in which the joint sped past that speed runs again at the curve's value at
            the highest speed it reached (up to :data:`ENVELOPE_RETRIES` times). The
            reference's speeds only say where the curve may start to bind (where the flat
            chunks end). None: the constant ``forcerange``.

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
    tau_id, ff, controls = reference_controls(built, motion, t, ref, feedforward)
    nv = model.nv

    flat = built.force_limits[:, 1]
    limit = np.tile(flat, (n_steps + 1, 1))  # the drive's limit at each step, N m
    env_ref = None if drives is None else np.minimum(_joint_peak(drives, np.abs(ref.qd)), flat)
    saved_range = model.actuator_forcerange[built.robot_act].copy()
    motor = None if drives is None else MotorLimit(built, drives, qvel_slice_of(model))
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
    control_spec = mujoco.mjtState.mjSTATE_CTRL
    scratch = mujoco.MjData(model)

    from tqdm import tqdm

    bar = tqdm(total=n_steps, unit="step", desc="simulate", leave=False,
               disable=not progress or not sys.stderr.isatty())
    wall = 0.0
    k = 0
    short_until = 0  # steps before which the envelope runs in short chunks (see below)
    retries, retry_lim = 0, None  # a short chunk run again at a lower limit (see below)
    # the constraint solver's warm start carries over from chunk to chunk (it is not part of
    # the state), so that results do not depend on where the chunks end
    warmstart = data.qacc_warmstart.copy()
    try:
        while k < n_steps:
            m = min(CHUNK_STEPS, n_steps - k)
            flat_chunk = True
            if env_ref is not None:
                m, lim = _envelope_chunk(drives, env_ref, flat, state, qvel_slice, built, k, m,
                                         short=k < short_until)
                if retry_lim is not None:  # a retried chunk: the limit the joint's speed set
                    m, lim = min(m, ENVELOPE_STEPS), np.minimum(lim, retry_lim)
                flat_chunk = bool(np.all(lim == flat))
                model.actuator_forcerange[built.robot_act] = np.column_stack([-lim, lim])
                limit[k:k + m] = lim
            for w in scratch.warning:
                w.number = 0
            t_start = time.perf_counter()
            st, sd = rollout.rollout(model, scratch, state, controls[k:k + m][None],
                                     control_spec=control_spec, initial_warmstart=warmstart)
            wall += time.perf_counter() - t_start
            st, sd = st[0], sd[0]
            if env_ref is not None:
                speeds = np.abs(st[:, qvel_slice][:, built.robot_dof]).max(axis=0)
                own = np.minimum(_joint_peak(drives, speeds), flat)
                if flat_chunk and m > ENVELOPE_STEPS:
                    # a joint that sags or lags may pass its curve's knee inside a flat chunk
                    # chosen from the speeds at its start: then run that stretch again, short
                    if np.any(own < flat * (1 - 1e-12)):
                        short_until = k + m
                        continue
                elif np.any(own < lim * (1 - 1e-9)) and retries < ENVELOPE_RETRIES:
                    # the joint sped up past the speed its limit was set for: the same chunk
                    # again at the curve's value at the speed the joint reached
                    retries += 1
                    lim = np.minimum(lim, own)
                    retry_lim = lim
                    continue
            retries, retry_lim = 0, None
            if (motor is not None and np.all(np.isfinite(st))
                    and not any(w.number for w in scratch.warning)
                    and motor.exceeded(state, st, sd)):
                # a motor past its peak (at its own speed) somewhere in the chunk: the chunk
                # again, a step at a time, each drive held at the joint torque at which its
                # motor gives exactly its peak
                lim_now = model.actuator_forcerange[built.robot_act, 1].copy()
                st, sd, held = motor.exact_steps(scratch, state, controls[k:k + m], warmstart,
                                                 lim_now, control_spec)
                limit[k:k + m] = np.where(np.isnan(held), limit[k:k + m], held)
                model.actuator_forcerange[built.robot_act] = np.column_stack([-lim_now,
                                                                             lim_now])
            warmstart = scratch.qacc_warmstart.copy()
            qpos[k + 1:k + m + 1] = st[:, qpos_slice]
            qvel[k + 1:k + m + 1] = st[:, qvel_slice]
            sens[k:k + m] = sd
            problem = _instability(model, scratch, st, t[k], dt, built, qpos_slice)
            if problem is not None:
                bad_step, message = problem
                partial = _arrays(built, motion, t[:k + bad_step + 1], ref, tau_id, ff,
                                  qpos[:k + bad_step + 1], qvel[:k + bad_step + 1],
                                  sens[:k + bad_step + 1], limit[:k + bad_step + 1])
                if on_failure is not None:
                    on_failure(partial, message)
                raise SimulationError(message)
            state = st[-1].copy()
            k += m
            bar.update(m)
        # sensors of the final state
        if env_ref is not None:
            limit[n_steps] = limit[n_steps - 1] if n_steps else flat
            model.actuator_forcerange[built.robot_act] = np.column_stack(
                [-limit[n_steps], limit[n_steps]])
        mujoco.mj_setState(model, scratch, state, spec)
        scratch.ctrl[:] = controls[n_steps]  # the final sample's own control (not in the state)
        mujoco.mj_forward(model, scratch)
        sens[n_steps] = scratch.sensordata
    finally:
        bar.close()
        model.actuator_forcerange[built.robot_act] = saved_range
    arrays = _arrays(built, motion, t, ref, tau_id, ff, qpos, qvel, sens, limit)
    return SimulationRecord(arrays=arrays, wall_s=wall, steps=n_steps, timestep=dt)


def qvel_slice_of(model: Any) -> slice:
    """Where ``qvel`` sits in a FULLPHYSICS state (time, qpos, qvel, ...)."""
    return slice(1 + model.nq, 1 + model.nq + model.nv)


def reference_controls(built: BuiltCell, motion: Motion, t: NDArray[np.float64], ref: Any,
                       feedforward: bool
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The controls of every step, known before stepping (they do not depend on the state).

    A position actuator's force is kp (ctrl - q) - kv qd, clamped to its forcerange. With
    feed-forward the set-point is shifted by (kv/kp) qd_ref, so the servo acts on the velocity
    error too, and by tau_ff / kp, so the drive also delivers the feed-forward torque: the whole
    torque passes through the drive and its limit. The suction actuator follows the tool state.

    Args:
        built: The compiled cell.
        motion: The reference motion.
        t: Sample times, s, (N,).
        ref: ``motion.at(t)``.
        feedforward: With the inverse-dynamics feed-forward.

    Returns:
        ``(tau_id, tau_ff, controls)``: the reference's inverse dynamics (N, n) and the
        feed-forward (N, n; zeros without), N m; the controls (N, nu).
    """
    model = built.model
    kp = model.actuator_gainprm[built.robot_act, 0]
    kv = -model.actuator_biasprm[built.robot_act, 2]
    if feedforward:  # both in one pass over the samples
        tau_id, ff = inverse_dynamics(model, built, ref.q, ref.qd, ref.qdd, discrete=(False, True))
    else:
        tau_id = inverse_dynamics(model, built, ref.q, ref.qd, ref.qdd)
        ff = np.zeros_like(tau_id)
    controls = np.zeros((t.size, model.nu))
    controls[:, built.robot_act] = (ref.q + (kv / kp) * ref.qd + ff / kp) if feedforward \
        else ref.q
    if built.suction_act is not None:
        controls[:, built.suction_act] = vacuum(motion.tool_state(t, "suction"),
                                                float(model.opt.timestep))
    return tau_id, ff, controls


def _envelope_chunk(drives: Sequence[Drive], env_ref: NDArray[np.float64],
                    flat: NDArray[np.float64], state: NDArray[np.float64], qvel_slice: slice,
                    built: BuiltCell, k: int, m: int, short: bool = False
                    ) -> tuple[int, NDArray[np.float64]]:
    """Length and drive limits of the next rollout chunk from step ``k`` (at most ``m``).

    Where neither the reference's speeds over the chunk nor the joints' present speeds reach
    the falling part of the peak curve, the limit is the flat ``forcerange`` and the chunk runs
    up to the first step where the curve would bind. Otherwise (or when ``short``: a flat chunk
    from here saw a joint pass its curve's knee) a short chunk of :data:`ENVELOPE_STEPS` steps
    runs at the curve's value at the joints' present speeds (the caller runs it again lower
    when a joint speeds up inside it).
    """
    eps = 1e-12
    qd_now = np.abs(state[qvel_slice][built.robot_dof])
    env_now = np.minimum(_joint_peak(drives, qd_now), flat)
    binds = np.any(env_ref[k:k + m + 1] < flat * (1 - eps), axis=1)
    first = int(np.argmax(binds)) if binds.any() else None
    if not short and not np.any(env_now < flat * (1 - eps)) and (first is None or first > 1):
        return (m if first is None else min(m, first - 1)), flat.copy()
    m = min(ENVELOPE_STEPS, m)
    return m, env_now


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
            qvel: NDArray[np.float64], sens: NDArray[np.float64],
            limit: NDArray[np.float64]) -> dict[str, NDArray[Any]]:
    n = t.size
    nj = motion.n_joints
    tau_act = np.column_stack([sens[:, built.sensor_slices[f"tau{i}"]] for i in range(nj)]) \
        if nj else np.zeros((n, 0))
    qd_sim = qvel[:, built.robot_dof]
    qdd_sim = _sim_acceleration(qd_sim, t)
    # the force the implicit step applied: the drive's velocity term at the end-of-step speed
    # (module docstring); a saturated drive applies its limit
    model = built.model
    kv = -model.actuator_biasprm[built.robot_act, 2]
    h = float(model.opt.timestep)
    hi = limit[:n]
    saturated = np.abs(tau_act) >= hi * (1 - 1e-9)
    tau = np.where(saturated, tau_act, tau_act - h * kv * qdd_sim)
    kin = built.context.kinematics
    nr = kin.n_joints  # the arm's joints; the external axes follow them
    na = built.context.n_axes
    poses = np.asarray(kin.fk(ref.q[:n, :nr]), dtype=float).reshape(n, 4, 4)
    if na:  # a track carries frame 0
        from sim.simulation.motion.axes import world_from_frame0

        W = world_from_frame0(built.context, ref.q[:n, nr:nr + na])
        tcp_ref = np.einsum("nij,nj->ni", W[:, :3, :3], poses[:, :3, 3]) + W[:, :3, 3]
    else:
        T0 = built.context.world_from_frame0
        tcp_ref = poses[:, :3, 3] @ T0[:3, :3].T + T0[:3, 3]
    out: dict[str, NDArray[Any]] = {
        "t": t,
        "phase": motion.phase_index(t).astype(np.int32),
        "q_ref": ref.q[:n], "qd_ref": ref.qd[:n], "qdd_ref": ref.qdd[:n],
        "qddd_ref": ref.qddd[:n],
        "q": qpos[:, built.robot_qpos], "qd": qd_sim,
        "qdd": qdd_sim,
        "tau": tau, "tau_actuator": tau_act, "tau_ff": ff[:n], "tau_limit": hi,
        "tau_id": tau_id[:n],
        "tcp_pos": sens[:, built.sensor_slices["tcp_pos"]],
        "tcp_pos_ref": tcp_ref,
        "tcp_quat": sens[:, built.sensor_slices["tcp_quat"]],
        "qpos": qpos,
        "arc_on": motion.tool_state(t, "arc"),
        "suction": motion.tool_state(t, "suction"),
        "knot_t": motion.knot_times(),
    }
    for (name, lane), cols in zip(motion.lanes, built.partner_cols.values(), strict=True):
        # each other robot's tool point, recorded and as its reference puts it
        ctx = built.context.partners[name]
        T0 = ctx.world_from_frame0
        p_ref = np.asarray(ctx.kinematics.fk(ref.q[:n, cols]), dtype=float).reshape(n, 4, 4)
        out[f"{name}_tcp_pos"] = sens[:, built.sensor_slices[f"{name}_tcp_pos"]]
        out[f"{name}_tcp_quat"] = sens[:, built.sensor_slices[f"{name}_tcp_quat"]]
        out[f"{name}_tcp_pos_ref"] = p_ref[:, :3, 3] @ T0[:3, :3].T + T0[:3, 3]
        out[f"{name}_arc_on"] = lane.tool_state(t, "arc")
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

