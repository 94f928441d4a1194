"""Actuator selection: every motor x reducer pair of a catalogue checked over the duty cycle.

For each joint, every pair of a :class:`~sim.analysis.catalog.Catalog` is checked on both torque
sources of the run, the inverse dynamics of the reference (``tau_id``, ``qd_ref``,
``qdd_ref``) and the simulated torque (``tau``, ``qd``, ``qdd``), and each check keeps the worse
of the two. The duty cycle is the recorded cycle followed by ``dwell_s`` at standstill holding
the last sample's torque. With ``N`` the ratio, ``eta`` the efficiency, ``J_r`` the rotor and
``J_in`` the reducer's input inertia, ``w`` the trapezoid weights of the samples' times::

    tau_l = tau - armature qdd                     # the model's own drive inertia removed
    tau_m = tau_l / (N eta) + (J_r + J_in) N qdd   when tau_l qd >= 0 (the motor drives)
                                                   or |qd| < 1e-3 rad/s (standstill)
    tau_m = tau_l eta / N   + (J_r + J_in) N qdd   otherwise (the load drives back)
    n     = N |qd| 60 / (2 pi)                     # motor (reducer input) speed, rpm

Checks (``error`` severity unless said):

* ``motor_rms``: ``sqrt((sum w tau_m^2 + dwell_s tau_dwell^2) / T_duty) <= rated torque``, with
  ``tau_dwell = tau_l[-1] / (N eta)`` and ``T_duty = T_cycle + dwell_s``;
* ``motor_peak``: ``max |tau_m| <= peak torque`` and, where the catalogue gives the motor's
  torque-speed curve, every point under it (the value is the worst ``|tau_m| / curve(n)``, in
  percent of the curve);
* ``motor_speed``: ``max n <= min(motor max speed, reducer max input speed)``;
* ``reducer_peak``: ``max |tau_l| <= repeated peak torque``;
* the peaks (``motor_peak``, the curve, ``reducer_peak``) of the simulated torque are of the
  torque sustained over 5 ms, as sizing takes them (:data:`sim.analysis.sizing.PEAK_WINDOW_S`:
  a contact's one-step impulse is not a peak the drive must hold);
* ``reducer_life``: ``L10 = rated_life_h (T_rated / T_k)^k (n_rated / n_av) >= life target``
  with ``T_k = (sum w |n| |tau_l|^k / sum w |n|)^(1/k)``, ``k`` the reducer's ``life_exponent``
  (3 for strain-wave gears, 10/3 for RV reducers), and ``n_av = sum w |n| / T_duty`` (the
  dwell adds time, no revolutions);
* ``reducer_average_torque``, where the catalogue gives the reducer's limit for average torque
  (Harmonic Drive's selection procedure): ``T_av = T_3 <= average_torque_limit_nm``;
* ``reducer_average_speed``, where it gives the limit for average input speed:
  ``n_av <= max_average_input_speed_rpm``;
* ``estop_torque`` (warning): the motor's peak torque braking the load through the reducer,
  ``T_peak N / eta``, against the momentary peak torque (an emergency stop, a collision);
* ``inertia_ratio`` (error, or a warning where ``[sizing] inertia_ratio = "warning"``):
  ``(J_load / N^2 + J_in) / J_r`` against ``inertia_ratio_max``,
  ``J_load`` the joint's largest diagonal of the joint-space inertia matrix along the cycle
  (armature excluded, every 10 ms);
* ``braking_energy`` (information, no limit): the energy the motor gives back per cycle,
  ``sum w max(0, -tau_m N qd)``, J.

A pair passes when every ``error`` check passes. Passing pairs are ranked (``rank``: ``mass`` of
motor + reducer, ties broken by the smaller rotor inertia; ``inertia``: rotor inertia, then
mass; ``margin``: the largest smallest margin first); the first is chosen, the second is the
runner-up. A joint that no pair serves is reported with the pair that came closest.

Speed: ``tau_m`` is linear in ``p = (u, v, qdd)`` with ``u = tau_l`` where the motor drives (0
elsewhere) and ``v = tau_l`` where the load drives back, ``tau_m = c . p`` with
``c = (1 / (N eta), eta / N, (J_r + J_in) N)``. So the RMS is ``sqrt(c^T M c / T)`` from the
second moments ``M = sum w p p^T``, and the peak ``max |c . p|`` is reached at a vertex of the
convex hull of the points ``+-p`` (computed once per joint and source), whatever the pair.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.analysis.catalog import Catalog, Motor, Reducer, describe_entry
from sim.analysis.sizing import PEAK_WINDOW_S
from sim.analysis.statistics import sustained
from sim.core.files import write_atomic
from sim.robots.registry import COULOMB_SPEED, RPM_PER_RAD_S
from sim.simulation.runfolder import SELECTION_CSV, SELECTION_JSON, RunRecord

#: Ways to rank the passing pairs (``--rank``).
RANKS = ("mass", "inertia", "margin")
#: Default reducer life target, h.
DEFAULT_LIFE_H = 20000.0
#: Default load-to-rotor inertia ratio above which a pair gets a warning.
DEFAULT_INERTIA_RATIO_MAX = 10.0
#: Sampling of the joint-space inertia along the cycle, s.
INERTIA_SAMPLE_S = 0.01
#: Passing pairs listed per joint in the report (all of them are in selection.json).
REPORT_TOP = 10


@dataclass(frozen=True)
class SelectionOptions:
    """What the selection needs besides the run.

    Attributes:
        catalog: The motors and reducers to choose from.
        life_h: Reducer L10 life target, h.
        dwell_s: Standstill after each cycle, s (holding the last sample's torque).
        rank: How passing pairs are ranked (:data:`RANKS`).
        inertia_ratio_max: Largest load-to-rotor inertia ratio a pair may have.
        inertia_ratio: ``"error"``: a pair over ``inertia_ratio_max`` does not pass (the
            default: the servo of a drive far over it cannot be tuned stiff); ``"warning"``:
            it passes with a warning.
    """

    catalog: Catalog
    life_h: float = DEFAULT_LIFE_H
    dwell_s: float = 0.0
    rank: str = "mass"
    inertia_ratio_max: float = DEFAULT_INERTIA_RATIO_MAX
    inertia_ratio: str = "error"


@dataclass(frozen=True)
class PairCheck:
    """One check of a pair: ``value`` against ``limit`` (``unit``), from ``source``."""

    name: str
    value: float
    limit: float
    unit: str
    source: str
    severity: str = "error"
    at_least: bool = False  # the value must reach the limit (life) instead of staying below

    @property
    def margin_pct(self) -> float:
        if not math.isfinite(self.limit) or self.limit == 0:
            return math.inf
        if self.at_least:
            return math.inf if math.isinf(self.value) else (self.value - self.limit) / self.limit * 100
        return (self.limit - self.value) / self.limit * 100

    @property
    def passed(self) -> bool:
        return self.margin_pct >= -1e-9

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "value": _num(self.value), "limit": _num(self.limit),
                "unit": self.unit, "margin_pct": _num(self.margin_pct), "pass": self.passed,
                "severity": self.severity, "source": self.source}


@dataclass
class PairResult:
    """A motor x reducer pair on one joint, with its checks."""

    motor: Motor
    reducer: Reducer
    checks: list[PairCheck]

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks if c.severity == "error")

    @property
    def mass_kg(self) -> float:
        """Motor + reducer mass, kg (inf when the catalogue gives either's mass not)."""
        a, b = self.motor.spec.mass_kg, self.reducer.spec.mass_kg
        return math.inf if a is None or b is None else a + b

    @property
    def min_margin_pct(self) -> float:
        return min((c.margin_pct for c in self.checks if c.severity == "error"),
                   default=math.inf)

    @property
    def hardest(self) -> PairCheck:
        return min((c for c in self.checks if c.severity == "error"), key=lambda c: c.margin_pct)

    def to_dict(self) -> dict[str, Any]:
        return {"motor": self.motor.id, "reducer": self.reducer.id, "ratio": self.reducer.spec.ratio,
                "mass_kg": _num(self.mass_kg),
                "rotor_inertia_kg_m2": self.motor.spec.rotor_inertia_kg_m2,
                "illustrative": self.motor.illustrative or self.reducer.illustrative,
                "pass": self.passed, "hardest_check": self.hardest.name,
                "min_margin_pct": _num(self.min_margin_pct),
                "checks": [c.to_dict() for c in self.checks]}


@dataclass
class JointSelection:
    """The selection of one joint."""

    joint: str
    chosen: PairResult | None
    runner_up: PairResult | None
    passing: list[PairResult]
    closest: PairResult | None
    n_pairs: int

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "motor": self.chosen.motor.id if self.chosen else None,
            "reducer": self.chosen.reducer.id if self.chosen else None,
            "ratio": self.chosen.reducer.spec.ratio if self.chosen else None,
            "checks": [c.to_dict() for c in self.chosen.checks] if self.chosen else [],
            "runner_up": self.runner_up.to_dict() if self.runner_up else None,
            "pairs_checked": self.n_pairs,
            "pairs_passing": len(self.passing),
            "ranking": [{"motor": p.motor.id, "reducer": p.reducer.id, "mass_kg": _num(p.mass_kg),
                         "rotor_inertia_kg_m2": p.motor.spec.rotor_inertia_kg_m2,
                         "min_margin_pct": _num(p.min_margin_pct)} for p in self.passing],
        }
        if self.chosen is None:
            out["reason"] = self.reason
            out["closest"] = self.closest.to_dict() if self.closest else None
        return out

    @property
    def reason(self) -> str:
        if self.chosen is not None:
            return ""
        if self.closest is None:
            return "the catalogue has no motor or no reducer"
        h = self.closest.hardest
        return (f"no pair passes; the closest, {self.closest.motor.id} + "
                f"{self.closest.reducer.id}, fails {h.name} ({_fmt(h.value)} against "
                f"{_fmt(h.limit)}{'' if h.unit == '-' else ' ' + h.unit})")


@dataclass
class SelectionResult:
    """The selection of every joint of a run."""

    joints: list[JointSelection]
    options: SelectionOptions
    duty_s: float
    cycle_s: float

    @property
    def all_served(self) -> bool:
        return all(j.chosen is not None for j in self.joints)

    def to_dict(self) -> dict[str, Any]:
        cat = self.options.catalog
        return {
            "catalog": list(cat.sources),
            "illustrative_entries": sorted(e.id for e in (*cat.motors, *cat.reducers)
                                           if e.illustrative),
            "life_h": self.options.life_h, "dwell_s": self.options.dwell_s,
            "rank": self.options.rank, "inertia_ratio_max": self.options.inertia_ratio_max,
            "cycle_s": self.cycle_s, "duty_cycle_s": self.duty_s,
            "all_joints_served": self.all_served,
            "joints": {j.joint: j.to_dict() for j in self.joints},
        }


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _fmt(x: float) -> str:
    return "inf" if not math.isfinite(x) else f"{x:.4g}"


# --------------------------------------------------------------------------------------------
# Per joint and torque source: what every pair's checks are computed from
# --------------------------------------------------------------------------------------------


@dataclass
class _Source:
    """One torque source of one joint, reduced to what the checks need."""

    name: str
    w: NDArray[np.float64]        # trapezoid weights, s
    p: NDArray[np.float64]        # (N, 3): u, v, qdd
    p_peak: NDArray[np.float64]   # p sustained over the source's peak window (sizing's)
    qd: NDArray[np.float64]       # joint speed, rad/s
    tau_l: NDArray[np.float64]    # load torque, N m
    moments: NDArray[np.float64]  # sum w p p^T, (3, 3)
    hull: NDArray[np.float64]     # points +-p (and the dwell point) spanning the peak, (K, 3)
    tau_l_last: float
    qd_max: float
    tau_l_max: float
    s1: float                     # sum w |qd|
    s3: float                     # sum w |qd| |tau_l|^3

    def average_torque(self, exponent: float) -> float:
        """The speed-weighted average load torque ``(sum w |qd| |tau_l|^k / sum w |qd|)^(1/k)``
        of the reducer makers' procedures (``k`` their life exponent), N m; 0 at rest."""
        if self.s1 <= 0:
            return 0.0
        sk = self.s3 if exponent == 3.0 else float(
            self.w @ (np.abs(self.qd) * np.abs(self.tau_l) ** exponent))
        return (sk / self.s1) ** (1.0 / exponent) if sk > 0 else 0.0


def _weights(t: NDArray[np.float64]) -> NDArray[np.float64]:
    dt = np.diff(t)
    w = np.zeros(t.size)
    w[:-1] += dt / 2.0
    w[1:] += dt / 2.0
    return w


def _hull_points(p: NDArray[np.float64]) -> NDArray[np.float64]:
    """Points of ``+-p`` among which ``max |c . p|`` is reached for every ``c``: the vertices of
    their convex hull, computed in the subspace the points span (a joint that never brakes,
    or never accelerates, gives a flat set)."""
    from scipy.spatial import ConvexHull, QhullError

    pts = np.vstack([p, -p])
    vals, vecs = np.linalg.eigh(pts.T @ pts)
    basis = vecs[:, vals > 1e-12 * max(float(vals.max()), 1e-300)]
    if basis.shape[1] == 0:
        return pts[:1]
    proj = pts @ basis
    if basis.shape[1] == 1:
        return pts[[int(np.argmin(proj[:, 0])), int(np.argmax(proj[:, 0]))]]
    try:
        return pts[ConvexHull(proj).vertices]
    except QhullError:  # nearly flat within the basis: every point (rare and exact)
        return pts


def _source(name: str, t: NDArray[np.float64], tau: NDArray[np.float64],
            qd: NDArray[np.float64], qdd: NDArray[np.float64], armature: float,
            window: float = 0.0) -> _Source:
    """A source; its peaks (motor and reducer peak torque, the torque-speed curve) of the
    signals sustained over ``window`` s, as sizing takes them (the simulated source's:
    :data:`sim.analysis.sizing.PEAK_WINDOW_S`)."""
    w = _weights(t)
    tau_l = tau - armature * qdd
    drives = (tau_l * qd >= 0.0) | (np.abs(qd) < COULOMB_SPEED)
    p = np.column_stack([np.where(drives, tau_l, 0.0), np.where(drives, 0.0, tau_l), qdd])
    moments = (p * w[:, None]).T @ p
    p_peak = sustained(t, p, window)  # linear in p: the sustained motor torque is p_peak @ c
    hull = _hull_points(np.vstack([p_peak, [[tau_l[-1], 0.0, 0.0]]]))
    aqd = np.abs(qd)
    return _Source(name, w, p, p_peak, qd, tau_l, moments, hull, float(tau_l[-1]),
                   float(np.max(aqd)), float(np.max(np.abs(p_peak[:, 0] + p_peak[:, 1]))),
                   float(w @ aqd), float(w @ (aqd * np.abs(tau_l) ** 3)))


def _coeffs(motor: Motor, reducer: Reducer) -> NDArray[np.float64]:
    r = reducer.spec
    return np.array([1.0 / (r.ratio * r.efficiency), r.efficiency / r.ratio,
                     (motor.spec.rotor_inertia_kg_m2 + r.input_inertia_kg_m2) * r.ratio])


def motor_torque(src: _Source, motor: Motor, reducer: Reducer) -> NDArray[np.float64]:
    """The motor torque at every sample of the cycle, N m (module docstring)."""
    return src.p @ _coeffs(motor, reducer)


# --------------------------------------------------------------------------------------------
# Checks of one pair
# --------------------------------------------------------------------------------------------


def _pair_values(src: _Source, motor: Motor, reducer: Reducer, opts: SelectionOptions,
                 cycle_s: float) -> dict[str, float]:
    r = reducer.spec
    c = _coeffs(motor, reducer)
    duty = cycle_s + opts.dwell_s
    tau_dwell = src.tau_l_last / (r.ratio * r.efficiency)
    rms = math.sqrt(max(0.0, (c @ src.moments @ c + opts.dwell_s * tau_dwell**2) / duty))
    peak = float(np.max(np.abs(src.hull @ c)))
    speed = src.qd_max * r.ratio * RPM_PER_RAD_S
    n_av = r.ratio * RPM_PER_RAD_S * src.s1 / duty
    t_life = src.average_torque(r.life_exponent)
    if n_av > 0 and t_life > 0:
        life = r.rated_life_h * (r.rated_torque_nm / t_life) ** r.life_exponent * (
            r.rated_input_speed_rpm / n_av)
    else:
        life = math.inf
    return {"rms": rms, "peak": peak, "speed": speed, "life": life, "tau_l_max": src.tau_l_max,
            "t_av": src.average_torque(3.0), "n_av": n_av}


def _curve_pct(src: _Source, motor: Motor, reducer: Reducer) -> float:
    """The worst ``|tau_m| / curve(n)`` over the cycle, percent (the dwell at speed 0 too)."""
    r = reducer.spec
    tau_m = np.abs(np.append(src.p_peak @ _coeffs(motor, reducer),
                             src.tau_l_last / (r.ratio * r.efficiency)))
    avail = motor.peak_torque_at(np.append(np.abs(src.qd) * r.ratio * RPM_PER_RAD_S, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(avail > 0, tau_m / avail, np.where(tau_m > 0, np.inf, 0.0))
    return float(np.max(ratio) * 100.0)


def check_pair(sources: Sequence[_Source], motor: Motor, reducer: Reducer,
               opts: SelectionOptions, cycle_s: float, j_load: float,
               with_energy: bool = False) -> PairResult:
    """Every check of one pair on one joint, each on the worse torque source."""
    r, m = reducer.spec, motor.spec
    vals = [(s.name, _pair_values(s, motor, reducer, opts, cycle_s)) for s in sources]

    def worst(key: str, low: bool = False) -> tuple[float, str]:
        pick = (min if low else max)(vals, key=lambda v: v[1][key])
        return pick[1][key], pick[0]

    checks = []
    rms, s_rms = worst("rms")
    checks.append(PairCheck("motor_rms", rms, m.rated_torque_nm, "N m", s_rms))
    peak, s_peak = worst("peak")
    checks.append(PairCheck("motor_peak", peak, m.peak_torque_nm, "N m", s_peak))
    speed, s_speed = worst("speed")
    checks.append(PairCheck("motor_speed", speed, min(m.max_speed_rpm, r.max_input_speed_rpm),
                            "rpm", s_speed))
    tl, s_tl = worst("tau_l_max")
    checks.append(PairCheck("reducer_peak", tl, r.repeated_peak_torque_nm, "N m", s_tl))
    life, s_life = worst("life", low=True)
    checks.append(PairCheck("reducer_life", life, opts.life_h, "h", s_life, at_least=True))
    if r.average_torque_limit_nm is not None:
        t_av, s_av = worst("t_av")
        checks.append(PairCheck("reducer_average_torque", t_av, r.average_torque_limit_nm,
                                "N m", s_av))
    if r.max_average_input_speed_rpm is not None:
        n_av, s_nav = worst("n_av")
        checks.append(PairCheck("reducer_average_speed", n_av, r.max_average_input_speed_rpm,
                                "rpm", s_nav))
    # the torque-speed curve (an O(samples) check) decides only between otherwise passing pairs
    if m.torque_speed is not None and all(c.passed for c in checks):
        pct, s_pct = max((_curve_pct(s, motor, reducer), s.name) for s in sources)
        checks.append(PairCheck("motor_curve", pct, 100.0, "% of the torque-speed curve",
                                s_pct))
    checks.append(PairCheck("estop_torque", m.peak_torque_nm * r.ratio / r.efficiency,
                            r.momentary_peak_torque_nm, "N m", "catalogue", "warning"))
    ratio = (j_load / r.ratio**2 + r.input_inertia_kg_m2) / m.rotor_inertia_kg_m2
    checks.append(PairCheck("inertia_ratio", ratio, opts.inertia_ratio_max, "-", "model",
                            opts.inertia_ratio))
    if with_energy:
        energy = max(_braking_energy(s, motor, reducer) for s in sources)
        checks.append(PairCheck("braking_energy", energy, math.inf, "J per cycle", "worst",
                                "info"))
    return PairResult(motor, reducer, checks)


def _braking_energy(src: _Source, motor: Motor, reducer: Reducer) -> float:
    power = motor_torque(src, motor, reducer) * src.qd * reducer.spec.ratio
    return float(src.w @ np.maximum(0.0, -power))


def _rank_key(rank: str):
    if rank == "inertia":
        return lambda p: (p.motor.spec.rotor_inertia_kg_m2, p.mass_kg, p.motor.id, p.reducer.id)
    if rank == "margin":
        return lambda p: (-p.min_margin_pct, p.mass_kg, p.motor.id, p.reducer.id)
    return lambda p: (p.mass_kg, p.motor.spec.rotor_inertia_kg_m2, p.motor.id, p.reducer.id)


# --------------------------------------------------------------------------------------------
# The selection
# --------------------------------------------------------------------------------------------


def joint_load_inertia(record: RunRecord, joint_ids: Sequence[int]) -> NDArray[np.float64]:
    """Each joint's largest joint-space inertia along the cycle, armature excluded, kg m^2."""
    import mujoco

    model = record.load_model()
    data = mujoco.MjData(model)
    t = record.t
    qpos = record.get("qpos")
    step = max(1, int(round(INERTIA_SAMPLE_S / max(float(np.median(np.diff(t))), 1e-9))))
    dofs = [int(model.jnt_dofadr[j]) for j in joint_ids]
    full = np.zeros((model.nv, model.nv))
    best = np.zeros(len(dofs))
    for i in range(0, t.size, step):
        data.qpos[:] = qpos[i]
        mujoco.mj_forward(model, data)
        mujoco.mj_fullM(model, data, full)
        diag = full[dofs, dofs] - model.dof_armature[dofs]
        best = np.maximum(best, diag)
    return best


def select_actuators(record: RunRecord, joint_ids: Sequence[int], armature: Sequence[float],
                     options: SelectionOptions) -> SelectionResult:
    """Choose a motor and a reducer for every joint of a run (module docstring).

    Args:
        record: The run (``t``, ``tau``, ``qd``, ``qdd``, ``tau_id``, ``qd_ref``, ``qdd_ref``,
            ``qpos`` and the model).
        joint_ids: The robot joints' ids in the run's model, in order.
        armature: The model's armature per joint (the drive inertia already in ``tau``), kg m^2.
        options: Catalogue, life target, dwell, ranking, inertia-ratio limit.
    """
    t = record.t
    cycle = float(t[-1] - t[0])
    j_load = joint_load_inertia(record, joint_ids)
    qdd_sim = record.get("qdd")
    out = []
    for k, joint in enumerate(record.joints):
        sources = [
            _source("id", t, record.get("tau_id")[:, k], record.get("qd_ref")[:, k],
                    record.get("qdd_ref")[:, k], float(armature[k])),
            _source("sim", t, record.get("tau")[:, k], record.get("qd")[:, k],
                    qdd_sim[:, k], float(armature[k]), PEAK_WINDOW_S),
        ]
        pairs = [check_pair(sources, m, r, options, cycle, float(j_load[k]))
                 for m in options.catalog.motors for r in options.catalog.reducers]
        passing = sorted((p for p in pairs if p.passed), key=_rank_key(options.rank))
        closest = max(pairs, key=lambda p: p.min_margin_pct) if pairs else None

        def full(p: PairResult | None) -> PairResult | None:
            return None if p is None else check_pair(sources, p.motor, p.reducer, options,
                                                     cycle, float(j_load[k]), with_energy=True)

        chosen = full(passing[0]) if passing else None
        runner = full(passing[1]) if len(passing) > 1 else None
        out.append(JointSelection(joint, chosen, runner, passing,
                                  None if passing else full(closest), len(pairs)))
    return SelectionResult(out, options, cycle + options.dwell_s, cycle)


# --------------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------------

_CSV_CHECKS = ("motor_rms", "motor_peak", "motor_speed", "reducer_peak", "reducer_life",
               "reducer_average_torque", "reducer_average_speed", "estop_torque",
               "inertia_ratio")


def selection_csv(result: SelectionResult) -> str:
    """One row per joint and passing pair, in rank order (rank 1 is the choice); a joint that
    no pair serves has one row with rank 0 and its closest pair."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    head = ["joint", "rank", "motor", "reducer", "mass_kg", "pass"]
    for c in _CSV_CHECKS:
        head += [f"{c}_value", f"{c}_limit", f"{c}_margin_pct"]
    w.writerow(head)
    for j in result.joints:
        rows = [(i + 1, p) for i, p in enumerate(j.passing)] or (
            [(0, j.closest)] if j.closest else [])
        for rank, p in rows:
            by = {c.name: c for c in p.checks}
            row = [j.joint, rank, p.motor.id, p.reducer.id, _csvnum(p.mass_kg), p.passed]
            for name in _CSV_CHECKS:
                c = by.get(name)  # the reducer's average limits only where it gives them
                row += ["", "", ""] if c is None else [
                    _csvnum(c.value), _csvnum(c.limit), _csvnum(c.margin_pct)]
            w.writerow(row)
    return buf.getvalue()


def _csvnum(x: float) -> str:
    return "" if not math.isfinite(x) else f"{x:.6g}"


def write_selection(folder: str | Path, result: SelectionResult) -> dict[str, Path]:
    """Write ``selection.json`` and ``selection.csv`` into a run folder."""
    folder = Path(folder)
    return {
        "json": write_atomic(folder / SELECTION_JSON,
                             json.dumps(result.to_dict(), indent=1, allow_nan=False) + "\n"),
        "csv": write_atomic(folder / SELECTION_CSV, selection_csv(result)),
    }


def selection_lines(result: SelectionResult) -> list[str]:
    """One line per joint for the terminal."""
    out = []
    for j in result.joints:
        if j.chosen is None:
            out.append(f"{j.joint}: NO PAIR of {j.n_pairs}: {j.reason}")
            continue
        h = j.chosen.hardest
        out.append(f"{j.joint}: {describe_entry(j.chosen.motor)} + "
                   f"{describe_entry(j.chosen.reducer)}, {_fmt(j.chosen.mass_kg)} kg, hardest "
                   f"{h.name} {h.margin_pct:.0f} % margin ({len(j.passing)} of {j.n_pairs} "
                   "pairs pass)")
    return out

