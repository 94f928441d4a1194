"""Actuator sizing on real runs (issue 5 acceptance): static gravity torques, report values
recomputed from trajectory.npz, payload and speed-scale trends, the sweep command and its
bad input."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
from support.limits import run_limited
from support.window_oracle import sustained_peak

from sim.analysis.sizing import PEAK_WINDOW_S
from sim.pipeline.run import RunOptions, run_scenario
from sim.scenario import load_scenario, parse_scenario

HOLD = """
name = "hold_horizontal"
description = "200iC/5L holding its arm horizontal (upper arm and forearm), with a payload"
robot = "lrmate200ic5l"
tool = "mig_torch"
payload_kg = 2.0
[[phases]]
name = "settle"
planner = "434"
time_s = [0.0, 0.2, 0.4]
joints_deg = [[0,-90,90,0,0,0],[0,-90,90,0,0,0],[0,-90,90,0,0,0]]
[[phases]]
name = "hold"
kind = "hold"
duration_s = 1.0
"""


def _opts(out: Path) -> RunOptions:
    return RunOptions(out_dir=out, video=False, plots=False, progress=False)


def hand_gravity_torques(model: mujoco.MjModel, data: mujoco.MjData,
                         joints: list[str]) -> np.ndarray:
    """Static gravity torque of each joint: tau_j = -a_j . sum_i (c_i - p_j) x (m_i g), over
    every body i carried by joint j (its subtree), with the body's mass m_i and centre of mass
    c_i, the joint's anchor p_j and axis a_j. Statics only, no MuJoCo dynamics."""
    g = model.opt.gravity
    out = []
    for name in joints:
        jid = model.joint(name).id
        body = model.jnt_bodyid[jid]
        p, a = data.xanchor[jid], data.xaxis[jid]
        moment = np.zeros(3)
        for i in range(model.nbody):
            k = i
            while k not in (0, body):
                k = model.body_parentid[k]
            if k == body:
                moment += np.cross(data.xipos[i] - p, model.body_mass[i] * g)
        out.append(-a @ moment)
    return np.array(out)


@pytest.fixture(scope="module")
def hold_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("hold") / "run"
    summary = run_scenario(parse_scenario(HOLD, source="hold.toml"), _opts(out))
    return out, summary


def test_hold_equals_static_gravity_torques(hold_run):
    """Arm horizontal (J2 at -90 deg: upper arm along +x; J3 at 90 deg: forearm along +x):
    simulated torque over the hold = hand-derived static gravity torque, to 0.5 %."""
    out, _ = hold_run
    a = np.load(out / "trajectory.npz")
    model = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    data = mujoco.MjData(model)
    data.qpos[:] = a["qpos"][-1]
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    joints = [f"robot/j{j + 1}" for j in range(6)]
    hand = hand_gravity_torques(model, data, joints)
    hold = a["phase"] == 1
    tau = a["tau"][hold][len(a["t"][hold]) // 2:].mean(axis=0)
    for j in (1, 2):  # J2 and J3 carry the horizontal arm
        assert abs(hand[j]) > 5.0
        assert tau[j] == pytest.approx(hand[j], rel=5e-3), (j, tau[j], hand[j])
    # the horizontal arm is J2's worst static case: lever arms are the whole arm's length
    x2 = data.xanchor[model.joint("robot/j2").id][0]
    lever = (data.xipos[1:, 0] - x2) * model.body_mass[1:]
    assert abs(hand[1]) <= 9.81 * np.abs(lever).sum() + 1e-9


def test_report_values_recomputed_from_npz(hold_run, tmp_path):
    """sizing.csv's simulated peak and RMS torque equal those recomputed from trajectory.npz
    (RMS time-weighted: sqrt of the trapezoidal integral of tau^2 over the cycle time; the peak
    of the torque sustained over 5 ms)."""
    out, summary = run_once_kacso(tmp_path)
    a = np.load(out / "trajectory.npz")
    rows = {r["joint"]: r for r in csv.DictReader(open(out / "sizing.csv"))}
    t = a["t"]
    for j, name in enumerate(summary["joints"]):
        tau, tau_id = a["tau"][:, j], a["tau_id"][:, j]
        rms_sim = np.sqrt(np.trapezoid(tau**2, t) / (t[-1] - t[0]))
        rms_id = np.sqrt(np.trapezoid(tau_id**2, t) / (t[-1] - t[0]))
        # the simulated peak is the torque sustained over PEAK_WINDOW_S (window_oracle)
        assert float(rows[name]["peak_torque_sim_nm"]) == pytest.approx(
            sustained_peak(t, tau, PEAK_WINDOW_S), rel=1e-9)
        assert float(rows[name]["peak_torque_sim_nm"]) <= np.abs(tau).max()
        assert float(rows[name]["rms_torque_sim_nm"]) == pytest.approx(rms_sim, rel=1e-9)
        assert float(rows[name]["rms_torque_id_nm"]) == pytest.approx(rms_id, rel=1e-9)
        assert float(rows[name]["peak_speed_sim_rad_s"]) == pytest.approx(
            np.abs(a["qd"][:, j]).max(), rel=1e-9)
        assert float(rows[name]["peak_speed_rad_s"]) >= np.abs(a["qd"][:, j]).max() - 1e-9
        peak_p = sustained_peak(t, tau * a["qd"][:, j], PEAK_WINDOW_S)
        assert float(rows[name]["peak_power_sim_w"]) == pytest.approx(peak_p, rel=1e-9)


_KACSO: dict[str, tuple[Path, dict]] = {}


def run_once_kacso(tmp_path: Path) -> tuple[Path, dict]:
    if "run" not in _KACSO:
        out = tmp_path / "kacso"
        _KACSO["run"] = (out, run_scenario(load_scenario("kacso_lrmate100ib_sequence1"),
                                           _opts(out)))
    return _KACSO["run"]


def test_torque_scales_with_speed_squared_without_gravity(tmp_path, monkeypatch):
    """With gravity, damping and friction removed, every torque of the same path run s times
    faster is s^2 times larger: inverse dynamics at every instant (to 1e-6 of the peak), the
    simulated torque's peak and RMS to 2 %."""
    import sim.pipeline.run as runner

    real_build = runner.build

    def weightless(scenario):
        built = real_build(scenario)
        built.model.opt.gravity[:] = 0.0
        built.model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS)
        built.model.dof_damping[:] = 0.0
        # joint friction is applied by friction actuators (sim.cells.compose): remove it too
        built.model.actuator_forcerange[built.friction_act] = 0.0
        built.model.actuator_biasprm[built.friction_act] = 0.0
        built.cell.frictionloss[:] = 0.0
        # s = 2 asks J2 for more than its drive's limit, which now clamps the whole torque
        # inside the simulation (tests/simulation/test_torques.py): lift the limits for this
        # scaling law
        built.model.actuator_forcerange[built.robot_act] *= 100.0
        built.force_limits[:] *= 100.0
        return built

    monkeypatch.setattr(runner, "build", weightless)
    base = load_scenario("kacso_lrmate100ib_sequence1")
    res = {}
    for s in (1.0, 2.0):
        out = tmp_path / f"s{s:g}"
        run_scenario(base.scaled(s), _opts(out))
        res[s] = np.load(out / "trajectory.npz")
    a1, a2 = res[1.0], res[2.0]
    # the same instants of the path: t2 = t1 / 2, i.e. every other sample of run 1
    n = a2["t"].size
    k1 = np.arange(n) * 2
    k1 = k1[k1 < a1["t"].size]
    np.testing.assert_allclose(a2["t"][: k1.size], a1["t"][k1] / 2, atol=1e-12)
    np.testing.assert_allclose(a2["tau_id"][: k1.size], 4 * a1["tau_id"][k1],
                               atol=1e-6 * np.abs(a2["tau_id"]).max())
    # the simulated torque adds the servo's small corrections, which do not scale: its peak
    # and time-weighted RMS scale as s^2 to 2 % on the loaded joints
    peak1, peak2 = np.abs(a1["tau"]).max(axis=0), np.abs(a2["tau"]).max(axis=0)

    def rms(a):
        return np.sqrt(np.trapezoid(a["tau"] ** 2, a["t"], axis=0) / (a["t"][-1] - a["t"][0]))

    loaded = peak1 > 0.01 * peak1.max()
    np.testing.assert_allclose(peak2[loaded] / peak1[loaded], 4.0, rtol=0.02)
    np.testing.assert_allclose(rms(a2)[loaded] / rms(a1)[loaded], 4.0, rtol=0.02)


def _cli(*args: str) -> subprocess.CompletedProcess:
    return run_limited([sys.executable, "-m", "sim", *args], capture_output=True, text=True,
                          cpu_s=600)


def test_size_sweep_payload_raises_j2_j3_torque(tmp_path):
    """`cellsim size` over payloads: sweep.csv has a row per variant and joint, and peak J2
    and J3 torque rise with payload."""
    out = tmp_path / "sweep"
    res = _cli("size", "kacso_lrmate100ib_sequence1", "--payload", "0,2.5,5",
               "--speed-scale", "1", "--out", str(out), "--quiet")
    assert res.returncode == 0, res.stderr
    rows = list(csv.DictReader(open(out / "sweep.csv")))
    assert len(rows) == 3 * 5
    for col in ("payload_kg", "speed_scale", "joint", "peak_torque_nm", "rms_torque_nm"):
        assert col in rows[0]
    for joint in ("j2", "j3"):
        peaks = [float(r["peak_torque_nm"]) for r in sorted(
            (r for r in rows if r["joint"] == joint), key=lambda r: float(r["payload_kg"]))]
        assert peaks[0] < peaks[1] < peaks[2], (joint, peaks)
    assert (out / "sweep.md").is_file() and (out / "sweep.svg").is_file()


@pytest.mark.parametrize("args, fragment", [
    (["--payload", "-1"], "--payload"),
    (["--speed-scale", "0"], "--speed-scale"),
    (["--speed-scale", "1,abc"], "--speed-scale"),
])
def test_size_bad_input(tmp_path, args, fragment):
    res = _cli("size", "kacso_lrmate100ib_sequence1", *args, "--out", str(tmp_path / "o"))
    assert res.returncode == 2
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and fragment in lines[0], res.stderr
    assert not (tmp_path / "o").exists()


def test_unknown_joint_in_drive_override_exit_2(tmp_path):
    text = load_scenario("kacso_lrmate100ib_sequence1").text + "\n[drives.j7]\ngear_ratio = 50.0\n"
    f = tmp_path / "d.toml"
    f.write_text(text)
    res = _cli("run", str(f), "--no-video", "--out", str(tmp_path / "o"))
    assert res.returncode == 2
    assert "drives.j7" in res.stderr and "j1, j2, j3, j4, j5" in res.stderr
    assert not (tmp_path / "o").exists()


def test_weld_cycle_report_names_hardest_joint(scenario_run):
    """bugnar_5r_weld_cycle's report names the joint that needs the largest actuator and its
    margin (the verdict in sizing.md equals sizing.json's)."""
    out, summary = scenario_run("bugnar_5r_weld_cycle")
    sizing = summary["sizing"]
    hardest, margin = sizing["hardest_joint"], sizing["hardest_margin_pct"]
    assert hardest in summary["joints"] and np.isfinite(margin)
    md = (out / "sizing.md").read_text()
    assert f"hardest joint is {hardest}" in md and f"{margin:.1f}%" in md
    data = json.loads((out / "sizing.json").read_text())
    margins = {j["joint"]: j["margin_pct"] for j in data["joints"]}
    assert min(margins, key=margins.get) == hardest
