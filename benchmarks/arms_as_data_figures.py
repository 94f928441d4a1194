"""Figures of the arms given as data (issue 13), each against an independent computation:

* the shipped KUKA KR 6 R900-2 and ABB IRB 2400: the generated model's flange against MuJoCo's
  own compile of the public URDF (``tool0``), 1000 random configurations; the derived OPW
  parameters against the published sets; IK round trips;
* a 5-axis DH arm of seed 000's structure: the 5R closed form's round trip against the textbook
  DH product;
* a bare URDF with inertials (the UR5 masses): the generated model's mass matrix and bias forces
  against MuJoCo's compile of the same URDF;
* time per IK call of each solver.

Run: ``.venv/bin/python benchmarks/arms_as_data_figures.py``
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "robots"))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))

from test_robots_as_data import (  # noqa: E402
    FIVE_DH,
    PUBLISHED,
    SHIPPED_DATA,
    URDFS,
    dh_product,
    mujoco_compiled_urdf,
    random_q,
    robot_toml,
    ur5_urdf_with_inertials,
)

from sim.robots.arm import load_arm  # noqa: E402
from sim.robots.kinematics import opw  # noqa: E402
from sim.robots.kinematics.chain import chain_from_urdf  # noqa: E402
from sim.robots.registry import ROBOTS, resolve_robot  # noqa: E402

print("shipped arms: generated model vs MuJoCo's compile of the public URDF (1000 configs)")
for name, urdf in SHIPPED_DATA.items():
    spec = ROBOTS[name]
    m = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    ref = mujoco_compiled_urdf(urdf)
    d, dr = mujoco.MjData(m), mujoco.MjData(ref)
    pos = rot = 0.0
    for q in np.random.default_rng(4).uniform(ref.jnt_range[:, 0], ref.jnt_range[:, 1], (1000, 6)):
        d.qpos[:] = dr.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_kinematics(ref, dr)
        pos = max(pos, np.abs(d.site_xpos[m.site("flange").id] - dr.xpos[ref.body("tool0").id]).max())
        rot = max(rot, np.abs(d.site_xmat[m.site("flange").id] - dr.xmat[ref.body("tool0").id]).max())
    print(f"  {name}: max position error {pos:.2e} m, max rotation entry error {rot:.2e}")

print("OPW parameters derived from the URDF chains vs the published sets")
for key, want in PUBLISHED.items():
    chain = chain_from_urdf(URDFS[key])
    p = opw.opw_from_axes(*chain.frames(np.zeros(6)), key)
    dl = max(abs(v - want[k]) for k, v in p.lengths().items())
    do = np.abs(np.asarray(p.offsets) - want["offsets"]).max()
    print(f"  {key}: lengths {1e3 * dl:.1e} mm, offsets {do:.1e} rad, signs "
          f"{'equal' if p.signs == want['signs'] else 'DIFFER'}")

print("IK round trips (random configurations; solutions checked by the chain's joint product)")
for name in SHIPPED_DATA:
    arm = ROBOTS[name].family.arm
    worst = back = 0.0
    n_sol = []
    t = time.perf_counter()
    Q = random_q(arm.chain, 300, seed=6)
    for q in Q:
        T = arm.fk(q)
        sols = arm.ik(T)
        n_sol.append(len({s.branch for s in sols}))
        worst = max(worst, max(np.abs(arm.chain.fk(s.q) - T).max() for s in sols))
        back = max(back, min(np.abs(s.q - q).max() for s in sols))
    dt = (time.perf_counter() - t) / len(Q)
    print(f"  {name} (OPW): 300 poses, max pose entry error {worst:.1e}, source config found "
          f"within {back:.1e} rad, branches per pose {min(n_sol)}..{max(n_sol)}, "
          f"{1e3 * dt:.2f} ms per IK")

with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    os.environ["XDG_CACHE_HOME"] = str(tmp / "cache")
    (tmp / "five").mkdir()
    (tmp / "five" / "robot.toml").write_text(robot_toml(FIVE_DH, "five"))
    arm = load_arm(tmp / "five")
    worst = back = 0.0
    t = time.perf_counter()
    Q = random_q(arm.chain, 500, seed=12)
    for q in Q:
        T = dh_product(FIVE_DH, q)
        sols = arm.ik(T)
        worst = max(worst, max(np.abs(dh_product(FIVE_DH, s.q) - T).max() for s in sols))
        back = max(back, min(np.abs(s.q - q).max() for s in sols))
    dt = (time.perf_counter() - t) / len(Q)
    print(f"  5-axis DH arm ({arm.solver}, dims {arm.five.dims}): 500 poses, max pose entry "
          f"error {worst:.1e} (textbook DH product), source config within {back:.1e} rad, "
          f"{1e3 * dt:.2f} ms per IK")

    (tmp / "ur5.urdf").write_text(ur5_urdf_with_inertials())
    spec = resolve_robot("ur5.urdf", tmp)
    ours = mujoco.MjModel.from_xml_path(str(spec.robot_path))
    ref = mujoco_compiled_urdf(tmp / "ur5.urdf", keep_fixed_links=False)
    d, dr = mujoco.MjData(ours), mujoco.MjData(ref)
    M, Mr = np.zeros((6, 6)), np.zeros((6, 6))
    em = eb = 0.0
    rng = np.random.default_rng(8)
    for _ in range(200):
        q, qd = rng.uniform(-2.9, 2.9, 6), rng.uniform(-2, 2, 6)
        d.qpos[:], d.qvel[:], dr.qpos[:], dr.qvel[:] = q, qd, q, qd
        mujoco.mj_forward(ours, d)
        mujoco.mj_forward(ref, dr)
        mujoco.mj_fullM(ours, d, M)
        mujoco.mj_fullM(ref, dr, Mr)
        em = max(em, np.abs(M - Mr).max() / np.abs(Mr).max())
        eb = max(eb, np.abs(d.qfrc_bias - dr.qfrc_bias).max() / np.abs(dr.qfrc_bias).max())
    print(f"bare URDF (UR5 masses; adapter, gripper past tool0 and side box fused): 200 states, mass matrix rel. error "
          f"{em:.1e}, gravity+Coriolis rel. error {eb:.1e} vs MuJoCo's URDF compile; solver "
          f"{spec.family.arm.solver}")
