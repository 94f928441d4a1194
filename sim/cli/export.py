"""``cellsim export SCENARIO --format fanuc-ls --out prog.ls``: a scenario's motion as a robot
program (:mod:`sim.pipeline.export`); in a cell with other robots (``[[robots]]``) each one's
with work as its own program beside it (``prog_r2.ls``)."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export", help="write a scenario's motion as a FANUC TP program (.ls)",
        description="Plan SCENARIO (no simulation) and write its motion as a FANUC TP program "
                    "in ASCII form: J moves to joint positions, L and C moves to Cartesian "
                    "positions with their CONFIG, FINE or CNT, Arc Start/End, WAIT, and Weave "
                    "Sine/Circle ... Weave End with the weave schedules in prog.weave.toml "
                    "beside the program. A scenario with `program = \"prog.ls\"` runs it back. "
                    "In a cell with other robots each one with work gets its own program beside "
                    "the first robot's (prog_r2.ls for r2; `[robots.r2] program = "
                    "\"prog_r2.ls\"` runs it back). An existing file is never replaced.")
    p.add_argument("scenario", metavar="SCENARIO",
                   help="a scenario file, or a shipped scenario's name (see `cellsim list`)")
    p.add_argument("--format", choices=["fanuc-ls"], default="fanuc-ls",
                   help="program format (default: fanuc-ls)")
    p.add_argument("--out", required=True, help="the (first robot's) program file to write "
                   "(must not exist)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from sim.pipeline.export import write_program
    from sim.scenario import load_scenario

    scenario = load_scenario(args.scenario)
    notes, written = write_program(scenario, args.out)
    for line in notes:
        print(f"note: {line}")
    print(f"{scenario.name}: wrote {' and '.join(str(p) for p in written)}")
    return 0
