"""Batched simulation on MuJoCo Warp: many variants of one model structure stepped at once.

The CPU path (:func:`sim.simulation.simulate.simulate`) steps one variant in C. Here the
variants of a sweep that share a model structure (the same bodies, joints, geoms and
actuators; masses, inertias, gains and force ranges may differ, so payloads, speed scales and
drive parameters batch) become the worlds of one ``mujoco_warp`` model and step together, on
a GPU where Warp finds one and on Warp's CPU device otherwise. Everything else is shared with
the CPU path: the reference motion and the inverse-dynamics feed-forward are computed on the
host per variant (they do not depend on the state, so the controls of every step are known
before stepping), and the recorded arrays are assembled by the same function, so checks,
sizing and the verdict do not know which backend ran.

Differences, all measured by ``tests/simulation/test_warp_backend.py`` against the CPU path:

* MuJoCo Warp computes in float32: joint paths agree to about 1e-5 rad and torques to a
  fraction of a percent on the shipped robots (the tests bound them at 1e-4 rad and 1 %).
* The drives' limit is the CPU path's (:class:`_MotorBounds`): every step, in every world,
  each drive may give at most the joint torque at which its motor gives exactly its peak at
  the motor's own speed (:meth:`sim.robots.registry.Drive.joint_torque_for`, the gear's
  efficiency in the direction power flows, the rotor's inertia on the motor side), and never
  more than its torque-speed curve at the joint. The step's acceleration enters that bound and
  is known only after the step, so a step whose acceleration moved the bound is run again
  (the whole batch, from the saved state) until the motors agree within
  :data:`WARP_MOTOR_TOL` of their peaks: float32 instead of the CPU path's 1e-9. The CPU path
  sets its curve limit in chunks of ten steps from the highest speed reached; here it follows
  the speed step by step, so past a curve's knee the two differ by that chunking (on a 5R
  arm whose weak J2 falls past its motor's top speed: within 5 % of the motor's peak torque
  on the curve's slope, up to 43 % for the ten steps where the two cross the top speed,
  where the curve drops from the rated torque to 0, and 9e-3 rad on the path). With drives,
  every step brings the batch's joint speeds and drive torques to the host (a
  synchronisation per step on a GPU), and a step runs again for every world when one world's
  drive is off its motor law (about 5 % more steps on that falling arm).
* Variants of different durations (speed scales) run to the longest; a shorter one holds its
  last control after its end and its arrays stop at its own end.

Warp compiles its kernels on first use (about a minute on the CPU device) and caches them
(``WARP_CACHE_PATH``, default ``~/.cache/warp``); later runs load them in seconds.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import SimulationError
from sim.robots.registry import RPM_PER_RAD_S, Drive
from sim.simulation.compile import BuiltCell
from sim.simulation.motion import Motion
from sim.simulation.motor_limit import MOTOR_ITERATIONS
from sim.simulation.simulate import (
    SimulationRecord,
    _arrays,
    reference_controls,
)

#: Simulation backends: MuJoCo in C (one variant at a time) or MuJoCo Warp (batched).
BACKENDS: tuple[str, ...] = ("mujoco", "warp")


def _import_warp() -> tuple[Any, Any]:
    try:
        import warp as wp

        wp.config.quiet = True  # no banner
        if hasattr(wp, "LOG_WARNING"):  # no "Module ... load on device" line per kernel
            wp.config.log_level = wp.LOG_WARNING
        _quiet_init(wp)
        import mujoco_warp as mjw
    except ImportError:
        raise SimulationError("--backend warp needs MuJoCo Warp: pip install 'cellsim[warp]' "
                              "(or use --backend mujoco)") from None
    return wp, mjw


def _quiet_init(wp: Any) -> None:
    """Initialise Warp with its standard error set aside: without a GPU it prints "Warp CUDA
    warning: Could not find or load the NVIDIA CUDA driver" from C, which a run on Warp's CPU
    device does not need (:func:`default_device` says which device runs)."""
    import sys
    import tempfile

    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with tempfile.TemporaryFile() as sink:
            os.dup2(sink.fileno(), 2)
            try:
                wp.init()
            finally:
                os.dup2(saved, 2)
    finally:
        os.close(saved)


def default_device() -> str:
    """``"cuda"`` where Warp finds a GPU, else ``"cpu"``."""
    wp, _ = _import_warp()
    return "cuda" if wp.is_cuda_available() else "cpu"


def _model_arrays(model: Any) -> dict[str, NDArray[Any]]:
    out = {}
    for name in dir(model):
        if name.startswith("_"):
            continue
        try:
            value = getattr(model, name)
        except Exception:  # noqa: BLE001 - properties that need arguments
            continue
        if isinstance(value, np.ndarray):
            out[name] = value
    return out


def _batched_fields(models: Sequence[Any], labels: Sequence[str]) -> list[str]:
    """The model arrays that differ between the variants (each must be batchable in MuJoCo
    Warp); the sizes and every other array must agree.

    Raises:
        SimulationError: The variants are not one model structure.
    """
    import dataclasses

    import mujoco_warp as mjw

    first = _model_arrays(models[0])
    warp_fields = {f.name: f.type for f in dataclasses.fields(mjw.Model)}
    differ: list[str] = []
    for i, model in enumerate(models[1:], start=1):
        for name, value in _model_arrays(model).items():
            ref = first.get(name)
            if ref is None or ref.shape != value.shape:
                raise SimulationError(
                    f"--backend warp: {labels[i]} has another model structure than {labels[0]} "
                    f"({name} has shape {value.shape}, not {getattr(ref, 'shape', None)}); a "
                    "batch needs one")
            if name in differ or np.array_equal(ref, value, equal_nan=True):
                continue
            if name not in warp_fields:
                continue  # not used on the device (names, visual settings, ...)
            shape = getattr(warp_fields[name], "shape", ())
            if not shape or shape[0] != "*":
                raise SimulationError(f"--backend warp: the variants differ in {name}, which "
                                      "MuJoCo Warp cannot batch; run them with --backend mujoco")
            differ.append(name)
    return differ


def simulate_batch(builts: Sequence[BuiltCell], motions: Sequence[Motion], *,
                   feedforward: bool, settle_s: float = 0.0,
                   drives: Sequence[Sequence[Drive] | None] | None = None,
                   device: str | None = None, labels: Sequence[str] | None = None
                   ) -> list[SimulationRecord]:
    """Simulate every variant's reference motion as one MuJoCo Warp batch.

    Args:
        builts: One compiled cell per variant (one model structure).
        motions: One reference motion per variant.
        feedforward: Inverse-dynamics feed-forward through the drives (as on the CPU path).
        settle_s: Simulated time after each motion's end, s.
        drives: Per variant, the drives whose motors limit the actuators, step by step at the
            motor's own speed and the step's acceleration (:class:`_MotorBounds`; None: the
            constant ``forcerange``).
        device: Warp device (``"cpu"``, ``"cuda"``, ``"cuda:1"``); default :func:`default_device`.
        labels: How errors name each variant (default ``"variant 0"``, ...).

    Returns:
        One :class:`~sim.simulation.simulate.SimulationRecord` per variant, in order; the
        arrays as the CPU path records them (float64, from float32 state).

    Raises:
        SimulationError: Not one model structure, a feature MuJoCo Warp lacks, different
            timesteps, or NaN in a world (the message names the variant and the time).
    """
    import mujoco

    wp, mjw = _import_warp()
    if len(builts) != len(motions) or not builts:
        raise SimulationError("simulate_batch: one motion per compiled cell, at least one")
    models = [b.model for b in builts]
    labels = list(labels) if labels is not None else [f"variant {i}" for i in range(len(builts))]
    dt = float(models[0].opt.timestep)
    if any(float(m.opt.timestep) != dt for m in models):
        raise SimulationError("--backend warp: the variants' timesteps differ; a batch steps "
                              "on one clock")
    nworld = len(builts)
    drives = list(drives) if drives is not None else [None] * nworld
    nu = models[0].nu

    # host side: references, feed-forward and controls per variant
    per: list[dict[str, Any]] = []
    for built, motion in zip(builts, motions):
        n = int(round((motion.duration + settle_s) / dt))
        t = motion.t0 + dt * np.arange(n + 1)
        ref = motion.at(t)
        tau_id, ff, controls = reference_controls(built, motion, t, ref, feedforward)
        per.append({"n": n, "t": t, "ref": ref, "tau_id": tau_id, "ff": ff,
                    "controls": controls})
    n_max = max(p["n"] for p in per)
    ends = np.array([p["n"] for p in per])
    # every step's controls, the shorter variants holding their last values
    ctrl = np.zeros((n_max + 1, nworld, nu), dtype=np.float32)
    for w, p in enumerate(per):
        pad = n_max - p["n"]
        ctrl[:, w] = np.concatenate([p["controls"], np.repeat(p["controls"][-1:], pad, 0)])
    motor = _MotorBounds(builts, drives) if any(d is not None for d in drives) else None
    nj = len(builts[0].robot_act)
    # the limit each step applied, per world and joint (float32, as the device clamps)
    limits = np.empty((n_max + 1, nworld, nj))

    device = device or default_device()
    try:
        with wp.ScopedDevice(device):
            batched = _batched_fields(models, labels)
            if motor is not None and "actuator_forcerange" not in batched:
                batched.append("actuator_forcerange")
            try:
                mw = mjw.put_model(models[0], batch_sizes={f: nworld for f in batched})
            except NotImplementedError as exc:
                raise SimulationError(f"--backend warp: MuJoCo Warp does not support this cell "
                                      f"({exc}); use --backend mujoco") from None
            for name in batched:
                stacked = np.stack([np.asarray(getattr(m, name)) for m in models])
                target = getattr(mw, name)
                target.assign(stacked.astype(target.numpy().dtype))
            data = mujoco.MjData(models[0])
            mujoco.mj_resetData(models[0], data)
            nconmax = max(32, 4 * models[0].ngeom)
            dw = mjw.put_data(models[0], data, nworld=nworld, nconmax=nconmax,
                              njmax=max(64, 4 * nconmax))
            qpos0 = np.stack([m.qpos0 for m in models]).astype(np.float64)
            qvel0 = np.zeros((nworld, models[0].nv))
            for w, (p, built) in enumerate(zip(per, builts)):
                qpos0[w, built.robot_qpos] = p["ref"].q[0]
                qvel0[w, built.robot_dof] = p["ref"].qd[0]
            dw.qpos.assign(qpos0.astype(np.float32))
            dw.qvel.assign(qvel0.astype(np.float32))
            dw.time.assign(np.array([m.t0 for m in motions], dtype=np.float32))

            ctrl_dev = wp.array(ctrl, dtype=float)
            nq, nv, ns = models[0].nq, models[0].nv, models[0].nsensordata
            qpos_dev = wp.zeros((n_max + 1, nworld, nq), dtype=float)
            qvel_dev = wp.zeros((n_max + 1, nworld, nv), dtype=float)
            sens_dev = wp.zeros((n_max + 1, nworld, ns), dtype=float)
            wp.copy(qpos_dev[0], dw.qpos)
            wp.copy(qvel_dev[0], dw.qvel)
            start = time.perf_counter()
            nacon_dev = wp.zeros(n_max + 1, dtype=int)
            nefc_dev = wp.zeros((n_max + 1, nworld), dtype=int)
            step = _Stepper(wp, mjw, mw, dw)
            if motor is None:
                flat = np.stack([b.force_limits[:, 1] for b in builts]).astype(np.float32)
                limits[:] = flat
                for k in range(n_max):
                    wp.copy(dw.ctrl, ctrl_dev[k])
                    step()
                    _record_step(wp, dw, k, qpos_dev, qvel_dev, sens_dev, nacon_dev, nefc_dev)
            else:
                first_qdd = np.stack([p["ref"].qdd[0] for p in per])
                _motor_steps(wp, mjw, step, mw, dw, motor, ctrl_dev, n_max, ends, first_qdd, labels,
                             limits, (qpos_dev, qvel_dev, sens_dev, nacon_dev, nefc_dev))
            wp.copy(dw.ctrl, ctrl_dev[n_max])
            if motor is None:
                mjw.forward(mw, dw)
            wp.copy(sens_dev[n_max], dw.sensordata)
            wp.synchronize()
            wall = time.perf_counter() - start
            # MuJoCo Warp drops contacts and constraints beyond its buffers without a warning
            # (MuJoCo in C warns, and the CPU path fails on it): fail here too
            if int(nacon_dev.numpy().max()) >= int(dw.naconmax):
                raise SimulationError(f"--backend warp: more than {int(dw.naconmax)} contacts "
                                      "at once in the batch; use --backend mujoco")
            worst = nefc_dev.numpy().max(axis=0)
            if np.any(worst >= int(dw.njmax)):
                w = int(np.argmax(worst))
                raise SimulationError(f"--backend warp: {labels[w]} has more than "
                                      f"{int(dw.njmax)} constraints at once; use --backend mujoco")
            qpos = qpos_dev.numpy().astype(np.float64)
            qvel = qvel_dev.numpy().astype(np.float64)
            sens = sens_dev.numpy().astype(np.float64)
    except SimulationError:
        raise
    except (RuntimeError, ValueError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise SimulationError(f"--backend warp on device {device!r}: {first}") from None

    records = []
    for w, (p, built, motion) in enumerate(zip(per, builts, motions)):
        n = p["n"]
        q, v, s = qpos[:n + 1, w], qvel[:n + 1, w], sens[:n + 1, w]
        bad = ~(np.all(np.isfinite(q), axis=1) & np.all(np.isfinite(v), axis=1))
        if bad.any():
            k = int(np.argmax(bad))
            raise SimulationError(f"{labels[w]}: simulation unstable at t = {p['t'][k]:.4f} s "
                                  "(NaN in the state, MuJoCo Warp); try a smaller "
                                  "simulation.timestep_s")
        arrays = _arrays(built, motion, p["t"], p["ref"], p["tau_id"], p["ff"], q, v, s,
                         limits[:n + 1, w])
        records.append(SimulationRecord(arrays=arrays, wall_s=wall / nworld, steps=n,
                                        timestep=dt))
    return records


#: What the last batch's stepping did (read by benchmarks/bench_warp_gpu.py): the steps run,
#: passes included, and whether they ran as a CUDA graph.
STEP_STATS: dict[str, Any] = {"steps": 0, "graph": False}


class _Stepper:
    """One ``mjw.step`` of the batch. On a GPU the step is captured once as a CUDA graph and
    launched as one graph after that: the same kernels on the same buffers, without Warp's
    per-kernel launch from Python, which bounds a batch's step time on a GPU (each step of the
    batch is a few hundred small kernels). The first step runs plainly (it loads the kernels).
    The graph reads the model and data buffers that the loop writes between steps (the
    controls, the force ranges, a saved state put back), so those stay where they are."""

    def __init__(self, wp: Any, mjw: Any, mw: Any, dw: Any) -> None:
        self.wp, self.mjw, self.mw, self.dw = wp, mjw, mw, dw
        self.capture = wp.get_device().is_cuda and os.environ.get("CELLSIM_WARP_GRAPH") != "0"
        self.graph: Any = None
        STEP_STATS.update(steps=0, graph=False)

    def __call__(self) -> None:
        STEP_STATS["steps"] += 1
        if self.graph is not None:
            self.wp.capture_launch(self.graph)
            return
        self.mjw.step(self.mw, self.dw)
        if self.capture:  # recorded, not run: the state stays where the step left it
            self.capture = False
            with self.wp.ScopedCapture() as cap:
                self.mjw.step(self.mw, self.dw)
            self.graph = cap.graph
            STEP_STATS["graph"] = True


def _record_step(wp: Any, dw: Any, k: int, qpos_dev: Any, qvel_dev: Any, sens_dev: Any,
                 nacon_dev: Any, nefc_dev: Any) -> None:
    """Keep step ``k``'s outcome: the state after it, the sensors before it (computed at state
    ``k``) and its contact and constraint counts."""
    wp.copy(qpos_dev[k + 1], dw.qpos)
    wp.copy(qvel_dev[k + 1], dw.qvel)
    wp.copy(sens_dev[k], dw.sensordata)
    wp.copy(nacon_dev, dw.nacon, dest_offset=k, count=1)
    wp.copy(nefc_dev[k], dw.nefc)


#: Motor torque tolerance of the batched step, in peak torques: a step runs again until every
#: motor at its limit gives its peak within it, and no other motor passes it by more (float32
#: speeds put about 1e-6 of a peak of noise into a motor torque through the step's acceleration).
WARP_MOTOR_TOL = 2e-5
#: Largest motor torque error accepted after ``MOTOR_ITERATIONS`` passes of a step, in peak
#: torques (as the CPU path's ``MOTOR_SETTLE_TOL``).
WARP_SETTLE_TOL = 1e-4


class _MotorBounds:
    """The drives' motor limit of every world of a batch, as the CPU path's
    :class:`~sim.simulation.motor_limit.MotorLimit`.

    Per world and joint, at joint speed ``qd`` (the step's start: the motor's own speed) and
    the step's acceleration ``qdd``, a drive's force range is where its motor torque
    (:meth:`~sim.robots.registry.Drive.motor_torque`) stays within the peak curve at the
    motor's speed: ``[joint_torque_for(-peak(qd), qd, qdd), joint_torque_for(peak(qd), qd,
    qdd)]``, and within the curve at the joint (``joint_peak_torque_at``, never above the
    actuator's ``forcerange``), as on the CPU path, where the force range stays the curve's and
    the motor's law only lowers it. The drive's own methods are called on the worlds that share
    it (vectorised over the batch). Where the two ranges do not meet (a motor past its top
    speed, which gives 0 N m, while the rotor accelerates), the motor's law wins, as on the CPU
    path. A joint whose actuator has no force limit has none here either.
    """

    def __init__(self, builts: Sequence[BuiltCell],
                 drives: Sequence[Sequence[Drive] | None]) -> None:
        b0 = builts[0]
        self.act = np.asarray(b0.robot_act)
        self.dof = np.asarray(b0.robot_dof)
        nj = len(self.act)
        rows = np.arange(b0.model.nsensordata)
        self.tau_cols = np.concatenate([rows[b0.sensor_slices[f"tau{i}"]] for i in range(nj)])
        self.h = float(b0.model.opt.timestep)
        self.flat = np.stack([b.force_limits[:, 1] for b in builts])
        self.arm = np.stack([b.model.dof_armature[self.dof] for b in builts])
        self.kv = np.stack([-b.model.actuator_biasprm[self.act, 2] for b in builts])
        self.base = np.stack([b.model.actuator_forcerange for b in builts])
        limited = np.stack([b.model.actuator_forcelimited[self.act].astype(bool) for b in builts])
        groups: dict[tuple[int, Drive], list[int]] = {}
        for w, drv in enumerate(drives):
            for j, d in enumerate(drv or ()):
                if limited[w, j]:
                    groups.setdefault((j, d), []).append(w)
        self.groups = [(j, d, np.array(ws)) for (j, d), ws in groups.items()]
        self.active = np.zeros(self.flat.shape, dtype=bool)
        #: one motor peak torque as a joint torque (N eta): the tolerances' scale, N m
        self.scale = np.ones(self.flat.shape)
        for j, d, ws in self.groups:
            self.active[ws, j] = True
            self.scale[ws, j] = d.peak_torque * d.gear_ratio * d.efficiency

    def bounds(self, qd: NDArray[np.float64], qdd: NDArray[np.float64]
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The force range ``(lo, hi)`` of every world and joint (nworld, n), float32 values."""
        lo, hi = -self.flat.copy(), self.flat.copy()
        for j, d, ws in self.groups:
            v, a, arm = qd[ws, j], qdd[ws, j], self.arm[ws, j]
            avail = d.peak_torque_at(v * d.gear_ratio * RPM_PER_RAD_S)
            curve = np.minimum(d.joint_peak_torque_at(v), self.flat[ws, j])
            top = d.joint_torque_for(avail, v, a, arm)
            bottom = d.joint_torque_for(-avail, v, a, arm)
            h, low = np.minimum(curve, top), np.maximum(-curve, bottom)
            near = np.where(bottom > curve, bottom, top)
            empty = low > h
            lo[ws, j] = np.where(empty, near, low)
            hi[ws, j] = np.where(empty, near, h)
        return (lo.astype(np.float32).astype(np.float64),
                hi.astype(np.float32).astype(np.float64))

    def forcerange(self, lo: NDArray[np.float64], hi: NDArray[np.float64],
                   hold: NDArray[np.int_]) -> NDArray[np.float32]:
        """Every actuator's force range of every world (nworld, nu, 2), the drives' set: ``(lo,
        hi)``, or the one value ``hi`` (``lo``) for a drive held there (``hold`` 1 (-1))."""
        out = self.base.copy()
        out[:, self.act, 0] = np.where(hold > 0, hi, lo)
        out[:, self.act, 1] = np.where(hold < 0, lo, hi)
        return out.astype(np.float32)

    def check(self, qd0: NDArray[np.float64], qdd: NDArray[np.float64],
              tau_act: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64],
              hold: NDArray[np.int_]
              ) -> tuple[NDArray[np.int_], NDArray[np.float64], NDArray[np.int_]]:
        """A step that ran with the bounds ``(lo, hi)`` and holds ``hold``, and had the
        acceleration ``qdd``: per world and joint, the side of its range the drive was at (1,
        -1; 0 inside it), how far it is from its motor law at that acceleration, in peak
        torques (a drive at its limit: the distance of that limit from the limit at this
        acceleration; any other: how far its torque, as recorded, with the implicit step's
        velocity term at the end-of-step speed, passes the latter), and the holds for the next
        pass (a drive inside its range whose torque passed it: held at it, as the CPU path
        holds one)."""
        lo_a, hi_a = self.bounds(qd0, qdd)
        side = np.where(hold != 0, hold, np.where(tau_act >= hi, 1, np.where(tau_act <= lo, -1, 0)))
        tau = tau_act - self.h * self.kv * qdd
        over, under = tau - hi_a, lo_a - tau
        err = np.where(side > 0, np.abs(hi_a - hi), np.where(
            side < 0, np.abs(lo_a - lo), np.maximum(np.maximum(over, under), 0.0)))
        err = np.where(self.active, err / self.scale, 0.0)
        passed = (side == 0) & self.active & (err > WARP_MOTOR_TOL)
        new_hold = np.where(passed, np.where(over > under, 1, -1), hold)
        return side, err, new_hold


def _motor_steps(wp: Any, mjw: Any, step: _Stepper, mw: Any, dw: Any, motor: _MotorBounds,
                 ctrl_dev: Any,
                 n_max: int, ends: NDArray[np.int_], first_qdd: NDArray[np.float64],
                 labels: Sequence[str], limits: NDArray[np.float64],
                 out: tuple[Any, ...]) -> None:
    """Step the batch ``n_max`` times with the drives' motor limit (:class:`_MotorBounds`), and
    set the final state's force ranges (for its sensors).

    Each step starts from an estimate of its acceleration (the last two steps' extrapolated;
    the reference's at the first): the bounds at it are set on the device and the batch steps.
    Where a drive's torque is off its motor law at the acceleration the step really had by
    more than :data:`WARP_MOTOR_TOL`, the batch runs the step again from the saved state, with
    a new acceleration for that drive (first the step's own, then a secant on the last two
    passes: the bound moves with the acceleration by ``J_r N^2 (1 - eta)`` or ``J_r N^2
    (1 - 1/eta)``, a fraction of the joint's inertia, so this settles in two or three passes),
    and a drive whose torque passed its bound inside its range (the implicit step's velocity
    term) held at the bound. Worlds past their own end (shorter variants) run along unchecked.
    ``limits`` gets the limit each step applied on the side the drive pushed (the records'
    ``tau_limit``).
    """
    qpos_dev, qvel_dev, sens_dev, nacon_dev, nefc_dev = out
    saved = {name: wp.clone(getattr(dw, name))
             for name in ("qpos", "qvel", "act", "time", "qacc_warmstart")}
    qd0 = dw.qvel.numpy()[:, motor.dof].astype(np.float64)
    last = np.zeros((2,) + qd0.shape)  # the accelerations of the last two steps
    for k in range(n_max + 1):
        live = k < ends  # worlds whose step k is recorded
        est = first_qdd if k == 0 else (last[1] if k == 1 else 2 * last[1] - last[0])
        # a world's final sample repeats its last step's acceleration (as recorded)
        est = np.where((k == ends)[:, None] & (k > 0), last[1], est)
        hold = np.zeros(qd0.shape, dtype=int)
        wp.copy(dw.ctrl, ctrl_dev[k])
        if k == n_max:  # the final state: its sensors
            lo, hi = motor.bounds(qd0, est)
            mw.actuator_forcerange.assign(motor.forcerange(lo, hi, hold))
            mjw.forward(mw, dw)
            tau_act = dw.sensordata.numpy()[:, motor.tau_cols].astype(np.float64)
            limits[k] = np.abs(np.where(tau_act >= 0, hi, lo))
            return
        for name, arr in saved.items():
            wp.copy(arr, getattr(dw, name))
        prev = None
        for it in range(MOTOR_ITERATIONS):
            if it:  # the step again, from the saved state
                for name, arr in saved.items():
                    wp.copy(getattr(dw, name), arr)
            lo, hi = motor.bounds(qd0, est)
            mw.actuator_forcerange.assign(motor.forcerange(lo, hi, hold))
            step()
            qd1 = dw.qvel.numpy()[:, motor.dof].astype(np.float64)
            tau_act = dw.sensordata.numpy()[:, motor.tau_cols].astype(np.float64)
            qdd = (qd1 - qd0) / motor.h
            side, err, new_hold = motor.check(qd0, qdd, tau_act, lo, hi, hold)
            bad = live[:, None] & ((err > WARP_MOTOR_TOL) | (new_hold != hold))
            if not bad.any():
                break
            # the next guess of the step's acceleration, drive by drive: a secant through the
            # last two passes where there are two, else this pass's
            new = qdd.copy()
            if prev is not None:
                p_est, p_qdd = prev
                r, p_r = qdd - est, p_qdd - p_est
                with np.errstate(divide="ignore", invalid="ignore"):
                    sec = est - r * (est - p_est) / (r - p_r)
                new = np.where(np.isfinite(sec), sec, qdd)
            prev = (est, qdd)
            est = np.where(bad, new, est)
            hold = np.where(live[:, None], new_hold, hold)
        else:
            left = np.where(live[:, None], err, 0.0)
            if np.any(left > WARP_SETTLE_TOL):
                w, j = np.unravel_index(int(np.argmax(left)), left.shape)
                raise SimulationError(
                    f"{labels[w]}: the drives' motor torque limit did not settle in "
                    f"{MOTOR_ITERATIONS} passes at step {k} (joint {j + 1}, {left[w, j]:.2g} "
                    "of the peak torque off, MuJoCo Warp); try a smaller simulation.timestep_s")
        _record_step(wp, dw, k, qpos_dev, qvel_dev, sens_dev, nacon_dev, nefc_dev)
        limits[k] = np.abs(np.where(side > 0, hi, np.where(side < 0, lo,
                                                            np.where(tau_act >= 0, hi, lo))))
        last = np.stack([last[1], qdd])
        qd0 = qd1
