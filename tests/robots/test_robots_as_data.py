"""Robots as data (issue 13, first slice): arms from a DH table or a URDF, their forward
kinematics, the OPW closed form derived from the joint axes, and a numeric IK otherwise.

Independent references: the textbook DH product (:func:`dh_product` below, the explicit matrix
entries of the formulas, not the chain code); the URDF's own joint chain; the OPW parameters that
ROS-Industrial publishes for the KUKA KR 6 R700 sixx and KR 6 R900-2
(``kuka_kr6_support/config/opw_kinematics_kr6r700sixx.yaml`` and
``opw_parameters_kr6r900_2.yaml``, github.com/ros-industrial/kuka_experimental, commit e78bbd1).
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from support import DATA, ROOT
from support.limits import run_limited
from support.robots import DH_ROBOT, DH_SCENARIO, DRIVES_6

from sim.errors import KinematicsError
from sim.robots.arm import load_arm
from sim.robots.kinematics import opw
from sim.robots.kinematics.chain import chain_from_dh, chain_from_urdf
from sim.robots.kinematics.numeric_ik import pose_error
from sim.robots.kinematics.numeric_ik import solve_ik as numeric_ik

MODELS = ROOT / "models"
#: The URDF of each arm with published OPW parameters.
URDFS = {"kuka_kr6r700sixx": DATA / "kuka_kr6r700sixx.urdf",
         "kuka_kr6r900_2": MODELS / "kuka_kr6r900_2" / "kr6r900_2.urdf",
         "abb_irb2400": MODELS / "abb_irb2400" / "irb2400.urdf"}
#: Published OPW parameters (m, rad): kuka_experimental e78bbd1, kuka_kr6_support/config
#: (the KUKA arms); opw_kinematics 8a32bda, include/opw_kinematics/opw_parameters_examples.h,
#: makeIrb2400_10 (the ABB IRB 2400).
PUBLISHED = {
    "abb_irb2400": dict(a1=0.100, a2=-0.135, b=0.0, c1=0.615, c2=0.705, c3=0.755, c4=0.085,
                        offsets=(0.0, 0.0, -np.pi / 2, 0, 0, 0), signs=(1, 1, 1, 1, 1, 1)),
    "kuka_kr6r700sixx": dict(a1=0.025, a2=-0.035, b=0.0, c1=0.400, c2=0.315, c3=0.365, c4=0.080,
                             offsets=(0.0, -np.pi / 2, 0, 0, 0, 0), signs=(-1, 1, 1, -1, 1, -1)),
    "kuka_kr6r900_2": dict(a1=0.025, a2=-0.025, b=0.0, c1=0.400, c2=0.455, c3=0.420, c4=0.090,
                           offsets=(0.0, -np.pi / 2, 0, 0, 0, 0), signs=(-1, 1, 1, -1, 1, -1)),
}

#: A six-axis OPW arm as a standard DH table [a m, alpha rad, d m, theta_offset rad] (an
#: LR Mate 200iC-like geometry: a1 = 75, c1 = 330, c2 = 300, a2 = -75, c3 = 320, c4 = 80 mm).
OPW_DH = np.array([[0.075, -np.pi / 2, 0.330, 0.0], [0.300, 0.0, 0.0, -np.pi / 2],
                   [0.075, -np.pi / 2, 0.0, 0.0], [0.0, np.pi / 2, 0.320, 0.0],
                   [0.0, -np.pi / 2, 0.0, 0.0], [0.0, 0.0, 0.080, 0.0]])
#: A UR5 (offset wrist: not OPW), standard DH from Universal Robots' published table.
UR5_DH = np.array([[0.0, np.pi / 2, 0.089159, 0.0], [-0.425, 0.0, 0.0, 0.0],
                   [-0.39225, 0.0, 0.0, 0.0], [0.0, np.pi / 2, 0.10915, 0.0],
                   [0.0, -np.pi / 2, 0.09465, 0.0], [0.0, 0.0, 0.0823, 0.0]])


def dh_product(rows: np.ndarray, q: np.ndarray, convention: str = "dh") -> np.ndarray:
    """The textbook DH (or Craig MDH) product for joint values ``q``: the explicit matrix
    entries of each row, independent of sim.robots.kinematics.chain and sim.robots.mjcf.builder."""
    T = np.eye(4)
    for (a, alpha, d, off), qi in zip(np.asarray(rows, dtype=float), np.asarray(q, float),
                                      strict=True):
        th = qi + off
        ct, st, ca, sa = math.cos(th), math.sin(th), math.cos(alpha), math.sin(alpha)
        if convention == "dh":
            A = np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                          [0, sa, ca, d], [0, 0, 0, 1.0]])
        else:
            A = np.array([[ct, -st, 0, a], [st * ca, ct * ca, -sa, -sa * d],
                          [st * sa, ct * sa, ca, ca * d], [0, 0, 0, 1.0]])
        T = T @ A
    return T


def random_q(chain, n: int, seed: int = 1) -> np.ndarray:
    lo = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
    hi = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
    return np.random.default_rng(seed).uniform(lo, hi, size=(n, chain.n))


def robot_toml(rows: np.ndarray, name: str, convention: str = "dh") -> str:
    dh = ",\n  ".join(f"[{float(a * 1e3)!r}, {float(np.rad2deg(al))!r}, {float(d * 1e3)!r}, "
                      f"{float(np.rad2deg(o))!r}]"
                      for a, al, d, o in rows)
    rng = ", ".join("[-170, 170]" for _ in rows)
    return (f'name = "{name}"\n[kinematics]\nconvention = "{convention}"\ndh = [\n  {dh}\n]\n'
            f"[joints]\nrange_deg = [{rng}]\n")


def urdf_from_dh(rows: np.ndarray, name: str) -> str:
    """The same arm as a URDF: joint i's origin is the DH transform of the rows before it
    (written with rpy from the rotation), its axis z."""
    from sim.core.rotations import matrix_to_euler_zyx

    out = [f'<robot name="{name}">', '<link name="base"/>']
    prev = "base"
    T = np.eye(4)
    for i, row in enumerate(rows):
        origin = T
        y, p, r = (float(v) for v in matrix_to_euler_zyx(origin[:3, :3]))
        xyz = " ".join(repr(float(v)) for v in origin[:3, 3])
        out += [f'<link name="l{i + 1}"/>',
                f'<joint name="j{i + 1}" type="revolute"><parent link="{prev}"/>'
                f'<child link="l{i + 1}"/><origin xyz="{xyz}" rpy="{r!r} {p!r} {y!r}"/>'
                f'<axis xyz="0 0 1"/><limit lower="-2.96706" upper="2.96706" velocity="3"/>'
                "</joint>"]
        prev = f"l{i + 1}"
        a, al, d, off = row
        T = dh_product([[a, al, d, off]], [0.0])
    y, p, r = (float(v) for v in matrix_to_euler_zyx(T[:3, :3]))
    xyz = " ".join(repr(float(v)) for v in T[:3, 3])
    out += ['<link name="tool0"/>', f'<joint name="flange" type="fixed"><parent link="{prev}"/>'
            f'<child link="tool0"/><origin xyz="{xyz}" rpy="{r!r} {p!r} {y!r}"/></joint>',
            "</robot>"]
    return "\n".join(out)


# ---------------------------------------------------------------------------- OPW from URDF
@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_opw_parameters_derived_from_the_urdf_equal_the_published_ones(name):
    chain = chain_from_urdf(URDFS[name])
    axes, points, flange = chain.frames(np.zeros(6))
    p = opw.opw_from_axes(axes, points, flange, name)
    want = PUBLISHED[name]
    for k, v in p.lengths().items():
        assert v == pytest.approx(want[k], abs=1e-12), k
    np.testing.assert_allclose(p.offsets, want["offsets"], atol=1e-12)
    assert p.signs == want["signs"]
    # tool0 is the OPW end frame (z along the tool axis); the IRB 2400 URDF writes pi/2 as
    # 1.57079632679 (4.9e-12 short)
    np.testing.assert_allclose(p.flange, np.eye(4), atol=1e-11)


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_opw_forward_equals_the_urdf_chain(name):
    """1000 random configurations: the OPW closed form and the URDF's joint product agree to
    1e-9 m (position) and 1e-9 (rotation entries)."""
    arm = load_arm(URDFS[name])
    assert arm.solver == "opw"
    Q = random_q(arm.chain, 1000)
    T = opw.forward(arm.opw, Q)
    err = max(np.abs(T[i] - arm.chain.fk(Q[i])).max() for i in range(len(Q)))
    assert err < 1e-9, err


# ------------------------------------------------------------- shipped arms from their URDF
#: The shipped arms given by a URDF: robot name -> its URDF.
SHIPPED_DATA = {"kr6r900_2": URDFS["kuka_kr6r900_2"], "irb2400": URDFS["abb_irb2400"],
                "m10ia": MODELS / "fanuc_m10ia" / "m10ia.urdf",
                "m20ia": MODELS / "fanuc_m20ia" / "m20ia.urdf",
                "ar2010": MODELS / "yaskawa_ar2010" / "ar2010.urdf",
                "irb1600": MODELS / "abb_irb1600" / "irb1600.urdf",
                "kr10r1420": MODELS / "kuka_kr10r1420" / "kr10r1420.urdf"}


def test_every_shipped_urdf_arm_is_checked_here():
    """The list above is every shipped robot folder that names a URDF (a new one is checked
    by the tests below without being added by hand to a list that could forget it)."""
    import tomllib

    named = {tomllib.loads(p.read_text())["name"] for p in MODELS.glob("*/robot.toml")
             if "urdf" in tomllib.loads(p.read_text()).get("kinematics", {})}
    assert named == set(SHIPPED_DATA)


#: OPW parameters that ROS-Industrial publishes for arms of the welding-robot library
#: (``fanuc_m10ia_support/config/opw_parameters_m10ia.yaml``, ``fanuc_m20ia_support/config/
#: opw_parameters_m20ia.yaml``: github.com/ros-industrial/fanuc, commit 8fee5e3;
#: ``kuka_kr10_support/config/opw_parameters_kr10r1420.yaml``: kuka_experimental e78bbd1),
#: with the joint offsets and sign corrections as written there. The FANUC files' J6 offset
#: of 180 deg is the half turn that cellsim's derivation keeps in its flange transform.
PUBLISHED_LIBRARY = {
    "m10ia": (dict(a1=0.15, a2=-0.20, b=0.0, c1=0.45, c2=0.60, c3=0.64, c4=0.10),
              (0.0, 0.0, -90.0, 0.0, 0.0, 180.0), (1, 1, -1, -1, -1, -1)),
    "m20ia": (dict(a1=0.15, a2=-0.25, b=0.0, c1=0.525, c2=0.79, c3=0.835, c4=0.10),
              (0.0, 0.0, -90.0, 0.0, 0.0, 180.0), (1, 1, -1, -1, -1, -1)),
    "kr10r1420": (dict(a1=0.150, a2=-0.020, b=0.0, c1=0.450, c2=0.610, c3=0.660, c4=0.080),
                  (0.0, -90.0, 0.0, 0.0, 0.0, 0.0), (-1, 1, 1, -1, 1, -1)),
}


@pytest.mark.parametrize("name", sorted(PUBLISHED_LIBRARY))
def test_the_published_opw_parameters_move_the_urdf_chains_tool0(name):
    """ROS-Industrial's own OPW parameters of a library arm (not derived by cellsim), put
    through the OPW forward kinematics with no flange transform, give the shipped URDF's tool0
    at 1000 random configurations to 1e-9."""
    import dataclasses

    from sim.robots.registry import ROBOTS

    lengths, offsets, signs = PUBLISHED_LIBRARY[name]
    arm = ROBOTS[name].family.arm
    pub = dataclasses.replace(arm.opw, **lengths, offsets=tuple(np.radians(offsets)),
                              signs=signs, flange=np.eye(4))
    chain = chain_from_urdf(SHIPPED_DATA[name])
    Q = random_q(chain, 1000, seed=11)
    err = max(np.abs(opw.forward(pub, q) - chain.fk(q)).max() for q in Q)
    assert err < 1e-9, err


def mujoco_compiled_urdf(path: Path, keep_fixed_links: bool = True):
    """MuJoCo's own compile of a URDF (an independent reader). ``keep_fixed_links``: fixed links
    kept as bodies so that ``tool0`` stays, massless links bounded (for kinematics); else
    MuJoCo fuses them into their moving link and nothing is added (for dynamics)."""
    import re

    import mujoco

    compiler = ('<compiler fusestatic="false" discardvisual="true" boundmass="0.001" '
                'boundinertia="1e-6"/>' if keep_fixed_links else
                '<compiler discardvisual="true"/>')
    text = re.sub(r"(<robot[^>]*>)", r"\1<mujoco>" + compiler + "</mujoco>", path.read_text(),
                  count=1)
    return mujoco.MjModel.from_xml_string(text)


@pytest.mark.parametrize("name", sorted(SHIPPED_DATA))
def test_a_shipped_arms_model_equals_mujocos_compile_of_its_public_urdf(name):
    """1000 random configurations: the shipped model's flange (generated by cellsim from the
    chain) and MuJoCo's own compile of the public URDF's tool0 agree to 1e-9 m and 1e-9 in
    the rotation entries; the joint ranges are the URDF's."""
    import mujoco

    from sim.robots.registry import ROBOTS, joint_ranges

    spec = ROBOTS[name]
    assert spec.family.arm.solver == "opw"
    ref = mujoco_compiled_urdf(SHIPPED_DATA[name])
    m = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    d, dr = mujoco.MjData(m), mujoco.MjData(ref)
    np.testing.assert_allclose(joint_ranges(spec), ref.jnt_range, atol=1e-12)
    fl, t0 = m.site("flange").id, ref.body("tool0").id
    rng = np.random.default_rng(4)
    worst = 0.0
    for q in rng.uniform(ref.jnt_range[:, 0], ref.jnt_range[:, 1], size=(1000, 6)):
        d.qpos[:] = q
        dr.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_kinematics(ref, dr)
        worst = max(worst, np.abs(d.site_xpos[fl] - dr.xpos[t0]).max(),
                    np.abs(d.site_xmat[fl] - dr.xmat[t0]).max())
    assert worst < 1e-9, worst


@pytest.mark.parametrize("name", sorted(SHIPPED_DATA))
def test_a_shipped_arms_drives_hold_it_against_gravity_with_the_rated_payload(name):
    """The README's rules for the estimated drives: motor max speed / ratio reaches the joint's
    speed limit, and the rated joint torque exceeds the largest static gravity torque with the
    rated payload at the flange (MuJoCo's inverse dynamics over 1000 poses)."""
    import mujoco

    from sim.robots.registry import ROBOTS, joint_ranges

    spec = ROBOTS[name]
    m = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    d = mujoco.MjData(m)
    R = joint_ranges(spec)
    jac = np.zeros((3, m.nv))
    g = np.zeros(6)
    for q in np.random.default_rng(5).uniform(R[:, 0], R[:, 1], size=(1000, 6)):
        d.qpos[:] = q
        mujoco.mj_forward(m, d)
        mujoco.mj_jacSite(m, d, jac, None, m.site("flange").id)
        g = np.maximum(g, np.abs(d.qfrc_bias + jac.T @ [0, 0, spec.payload_kg * 9.81]))
    for i, dr in enumerate(spec.drives):
        assert dr.max_speed_rpm / dr.gear_ratio * 2 * np.pi / 60 >= spec.max_speed[i] - 1e-6
        assert dr.rated_torque * dr.gear_ratio * dr.efficiency > g[i], (i, g[i])


def test_the_shipped_generated_models_and_readmes_are_what_the_generator_writes():
    """models/build_data_robots.py --check: each shipped URDF arm's MJCF, scene.xml and README
    tables are what cellsim generates from its robot.toml (no hand edits, no stale file)."""
    r = run_limited([sys.executable, str(MODELS / "build_data_robots.py"), "--check"],
                       capture_output=True, text=True, cpu_s=600)
    assert r.returncode == 0, r.stdout + r.stderr


@pytest.mark.parametrize("name", sorted(SHIPPED_DATA))
def test_cellsim_ik_of_a_shipped_arm_returns_the_pose_it_came_from(name):
    """The closed form of a shipped URDF arm: 200 random poses, the configuration they came
    from is among the solutions (modulo whole turns), pose error < 1e-9."""
    from sim.robots.registry import ROBOTS

    arm = ROBOTS[name].family.arm
    for q in random_q(arm.chain, 200, seed=6):
        T = arm.fk(q)
        sols = arm.ik(T)
        assert 1 <= len(sols) and len({s.branch for s in sols}) <= 8
        assert all(np.abs(pose_error(arm.chain.fk(s.q), T)).max() < 1e-9 for s in sols)
        assert min(np.abs(s.q - q).max() for s in sols) < 1e-7


# ---------------------------------------------------------------------------- DH and URDF
@pytest.fixture(scope="module")
def dh_arm(tmp_path_factory):
    """The OPW_DH arm as a robot folder (robot.toml with the DH table) and as a URDF."""
    root = tmp_path_factory.mktemp("arm")
    (root / "my_arm").mkdir()
    (root / "my_arm" / "robot.toml").write_text(robot_toml(OPW_DH, "my_arm"))
    (root / "my_arm.urdf").write_text(urdf_from_dh(OPW_DH, "my_arm_urdf"))
    return load_arm(root / "my_arm"), load_arm(root / "my_arm.urdf")


def test_dh_table_and_urdf_forward_kinematics_equal_the_dh_product(dh_arm):
    """The robot folder (DH table) and the same arm as a URDF: FK equals an independent DH
    product to 1e-9 m for 1000 random configurations."""
    from_dh, from_urdf = dh_arm
    Q = random_q(from_dh.chain, 1000, seed=7)
    for q in Q:
        ref = dh_product(OPW_DH, q)
        assert np.abs(from_dh.fk(q) - ref).max() < 1e-9
        assert np.abs(from_urdf.fk(q) - ref).max() < 1e-9


def test_the_dh_arm_is_recognised_as_opw_both_ways(dh_arm):
    for arm in dh_arm:
        assert arm.solver == "opw", arm.why_numeric
        assert arm.opw.lengths()["c2"] == pytest.approx(0.300, abs=1e-12)


@pytest.mark.parametrize("which", ["dh", "urdf", "kuka_kr6r700sixx", "kuka_kr6r900_2"])
def test_ik_returns_every_configuration_the_pose_came_from(which, dh_arm):
    """Random poses (FK of random configurations): the configuration is among the solutions
    (modulo 2 pi), every solution reproduces the pose to 1e-9, at most 8 distinct solutions
    modulo 2 pi."""
    arm = {"dh": dh_arm[0], "urdf": dh_arm[1]}.get(which) or load_arm(DATA / f"{which}.urdf")
    Q = random_q(arm.chain, 1000, seed=3)
    for q in Q:
        T = arm.fk(q)
        sols = arm.ik(T)
        assert sols
        for s in sols:
            assert np.linalg.norm(pose_error(arm.fk(s.q), T)) < 1e-9
        wrapped = np.array([np.mod(s.q + np.pi, 2 * np.pi) - np.pi for s in sols])
        distinct = []
        for w in wrapped:
            if not any(np.abs(np.angle(np.exp(1j * (w - d)))).max() < 1e-7 for d in distinct):
                distinct.append(w)
        assert len(distinct) <= 8
        d = np.abs(np.angle(np.exp(1j * (wrapped - q)))).max(axis=1)
        assert d.min() < 1e-7, (q, d.min())


def test_a_joint_beyond_360_degrees_gets_its_whole_turn_variants():
    """KR 6 J6 ranges +-350 deg: the configuration with q6 = 20 deg comes with q6 = -340 deg
    (and not 380 deg, outside the range)."""
    arm = load_arm(DATA / "kuka_kr6r700sixx.urdf")
    q = np.deg2rad([10, -80, 100, 20, 40, 20])
    q6 = sorted(np.rad2deg(s.q[5]) for s in arm.ik(arm.fk(q))
                if np.abs(s.q[:5] - q[:5]).max() < 1e-9)
    np.testing.assert_allclose(q6, [20 - 360, 20], atol=1e-9)


# ---------------------------------------------------------------------------- numeric IK
def test_an_offset_wrist_arm_gets_the_offset_wrist_closed_form(tmp_path):
    """A UR5 is not OPW (its wrist axes do not meet) but has the UR-type closed form
    (tests/robots/test_offset_wrist_ik.py)."""
    (tmp_path / "robot.toml").write_text(robot_toml(UR5_DH, "ur5"))
    arm = load_arm(tmp_path)
    assert arm.solver == "offset_wrist" and arm.opw is None


def test_an_arm_with_neither_closed_form_falls_back_to_the_numeric_solver(tmp_path):
    """The UR5 with its J4 tilted 10 deg off J2-J3: neither OPW nor offset-wrist."""
    rows = UR5_DH.copy()
    rows[2, 1] = np.radians(10.0)
    (tmp_path / "robot.toml").write_text(robot_toml(rows, "ur5_tilted"))
    arm = load_arm(tmp_path)
    assert arm.solver == "numeric" and "wrist" in arm.why_numeric and "J4" in arm.why_numeric


def test_numeric_ik_solves_99_percent_of_reachable_poses(tmp_path):
    """200 random reachable poses of a UR5 (its seeds: the zero pose, then random ones): at
    least 99 % solved to a pose error under 1e-9; the 20 ms budget per pose is measured by
    benchmarks/bench_numeric_ik.py, not here."""
    chain = chain_from_dh(UR5_DH, lower=np.full(6, -2 * np.pi), upper=np.full(6, 2 * np.pi))
    Q = random_q(chain, 200, seed=11)
    solved = 0
    for q in Q:
        T = chain.fk(q)
        sols = numeric_ik(chain, T, first=True)
        if sols and np.linalg.norm(pose_error(chain.fk(sols[0]), T)) < 1e-9:
            solved += 1
    assert solved >= 198, solved


# ---------------------------------------------------------------------------- bad input
def _cli(*args: str) -> subprocess.CompletedProcess:
    return run_limited([sys.executable, "-m", "sim", "ik", *args, "500", "0", "500"],
                          capture_output=True, text=True, cpu_s=120)


def _urdf_with(joint_type: str = "revolute", lower: str = "-1", upper: str = "1") -> str:
    return (f'<robot name="bad"><link name="a"/><link name="b"/>'
            f'<joint name="j1" type="{joint_type}"><parent link="a"/><child link="b"/>'
            f'<axis xyz="0 0 1"/><limit lower="{lower}" upper="{upper}" velocity="1"/></joint>'
            "</robot>")


@pytest.mark.parametrize("case,content,needle", [
    ("dh_row", 'name = "x"\n[kinematics]\nconvention = "dh"\ndh = [[1, 2, 3]]\n',
     "kinematics.dh[0]: 3 values"),
    ("range", robot_toml(OPW_DH[:2], "x").replace("[-170, 170]", "[170, -170]", 1),
     "joints.range_deg[0]: lower 170 > upper -170"),
    ("prismatic", _urdf_with("prismatic"), "joint 'j1': type 'prismatic' is not supported"),
    ("continuous", _urdf_with("continuous"), "joint 'j1': type 'continuous' is not supported"),
    ("limits", _urdf_with(lower="2", upper="1"), "joint 'j1': limit lower 2 > upper 1"),
    ("missing", None, "no such URDF file"),
])
def test_bad_robot_data_is_one_line_and_exit_2(case, content, needle, tmp_path):
    if case in ("dh_row", "range"):
        path = tmp_path / "robot.toml"
    else:
        path = tmp_path / "arm.urdf"
    if content is not None:
        path.write_text(content)
    r = _cli(str(path))
    assert r.returncode == 2, r.stdout + r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in r.stderr, r.stderr
    with pytest.raises(KinematicsError, match="."):
        load_arm(path)


def test_cellsim_ik_of_a_urdf_lists_the_closed_form_solutions():
    r = run_limited([sys.executable, "-m", "sim", "ik", str(DATA / "kuka_kr6r700sixx.urdf"),
                        "500", "100", "600", "--all", "--json"], capture_output=True, text=True,
                       cpu_s=120)
    assert r.returncode == 0, r.stderr
    import json

    doc = json.loads(r.stdout)
    assert doc["solver"] == "opw" and len(doc["solutions"]) >= 8
    arm = load_arm(DATA / "kuka_kr6r700sixx.urdf")
    for s in doc["solutions"]:
        T = arm.fk(np.deg2rad(s["joints_deg"]))
        np.testing.assert_allclose(T[:3, 3], [0.5, 0.1, 0.6], atol=1e-9)


# ---------------------------------------------------------------------------- MDH
def test_a_modified_dh_table_equals_its_textbook_product(tmp_path):
    """Craig's modified DH (the rows of the LR Mate 200iC-like arm written in MDH form):
    the chain equals the textbook MDH product for 1000 random configurations."""
    rows = np.array([[0.0, 0.0, 0.330, 0.0], [0.075, -np.pi / 2, 0.0, -np.pi / 2],
                     [0.300, 0.0, 0.0, 0.0], [0.075, -np.pi / 2, 0.320, 0.0],
                     [0.0, np.pi / 2, 0.0, 0.0], [0.0, -np.pi / 2, 0.080, 0.0]])
    (tmp_path / "robot.toml").write_text(robot_toml(rows, "mdh_arm", convention="mdh"))
    arm = load_arm(tmp_path)
    for q in random_q(arm.chain, 1000, seed=5):
        assert np.abs(arm.fk(q) - dh_product(rows, q, "mdh")).max() < 1e-9


# ---------------------------------------------------------------------------- maker's joints
@pytest.mark.parametrize("robot", ["lrmate100ib", "lrmate200ic5l", "m10ia", "m20ia"])
def test_fanuc_j3_is_measured_from_the_horizontal(robot):
    """The J2/J3 interaction, checked on the arm itself: with the maker's J3 fixed, the
    forearm's elevation (J3 axis to the wrist, in the arm plane) does not change with J2, and a
    change of the maker's J3 turns it by that much; maps both ways are inverse. The M-10iA and
    M-20iA (ROS-Industrial URDFs, fanuc_driver's J23_factor = 1 as for the 200iC) had no maker
    table: --maker and cellsim export printed the URDF's serial J3 (found by a new-user
    trial)."""
    from sim.robots.kinematics.model import kinematic_model
    from sim.robots.maker import from_maker, to_maker
    from sim.robots.registry import ROBOTS

    spec = ROBOTS[robot]
    assert spec.maker_matrix
    km = kinematic_model(spec)
    wrist = 3 if spec.n_joints == 5 else 4

    def elevation(maker_deg):
        q = from_maker(spec, np.deg2rad(maker_deg))
        axes, points, _ = km.joint_frames(q)
        v = points[wrist] - points[2]
        v = v - (v @ axes[2]) * axes[2]
        return np.degrees(np.arctan2(v[2], np.hypot(v[0], v[1])))

    rng = np.random.default_rng(4)
    for _ in range(50):
        m = rng.uniform(-40, 40, spec.n_joints)
        e0 = elevation(m)
        for j2 in rng.uniform(-40, 40, 5):
            m2 = m.copy()
            m2[1] = j2
            assert elevation(m2) == pytest.approx(e0, abs=1e-9)
        m3 = m.copy()
        m3[2] += 7.0
        assert abs(elevation(m3) - e0) == pytest.approx(7.0, abs=1e-9)
        np.testing.assert_allclose(to_maker(spec, from_maker(spec, m)), m, atol=1e-12)


def test_joints_maker_deg_in_a_scenario_are_the_controllers_values():
    """A scenario written with FANUC's joint values loads as the seed's joint values, and is
    refused (one line) for the 5R robot, which has no maker's convention."""
    from sim.errors import ScenarioError
    from sim.robots.maker import to_maker
    from sim.scenario.loader import parse_scenario

    text = """
name = "maker"
description = "x"
robot = "lrmate200ic5l"
[[phases]]
name = "p"
planner = "434"
time_s = [0, 1, 2]
joints_maker_deg = [[0, 0, 0, 0, -90, 0], [10, 20, -30, 0, -60, 0], [20, 10, -10, 5, -45, 5]]
"""
    sc = parse_scenario(text, source="m.toml")
    q = sc.phases[0].q
    np.testing.assert_allclose(np.rad2deg(to_maker(sc.robot, q)),
                               [[0, 0, 0, 0, -90, 0], [10, 20, -30, 0, -60, 0],
                                [20, 10, -10, 5, -45, 5]], atol=1e-12)
    # FANUC J2 = 20, J3 = -30: seed theta2 = -20 (sign), theta3 = J3 + J2 = -10
    np.testing.assert_allclose(np.rad2deg(q[1, 1:3]), [-20.0, -10.0], atol=1e-12)
    bad = text.replace('robot = "lrmate200ic5l"', 'robot = "robot_5r"').replace(
        ", 0], [10", "], [10").replace("0, -60, 0]", "0, -60]").replace("5, -45, 5]", "5, -45]")
    with pytest.raises(ScenarioError, match="no maker's joint convention"):
        parse_scenario(bad, source="m.toml")


# ---------------------------------------------------------------------------- robot folders
def _former_specs():
    """The three robots as sim/robots/registry.py defined them in Python before they became
    folders (commit 34e77e9): the folders must hold the same values."""
    from sim.robots.families import Fanuc6, FiveR
    from sim.robots.registry import Drive, RobotSpec

    def deg(*v):
        return tuple(float(np.deg2rad(x)) for x in v)

    return [
        RobotSpec(name="lrmate100ib", title="FANUC LR Mate 100iB", folder="fanuc_lrmate100ib",
                  robot_file="lrmate100ib.xml",
                  family=FiveR({"l1": 0.150, "d1": 0.250, "l2": 0.220, "l3": 0.225}),
                  max_speed=deg(240, 270, 270, 330, 480),
                  description="5-axis FANUC LR Mate 100iB (seed 000), 5 kg payload",
                  drives=(Drive(120, 0.75, 2.0e-5, 0.65, 2.4, 6000),
                          Drive(120, 0.75, 4.5e-5, 1.3, 4.5, 6000),
                          Drive(120, 0.75, 2.0e-5, 0.65, 2.4, 6000),
                          Drive(80, 0.70, 5.0e-6, 0.32, 1.0, 5000),
                          Drive(50, 0.70, 3.0e-6, 0.25, 0.8, 5000)),
                  payload_kg=5.0, max_accel=deg(1800, 4500, 7500, 8700, 200000),
                  estimated_links=(True,) * 5,
                  maker_joints=("J1", "J2", "J3", "J5", "J6"),
                  maker_matrix=((1, 0, 0, 0, 0), (0, 1, 0, 0, 0), (0, -1, -1, 0, 0),
                                (0, 0, 0, -1, 0), (0, 0, 0, 0, -1))),
        RobotSpec(name="lrmate200ic5l", title="FANUC LR Mate 200iC/5L",
                  folder="fanuc_lrmate200ic", robot_file="lrmate200ic5l.xml",
                  family=Fanuc6({"d2": 0.075, "d3": 0.400, "d4": 0.075, "R4": 0.410,
                                 "R6": 0.080}),
                  max_speed=deg(270, 270, 270, 450, 450, 720),
                  description="6-axis FANUC LR Mate 200iC/5L (seed 004), 5 kg payload",
                  drives=(Drive(120, 0.75, 2.0e-5, 0.65, 2.4, 6000),
                          Drive(120, 0.75, 4.5e-5, 1.3, 4.5, 6000),
                          Drive(120, 0.75, 2.0e-5, 0.65, 2.4, 6000),
                          Drive(75, 0.70, 5.0e-6, 0.32, 1.0, 6000),
                          Drive(75, 0.70, 5.0e-6, 0.32, 1.0, 6000),
                          Drive(48, 0.70, 3.0e-6, 0.25, 0.8, 6000)),
                  payload_kg=5.0, max_accel=deg(1400, 2300, 5200, 40000, 43000, 210000),
                  estimated_links=(True,) * 6,
                  maker_joints=("J1", "J2", "J3", "J4", "J5", "J6"),
                  maker_matrix=((1, 0, 0, 0, 0, 0), (0, -1, 0, 0, 0, 0), (0, 1, 1, 0, 0, 0),
                                (0, 0, 0, -1, 0, 0), (0, 0, 0, 0, 1, 0),
                                (0, 0, 0, 0, 0, -1))),
        RobotSpec(name="robot_5r", title="5R welding robot", folder="robot_5r",
                  robot_file="robot_5r.xml",
                  family=FiveR({"l1": 0.250, "d1": 1.000, "l2": 0.600, "l3": 0.400}),
                  max_speed=deg(150, 150, 180, 300, 450),
                  description="5-axis welding robot for large cylindrical parts (seed 001)",
                  drives=(Drive(160, 0.80, 1.2e-3, 8.0, 32.0, 4000),
                          Drive(160, 0.80, 2.3e-3, 12.0, 46.0, 4000),
                          Drive(150, 0.80, 5.2e-4, 4.0, 15.0, 5000),
                          Drive(90, 0.75, 2.9e-4, 2.0, 7.8, 5000),
                          Drive(60, 0.75, 1.0e-4, 1.0, 4.0, 5000)),
                  payload_kg=10.0, max_accel=deg(1200, 1700, 3700, 6900, 28000),
                  estimated_links=(True,) * 5),
    ]


@pytest.mark.parametrize("former", _former_specs(), ids=lambda s: s.name)
def test_the_shipped_robot_folders_hold_the_former_values(former):
    """models/<folder>/robot.toml, scanned by the registry, gives exactly the RobotSpec the
    Python registry held (every field, every float): results are unchanged."""
    from sim.robots.registry import ROBOTS

    assert ROBOTS[former.name] == former
    for f in former.__dataclass_fields__:
        assert getattr(ROBOTS[former.name], f) == getattr(former, f), f


BARE_SCENARIO = """
name = "folder_robot"
description = "a robot folder of one's own"
robot = "{robot}"
payload_kg = 2.0
[[phases]]
name = "move"
planner = "434"
time_s = [0.0, 0.8, 1.6]
joints_deg = [[0, 0, 0, 0, -90, 0], [20, 10, -20, 10, -70, 20], [40, 20, -30, 0, -60, 0]]
"""


def test_a_robot_folder_of_ones_own_runs_a_scenario(tmp_path):
    """A copy of the 200iC folder under another name, named by path in a scenario, runs and
    gives the shipped robot's torques (same data); a folder without its MJCF is one line."""
    import shutil

    from sim.errors import ScenarioError
    from sim.pipeline.run import evaluate_scenario
    from sim.scenario import load_scenario

    src = MODELS / "fanuc_lrmate200ic"
    dst = tmp_path / "robots" / "my_arm"
    shutil.copytree(src, dst)
    toml = dst / "robot.toml"
    toml.write_text(toml.read_text().replace('name = "lrmate200ic5l"', 'name = "my_arm"'))
    (tmp_path / "mine.toml").write_text(BARE_SCENARIO.format(robot="robots/my_arm"))
    (tmp_path / "shipped.toml").write_text(BARE_SCENARIO.format(robot="lrmate200ic5l"))
    mine = load_scenario(tmp_path / "mine.toml")
    assert mine.robot.name == "my_arm" and Path(mine.robot.robot_path).is_file()
    a = evaluate_scenario(mine)
    b = evaluate_scenario(load_scenario(tmp_path / "shipped.toml"))
    np.testing.assert_array_equal(a.record.arrays["tau"], b.record.arrays["tau"])
    assert a.summary["verdict"] == "pass"
    (dst / "lrmate200ic5l.xml").unlink()
    with pytest.raises(ScenarioError, match=r"robot: .*robot.toml: mjcf: no such file"):
        load_scenario(tmp_path / "mine.toml")


# ---------------------------------------------------------------------------- DH robots in cells
@pytest.fixture
def dh_robot(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    folder = tmp_path / "robots" / "dh_arm"
    folder.mkdir(parents=True)
    (folder / "robot.toml").write_text(DH_ROBOT)
    (tmp_path / "scn.toml").write_text(DH_SCENARIO)
    return tmp_path


def test_a_robot_from_a_dh_table_runs_with_no_self_collision(dh_robot):
    """A robot folder with only a DH table, drives and a mass: cellsim writes its MJCF (into
    its cache, not the folder), whose flange equals the DH product for 1000 configurations; a
    joint move and a straight line run, tracked, with no collision and a passing verdict; the
    straight line is solved by the arm's closed form."""
    import mujoco

    from sim.pipeline.run import evaluate_scenario
    from sim.scenario import load_scenario

    sc = load_scenario(dh_robot / "scn.toml")
    spec = sc.robot
    assert spec.family.arm.solver == "opw"
    assert not (dh_robot / "robots" / "dh_arm" / "dh_arm.xml").exists()
    assert str(spec.robot_path).startswith(str(dh_robot / "cache"))
    m = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    d = mujoco.MjData(m)
    rows = np.array([[0.075, -np.pi / 2, 0.330, 0.0], [0.300, 0.0, 0.0, -np.pi / 2],
                     [0.075, -np.pi / 2, 0.0, 0.0], [0.0, np.pi / 2, 0.320, 0.0],
                     [0.0, -np.pi / 2, 0.0, 0.0], [0.0, 0.0, 0.080, 0.0]])
    fl = m.site("flange").id
    lo, hi = m.jnt_range.T
    for q in np.random.default_rng(8).uniform(lo, hi, size=(1000, 6)):
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        T = dh_product(rows, q)
        np.testing.assert_allclose(d.site_xpos[fl], T[:3, 3], atol=1e-9)
        np.testing.assert_allclose(d.site_xmat[fl].reshape(3, 3), T[:3, :3], atol=1e-9)
    ev = evaluate_scenario(sc)
    assert ev.summary["collisions"] == []
    assert ev.summary["verdict"] == "pass", [c for c in ev.summary["checks"] if not c["ok"]]
    rec = ev.record.arrays
    k = [p["name"] for p in ev.summary["phases"]].index("line")
    np.testing.assert_allclose(rec["tcp_pos_ref"][rec["phase"] == k][-1], [0.45, 0.15, 0.30],
                               atol=1e-6)
    assert max(ev.summary["max_tracking_error_deg"]) < 0.1


@pytest.mark.parametrize("edit,needle", [
    (("total_kg = 25", ""), "mass.total_kg: required"),
    (("[[drives]]", "[[drive]]"), "unknown key"),
])
def test_a_dh_robot_without_its_data_is_one_line(dh_robot, edit, needle):
    old, new = edit
    (dh_robot / "robots" / "dh_arm" / "robot.toml").write_text(DH_ROBOT.replace(old, new, 1))
    r = run_limited([sys.executable, "-m", "sim", "run", str(dh_robot / "scn.toml"),
                        "--no-video", "--out", str(dh_robot / "out")], capture_output=True,
                       text=True, cpu_s=300, env={**__import__("os").environ,
                                                    "XDG_CACHE_HOME": str(dh_robot / "cache")})
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "robot.toml" in lines[0], r.stderr
    assert not (dh_robot / "out").exists()


def test_a_robot_folder_naming_a_urdf_builds_the_urdf_arm(tmp_path, monkeypatch):
    """robot.toml with convention = "urdf" (the KR 6 R700 sixx chain of ROS-Industrial): the
    generated MJCF's flange is the URDF's tool0 for 200 configurations, the family's IK is the
    OPW closed form, and the URDF's velocity limits are the joint speed limits."""
    import shutil

    import mujoco

    from sim.robots.robotfile import load_robot_folder

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    folder = tmp_path / "kr6"
    folder.mkdir()
    shutil.copy(DATA / "kuka_kr6r700sixx.urdf", folder / "kr6.urdf")
    (folder / "robot.toml").write_text('name = "kr6"\n[kinematics]\nconvention = "urdf"\n'
                                       'urdf = "kr6.urdf"\n[mass]\ntotal_kg = 50\n' + DRIVES_6)
    spec = load_robot_folder(folder)
    chain = chain_from_urdf(DATA / "kuka_kr6r700sixx.urdf")
    np.testing.assert_allclose(spec.max_speed, chain.max_speed)
    assert spec.family.arm.solver == "opw"
    m = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    d = mujoco.MjData(m)
    fl = m.site("flange").id
    for q in random_q(chain, 200, seed=9):
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        T = chain.fk(q)
        np.testing.assert_allclose(d.site_xpos[fl], T[:3, 3], atol=1e-9)
        np.testing.assert_allclose(d.site_xmat[fl].reshape(3, 3), T[:3, :3], atol=1e-9)


def test_robot_format_reference_documents_every_key():
    """docs/robot-format.md and the declared robot.toml schema name the same keys."""
    import re

    from sim.robots.schema import (
        DriveBlock,
        FamilyKinematics,
        LinkBlock,
        MakerBlock,
        RobotFolderSpec,
        RobotJoints,
        RobotMass,
    )

    doc = (ROOT / "docs" / "robot-format.md").read_text()
    table_keys = set(re.findall(r"^\| `([a-z][a-z0-9_]*)`", doc, flags=re.M))
    declared = set()
    for model in (RobotFolderSpec, FamilyKinematics, RobotJoints, RobotMass, DriveBlock,
                  MakerBlock, LinkBlock):
        for key in model.model_fields:
            assert key in table_keys, f"{model.__name__}.{key} is not documented"
            declared.add(key)
    assert table_keys <= declared, f"documented but not accepted: {table_keys - declared}"


def test_the_wrist_centre_stays_within_the_reach_bound_of_a_data_arm(dh_arm):
    """ChainFamily.reach() bounds the wrist centre's distance from frame 0 (all links count,
    the first joint's offset from the base too)."""
    from sim.robots.families.chain_family import ChainFamily

    for arm in (*dh_arm, load_arm(DATA / "kuka_kr6r900_2.urdf")):
        fam = ChainFamily(arm)
        Q = random_q(arm.chain, 2000, seed=12)
        _, points, _ = fam.joint_frames(Q)
        assert np.linalg.norm(points[:, fam.wrist_centre_index], axis=1).max() <= fam.reach()


def test_a_dh_robot_holds_its_home_pose_on_its_servos(dh_robot):
    """The generated gains hold the arm (and its rated payload) against gravity on the position
    servos alone, with no feed-forward: every joint within 2 mrad after 1 s, no warnings (as
    the shipped robots, tests/cells/test_cells.py)."""
    import mujoco

    from sim.cells import build_cell
    from sim.scenario import load_scenario

    sc = load_scenario(dh_robot / "scn.toml")
    for q_home in (np.zeros(6), np.deg2rad([0, 30, -20, 0, 45, 0])):
        cell = build_cell(None, sc.robot, payload_kg=2.0)
        m = cell.compile()
        d = mujoco.MjData(m)
        ids = [m.joint(j).id for j in cell.joint_names]
        for j, q in zip(ids, q_home, strict=True):
            d.qpos[m.jnt_qposadr[j]] = q
        d.ctrl[[m.actuator(a).id for a in cell.actuator_names]] = q_home
        for _ in range(1000):
            mujoco.mj_step(m, d)
        q = np.array([d.qpos[m.jnt_qposadr[j]] for j in ids])
        assert np.abs(q - q_home).max() < 2e-3, np.abs(q - q_home)
        assert all(d.warning[i].number == 0 for i in range(len(d.warning)))


# ---------------------------------------------------------------------------- a bare URDF
#: UR5 masses (kg) and centres of mass of ur_description's physical_parameters.yaml
#: (github.com/ros-industrial/universal_robot a7a2c54), per link of the DH frames here; the
#: inertias are those of uniform cylinders of the radii listed there, turned by a small rpy so
#: that the full tensor (off-diagonal terms) is exercised.
UR5_LINKS = [(3.7, (0.0, 0.00193, -0.02561), 0.075, 0.178),
             (8.393, (0.2125, 0.0, 0.024201), 0.06, 0.425),
             (2.275, (0.11993, 0.0, 0.0265), 0.06, 0.39225),
             (1.219, (0.0, 0.0, 0.01634), 0.06, 0.12),
             (1.219, (0.0, 0.0, 0.0018), 0.06, 0.12),
             (0.1879, (0.0, 0.0, -0.001159), 0.0375, 0.0345)]


def ur5_urdf_with_inertials(name: str = "ur5", efforts=(150, 150, 150, 28, 28, 28)) -> str:
    """The UR5 of :data:`UR5_DH` as a URDF with ``<inertial>`` on every moving link, fixed links
    with a mass (a 0.4 kg flange adapter on the chain, a 1.2 kg gripper past tool0, a 0.7 kg
    cable box on the upper arm's side: all fused into their moving link), efforts and
    velocities."""
    text = urdf_from_dh(UR5_DH, name)
    for i, (m, com, r, h) in enumerate(UR5_LINKS):
        ixx = m * (3 * r * r + h * h) / 12
        izz = m * r * r / 2
        inertial = (f'<inertial><origin xyz="{com[0]} {com[1]} {com[2]}" rpy="0.1 -0.2 0.3"/>'
                    f'<mass value="{m}"/><inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{ixx}" '
                    f'iyz="0" izz="{izz}"/></inertial>')
        text = text.replace(f'<link name="l{i + 1}"/>', f'<link name="l{i + 1}">{inertial}</link>')
    for i, e in enumerate(efforts):
        v = 3.14159 if i < 3 else 3.2
        text = text.replace(f'<joint name="j{i + 1}" type="revolute">',
                            f'<joint name="j{i + 1}" type="revolute" data-e="{e}" data-v="{v}">')
    # effort and velocity into each limit (urdf_from_dh writes velocity="3")
    parts = text.split('<limit lower="-2.96706" upper="2.96706" velocity="3"/>')
    out = parts[0]
    for i, rest in enumerate(parts[1:]):
        e, v = efforts[i], 3.14159 if i < 3 else 3.2
        out += f'<limit lower="-2.96706" upper="2.96706" velocity="{v}" effort="{e}"/>' + rest
    out = out.replace('<link name="tool0"/>', '<link name="adapter"><inertial><origin '
                      'xyz="0.01 0 0.02"/><mass value="0.4"/><inertia ixx="2e-4" ixy="1e-5" '
                      'ixz="0" iyy="3e-4" iyz="0" izz="4e-4"/></inertial></link>'
                      '<link name="tool0"/>')
    out = out.replace('<joint name="flange" type="fixed"><parent link="l6"/>',
                      '<joint name="adapter" type="fixed"><parent link="l6"/><child link="adapter"/>'
                      '<origin xyz="0 0 0.005" rpy="0 0 0.5"/></joint>'
                      '<joint name="flange" type="fixed"><parent link="adapter"/>')
    # a 1.2 kg gripper past the tip (fixed under tool0) and a cable box on the upper arm's side
    out = out.replace("</robot>", (
        '<link name="gripper"><inertial><origin xyz="0 0.01 0.06" rpy="0.3 0 0"/>'
        '<mass value="1.2"/><inertia ixx="3e-3" ixy="0" ixz="0" iyy="2e-3" iyz="0" izz="1.5e-3"/>'
        '</inertial></link><joint name="grip" type="fixed"><parent link="tool0"/>'
        '<child link="gripper"/><origin xyz="0 0 0.01" rpy="0 0.2 0"/></joint>'
        '<link name="cable_box"><inertial><origin xyz="0 0 0"/><mass value="0.7"/>'
        '<inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>'
        '<joint name="box" type="fixed"><parent link="l2"/><child link="cable_box"/>'
        '<origin xyz="0.1 0.05 0.02" rpy="0 0 0.4"/></joint></robot>'))
    return out.replace(' data-e="', ' x-e="')


def test_a_bare_urdf_runs_with_its_own_inertials_and_efforts(tmp_path, monkeypatch):
    """robot = "ur5.urdf" in a scenario: the generated model's mass matrix and gravity and
    Coriolis torques equal MuJoCo's own compile of the URDF (its inertials, the fixed adapter
    fused in) at 50 random states; the drives are the URDF's efforts and velocities; a joint
    move runs and passes."""
    import mujoco

    from sim.pipeline.run import evaluate_scenario
    from sim.robots.registry import resolve_robot
    from sim.scenario import load_scenario

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    (tmp_path / "ur5.urdf").write_text(ur5_urdf_with_inertials())
    spec = resolve_robot("ur5.urdf", tmp_path)
    assert spec.family.arm.solver == "offset_wrist"  # the UR-type closed form, from a URDF
    assert [d.peak_torque for d in spec.drives] == [150, 150, 150, 28, 28, 28]
    np.testing.assert_allclose(spec.max_speed, [3.14159] * 3 + [3.2] * 3)
    ours = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    ref = mujoco_compiled_urdf(tmp_path / "ur5.urdf", keep_fixed_links=False)
    moving = sum(m for m, *_ in UR5_LINKS) + 0.4 + 1.2 + 0.7
    assert ours.body_mass[ours.body("link1").id:].sum() == pytest.approx(moving)
    assert ref.body_mass.sum() == pytest.approx(moving)
    d, dr = mujoco.MjData(ours), mujoco.MjData(ref)
    rng = np.random.default_rng(8)
    M, Mr = np.zeros((6, 6)), np.zeros((6, 6))
    for _ in range(50):
        q, qd = rng.uniform(-2.9, 2.9, 6), rng.uniform(-2, 2, 6)
        d.qpos[:], d.qvel[:], dr.qpos[:], dr.qvel[:] = q, qd, q, qd
        mujoco.mj_forward(ours, d)
        mujoco.mj_forward(ref, dr)
        mujoco.mj_fullM(ours, d, M)
        mujoco.mj_fullM(ref, dr, Mr)
        np.testing.assert_allclose(M, Mr, atol=1e-9 * np.abs(Mr).max())
        np.testing.assert_allclose(d.qfrc_bias, dr.qfrc_bias, atol=1e-9 * max(1, np.abs(dr.qfrc_bias).max()))
    (tmp_path / "s.toml").write_text(BARE_SCENARIO.format(robot="ur5.urdf").replace(
        "payload_kg = 2.0", "payload_kg = 0.0").replace(
        "[0, 0, 0, 0, -90, 0], [20, 10, -20, 10, -70, 20], [40, 20, -30, 0, -60, 0]",
        "[0, -90, 0, -90, 0, 0], [20, -80, -20, -80, 10, 20], [40, -70, -40, -70, 20, 0]"))
    result = evaluate_scenario(load_scenario(tmp_path / "s.toml"))
    assert result.summary["verdict"] == "pass", result.summary


@pytest.mark.parametrize("edit,needle", [
    (lambda t: t.replace("<inertial>", "<!--").replace("</inertial>", "-->"), "no <inertial>"),
    (lambda t: t.replace('effort="28"', 'effort="0"', 1), "<limit effort> is missing or 0"),
    (lambda t: t.replace('iyy="1e-3" iyz="0" izz="1e-3"', 'iyy="1e-3" iyz="0" izz="5e-3"'),
     "inertia is not physical"),
    (lambda t: t.replace('<mass value="0.4"/><inertia ixx="2e-4" ixy="1e-5" ixz="0" iyy="3e-4" '
                         'iyz="0" izz="4e-4"/>', '<mass value="0.4"/>'), "no <inertia>"),
])
def test_a_bare_urdf_that_cannot_run_as_it_is_is_one_line(edit, needle, tmp_path):
    """A URDF without inertials or efforts, named by a scenario: one line naming the file and
    what is missing (and the robot.toml keys that supply it), exit 2."""
    (tmp_path / "ur5.urdf").write_text(edit(ur5_urdf_with_inertials()))
    (tmp_path / "s.toml").write_text(BARE_SCENARIO.format(robot="ur5.urdf"))
    r = run_limited([sys.executable, "-m", "sim", "run", str(tmp_path / "s.toml"), "--out",
                        str(tmp_path / "out")], capture_output=True, text=True, cpu_s=300,
                       env={**__import__("os").environ, "XDG_CACHE_HOME": str(tmp_path / "c")})
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "ur5.urdf" in lines[0], r.stderr
    assert not (tmp_path / "out").exists()


# ---------------------------------------------------------------------------- a 5-axis DH arm
#: A 5-axis arm of seed 000's structure as a standard DH table [a m, alpha rad, d m, offset rad]
#: (the LR Mate 100iB's lengths: l1 = 150, d1 = 250, l2 = 220, J2 350 mm up, 145 mm to the
#: flange on the J5 axis).
FIVE_DH = np.array([[0.150, -np.pi / 2, 0.350, 0.0], [0.250, 0.0, 0.0, -np.pi / 2],
                    [0.220, 0.0, 0.0, 0.0], [0.0, -np.pi / 2, 0.0, -np.pi / 2],
                    [0.0, 0.0, 0.145, 0.0]])


def test_a_5_axis_dh_arm_gets_the_seeds_5r_closed_form(tmp_path):
    """A robot folder with a 5-axis DH table of the 5R structure: its IK is seed 000's closed
    form (solver five_r, dimensions l1, d1, l2, l3 read from the table); for 500 random
    configurations the one the pose came from is among at most 4 branches (front/back x
    up/down) modulo whole turns, every solution within 1e-9 of the pose (the textbook DH
    product), and the tool point equals seed 000's eq. 5 with the derived dimensions."""
    from sim.robots.kinematics.closed_form import fk_5r

    (tmp_path / "five").mkdir()
    (tmp_path / "five" / "robot.toml").write_text(robot_toml(FIVE_DH, "five"))
    arm = load_arm(tmp_path / "five")
    assert arm.solver == "five_r", arm.why_numeric
    assert arm.five.dims == pytest.approx({"l1": 0.150, "d1": 0.250, "l2": 0.220, "l3": 0.145},
                                          abs=1e-12)
    for q in random_q(arm.chain, 500, seed=12):
        T = dh_product(FIVE_DH, q)
        sols = arm.ik(T)
        assert 1 <= len({s.branch for s in sols}) <= 4
        assert {s.branch for s in sols} <= {"front/up", "front/down", "back/up", "back/down"}
        for s in sols:
            assert np.abs(dh_product(FIVE_DH, s.q) - T).max() < 1e-9
        assert min(np.abs(s.q - q).max() for s in sols) < 1e-9
        _, p = fk_5r(arm.five.theta(q), arm.five.dims)
        np.testing.assert_allclose(p + [0, 0, 0.350], T[:3, 3], atol=1e-12)


def test_a_5_axis_arm_anchored_anywhere_along_its_parallel_axes_is_still_5r(tmp_path):
    """Where the joint frames sit along the parallel J2..J4 axes changes nothing (DH d of J2
    and J3 +-30 mm: the same arm): still the 5R closed form, same dimensions."""
    rows = FIVE_DH.copy()
    rows[1, 2], rows[2, 2] = 0.030, -0.030
    (tmp_path / "five").mkdir()
    (tmp_path / "five" / "robot.toml").write_text(robot_toml(rows, "five"))
    arm = load_arm(tmp_path / "five")
    assert arm.solver == "five_r", arm.why_numeric
    assert arm.five.dims == pytest.approx({"l1": 0.150, "d1": 0.250, "l2": 0.220, "l3": 0.145},
                                          abs=1e-12)
    for q in random_q(arm.chain, 50, seed=3):
        assert min(np.abs(s.q - q).max() for s in arm.ik(dh_product(rows, q))) < 1e-9


def test_a_5_axis_arm_with_a_lateral_offset_is_solved_numerically(tmp_path):
    """The same arm with its wrist 30 mm out of the arm's plane is no 5R arm: numeric IK, and
    the reason says why."""
    rows = FIVE_DH.copy()
    rows[4, 2] = 0.0
    rows[3, 2] = 0.030  # J5 (and the flange) 30 mm out of the arm's plane
    (tmp_path / "five").mkdir()
    (tmp_path / "five" / "robot.toml").write_text(robot_toml(rows, "five"))
    arm = load_arm(tmp_path / "five")
    assert arm.solver == "numeric" and "lateral offset" in arm.why_numeric


@pytest.mark.parametrize("edit,needle", [
    (lambda t: t.replace("home_deg = [0, -90, 90, 0, 0, 0]", "home_deg = [0, -90]"),
     "joints.home_deg: 2 values for 6 joints"),
    (lambda t: t.replace("home_deg = [0, -90, 90, 0, 0, 0]", "home_deg = [0, -90, 900, 0, 0, 0]"),
     "outside its range"),
    (lambda t: t.replace("home_deg = [0, -90, 90, 0, 0, 0]", "home_deg = [0, -80, 90, 0, 0, 0]"),
     "is not the model of this robot.toml"),
])
def test_a_kept_model_must_match_its_robot_toml(edit, needle, tmp_path):
    """A folder keeping its generated model (mjcf) with home_deg of the wrong length, out of
    range, or no longer the model's home keyframe: one line naming the file and key."""
    import shutil

    from sim.robots.robotfile import load_robot_folder

    dst = tmp_path / "kr6"
    shutil.copytree(MODELS / "kuka_kr6r900_2", dst)
    toml = dst / "robot.toml"
    toml.write_text(edit(toml.read_text()))
    with pytest.raises(KinematicsError, match=needle) as e:
        load_robot_folder(dst)
    assert "robot.toml" in str(e.value) and "\n" not in str(e.value)


def test_a_drive_whose_peak_is_below_its_rated_torque_is_refused(tmp_path):
    """robot.toml's [[drives]] are held to what a scenario's [drives.jN] is: a peak torque
    under the rated one is a typo (a trial's j6 with 0.1 against 0.32 N m ran and passed)."""
    import shutil

    from sim.robots.robotfile import load_robot_folder

    dst = tmp_path / "kr6"
    shutil.copytree(MODELS / "kuka_kr6r900_2", dst)
    toml = dst / "robot.toml"
    text = toml.read_text()
    assert text.count("peak_torque_nm = 4.5\n") >= 1  # J1's comes first
    toml.write_text(text.replace("peak_torque_nm = 4.5\n", "peak_torque_nm = 0.5\n", 1))
    with pytest.raises(KinematicsError, match=r"drives\[0\] \(j1\): peak_torque_nm 0.5 N m is "
                       r"below rated_torque_nm 1.3 N m") as e:
        load_robot_folder(dst)
    assert "robot.toml" in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("name", ["lrmate200ic5l", "kr6r900_2"])
def test_a_robot_of_ones_own_may_not_take_a_shipped_robots_name(tmp_path, name):
    """Cells are laid out for a robot by name ([robot] model): a DH arm of one's own named
    after a shipped robot went into the LR Mate's pick cell, which took it for the LR Mate (a
    trial: 42 findings). Refused in one line naming the file; the shipped folder itself,
    given by its path, is still the shipped robot."""
    from sim.robots.registry import ROBOTS, resolve_robot

    (tmp_path / "arm").mkdir()
    (tmp_path / "arm" / "robot.toml").write_text(DH_ROBOT.replace('"dh_arm"', f'"{name}"', 1))
    with pytest.raises(KinematicsError, match=f"name '{name}' is a shipped robot's name") as e:
        resolve_robot("./arm", tmp_path)
    assert str(e.value).startswith(str(tmp_path / "arm" / "robot.toml"))
    (tmp_path / "arm" / "robot.toml").write_text(DH_ROBOT.replace('"dh_arm"', f'"my_{name}"', 1))
    assert resolve_robot("./arm", tmp_path).name == f"my_{name}"
    shipped = ROBOTS.get(name)
    assert resolve_robot(str(MODELS / shipped.folder)).name == name


def test_a_urdf_robot_name_that_is_no_file_name_still_runs(tmp_path, monkeypatch):
    """<robot name='my/ur "5"'>: the generated model is named after the file instead."""
    from sim.robots.registry import resolve_robot

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    text = ur5_urdf_with_inertials().replace('<robot name="ur5">', '<robot name=\'my/ur "5"\'>')
    (tmp_path / "arm.urdf").write_text(text)
    spec = resolve_robot("arm.urdf", tmp_path)
    assert spec.name == "arm" and spec.robot_path.is_file()


def test_every_collision_geom_of_a_generated_arm_is_named_after_its_link(dh_robot):
    """A collision finding names the geoms that touched: a generated arm's were
    "unnamed_geom_9" (a trial); each is now ``base_collision`` or ``link<k>_collision`` on
    body ``link<k>``, as the compiled model shows."""
    import mujoco

    from sim.robots.robotfile import load_robot_folder

    spec = load_robot_folder(dh_robot / "robots" / "dh_arm")
    model = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    names = []
    for g in range(model.ngeom):
        if model.geom_group[g] != 3:  # the collision class
            continue
        body = model.body(model.geom_bodyid[g]).name
        name = model.geom(g).name
        assert name == ("base_collision" if body == "base" else f"{body}_collision"), name
        names.append(name)
    assert names[:2] == ["base_collision", "link1_collision"] and len(names) == 1 + 6


def test_a_second_load_of_a_dh_robot_reuses_its_cache_without_mujoco(dh_robot):
    """The first load of a DH robot folder writes its model and derived acceleration limits
    into cellsim's cache; a second load (a new process) reads both back, identical, and does
    not import mujoco (the command line picks its OpenGL backend after loading a scenario)."""
    import os

    from sim.robots.robotfile import load_robot_folder

    first = load_robot_folder(dh_robot / "robots" / "dh_arm")
    code = ("import sys, json; from sim.robots.robotfile import load_robot_folder; "
            f"s = load_robot_folder({str(dh_robot / 'robots' / 'dh_arm')!r}); "
            "print(json.dumps([list(s.max_accel), 'mujoco' in sys.modules]))")
    r = run_limited([sys.executable, "-c", code], capture_output=True, text=True,
                       cpu_s=300, env={**os.environ})
    assert r.returncode == 0, r.stderr
    import json

    accel, imported = json.loads(r.stdout.strip().splitlines()[-1])
    assert accel == list(first.max_accel)
    assert imported is False


def test_a_numeric_arms_path_ik_continues_its_branch_as_the_global_search_would(tmp_path):
    """Along generated smooth paths of a UR5 with its J4 tilted 10 deg (neither closed form:
    numeric IK), ``ik_path`` continues each point from the one before with one local Newton
    run: every pose is reached (FK of the result), and each point's joints are those the
    global search (every seed, the nearest taken) gives from the point before."""
    from sim.robots.families.chain_family import ChainFamily
    from sim.robots.kinematics.ik import ik_path
    from sim.robots.kinematics.model import KinematicModel

    rows = UR5_DH.copy()
    rows[2, 1] = np.radians(10.0)
    (tmp_path / "robot.toml").write_text(robot_toml(rows, "ur5_tilted"))
    arm = load_arm(tmp_path)
    assert arm.solver == "numeric"
    model = KinematicModel("ur5", ChainFamily(arm), lower=arm.chain.lower,
                           upper=arm.chain.upper)
    rng = np.random.default_rng(5)
    for _ in range(3):
        q0 = random_q(arm.chain, 1, seed=int(rng.integers(1000)))[0]
        q1 = q0 + rng.uniform(-0.4, 0.4, 6)
        Q = np.linspace(q0, q1, 15)
        poses = np.array([arm.chain.fk(q) for q in Q])
        got = ik_path(model, poses, q_start=q0)
        prev = q0
        for k, T in enumerate(poses):
            np.testing.assert_allclose(arm.chain.fk(got[k]), T, atol=1e-9)
            sols = numeric_ik(arm.chain, T, prev)
            want = min(sols, key=lambda s: float(np.sum(((s - prev) / model.max_speed) ** 2)))
            # the same configuration (the global search gives each joint's lowest turn in range)
            np.testing.assert_allclose(np.angle(np.exp(1j * (got[k] - want))), 0.0, atol=1e-6,
                                       err_msg=f"point {k}")
            prev = got[k]


@pytest.mark.parametrize("kind", ["joint", "link"])
def test_a_urdf_with_two_joints_or_links_of_one_name_is_refused(kind, tmp_path):
    """Issue 31: a second joint (or link) of one name silently replaced the first; now one
    line naming the file and the name."""
    text = SHIPPED_DATA["irb2400"].read_text()
    if kind == "joint":
        text = text.replace('<joint name="joint_2"', '<joint name="joint_1"')
    else:
        text = text.replace('<link name="link_2"/>', '<link name="link_1"/>')
    path = tmp_path / "twice.urdf"
    path.write_text(text)
    with pytest.raises(KinematicsError, match=rf"two {kind}s named '(joint|link)_1'"):
        chain_from_urdf(path)
