"""The scenario runner: build the cell, plan, simulate with position actuators, record.

``run_scenario`` is what ``cellsim run`` does:

1. compose the cell (robot, tool, fixtures, cameras) with ``dm_control.mjcf`` and compile it;
2. plan every phase into one reference motion (:mod:`sim.motion`);
3. simulate: the robot's position actuators track the reference (``ctrl = q_ref(t)``). With
   feed-forward on (the default) the drives also apply ``tau_id``, the inverse dynamics of the
   reference (``mj_inverse``), and the set-point carries the velocity feed-forward
   ``ctrl = q_ref + (kv/kp) qd_ref``, so the servo force ``kp (q_ref - q) + kv (qd_ref - qd)``
   only corrects errors. Without feed-forward the arm lags by about ``(kv/kp) qd`` plus
   ``tau/kp`` (the position servo alone; see the README's tracking figures). Steps run
   in C through ``mujoco.rollout`` in chunks, with the controls precomputed (they do not depend
   on the state), and every chunk is checked for NaN and MuJoCo warnings;
4. record the tool-point path and the joint torques, compute the summary metrics, and write
   the run folder atomically.

Recorded torque ``tau`` is what the joint's drive delivers: the position actuator's force plus
the feed-forward torque. ``tau_id`` is the inverse dynamics of the reference motion.
"""

from __future__ import annotations

import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from sim import __version__
from sim.errors import CellsimError, SimulationError
from sim.motion import CartesianContext, Motion, build_motion, check_motion_limits
from sim.scenario import Scenario

#: Steps per rollout chunk (checked for instability after each).
CHUNK_STEPS = 2000


@dataclass
class RunOptions:
    """Options of one run.

    Attributes:
        out_dir: Run folder (default ``runs/<scenario name>``).
        video: Write ``video.mp4``.
        feedforward: Override the scenario's ``simulation.feedforward``.
        video_args: Keyword arguments for :func:`sim.video.write_video` (cameras, width,
            height, fps, gl).
        plots: Write ``plots/*.png``.
        sizing: Write the actuator-sizing report.
        progress: Show progress bars (they are silent anyway when stderr is not a terminal).
    """

    out_dir: Path | None = None
    video: bool = True
    feedforward: bool | None = None
    video_args: dict[str, Any] = field(default_factory=dict)
    plots: bool = True
    sizing: bool = True
    progress: bool = True


@dataclass
class SimulationRecord:
    """What the simulation recorded, N samples at the physics rate (SI units, world frame)."""

    arrays: dict[str, NDArray[Any]]
    wall_s: float
    steps: int
    timestep: float


@dataclass
class BuiltCell:
    """A compiled cell and the handles the runner needs."""

    cell: Any
    model: Any
    xml: str
    robot_qpos: NDArray[np.int64]
    robot_dof: NDArray[np.int64]
    robot_act: NDArray[np.int64]
    suction_act: int | None
    sensor_slices: dict[str, slice]
    part_qpos: list[NDArray[np.int64]]
    context: CartesianContext


# --------------------------------------------------------------------------------------------
# Cell compilation
# --------------------------------------------------------------------------------------------


def build(scenario: Scenario) -> BuiltCell:
    """Compose and compile the scenario's cell, with the sensors the runner records."""
    import mujoco

    from sim.cells import build_cell
    from sim.kinematics.model import closed_form_model

    cell = build_cell(scenario.cell, scenario.robot.name, tool=scenario.tool,
                      mount=scenario.mount, payload_kg=scenario.payload_kg)
    root = cell.mjcf
    if scenario.simulation.timestep_s is not None:
        root.option.timestep = scenario.simulation.timestep_s
    sensors: list[tuple[str, int]] = []
    for i, name in enumerate(cell.actuator_names):
        root.sensor.add("actuatorfrc", name=f"cellsim_tau{i}", actuator=root.find("actuator", name))
        sensors.append((f"tau{i}", 1))
    tcp = root.find("site", cell.tcp_site)
    root.sensor.add("framepos", name="cellsim_tcp_pos", objtype="site", objname=tcp)
    root.sensor.add("framequat", name="cellsim_tcp_quat", objtype="site", objname=tcp)
    sensors += [("tcp_pos", 3), ("tcp_quat", 4)]
    xml = root.to_xml_string()
    try:
        model = mujoco.MjModel.from_xml_string(xml, root.get_assets())
    except ValueError as exc:  # a bug in a cell builder, not a user mistake
        raise RuntimeError(f"cell {scenario.cell!r} does not compile: {exc}") from exc
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "model.xml"
        mujoco.mj_saveLastXML(str(path), model)
        saved_xml = path.read_text()

    slices, start = {}, 0
    for name, size in sensors:
        slices[name] = slice(start, start + size)
        start += size
    jids = [model.joint(n).id for n in cell.joint_names]
    robot_qpos = np.array([model.jnt_qposadr[j] for j in jids])
    robot_dof = np.array([model.jnt_dofadr[j] for j in jids])
    robot_act = np.array([model.actuator(n).id for n in cell.actuator_names])
    suction = (model.actuator(cell.adhesion_actuator).id
               if getattr(cell, "adhesion_actuator", None) else None)
    part_qpos = [np.arange(model.jnt_qposadr[model.body(p).jntadr[0]],
                           model.jnt_qposadr[model.body(p).jntadr[0]] + 7)
                 for p in getattr(cell, "parts", [])]
    kin = _tool_kinematics(closed_form_model(scenario.robot.name), model, cell, robot_qpos)
    ctx = CartesianContext(kinematics=kin, seams=dict(getattr(cell, "seams", {})),
                           world_from_frame0=np.asarray(cell.world_from_frame0, dtype=float))
    return BuiltCell(cell, model, saved_xml, robot_qpos, robot_dof, robot_act, suction, slices,
                     part_qpos, ctx)


def _tool_kinematics(kin: Any, model: Any, cell: Any, robot_qpos: NDArray[np.int64]) -> Any:
    """The closed-form kinematics with the attached tool, measured from the compiled cell.

    Tools are straight (their tip lies on the seeds' tool axis), so the tool changes one
    number: ``l3`` of the 5R family (seed 000 Table 1, J4 axis to the tool point) or the tool
    length ``r`` of the 200iC (seed 004, along z6 beyond R6). It is read off MuJoCo's ``tcp``
    in ``frame0`` at q = 0, where the seeds put the tool point at ``(l1 + l2 + l3, 0, d1)`` and
    ``(d2 + R4 + R6 + r, 0, d3 + d4)``; :func:`_check_tcp_consistency` then checks the whole pose.
    """
    import dataclasses

    import mujoco

    data = mujoco.MjData(model)
    data.qpos[robot_qpos] = 0.0
    mujoco.mj_kinematics(model, data)
    f0 = model.site(cell.frame0_site).id
    tcp = model.site(cell.tcp_site).id
    p = data.site_xmat[f0].reshape(3, 3).T @ (data.site_xpos[tcp] - data.site_xpos[f0])
    dims = dict(kin.dims)
    if kin.family == "5r":
        dims["l3"] = float(p[0] - dims["l1"] - dims["l2"])
        return dataclasses.replace(kin, dims=dims)
    return dataclasses.replace(kin, tool_length=float(p[0] - dims["d2"] - dims["R4"] - dims["R6"]))


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
    nj = motion.n_joints
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


# --------------------------------------------------------------------------------------------
# Metrics
# --------------------------------------------------------------------------------------------


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
        if not np.any(arrays["arc_on"][sel]):
            continue
        cart = pm.cartesian
        p = arrays["tcp_pos"][sel]
        ts = t[sel]
        share = cart.constant_speed_fraction
        ramp = float(cart.profile.ramp_time)
        tc0, tc1 = pm.t0 + ramp, pm.t1 - ramp
        cs = (ts >= tc0 + 1e-9) & (ts <= tc1 - 1e-9)
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
    slots = np.asarray(getattr(built.cell, "slots", np.zeros((0, 3))), dtype=float)
    if "part_pos" not in arrays or slots.size == 0:
        return None
    final = arrays["part_pos"][-1]
    err = np.linalg.norm(final[: slots.shape[0]] - slots, axis=1) * 1e3
    return {"placed": [bool(e <= tol_mm) for e in err], "place_error_mm": [float(e) for e in err]}


# --------------------------------------------------------------------------------------------
# Run folder
# --------------------------------------------------------------------------------------------


def _git_commit() -> str | None:
    try:
        res = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                             cwd=Path(__file__).resolve().parent, timeout=5)
        return res.stdout.strip() or None if res.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        return None


def manifest(scenario: Scenario) -> dict[str, Any]:
    import mujoco

    return {
        "cellsim": __version__,
        "mujoco": mujoco.__version__,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "git_commit": _git_commit(),
        "scenario": scenario.name,
        "scenario_sha256": scenario.sha256,
    }


def write_csv(path: Path, arrays: dict[str, NDArray[Any]], joints: tuple[str, ...]) -> None:
    cols: list[tuple[str, NDArray[Any]]] = [("t", arrays["t"]), ("phase", arrays["phase"])]
    for key in ("q_ref", "qd_ref", "qdd_ref", "q", "qd", "tau", "tau_id"):
        for j, name in enumerate(joints):
            cols.append((f"{key}_{name}", arrays[key][:, j]))
    for key in ("tcp_pos", "tcp_pos_ref"):
        for a, axis in enumerate("xyz"):
            cols.append((f"{key}_{axis}", arrays[key][:, a]))
    for key in ("arc_on", "suction"):
        cols.append((key, arrays[key].astype(int)))
    header = ",".join(c for c, _ in cols)
    data = np.column_stack([np.asarray(v, dtype=float) for _, v in cols])
    np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.9g")


def default_out_dir(scenario: Scenario) -> Path:
    return Path("runs") / scenario.name


def run_scenario(scenario: Scenario, options: RunOptions | None = None) -> dict[str, Any]:
    """Run a scenario and write its run folder; returns the summary.

    The folder is built in a temporary sibling and moved into place at the end, so a failed
    run never leaves a ``summary.json``. A run that fails mid-simulation keeps what it recorded
    in ``<out_dir>.failed/`` with ``error.txt``.

    Raises:
        CellsimError: A user mistake or an unstable simulation (one-line message).
    """
    options = options or RunOptions()
    out_dir = Path(options.out_dir) if options.out_dir else default_out_dir(scenario)
    out_dir = out_dir.resolve()
    feedforward = (scenario.simulation.feedforward if options.feedforward is None
                   else options.feedforward)

    built = build(scenario)
    _check_tcp_consistency(built, scenario)
    video_args = _video_args(scenario, options)
    if options.video:  # refuse bad video settings before simulating, not after
        from sim.render.frames import resolve_cameras, validate_size

        resolve_cameras(built.model, video_args.get("cameras", ("overview",)))
        validate_size(video_args.get("width", 640), video_args.get("height", 480))
        fps = video_args.get("fps", 30.0)
        if not (np.isfinite(fps) and fps > 0):
            from sim.errors import RenderError

            raise RenderError(f"--fps must be a positive number, got {fps!r}")
    motion = build_motion(scenario, built.context)
    check_motion_limits(scenario, motion)

    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=out_dir.parent))
    try:
        (tmp / "model.xml").write_text(built.xml)
        (tmp / "scenario.toml").write_text(scenario.text)
        (tmp / "manifest.json").write_text(json.dumps(manifest(scenario), indent=1) + "\n")

        def keep_failed(partial: dict[str, NDArray[Any]], message: str) -> None:
            np.savez_compressed(tmp / "trajectory.npz", **partial)
            (tmp / "error.txt").write_text(message + "\n")
            failed = out_dir.with_name(out_dir.name + ".failed")
            if failed.exists():
                shutil.rmtree(failed)
            os.replace(tmp, failed)

        rec = simulate(built, motion, feedforward=feedforward,
                       settle_s=scenario.simulation.settle_s, progress=options.progress,
                       on_failure=keep_failed)
        arrays = rec.arrays
        np.savez_compressed(tmp / "trajectory.npz", **arrays)
        write_csv(tmp / "trajectory.csv", arrays, scenario.robot.joints)

        summary = make_summary(scenario, built, motion, rec, feedforward)
        # written now for the report writers, rewritten complete at the end; the folder only
        # becomes visible (moved into place) once everything succeeded
        (tmp / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
        if options.plots:
            from sim.plots import write_plots

            write_plots(tmp)
        if options.video:
            from sim.video import write_video

            write_video(tmp, tmp / "video.mp4", progress=options.progress, **video_args)
            summary["video"] = "video.mp4"
            (tmp / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
        if options.sizing:  # last: report.html links the video when there is one
            _write_sizing(tmp, scenario, built, arrays, summary)
        (tmp / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    except BaseException:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
        raise
    if out_dir.exists():
        trash = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.old.", dir=out_dir.parent))
        os.replace(out_dir, trash / "old")
        shutil.rmtree(trash, ignore_errors=True)
    os.replace(tmp, out_dir)
    stale = out_dir.with_name(out_dir.name + ".failed")
    if stale.exists():
        shutil.rmtree(stale, ignore_errors=True)
    return summary


def _video_args(scenario: Scenario, options: RunOptions) -> dict[str, Any]:
    v = scenario.video
    args: dict[str, Any] = {}
    if v.cameras:
        args["cameras"] = tuple(v.cameras)
    for key in ("width", "height", "fps"):
        if getattr(v, key) is not None:
            args[key] = getattr(v, key)
    args.update({k: val for k, val in options.video_args.items() if val is not None})
    return args


def _write_sizing(tmp: Path, scenario: Scenario, built: BuiltCell, arrays: dict[str, Any],
                  summary: dict[str, Any]) -> None:
    from sim.report import write_sizing
    from sim.sizing import apply_overrides, armature_from_model, forcerange_from_model, size_run

    drives = apply_overrides(scenario.robot.drives, scenario.drives, scenario.robot.joints)
    joints = built.cell.joint_names
    result = size_run(tmp, scenario.robot, drives, forcerange_from_model(built.model, joints),
                      armature=armature_from_model(built.model, joints))
    write_sizing(tmp, result)
    summary["sizing"] = {"hardest_joint": result.hardest_joint,
                         "hardest_margin_pct": result.hardest_margin_pct,
                         "pass": bool(result.all_pass),
                         "verdict": result.verdict}


def _check_tcp_consistency(built: BuiltCell, scenario: Scenario) -> None:
    """The closed-form kinematics (with the tool) must place the tcp where MuJoCo does."""
    import mujoco

    model = built.model
    data = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    lo = model.jnt_range[[model.joint(n).id for n in built.cell.joint_names], 0]
    hi = model.jnt_range[[model.joint(n).id for n in built.cell.joint_names], 1]
    q = lo + (hi - lo) * rng.uniform(0.3, 0.7, size=lo.size)
    data.qpos[built.robot_qpos] = q
    mujoco.mj_kinematics(model, data)
    site = model.site(built.cell.tcp_site).id
    T0 = built.context.world_from_frame0
    T = np.asarray(built.context.kinematics.fk(q), dtype=float)
    p_cf = T0[:3, :3] @ T[:3, 3] + T0[:3, 3]
    R_cf = T0[:3, :3] @ T[:3, :3]
    err = float(np.linalg.norm(data.site_xpos[site] - p_cf))
    rerr = float(np.max(np.abs(data.site_xmat[site].reshape(3, 3) - R_cf)))
    if err > 1e-6 or rerr > 1e-6:
        raise RuntimeError(f"internal error: closed-form tcp and MuJoCo tcp differ by "
                           f"{err * 1e3:.3f} mm / {rerr:.2e} in rotation for robot "
                           f"{scenario.robot.name} with tool {scenario.tool!r}")


def make_summary(scenario: Scenario, built: BuiltCell, motion: Motion, rec: SimulationRecord,
                 feedforward: bool) -> dict[str, Any]:
    a = rec.arrays
    sim_time = rec.steps * rec.timestep
    track = np.max(np.abs(a["q"] - a["q_ref"]), axis=0)
    dev = np.linalg.norm(a["tcp_pos"] - a["tcp_pos_ref"], axis=1)
    peak_id = np.max(np.abs(a["tau_id"]), axis=0)
    rms_diff = np.sqrt(np.mean((a["tau"] - a["tau_id"]) ** 2, axis=0))
    torch_axis = 0 if scenario.robot.family == "5r" else 2
    summary: dict[str, Any] = {
        "scenario": scenario.name,
        "robot": scenario.robot.name,
        "cell": scenario.cell,
        "tool": scenario.tool,
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
    }
    summary["singularity"] = singularity_summary(a, motion, built, rec.timestep)
    pick = pick_metrics(a, built)
    if pick is not None:
        summary.update(pick)
    return summary


def singularity_summary(arrays: dict[str, NDArray[Any]], motion: Motion, built: BuiltCell,
                        dt: float) -> dict[str, Any]:
    """Closest approach of the reference to a singularity (sampled every 10 ms).

    ``min_sigma`` is the smallest singular value of the task Jacobian (0 at a singularity,
    mixed units; :func:`sim.kinematics.jacobian.singularity_measures`), with its time and
    phase; ``min_abs_<factor>`` are the explicit factors of det J (200iC: ``wrist`` = sin
    theta5, ``elbow``, ``shoulder`` = wrist-centre distance from the J1 axis in m; 5R:
    ``elbow`` = cos q3, ``shoulder`` = reach in m).
    """
    from sim.kinematics.jacobian import singularity_measures

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
