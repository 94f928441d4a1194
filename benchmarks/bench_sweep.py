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

By default (issue 29's acceptance) it prints instead, for the weld plate:

* the pool's start-up on its own (start ``--workers`` warmed workers, one no-op each), the
  median of ``--repeat`` pools (it varies by a tenth of a second from one to the next);
* one metrics-only variant's wall time against its ``simulate`` stage (target <= 1.3): the
  first variant of a plan in a process (it scans the plan's reference) and a variant that
  reuses its plan (another payload at the same speed: what every further variant of a plan
  costs), each also without the reuse (a variant checked as a run checks it);
* a 6-variant sweep on 2 workers, its wall time against the bound
  ``1.5 x (6 x one variant's simulate) / 2 + the pool's start-up`` (the sum of the 6 variants'
  own simulate stages: a slower speed scale simulates a longer cycle): 6 payloads at one speed
  (one plan: each worker scans its reference once and reuses it) and a 2 x 3 grid (three plans
  over two workers: a plan and its reference scan per task that has it, four in all), each
  with and without the reuse; the tables with and without the reuse must be identical. Each
  sweep runs ``--repeat`` times, each time in a new Python process as ``cellsim size`` runs
  it (a fresh interpreter each time, its report written); every run's ratio is printed and the
  figures are of the median run. Below each sweep's line: how much of its wall the pool took
  (the rest: loading the scenario and writing the report), the variants' own wall times and
  their stages, summed.

Wall times on a machine shared with other jobs say little: CPU times (this process's, and the
workers' from ``getrusage``) and the load average are printed beside them.

Usage::

    .venv/bin/python benchmarks/bench_sweep.py                  # the acceptance figures
    .venv/bin/python benchmarks/bench_sweep.py --scale          # 8, 64, 256 on pool and ray
    .venv/bin/python benchmarks/bench_sweep.py --scale --sizes 8 --engines pool
    .venv/bin/python benchmarks/bench_sweep.py --warp
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from sim.pipeline.sweep import Variant, run_sweep  # noqa: E402
from sim.pipeline.sweep import reuse as sweep_reuse  # noqa: E402
from sim.pipeline.sweep.engines import pool_startup_s  # noqa: E402
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
                         for a, b in zip(out["pool"]["rows"], out["warp"]["rows"], strict=True)
                         if abs(a[key]) >= 0.02 * big[(a["payload_kg"], a["speed_scale"])])
    return {"variants": len(payloads) * len(speeds), "scenario": scenario,
            "pool_variants_per_min": out["pool"]["variants_per_min"],
            "warp_cpu_variants_per_min": out["warp"]["variants_per_min"],
            "max_relative_difference": worst}


def evaluate_without_reuse(variant: Variant) -> object:
    """A variant checked as a run checks it (no plan scan reused): the figures before."""
    sweep_reuse.ENABLED = False
    return evaluate_variant(variant)


def one_sweep(spec: str) -> None:
    """``--one-sweep SPEC``: run one sweep (SPEC: JSON with the scenario, payloads, speed
    scales, workers and whether the plan's scan is reused) and print its figures as one JSON
    line: the wall time of ``run_sweep`` (its scenario load, pool, variants and report), the
    workers' CPU, the pool's wall, each variant's stages, wall and cycle, and the table."""
    a = json.loads(spec)
    runner = evaluate_variant if a["reuse"] else evaluate_without_reuse
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        c0, w0 = children_cpu(), time.perf_counter()
        res = run_sweep(a["scenario"], a["payloads"], a["speeds"], runner,
                        workers=a["workers"], out_dir=Path(tmp) / "sweep", progress=False,
                        raise_on_failure=False)
        wall, cpu = time.perf_counter() - w0, children_cpu() - c0
    print(json.dumps({"wall": wall, "cpu": cpu, "wall_s": res.wall_s,
                      "failures": len(res.failures), "table": table(res),
                      "outcomes": [{"timings_s": o.timings_s, "wall_s": o.wall_s,
                                    "duration_s": o.rows[0]["duration_s"] if o.rows else None}
                                   for o in res.outcomes]}))


def sweep_in_a_new_process(scenario: str, payloads: list[float], speeds: list[float],
                           workers: int, reuse: bool) -> Any:
    """:func:`one_sweep` in a new Python process; its figures as attributes (``outcomes``
    with ``timings_s``, ``wall_s`` and ``rows[0]["duration_s"]``, as a sweep's)."""
    spec = json.dumps({"scenario": scenario, "payloads": payloads, "speeds": speeds,
                       "workers": workers, "reuse": reuse})
    done = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--one-sweep", spec],
                          capture_output=True, text=True, check=True)
    got = json.loads(done.stdout.strip().splitlines()[-1])
    outcomes = [SimpleNamespace(timings_s=o["timings_s"], wall_s=o["wall_s"],
                                rows=[{"duration_s": o["duration_s"]}])
                for o in got["outcomes"]]
    return SimpleNamespace(wall=got["wall"], cpu=got["cpu"], wall_s=got["wall_s"],
                           outcomes=outcomes, failures=[None] * got["failures"],
                           table=got["table"])


def load() -> str:
    return f"load average {os.getloadavg()[0]:.2f}, {os.getloadavg()[1]:.2f} (1, 5 min)"


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def one_variant(scenario: str, payload: float, speed: float) -> dict:
    """A metrics-only variant in this process: wall, CPU, stages; and its simulation's CPU
    alone (the same simulate call, timed on its own)."""
    from sim.pipeline.run import RunOptions, _drives, _prepare
    from sim.pipeline.stages import Stages
    from sim.pipeline.sweep.evaluation import _variant_scenario
    from sim.simulation.simulate import simulate

    v = Variant(payload, speed, scenario)
    c0, w0 = time.process_time(), time.perf_counter()
    m = evaluate_variant(v)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    sc = _variant_scenario(v)
    built, motion, _ = _prepare(sc, RunOptions(video=False, plots=False, progress=False),
                                Stages(enabled=False))
    c1 = time.process_time()
    simulate(built, motion, feedforward=sc.simulation.feedforward,
             settle_s=sc.simulation.settle_s, progress=False, drives=_drives(sc))
    sim_cpu = time.process_time() - c1
    return {"wall_s": wall, "cpu_s": cpu, "stages_s": m.timings_s,
            "duration_s": m.rows[0]["duration_s"],
            "simulate_s": m.timings_s["simulate"], "simulate_cpu_s": sim_cpu,
            "wall_over_simulate": wall / m.timings_s["simulate"],
            "cpu_over_simulate_cpu": cpu / sim_cpu}


def acceptance(scenario: str, workers: int, repeat: int = 3) -> dict:
    out: dict = {"scenario": scenario, "workers": workers, "repeat": repeat,
                 "load_start": load()}
    print(f"{scenario}, {workers} workers, {os.cpu_count()} CPUs; {load()}", flush=True)
    # the start-up varies by a tenth of a second from one pool to the next: the bound takes
    # the median of `repeat` pools
    starts, cpus = [], []
    for _ in range(repeat):
        c0 = children_cpu()
        starts.append(pool_startup_s(workers, "spawn", scenario))
        cpus.append(children_cpu() - c0)
    start = statistics.median(starts)
    out["pool_startup_s"], out["pool_startup_cpu_s"] = start, statistics.median(cpus)
    out["pool_startup_runs_s"] = starts
    print(f"pool start-up ({workers} warmed workers, one no-op each): {start:.2f} s wall "
          f"(median of {', '.join(f'{x:.2f}' for x in starts)}), "
          f"{out['pool_startup_cpu_s']:.2f} s CPU (workers)", flush=True)
    evaluate_variant(Variant(0.5, 0.9, scenario))  # imports, in this process
    for label, enabled, payloads in (("without reuse", False, (1.0, 3.0)),
                                     ("with reuse", True, (1.0, 3.0))):
        from sim.pipeline import run as run_module

        run_module._PLANS.clear()
        sweep_reuse.ENABLED = enabled
        from sim.simulation.collision_reuse import clear_cache

        clear_cache()
        for k, p in enumerate(payloads):
            r = one_variant(scenario, p, 1.0)
            kind = "first of its plan" if k == 0 else "reusing its plan"
            out[f"variant {label}, {kind}"] = r
            st = ", ".join(f"{a} {b:.2f}" for a, b in r["stages_s"].items())
            print(f"one variant {label} ({kind}, {p:g} kg): {r['wall_s']:.2f} s wall = "
                  f"{r['wall_over_simulate']:.2f}x its simulate stage (target <= 1.3); CPU "
                  f"{r['cpu_s']:.2f} s = {r['cpu_over_simulate_cpu']:.2f}x the simulation's CPU "
                  f"{r['simulate_cpu_s']:.2f} s (stages s: {st})", flush=True)
    sweep_reuse.ENABLED = True
    sim_one = out["variant with reuse, reusing its plan"]["simulate_s"]
    sim_cpu = out["variant with reuse, reusing its plan"]["simulate_cpu_s"]
    one_cycle = out["variant with reuse, reusing its plan"]["duration_s"]
    tables = {}
    for grid_label, payloads, speeds in (("6 payloads x 1 speed", [1.0, 1.5, 2.0, 2.5, 3.0, 3.5],
                                          [1.0]),
                                         ("2 payloads x 3 speeds", [1.0, 3.0], [0.8, 0.9, 1.0])):
        for label, runner in (("with reuse", evaluate_variant),
                              ("without reuse", evaluate_without_reuse)):
            # `repeat` sweeps, each in a new Python process as `cellsim size` runs one (its
            # report written each time); the figures below are of the
            # median one by its ratio to its own bound
            runs = []
            for _ in range(repeat):
                res = sweep_in_a_new_process(scenario, payloads, speeds, workers,
                                             reuse=runner is evaluate_variant)
                wall, cpu = res.wall, res.cpu
                sims = sum(o.timings_s.get("simulate", float("nan")) for o in res.outcomes)
                runs.append((wall / (1.5 * sims / workers + start), wall, cpu, res))
            ratios = [r[0] for r in runs]
            _, wall, cpu, res = sorted(runs, key=lambda r: r[0])[len(runs) // 2]
            tables[(grid_label, label)] = res.table
            n = len(res.outcomes)
            # the variants' own simulate stages (in their workers; a slower speed scale is a
            # longer cycle), and the simulation's CPU scaled by each variant's cycle duration
            sims = sum(o.timings_s.get("simulate", float("nan")) for o in res.outcomes)
            cycles = sum(o.rows[0]["duration_s"] for o in res.outcomes) / one_cycle
            bound = 1.5 * sims / workers + start
            cpu_bound = 1.5 * cycles * sim_cpu
            # where the wall went: the pool (start-up and variants) and the rest (the
            # scenario's load, the report's files); and the variants' stages summed
            stages: dict[str, float] = {}
            for o in res.outcomes:
                for k, v in o.timings_s.items():
                    stages[k] = stages.get(k, 0.0) + v
            out[f"sweep {grid_label} {label}"] = {"wall_s": wall, "bound_s": bound,
                                                  "simulate_sum_s": sims, "cpu_s": cpu,
                                                  "cpu_bound_s": cpu_bound,
                                                  "pool_wall_s": res.wall_s,
                                                  "variants_wall_sum_s": sum(
                                                      o.wall_s for o in res.outcomes),
                                                  "stages_sum_s": stages,
                                                  "failures": len(res.failures),
                                                  "ratios_of_the_runs": ratios}
            print(f"sweep {grid_label} {label}: {wall:.1f} s wall vs bound {bound:.1f} s "
                  f"(1.5 x {sims:.1f} s of its {n} simulate stages / {workers} + {start:.2f} s "
                  f"start-up; with {n} x one variant's {sim_one:.2f} s: "
                  f"{1.5 * n * sim_one / workers + start:.1f} s): {wall / bound:.2f}x the "
                  f"bound; workers' CPU {cpu:.1f} s (start-up "
                  f"included) vs 1.5 x {cycles:.2f} cycles x {sim_cpu:.2f} s = {cpu_bound:.1f} s "
                  f"({cpu / cpu_bound:.2f}x; less the start-up's "
                  f"{(cpu - out['pool_startup_cpu_s']) / cpu_bound:.2f}x); {load()}", flush=True)
            print(f"  ({repeat} runs: " + ", ".join(f"{x:.3f}x" for x in ratios)
                  + " the bound; the median run above)", flush=True)
            rec = out[f"sweep {grid_label} {label}"]
            print(f"  (pool {res.wall_s:.1f} s of it; the variants' own wall summed "
                  f"{rec['variants_wall_sum_s']:.1f} s, stages summed: "
                  + ", ".join(f"{a} {b:.1f}" for a, b in stages.items()) + ")", flush=True)
        same = tables[(grid_label, "with reuse")] == tables[(grid_label, "without reuse")]
        out[f"sweep {grid_label} identical tables"] = same
        print(f"  {grid_label}: tables with and without reuse identical: {same}", flush=True)
    out["load_end"] = load()
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="lrmate200ic_weld_plate")
    ap.add_argument("--sizes", default="8,64,256", help="variant counts (default 8,64,256)")
    ap.add_argument("--engines", default="pool,ray", help="pool, ray or both (default)")
    ap.add_argument("--workers", type=int, default=None,
                    help="worker processes (default 2 for the acceptance, else every CPU)")
    ap.add_argument("--scale", action="store_true",
                    help="the 8/64/256-variant table of --sizes and --engines instead")
    ap.add_argument("--warp", action="store_true",
                    help="Warp-CPU parity on 8 variants of --warp-scenario instead")
    ap.add_argument("--warp-scenario", default="kacso_lrmate100ib_sequence1")
    ap.add_argument("--repeat", type=int, default=3,
                    help="acceptance: pools started and sweeps run this many times each; the "
                         "medians are reported (default 3)")
    ap.add_argument("--json", type=Path, default=None, help="write the numbers here")
    ap.add_argument("--one-sweep", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.one_sweep:
        one_sweep(args.one_sweep)
        return 0
    info = {"python": platform.python_version(), "cpu_count": os.cpu_count(),
            "machine": platform.machine()}
    if not args.warp and not args.scale:
        out = acceptance(args.scenario, args.workers or 2, max(1, args.repeat))
        if args.json:
            args.json.write_text(json.dumps({**info, **out}, indent=2) + "\n")
        return 0
    args.workers = args.workers or os.cpu_count() or 1
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
