"""Planning time and evaluation throughput of the joint-space planners (4-3-4, 5-4-6).

Run:  python benchmarks/bench_planners.py [--joints 6] [--repeat 5]

For 10, 100, 1000 and 10000 knots of random positions (uneven durations, 6 joints) it
prints the best-of-N wall time of one planning call (validation + one banded solve for all
joints + building the trajectory), the time per knot (constant when growth is linear), and
the evaluation throughput of ``at`` (q, qd, qdd, qddd for every joint) in samples per second,
plus the time of ``extrema()``.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

from planners import plan_434, plan_546


def best_time(fn, repeat: int) -> float:
    """Best wall time of ``repeat`` calls, s."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--joints", type=int, default=6)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--samples", type=int, default=200_000, help="samples per evaluation call")
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    print(f"python {platform.python_version()}, numpy {np.__version__}, {platform.machine()}; "
          f"{args.joints} joints, best of {args.repeat}")
    header = (f"{'planner':>7} {'knots':>6} {'plan ms':>9} {'us/knot':>8} "
              f"{'eval Msamples/s':>16} {'extrema ms':>11}")
    print(header)
    print("-" * len(header))
    for name, plan in (("434", plan_434), ("546", plan_546)):
        for n_knots in (10, 100, 1000, 10000):
            h = rng.uniform(0.1, 1.0, n_knots - 1)
            times = np.concatenate(([0.0], np.cumsum(h)))
            q = rng.uniform(-1.0, 1.0, (n_knots, args.joints))
            plan(times, q)  # warm-up
            t_plan = best_time(lambda: plan(times, q), args.repeat)
            traj = plan(times, q)
            t = np.sort(rng.uniform(traj.start, traj.end, args.samples))
            t_eval = best_time(lambda: traj.at(t), args.repeat)
            t_ext = best_time(traj.extrema, max(1, args.repeat // 2))
            print(f"{name:>7} {n_knots:>6} {t_plan * 1e3:>9.3f} {t_plan / n_knots * 1e6:>8.2f} "
                  f"{args.samples / t_eval / 1e6:>16.2f} {t_ext * 1e3:>11.2f}")


if __name__ == "__main__":
    main()
