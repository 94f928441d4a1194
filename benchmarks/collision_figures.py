"""The figures of the collision checks (issue 11), reproducible.

1. Contact depths: for every pair of primitive types, 3000 random poses of a free geom against
   a fixed one; how far ``mj_collision``'s contact depth is from ``mj_geomDistance`` (GJK/EPA),
   and whether ``mj_collision`` ever missed a penetrating pair. ``mj_geomDistance`` itself is
   checked against an analytic case first (a cylinder pressed into a box face).
2. Wrist sweep: per robot, with J1..J3 at ``home`` and J4..J6 over their full ranges (the grid
   of ``tests/robots/test_self_collision.py``), the smallest distance between two robot links
   that are not parent and child (collision geoms, ``mj_geomDistance``).
3. The plunge of ``tests/simulation/test_collisions.py``: when the wire tip reaches the base
   plate's top and when the reported torch-plate collision starts.

Usage: python benchmarks/collision_figures.py [depths] [wrist] [plunge]
"""

from __future__ import annotations

import itertools
import math
import tempfile
from pathlib import Path

import mujoco
import numpy as np

from sim.robots.registry import ROBOTS

SHAPES = {"box": 'type="box" size="0.1 0.05 0.02"', "cylinder": 'type="cylinder" size="0.03 0.06"',
          "capsule": 'type="capsule" size="0.03 0.06"', "sphere": 'type="sphere" size="0.04"'}


def depth_errors() -> None:
    xml = ('<mujoco><worldbody><geom type="box" size="0.1 0.05 0.02"/><body><freejoint/>'
           '<geom type="cylinder" size="0.03 0.06"/></body></worldbody></mujoco>')
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qpos[:7] = [0.02, 0.0, 0.02 + 0.06 - 0.005, 1, 0, 0, 0]  # 5 mm into the box's top face
    mujoco.mj_kinematics(m, d)
    print(f"analytic check: cylinder 5 mm into a box: mj_geomDistance "
          f"{mujoco.mj_geomDistance(m, d, 0, 1, 0.5, np.zeros(6)) * 1e3:.4f} mm")
    print(f"{'pair':18s} {'penetrating':>11s} {'missed':>6s} {'worst depth error (mm)':>23s}")
    rng = np.random.default_rng(1)
    for a, b in itertools.product(SHAPES, SHAPES):
        xml = (f'<mujoco><worldbody><geom {SHAPES[a]} margin="0.001"/><body><freejoint/>'
               f'<geom {SHAPES[b]} margin="0.001"/></body></worldbody></mujoco>')
        m = mujoco.MjModel.from_xml_string(xml)
        d = mujoco.MjData(m)
        n = missed = 0
        worst = 0.0
        for _ in range(3000):
            q = rng.normal(size=4)
            d.qpos[:3], d.qpos[3:] = rng.uniform(-0.12, 0.12, 3), q / np.linalg.norm(q)
            mujoco.mj_kinematics(m, d)
            mujoco.mj_collision(m, d)
            true = mujoco.mj_geomDistance(m, d, 0, 1, 0.5, np.zeros(6))
            if true < -1e-4:
                n += 1
                reported = [c.dist for c in d.contact[:d.ncon]]
                if not reported:
                    missed += 1
                else:
                    worst = max(worst, min(reported) - true)
        print(f"{a + '-' + b:18s} {n:11d} {missed:6d} {worst * 1e3:23.1f}")


def wrist_gaps() -> None:
    print("wrist sweep at home, smallest gap between links that are not parent and child:")
    for name, spec in ROBOTS.items():
        mspec = mujoco.MjSpec.from_file(str(spec.robot_path))
        for g in mspec.geoms:
            on = int(g.group == 3)
            g.contype = g.conaffinity = on
            g.margin = 0.05 * on
        m = mspec.compile()
        d = mujoco.MjData(m)
        home = m.key("home").qpos.copy()
        lo, hi = m.jnt_range.T
        grids = []
        for j in range(3, m.njnt):
            step = math.radians(2.5 if abs(m.jnt_axis[j, 1]) == 1.0 else 15.0)
            grids.append(np.r_[np.arange(lo[j], hi[j], step), hi[j]])
        best, where = np.inf, None
        for wrist in itertools.product(*grids):
            d.qpos[:] = home
            d.qpos[3:] = wrist
            mujoco.mj_kinematics(m, d)
            mujoco.mj_collision(m, d)
            for c in d.contact[:d.ncon]:
                g1, g2 = int(c.geom[0]), int(c.geom[1])
                b1, b2 = int(m.geom_bodyid[g1]), int(m.geom_bodyid[g2])
                if b1 == b2 or m.body_parentid[b1] == b2 or m.body_parentid[b2] == b1:
                    continue
                dist = mujoco.mj_geomDistance(m, d, g1, g2, 0.05, np.zeros(6))
                if dist < best:
                    best = dist
                    where = (m.body(m.geom_bodyid[g1]).name, m.body(m.geom_bodyid[g2]).name,
                             np.round(np.degrees(np.asarray(wrist)), 1).tolist())
        print(f"  {name:16s} {best * 1e3:6.1f} mm  {where}")


def plunge() -> None:
    import sys

    tests = Path(__file__).resolve().parents[1] / "tests"
    sys.path[:0] = [str(tests / "simulation"), str(tests)]
    from test_collisions import PLUNGE  # the scenario the test runs

    from sim.pipeline.run import RunOptions, run_scenario
    from sim.scenario import load_scenario

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "plunge.toml"
        path.write_text(PLUNGE)
        summary = run_scenario(load_scenario(path), RunOptions(
            out_dir=Path(tmp) / "run", video=False, plots=False, sizing=False, progress=False))
        m = mujoco.MjModel.from_xml_path(str(Path(tmp) / "run" / "model.xml"))
        traj = np.load(Path(tmp) / "run" / "trajectory.npz")
        g = m.geom("base_plate").id
        top = m.geom_pos[g][2] + m.geom_size[g][2]
        t_hit = traj["t"][np.argmax(traj["tcp_pos"][:, 2] <= top)]
    print(f"plunge: wire tip at the plate top at {t_hit:.3f} s")
    for c in summary["collisions"]:
        print(f"  {c['kind']} {c['bodies'][0]} / {c['bodies'][1]}: {c['t0']:.3f}-{c['t1']:.3f} s, "
              f"{c['depth_mm']:.1f} mm deep")


if __name__ == "__main__":
    import sys

    parts = sys.argv[1:] or ["depths", "wrist", "plunge"]
    for part, fn in (("depths", depth_errors), ("wrist", wrist_gaps), ("plunge", plunge)):
        if part in parts:
            fn()
