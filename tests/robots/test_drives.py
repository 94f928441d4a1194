"""One drive everywhere (issue 26): the drive a joint really has, from whichever source (the
shipped robot's defaults, a robot folder's ``[[drives]]``, a scenario's ``[drives.jN]``
override), sets the compiled model's force range and armature, the simulated clamp and the
torque range sizing checks against.

The oracle is the input's own numbers: peak motor torque x gear ratio x efficiency, and
``J_r N^2``, computed here from the values the test writes or the robot's published table.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.limits import run_limited
from support.scenarios import joint_phase, write_scenario

from sim.pipeline.run import RunOptions, evaluate_scenario
from sim.scenario import load_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
#: The 5R's J2 drive (models/robot_5r/README.md): peak motor torque N m, ratio, efficiency,
#: rotor inertia kg m^2.
J2_5R = (46.0, 160.0, 0.8, 2.3e-3)

UR5_TOML = """name = "ur5_drives"
description = "a UR5-like DH arm with its own drives"
[kinematics]
convention = "dh"
dh = [[0.0, 90.0, 89.159, 0.0], [-425.0, 0.0, 0.0, 0.0], [-392.25, 0.0, 0.0, 0.0],
      [0.0, 90.0, 109.15, 0.0], [0.0, -90.0, 94.65, 0.0], [0.0, 0.0, 82.3, 0.0]]
[joints]
range_deg = [[-360, 360], [-360, 360], [-180, 180], [-360, 360], [-360, 360], [-360, 360]]
max_speed_deg_s = [180, 180, 180, 180, 180, 180]
[mass]
total_kg = 18
payload_kg = 5
""" + "".join(f"""[[drives]]
gear_ratio = {r}
efficiency = {e}
rotor_inertia_kg_m2 = {i}
rated_torque_nm = {t}
peak_torque_nm = {p}
max_speed_rpm = 6000
""" for r, e, i, t, p in ((101, 0.75, 2e-5, 0.8, 3.0), (121, 0.7, 4.5e-5, 1.6, 5.0),
                          (101, 0.75, 2e-5, 0.8, 3.0), (81, 0.8, 5e-6, 0.3, 1.0),
                          (81, 0.8, 5e-6, 0.3, 1.0), (51, 0.85, 5e-6, 0.3, 1.0)))
UR5_DRIVES = ((101, 0.75, 2e-5, 3.0), (121, 0.7, 4.5e-5, 5.0), (101, 0.75, 2e-5, 3.0),
              (81, 0.8, 5e-6, 1.0), (81, 0.8, 5e-6, 1.0), (51, 0.85, 5e-6, 1.0))


def model_drive(ev, joint: int) -> tuple[float, float]:
    """The compiled model's (as written to model.xml) force range and armature of a joint."""
    m = mujoco.MjModel.from_xml_string(ev.built.xml)
    a = int(ev.built.robot_act[joint])
    dof = int(ev.built.robot_dof[joint])
    lo, hi = m.actuator_forcerange[a] * m.actuator_gear[a, 0]
    assert lo == pytest.approx(-hi)
    return float(hi), float(m.dof_armature[dof])


def run(path: Path):
    return evaluate_scenario(load_scenario(path), RunOptions(video=False, plots=False,
                                                             progress=False))


def five_r(tmp_path: Path, override: str = "") -> Path:
    text = (SCENARIOS / "bugnar_5r_phase1.toml").read_text()
    path = tmp_path / "s.toml"
    path.write_text(text + "\n" + override)
    return path


def ur5(tmp_path: Path) -> Path:
    """A joint move of a robot folder's arm (:data:`UR5_TOML` as ``robots/ur5``)."""
    (tmp_path / "robots" / "ur5").mkdir(parents=True)
    (tmp_path / "robots" / "ur5" / "robot.toml").write_text(UR5_TOML)
    return write_scenario(tmp_path, "robots/ur5", [joint_phase(
        [[0, -90, 90, -90, -90, 0], [20, -80, 80, -80, -80, 10], [40, -70, 70, -70, -70, 20]])],
        name="ur5_move", description="a joint move of a robot folder's arm")


@pytest.mark.parametrize("source", ["robot defaults", "robot folder", "scenario override"])
def test_the_drive_a_joint_has_sets_the_model_the_clamp_and_sizing(tmp_path, source):
    """Each source of a drive: model.xml's force range and armature, the simulated torque
    limit (``tau_limit``), the actuator's clamped force and sizing's torque range are the
    drive's."""
    if source == "robot defaults":
        path, joint, (peak, ratio, eta, rotor) = five_r(tmp_path), 1, J2_5R
    elif source == "robot folder":
        (ratio, eta, rotor, peak), joint = UR5_DRIVES[1], 1
        path = ur5(tmp_path)
    else:  # a twentieth of the 5R's J2 peak and another rotor: the arm sags under gravity
        peak, ratio, eta, rotor = J2_5R[0] / 20, J2_5R[1], J2_5R[2], 1.0e-3
        path, joint = five_r(tmp_path, f"[drives.j2]\npeak_torque_nm = {peak}\n"
                                       f"rated_torque_nm = {peak / 2}\n"
                                       f"rotor_inertia_kg_m2 = {rotor}\n"), 1
    limit = peak * ratio * eta
    ev = run(path)
    got_limit, got_armature = model_drive(ev, joint)
    assert got_limit == pytest.approx(limit, rel=1e-9)
    assert got_armature == pytest.approx(rotor * ratio**2, rel=1e-9)
    a = ev.record.arrays
    # the simulated clamp is the drive's motor: its torque, recomputed here from the recorded
    # joint torque, speed and acceleration with the file's numbers (the gear's efficiency on
    # the load torque in the direction power flows, the rotor's inertia on the motor side),
    # never passes the motor's peak at its speed (flat to 70 % of its top speed, then falling
    # to the rated torque at the top speed, 0 beyond)
    tau, qd, qdd = (a[k][:, joint] for k in ("tau", "qd", "qdd"))
    load = tau - rotor * ratio**2 * qdd
    motor = np.where((load * qd >= 0) | (np.abs(qd) < 1e-3), load / (ratio * eta),
                     load * eta / ratio) + \
        rotor * ratio * qdd
    rpm = np.abs(qd) * ratio * 60 / (2 * np.pi)
    if source == "scenario override":  # the 5R's J2: a 4000 rpm motor, rated = peak / 2
        top, rated = 4000.0, peak / 2
        curve = np.where(rpm <= 0.7 * top, peak,
                         np.where(rpm <= top, peak + (rated - peak) * (rpm - 0.7 * top)
                                  / (0.3 * top), 0.0))
        assert np.all(np.abs(motor) <= curve + 1e-9 * peak), np.max(np.abs(motor) - curve)
    else:
        assert np.abs(motor).max() <= peak * (1 + 1e-9)
        assert np.abs(a["tau_actuator"][:, joint]).max() <= limit * (1 + 1e-9)
    sized = {j["joint"]: j for j in ev.sizing.to_dict()["joints"]}
    name = list(sized)[joint]
    assert sized[name]["torque_range_nm"] == pytest.approx([-limit, limit], rel=1e-9)
    reported = sized[name]["motor_side"]["sim"]["peak_torque"]
    assert reported <= peak * (1 + 1e-9)  # sizing reports what the simulation's motor gave
    if source == "scenario override":  # the arm cannot be held: a saturated drive fails
        assert reported == pytest.approx(peak, rel=1e-8)
        assert ev.summary["verdict"] == "fail"
        assert "saturation" in {c["name"] for c in ev.summary["checks"] if not c["pass"]}


def test_a_drive_that_cannot_hold_the_arm_is_refused_with_its_numbers(tmp_path):
    """A robot folder whose J2 drive is far too weak: one line naming the joint, the torque it
    must hold (gravity and friction, recomputed here with MuJoCo at the configuration the
    message names), what the drive gives (peak x ratio x efficiency from the file's numbers)
    and the motor peak that would hold it; exit 2."""
    import re
    import sys

    weak = UR5_TOML.replace("rated_torque_nm = 1.6\npeak_torque_nm = 5.0",
                            "rated_torque_nm = 0.1\npeak_torque_nm = 0.2")
    assert weak != UR5_TOML
    path = ur5(tmp_path)
    (tmp_path / "robots" / "ur5" / "robot.toml").write_text(weak)
    r = run_limited([sys.executable, "-m", "sim", "check", str(path)], capture_output=True,
                       text=True, cpu_s=600)
    assert r.returncode == 2, r.stderr
    line = r.stderr.strip()
    assert "\n" not in line and "Traceback" not in line, line
    m = re.search(r"j2 needs up to ([\d.e+-]+) N m .*at \[([-\d, ]+)\] deg\) where its drive "
                  r"gives ([\d.e+-]+) N m .*a motor peak of at least ([\d.e+-]+) N m", line)
    assert m, line
    need, gives, motor = float(m.group(1)), float(m.group(3)), float(m.group(4))
    assert gives == pytest.approx(0.2 * 121 * 0.7, rel=1e-3)
    assert need > gives and motor == pytest.approx(need / (121 * 0.7), rel=1e-3)
    # the torque to hold at that configuration: the arm's gravity (the same geometry and
    # masses with the file's own drives, generated by cellsim) plus the rated payload's, 5 kg
    # at the tool point through its Jacobian, plus J2's friction
    from sim.robots.registry import resolve_robot

    (tmp_path / "ok" / "ur5").mkdir(parents=True)
    (tmp_path / "ok" / "ur5" / "robot.toml").write_text(UR5_TOML)
    spec = resolve_robot(str(tmp_path / "ok" / "ur5"))
    model = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    data = mujoco.MjData(model)
    q = np.radians([float(v) for v in m.group(2).split(",")])
    ids = [model.joint(j).id for j in spec.joints]
    data.qpos[[model.jnt_qposadr[i] for i in ids]] = q
    mujoco.mj_forward(model, data)
    dof = model.jnt_dofadr[ids[1]]
    jp = np.zeros((3, model.nv))
    mujoco.mj_jacSite(model, data, jp, None, model.site("tcp").id)
    payload = -(jp.T @ (5.0 * model.opt.gravity))[dof]
    held = abs(data.qfrc_bias[dof] + payload) + model.dof_frictionloss[dof]
    assert need == pytest.approx(held, rel=2e-3), (need, held)
    # and the lightest pair of the starter catalogue that would pass the check, chosen here
    # from the catalogue file's own numbers
    import tomllib

    from sim.analysis.catalog import starter_catalog

    cat = tomllib.loads(starter_catalog().read_text())
    fits = [(m["mass_kg"] + r["mass_kg"], m["id"], r["id"]) for m in cat["motors"]
            for r in cat["reducers"]
            if m["peak_torque_nm"] * r["ratio"] * r["efficiency"] >= need * (1 + 1e-4)
            and r["repeated_peak_torque_nm"] >= need * (1 + 1e-4)]
    _, motor_id, reducer_id = min(fits)
    assert f"the lightest pair of the starter catalogue that would hold it: j2: {motor_id} + " \
           f"{reducer_id} (" in line, line


@given(st.floats(0.05, 50.0), st.floats(10.0, 200.0), st.floats(0.5, 1.0),
       st.floats(0.0, 1e-3), st.floats(-50.0, 50.0), st.floats(-5.0, 5.0),
       st.floats(-500.0, 500.0), st.floats(0.0, 30.0))
@settings(max_examples=300, deadline=None)
def test_the_joint_torque_a_motor_gives_is_the_inverse_of_its_motor_torque(
        peak, ratio, eta, rotor, tau_m, qd, qdd, armature):
    """The simulation holds a saturated drive at ``joint_torque_for(peak)``: its motor torque
    (the formula sizing uses) is then exactly the peak, in both directions of power flow."""
    from sim.robots.registry import Drive

    d = Drive(ratio, eta, rotor, peak / 2, peak, 4000.0)
    f = d.joint_torque_for(tau_m, qd, qdd, armature)
    assert float(d.motor_torque(f, qd, qdd, armature)) == pytest.approx(tau_m, abs=1e-9 * (
        1 + abs(tau_m) + rotor * ratio * abs(qdd) + armature * abs(qdd) / ratio))


OVERLOADED = """
name = "overloaded"
description = "the LR Mate 200iC/5L with 40 times its rated payload"
robot = "lrmate200ic5l"
tool = "mig_torch"
payload_kg = {payload}

[[phases]]
name = "lift"
planner = "434"
time_s = [0.0, 0.5, 1.0]
joints_deg = [[0, 0, 0, 0, -90, 0], [0, 5, -5, 0, -90, 0], [0, 10, -10, 0, -90, 0]]

[[phases]]
name = "rest"
kind = "hold"
duration_s = 0.3
"""


def test_an_arm_its_drives_cannot_move_is_a_failed_result_not_an_error(tmp_path, capsys):
    """Issue 31: 200 kg on a 5 kg arm stopped the run with "the drives' motor torque limit did
    not settle ...; try a smaller timestep" (the arm falls, its motors past their top speed
    have 0 N m to give, which the per-step solve approached within 1e-8 of a peak, not 1e-9).
    The run now completes and its verdict fails on the payload, the saturated drives and the
    tracking; a payload of 1e308 kg is refused naming the key."""
    import json

    from sim.cli import main

    (tmp_path / "s.toml").write_text(OVERLOADED.format(payload=200.0))
    rc = main(["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "r"), "--no-video",
               "--no-plots", "--quiet", "--strict"])
    err = capsys.readouterr().err
    assert rc == 1, err
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    failed = {c["name"] for c in summary["checks"] if not c["pass"]}
    assert {"payload", "saturation", "tracking"} <= failed
    a = np.load(tmp_path / "r" / "trajectory.npz")
    # the arm really fell: J2's tracking error, from the recorded joint states, passes 10 deg
    assert np.degrees(np.max(np.abs(a["q"][:, 1] - a["q_ref"][:, 1]))) > 10.0
    # each joint's range check is how far the recorded q went past the range MuJoCo compiles
    # from the robot's MJCF (a fallen arm lies on a hard stop)
    import mujoco

    from sim.robots.registry import get_robot

    model = mujoco.MjModel.from_xml_path(str(get_robot("lrmate200ic5l").robot_path))
    ranges = {c["joint"]: c for c in summary["checks"] if c["name"] == "range"}
    for k, j in enumerate(summary["joints"]):
        lo, hi = model.joint(j).range
        past = max(0.0, np.degrees(max(a["q"][:, k].max() - hi, lo - a["q"][:, k].min())))
        assert ranges[j]["value"] == pytest.approx(past, abs=1e-9)
        assert ranges[j]["pass"] == (past <= ranges[j]["limit"])
    (tmp_path / "s.toml").write_text(OVERLOADED.format(payload=1e308))
    assert main(["check", str(tmp_path / "s.toml")]) == 2
    assert capsys.readouterr().err.strip().endswith(
        "s.toml: payload_kg: must be less than or equal to 10000")
