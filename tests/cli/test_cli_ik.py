"""`cellsim ik` and `cellsim workspace`: outputs, JSON shape, exit codes, bad input."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest
from support.limits import run_limited

from sim.cli import main
from sim.core.rotations import euler_zyx_to_matrix, matrix_to_euler_zyx
from sim.robots.kinematics.model import closed_form_model, kinematic_model
from sim.robots.registry import ROBOTS

ALL_ROBOTS = sorted(ROBOTS)
REPO = Path(__file__).resolve().parents[2]


def _run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _pose_args(name: str, q: np.ndarray) -> list[str]:
    T = kinematic_model(ROBOTS[name]).fk(q)
    a, b, g = np.rad2deg(matrix_to_euler_zyx(T[:3, :3]))
    return [*(f"{v:.12f}" for v in 1e3 * T[:3, 3]), "--euler-zyx-deg",
            *(f"{v:.12f}" for v in (a, b, g))]


@pytest.mark.parametrize("name", ALL_ROBOTS)
def test_ik_json_round_trip(capsys, name):
    m = kinematic_model(ROBOTS[name])
    q = np.deg2rad([10.0, 20.0, -15.0, 25.0, 30.0, 40.0][: m.n_joints])
    code, out, err = _run(capsys, "ik", name, *_pose_args(name, q), "--all", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert set(doc) == {"robot", "tool", "solutions"} and doc["robot"] == name
    assert doc["tool"] is None
    assert len(doc["solutions"]) >= 2
    for s in doc["solutions"]:
        assert set(s) == {"joints_deg", "within_limits"}
        assert isinstance(s["within_limits"], bool) and len(s["joints_deg"]) == m.n_joints
        np.testing.assert_allclose(m.fk(np.deg2rad(s["joints_deg"])), m.fk(q), atol=1e-9)
    # the source configuration is among them, and they are ranked as --help says: inside the
    # ranges first, then closest to home (q = 0; joint distance weighted by 1/max speed, as
    # sqrt(sum(((q - home) / v_max)^2)))
    sols = np.array([s["joints_deg"] for s in doc["solutions"]])
    assert np.abs(sols - np.rad2deg(q)).max(axis=1).min() < 1e-6
    inside = [s["within_limits"] for s in doc["solutions"]]
    assert inside == sorted(inside, reverse=True)
    dist = np.linalg.norm(np.deg2rad(sols) / np.asarray(ROBOTS[name].max_speed), axis=1)
    n_in = sum(inside)
    assert np.all(np.diff(dist[:n_in]) >= -1e-9), dist
    # without --all only the best one
    code, out, _ = _run(capsys, "ik", name, *_pose_args(name, q), "--json")
    assert code == 0 and len(json.loads(out)["solutions"]) == 1


def test_ik_text_seed000_table2_point1(capsys):
    """Seed 000 Table 2 point 1 -> Table 3 row 1 (q2 28.79, q3 -1.2, q4 2.41 deg, within 0.35)."""
    code, out, err = _run(capsys, "ik", "lrmate100ib", "660.56", "0", "5.17",
                          "--euler-zyx-deg", "0", "30", "0")
    assert code == 0, err
    line = [ln for ln in out.splitlines() if ln.strip().startswith("1:")][0]
    q = [float(v) for v in line.split(":")[1].split()[:5]]
    np.testing.assert_allclose(q, [0.0, 28.79, -1.2, 2.41, 0.0], atol=0.35)
    assert "within limits" in line
    assert err == ""


def test_ik_5axis_disagreeing_alpha_note(capsys):
    m = kinematic_model(ROBOTS["lrmate100ib"])
    q = np.deg2rad([30.0, 20.0, -10.0, 15.0, 5.0])
    T = m.fk(q)
    x, y, z = 1e3 * T[:3, 3]
    code, out, err = _run(capsys, "ik", "lrmate100ib", f"{x}", f"{y}", f"{z}",
                          "--euler-zyx-deg", "0", "25", "5", "--json")
    assert code == 0
    assert err.count("\n") == 1 and "implied by the position" in err and "30.000" in err
    best = np.deg2rad(json.loads(out)["solutions"][0]["joints_deg"])
    np.testing.assert_allclose(m.fk(best), T, atol=1e-9)
    # a consistent A gives no note
    code, out, err = _run(capsys, "ik", "lrmate100ib", f"{x}", f"{y}", f"{z}",
                          "--euler-zyx-deg", "30", "25", "5")
    assert code == 0 and err == ""


def test_ik_default_orientation_is_home(capsys):
    m = kinematic_model(ROBOTS["lrmate200ic5l"])
    p = 1e3 * m.fk(np.zeros(6))[:3, 3]
    code, out, err = _run(capsys, "ik", "lrmate200ic5l", *(f"{v:.9f}" for v in p), "--json")
    assert code == 0
    q = np.deg2rad(json.loads(out)["solutions"][0]["joints_deg"])
    np.testing.assert_allclose(q, 0.0, atol=1e-9)
    assert "wrist singularity" in err  # home has theta5 = 0


@pytest.mark.parametrize("argv, needle", [
    (["ik", "lrmate300", "1", "2", "3"], "lrmate100ib, lrmate200ic5l, m10ia, m20ia, robot_5r"),
    (["ik", "robot_5r", "1", "2", "nan"], "Z must be a finite number"),
    (["ik", "robot_5r", "1", "2", "3", "--euler-zyx-deg", "0", "inf", "0"], "B must be a finite"),
    (["ik", "lrmate200ic5l", "2000", "0", "300"], "mm outside"),
    (["workspace", "robot_6r"], "unknown robot"),
    (["workspace", "robot_5r", "--out", "picture.jpg"], ".png"),
])
def test_bad_input_exit_2(capsys, argv, needle):
    code, out, err = _run(capsys, *argv)
    assert code == 2
    assert needle in err and err.count("\n") == 1 and out == ""


@pytest.mark.parametrize("argv", [["ik", "robot_5r", "1", "2"],
                                  ["ik", "robot_5r", "1", "2", "3", "4"],
                                  ["ik", "robot_5r", "1", "2", "x"],
                                  ["ik", "robot_5r", "1", "2", "3", "--euler-zyx-deg", "1", "2"]])
def test_wrong_number_of_values_argparse_exit_2(capsys, argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2


def test_python_m_sim_ik_subprocess():
    env = dict(os.environ, PYTHONPATH=str(REPO))
    ok = run_limited([sys.executable, "-m", "sim", "ik", "lrmate100ib", "428.36", "0",
                         "-426.53", "--euler-zyx-deg", "0", "90", "0", "--json"],
                        capture_output=True, text=True, cwd=REPO, env=env, cpu_s=120)
    assert ok.returncode == 0, ok.stderr
    doc = json.loads(ok.stdout)
    q = doc["solutions"][0]["joints_deg"]
    # seed 000 Table 3 row 3: q2 86.38, q3 -3.62, q4 7.24
    np.testing.assert_allclose(q, [0.0, 86.38, -3.62, 7.24, 0.0], atol=0.35)
    bad = run_limited([sys.executable, "-m", "sim", "ik", "nosuchrobot", "1", "2", "3"],
                         capture_output=True, text=True, cwd=REPO, env=env, cpu_s=120)
    assert bad.returncode == 2 and "known: " in bad.stderr
    assert all(name in bad.stderr for name in ROBOTS)
    bad = run_limited([sys.executable, "-m", "sim", "ik", "robot_5r", "1"],
                         capture_output=True, text=True, cwd=REPO, env=env, cpu_s=120)
    assert bad.returncode == 2


def test_workspace_png_and_reach(capsys, tmp_path):
    out_png = tmp_path / "ws.png"
    code, out, err = _run(capsys, "workspace", "lrmate200ic5l", "--out", str(out_png))
    assert code == 0, err
    data = out_png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000
    line = [ln for ln in out.splitlines() if "wrist centre" in ln][0]
    reach_mm = float(line.split(":")[1].split("mm")[0])
    # seed 004 Table 2: reach 892 mm = d2 + d3 + sqrt(R4^2 + d4^2) (the ranges allow it)
    assert reach_mm == pytest.approx(892.0, abs=0.5)


def test_workspace_replaces_its_own_picture_and_refuses_anyone_elses(capsys, tmp_path):
    """``--out`` over a file: a picture ``cellsim workspace`` wrote (its PNG's Software text) is
    replaced, as a second run of the same command does; any other file, a copy of such a
    picture at another place included, is refused in one line and left as it was (both were
    overwritten: found by new-user trials); the pictures take the umask's mode."""
    import os

    out_png = tmp_path / "ws.png"
    for _ in range(2):
        code, _out, err = _run(capsys, "workspace", "robot_5r", "--out", str(out_png))
        assert code == 0, err
    assert oct(out_png.stat().st_mode & 0o777) == oct(0o666 & ~_umask())
    precious = tmp_path / "mine.png"
    precious.write_text("my precious")
    code, _out, err = _run(capsys, "workspace", "robot_5r", "--out", str(precious))
    assert code == 2 and precious.read_text() == "my precious"
    assert err.strip().splitlines() == [
        f"cellsim: error: --out: {str(precious)!r} exists and cellsim workspace did not write "
        "it; name a new .png file (or remove it)"]
    other = tmp_path / "plot.png"  # a PNG someone else drew: refused too
    other.write_bytes(out_png.read_bytes().replace(b"cellsim workspace", b"matplotlib v3.9.0"))
    assert _run(capsys, "workspace", "robot_5r", "--out", str(other))[0] == 2
    assert os.path.getsize(other) == os.path.getsize(out_png) + 0
    # a picture cellsim wrote, copied elsewhere, is the user's file there (it was overwritten:
    # found by a new-user trial); at its own place it is still replaced
    copied = tmp_path / "keep" / "mypic.png"
    copied.parent.mkdir()
    copied.write_bytes(out_png.read_bytes())
    code, _out, err = _run(capsys, "workspace", "robot_5r", "--out", str(copied))
    assert code == 2 and "cellsim workspace did not write it" in err
    assert copied.read_bytes() == out_png.read_bytes()
    assert _run(capsys, "workspace", "robot_5r", "--out", str(out_png))[0] == 0


def _umask() -> int:
    import os

    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def test_reach_definition_against_closed_form():
    from sim.robots.kinematics.workspace import compute_reach

    m = closed_form_model(ROBOTS["lrmate200ic5l"])
    m.lower = m.upper = None
    d = m.dims
    r = compute_reach(m)
    assert r.wrist == pytest.approx(d["d2"] + d["d3"] + np.hypot(d["R4"], d["d4"]), abs=1e-6)
    assert r.tcp == pytest.approx(r.wrist + d["R6"], abs=1e-6)
    m5 = closed_form_model(ROBOTS["robot_5r"])
    m5.lower = m5.upper = None
    d5 = m5.dims
    r5 = compute_reach(m5)
    # |J2 -> wrist|^2 = d1^2 + l2^2 - 2 d1 l2 sin q3: longest at q3 = -90 deg
    assert r5.wrist == pytest.approx(d5["l1"] + d5["d1"] + d5["l2"], abs=1e-6)
    assert r5.tcp == pytest.approx(r5.wrist + d5["l3"], abs=1e-6)
    # the configurations attain what they claim
    assert np.hypot(*m5.fk(r5.q_tcp)[:2, 3]) == pytest.approx(r5.tcp, abs=1e-9)


def test_euler_helpers_round_trip():
    rng = np.random.default_rng(0)
    for a, b, g in rng.uniform([-3, -1.5, -3], [3, 1.5, 3], size=(20, 3)):
        np.testing.assert_allclose(matrix_to_euler_zyx(euler_zyx_to_matrix(a, b, g)), [a, b, g],
                                   atol=1e-12)


@pytest.mark.parametrize("robot, tool, xyz", [
    ("lrmate200ic5l", "mig_torch", (500.0, 0.0, 300.0)),
    ("lrmate200ic5l", "vacuum_gripper", (450.0, 100.0, 200.0)),
    ("lrmate100ib", "mig_torch_long", (520.0, 0.0, 150.0)),
    ("robot_5r", "mig_torch_long", (900.0, 200.0, 300.0)),
])
def test_ik_with_a_tool_puts_the_tool_tip_there(robot, tool, xyz, capsys):
    """`cellsim ik --tool`: the answer, set on the compiled robot with that tool in MuJoCo,
    puts the tool's tcp site at X Y Z in frame 0 (an independent check of the closed form with
    the tool); without --tool, the answer puts the bare robot's tcp there."""
    import json

    import mujoco

    from sim.cells import build_cell
    from sim.cells.tools import TOOLS
    from sim.robots.registry import ROBOTS

    args = ["ik", robot, *(str(v) for v in xyz), "--json"]
    assert main([*args, "--tool", tool]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["tool"] == tool and doc["solutions"]
    def tcp_mm(tool_spec, joints_deg):
        cell = build_cell(None, ROBOTS[robot], tool=tool_spec)
        model = cell.compile()
        data = mujoco.MjData(model)
        for name, v in zip(cell.joint_names, np.deg2rad(joints_deg)):
            data.qpos[model.joint(name).qposadr[0]] = v
        mujoco.mj_kinematics(model, data)
        T0 = cell.world_from_frame0
        p_world = data.site_xpos[model.site(cell.tcp_site).id]
        return 1000.0 * (T0[:3, :3].T @ (p_world - T0[:3, 3]))

    assert np.allclose(tcp_mm(TOOLS[tool], doc["solutions"][0]["joints_deg"]), xyz, atol=1e-6)
    assert main(args) == 0
    bare = json.loads(capsys.readouterr().out)
    assert np.allclose(tcp_mm(None, bare["solutions"][0]["joints_deg"]), xyz, atol=1e-6)


def test_ik_unknown_tool_lists_the_tools(capsys):
    assert main(["ik", "lrmate200ic5l", "500", "0", "300", "--tool", "torch9"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "mig_torch" in err and "vacuum_gripper" in err


# ---------------------------------------------------------------------------- no solution
#: DH tables [a mm, alpha deg, d mm, theta offset deg]: an ortho-parallel arm (closed form,
#: OPW) and a UR5 (offset wrist: the numeric solver), Universal Robots' published table.
OPW_DH_MM = [[75, -90, 330, 0], [300, 0, 0, -90], [75, -90, 0, 0], [0, 90, 320, 0],
             [0, -90, 0, 0], [0, 0, 80, 0]]
UR5_DH_MM = [[0, 90, 89.159, 0], [-425, 0, 0, 0], [-392.25, 0, 0, 0], [0, 90, 109.15, 0],
             [0, -90, 94.65, 0], [0, 0, 82.3, 0]]


def _dh_folder(root: Path, name: str, rows: list[list[float]]) -> Path:
    folder = root / name
    folder.mkdir()
    (folder / "robot.toml").write_text(
        f'name = "{name}"\n[kinematics]\nconvention = "dh"\ndh = {rows!r}\n'
        f"[joints]\nrange_deg = {[[-170, 170]] * len(rows)!r}\n")
    return folder


@pytest.mark.parametrize("kind", ["shipped", "shipped_from_urdf", "robot_folder_opw",
                                  "dh_numeric", "bare_urdf"])
def test_a_pose_with_no_solution_exits_2_with_one_line_for_every_kind_of_robot(kind, capsys,
                                                                                tmp_path):
    """The same pose 3 m from the base, for each way of giving a robot: one line on stderr,
    nothing on stdout, exit 2 (with and without --json). The same robot at a pose made by its
    own forward kinematics (so it has a solution) exits 0 and lists it: the exit 2 is about
    the pose, not the robot."""
    from sim.robots.arm import load_arm

    ref = {"shipped": "lrmate200ic5l", "shipped_from_urdf": "kr6r900_2",
           "robot_folder_opw": str(_dh_folder(tmp_path, "opw_arm", OPW_DH_MM)),
           "dh_numeric": str(_dh_folder(tmp_path, "ur5", UR5_DH_MM)),
           "bare_urdf": str(REPO / "tests" / "data" / "kuka_kr6r700sixx.urdf")}[kind]
    for extra in ([], ["--json"]):
        code, out, err = _run(capsys, "ik", ref, "3000", "0", "500", *extra)
        assert code == 2, (kind, out, err)
        assert out == "" and err.count("\n") == 1, (kind, err)
        assert "unreachable" in err or "no inverse-kinematics solution" in err, (kind, err)
    q = np.deg2rad([10.0, 20.0, -15.0, 25.0, 30.0, 40.0])
    fk = (kinematic_model(ROBOTS[ref]).fk if ref in ROBOTS else load_arm(ref).fk)(q)
    a, b, g = np.rad2deg(matrix_to_euler_zyx(fk[:3, :3]))
    code, out, err = _run(capsys, "ik", ref, *(f"{v:.9f}" for v in 1e3 * fk[:3, 3]),
                          "--euler-zyx-deg", f"{a:.9f}", f"{b:.9f}", f"{g:.9f}", "--json")
    assert code == 0, (kind, err)
    assert json.loads(out)["solutions"], kind


def test_the_help_says_where_the_default_tcp_is(capsys):
    """``ik --help``'s default tcp: the flange centre, except the seeds' models with a built-in
    torch, whose tcp the help places 145 and 300 mm past the flange (it said "the flange centre
    (no tool)" for all: found by a new-user trial); the numbers are the models' own."""
    from sim.cells.compose import robot_statics

    with pytest.raises(SystemExit):
        main(["ik", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "their tcp is its tip, 145 and 300 mm past the flange" in text
    got = {n: round(float(np.linalg.norm(robot_statics(ROBOTS[n]).tcp_minus_flange)) * 1e3, 1)
           for n in ("lrmate100ib", "robot_5r", "lrmate200ic5l")}
    assert got == {"lrmate100ib": 145.0, "robot_5r": 300.0, "lrmate200ic5l": 0.0}
