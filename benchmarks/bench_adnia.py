"""Benchmark of ADNIA Cartesian interpolation: sampling throughput (points/s) of long moves.

Times ``CartesianTrajectory.sample(dt)`` (position, velocity, acceleration, jerk, tool frame,
angular velocity per point) for a long line, a long arc, a multi-turn circle and a spherical
move, and the discrete seed-003 algorithms (:func:`adnia_linear`, :func:`adnia_arc`), at the
controller period ``--dt``. Each figure is the best of ``--repeat`` runs.

Usage::

    .venv/bin/python benchmarks/bench_adnia.py
    .venv/bin/python benchmarks/bench_adnia.py --points 2000000 --repeat 5 --json bench_adnia.json
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from planners.adnia import (  # noqa: E402
    adnia_arc,
    adnia_linear,
    arc_move,
    circle_move,
    linear_move,
    spherical_move,
)


def _best(fn: Callable[[], int], repeat: int) -> tuple[float, int]:
    """Best wall time of ``fn`` over ``repeat`` runs, s, and the point count it returned."""
    best, n = math.inf, 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        n = fn()
        best = min(best, time.perf_counter() - t0)
    return best, n


def run(points: int = 1_000_000, dt: float = 1e-3, repeat: int = 3) -> list[dict]:
    """Time every case for about ``points`` samples each.

    Returns:
        One dict per case: ``case``, ``points``, ``seconds``, ``points_per_s``.
    """
    v = 0.1                                   # m/s
    L = points * v * dt                       # path length for ~points samples, m
    R = 0.5
    cases: dict[str, Callable[[], int]] = {}

    line = linear_move([0, 0, 0], [L / math.sqrt(3)] * 3, v, ramp_time=0.2,
                       rotation_end=np.diag([1.0, -1.0, -1.0]))
    cases["line  sample(dt)"] = lambda: len(line.sample(dt)[0])

    # arc: 3 points, 350 deg, with the radius chosen for the same length
    Ra = L / math.radians(350)
    ang = np.radians([0.0, 175.0, 350.0])
    A, B, C = (np.stack([Ra * np.cos(ang), Ra * np.sin(ang), 0.1 * np.ones(3)], axis=1))
    arc = arc_move(A, B, C, v, ramp_time=0.2)
    cases["arc   sample(dt)"] = lambda: len(arc.sample(dt)[0])

    turns = L / (2 * math.pi * R)
    circ = circle_move([0, 0, 0], [0, 0, 1], [R, 0, 0], 2 * math.pi * turns, v, ramp_time=0.2)
    cases["circle sample(dt) (multi-turn)"] = lambda: len(circ.sample(dt)[0])

    Rs = L / 2.0                              # the curve below is about 2 R long
    sph = spherical_move((Rs, 0.0, math.pi / 2), (Rs, math.radians(100), math.pi / 4), v,
                         ramp_time=0.2, orientation="spherical",
                         rotation_end=np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]))
    dt_s = sph.duration / points
    cases["sphere sample(dt)"] = lambda: len(sph.sample(dt_s)[0])

    cases["adnia_linear (discrete, eq. 1-7)"] = lambda: len(
        adnia_linear([0, 0, 0], [L, 0, 0], v, dt).points)
    cases["adnia_linear + 0.01 mm DDA steps"] = lambda: len(
        adnia_linear([0, 0, 0], [L, 0.3 * L, 0], v, dt, resolution=1e-5).points)
    cases["adnia_arc (discrete, eq. 11-14)"] = lambda: len(adnia_arc(A, B, C, v, dt).points)

    out = []
    for name, fn in cases.items():
        fn()                                  # warm-up (caches, allocations)
        sec, n = _best(fn, repeat)
        out.append({"case": name, "points": n, "seconds": sec, "points_per_s": n / sec})
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1_000_000, help="samples per move (default 1e6)")
    ap.add_argument("--dt", type=float, default=1e-3, help="controller period, s (default 1e-3)")
    ap.add_argument("--repeat", type=int, default=3, help="runs per case, best kept (default 3)")
    ap.add_argument("--json", type=Path, help="also write the results to this JSON file")
    args = ap.parse_args(argv)
    rows = run(args.points, args.dt, args.repeat)
    print(f"ADNIA sampling throughput, best of {args.repeat}; python {platform.python_version()},"
          f" numpy {np.__version__}, {platform.machine()}")
    print(f"{'case':36s} {'points':>10s} {'time, s':>9s} {'points/s':>12s}")
    for r in rows:
        print(f"{r['case']:36s} {r['points']:10d} {r['seconds']:9.3f} {r['points_per_s']:12.3e}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
