"""``cellsim size SCENARIO --payload ... --speed-scale ...``: actuator-sizing sweeps.

Every (payload, speed scale) combination is simulated (the speed scale divides the knot
times: 2 is twice as fast) and sized, in parallel: over the machine's cores (``--engine pool``,
the default) or as Ray tasks on a local Ray instance or an existing cluster (``--engine ray
[--address auto|HOST:PORT]``). A variant computes its arrays, checks and sizing in memory and
returns a few numbers per joint (metrics only); the sweep folder (``--out``, default
``runs/<scenario>_sweep``) gets ``sweep.csv`` (one row per variant and joint), ``sweep.md``
(tables), ``sweep.json`` and ``sweep.svg`` (peak and RMS torque per joint against payload and
speed), drawn once at the end. ``--keep-runs`` also writes one full run folder per variant
(arrays, summary, sizing report; ``--plots`` adds each run's charts). A variant that exceeds a
speed, acceleration or torque limit is kept, with its negative margins and its run's verdict;
the command exits 0 when it could evaluate every variant (``--strict``: 1 when a variant's
verdict failed, a gate for a CI job).
"""

from __future__ import annotations

import argparse
import functools
import math
import os
from pathlib import Path

from sim.errors import SweepError
from sim.pipeline.sweep.evaluation import evaluate_batch, evaluate_variant


# ---------------------------------------------------------------------------- value lists
def _number(token: str, field: str) -> float:
    try:
        value = float(token)
    except ValueError:
        raise SweepError(f"{field}: {token!r} is not a number (expected a comma-separated list "
                         "like 0,2.5,5 or a range start:stop:step like 0:10:2.5)") from None
    if not math.isfinite(value):
        raise SweepError(f"{field}: {token!r} is not a finite number")
    return value


#: Most values one option may list.
MAX_SWEEP_VALUES = 10_000


def parse_float_list(text: str, field: str = "value") -> list[float]:
    """Numbers from a command-line list: ``"0,2.5,5"`` or an inclusive range ``"0:10:2.5"``
    (items may mix: ``"0,1:3:1"``), in order, repeats kept: the values' own checks
    (:func:`~sim.pipeline.sweep.validate_payloads`) refuse a bad one first, then drop the
    repeats with a warning naming them.

    Args:
        text: The option's text.
        field: Option name for error messages (``"--payload"``).

    Returns:
        The numbers, in order of appearance.

    Raises:
        SweepError: Empty list, empty item, non-number, or a bad range (names ``field``).
    """
    if text is None or not str(text).strip():
        raise SweepError(f"{field}: empty list (expected numbers like 0,2.5,5)")
    out: list[float] = []
    for item in str(text).split(","):
        item = item.strip()
        if not item:
            raise SweepError(f"{field}: empty item in {text!r} (expected numbers like 0,2.5,5)")
        if ":" in item:
            parts = item.split(":")
            if len(parts) != 3:
                raise SweepError(f"{field}: range {item!r} must be start:stop:step")
            a, b, step = (_number(p.strip(), field) for p in parts)
            if step <= 0:
                raise SweepError(f"{field}: range {item!r} needs a positive step")
            if b < a:
                raise SweepError(f"{field}: range {item!r} has stop < start")
            span = (b - a) / step  # inf for a huge range or a tiny step: refused, not allocated
            if not math.isfinite(span) or span + 1 > MAX_SWEEP_VALUES:
                shown = "more than 1e308" if not math.isfinite(span) else f"{int(span) + 1}"
                raise SweepError(f"{field}: range {item!r} has {shown} values (at most "
                                 f"{MAX_SWEEP_VALUES})")
            count = int(math.floor(span + 1e-9)) + 1
            out.extend(round(a + k * step, 12) for k in range(count))
        else:
            out.append(_number(item, field))
    return out


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "size", help="actuator-sizing sweep over payloads and speed scales",
        description="Simulate SCENARIO for every combination of --payload and --speed-scale "
                    "(in parallel: a process pool, Ray, or one MuJoCo Warp batch), size every "
                    "joint's actuator, and write sweep.csv, sweep.md, sweep.json and sweep.svg "
                    "(metrics only: nothing per variant unless --keep-runs). Variants are "
                    "simulated even past the robot's speed or acceleration limits (the "
                    "scenario's enforce_* keys are not applied): they stay in the tables with "
                    "negative margins and their run's verdict. Exit 0 when every variant was "
                    "evaluated (with --strict: 1 when a variant's verdict failed).")
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
                   help="parallel processes, or CPUs of a local Ray instance (default: the "
                        "number of cores)")
    p.add_argument("--engine", choices=("pool", "ray"), default="pool",
                   help="where variants run: a process pool on this machine (default) or Ray "
                        "tasks (needs the extra: pip install 'cellsim[ray]')")
    p.add_argument("--address", metavar="auto|HOST:PORT",
                   help="with --engine ray: an existing Ray cluster ('auto': the one this "
                        "machine belongs to); default: start a local instance")
    p.add_argument("--backend", choices=("mujoco", "warp"), default="mujoco",
                   help="physics: MuJoCo in C, one variant per process (default), or MuJoCo "
                        "Warp: the variants that share a model structure step as one batch in "
                        "this process, on a GPU where there is one (pip install "
                        "'cellsim[warp]')")
    p.add_argument("--keep-runs", action="store_true",
                   help="also write each variant's run folder (arrays, summary, sizing report) "
                        "in the sweep folder; default: metrics only, nothing per variant")
    p.add_argument("--plots", action="store_true",
                   help="with --keep-runs: draw each variant's plots too")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--strict", action="store_true",
                   help="exit with 1 when a variant's verdict is fail (a collision, a saturated "
                        "drive, a joint past a limit, a payload over a rating, a sizing limit "
                        "exceeded, no actuator pair found): a gate for a CI job")
    add_selection_args(p)
    p.set_defaults(func=run)


def add_selection_args(p: argparse.ArgumentParser) -> None:
    """The actuator-selection flags (shared by ``cellsim size`` and ``cellsim run``)."""
    g = p.add_argument_group(
        "actuator selection", "choose a motor and a reducer per joint from a catalogue over "
        "the duty cycle (selection.json, selection.csv, a report section; a sweep's one row per "
        "variant and joint); defaults from the "
        "scenario's [sizing] table, which the flags override")
    g.add_argument("--select", action="store_true",
                   help="choose motors and reducers (also on when the scenario says "
                        "[sizing] select = true)")
    g.add_argument("--catalog", type=Path, metavar="FILE",
                   help="catalogue TOML (default: the scenario's [sizing] catalog, else the "
                        "shipped models/catalog/starter.toml)")
    g.add_argument("--life-h", type=float, metavar="H", help="reducer L10 life target, h "
                   "(default 20000)")
    g.add_argument("--dwell-s", type=float, metavar="S",
                   help="standstill after each cycle, s (default 0)")
    g.add_argument("--rank", choices=("mass", "inertia", "margin"),
                   help="rank passing pairs by mass (default), rotor inertia or margin")
    g.add_argument("--inertia-ratio-max", type=float, metavar="X",
                   help="largest load/rotor inertia ratio a pair may have (default 10): over it "
                        "a pair fails, or only warns where the scenario's [sizing] "
                        "inertia_ratio = \"warning\"")


def selection_overrides(args: argparse.Namespace, scenario_selects: bool = False
                        ) -> dict | None:
    """The selection flags given (over the scenario's ``[sizing]`` keys), or None when no
    selection was asked for (no ``--select`` and no ``[sizing] select = true``).

    Raises:
        CellsimError: A selection flag (``--catalog``, ``--life-h``, ...) without a selection
            to apply it to: it would do nothing.
    """
    from sim.errors import CellsimError

    flags = {"catalog": None if args.catalog is None else str(args.catalog),
             "life_h": args.life_h, "dwell_s": args.dwell_s, "rank": args.rank,
             "inertia_ratio_max": args.inertia_ratio_max}
    if getattr(args, "select", False) or scenario_selects:
        return flags
    given = [f"--{k.replace('_', '-')}" for k, v in flags.items() if v is not None]
    if given:
        raise CellsimError(f"{', '.join(given)}: for an actuator selection; give --select too "
                           "(or [sizing] select = true in the scenario)")
    return None


def run(args: argparse.Namespace) -> int:
    from sim.errors import CellsimError
    from sim.pipeline.sweep import run_sweep, validate_payloads, validate_speed_scales
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
    select = selection_overrides(args, scenario.sizing.select)
    selection = None
    if select is not None:  # loaded once; a bad one fails here
        from sim.pipeline.run import selection_options

        selection = selection_options(scenario, **select)
    if args.plots and not args.keep_runs:
        raise CellsimError("--plots draws each variant's run folder: give --keep-runs too")
    if args.address is not None and args.engine != "ray":
        raise CellsimError("--address is for --engine ray")
    batch = None
    if args.backend == "warp":
        if args.engine == "ray":
            raise CellsimError("--backend warp runs its batch in this process, on this "
                               "machine's device: use it without --engine ray")
        if args.keep_runs:
            raise CellsimError("--keep-runs is for --backend mujoco (a Warp batch computes "
                               "metrics only)")
        from sim.simulation.warp_batch import default_device

        default_device()  # MuJoCo Warp is there (else one line), before any folder is made
        batch = functools.partial(evaluate_batch, selection=selection)
    # the loaded scenario travels with each variant (a Ray node needs no copy of the file)
    result = run_sweep(scenario, payloads, scales,
                       functools.partial(evaluate_variant, selection=selection,
                                         keep_runs=args.keep_runs,
                                         plots=args.plots),
                       workers=min(workers, len(payloads) * len(scales)), out_dir=out,
                       progress=not args.quiet, engine=args.engine, address=args.address,
                       batch=batch)
    print(f"{len(result.outcomes)} variants in {result.wall_s:.1f} s on {result.workers} "
          f"worker(s); results in {out}/ (sweep.csv, sweep.md, sweep.svg"
          f"{', selection.csv, selection.json' if 'selection_csv' in result.files else ''})")
    failed = 0
    for o in result.outcomes:  # simulated and sized, but not physically possible: said here too
        if o.rows and o.rows[0].get("verdict") == "fail":
            failed += 1
            print(f"  verdict fail, {o.variant.label}: {o.rows[0].get('failed_checks') or 'fail'}")
    if selection is not None:
        _print_selections(result)
    return 1 if args.strict and failed else 0


def _print_selections(result) -> None:
    """Each variant's choice per joint (``selection.json``'s content, returned by the
    variant)."""
    for outcome in result.outcomes:
        doc = outcome.selection
        if doc is None:  # a failed variant
            continue
        print(f"selection, {outcome.variant.label}:")
        for joint, j in doc["joints"].items():
            if j["motor"] is None:
                print(f"  {joint}: NO PAIR: {j['reason']}")
                continue
            hard = min((c for c in j["checks"] if c["severity"] == "error"),
                       key=lambda c: c["margin_pct"] if c["margin_pct"] is not None else 1e300)
            margin = hard["margin_pct"]
            print(f"  {joint}: {j['motor']} + {j['reducer']} (hardest {hard['name']}, "
                  f"margin {'inf' if margin is None else f'{margin:.0f}'} %; "
                  f"{j['pairs_passing']} of {j['pairs_checked']} pairs pass)")
