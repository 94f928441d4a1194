"""Benchmark of actuator-sizing sweeps at scale: variants per minute on the process pool and on
Ray, and what a metrics-only variant costs against its simulation alone.

Each sweep is the real thing (``cellsim size``'s runner, metrics only): the weld plate
(``lrmate200ic_weld_plate``, an 82.6 s cycle) over a payload x speed-scale grid, 8 (2 x 4),
64 (8 x 8) and 256 (16 x 16) variants. Printed per engine and size: wall time, variants per
minute, and the ratio of a variant's wall time (inside its worker: build, plan, simulate,
collision and limit checks, sizing) to its ``simulate`` stage (reference, inverse-dynamics
feed-forward and MuJoCo steps), with the stages' mean times. The two engines' tables are
compared (they must be identical, bit for bit).

``--warp`` instead runs 8 variants (2 payloads x 4 speed scales) of a short scenario on the
MuJoCo Warp backend (Warp's CPU device without a GPU: for parity, not speed) and on the pool,
and prints the largest relative difference of the peak and RMS torques.

Usage::

    .venv/bin/python benchmarks/bench_sweep.py                  # 8, 64, 256 on pool and ray
    .venv/bin/python benchmarks/bench_sweep.py --sizes 8 --engines pool
    .venv/bin/python benchmarks/bench_sweep.py --warp
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sim.pipeline.sweep import run_sweep  # noqa: E402
from sim.pipeline.sweep.evaluation import evaluate_batch, evaluate_variant  # noqa: E402

GRIDS = {8: (2, 4), 64: (8, 8), 256: (16, 16)}


def grid(n: int) -> tuple[list[float], list[float]]:
    """Payloads 0..5 kg and speed scales 0.5..1 for an n-variant sweep."""
    if n in GRIDS:
        p, s = GRIDS[n]
    else:
        p = max(1, int(math.sqrt(n)))
        s = max(1, n // p)
    payloads = [round(x, 6) for x in np.linspace(0.0, 5.0, p)] if p > 1 else [2.5]
    speeds = [round(x, 6) for x in np.linspace(0.5, 1.0, s)] if s > 1 else [1.0]
    return payloads, speeds


def table(result) -> str:
    return json.dumps([{k: repr(v) for k, v in r.items()} for r in result.rows])


def sweep(scenario: str, n: int, engine: str, workers: int, **kw) -> dict:
    payloads, speeds = grid(n)
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        t0 = time.perf_counter()
        res = run_sweep(scenario, payloads, speeds, evaluate_variant, workers=workers,
                        out_dir=Path(tmp) / "sweep", progress=False, engine=engine, **kw)
        wall = time.perf_counter() - t0
    stages: dict[str, list[float]] = {}
    for o in res.outcomes:
        for k, v in o.timings_s.items():
            stages.setdefault(k, []).append(v)
    ratios = [o.wall_s / o.timings_s["simulate"] for o in res.outcomes
              if o.timings_s.get("simulate")]
    return {"variants": len(res.outcomes), "engine": engine, "workers": workers,
            "wall_s": wall, "variants_per_min": 60.0 * len(res.outcomes) / wall,
            "variant_over_simulation": float(np.mean(ratios)) if ratios else float("nan"),
            "stages_mean_s": {k: float(np.mean(v)) for k, v in stages.items()},
            "failures": len(res.failures), "table": table(res)}


def warp_parity(scenario: str, workers: int) -> dict:
    payloads, speeds = [1.0, 3.0], [0.7, 0.8, 0.9, 1.0]
    out = {}
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        for name, kw in (("pool", {}), ("warp", {"batch": functools.partial(evaluate_batch)})):
            t0 = time.perf_counter()
            res = run_sweep(scenario, payloads, speeds, evaluate_variant, workers=workers,
                            out_dir=Path(tmp) / name, progress=False, **kw)
            wall = time.perf_counter() - t0
            out[name] = {"wall_s": wall, "rows": res.rows,
                         "variants_per_min": 60.0 * len(res.outcomes) / wall}
    worst = {}
    for key in ("peak_torque_sim_nm", "rms_torque_sim_nm"):
        # joints that carry at least 2 % of the variant's largest value (a joint that stays
        # still carries only friction: its relative error says nothing)
        big = {}
        for r in out["pool"]["rows"]:
            v = (r["payload_kg"], r["speed_scale"])
            big[v] = max(big.get(v, 0.0), abs(r[key]))
        worst[key] = max(abs(a[key] - b[key]) / abs(a[key])
                         for a, b in zip(out["pool"]["rows"], out["warp"]["rows"])
                         if abs(a[key]) >= 0.02 * big[(a["payload_kg"], a["speed_scale"])])
    return {"variants": len(payloads) * len(speeds), "scenario": scenario,
            "pool_variants_per_min": out["pool"]["variants_per_min"],
            "warp_cpu_variants_per_min": out["warp"]["variants_per_min"],
            "max_relative_difference": worst}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="lrmate200ic_weld_plate")
    ap.add_argument("--sizes", default="8,64,256", help="variant counts (default 8,64,256)")
    ap.add_argument("--engines", default="pool,ray", help="pool, ray or both (default)")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--warp", action="store_true",
                    help="Warp-CPU parity on 8 variants of --warp-scenario instead")
    ap.add_argument("--warp-scenario", default="kacso_lrmate100ib_sequence1")
    ap.add_argument("--json", type=Path, default=None, help="write the numbers here")
    args = ap.parse_args(argv)
    info = {"python": platform.python_version(), "cpu_count": os.cpu_count(),
            "machine": platform.machine()}
    if args.warp:
        out = warp_parity(args.warp_scenario, args.workers)
        print(f"{out['variants']} variants of {out['scenario']}: pool "
              f"{out['pool_variants_per_min']:.1f}/min, MuJoCo Warp (CPU device) "
              f"{out['warp_cpu_variants_per_min']:.1f}/min; largest relative difference: "
              + ", ".join(f"{k} {v:.2%}" for k, v in out["max_relative_difference"].items()))
        if args.json:
            args.json.write_text(json.dumps({**info, **out}, indent=2) + "\n")
        return 0
    results = []
    for n in (int(x) for x in args.sizes.split(",")):
        tables = {}
        for engine in args.engines.split(","):
            r = sweep(args.scenario, n, engine, args.workers)
            tables[engine] = r.pop("table")
            results.append(r)
            st = ", ".join(f"{k} {v:.2f}" for k, v in r["stages_mean_s"].items())
            print(f"{n:4d} variants, {engine:4s}, {args.workers} workers: {r['wall_s']:7.1f} s, "
                  f"{r['variants_per_min']:6.1f} variants/min; a variant costs "
                  f"{r['variant_over_simulation']:.2f}x its simulation (mean s: {st})",
                  flush=True)
        if len(tables) > 1:
            same = len(set(tables.values())) == 1
            print(f"     tables identical across {', '.join(tables)}: {same}", flush=True)
            results.append({"variants": n, "identical_tables": same})
    if args.json:
        args.json.write_text(json.dumps({**info, "results": results}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
