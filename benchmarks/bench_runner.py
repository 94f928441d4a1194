"""Runner speed: simulation time of `cellsim run` against a bare mujoco.mj_step loop.

For each shipped scenario (or those named on the command line) this builds the cell and the
reference motion, then times, over the same model and number of steps:

* ``bare``: a plain Python loop ``for k in range(n): mj_step(model, data)`` (ctrl held);
* ``sim``: the runner's simulation proper (``summary.wall_s``: the chunked mujoco.rollout);
* ``total``: :func:`sim.simulation.simulate.simulate` as a whole (inverse dynamics of the reference,
  controls, rollout, recording).

and prints ``sim/bare`` (target <= 1.2) and ``total/bare`` with the real-time factor.

Usage: python benchmarks/bench_runner.py [SCENARIO ...] [--repeat N]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from sim.core.resources import shipped_scenarios
from sim.scenario import load_scenario
from sim.simulation.compile import build
from sim.simulation.motion import build_motion
from sim.simulation.simulate import simulate


def bare_loop(model: mujoco.MjModel, n: int, q0: np.ndarray, built) -> float:
    data = mujoco.MjData(model)
    data.qpos[built.robot_qpos] = q0
    data.ctrl[built.robot_act] = q0
    mujoco.mj_forward(model, data)
    t0 = time.perf_counter()
    for _ in range(n):
        mujoco.mj_step(model, data)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*")
    ap.add_argument("--repeat", type=int, default=3, help="best of N (default 3)")
    args = ap.parse_args()
    names = args.scenarios or list(shipped_scenarios())
    print(f"{'scenario':32s} {'steps':>7s} {'bare s':>8s} {'sim s':>8s} {'total s':>8s} "
          f"{'sim/bare':>9s} {'total/bare':>10s} {'realtime x':>10s}")
    for name in names:
        sc = load_scenario(name)
        built = build(sc)
        motion = build_motion(sc, built.context)
        # the drives as the runner passes them (their torque-speed curves limit the actuators)
        drives = sc.drive_train
        drives = drives if sc.simulation.motor_speed_limits and drives else None
        best_sim = best_total = best_bare = np.inf
        steps = 0
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            rec = simulate(built, motion, feedforward=sc.simulation.feedforward,
                           settle_s=sc.simulation.settle_s, progress=False, drives=drives)
            best_total = min(best_total, time.perf_counter() - t0)
            best_sim = min(best_sim, rec.wall_s)
            steps = rec.steps
            best_bare = min(best_bare, bare_loop(built.model, steps, motion.at(motion.t0).q[0],
                                                 built))
        rt = steps * built.model.opt.timestep / best_sim
        print(f"{name:32s} {steps:7d} {best_bare:8.3f} {best_sim:8.3f} {best_total:8.3f} "
              f"{best_sim / best_bare:9.2f} {best_total / best_bare:10.2f} {rt:10.1f}")


if __name__ == "__main__":
    main()
