"""``cellsim size SCENARIO --payload ... --speed-scale ...``: actuator-sizing sweeps.

Every (payload, speed scale) combination is simulated (the speed scale divides the knot
times: 2 is twice as fast), in parallel over the machine's cores, and sized. The sweep folder
(``--out``, default ``runs/<scenario>_sweep``) holds ``sweep.csv`` (one row per variant and
joint), ``sweep.md`` (tables), ``sweep.png`` (peak and RMS torque per joint against payload and
speed) and one run folder per variant. A variant that exceeds a speed, acceleration or
torque limit is kept, with its negative margins and its run's verdict; the command exits 0
when it could evaluate every variant.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from sim.pipeline.sweep import Variant


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "size", help="actuator-sizing sweep over payloads and speed scales",
        description="Simulate SCENARIO for every combination of --payload and --speed-scale "
                    "(in parallel), size every joint's actuator, and write sweep.csv, sweep.md, "
                    "sweep.json and sweep.png with one run folder per variant. Variants are "
                    "simulated even past the robot's speed or acceleration limits (the "
                    "scenario's enforce_* keys are not applied): they stay in the tables with "
                    "negative margins and their run's verdict. Exit 0 when every variant was "
                    "evaluated.")
    p.add_argument("scenario", metavar="SCENARIO",
                   help="a scenario file, or a shipped scenario's name (see `cellsim list`)")
    p.add_argument("--payload", default=None, metavar="KG,..",
                   help="payloads at the tool tip, kg: a list 0,2.5,5 or a range 0:5:2.5 "
                        "(default: the scenario's)")
    p.add_argument("--speed-scale", default="1", metavar="S,..",
                   help="speed scales (knot times are divided by each): 0.5,1,1.5 (default 1)")
    p.add_argument("--out", type=Path, metavar="DIR",
                   help="sweep folder (default: runs/<scenario name>_sweep)")
    p.add_argument("--workers", type=int, default=None,
                   help="parallel processes (default: the number of cores)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run_variant(variant: Variant) -> Path:
    """Run one sweep variant (module level, so worker processes can import it).

    A variant faster or heavier than the robot allows is still simulated (speed and
    acceleration limits are not enforced): it stays in the tables with negative margins and a
    failed verdict instead of being dropped.
    """
    import dataclasses

    from sim.pipeline.run import RunOptions, run_scenario
    from sim.scenario import load_scenario

    scenario = load_scenario(variant.scenario).scaled(variant.speed_scale, variant.payload_kg)
    scenario = dataclasses.replace(scenario, simulation=scenario.simulation.model_copy(
        update={"enforce_speed_limits": False, "enforce_accel_limits": False}))
    run_scenario(scenario, RunOptions(out_dir=variant.run_dir, video=False, plots=False,
                                      progress=False))
    return Path(variant.run_dir)


def run(args: argparse.Namespace) -> int:
    from sim.errors import CellsimError
    from sim.pipeline.sweep import (
        parse_float_list,
        run_sweep,
        validate_payloads,
        validate_speed_scales,
    )
    from sim.scenario import load_scenario

    scenario = load_scenario(args.scenario)  # validates before any process starts
    payloads = validate_payloads(parse_float_list(args.payload, field="--payload")
                                 if args.payload is not None else [scenario.payload_kg],
                                 field="--payload")
    scales = validate_speed_scales(parse_float_list(args.speed_scale, field="--speed-scale"),
                                   field="--speed-scale")
    if args.workers is not None and args.workers < 1:
        raise CellsimError(f"--workers must be at least 1, got {args.workers}")
    out = args.out or Path("runs") / f"{scenario.name}_sweep"
    workers = args.workers or os.cpu_count() or 1
    result = run_sweep(str(scenario.source), payloads, scales, run_variant,
                       workers=min(workers, len(payloads) * len(scales)), out_dir=out,
                       progress=not args.quiet)
    print(f"{len(result.outcomes)} variants in {result.wall_s:.1f} s on {result.workers} "
          f"worker(s); results in {out}/ (sweep.csv, sweep.md, sweep.png)")
    return 0
