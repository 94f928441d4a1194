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

Motor side (:class:`MotorStats`), with a :class:`sim.robots.registry.Drive` (ratio ``N``, efficiency
``eta``, rotor inertia ``J_r`` motor side) per joint::

    tau_load = tau_joint - armature * qdd            # joint torque without the rotor inertia
    tau_m    = tau_load / (N * eta)  + J_r * N * qdd   when tau_load * qd >= 0 (motoring)
    tau_m    = tau_load * eta / N    + J_r * N * qdd   when tau_load * qd <  0 (power flows back)
    n_m      = |qd| * N * 60 / (2 pi)  rpm

The gearbox loses power in the direction of power flow: when the motor drives the load it must
supply ``P / eta``; when the load drives the motor back (braking, lowering an arm) the gearbox
losses help and the motor only sees ``eta`` times the load torque (the ``1/eta`` of the
motoring formula inverted). At standstill (``|qd| < 1e-3 rad/s``, the friction law's zone
through zero: :meth:`sim.robots.registry.Drive.motor_torque`) the motoring formula is used
(the larger torque, conservative; a held joint's speed wobbles about zero and must not flip
the gear's direction from sample to sample). ``armature`` is the joint-side inertia the
simulated model already adds to its torques (MJCF ``armature``, by the registry's convention
the reflected rotor inertia ``J_r N^2`` of the *default* drives); it is taken out first so that
the rotor inertia of the drive being checked is counted once.

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
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import CellsimError, UnknownNameError
from sim.robots.registry import PEAK_KNEE_FRACTION as _PEAK_KNEE_FRACTION
from sim.robots.registry import RPM_PER_RAD_S, Drive, RobotSpec
from sim.simulation.runfolder import SUMMARY_JSON, TRAJECTORY_NPZ, RunRecord

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
# Signal primitives
# --------------------------------------------------------------------------------------------

def _as_time(t: ArrayLike) -> NDArray[np.float64]:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise CellsimError(f"time vector t must be 1-D with at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise CellsimError("time vector t must be finite and strictly increasing")
    return t


def time_integral(t: ArrayLike, x: ArrayLike) -> NDArray[np.float64] | float:
    """Trapezoidal integral ``int x dt`` over the samples' own times.

    Args:
        t: Sample times, s, shape (N,), strictly increasing (spacing may vary).
        x: Samples, shape (N,) or (N, n).

    Returns:
        The integral, a float or shape (n,).
    """
    t = _as_time(t)
    x = np.asarray(x, dtype=float)
    dt = np.diff(t)
    mid = 0.5 * (x[1:] + x[:-1])
    terms = dt.reshape((-1,) + (1,) * (mid.ndim - 1)) * mid
    flat = terms.reshape(terms.shape[0], -1)
    # an exactly rounded sum (math.fsum): the same bits whatever BLAS, its thread count or the
    # arrays' alignment (a sweep on Ray, one thread per task, gives the pool's table exactly);
    # numpy's sum where a term is not finite (fsum raises on inf - inf and on overflow)
    out = np.array([math.fsum(col) if np.all(np.isfinite(col)) else float(np.sum(col))
                    for col in flat.T])
    return float(out[0]) if terms.ndim == 1 else out.reshape(terms.shape[1:])


def rms(t: ArrayLike, x: ArrayLike) -> NDArray[np.float64] | float:
    """Time-weighted RMS ``sqrt(1/T int x^2 dt)`` (trapezoidal), ``T = t[-1] - t[0]``.

    Args:
        t: Sample times, s, shape (N,).
        x: Samples, shape (N,) or (N, n).

    Returns:
        The RMS value(s), same unit as ``x``; a float or shape (n,).
    """
    t = _as_time(t)
    x = np.asarray(x, dtype=float)
    return np.sqrt(time_integral(t, x * x) / (t[-1] - t[0]))


def peak_abs(t: ArrayLike, x: ArrayLike) -> tuple[float, float]:
    """Largest ``|x|`` and the (first) time it occurs.

    Args:
        t: Sample times, s, shape (N,).
        x: Samples, shape (N,).

    Returns:
        ``(value, time)``; value >= 0 in the unit of ``x``, time in s.
    """
    x = np.abs(np.asarray(x, dtype=float))
    i = int(np.argmax(x))
    return float(x[i]), float(np.asarray(t, dtype=float)[i])


def sustained(t: ArrayLike, x: ArrayLike, window: float) -> NDArray[np.float64]:
    """The centred sliding mean of ``x`` over ``window`` s at each sample: ``1/w int x dt``
    over ``[t - w/2, t + w/2]`` clipped to the record, the exact integral of the samples'
    piecewise-linear interpolant (the trapezoidal rule on the samples' own times, the window's
    ends interpolated); ``x`` itself when ``window <= 0``.

    Args:
        t: Sample times, s, shape (N,), strictly increasing.
        x: Samples, shape (N,) or (N, n).
        window: Window length, s.

    Returns:
        The sustained signal, shape of ``x``.
    """
    t = _as_time(t)
    x = np.asarray(x, dtype=float)
    if window <= 0.0:
        return x
    flat = x.reshape(t.size, -1)
    c = np.concatenate([np.zeros((1, flat.shape[1])),
                        np.cumsum(0.5 * (flat[1:] + flat[:-1]) * np.diff(t)[:, None], axis=0)])
    lo = np.maximum(t - 0.5 * window, t[0])
    hi = np.minimum(t + 0.5 * window, t[-1])

    def integral_to(s: NDArray[np.float64]) -> NDArray[np.float64]:
        # int from t[0] to s: whole trapezoids up to the sample before s, then the part
        # trapezoid from that sample to s (x linear in between)
        k = np.clip(np.searchsorted(t, s, side="right") - 1, 0, t.size - 2)
        xs = np.stack([np.interp(s, t, flat[:, m]) for m in range(flat.shape[1])], axis=1)
        return c[k] + (s - t[k])[:, None] * 0.5 * (flat[k] + xs)

    width = hi - lo
    inside = width > 0.0  # else a window below the times' resolution: the sample itself
    out = flat.copy()
    out[inside] = ((integral_to(hi) - integral_to(lo))[inside] / width[inside, None])
    return out.reshape(x.shape)


def margin_pct(limit: float, used: float) -> float:
    """Margin in percent, ``(limit - used) / limit * 100`` (NaN when there is no finite limit)."""
    if not np.isfinite(limit) or limit <= 0:
        return float("nan")
    return float((limit - used) / limit * 100.0)


# --------------------------------------------------------------------------------------------
# Result types
# --------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SignalStats:
    """Joint-side statistics of one joint from one torque source (SI units).

    Attributes:
        source: ``"id"`` or ``"sim"``.
        peak_torque: max |tau|, N m; ``peak_torque_time`` its time, s.
        max_torque: max tau (signed), N m; ``min_torque``: min tau, N m.
        rms_torque: time-weighted RMS torque over the cycle, N m.
        peak_speed: max |qd|, rad/s; ``peak_speed_time`` its time, s.
        peak_accel: max |qdd|, rad/s^2; ``peak_accel_time`` its time, s.
        peak_power: max |tau qd|, W; ``peak_power_time`` its time, s.
        mean_abs_power: ``1/T int |P| dt``, W.
        mean_power: ``1/T int P dt``, W (net; negative when the joint mostly brakes).
        energy: ``int |P| dt`` over the cycle, J.
        net_energy: ``int P dt`` over the cycle (regenerative), J.
        momentary_torque: max |tau| of the samples, N m; ``momentary_torque_time`` its time, s.
        window: The peaks (torque, max and min, acceleration, power) are of the signal
            sustained over this window, s (:data:`PEAK_WINDOW_S` for the simulated source, 0
            for the reference: its peaks are the samples').
    """

    source: str
    peak_torque: float
    peak_torque_time: float
    max_torque: float
    min_torque: float
    rms_torque: float
    peak_speed: float
    peak_speed_time: float
    peak_accel: float
    peak_accel_time: float
    peak_power: float
    peak_power_time: float
    mean_abs_power: float
    mean_power: float
    energy: float
    net_energy: float
    momentary_torque: float = float("nan")
    momentary_torque_time: float = float("nan")
    window: float = 0.0


@dataclass(frozen=True)
class MotorStats:
    """Motor-side statistics of one joint from one torque source.

    Attributes:
        source: ``"id"`` or ``"sim"``.
        peak_torque: max |tau_m|, N m; ``peak_torque_time`` its time, s.
        rms_torque: time-weighted RMS of tau_m, N m.
        peak_speed_rpm: max motor speed, rpm; ``peak_speed_time`` its time, s.
        mean_speed_rpm: time-weighted mean |motor speed|, rpm (the continuous-duty point's speed).
        envelope_ratio: max over the cycle of ``|tau_m| / peak_envelope(|n_m|)`` (1 = on the curve).
        envelope_ratio_time: time of that worst point, s.
        momentary_torque: max |tau_m| of the samples, N m.
        window: ``peak_torque`` and ``envelope_ratio`` are of the motor torque sustained over
            this window, s (as :class:`SignalStats`).
    """

    source: str
    peak_torque: float
    peak_torque_time: float
    rms_torque: float
    peak_speed_rpm: float
    peak_speed_time: float
    mean_speed_rpm: float
    envelope_ratio: float
    envelope_ratio_time: float
    momentary_torque: float = float("nan")
    window: float = 0.0


@dataclass(frozen=True)
class Check:
    """One limit check of one joint.

    Attributes:
        key: ``"joint_torque"``, ``"joint_speed"``, ``"motor_rms_torque"``,
            ``"motor_peak_torque"``, ``"motor_speed"`` or ``"motor_envelope"``.
        title: Human-readable quantity.
        used: Value used, in ``unit``.
        limit: The limit, in ``unit``.
        unit: Unit of ``used`` and ``limit``.
        margin_pct: ``(limit - used) / limit * 100``.
        passed: ``margin_pct >= 0``.
        source: Source of ``used`` (``"id"`` or ``"sim"``).
        time: When ``used`` occurs, s (NaN for RMS values).
    """

    key: str
    title: str
    used: float
    limit: float
    unit: str
    margin_pct: float
    passed: bool
    source: str
    time: float = float("nan")


CHECK_TITLES = {
    "joint_torque": "joint torque",
    "joint_speed": "joint speed",
    "motor_rms_torque": "motor RMS torque vs rated",
    "motor_peak_torque": "motor peak torque",
    "motor_speed": "motor speed",
    "motor_envelope": "motor torque-speed envelope",
}


@dataclass(frozen=True)
class JointSizing:
    """Sizing of one joint.

    Attributes:
        joint: Joint name.
        stats: Joint-side statistics by source (``"id"``, ``"sim"``).
        motor: Motor-side statistics by source; empty without a drive.
        drive: The drive checked (None when the robot has no drive data).
        torque_range: Joint torque limits ``(lo, hi)``, N m (``(-inf, inf)`` when unlimited).
        speed_limit: Joint speed limit, rad/s (inf when unknown).
        armature: Joint-side inertia taken out of the torques before the drive train, kg m^2.
        checks: The limit checks, each on the chosen basis.
        saturated: The simulated torque reached the force range (the actuator clipped it).
        points: Motor operating points by source: ``(speed_rpm, torque_nm)`` arrays, shape (N,)
            each, signed (for the torque-speed chart; not serialized).
    """

    joint: str
    stats: dict[str, SignalStats]
    motor: dict[str, MotorStats]
    drive: Drive | None
    torque_range: tuple[float, float]
    speed_limit: float
    armature: float
    checks: tuple[Check, ...]
    saturated: bool = False
    points: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = field(
        default_factory=dict, repr=False, compare=False)

    @property
    def limiting(self) -> Check | None:
        """The check with the smallest margin (None when no check had a limit)."""
        finite = [c for c in self.checks if np.isfinite(c.margin_pct)]
        # Rounded so that a tie (the envelope equals the peak torque below the knee) names
        # the simpler check, the one listed first.
        return min(finite, key=lambda c: round(c.margin_pct, 6)) if finite else None

    @property
    def margin_pct(self) -> float:
        """Smallest margin of the joint, percent (NaN when no check had a limit)."""
        c = self.limiting
        return c.margin_pct if c is not None else float("nan")

    @property
    def passed(self) -> bool:
        """Every check passed."""
        return all(c.passed for c in self.checks)

    def check(self, key: str) -> Check | None:
        """The check named ``key`` (None when not applicable)."""
        return next((c for c in self.checks if c.key == key), None)


@dataclass(frozen=True)
class SizingResult:
    """Sizing of a whole run.

    Attributes:
        joints: One :class:`JointSizing` per joint, in the robot's order.
        duration: Cycle duration ``T``, s.
        basis: ``"worst"``, ``"id"`` or ``"sim"``.
        robot: Robot name ("" when unknown).
        scenario: Scenario name ("" when unknown).
        phases: Phases as in ``summary.json`` (``name``, ``kind``, ``t0``, ``t1``).
        series: Time series for charts (``t``, ``tau_id``, ``tau``, ``qd_ref``, ``qd``), not
            serialized.
        estimated_joints: The joints whose torques rest on estimated link inertials
            (:attr:`sim.robots.registry.RobotSpec.joints_on_estimates`).
    """

    joints: tuple[JointSizing, ...]
    duration: float
    basis: str = "worst"
    robot: str = ""
    scenario: str = ""
    phases: tuple[dict[str, Any], ...] = ()
    series: dict[str, NDArray[np.float64]] = field(default_factory=dict, repr=False, compare=False)
    estimated_joints: tuple[str, ...] = ()

    @property
    def estimates_note(self) -> str:
        """One sentence naming the joints whose torques rest on estimated link inertials ("" when
        none do)."""
        if not self.estimated_joints:
            return ""
        return (f"The torques of {', '.join(self.estimated_joints)} rest on estimated link "
                "inertials (the robot's README says which): check them against the maker's "
                "data before ordering.")

    @property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(j.joint for j in self.joints)

    @property
    def passed(self) -> bool:
        """Every joint passed every check."""
        return all(j.passed for j in self.joints)

    @property
    def hardest(self) -> JointSizing | None:
        """The joint with the smallest margin (None when no joint had a limit)."""
        finite = [j for j in self.joints if np.isfinite(j.margin_pct)]
        return min(finite, key=lambda j: j.margin_pct) if finite else None

    @property
    def hardest_joint(self) -> str | None:
        """Name of the joint with the smallest margin (None when no joint had a limit)."""
        h = self.hardest
        return h.joint if h else None

    @property
    def hardest_margin_pct(self) -> float:
        """Smallest margin over all joints, percent (NaN when no joint had a limit)."""
        h = self.hardest
        return h.margin_pct if h else float("nan")

    @property
    def all_pass(self) -> bool:
        """Alias of :attr:`passed`."""
        return self.passed

    def joint(self, name: str) -> JointSizing:
        for j in self.joints:
            if j.joint == name:
                return j
        raise UnknownNameError("joint", name, self.joint_names)

    def phase_at(self, time: float) -> str:
        """Name of the phase holding ``time`` ("" when none)."""
        for p in self.phases:
            if float(p.get("t0", -np.inf)) <= time <= float(p.get("t1", np.inf)):
                return str(p.get("name", ""))
        return ""

    @property
    def verdict(self) -> str:
        """One paragraph: pass/fail, the hardest joint, its limiting check and margin."""
        return verdict_text(self)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (NaN and infinities become None)."""
        joints = []
        for j in self.joints:
            lim = j.limiting
            joints.append({
                "joint": j.joint,
                "pass": j.passed,
                "margin_pct": j.margin_pct,
                "limiting": lim.key if lim else None,
                "saturated": j.saturated,
                "torque_range_nm": list(j.torque_range),
                "speed_limit_rad_s": j.speed_limit,
                "armature_kg_m2": j.armature,
                "drive": dataclasses.asdict(j.drive) if j.drive else None,
                "joint_side": {s: dataclasses.asdict(v) for s, v in j.stats.items()},
                "motor_side": {s: dataclasses.asdict(v) for s, v in j.motor.items()},
                "checks": [dataclasses.asdict(c) for c in j.checks],
            })
        hardest = self.hardest
        return _json_clean({
            "robot": self.robot,
            "scenario": self.scenario,
            "duration_s": self.duration,
            "basis": self.basis,
            "pass": self.passed,
            "hardest_joint": hardest.joint if hardest else None,
            "hardest_margin_pct": hardest.margin_pct if hardest else None,
            "hardest_check": hardest.limiting.key if hardest and hardest.limiting else None,
            "verdict": self.verdict,
            "inertia_estimated_joints": list(self.estimated_joints),
            "conventions": {
                "rms": "sqrt(1/T int x^2 dt), trapezoidal over the sample times",
                "mean_abs_power": "1/T int |tau qd| dt",
                "mean_power": "1/T int tau qd dt (net)",
                "energy": "int |tau qd| dt per cycle; net_energy = int tau qd dt",
                "motor_torque": "(tau - armature qdd)/(N eta) + J_r N qdd when motoring, "
                                "(tau - armature qdd) eta/N + J_r N qdd when power flows back",
                "margin_pct": "(limit - used)/limit*100; pass when >= 0",
                "peak_envelope": f"peak torque to {PEAK_KNEE_FRACTION:g} x max speed, then linear "
                                 "to the rated torque at max speed",
            },
            "joints": joints,
        })


def _json_clean(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _json_clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_clean(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj) if np.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.ndarray):
        return _json_clean(obj.tolist())
    return obj


# --------------------------------------------------------------------------------------------
# Joint side
# --------------------------------------------------------------------------------------------

def signal_stats(t: ArrayLike, tau: ArrayLike, qd: ArrayLike, qdd: ArrayLike,
                 source: str = "id", window: float = 0.0) -> SignalStats:
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

    Returns:
        The :class:`SignalStats`.
    """
    t = _as_time(t)
    tau = np.asarray(tau, dtype=float)
    qd = np.asarray(qd, dtype=float)
    qdd = np.asarray(qdd, dtype=float)
    T = t[-1] - t[0]
    power = tau * qd
    tau_s = sustained(t, tau, window)
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
        out = np.where(n <= n_r, drive.rated_torque, drive.rated_torque * n_r / np.maximum(n, 1e-300))
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
    t = _as_time(t)
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
# Reading limits from the MuJoCo model
# --------------------------------------------------------------------------------------------

def forcerange_from_model(model: Any, joint_names: Sequence[str]) -> NDArray[np.float64]:
    """Joint torque limits from a compiled ``mujoco.MjModel``.

    The limit of a joint is the sum over the actuators driving it (transmission type joint) of
    ``gear * forcerange`` (when ``forcelimited``), intersected with the joint's own
    ``actuatorfrcrange`` (when ``actuatorfrclimited``). Unlimited sides are +-inf.

    Args:
        model: The compiled model.
        joint_names: Joint names, in the order wanted.

    Returns:
        ``(lo, hi)`` per joint, N m, shape (n_joints, 2).

    Raises:
        UnknownNameError: A joint name is not in the model.
    """
    return joint_forcerange(model, _joint_ids(model, joint_names))


def _joint_ids(model: Any, joint_names: Sequence[str]) -> list[int]:
    import mujoco

    valid = [model.joint(i).name for i in range(model.njnt)]
    ids = []
    for name in joint_names:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid < 0:
            raise UnknownNameError("joint", name, valid)
        ids.append(int(jid))
    return ids


def joint_forcerange(model: Any, joint_ids: Sequence[int]) -> NDArray[np.float64]:
    """:func:`forcerange_from_model` for joints given by id (resolved once by the caller). The
    joints' Coulomb friction actuators (cellsim's ``friction_<joint>``) are friction, not drive:
    they are left out."""
    import mujoco

    from sim.cells.compose import FRICTION_PREFIX

    out = np.empty((len(joint_ids), 2))
    for k, jid in enumerate(joint_ids):
        lo, hi, driven = 0.0, 0.0, False
        for a in range(model.nu):
            if model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT or model.actuator_trnid[a, 0] != jid:
                continue
            if model.actuator(a).name.rsplit("/", 1)[-1].startswith(FRICTION_PREFIX):
                continue
            driven = True
            if model.actuator_forcelimited[a]:
                g = float(model.actuator_gear[a, 0])
                ends = sorted((g * model.actuator_forcerange[a, 0], g * model.actuator_forcerange[a, 1]))
                lo, hi = lo + ends[0], hi + ends[1]
            else:
                lo, hi = -np.inf, np.inf
        if not driven:
            lo, hi = -np.inf, np.inf
        if model.jnt_actfrclimited[jid]:
            lo = max(lo, float(model.jnt_actfrcrange[jid, 0]))
            hi = min(hi, float(model.jnt_actfrcrange[jid, 1]))
        out[k] = lo, hi
    return out


def armature_from_model(model: Any, joint_names: Sequence[str]) -> NDArray[np.float64]:
    """``dof_armature`` of each (hinge/slide) joint, kg m^2, shape (n_joints,)."""
    return joint_armature(model, _joint_ids(model, joint_names))


def joint_armature(model: Any, joint_ids: Sequence[int]) -> NDArray[np.float64]:
    """:func:`armature_from_model` for joints given by id (resolved once by the caller)."""
    return np.array([float(model.dof_armature[model.jnt_dofadr[j]]) for j in joint_ids])


# --------------------------------------------------------------------------------------------
# Whole run
# --------------------------------------------------------------------------------------------

def load_trajectory(run_dir: str | Path) -> dict[str, NDArray[np.float64]]:
    """Read and validate ``run_dir/trajectory.npz``.

    Returns:
        The arrays by key (``t`` shape (N,), the others (N, n_joints); ``phase`` and ``qdd``
        when present).

    Raises:
        CellsimError: Missing file or key, or inconsistent shapes (names the file and key).
    """
    path = Path(run_dir) / TRAJECTORY_NPZ
    if not path.is_file():
        raise CellsimError(f"{path}: no such file (is {run_dir} a run folder from 'cellsim run'?)")
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: np.asarray(z[k]) for k in z.files}
    except Exception as exc:  # zipfile / format errors
        raise CellsimError(f"{path}: cannot be read ({exc})") from None
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
    _as_time(t)
    return data


def load_summary(run_dir: str | Path) -> dict[str, Any]:
    """``run_dir/summary.json`` as a dict ({} when absent)."""
    path = Path(run_dir) / SUMMARY_JSON
    if not path.is_file():
        return {}
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise CellsimError(f"{path}: invalid JSON ({exc})") from None


def _pick(basis: str, candidates: dict[str, Check]) -> Check:
    if basis == "worst":
        return min(candidates.values(),
                   key=lambda c: c.margin_pct if np.isfinite(c.margin_pct) else np.inf)
    return candidates[basis]


def _check(key: str, used: float, limit: float, unit: str, source: str, time: float) -> Check:
    m = margin_pct(limit, used)
    return Check(key=key, title=CHECK_TITLES[key], used=float(used), limit=float(limit), unit=unit,
                 margin_pct=m, passed=not (np.isfinite(m) and m < 0), source=source, time=time)


def _torque_check(s: SignalStats, lo: float, hi: float, t: NDArray, tau: NDArray) -> Check:
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
        return _check("joint_torque", s.peak_torque, np.inf, "N m", s.source, s.peak_torque_time)
    m, used, limit, when = min(finite)
    return _check("joint_torque", used, limit, "N m", s.source, when)


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

    Returns:
        The :class:`SizingResult`.
    """
    if basis not in BASES:
        raise UnknownNameError("sizing basis", basis, BASES)
    names = tuple(joint_names)
    n = len(names)
    t = _as_time(traj["t"])
    arr = {k: np.asarray(traj[k], dtype=float) for k in ("tau_id", "qd_ref", "qdd_ref", "tau", "qd")}
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
    for j, name in enumerate(names):
        lo, hi = float(fr[j, 0]), float(fr[j, 1])
        stats = {s: signal_stats(t, tau[:, j], qd[:, j], qdd[:, j], s, windows[s])
                 for s, (tau, qd, qdd) in sources.items()}
        cands: dict[str, dict[str, Check]] = {}
        for s, (tau, qd, qdd) in sources.items():
            st = stats[s]
            cands.setdefault("joint_torque", {})[s] = _torque_check(
                st, lo, hi, t, sustained(t, tau[:, j], windows[s]))
            cands.setdefault("joint_speed", {})[s] = _check(
                "joint_speed", st.peak_speed, vmax[j], "rad/s", s, st.peak_speed_time)
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
            saturated=saturated, points=points))

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
        phases=summary.get("phases", ()))
    return dataclasses.replace(result, estimated_joints=spec.joints_on_estimates)


# --------------------------------------------------------------------------------------------
# Verdict
# --------------------------------------------------------------------------------------------

_SOURCE_SHORT = {"id": "inverse dynamics", "sim": "simulated"}


def _pct(m: float) -> str:
    """A margin in percent: one decimal, two significant digits below 1 % (never "-0.0")."""
    return f"{m:.1f}" if abs(m) >= 1 else f"{m:.2g}"


def _fmt(x: float, unit: str) -> str:
    if not np.isfinite(x):
        return "n/a"
    return f"{x:.4g} {unit}".rstrip()


def verdict_text(result: SizingResult) -> str:
    """One paragraph: pass/fail, the hardest joint, its limiting check, margin and when."""
    n = len(result.joints)
    hardest = result.hardest
    basis = {"worst": "the worse of inverse dynamics and simulation", "id": "inverse dynamics",
             "sim": "the simulated actuator torque"}[result.basis]
    if hardest is None:
        return (f"No limits known for any of the {n} joints (no force range, speed limit or drive "
                "data): nothing to pass or fail.")
    lim = hardest.limiting
    assert lim is not None
    when = ""
    if np.isfinite(lim.time):
        phase = result.phase_at(lim.time)
        when = f" at t = {lim.time:.3f} s" + (f" ({phase})" if phase else "")
    detail = (f"{lim.title}: {_fmt(lim.used, lim.unit)} against {_fmt(lim.limit, lim.unit)} "
              f"({_SOURCE_SHORT[lim.source]}){when}")
    failed = [j for j in result.joints if not j.passed]
    if not failed:
        text = (f"PASS: all {n} joints are within their limits on {basis}. The hardest joint is "
                f"{hardest.joint}, margin {_pct(hardest.margin_pct)}% on {detail}.")
    else:
        worst = ", ".join(f"{j.joint} ({j.limiting.title if j.limiting else '?'}, "
                          f"{_pct(j.margin_pct)}%)" for j in sorted(failed, key=lambda j: j.margin_pct))
        text = (f"FAIL: {len(failed)} of {n} joints exceed a limit on {basis}: {worst}. The hardest "
                f"joint is {hardest.joint}, margin {_pct(hardest.margin_pct)}% on {detail}.")
    sat = [j.joint for j in result.joints if j.saturated]
    if sat:
        text += (f" The simulated actuator torque reached its force range on {', '.join(sat)}: "
                 "the actuator clipped the demand there, so the simulated motion lags the reference.")
    return text
