"""The result types of actuator sizing and their verdict: per-joint statistics (joint and
motor side), the limit checks, a joint's and a run's sizing, its JSON form and the one-paragraph
verdict.

Owns what a sizing *is* (:class:`SizingResult` and its parts); :mod:`sim.analysis.sizing`
computes it.
May import: :mod:`sim.robots.registry` (the :class:`Drive` a joint is checked with).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import UnknownNameError
from sim.robots.registry import PEAK_KNEE_FRACTION, Drive


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


#: Joint-side units by joint kind: ``(torque, speed, acceleration)``; a prismatic joint (a
#: track's axis) has a force, a linear speed and acceleration (SI, as the recorded arrays).
JOINT_UNITS = {"revolute": ("N m", "rad/s", "rad/s^2"), "prismatic": ("N", "m/s", "m/s^2")}


@dataclass(frozen=True)
class JointSizing:
    """Sizing of one joint.

    Attributes:
        joint: Joint name.
        stats: Joint-side statistics by source (``"id"``, ``"sim"``); for a prismatic joint
            (:attr:`kind`) its torques are forces in N, its speeds in m/s (:attr:`torque_unit`,
            :attr:`speed_unit`).
        motor: Motor-side statistics by source; empty without a drive.
        drive: The drive checked (None when the robot has no drive data).
        torque_range: Joint torque limits ``(lo, hi)``, N m (``(-inf, inf)`` when unlimited).
        speed_limit: Joint speed limit, rad/s (inf when unknown).
        armature: Joint-side inertia taken out of the torques before the drive train, kg m^2.
        checks: The limit checks, each on the chosen basis.
        saturated: The simulated torque reached the force range (the actuator clipped it).
        points: Motor operating points by source: ``(speed_rpm, torque_nm)`` arrays, shape (N,)
            each, signed (for the torque-speed chart; not serialized).
        kind: ``"revolute"`` or ``"prismatic"`` (a linear external axis: force in N, m/s).
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
    kind: str = "revolute"

    @property
    def torque_unit(self) -> str:
        """Unit of the joint-side "torque": ``"N m"``, or ``"N"`` (a force) for a prismatic
        joint (a track's axis)."""
        return JOINT_UNITS[self.kind][0]

    @property
    def speed_unit(self) -> str:
        """Unit of the joint-side speed: ``"rad/s"``, or ``"m/s"`` for a prismatic joint."""
        return JOINT_UNITS[self.kind][1]

    @property
    def accel_unit(self) -> str:
        """Unit of the joint-side acceleration: ``"rad/s^2"``, or ``"m/s^2"``."""
        return JOINT_UNITS[self.kind][2]

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
                "inertials (the robot's folder says which: its README, or its robot.toml's [mass] "
                "and [[links]]): check them against the maker's "
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
        """JSON-ready dictionary (NaN and infinities become None). Each joint names its
        ``kind`` and units: a prismatic joint's ``torque_range_nm``, joint-side torques and
        ``speed_limit_rad_s`` are in its ``torque_unit`` (N) and ``speed_unit`` (m/s)."""
        joints = []
        for j in self.joints:
            lim = j.limiting
            joints.append({
                "joint": j.joint,
                "kind": j.kind,
                "torque_unit": j.torque_unit,
                "speed_unit": j.speed_unit,
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
                "motor_torque": "(tau - armature qdd)/(N eta) + J_r N qdd when motoring or at "
                                "standstill (|qd| < 1e-3 rad/s), (tau - armature qdd) eta/N + "
                                "J_r N qdd when power flows back",
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
