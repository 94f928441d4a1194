"""Link inertials as data (issue 26): ``[[links]]`` in robot.toml, the KUKA KR 6 R900-2's
published-by-a-source inertials, and reports that mark the joints whose torques rest on
estimates.

* The shipped KR 6's model, built from its ``[[links]]`` (carried from kroshu's description of
  the arm into the ROS-Industrial frames cellsim uses), gives the same inverse dynamics as
  pinocchio's RNEA on kroshu's own URDF: a second engine on the source's numbers, in the
  source's frames. A 1 % error planted in one link's mass is caught.
* A user's robot folder with ``[[links]]`` (explicit inertials and mass-only capsules) compiles
  to bodies with exactly the file's numbers; mistakes are one line naming ``links[i]``.
* The joints whose torques rest on estimates are named in sizing.md, report.html and
  sizing.json.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
KR6 = ROOT / "models" / "kuka_kr6r900_2"


def _mujoco_rigid_body_torques(model: mujoco.MjModel, q, qd, qdd) -> np.ndarray:
    """MuJoCo's continuous-time inverse dynamics of the robot's bodies alone (armature,
    damping and friction removed), N m."""
    m = model
    m.dof_armature[:] = 0.0
    m.dof_damping[:] = 0.0
    m.dof_frictionloss[:] = 0.0
    m.opt.enableflags &= ~int(mujoco.mjtEnableBit.mjENBL_INVDISCRETE)  # continuous time
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:], d.qacc[:] = q, qd, qdd
    mujoco.mj_inverse(m, d)
    return d.qfrc_inverse.copy()


def _pinocchio_torques(pin, model, q, qd, qdd) -> np.ndarray:
    data = model.createData()
    return np.asarray(pin.rnea(model, data, q, qd, qdd)).copy()


@pytest.fixture(scope="module")
def kroshu():
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(KR6 / "kr6_r900_2_kroshu.urdf"))
    assert [model.names[i] for i in range(1, model.njoints)] == [f"joint_{i}" for i in range(1, 7)]
    return pin, model


def _samples(n: int = 40):
    from sim.robots.registry import resolve_robot

    spec = resolve_robot("kr6r900_2")
    mj = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    lo, hi = mj.jnt_range[:6].T
    rng = np.random.default_rng(26)
    return mj, [(rng.uniform(lo, hi), rng.uniform(-3, 3, 6), rng.uniform(-20, 20, 6))
                for _ in range(n)]


def test_the_kr6_model_has_the_dynamics_of_its_sources_urdf(kroshu):
    """MuJoCo on the shipped model (its inertials from robot.toml's [[links]]) and pinocchio on
    kroshu's URDF agree to 1e-9 of each joint's largest torque, at 40 random states; the moving
    mass is the source's, 38.244 kg."""
    pin, model = kroshu
    mj, states = _samples()
    moving = sum(float(mj.body_mass[mj.body(f"link{i}").id]) for i in range(1, 7))
    assert moving == pytest.approx(sum(model.inertias[i].mass for i in range(1, 7)), rel=1e-12)
    assert moving == pytest.approx(38.24355262, rel=1e-9)
    ours = np.array([_mujoco_rigid_body_torques(mj, *s) for s in states])
    theirs = np.array([_pinocchio_torques(pin, model, *s) for s in states])
    scale = np.abs(theirs).max(axis=0)
    assert np.all(scale > 0.005)
    np.testing.assert_allclose(ours, theirs, atol=1e-9 * scale.max())


def test_a_planted_one_percent_mass_error_is_caught(kroshu):
    """The comparison above is not blind: with link 3's mass 1 % off in pinocchio's model, the
    torques differ by far more than its tolerance."""
    pin, model = kroshu
    bad = model.copy()
    inertia = bad.inertias[3]
    bad.inertias[3] = pin.Inertia(inertia.mass * 1.01, inertia.lever, inertia.inertia)
    mj, states = _samples(10)
    ours = np.array([_mujoco_rigid_body_torques(mj, *s) for s in states])
    theirs = np.array([_pinocchio_torques(pin, bad, *s) for s in states])
    assert np.abs(ours - theirs).max() > 1e-4 * np.abs(theirs).max()


def test_the_kr6_links_are_what_their_derivation_script_prints():
    """robot.toml's [[links]] are the output of links_from_kroshu.py (the README's derivation),
    which refuses two URDFs that are not the same arm."""
    out = subprocess.run([sys.executable, str(KR6 / "links_from_kroshu.py")], capture_output=True,
                         text=True, check=True).stdout
    assert out.strip() and out in (KR6 / "robot.toml").read_text()


# ---------------------------------------------------------------------------- a user's folder
DH_TOML = """
name = "arm3"
[kinematics]
convention = "dh"
dh = [[0, 90, 300, 0], [400, 0, 0, 0], [300, 0, 0, 0]]
[joints]
range_deg = [[-170, 170], [-120, 120], [-150, 150]]
max_speed_deg_s = [180, 180, 180]
[mass]
payload_kg = 2.0
{links}
""" + "\n".join(["""[[drives]]
gear_ratio = 100
efficiency = 0.8
rotor_inertia_kg_m2 = 5e-5
rated_torque_nm = 2.0
peak_torque_nm = 6.0
max_speed_rpm = 5000"""] * 3)

LINKS = """
[[links]]
mass_kg = 6.0
com_mm = [0, -120, 10]
inertia_kg_m2 = [0.05, 0.04, 0.03, 0.001, 0.0, -0.002]
source = "test"
[[links]]
mass_kg = 4.5
[[links]]
mass_kg = 2.5
com_mm = [-140, 5, 0]
inertia_kg_m2 = [0.004, 0.02, 0.021, 0.0, 0.0005, 0.0]
"""


def _folder(tmp_path: Path, links: str) -> Path:
    folder = tmp_path / "arm3"
    folder.mkdir(exist_ok=True)
    (folder / "robot.toml").write_text(DH_TOML.replace("{links}", links))
    return folder


def test_links_of_a_robot_folder_are_the_bodies_of_its_model(tmp_path, monkeypatch):
    """Explicit links compile to the file's mass, centre of mass and inertia tensor (MuJoCo's
    principal axes rotated back); a mass-only link is a capsule of that mass; the joints at
    and before that estimated link are the ones whose torques rest on an estimate."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    from sim.robots.registry import resolve_robot

    spec = resolve_robot(str(_folder(tmp_path, LINKS)))
    m = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    for i, (mass, com, full) in {
            0: (6.0, [0, -0.120, 0.010], [0.05, 0.04, 0.03, 0.001, 0.0, -0.002]),
            2: (2.5, [-0.140, 0.005, 0], [0.004, 0.02, 0.021, 0.0, 0.0005, 0.0])}.items():
        b = m.body(f"link{i + 1}").id
        assert m.body_mass[b] == pytest.approx(mass, rel=1e-9)
        np.testing.assert_allclose(m.body_ipos[b], com, atol=1e-9)
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, m.body_iquat[b])
        R = R.reshape(3, 3)
        inertia = R @ np.diag(m.body_inertia[b]) @ R.T
        ixx, iyy, izz, ixy, ixz, iyz = full
        np.testing.assert_allclose(inertia, [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]],
                                   atol=1e-9)
    assert m.body_mass[m.body("link2").id] == pytest.approx(4.5, rel=1e-6)
    assert spec.estimated_links == (False, True, False)
    assert spec.joints_on_estimates == ("j1", "j2")


@pytest.mark.parametrize("links,needle", [
    (LINKS.replace("com_mm = [0, -120, 10]\n", ""), "links[0]: give com_mm and inertia_kg_m2"),
    (LINKS.replace("[0.05, 0.04, 0.03,", "[0.05, 0.01, 0.03,"),
     "links[0].inertia_kg_m2: inertia is not physical"),
    (LINKS.split("[[links]]\nmass_kg = 2.5")[0], "links: 2 [[links]] for 3 moving links"),
    (LINKS.replace("mass_kg = 4.5", "mass_kg = -1"), "links[1].mass_kg: must be between 1e-06 and"),
    (LINKS + "\n", None),
])
def test_bad_links_are_one_line_naming_the_entry(links, needle, tmp_path, monkeypatch):
    """``cellsim check`` of a scenario on the folder: exit 2 and one line naming the entry;
    the well-formed file passes the load (a control)."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    _folder(tmp_path, links)
    scenario = tmp_path / "s.toml"
    scenario.write_text('name = "arm3_move"\ndescription = "a move"\nrobot = "./arm3"\n'
                        '[[phases]]\nname = "move"\nplanner = "434"\ntime_s = [0.0, 1.0, 2.0]\n'
                        'joints_deg = [[0, 30, -30], [10, 40, -40], [20, 50, -50]]\n')
    r = subprocess.run([sys.executable, "-m", "sim", "check", str(scenario)],
                       capture_output=True, text=True, cwd=ROOT, check=False)
    if needle is None:
        assert r.returncode in (0, 1) and "Traceback" not in r.stderr, r.stderr
        return
    assert r.returncode == 2, r.stderr
    line = r.stderr.strip()
    assert "\n" not in line and needle in line, line


def test_total_mass_and_links_together_are_refused(tmp_path):
    from sim.errors import KinematicsError
    from sim.robots.robotfile import load_robot_folder

    folder = _folder(tmp_path, LINKS)
    text = (folder / "robot.toml").read_text().replace("payload_kg = 2.0",
                                                       "payload_kg = 2.0\ntotal_kg = 13")
    (folder / "robot.toml").write_text(text)
    with pytest.raises(KinematicsError, match="give \\[\\[links\\]\\] or mass.total_kg"):
        load_robot_folder(folder)


# ---------------------------------------------------------------------------- the reports
def test_the_reports_name_the_joints_whose_torques_rest_on_estimates(scenario_run):
    """The LR Mate's MJCF inertials are estimates ([mass] estimated = true): sizing.md,
    report.html and sizing.json name all six joints."""
    out, _ = scenario_run("lrmate200ic_weld_plate")
    doc = json.loads((out / "sizing.json").read_text())
    joints = [f"j{i}" for i in range(1, 7)]
    assert doc["inertia_estimated_joints"] == joints
    sentence = f"The torques of {', '.join(joints)} rest on estimated link inertials"
    assert sentence in (out / "sizing.md").read_text()
    # where to look, for a shipped robot and one's own folder (which has no README)
    assert "its README, or its robot.toml's [mass] and [[links]]" in (
        out / "sizing.md").read_text()
    assert sentence in (out / "report.html").read_text()
