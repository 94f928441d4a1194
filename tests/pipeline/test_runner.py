"""The scenario runner (issue 4 section 3): tracking, torques, determinism, model.xml replay,
atomic run folders and instability handling."""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import numpy as np
import pytest
from support.scenarios import joint_phase, scenario_text

from sim.cli import main
from sim.errors import CellsimError, SimulationError
from sim.pipeline.run import RunOptions, run_scenario
from sim.scenario import load_scenario, parse_scenario

REQUIRED_ARRAYS = {"t", "phase", "q_ref", "qd_ref", "qdd_ref", "qddd_ref", "q", "qd", "tau",
                   "tau_id", "tcp_pos", "tcp_pos_ref", "tcp_quat", "qpos"}
REQUIRED_SUMMARY = {"scenario", "robot", "joints", "phases", "duration_s", "timestep_s", "steps",
                    "wall_s", "realtime_factor", "max_tracking_error_rad", "max_tcp_deviation_mm"}


def _run(name_or_scenario, out: Path, **kw) -> dict:
    sc = load_scenario(name_or_scenario) if isinstance(name_or_scenario, str) else name_or_scenario
    return run_scenario(sc, RunOptions(out_dir=out, video=False, plots=False, progress=False, **kw))


@pytest.fixture(scope="module")
def kacso_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs") / "kacso"
    return out, _run("kacso_lrmate100ib_sequence1", out, csv=True)


def test_run_folder_contents(kacso_run):
    out, summary = kacso_run
    for f in ("summary.json", "trajectory.npz", "trajectory.csv", "model.xml", "scenario.toml",
              "manifest.json", "sizing.csv", "report.html"):
        assert (out / f).is_file(), f
    assert REQUIRED_SUMMARY <= set(summary)
    on_disk = json.loads((out / "summary.json").read_text())
    assert on_disk["scenario"] == "kacso_lrmate100ib_sequence1"
    assert on_disk["phases"] == [{"name": "sequence1", "kind": "joint", "t0": 0.0, "t1": 0.624}]
    a = np.load(out / "trajectory.npz")
    assert REQUIRED_ARRAYS <= set(a.files)
    n = a["t"].size
    assert summary["steps"] == n - 1 == round(0.624 / summary["timestep_s"])
    for key in ("q_ref", "q", "tau", "tau_id"):
        assert a[key].shape == (n, 5)
    assert a["tcp_pos"].shape == (n, 3) and a["tcp_quat"].shape == (n, 4)
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["mujoco"] == mujoco.__version__ and len(manifest["scenario_sha256"]) == 64
    assert (out / "scenario.toml").read_text() == load_scenario(
        "kacso_lrmate100ib_sequence1").text


def test_seed000_sequence_tracks_and_torques_agree(kacso_run):
    """At the seed's own speed: tracking < 0.1 deg, tcp within 0.5 mm of the reference, and
    simulated torque vs inverse dynamics RMS difference < 5 % of the joint's peak."""
    out, summary = kacso_run
    assert max(summary["max_tracking_error_deg"]) < 0.1
    assert summary["max_tcp_deviation_mm"] < 0.5
    a = np.load(out / "trajectory.npz")
    peak = np.max(np.abs(a["tau_id"]), axis=0)
    rms = np.sqrt(np.mean((a["tau"] - a["tau_id"]) ** 2, axis=0))
    moving = peak > 1.0  # joints with real load
    assert np.all(rms[moving] < 0.05 * peak[moving])
    # the reference really is seed 000 Table 3 (knots) and the arm really went there
    np.testing.assert_allclose(np.degrees(a["q_ref"][-1, 1:4]), [86.38, -3.62, 7.24], atol=1e-9)
    np.testing.assert_allclose(np.degrees(a["q"][-1, 1:4]), [86.38, -3.62, 7.24], atol=0.1)


def test_reference_tcp_is_closed_form_fk(kacso_run):
    """tcp_pos_ref = seed 000 eq. 5 of q_ref, placed by frame0 (checked via MuJoCo's site)."""
    out, _ = kacso_run
    a = np.load(out / "trajectory.npz")
    model = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    data = mujoco.MjData(model)
    tcp = [i for i in range(model.nsite) if model.site(i).name.endswith("tcp")][0]
    for k in (0, len(a["t"]) // 2, -1):
        data.qpos[:] = a["qpos"][k]
        qadr = [model.jnt_qposadr[model.joint(f"robot/j{j + 1}").id]
                if model.joint(f"robot/j{j + 1}") is not None else None for j in range(5)]
        data.qpos[qadr] = a["q_ref"][k]
        mujoco.mj_kinematics(model, data)
        np.testing.assert_allclose(data.site_xpos[tcp], a["tcp_pos_ref"][k], atol=1e-9)


def test_same_scenario_twice_identical_arrays(kacso_run, tmp_path):
    out, _ = kacso_run
    _run("kacso_lrmate100ib_sequence1", tmp_path / "again")
    a, b = np.load(out / "trajectory.npz"), np.load(tmp_path / "again" / "trajectory.npz")
    assert set(a.files) == set(b.files)
    for key in a.files:
        assert np.array_equal(a[key], b[key]), key


def test_model_xml_reproduces_the_run(kacso_run):
    """model.xml is the compiled cell exactly as simulated: replaying the recorded controls on
    it reproduces the recorded joint trajectory."""
    out, _ = kacso_run
    a = np.load(out / "trajectory.npz")
    model = mujoco.MjModel.from_xml_path(str(out / "model.xml"))
    data = mujoco.MjData(model)
    acts = [model.actuator(f"robot/a{j + 1}").id for j in range(5)]
    joints = [model.joint(f"robot/j{j + 1}").id for j in range(5)]
    qadr, dadr = model.jnt_qposadr[joints], model.jnt_dofadr[joints]
    kp, kv = model.actuator_gainprm[acts, 0], -model.actuator_biasprm[acts, 2]
    data.qpos[:] = a["qpos"][0]
    mujoco.mj_forward(model, data)
    for k in range(len(a["t"]) - 1):
        data.ctrl[acts] = a["q_ref"][k] + kv / kp * a["qd_ref"][k]
        data.qfrc_applied[dadr] = a["tau_ff"][k]
        mujoco.mj_step(model, data)
    np.testing.assert_allclose(data.qpos[qadr], a["q"][-1], atol=1e-9)


def test_feedforward_off_is_a_pure_position_servo(tmp_path):
    """Without feed-forward the position servo lags: the error is much larger (physics:
    about kv/kp * qd + tau/kp), and ctrl = q_ref exactly."""
    s = _run("kacso_lrmate100ib_sequence1", tmp_path / "noff", feedforward=False)
    assert not s["feedforward"]
    assert max(s["max_tracking_error_deg"]) > 0.5
    a = np.load(tmp_path / "noff" / "trajectory.npz")
    assert np.all(a["tau_ff"] == 0)


UNSTABLE = """
name = "unstable"
description = "5R with a far too long time step"
robot = "robot_5r"
[simulation]
timestep_s = 0.001
[[phases]]
name = "a"
planner = "434"
time_s = [0.0, 0.5, 1.0]
joints_deg = [[0,0,0,0,0],[10,20,10,10,10],[20,40,20,20,20]]
"""


def test_instability_stops_with_time_and_joint_and_keeps_failed_folder(tmp_path, monkeypatch):
    """An unstable simulation (here: a servo gain far beyond the time step's stability limit)
    stops the run with the time and the joint; what was recorded goes to DIR.failed/."""
    import sim.pipeline.run as runner

    real_build = runner.build

    def stiff_build(scenario):
        built = real_build(scenario)
        a = built.robot_act[1]  # j2
        built.model.actuator_gainprm[a, 0] *= 1e6
        built.model.actuator_biasprm[a, 1] *= 1e6
        built.model.actuator_forcelimited[a] = 0
        return built

    monkeypatch.setattr(runner, "build", stiff_build)
    sc = parse_scenario(UNSTABLE, source="unstable.toml")
    out = tmp_path / "u"
    with pytest.raises(SimulationError) as info:
        _run(sc, out)
    msg = str(info.value)
    assert "unstable at t =" in msg and "joint" in msg and "\n" not in msg
    assert not out.exists(), "a failed run leaves no result folder"
    failed = out.with_name("u.failed")
    assert (failed / "error.txt").read_text().strip() == msg
    assert (failed / "trajectory.npz").is_file() and not (failed / "summary.json").exists()
    t_fail = float(msg.split("t = ")[1].split(" s")[0])
    assert 0 < t_fail < 1.0


def test_cli_run_bad_input_leaves_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(UNSTABLE.replace("[[0,0,0,0,0]", "[[0,0,0,0,0,0]"))
    rc = main(["run", str(bad), "--out", str(tmp_path / "o"), "--no-video", "--quiet"])
    assert rc == 2
    assert "joints_deg[0]" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_joint_range_violation_names_joint_and_time(tmp_path):
    text = UNSTABLE.replace("[20,40,20,20,20]", "[20,40,20,20,400]")
    with pytest.raises(CellsimError) as info:
        _run(parse_scenario(text, source="lim.toml"), tmp_path / "l")
    msg = str(info.value)
    assert "joint j5" in msg and "position" in msg and "t=" in msg
    assert not (tmp_path / "l").exists()


COARSE_LINE = """
name = "coarse_line"
description = "200iC welding the table's line seam with via points 1 s apart"
robot = "lrmate200ic5l"
cell = "weld_table"
tool = "mig_torch"
[[actions]]
action = "arc_on"
phase = "weld"
[[actions]]
action = "arc_off"
phase = "weld"
at = "end"
[[phases]]
name = "ready"
planner = "434"
time_s = [0.0, 1.0, 2.0]
joints_deg = [[0,0,0,0,-90,0],[-15,4,-25,0,-75,0],[-30,8,-50,0,-45,0]]
[[phases]]
name = "to_line"
planner = "434"
durations_s = [2.0]
to_seam = "line"
[[phases]]
name = "weld"
kind = "linear"
seam = "line"
orientation = "seam"
speed_mm_s = 40.0
sample_period_s = 1.0
"""


def test_path_deviation_metric_against_the_line(tmp_path, monkeypatch):
    """Via points 40 mm apart, not halved where the polynomial leaves the move (a planted
    fault: :data:`~sim.simulation.motion.sampling.PATH_REFINEMENTS` 0): the joint polynomial
    leaves the straight seam between them. The summary's max_path_deviation_mm equals the
    largest distance of the recorded tool point from the seam's line (computed here from the
    cell's seam end points)."""
    from sim.cells import CELLS, build_cell
    from sim.cells.tools import TOOLS
    from sim.robots.registry import ROBOTS
    from sim.simulation.motion import sampling

    monkeypatch.setattr(sampling, "PATH_REFINEMENTS", 0)

    s = _run(parse_scenario(COARSE_LINE, source="coarse.toml"), tmp_path / "c")
    (weld,) = s["weld"]
    a = np.load(tmp_path / "c" / "trajectory.npz")
    seam = build_cell(CELLS["weld_table"], ROBOTS["lrmate200ic5l"],
                      tool=TOOLS["mig_torch"]).seams["line"]
    p0, p1 = seam.points
    u = (p1 - p0) / np.linalg.norm(p1 - p0)
    p = a["tcp_pos"][a["arc_on"]] - p0
    dist = np.linalg.norm(p - np.outer(p @ u, u), axis=1)
    assert weld["max_path_deviation_mm"] > 0.01, "coarse via points must show a deviation"
    assert weld["max_path_deviation_mm"] == pytest.approx(dist.max() * 1e3, rel=0.02, abs=2e-3)


def test_singularity_summary_sees_the_wrist_singularity(tmp_path):
    """A 200iC phase passing through theta5 = 0 (seed 004 eq. 23: det J = 0) is reported as the
    closest approach to a singularity, at that time; a phase far from it is not."""
    text = scenario_text("lrmate200ic5l", [
        joint_phase([[0, 0, 0, 0, -30, 0], [0, 0, 0, 0, 0, 0], [0, 0, 0, 0, 30, 0]],
                    name="through", time_s=[0.0, 0.5, 1.0]),
        joint_phase([[0, 10, -20, 0, 45, 0], [0, 20, -40, 0, 60, 0]], name="away",
                    durations_s=[0.5, 0.5]),
    ], name="wrist", description="theta5 through zero")
    s = _run(parse_scenario(text, source="w.toml"), tmp_path / "w")
    sing = s["singularity"]
    assert sing["phase"] == "through" and sing["t"] == pytest.approx(0.5, abs=0.011)
    assert sing["min_abs_wrist"] < 1e-3 and sing["min_sigma"] < 1e-3


def test_csv_only_when_asked_and_record_hz_thins_the_saved_arrays(tmp_path):
    """Without ``csv`` no trajectory.csv; ``simulation.record_hz = 100`` keeps every 10th
    step of the 1 kHz record (and the last), while the summary's figures come from every
    step: the same as a full-rate run's."""
    import dataclasses

    from sim.scenario import load_scenario
    from sim.simulation.runfolder import load_run

    sc = load_scenario("bugnar_5r_phase1")
    full = _run(sc, tmp_path / "full")
    thin_sc = dataclasses.replace(sc, simulation=sc.simulation.model_copy(
        update={"record_hz": 100.0}))
    thin = _run(thin_sc, tmp_path / "thin")
    assert not (tmp_path / "full" / "trajectory.csv").exists()
    n_full = load_run(tmp_path / "full").t.size
    rec = load_run(tmp_path / "thin")
    assert rec.t.size == (n_full - 1) // 10 + 1 + (0 if (n_full - 1) % 10 == 0 else 1)
    assert thin["record_hz"] == pytest.approx(100.0)
    assert full["record_hz"] == pytest.approx(1000.0)
    assert thin["max_tracking_error_deg"] == full["max_tracking_error_deg"]
    assert thin["verdict"] == full["verdict"]
