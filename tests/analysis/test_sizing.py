"""Tests of sim.analysis.sizing: every statistic is recomputed independently (closed forms, scipy
quadrature of the analytic signal, hand formulas), never echoed from the code under test."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate, optimize
from support.window_oracle import window_mean

from sim.analysis.sizing import (
    PEAK_KNEE_FRACTION,
    PEAK_WINDOW_S,
    armature_from_model,
    continuous_envelope,
    forcerange_from_model,
    load_trajectory,
    motor_speed_rpm,
    motor_torque,
    peak_abs,
    rms,
    signal_stats,
    size_run,
    size_trajectory,
    sustained,
    time_integral,
)
from sim.errors import CellsimError, ScenarioError, UnknownNameError
from sim.robots.drives import apply_overrides
from sim.robots.registry import ROBOTS, Drive

DRIVE = Drive(gear_ratio=100.0, efficiency=0.9, rotor_inertia=1e-4, rated_torque=1.0,
              peak_torque=3.0, max_speed_rpm=4000.0)


def nonuniform_grid(t0: float, t1: float, n: int, seed: int = 0) -> np.ndarray:
    """Sorted random times with both ends included (spacing varies by a factor ~100)."""
    rng = np.random.default_rng(seed)
    inner = np.sort(rng.uniform(t0, t1, n - 2))
    return np.concatenate([[t0], inner, [t1]])


def trajectory(t: np.ndarray, tau_id: np.ndarray, qd_ref: np.ndarray, qdd_ref: np.ndarray,
               tau: np.ndarray | None = None, qd: np.ndarray | None = None,
               qdd: np.ndarray | None = None) -> dict[str, np.ndarray]:
    tau = tau_id if tau is None else tau
    qd = qd_ref if qd is None else qd
    traj = dict(t=t, q_ref=np.zeros_like(tau_id), qd_ref=qd_ref, qdd_ref=qdd_ref,
                q=np.zeros_like(tau_id), qd=qd, tau=tau, tau_id=tau_id)
    traj["qdd"] = qdd_ref if qdd is None else qdd
    return traj


# ---------------------------------------------------------------------------------------------
# RMS, peaks, energy: closed forms and quadrature
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("periods", [1, 3])
def test_rms_of_sine_over_whole_periods_is_amplitude_over_sqrt2(periods: int) -> None:
    # Closed form: RMS of A sin(w t) over whole periods = A / sqrt(2).
    A, T = 7.5, 0.8
    t = nonuniform_grid(0.0, periods * T, 20000, seed=periods)
    x = A * np.sin(2 * np.pi * t / T)
    assert rms(t, x) == pytest.approx(A / math.sqrt(2), rel=1e-5)


def test_rms_is_time_weighted_not_a_plain_mean() -> None:
    # Samples crowded where |x| is large: a plain mean of samples is badly biased, the
    # time-weighted RMS still gives the closed form A / sqrt(2).
    A, T = 2.0, 1.0
    dense = np.linspace(0.2, 0.3, 20000)  # around the crest at t = T/4
    t = np.unique(np.concatenate([np.linspace(0, T, 2001), dense]))
    x = A * np.sin(2 * np.pi * t / T)
    plain = math.sqrt(np.mean(x**2))
    assert abs(plain - A / math.sqrt(2)) > 0.3  # the naive estimate is far off
    assert rms(t, x) == pytest.approx(A / math.sqrt(2), rel=1e-5)


def test_stats_match_scipy_quadrature_of_the_analytic_signal() -> None:
    # A non-periodic torque and speed, integrated independently with scipy.integrate.quad on
    # the analytic functions (not on the samples).
    def tau(t):
        return 12.0 * np.sin(3.1 * t) + 4.0 * np.cos(7.3 * t) + 1.5 * t

    def qd(t):
        return 0.8 * np.cos(2.2 * t) - 0.3 * t

    def qdd(t):
        return -0.8 * 2.2 * np.sin(2.2 * t) - 0.3

    t0, t1 = 0.0, 2.7
    t = nonuniform_grid(t0, t1, 30000, seed=3)
    T = t1 - t0
    s = signal_stats(t, tau(t), qd(t), qdd(t))
    quad = lambda f: integrate.quad(f, t0, t1, limit=400)[0]  # noqa: E731
    p = lambda x: tau(x) * qd(x)  # noqa: E731
    assert s.rms_torque == pytest.approx(math.sqrt(quad(lambda x: tau(x) ** 2) / T), rel=1e-5)
    assert s.energy == pytest.approx(quad(lambda x: abs(p(x))), rel=1e-4)
    assert s.net_energy == pytest.approx(quad(p), rel=1e-4, abs=1e-6)
    assert s.mean_abs_power == pytest.approx(quad(lambda x: abs(p(x))) / T, rel=1e-4)
    assert s.mean_power == pytest.approx(quad(p) / T, rel=1e-4, abs=1e-6)
    # Peaks: the continuous maximum found by a bounded optimizer on a fine bracket.
    for fn, value, when in ((tau, s.peak_torque, s.peak_torque_time),
                            (qd, s.peak_speed, s.peak_speed_time),
                            (p, s.peak_power, s.peak_power_time)):
        grid = np.linspace(t0, t1, 2001)
        k = int(np.argmax(np.abs(fn(grid))))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        res = optimize.minimize_scalar(lambda x: -abs(fn(x)), bounds=(lo, hi), method="bounded",
                                       options={"xatol": 1e-10})
        assert value == pytest.approx(-res.fun, rel=1e-4)
        assert when == pytest.approx(res.x, abs=2e-3)


def test_energy_of_known_power_profiles() -> None:
    A, B, T = 5.0, 2.0, 0.5  # torque N m, speed rad/s, period s
    t = nonuniform_grid(0.0, 2 * T, 40000, seed=5)
    w = 2 * np.pi / T
    # In phase: P = A B sin^2 >= 0, energy over the cycle = A B (2T) / 2, all of it net.
    s = signal_stats(t, A * np.sin(w * t), B * np.sin(w * t), np.zeros_like(t))
    assert s.energy == pytest.approx(A * B * T, rel=1e-5)
    assert s.net_energy == pytest.approx(A * B * T, rel=1e-5)
    assert s.peak_power == pytest.approx(A * B, rel=1e-6)
    # Quadrature: P = A B/2 sin(2 w t); int |P| = (A B / 2) (2T) (2/pi), net 0 (all regenerated).
    s = signal_stats(t, A * np.sin(w * t), B * np.cos(w * t), np.zeros_like(t))
    assert s.energy == pytest.approx(A * B * 2 * T / np.pi, rel=1e-5)
    assert abs(s.net_energy) < 1e-5 * s.energy
    assert s.mean_abs_power == pytest.approx(A * B / np.pi, rel=1e-5)
    assert s.peak_power == pytest.approx(A * B / 2, rel=1e-6)
    # Constant torque and speed: mean power = tau v, energy = tau v T.
    s = signal_stats(t, np.full_like(t, -3.0), np.full_like(t, 0.4), np.zeros_like(t))
    assert s.energy == pytest.approx(3.0 * 0.4 * 2 * T)
    assert s.net_energy == pytest.approx(-3.0 * 0.4 * 2 * T)
    assert s.mean_power == pytest.approx(-1.2)
    assert s.mean_abs_power == pytest.approx(1.2)


def test_peak_reports_value_and_time_of_signed_extreme() -> None:
    t = np.array([0.0, 0.1, 0.25, 0.5, 1.0])
    x = np.array([1.0, -4.0, 3.9, 2.0, 0.0])
    assert peak_abs(t, x) == (4.0, 0.1)
    s = signal_stats(t, x, np.ones_like(t), np.zeros_like(t))
    assert (s.max_torque, s.min_torque) == (3.9, -4.0)


def test_time_integral_trapezoid_by_hand() -> None:
    # Trapezoids by hand: (0.1)(1+3)/2 + (0.4)(3+1)/2 = 0.2 + 0.8
    assert time_integral([0.0, 0.1, 0.5], [1.0, 3.0, 1.0]) == pytest.approx(1.0)


@pytest.mark.parametrize("bad", [[0.0], [0.0, 0.0, 1.0], [0.0, np.nan], [[0.0, 1.0]]])
def test_bad_time_vector_is_a_one_line_error(bad) -> None:
    with pytest.raises(CellsimError):
        rms(bad, np.zeros(np.size(bad)))


# ---------------------------------------------------------------------------------------------
# Motor side
# ---------------------------------------------------------------------------------------------

def test_motor_torque_constant_acceleration_hand_formula() -> None:
    # Constant acceleration a from rest: qd = a t >= 0, link inertia I, gravity torque g_t.
    # The model torque includes the armature (reflected rotor inertia J_r N^2) like MuJoCo's.
    N, eta, J_r = 100.0, 0.9, 1e-4
    drive = Drive(N, eta, J_r, 1.0, 3.0, 4000.0)
    I, a, g_t = 2.0, 3.0, 10.0
    arm = J_r * N**2  # 1.0 kg m^2
    t = np.linspace(0.0, 1.0, 11)
    tau_joint = np.full_like(t, (I + arm) * a + g_t)  # 19 N m
    tm = motor_torque(tau_joint, a * t, np.full_like(t, a), drive, armature=arm)
    # Motoring: (I a + g_t) / (N eta) + J_r N a = 16/90 + 0.03
    assert tm == pytest.approx(np.full_like(t, 16.0 / 90.0 + 0.03), rel=1e-12)
    # Braking while moving forward (a < 0, qd > 0, no gravity): power flows back,
    # motor torque = (I a) eta / N + J_r N a = -6 * 0.9/100 - 0.03 = -0.084
    tm = motor_torque(np.full_like(t, (I + arm) * -a), np.full_like(t, 1.0), np.full_like(t, -a),
                      drive, armature=arm)
    assert tm == pytest.approx(np.full_like(t, -0.084), rel=1e-12)
    # Standstill holding the gravity torque: the motoring (larger) form, also while the held
    # joint's speed wobbles about zero inside the friction law's 1e-3 rad/s zone (the gear's
    # direction does not flip from sample to sample); out of it, lowering, the load drives.
    tm = motor_torque(np.array([g_t]), np.array([0.0]), np.array([0.0]), drive, armature=arm)
    assert tm[0] == pytest.approx(g_t / (N * eta))
    wobble = np.array([1e-4, -3e-4, 9.9e-4, -9.9e-4])
    tm = motor_torque(np.full(4, g_t), wobble, np.zeros(4), drive)
    assert tm == pytest.approx(np.full(4, g_t / (N * eta)), rel=1e-12)
    tm = motor_torque(np.array([g_t]), np.array([-1.5e-3]), np.zeros(1), drive)
    assert tm[0] == pytest.approx(g_t * eta / N)


def test_motor_power_balance_through_the_gearbox() -> None:
    # Physics, not the formula's sign rule: without rotor inertia the gearbox only loses power,
    # and it loses (1 - eta) of what flows into it, from whichever side that is. With the
    # motor's power into the gear P_m = tau_m N qd and the power the gear gives the load
    # P_l = tau qd, the loss P_m - P_l is >= 0 and equals (1 - eta) max(P_m, -P_l) (the motor
    # supplies P_m > 0, or the load supplies -P_l > 0). A gear that gained power, or lost it
    # on the wrong side, fails this.
    rng = np.random.default_rng(1)
    tau = rng.normal(0, 50, 500)
    qd = rng.normal(0, 2, 500)
    moving = np.abs(qd) >= 1e-3  # out of the standstill zone (covered in the test above)
    tau, qd = tau[moving], qd[moving]
    eta = 0.75
    drive = Drive(80.0, eta, 0.0, 1.0, 3.0, 5000.0)
    tm = motor_torque(tau, qd, np.zeros(qd.size), drive)
    p_motor = tm * qd * 80.0
    p_load = tau * qd
    loss = p_motor - p_load
    assert np.all(loss >= -1e-12 * np.abs(p_load))
    assert loss == pytest.approx((1 - eta) * np.maximum(p_motor, -p_load), rel=1e-12, abs=1e-12)
    # both directions of power flow occur in the sample, so both sides were exercised
    assert np.any(p_load > 0) and np.any(p_load < 0)


def test_motor_speed_in_rpm() -> None:
    # 1 rad/s at the joint through 100:1 = 100 rad/s = 100 * 60 / (2 pi) rpm.
    assert motor_speed_rpm(np.array([1.0, -0.5]), DRIVE) == pytest.approx(
        [6000 / (2 * np.pi), -3000 / (2 * np.pi)])


def test_envelopes_shape() -> None:
    from sim.analysis.sizing import peak_envelope

    n_max, n_k = DRIVE.max_speed_rpm, PEAK_KNEE_FRACTION * DRIVE.max_speed_rpm
    env = peak_envelope(DRIVE, [0.0, n_k, (n_k + n_max) / 2, n_max, -n_max, 1.01 * n_max])
    assert env == pytest.approx([3.0, 3.0, 2.0, 1.0, 1.0, 0.0])
    assert continuous_envelope(DRIVE, [0.0, n_max, 1.5 * n_max]) == pytest.approx([1.0, 1.0, 0.0])


# ---------------------------------------------------------------------------------------------
# Checks, margins and the verdict
# ---------------------------------------------------------------------------------------------

def _three_joint_case(peaks=(80.0, 120.0, 40.0), drives=None, **kw):
    t = np.linspace(0.0, 1.0, 1001)
    shape = np.sin(2 * np.pi * t)  # peak +1 at t = 0.25, -1 at t = 0.75
    tau = np.stack([p * shape for p in peaks], axis=1)
    qd = np.full_like(tau, 0.5)
    traj = trajectory(t, tau, qd, np.zeros_like(tau))
    return size_trajectory(traj, ["j1", "j2", "j3"], drives=drives, **kw)


def test_margins_pass_fail_and_hardest_joint() -> None:
    res = _three_joint_case(forcerange=[[-100, 100]] * 3, speed_limits=[1.0, 1.0, 1.0])
    j1, j2, j3 = res.joints
    # (limit - used) / limit * 100 by hand
    assert j1.check("joint_torque").margin_pct == pytest.approx(20.0, rel=1e-9)
    assert j2.check("joint_torque").margin_pct == pytest.approx(-20.0, rel=1e-9)
    assert j3.check("joint_torque").margin_pct == pytest.approx(60.0, rel=1e-9)
    assert j1.check("joint_speed").margin_pct == pytest.approx(50.0)
    assert (j1.passed, j2.passed, j3.passed) == (True, False, True)
    assert not res.passed
    assert res.hardest.joint == "j2"
    assert "FAIL" in res.verdict and "j2" in res.verdict and "-20.0%" in res.verdict


def test_verdict_pass_names_hardest_joint_and_margin() -> None:
    res = _three_joint_case(peaks=(80.0, 90.0, 40.0), forcerange=[[-100, 100]] * 3)
    assert res.passed
    assert res.hardest.joint == "j2"
    assert res.verdict.startswith("PASS")
    assert "j2" in res.verdict and "10.0%" in res.verdict


def test_asymmetric_force_range_checked_sign_by_sign() -> None:
    # Torque swings +-60: positive side 60/100 (40 %), negative side 60/50 (-20 %).
    res = _three_joint_case(peaks=(60.0, 60.0, 60.0), forcerange=[[-50, 100]] * 3)
    c = res.joints[0].check("joint_torque")
    assert c.margin_pct == pytest.approx(-20.0, rel=1e-9)
    assert c.limit == 50.0 and c.used == pytest.approx(60.0)
    assert c.time == pytest.approx(0.75)


def test_motor_checks_on_constructed_case() -> None:
    # Joint 1 torque 60 sin at qd = 0.5 rad/s through 100:1, eta 1, no rotor inertia:
    # motor peak 0.6 N m, RMS 0.6/sqrt2, speed 0.5*100*60/2pi rpm.
    drive = Drive(100.0, 1.0, 0.0, 0.4, 0.5, 1000.0)
    res = _three_joint_case(peaks=(60.0, 30.0, 30.0), drives=[drive] * 3)
    j1 = res.joints[0]
    assert j1.check("motor_peak_torque").margin_pct == pytest.approx((0.5 - 0.6) / 0.5 * 100, rel=1e-6)
    rms_m = 0.6 / math.sqrt(2)
    assert j1.check("motor_rms_torque").margin_pct == pytest.approx((0.4 - rms_m) / 0.4 * 100, rel=1e-4)
    n = 0.5 * 100 * 60 / (2 * np.pi)
    assert j1.check("motor_speed").margin_pct == pytest.approx((1000 - n) / 1000 * 100)
    assert not j1.passed and res.joints[1].passed
    assert res.hardest.joint == "j1"
    assert res.hardest.limiting.key == "motor_peak_torque"


def test_envelope_check_catches_high_speed_point_below_peak_torque() -> None:
    # 2.5 N m < 3 N m peak, but at 3700 rpm the voltage-limited curve gives only
    # 3 - 2 * (3700 - 2800) / 1200 = 1.5 N m.
    # The torque is a short burst (5 % of the cycle) so that the RMS stays below rated.
    drive = DRIVE
    qd_j = 3700 / (drive.gear_ratio * 60 / (2 * np.pi))
    t = np.linspace(0, 1, 101)
    tau_joint = np.zeros((101, 1))
    tau_joint[40:46] = 2.5 * drive.gear_ratio * drive.efficiency
    traj = trajectory(t, tau_joint, np.full((101, 1), qd_j), np.zeros((101, 1)))
    res = size_trajectory(traj, ["j1"], drives=[drive])
    j = res.joints[0]
    assert j.check("motor_peak_torque").passed
    env = 3.0 - 2.0 * (3700 - 0.7 * 4000) / (0.3 * 4000)
    assert j.check("motor_envelope").margin_pct == pytest.approx((1 - 2.5 / env) * 100, rel=1e-9)
    assert not j.passed and j.limiting.key == "motor_envelope"


def test_worst_basis_takes_the_worse_source_and_single_bases_do_not() -> None:
    t = np.linspace(0, 1, 501)
    tau_id = (50 * np.sin(2 * np.pi * t))[:, None]
    tau_sim = 1.3 * tau_id
    traj = trajectory(t, tau_id, np.ones_like(tau_id), np.zeros_like(tau_id), tau=tau_sim)
    kw = dict(forcerange=[[-100, 100]])
    worst = size_trajectory(traj, ["j1"], **kw).joints[0].check("joint_torque")
    only_id = size_trajectory(traj, ["j1"], basis="id", **kw).joints[0].check("joint_torque")
    # the simulated peak is sustained over 5 ms: a 1 Hz sine's mean over w about its crest is
    # sin(pi w) / (pi w) of it (to the samples' linear interpolation, 2e-5 of it here)
    w = np.pi * PEAK_WINDOW_S
    assert worst.source == "sim"
    assert worst.margin_pct == pytest.approx(100 - 65 * np.sin(w) / w, abs=0.003)
    assert (only_id.source, only_id.margin_pct) == ("id", pytest.approx(50.0))
    with pytest.raises(UnknownNameError, match="worst"):
        size_trajectory(traj, ["j1"], basis="best")


def test_saturation_flagged_when_simulated_torque_hits_force_range() -> None:
    t = np.linspace(0, 1, 501)
    tau_id = (150 * np.sin(2 * np.pi * t))[:, None]
    tau_sim = np.clip(tau_id, -100, 100)
    traj = trajectory(t, tau_id, np.ones_like(tau_id), np.zeros_like(tau_id), tau=tau_sim)
    res = size_trajectory(traj, ["j1"], forcerange=[[-100, 100]])
    assert res.joints[0].saturated and "clipped" in res.verdict
    assert res.joints[0].check("joint_torque").source == "id"  # the demand, not the clipped torque


@settings(max_examples=60, deadline=None, database=None)
@given(st.lists(st.floats(1e-4, 1e-2), min_size=1, max_size=60),
       st.lists(st.floats(-100.0, 100.0), min_size=61, max_size=61),
       st.one_of(st.just(0.0), st.floats(1e-4, 0.05)))
def test_sustained_is_the_windowed_mean_of_the_linear_interpolant(steps, values, window) -> None:
    """sustained() equals window_oracle's mean (the exact integral written another way) on
    generated non-uniform records, to 1e-9 of the signal's scale; a constant stays itself and
    the window never raises a peak."""
    t = np.concatenate([[0.0], np.cumsum(steps)])
    x = np.asarray(values[: t.size])
    got = sustained(t, x, window)
    want = x if window == 0.0 else window_mean(t, x, window)
    assert np.abs(got - want).max() <= 1e-9 * (1.0 + np.abs(x).max())
    assert np.abs(got).max() <= np.abs(x).max() + 1e-9
    np.testing.assert_allclose(sustained(t, np.full_like(t, 3.5), window), 3.5, rtol=1e-9)


def test_simulated_acceleration_from_speed_when_npz_has_none() -> None:
    # qd = sin(w t) -> qdd = w cos(w t): peak |qdd| = w, by second-order differences.
    w = 2 * np.pi
    t = nonuniform_grid(0.0, 1.0, 4000, seed=9)
    qd = np.sin(w * t)[:, None]
    traj = trajectory(t, np.zeros_like(qd), qd, w * np.cos(w * t)[:, None])
    del traj["qdd"]
    res = size_trajectory(traj, ["j1"])
    assert res.joints[0].stats["sim"].peak_accel == pytest.approx(w, rel=1e-3)


def test_no_limits_at_all_gives_not_applicable() -> None:
    res = _three_joint_case()
    assert res.passed and res.hardest is None
    assert "No limits" in res.verdict
    d = res.to_dict()
    json.dumps(d, allow_nan=False)  # NaN/inf became null
    assert d["joints"][0]["margin_pct"] is None


# ---------------------------------------------------------------------------------------------
# Drive overrides
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_apply_overrides_for_every_robot(robot: str) -> None:
    spec = ROBOTS[robot]
    joints = spec.joints
    last = joints[-1]
    if spec.drives:
        out = apply_overrides(spec.drives, {last: {"gear_ratio": 123, "efficiency": 0.7}}, joints)
        assert out[-1].gear_ratio == 123.0 and out[-1].efficiency == 0.7
        assert out[-1].rotor_inertia == spec.drives[-1].rotor_inertia
        assert out[:-1] == tuple(spec.drives[:-1])
    else:
        full = {j: {"gear_ratio": 100.0, "efficiency": 0.9, "rotor_inertia_kg_m2": 1e-4,
                    "rated_torque_nm": 1.0, "peak_torque_nm": 3.0, "max_speed_rpm": 4000.0}
                for j in joints}
        out = apply_overrides((), full, joints)
        assert out == (DRIVE,) * len(joints)
    with pytest.raises(UnknownNameError) as err:
        apply_overrides(spec.drives, {"j9": {"gear_ratio": 50}}, joints)
    assert "j9" in str(err.value) and all(j in str(err.value) for j in joints)
    assert "\n" not in str(err.value)


def test_apply_overrides_rejects_bad_fields_and_values() -> None:
    names = ("j1", "j2")
    drives = (DRIVE, DRIVE)
    assert apply_overrides(drives, None, names) == drives
    # Keys of docs/scenario-format.md (unit-suffixed) and bare Drive field names both work.
    out = apply_overrides(drives, {"j2": {"rated_torque_nm": 1.2, "rotor_inertia_kg_m2": 2e-4,
                                          "peak_torque": 5.0}}, names)
    assert (out[1].rated_torque, out[1].rotor_inertia, out[1].peak_torque) == (1.2, 2e-4, 5.0)
    assert out[0] == DRIVE
    with pytest.raises(UnknownNameError, match="rated_torque_nm") as err:
        apply_overrides(drives, {"j2": {"gear": 50}}, names)
    assert "'gear'" in str(err.value) and "gear_ratio" in str(err.value)
    cases = [({"efficiency": 1.5}, "drives.j2.efficiency"),
             ({"efficiency": 0}, "drives.j2.efficiency"),
             ({"gear_ratio": -3}, "drives.j2.gear_ratio"),
             ({"gear_ratio": "fast"}, "drives.j2.gear_ratio"),
             ({"rated_torque_nm": True}, "drives.j2.rated_torque_nm"),
             ({"rotor_inertia_kg_m2": -1e-5}, "drives.j2.rotor_inertia_kg_m2"),
             ({"peak_torque_nm": 0.5}, "drives.j2.peak_torque_nm")]
    for table, field in cases:
        with pytest.raises(ScenarioError, match=field.replace(".", r"\.")):
            apply_overrides(drives, {"j2": table}, names)
    with pytest.raises(ScenarioError, match="drives.j1"):
        apply_overrides(drives, {"j1": 3}, names)
    # No defaults: a partial table cannot make a drive; naming one joint leaves the other bare.
    with pytest.raises(ScenarioError, match="efficiency"):
        apply_overrides((), {"j1": {"gear_ratio": 50}}, names)
    with pytest.raises(ScenarioError, match="j2"):
        apply_overrides((), {"j1": dict(DRIVE.__dict__)}, names)


# ---------------------------------------------------------------------------------------------
# Limits read from a MuJoCo model
# ---------------------------------------------------------------------------------------------

_MJCF = """
<mujoco><worldbody><body>
  <joint name="a" type="hinge" armature="0.2" actuatorfrcrange="-5 5"/><geom size=".1" mass="1"/>
  <body pos="0 0 1"><joint name="b" type="hinge" armature="0.05"/><geom size=".1" mass="1"/>
    <body pos="0 0 1"><joint name="c" type="hinge"/><geom size=".1" mass="1"/></body>
  </body></body></worldbody>
<actuator>
  <general joint="b" forcerange="-3 4" forcelimited="true" gear="2"/>
  <general joint="a" forcerange="-10 10" forcelimited="true" gear="-1"/>
</actuator></mujoco>
"""


def test_forcerange_and_armature_from_model() -> None:
    import mujoco

    model = mujoco.MjModel.from_xml_string(_MJCF)
    fr = forcerange_from_model(model, ["a", "b", "c"])
    # a: gear -1 x [-10, 10] = [-10, 10], cut by the joint's actuatorfrcrange [-5, 5]
    # b: gear 2 x [-3, 4] = [-6, 8]; c: no actuator -> unlimited
    assert fr[0] == pytest.approx([-5, 5])
    assert fr[1] == pytest.approx([-6, 8])
    assert np.all(np.isinf(fr[2]))
    assert armature_from_model(model, ["a", "b", "c"]) == pytest.approx([0.2, 0.05, 0.0])
    with pytest.raises(UnknownNameError, match="'d'"):
        forcerange_from_model(model, ["d"])


# ---------------------------------------------------------------------------------------------
# Run folders
# ---------------------------------------------------------------------------------------------

def write_run(tmp_path, spec, T=2.0, n=801, extra_summary=None):
    t = np.linspace(0.0, T, n)
    k = np.arange(1, spec.n_joints + 1)
    tau_id = 10.0 * k * np.sin(2 * np.pi * t / T)[:, None]
    qd = 0.3 * np.cos(2 * np.pi * t / T)[:, None] * np.ones(spec.n_joints)
    qdd = -0.3 * 2 * np.pi / T * np.sin(2 * np.pi * t / T)[:, None] * np.ones(spec.n_joints)
    np.savez(tmp_path / "trajectory.npz", t=t, phase=np.zeros(n, dtype=int), q_ref=0 * qd,
             qd_ref=qd, qdd_ref=qdd, q=0 * qd, qd=qd, tau=tau_id, tau_id=tau_id)
    summary = {"scenario": "demo", "robot": spec.name, "joints": list(spec.joints),
               "phases": [{"name": "approach", "kind": "move", "t0": 0.0, "t1": T}],
               "duration_s": T}
    summary.update(extra_summary or {})
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    return tau_id


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_size_run_for_every_robot(tmp_path, robot: str) -> None:
    spec = ROBOTS[robot]
    tau_id = write_run(tmp_path, spec)
    fr = np.tile([-1000.0, 1000.0], (spec.n_joints, 1))
    res = size_run(tmp_path, spec, None, fr)
    assert res.joint_names == spec.joints and res.robot == robot and res.scenario == "demo"
    for k, j in enumerate(res.joints):
        assert j.stats["id"].peak_torque == pytest.approx(np.abs(tau_id[:, k]).max())
        assert j.stats["id"].rms_torque == pytest.approx(10.0 * (k + 1) / math.sqrt(2), rel=1e-5)
        assert j.speed_limit == spec.max_speed[k]
        assert j.check("joint_speed").margin_pct == pytest.approx(
            (spec.max_speed[k] - 0.3) / spec.max_speed[k] * 100)
        # Default armature: the registry's reflected inertia (MJCF armature convention).
        expected_arm = spec.drives[k].reflected_inertia if spec.drives else 0.0
        assert j.armature == pytest.approx(expected_arm)
        assert bool(j.motor) == bool(spec.drives)


def test_size_run_rejects_bad_run_folders(tmp_path) -> None:
    spec = ROBOTS["lrmate200ic5l"]
    with pytest.raises(CellsimError, match="trajectory.npz"):
        size_run(tmp_path, spec)
    write_run(tmp_path, spec, extra_summary={"joints": ["a", "b"]})
    with pytest.raises(CellsimError, match="do not match robot lrmate200ic5l"):
        size_run(tmp_path, spec)
    t = np.linspace(0, 1, 5)
    np.savez(tmp_path / "trajectory.npz", t=t, tau=np.zeros((5, 6)))
    with pytest.raises(CellsimError, match="missing array.*tau_id"):
        load_trajectory(tmp_path)
    z = np.zeros((5, 6))
    np.savez(tmp_path / "trajectory.npz", t=t, q_ref=z, qd_ref=z, qdd_ref=z, q=z, qd=z,
             tau=z, tau_id=np.zeros((5, 5)))
    with pytest.raises(CellsimError, match="tau_id has shape"):
        load_trajectory(tmp_path)


def test_runner_facing_summary_properties() -> None:
    res = _three_joint_case(forcerange=[[-100, 100]] * 3)
    assert res.hardest_joint == "j2" and res.hardest_margin_pct == pytest.approx(-20.0)
    assert res.all_pass is False
    none = _three_joint_case()
    assert none.hardest_joint is None and math.isnan(none.hardest_margin_pct) and none.all_pass


def test_tiny_negative_margin_never_reads_as_zero() -> None:
    # 100.2 against 100: margin -0.2 %, must read as a failure, not "-0.0%".
    res = _three_joint_case(peaks=(100.2, 10.0, 10.0), forcerange=[[-100, 100]] * 3)
    assert not res.passed
    assert "-0.2%" in res.verdict and "-0.0%" not in res.verdict


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_model_limits_and_armature_convention(robot: str) -> None:
    # The shipped models: every joint has a finite force range around zero, and the MJCF
    # armature is the drive's reflected inertia J_r N^2 (sim/robots/registry.py), which size_run
    # subtracts by default so that the rotor inertia is counted once.
    import mujoco

    spec = ROBOTS[robot]
    model = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    fr = forcerange_from_model(model, spec.joints)
    assert np.all(np.isfinite(fr)) and np.all(fr[:, 0] < 0) and np.all(fr[:, 1] > 0)
    arm = armature_from_model(model, spec.joints)
    assert arm == pytest.approx([d.reflected_inertia for d in spec.drives], rel=1e-9)
