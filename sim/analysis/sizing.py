"""Actuator sizing from a simulated work cycle (seed 001: "based on their extreme values, the
corresponding actuators of the robot joints will be chosen").

What is computed, per joint, from two torque sources shown side by side:

* ``"id"``: inverse dynamics of the *reference* trajectory (``tau_id`` with ``qd_ref``,
  ``qdd_ref``): the torque the cycle demands;
* ``"sim"``: the simulated actuator torque (``tau`` with the simulated ``qd`` and ``qdd``;
  ``qdd`` is taken from ``trajectory.npz`` when present, otherwise ``numpy.gradient`` of ``qd``
  over the non-uniform time grid, second order).

Joint-side statistics (:class:`SignalStats`): peak ``|tau|`` and when, time-weighted RMS torque
``sqrt(1/T * int tau^2 dt)`` (trapezoidal rule over the samples' own, possibly non-uniform,
times: not a plain mean of samples), peak ``|qd|``, peak ``|qdd|``, peak mechanical power
``|tau * qd|``, two mean powers, ``mean |P| = 1/T int |P| dt`` (what the drive must supply and
absorb) and ``mean P = 1/T int P dt`` (net, negative when the joint mostly brakes), energy per
cycle ``int |P| dt`` and the regenerative net energy ``int P dt``. ``T`` is the cycle duration
``t[-1] - t[0]``.

Motor side (:class:`MotorStats`), with a :class:`sim.robots.registry.Drive` per joint: the
motor torque is the drive's own :meth:`~sim.robots.registry.Drive.motor_torque` (the one
formula of cellsim: the gear's efficiency in the direction power flows, the rotor inertia on
the motor side, the motoring formula at standstill), the envelope its
:meth:`~sim.robots.registry.Drive.peak_torque_at`; the motor speed is ``qd N`` in rpm.
``armature`` is the joint-side inertia the simulated model already adds to its torques (MJCF
``armature``, by the registry's convention the reflected rotor inertia ``J_r N^2`` of the
*default* drives); the drive takes it out first so that the rotor inertia of the drive being
checked is counted once.

Limits (:class:`Check`): the joint torque against the MJCF actuator force range (sign by sign
when asymmetric; the gear of the actuator is applied), the joint speed against
``RobotSpec.max_speed``, the motor RMS torque against the rated (continuous) torque, the motor
peak torque against the peak torque, the motor speed against ``max_speed_rpm`` and every
operating point against the peak torque-speed envelope. Margin in percent is
``(limit - used) / limit * 100``; a check passes when the margin is >= 0. With the default
basis ``"worst"`` each check takes the worse of the two sources (the source is recorded).

Torque-speed envelopes (:func:`continuous_envelope`, :func:`peak_envelope`), the usual
servo-motor catalogue picture: the continuous (S1) curve is the rated torque, flat up to the
rated speed (``Drive`` gives no rated speed, so up to ``max_speed_rpm``); the peak
(intermittent, S3-like) curve is the peak torque, flat up to the voltage-limit knee at
``knee_fraction * max_speed_rpm`` (default :data:`PEAK_KNEE_FRACTION`, a generic assumption,
no catalogue data), then a straight voltage-limit slope down to the rated torque at
``max_speed_rpm``. Both are zero above ``max_speed_rpm``; the envelope check clips the speed at
``max_speed_rpm`` (over-speed is the motor speed check's business).

Owns the sizing computation (the checks of a run, from its record or folder); the signal
statistics are :mod:`sim.analysis.statistics`', the result types and verdict
:mod:`sim.analysis.sizing_result`'s, the limits read from a model
:mod:`sim.analysis.model_limits`' (all importable from here, as before). The run folder is read
through :mod:`sim.simulation.runfolder`.
May import: :mod:`sim.robots` and :mod:`sim.simulation` (the run folder).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.analysis.model_limits import (
    armature_from_model,
    forcerange_from_model,
    joint_armature,
    joint_forcerange,
)
from sim.analysis.sizing_result import (
    CHECK_TITLES,
    JOINT_UNITS,
    Check,
    JointSizing,
    MotorStats,
    SignalStats,
    SizingResult,
    verdict_text,
)
from sim.analysis.statistics import (
    as_time,
    margin_pct,
    peak_abs,
    rms,
    sustained,
    time_integral,
)
from sim.errors import CellsimError, UnknownNameError
from sim.robots.registry import PEAK_KNEE_FRACTION as _PEAK_KNEE_FRACTION
from sim.robots.registry import RPM_PER_RAD_S, Drive, RobotSpec
from sim.simulation.runfolder import (
    SUMMARY_JSON,
    TRAJECTORY_NPZ,
    RunRecord,
    read_run_summary,
    read_run_trajectory,
)

#: Sizing's names, with those of the modules it was split into (statistics, result types,
#: model limits), importable from here as before.
__all__ = [
    "BASES",
    "CHECK_TITLES",
    "JOINT_UNITS",
    "PEAK_KNEE_FRACTION",
    "PEAK_WINDOW_S",
    "SATURATION_TOL",
    "SOURCES",
    "SOURCE_TITLES",
    "TRAJECTORY_KEYS",
    "Check",
    "JointSizing",
    "MotorStats",
    "SignalStats",
    "SizingResult",
    "armature_from_model",
    "as_time",
    "check_trajectory",
    "continuous_envelope",
    "forcerange_from_model",
    "joint_armature",
    "joint_forcerange",
    "load_summary",
    "load_trajectory",
    "margin_pct",
    "motor_speed_rpm",
    "motor_stats",
    "motor_torque",
    "peak_abs",
    "peak_envelope",
    "rms",
    "signal_stats",
    "size_record",
    "size_run",
    "size_trajectory",
    "sustained",
    "time_integral",
    "verdict_text",
]

#: Fraction of the motor's maximum speed up to which the peak torque is available (the
#: voltage-limit knee of the peak envelope). Generic servo-motor shape, not catalogue data.
PEAK_KNEE_FRACTION = _PEAK_KNEE_FRACTION

#: Simulated torque within this fraction of the force range counts as saturated.
SATURATION_TOL = 0.005

#: The simulated source's peaks are of the signal sustained over this window, s (the centred
#: sliding mean, :func:`sustained`): a contact's onset or release (a part touching down, a
#: cup's vacuum pulling a part) moves a joint within one or two steps, an impulse whose
#: torque peak scales with 1 / timestep (LR Mate pick-and-place J3: 15.99 N m at 2 ms, 12.85 at
#: 1 ms, 12.83 at 0.5 ms). Its impulse is a result, its torque at one step is not: the peak a
#: drive must deliver for at least 5 ms is (12.81 N m at all three steps to 0.1 %), and the
#: largest instantaneous torque is kept as ``momentary_torque`` (a reducer's momentary rating
#: is the limit for shocks that short).
PEAK_WINDOW_S = 0.005

#: Torque sources, in display order.
SOURCES = ("id", "sim")
SOURCE_TITLES = {"id": "inverse dynamics of the reference", "sim": "simulated actuator torque"}

#: Basis of the checks: the worse of both sources, or one source only.
BASES = ("worst", "id", "sim")

#: Keys ``trajectory.npz`` must hold.
TRAJECTORY_KEYS = ("t", "q_ref", "qd_ref", "qdd_ref", "q", "qd", "tau", "tau_id")



# --------------------------------------------------------------------------------------------
# Joint side
# --------------------------------------------------------------------------------------------

def signal_stats(t: ArrayLike, tau: ArrayLike, qd: ArrayLike, qdd: ArrayLike,
                 source: str = "id", window: float = 0.0,
                 sustained_tau: ArrayLike | None = None) -> SignalStats:
    """Joint-side statistics of one joint.

    Args:
        t: Sample times, s, shape (N,).
        tau: Joint torque, N m, shape (N,).
        qd: Joint speed, rad/s, shape (N,).
        qdd: Joint acceleration, rad/s^2, shape (N,).
        source: Label stored in the result.
        window: Peaks of torque, acceleration and power of the signals sustained over this
            window, s (:func:`sustained`; 0: of the samples). RMS, speeds and energies are of
            the samples.
        sustained_tau: ``sustained(t, tau, window)`` when the caller has it already (the
            same values; computed here when None).

    Returns:
        The :class:`SignalStats`.
    """
    t = as_time(t)
    tau = np.asarray(tau, dtype=float)
    qd = np.asarray(qd, dtype=float)
    qdd = np.asarray(qdd, dtype=float)
    T = t[-1] - t[0]
    power = tau * qd
    tau_s = (sustained(t, tau, window) if sustained_tau is None
             else np.asarray(sustained_tau, dtype=float))
    pk_tau, t_tau = peak_abs(t, tau_s)
    mom, t_mom = peak_abs(t, tau)
    pk_qd, t_qd = peak_abs(t, qd)
    pk_qdd, t_qdd = peak_abs(t, sustained(t, qdd, window))
    pk_p, t_p = peak_abs(t, sustained(t, power, window))
    energy = time_integral(t, np.abs(power))
    net = time_integral(t, power)
    return SignalStats(
        source=source,
        peak_torque=pk_tau, peak_torque_time=t_tau,
        max_torque=float(tau_s.max()), min_torque=float(tau_s.min()),
        rms_torque=float(rms(t, tau)),
        peak_speed=pk_qd, peak_speed_time=t_qd,
        peak_accel=pk_qdd, peak_accel_time=t_qdd,
        peak_power=pk_p, peak_power_time=t_p,
        mean_abs_power=energy / T, mean_power=net / T,
        energy=energy, net_energy=net,
        momentary_torque=mom, momentary_torque_time=t_mom, window=float(window),
    )


# --------------------------------------------------------------------------------------------
# Motor side
# --------------------------------------------------------------------------------------------

def motor_torque(tau_joint: ArrayLike, qd: ArrayLike, qdd: ArrayLike, drive: Drive,
                 armature: float = 0.0) -> NDArray[np.float64]:
    """Motor-side torque of one joint (see the module docstring for the formula and signs).

    Args:
        tau_joint: Joint torque, N m, shape (N,), including ``armature * qdd``.
        qd: Joint speed, rad/s, shape (N,).
        qdd: Joint acceleration, rad/s^2, shape (N,).
        drive: The joint's drive train.
        armature: Joint-side inertia already inside ``tau_joint``, kg m^2 (0 when the torques
            are link torques only).

    Returns:
        Motor torque, N m, shape (N,).
    """
    return drive.motor_torque(tau_joint, qd, qdd, armature)


def motor_speed_rpm(qd: ArrayLike, drive: Drive) -> NDArray[np.float64]:
    """Motor speed, rpm (signed), from joint speed ``qd`` (rad/s, any shape)."""
    return np.asarray(qd, dtype=float) * drive.gear_ratio * RPM_PER_RAD_S


def _rated_speed_rpm(drive: Drive) -> float:
    # Drive has no rated speed: the generic S1 shape is flat up to the maximum speed.
    return float(drive.max_speed_rpm)


def continuous_envelope(drive: Drive, speed_rpm: ArrayLike) -> NDArray[np.float64]:
    """Continuous (S1) torque available at ``|speed_rpm|``, N m, motor side.

    Rated torque flat up to the rated speed (``max_speed_rpm`` when the drive gives none), then
    constant power down to ``max_speed_rpm``; zero above ``max_speed_rpm``.
    """
    n = np.abs(np.asarray(speed_rpm, dtype=float))
    n_r, n_max = _rated_speed_rpm(drive), float(drive.max_speed_rpm)
    with np.errstate(divide="ignore"):
        out = np.where(n <= n_r, drive.rated_torque,
                       drive.rated_torque * n_r / np.maximum(n, 1e-300))
    return np.where(n <= n_max, out, 0.0)


def peak_envelope(drive: Drive, speed_rpm: ArrayLike,
                  knee_fraction: float = PEAK_KNEE_FRACTION) -> NDArray[np.float64]:
    """Peak (intermittent) torque available at ``|speed_rpm|``, N m, motor side.

    Peak torque flat up to ``knee_fraction * max_speed_rpm``, then a straight voltage-limit
    slope down to the rated torque at ``max_speed_rpm``; zero above ``max_speed_rpm``.
    """
    return drive.peak_torque_at(speed_rpm, knee_fraction)


def motor_stats(t: ArrayLike, tau_m: ArrayLike, speed_rpm: ArrayLike, drive: Drive,
                source: str = "id", knee_fraction: float = PEAK_KNEE_FRACTION,
                sustained_tau_m: ArrayLike | None = None, window: float = 0.0) -> MotorStats:
    """Motor-side statistics from motor torque (N m) and speed (rpm), shape (N,) each; the
    peak torque and the envelope ratio of ``sustained_tau_m`` when given (the motor torque
    sustained over ``window`` s, :func:`sustained`), else of the samples."""
    t = as_time(t)
    tau_raw = np.asarray(tau_m, dtype=float)
    tau_m = tau_raw if sustained_tau_m is None else np.asarray(sustained_tau_m, dtype=float)
    speed = np.asarray(speed_rpm, dtype=float)
    pk, t_pk = peak_abs(t, tau_m)
    pk_n, t_n = peak_abs(t, speed)
    env = peak_envelope(drive, np.minimum(np.abs(speed), drive.max_speed_rpm), knee_fraction)
    ratio = np.abs(tau_m) / env
    i = int(np.argmax(ratio))
    return MotorStats(
        source=source,
        peak_torque=pk, peak_torque_time=t_pk,
        rms_torque=float(rms(t, tau_raw)),
        peak_speed_rpm=pk_n, peak_speed_time=t_n,
        mean_speed_rpm=float(time_integral(t, np.abs(speed)) / (t[-1] - t[0])),
        envelope_ratio=float(ratio[i]), envelope_ratio_time=float(t[i]),
        momentary_torque=float(np.abs(tau_raw).max()), window=float(window),
    )


# --------------------------------------------------------------------------------------------
# Whole run
# --------------------------------------------------------------------------------------------

def load_trajectory(run_dir: str | Path) -> dict[str, NDArray[np.float64]]:
    """Read ``run_dir/trajectory.npz`` through the run folder's reader
    (:func:`sim.simulation.runfolder.read_run_trajectory`: confined, bounded) and validate it
    for sizing (:func:`check_trajectory`).

    Returns:
        The arrays by key (``t`` shape (N,), the others (N, n_joints); ``phase`` and ``qdd``
        when present).

    Raises:
        CellsimError: Missing file or key, or inconsistent shapes (names the file and key).
    """
    path = Path(run_dir) / TRAJECTORY_NPZ
    data = read_run_trajectory(run_dir)
    if data is None:
        raise CellsimError(f"{path}: no such file (is {run_dir} a run folder from 'cellsim run'?)")
    return check_trajectory(data, path)


def check_trajectory(data: Mapping[str, NDArray[Any]], path: str | Path
                     ) -> dict[str, NDArray[np.float64]]:
    """Validate recorded arrays for sizing (keys, shapes, finite values); ``path`` names them
    in messages. Returns them as a dict.

    Raises:
        CellsimError: Missing key, inconsistent shapes, NaN (names ``path`` and the key).
    """
    data = dict(data)
    missing = [k for k in TRAJECTORY_KEYS if k not in data]
    if missing:
        raise CellsimError(f"{path}: missing array(s) {', '.join(missing)}")
    t = data["t"]
    if t.ndim != 1:
        raise CellsimError(f"{path}: t must be 1-D, got shape {t.shape}")
    shape = data["tau"].shape
    if len(shape) != 2 or shape[0] != t.size:
        raise CellsimError(f"{path}: tau must have shape ({t.size}, n_joints), got {shape}")
    for k in (*TRAJECTORY_KEYS[1:], "qdd"):
        if k in data and data[k].shape != shape:
            raise CellsimError(f"{path}: {k} has shape {data[k].shape}, expected {shape}")
    for k in (*TRAJECTORY_KEYS, "qdd"):
        if k in data and not np.all(np.isfinite(data[k])):
            raise CellsimError(f"{path}: {k} holds NaN or infinite values")
    as_time(t)
    return data


def load_summary(run_dir: str | Path) -> dict[str, Any]:
    """``run_dir/summary.json`` as a dict ({} when absent), read through the run folder's reader
    (:func:`sim.simulation.runfolder.read_run_summary`)."""
    return read_run_summary(run_dir)


def _pick(basis: str, candidates: dict[str, Check]) -> Check:
    if basis == "worst":
        return min(candidates.values(),
                   key=lambda c: c.margin_pct if np.isfinite(c.margin_pct) else np.inf)
    return candidates[basis]


def _check(key: str, used: float, limit: float, unit: str, source: str, time: float) -> Check:
    m = margin_pct(limit, used)
    return Check(key=key, title=CHECK_TITLES[key], used=float(used), limit=float(limit), unit=unit,
                 margin_pct=m, passed=not (np.isfinite(m) and m < 0), source=source, time=time)


def _torque_check(s: SignalStats, lo: float, hi: float, t: NDArray, tau: NDArray,
                  unit: str = "N m") -> Check:
    # Sign by sign: the positive side against hi, the negative side against |lo|.
    cands = []
    if hi > 0:
        used = max(s.max_torque, 0.0)
        cands.append((margin_pct(hi, used), used, hi, float(t[int(np.argmax(tau))])))
    if lo < 0:
        used = max(-s.min_torque, 0.0)
        cands.append((margin_pct(-lo, used), used, -lo, float(t[int(np.argmin(tau))])))
    finite = [c for c in cands if np.isfinite(c[0])]
    if not finite:
        return _check("joint_torque", s.peak_torque, np.inf, unit, s.source, s.peak_torque_time)
    m, used, limit, when = min(finite)
    return _check("joint_torque", used, limit, unit, s.source, when)


def size_trajectory(
    traj: Mapping[str, ArrayLike],
    joint_names: Sequence[str],
    *,
    drives: Sequence[Drive] | None = None,
    forcerange: ArrayLike | None = None,
    speed_limits: ArrayLike | None = None,
    armature: ArrayLike | None = None,
    basis: str = "worst",
    knee_fraction: float = PEAK_KNEE_FRACTION,
    robot: str = "",
    scenario: str = "",
    phases: Sequence[Mapping[str, Any]] = (),
    prismatic: Sequence[str] = (),
) -> SizingResult:
    """Size every joint of a trajectory (pure computation, no I/O).

    Args:
        traj: Arrays as in ``trajectory.npz``: ``t`` (N,) s; ``tau_id``, ``qd_ref``, ``qdd_ref``,
            ``tau``, ``qd`` (N, n) SI units; ``qdd`` (N, n) optional (otherwise
            ``numpy.gradient(qd, t)``).
        joint_names: Names of the n joints.
        drives: One drive per joint, or None/empty for joint-side sizing only.
        forcerange: Joint torque limits ``(lo, hi)`` per joint, N m, shape (n, 2); None or
            infinite entries for no limit.
        speed_limits: Joint speed limits, rad/s, shape (n,); None for none.
        armature: Joint-side inertia inside the torques, kg m^2, shape (n,); None for zeros.
        basis: ``"worst"`` (default: each check on the worse source), ``"id"`` or ``"sim"``.
        knee_fraction: Voltage-limit knee of the peak envelope, fraction of max motor speed.
        robot, scenario, phases: Carried into the result for the reports.
        prismatic: The names of the prismatic joints (a track's axis): their "torque" is a
            force in N, their speed in m/s, and their checks say so.

    Returns:
        The :class:`SizingResult`.
    """
    if basis not in BASES:
        raise UnknownNameError("sizing basis", basis, BASES)
    names = tuple(joint_names)
    n = len(names)
    t = as_time(traj["t"])
    arr = {k: np.asarray(traj[k], dtype=float)
           for k in ("tau_id", "qd_ref", "qdd_ref", "tau", "qd")}
    for k, v in arr.items():
        if v.shape != (t.size, n):
            raise CellsimError(f"trajectory {k} has shape {v.shape}, expected ({t.size}, {n}) "
                               f"for joints {', '.join(names)}")
    qdd_sim = (np.asarray(traj["qdd"], dtype=float) if "qdd" in traj
               else np.gradient(arr["qd"], t, axis=0, edge_order=2))
    drives = tuple(drives or ())
    if drives and len(drives) != n:
        raise CellsimError(f"{len(drives)} drives for {n} joints ({', '.join(names)})")
    fr = (np.tile([-np.inf, np.inf], (n, 1)) if forcerange is None
          else np.asarray(forcerange, dtype=float).reshape(n, 2))
    vmax = np.full(n, np.inf) if speed_limits is None else np.asarray(speed_limits, dtype=float)
    arm = np.zeros(n) if armature is None else np.asarray(armature, dtype=float).reshape(n)
    sources = {
        "id": (arr["tau_id"], arr["qd_ref"], np.asarray(traj["qdd_ref"], dtype=float)),
        "sim": (arr["tau"], arr["qd"], qdd_sim),
    }
    windows = {"id": 0.0, "sim": PEAK_WINDOW_S}

    joints = []
    linear = set(prismatic)
    for j, name in enumerate(names):
        kind = "prismatic" if name in linear else "revolute"
        torque_unit, speed_unit, _ = JOINT_UNITS[kind]
        lo, hi = float(fr[j, 0]), float(fr[j, 1])
        tau_w = {s: sustained(t, tau[:, j], windows[s]) for s, (tau, _, _) in sources.items()}
        stats = {s: signal_stats(t, tau[:, j], qd[:, j], qdd[:, j], s, windows[s], tau_w[s])
                 for s, (tau, qd, qdd) in sources.items()}
        cands: dict[str, dict[str, Check]] = {}
        for s in sources:
            st = stats[s]
            cands.setdefault("joint_torque", {})[s] = _torque_check(
                st, lo, hi, t, tau_w[s], torque_unit)
            cands.setdefault("joint_speed", {})[s] = _check(
                "joint_speed", st.peak_speed, vmax[j], speed_unit, s, st.peak_speed_time)
        motor: dict[str, MotorStats] = {}
        points = {}
        drive = drives[j] if drives else None
        if drive is not None:
            for s, (tau, qd, qdd) in sources.items():
                tm = motor_torque(tau[:, j], qd[:, j], qdd[:, j], drive, arm[j])
                nm = motor_speed_rpm(qd[:, j], drive)
                points[s] = (nm, tm)
                w = windows[s]
                # the motor torque sustained over the window: a mean of torques the motor
                # gave, never above the largest of them
                tm_w = None if w <= 0.0 else sustained(t, tm, w)
                ms = motor_stats(t, tm, nm, drive, s, knee_fraction, tm_w, w)
                motor[s] = ms
                cands.setdefault("motor_rms_torque", {})[s] = _check(
                    "motor_rms_torque", ms.rms_torque, drive.rated_torque, "N m", s, float("nan"))
                cands.setdefault("motor_peak_torque", {})[s] = _check(
                    "motor_peak_torque", ms.peak_torque, drive.peak_torque, "N m", s,
                    ms.peak_torque_time)
                cands.setdefault("motor_speed", {})[s] = _check(
                    "motor_speed", ms.peak_speed_rpm, drive.max_speed_rpm, "rpm", s,
                    ms.peak_speed_time)
                cands.setdefault("motor_envelope", {})[s] = _check(
                    "motor_envelope", 100.0 * ms.envelope_ratio, 100.0, "% of peak curve", s,
                    ms.envelope_ratio_time)
        checks = tuple(_pick(basis, c) for c in cands.values())
        tau_sim = arr["tau"][:, j]
        tol = SATURATION_TOL
        saturated = bool((np.isfinite(hi) and hi > 0 and tau_sim.max() >= hi * (1 - tol))
                         or (np.isfinite(lo) and lo < 0 and tau_sim.min() <= lo * (1 - tol)))
        joints.append(JointSizing(
            joint=name, stats=stats, motor=motor, drive=drive, torque_range=(lo, hi),
            speed_limit=float(vmax[j]), armature=float(arm[j]), checks=checks,
            saturated=saturated, points=points, kind=kind))

    series = {"t": t, "tau_id": arr["tau_id"], "tau": arr["tau"], "qd_ref": arr["qd_ref"],
              "qd": arr["qd"]}
    return SizingResult(joints=tuple(joints), duration=float(t[-1] - t[0]), basis=basis,
                        robot=robot, scenario=scenario,
                        phases=tuple(dict(p) for p in phases), series=series)


def size_run(run_dir: str | Path, spec: RobotSpec, drives: Sequence[Drive] | None = None,
             forcerange: ArrayLike | None = None, *, armature: ArrayLike | None = None,
             basis: str = "worst", knee_fraction: float = PEAK_KNEE_FRACTION) -> SizingResult:
    """Size the run in ``run_dir`` (reads ``trajectory.npz`` and ``summary.json``).

    Args:
        run_dir: A run folder written by ``cellsim run``.
        spec: The robot (joint names, speed limits; ``spec.drives`` when ``drives`` is None).
        drives: Drives after scenario overrides (:func:`apply_overrides`); None for the
            registry defaults.
        forcerange: Joint torque limits, shape (n, 2), N m (:func:`forcerange_from_model`);
            None for unlimited.
        armature: Joint-side inertia the simulated model added to its torques, kg m^2, shape
            (n,) (:func:`armature_from_model`). None assumes the registry convention: the MJCF
            armature equals the reflected inertia of ``spec.drives`` (zeros without drives).
        basis: ``"worst"``, ``"id"`` or ``"sim"`` (see :func:`size_trajectory`).
        knee_fraction: Voltage-limit knee of the peak envelope.

    Returns:
        The :class:`SizingResult`.

    Raises:
        CellsimError: Missing or malformed run files, or joints that do not match ``spec``.
    """
    return _size(load_trajectory(run_dir), load_summary(run_dir), Path(run_dir) / SUMMARY_JSON,
                 spec, drives, forcerange, armature=armature, basis=basis,
                 knee_fraction=knee_fraction)


def size_record(record: RunRecord, spec: RobotSpec, drives: Sequence[Drive] | None = None,
                forcerange: ArrayLike | None = None, *, armature: ArrayLike | None = None,
                basis: str = "worst", knee_fraction: float = PEAK_KNEE_FRACTION) -> SizingResult:
    """Size a run held in memory (the runner's :class:`RunRecord`); arguments as
    :func:`size_run`."""
    traj = check_trajectory(record.arrays, f"{record.where}: trajectory")
    return _size(traj, record.summary, f"{record.where}: summary", spec, drives, forcerange,
                 armature=armature, basis=basis, knee_fraction=knee_fraction)


def _size(traj: dict[str, NDArray[np.float64]], summary: Mapping[str, Any], where: str | Path,
          spec: RobotSpec, drives: Sequence[Drive] | None, forcerange: ArrayLike | None, *,
          armature: ArrayLike | None, basis: str, knee_fraction: float) -> SizingResult:
    names = tuple(summary.get("joints") or spec.joints)
    if names != tuple(spec.joints):
        raise CellsimError(f"{where}: joints {', '.join(names)} do not "
                           f"match robot {spec.name} ({', '.join(spec.joints)})")
    if drives is None:
        drives = spec.drives
    if armature is None:
        armature = ([d.reflected_inertia for d in spec.drives] if spec.drives
                    else np.zeros(len(names)))
    result = size_trajectory(
        traj, names, drives=drives, forcerange=forcerange, speed_limits=spec.max_speed,
        armature=armature, basis=basis, knee_fraction=knee_fraction,
        robot=str(summary.get("robot", spec.name)), scenario=str(summary.get("scenario", "")),
        phases=summary.get("phases", ()),
        prismatic=[name for name, axis in spec.external if axis.kind == "prismatic"])
    return dataclasses.replace(result, estimated_joints=spec.joints_on_estimates)
