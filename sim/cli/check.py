"""``cellsim check SCENARIO``: reach, joint limits, singular passes and collisions of the
reference motion, without dynamics (:mod:`sim.pipeline.check`), in seconds.

Prints what a TP program holds that is not run (``program: ...``, as ``cellsim run`` does; not
a finding), then one line per finding. Exit codes: 0 when nothing was found, 1 when something
was, 2 for a mistake in the input.
"""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "check", help="check a scenario's reference motion: reach, limits, singularities, "
                      "collisions (no dynamics, seconds)",
        description="Plan SCENARIO and check its reference motion without simulating the "
                    "dynamics: targets out of reach, joints past their range, speed or "
                    "acceleration limit, passes near a singularity, and collisions of the robot "
                    "with itself and of the tool or the arm with the cell. One line per "
                    "finding; exit 1 when something was found.")
    p.add_argument("scenario", metavar="SCENARIO",
                   help="a scenario file, or a shipped scenario's name (see `cellsim list`)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import time

    from sim.pipeline.check import check_scenario
    from sim.scenario import load_scenario

    start = time.perf_counter()
    scenario = load_scenario(args.scenario)
    # what a TP program holds that is not run (as `cellsim run` lists it): the user edits a
    # program and checks it, so they see it here first (warnings: no finding, exit unchanged)
    for line in scenario.program_warnings:
        print(f"program: {line}")
    for partner in scenario.partners:
        for line in partner.program_warnings:
            print(f"{partner.name}: program: {line}")
    res = check_scenario(scenario)
    for f in res.findings:
        print(f"{f.kind}: {f.line}")
    wall = time.perf_counter() - start
    if res.ok:
        print(f"{scenario.name}: ok, no finding ({wall:.1f} s)")
        return 0
    print(f"{scenario.name}: {len(res.findings)} finding(s) ({wall:.1f} s)")
    return 1
