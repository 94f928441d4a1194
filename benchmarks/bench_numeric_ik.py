"""Numeric and closed-form inverse kinematics of arms given as data (issue 13).

Numeric: 1000 random reachable poses of a UR5 (offset wrist, no closed form; standard DH from
Universal Robots' table), each solved from the zero configuration then random seeds until one
solution reaches a pose error under 1e-9 (``sim.robots.kinematics.numeric_ik.solve_ik(first=True)``). The
issue's goal: 99 % solved within 20 ms each. Closed form: the same count of poses of the KUKA
KR 6 R700 sixx (its URDF, tests/data), every branch (``Arm.ik``), for the ratio of the two.

Run: ``.venv/bin/python benchmarks/bench_numeric_ik.py [--poses 1000]``
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sim.robots.arm import load_arm  # noqa: E402
from sim.robots.kinematics.chain import chain_from_dh  # noqa: E402
from sim.robots.kinematics.numeric_ik import pose_error, solve_ik  # noqa: E402

UR5_DH = np.array([[0.0, np.pi / 2, 0.089159, 0.0], [-0.425, 0.0, 0.0, 0.0],
                   [-0.39225, 0.0, 0.0, 0.0], [0.0, np.pi / 2, 0.10915, 0.0],
                   [0.0, -np.pi / 2, 0.09465, 0.0], [0.0, 0.0, 0.0823, 0.0]])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=1000)
    args = ap.parse_args()
    chain = chain_from_dh(UR5_DH, lower=np.full(6, -2 * np.pi), upper=np.full(6, 2 * np.pi))
    rng = np.random.default_rng(2026)
    Q = rng.uniform(-np.pi, np.pi, size=(args.poses, 6))
    times, solved = [], 0
    for q in Q:
        T = chain.fk(q)
        t0 = time.perf_counter()
        sols = solve_ik(chain, T, first=True)
        dt = time.perf_counter() - t0
        ok = bool(sols) and np.linalg.norm(pose_error(chain.fk(sols[0]), T)) < 1e-9
        solved += ok
        times.append(dt if ok else np.inf)
    t = np.array(times)
    within = np.mean(t < 0.020)
    finite = t[np.isfinite(t)]
    print(f"numeric IK, UR5, {args.poses} random reachable poses: solved {solved / len(Q):.1%}; "
          f"solved within 20 ms: {within:.1%}; time per pose median {np.median(finite) * 1e3:.2f} ms, "
          f"95th percentile {np.percentile(finite, 95) * 1e3:.2f} ms, max {finite.max() * 1e3:.2f} ms")
    arm = load_arm(ROOT / "tests" / "data" / "kuka_kr6r700sixx.urdf")
    Qk = rng.uniform(arm.chain.lower, arm.chain.upper, size=(args.poses, 6))
    t0 = time.perf_counter()
    n = sum(len(arm.ik(arm.fk(q))) for q in Qk)
    dt = (time.perf_counter() - t0) / len(Qk)
    print(f"closed form (OPW), KR 6 R700 sixx: {dt * 1e3:.3f} ms per pose, all branches and "
          f"turns ({n / len(Qk):.1f} solutions per pose); numeric/closed-form time ratio "
          f"{np.median(finite) / dt:.1f}")
    return 0 if within >= 0.99 else 1


if __name__ == "__main__":
    raise SystemExit(main())
