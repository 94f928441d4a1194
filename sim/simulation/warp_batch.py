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

Differences, all measured by ``tests/test_warp_backend.py`` against the CPU path:

* MuJoCo Warp computes in float32: joint paths agree to about 1e-5 rad and torques to a
  fraction of a percent on the shipped robots (the tests bound them at 1e-4 rad and 1 %).
* A drive's torque-speed envelope (``simulation.motor_speed_limits``) follows the reference's
  speeds step by step (the CPU path also watches the joint's own speed, in chunks); where a
  drive runs past its curve's knee the two may differ, and the CPU path is the reference.
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
from sim.robots.registry import Drive
from sim.simulation.compile import BuiltCell
from sim.simulation.motion import Motion
from sim.simulation.simulate import (
    SimulationRecord,
    _arrays,
    _joint_peak,
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
        drives: Per variant, the drives whose torque-speed curves limit the actuators (None:
            the constant ``forcerange``).
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

    # host side: references, feed-forward, controls and drive limits per variant
    per: list[dict[str, Any]] = []
    for built, motion, drv in zip(builts, motions, drives):
        n = int(round((motion.duration + settle_s) / dt))
        t = motion.t0 + dt * np.arange(n + 1)
        ref = motion.at(t)
        tau_id, ff, controls = reference_controls(built, motion, t, ref, feedforward)
        flat = built.force_limits[:, 1]
        limit = np.tile(flat, (n + 1, 1))
        if drv is not None:
            limit = np.minimum(_joint_peak(drv, np.abs(ref.qd)), flat)
        per.append({"n": n, "t": t, "ref": ref, "tau_id": tau_id, "ff": ff,
                    "controls": controls, "limit": limit})
    n_max = max(p["n"] for p in per)
    # every step's controls and force ranges, the shorter variants holding their last values
    ctrl = np.zeros((n_max + 1, nworld, nu), dtype=np.float32)
    frange = np.zeros((n_max + 1, nworld, nu, 2), dtype=np.float32)
    for w, (p, built) in enumerate(zip(per, builts)):
        pad = n_max - p["n"]
        ctrl[:, w] = np.concatenate([p["controls"], np.repeat(p["controls"][-1:], pad, 0)])
        base = built.model.actuator_forcerange.astype(np.float32)
        lim = np.concatenate([p["limit"], np.repeat(p["limit"][-1:], pad, 0)])
        frange[:, w] = base
        frange[:, w, built.robot_act, 0] = -lim
        frange[:, w, built.robot_act, 1] = lim
    # limits that differ from the models' force ranges at any step (a drive's torque-speed
    # curve binding) are copied to the device every step
    model_ranges = np.stack([m.actuator_forcerange for m in models]).astype(np.float32)
    varying_limits = bool(np.any(frange != model_ranges[None]))

    device = device or default_device()
    try:
        with wp.ScopedDevice(device):
            batched = _batched_fields(models, labels)
            if varying_limits and "actuator_forcerange" not in batched:
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
            frange_dev = wp.array(frange.reshape(n_max + 1, nworld, nu, 2), dtype=wp.vec2) \
                if varying_limits else None
            nq, nv, ns = models[0].nq, models[0].nv, models[0].nsensordata
            qpos_dev = wp.zeros((n_max + 1, nworld, nq), dtype=float)
            qvel_dev = wp.zeros((n_max + 1, nworld, nv), dtype=float)
            sens_dev = wp.zeros((n_max + 1, nworld, ns), dtype=float)
            wp.copy(qpos_dev[0], dw.qpos)
            wp.copy(qvel_dev[0], dw.qvel)
            start = time.perf_counter()
            nacon_dev = wp.zeros(n_max + 1, dtype=int)
            nefc_dev = wp.zeros((n_max + 1, nworld), dtype=int)
            for k in range(n_max):
                wp.copy(dw.ctrl, ctrl_dev[k])
                if frange_dev is not None:
                    wp.copy(mw.actuator_forcerange, frange_dev[k])
                mjw.step(mw, dw)
                wp.copy(qpos_dev[k + 1], dw.qpos)
                wp.copy(qvel_dev[k + 1], dw.qvel)
                wp.copy(sens_dev[k], dw.sensordata)  # computed at state k, before the step
                wp.copy(nacon_dev, dw.nacon, dest_offset=k, count=1)
                wp.copy(nefc_dev[k], dw.nefc)
            wp.copy(dw.ctrl, ctrl_dev[n_max])
            if frange_dev is not None:
                wp.copy(mw.actuator_forcerange, frange_dev[n_max])
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
                         p["limit"])
        records.append(SimulationRecord(arrays=arrays, wall_s=wall / nworld, steps=n,
                                        timestep=dt))
    return records
