"""Torques you can size from: continuous-time joint torques that do not depend on the timestep,
agree with an independent RNEA (pinocchio) and with the energy balance; drives that saturate
inside the simulation; a verdict that fails a physically impossible run."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest
from support.rnea_oracle import tau_id_error

from sim.analysis.sizing import peak_abs, rms
from sim.cli import main
from sim.core.resources import shipped_scenarios
from sim.errors import ScenarioError
from sim.pipeline.run import RunOptions, run_scenario
from sim.scenario import load_scenario, parse_scenario
from sim.simulation.compile import build
from sim.simulation.motion import build_motion
from sim.simulation.simulate import inverse_dynamics, simulate

SCENARIOS = sorted(shipped_scenarios())


def _simulate(scenario, timestep: float) -> dict:
    sc = dataclasses.replace(scenario, simulation=scenario.simulation.model_copy(
        update={"timestep_s": timestep}))
    built = build(sc)
    motion = build_motion(sc, built.context)
    return simulate(built, motion, feedforward=True, settle_s=sc.simulation.settle_s,
                    progress=False).arrays


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENARIOS)
def test_sizing_torques_converge_as_the_timestep_shrinks(name):
    """Peak and RMS torque (inverse dynamics and simulated) at 1 ms and 0.25 ms agree within 1 %
    for every joint whose peak is over 2 % of the largest."""
    scenario = load_scenario(name)
    stats = {}
    for h in (0.001, 0.00025):
        a = _simulate(scenario, h)
        t = a["t"]
        stats[h] = {k: np.array([[peak_abs(t, a[k][:, j])[0], rms(t, a[k][:, j])]
                                 for j in range(a[k].shape[1])]) for k in ("tau_id", "tau")}
    for key in ("tau_id", "tau"):
        coarse, fine = stats[0.001][key], stats[0.00025][key]
        loaded = fine[:, 0] > 0.02 * fine[:, 0].max()
        np.testing.assert_allclose(coarse[loaded], fine[loaded], rtol=0.01,
                                   err_msg=f"{name} {key} (peak, RMS) per joint")


def _reported_peaks(scenario, timestep: float) -> dict[str, np.ndarray]:
    """The sizing's peaks at ``timestep``, per joint: ``used``: the values its peak checks use
    (joint torque, motor peak torque; basis worst: the worse source), ``id`` and ``sim``: each
    source's peak joint and motor torque; shape (n, 2) each."""
    from sim.pipeline.run import evaluate_scenario

    sc = dataclasses.replace(scenario, simulation=scenario.simulation.model_copy(
        update={"timestep_s": timestep}))
    res = evaluate_scenario(sc, RunOptions(video=False, plots=False, progress=False)).sizing
    out = {s: np.array([[j.stats[s].peak_torque, j.motor[s].peak_torque] for j in res.joints])
           for s in ("id", "sim")}
    out["used"] = np.array([[j.check("joint_torque").used, j.check("motor_peak_torque").used]
                            for j in res.joints])
    return out


def _peaks_agree(name: str, sim_rtol: float) -> None:
    """Peaks at 2 and 1 ms against 0.5 ms, every joint loaded over 2 % of the largest: the
    values the checks use and the reference's within 0.2 %, the simulated ones within
    ``sim_rtol``."""
    scenario = load_scenario(name)
    fine = _reported_peaks(scenario, 0.0005)
    for h in (0.002, 0.001):
        got = _reported_peaks(scenario, h)
        for key, rtol in (("used", 0.002), ("id", 0.002), ("sim", sim_rtol)):
            loaded = fine[key] > 0.02 * fine[key].max(axis=0)
            np.testing.assert_allclose(got[key][loaded], fine[key][loaded], rtol=rtol,
                                       err_msg=f"{name} at {h * 1e3:g} ms: {key} (joint, motor) "
                                       "peak per joint")


@pytest.mark.slow  # the fast share's ten minutes (issue 29): a convergence study
def test_reported_peaks_agree_at_2_1_and_half_ms_through_contacts():
    """Issue 26's acceptance on the pick-and-place cycle, whose part contacts move the joints
    in a step or two (its simulated J3 torque at one step: 15.99 N m at 2 ms, 12.85 at 1 ms,
    12.83 at 0.5 ms): every peak sizing reports, of both sources, joint and motor side, at
    2, 1 and 0.5 ms steps within 0.2 % (the simulated peaks are sustained over 5 ms)."""
    _peaks_agree("lrmate200ic_pick_place", sim_rtol=0.002)


@pytest.mark.slow
def test_peaks_of_the_samples_would_not_agree(monkeypatch):
    """The check above is not blind: with the peaks taken of the samples (no window), the
    pick-and-place's J3 peak that its check uses at 2 ms is 25 % over the one at 0.5 ms."""
    import sim.analysis.sizing as sizing

    monkeypatch.setattr(sizing, "PEAK_WINDOW_S", 0.0)
    with pytest.raises(AssertionError, match="at 2 ms: used"):
        _peaks_agree("lrmate200ic_pick_place", sim_rtol=0.002)


@pytest.mark.slow
@pytest.mark.parametrize("name", [s for s in SCENARIOS if s != "lrmate200ic_pick_place"])
def test_reported_peaks_agree_at_2_1_and_half_ms(name):
    """Every other shipped scenario: the peaks the checks use and the reference's within
    0.2 % at 2, 1 and 0.5 ms. The simulated source converges at first order in the step
    (MuJoCo's implicit Euler): seed 000's fast J2 motor peak is 1.013, 1.021 and 1.024 N m at
    2, 1 and 0.5 ms, so it is held to 1.5 % here; its checks use the reference's 1.029."""
    _peaks_agree(name, sim_rtol=0.015)


@pytest.mark.parametrize("name", ["kacso_lrmate100ib_sequence1", "lrmate200ic_weld_plate",
                                  "bugnar_5r_phase1", "bugnar_5r_weld_cycle",
                                  "bugnar_5r_weld_cycle_ceiling", "lrmate200ic_pick_place"])
def test_tau_id_equals_an_independent_rnea(name, scenario_run, tmp_path):
    """tau_id = pinocchio's RNEA on the run's model.xml (+ armature qdd when pinocchio leaves it
    out) + damping qd + Coulomb friction, to 1e-6 of each joint's peak where |qd| > 1e-2."""
    out, summary = scenario_run(name)
    with np.load(out / "trajectory.npz") as npz:
        a = {k: npz[k] for k in ("t", "q_ref", "qd_ref", "qdd_ref", "tau_id")}
    assert tau_id_error(out / "model.xml", summary["joints"], a, tmp_path) <= 1e-6


def test_the_rnea_oracle_catches_a_one_percent_torque_error(scenario_run, tmp_path):
    """The comparison above is not blind: J2's recorded torque 1 % high is found, as that."""
    out, summary = scenario_run("lrmate200ic_weld_plate")
    with np.load(out / "trajectory.npz") as npz:
        a = {k: npz[k] for k in ("t", "q_ref", "qd_ref", "qdd_ref", "tau_id")}
    a["tau_id"] = a["tau_id"].copy()
    a["tau_id"][:, 1] *= 1.01
    err = tau_id_error(out / "model.xml", summary["joints"], a, tmp_path)
    assert 0.009 < err < 0.0100001, err


CLOSED_CYCLE = """
name = "closed_cycle"
description = "LR Mate 200iC/5L out and back to its start, at rest at both ends"
robot = "lrmate200ic5l"
payload_kg = 2.0

[[phases]]
name = "out_and_back"
planner = "434"
time_s = [0.0, 0.6, 1.2, 1.8, 2.4]
joints_deg = [
  [0.0,   0.0,  0.0,   0.0, -90.0,  0.0],
  [40.0, -30.0, 40.0,  60.0, -40.0, 90.0],
  [80.0, -60.0, 90.0, 120.0,  10.0, 180.0],
  [40.0, -30.0, 40.0,  60.0, -40.0, 90.0],
  [0.0,   0.0,  0.0,   0.0, -90.0,  0.0],
]
"""


def test_energy_balance_over_a_closed_frictionless_cycle():
    """Without damping and friction, the work of tau_id, integral of tau_id . qd dt, equals the
    change of kinetic + potential energy at every instant, to 1e-4 of the gross energy."""
    scenario = parse_scenario(CLOSED_CYCLE, source="closed_cycle.toml")
    built = build(scenario)
    model = built.model
    model.dof_damping[:] = 0.0
    built.cell.frictionloss[:] = 0.0
    motion = build_motion(scenario, built.context)
    t = np.linspace(motion.t0, motion.t1, 24001)
    ref = motion.at(t)
    tau = inverse_dynamics(model, built, ref.q, ref.qd, ref.qdd)
    power = np.einsum("ij,ij->i", tau, ref.qd)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    gross = np.trapezoid(np.abs(power), t)
    data = mujoco.MjData(model)
    model.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_ENERGY)
    energy = np.empty(t.size)
    for k in range(t.size):
        data.qpos[built.robot_qpos] = ref.q[k]
        data.qvel[:] = 0.0
        data.qvel[built.robot_dof] = ref.qd[k]
        mujoco.mj_forward(model, data)
        energy[k] = data.energy.sum()
    assert gross > 10.0  # joules: a real cycle, not a standstill
    np.testing.assert_allclose(work, energy - energy[0], atol=1e-4 * gross)


OVERLOAD = """
name = "overload_60kg"
description = "60 kg on the 5 kg LR Mate 200iC/5L, swung out to horizontal"
robot = "lrmate200ic5l"
payload_kg = 60.0

[[phases]]
name = "swing_out"
planner = "434"
time_s = [0.0, 1.0, 2.0]
joints_deg = [
  [0.0,   0.0,  0.0, 0.0, -90.0, 0.0],
  [0.0, -45.0, 45.0, 0.0, -90.0, 0.0],
  [0.0, -90.0, 90.0, 0.0, -90.0, 0.0],
]

[[phases]]
name = "hold"
kind = "hold"
duration_s = 1.0
"""


def test_an_overloaded_robot_saturates_sags_and_fails(tmp_path, capsys):
    """60 kg on the 5 kg LR Mate 200iC/5L: J2's drive saturates inside the simulation, the arm
    lags by more than 0.5 deg, the saturation is listed, the verdict fails, --strict exits 1."""
    path = tmp_path / "overload.toml"
    path.write_text(OVERLOAD)
    summary = run_scenario(parse_scenario(OVERLOAD, source=path), RunOptions(
        out_dir=tmp_path / "run", video=False, plots=False, progress=False))
    j2 = [s for s in summary["saturation"] if s["joint"] == "j2"]
    assert j2 and all(s["worst_excess_nm"] > 0 and s["t1"] >= s["t0"] for s in j2)
    assert summary["max_tracking_error_deg"][1] > 0.5
    assert summary["verdict"] == "fail"
    failed = {(c["name"], c["joint"]) for c in summary["checks"] if not c["pass"]}
    assert {("saturation", "j2"), ("tracking", "j2")} <= failed
    # the drive delivered no more than its limit at any sample
    a = np.load(tmp_path / "run" / "trajectory.npz")
    assert np.abs(a["tau_actuator"][:, 1]).max() <= 405.0 * (1 + 1e-9)
    args = ["run", str(path), "--out", str(tmp_path / "cli"), "--no-video", "--no-plots",
            "--quiet"]
    assert main(args) == 0
    assert main([*args, "--strict"]) == 1
    assert "verdict: FAIL" in capsys.readouterr().out


@pytest.mark.parametrize("name", SCENARIOS)
def test_shipped_scenarios_pass_unless_they_document_an_excess(name, scenario_run):
    """Every shipped scenario's run gives the verdict its [expect] table declares: a pass,
    unless it documents an excess with a reason (seed 000's sequence: J2 past its speed and
    acceleration limits), and then its failed checks are exactly the ones it names."""
    expect = load_scenario(name).expect
    _, summary = scenario_run(name)
    failed = sorted(f"{c['name']} {c.get('subject') or c['joint']}" for c in summary["checks"]
                    if not c["pass"] and c.get("severity", "error") == "error")
    assert summary["verdict"] == expect.verdict, failed
    assert failed == sorted(expect.failed_checks)
    if expect.verdict == "pass":
        assert summary["saturation"] == []


def test_a_declared_failure_is_one_line_after_the_verdict_and_changes_no_exit_code(tmp_path,
                                                                                   capsys):
    """[expect] changes nothing but one line: seed 000's sequence still fails its verdict and
    `--strict` exits 1; `cellsim run` says after the verdict that the scenario declares it, and
    why. The same file without its [expect] gets a line saying the verdict is not the one
    expected, and that it has no [expect] table (not that it declares one)."""
    import re

    args = ["--no-video", "--no-plots", "--quiet", "--strict"]
    name = "kacso_lrmate100ib_sequence1"
    assert main(["run", name, "--out", str(tmp_path / "a"), *args]) == 1
    out = capsys.readouterr().out
    assert re.search(r"verdict: FAIL.*\n(    .*\n)*  expected: the scenario declares this "
                     r"failure \(\[expect\]\): Seed 000's sequence .* 7140 rpm", out), out
    text = re.sub(r"\[expect\].*?\n(?=\[\[phases\]\])", "", load_scenario(name).text,
                  count=1, flags=re.S)
    assert "[expect]" not in text and "[[phases]]" in text
    (tmp_path / "s.toml").write_text(text)
    assert main(["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "b"), *args]) == 1
    out = capsys.readouterr().out
    assert ("  unexpected: verdict 'fail'; the scenario expects 'pass' (it has no [expect] "
            "table declaring a failure)\n") in out, out


def test_simulated_friction_is_the_coulomb_law_of_tau_id():
    """A joint turning at constant speed against its friction actuator: the drive's torque is
    exactly F sign(qd) (plus damping), at any timestep - the law tau_id adds."""
    scenario = load_scenario("bugnar_5r_phase1")
    for h in (0.001, 0.0002):
        sc = dataclasses.replace(scenario, simulation=scenario.simulation.model_copy(
            update={"timestep_s": h}))
        built = build(sc)
        model, data = built.model, mujoco.MjData(built.model)
        model.opt.gravity[:] = 0.0
        j = 0  # J1, vertical axis: no gravity torque anyway
        F = built.cell.frictionloss[j]
        assert F > 0
        data.qpos[built.robot_qpos] = 0.0
        data.qvel[built.robot_dof[j]] = 0.5
        mujoco.mj_forward(model, data)
        friction_force = data.actuator_force[built.friction_act[j]]
        assert friction_force == pytest.approx(-F, rel=1e-12)


def test_size_keeps_variants_past_the_limits_with_negative_margins(tmp_path):
    """A variant twenty times faster than seed 001's phase I (refused by `cellsim run`, whose
    limits are enforced) stays in the sweep table with negative margins and a failed verdict;
    the command exits 0 because it could evaluate every variant."""
    import csv

    out = tmp_path / "sweep"
    assert main(["size", "bugnar_5r_phase1", "--speed-scale", "1,20", "--out", str(out),
                 "--workers", "1", "--quiet"]) == 0
    rows = list(csv.DictReader((out / "sweep.csv").open()))
    fast = [r for r in rows if float(r["speed_scale"]) == 20.0]
    slow = [r for r in rows if float(r["speed_scale"]) == 1.0]
    assert len(fast) == len(slow) == 5
    assert all(r["verdict"] == "fail" for r in fast) and all(r["verdict"] == "pass" for r in slow)
    assert min(float(r["margin_pct"]) for r in fast) < 0
    assert any(r["pass"] == "FAIL" for r in fast)
    with pytest.raises(ScenarioError, match="velocity .* exceeds limit"):
        run_scenario(load_scenario("bugnar_5r_phase1").scaled(20.0), RunOptions(
            out_dir=tmp_path / "refused", video=False, plots=False, progress=False))


FAST_J1 = """
name = "fast_j1"
description = "LR Mate 200iC/5L: a fast J1 swing, arm stretched, 5 kg, a J1 motor that tops out"
robot = "lrmate200ic5l"
payload_kg = 5.0

[[phases]]
name = "swing"
planner = "434"
time_s = [0.0, 0.6, 1.2]
joints_deg = [
  [0.0,   -90.0, 90.0, 0.0, -90.0, 0.0],
  [75.0,  -90.0, 90.0, 0.0, -90.0, 0.0],
  [150.0, -90.0, 90.0, 0.0, -90.0, 0.0],
]

[drives.j1]
max_speed_rpm = 5000.0
rated_torque_nm = 0.1
"""


def test_drive_limit_follows_the_motor_torque_speed_curve(tmp_path):
    """J1 at up to 250 deg/s on a motor that tops out at 5000 rpm (250 deg/s through its 120:1
    reducer): the drive's limit falls along the peak curve at the motor's own speed (never
    above the curve at the speed the joint ran, and never cut to zero while the motor runs
    below its top speed, though the reference asks for more), the drive never delivers more,
    J1 saturates and lags, the verdict fails. With motor_speed_limits = false the limit stays
    the flat peak and J1 tracks."""
    from sim.robots.registry import Drive

    summary = run_scenario(parse_scenario(FAST_J1, source="fast_j1.toml"), RunOptions(
        out_dir=tmp_path / "curve", video=False, plots=False, progress=False))
    a = np.load(tmp_path / "curve" / "trajectory.npz")
    drive = Drive(120, 0.75, 2.0e-5, 0.1, 2.4, 5000)  # the 200iC's J1 with the overrides
    flat = 2.4 * 120 * 0.75
    qd = np.abs(a["qd"][:, 0])
    curve = np.minimum(drive.joint_peak_torque_at(qd), flat)  # at the joint's own speed
    limit = a["tau_limit"][:, 0]
    assert limit.min() < 0.2 * flat  # it falls far below the flat peak near top speed
    # never above the curve at the speed the joint ran (the sample's own, the step's end)
    assert np.all(limit[:-1] <= np.minimum(curve[:-1], curve[1:]) + 1e-6 * flat)
    # the motor below 99 % of its top speed always has torque: the reference, faster than the
    # motor, does not set the limit (it did: 0 N m for 0.18 s)
    top = 5000 / 120 * 2 * np.pi / 60
    slow = qd[:-1] < 0.99 * top
    assert np.all(limit[:-1][slow] > 0.0)
    ref_curve = np.minimum(drive.joint_peak_torque_at(np.abs(a["qd_ref"][:, 0])), flat)
    assert np.any(limit > ref_curve + 1e-6 * flat)  # the reference's curve is not the limit
    assert np.all(np.abs(a["tau_actuator"][:, 0]) <= limit * (1 + 1e-9) + 1e-12)
    assert any(s["joint"] == "j1" for s in summary["saturation"])
    assert summary["max_tracking_error_deg"][0] > 0.5 and summary["verdict"] == "fail"

    flat_only = FAST_J1.replace('payload_kg = 5.0\n',
                                'payload_kg = 5.0\n\n[simulation]\nmotor_speed_limits = false\n')
    summary = run_scenario(parse_scenario(flat_only, source="fast_j1_flat.toml"), RunOptions(
        out_dir=tmp_path / "flat", video=False, plots=False, progress=False))
    a = np.load(tmp_path / "flat" / "trajectory.npz")
    assert np.all(a["tau_limit"][:, 0] == flat)
    assert not any(s["joint"] == "j1" for s in summary["saturation"])
    assert summary["max_tracking_error_deg"][0] < 0.1
