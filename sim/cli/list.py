"""``cellsim list``: robots, cells, tools and scenarios, one line each."""

from __future__ import annotations

import argparse

from sim.core.resources import shipped_scenarios
from sim.errors import CellsimError
from sim.robots.registry import ROBOTS


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("list", help="list robots, cells, tools and scenarios",
                       description="List the robots, cells, tools and shipped scenarios, "
                                   "one line each.")
    p.set_defaults(func=run)


def _scenario_line(name: str, path) -> str:
    from sim.scenario import load_scenario

    try:
        sc = load_scenario(path)
        return f"  {name:32s} {sc.robot.name:14s} {sc.description}"
    except CellsimError as exc:  # a broken shipped scenario must not hide the others
        return f"  {name:32s} (invalid: {exc})"


def run(args: argparse.Namespace) -> int:
    print("robots:")
    for spec in ROBOTS.values():
        print(f"  {spec.name:32s} {spec.n_joints} axes  {spec.description}")
    from sim.cells import CELLS
    from sim.cells.tools import TOOLS

    for title, registry in (("cells", CELLS), ("tools", TOOLS)):
        print(f"{title}:")
        for name, item in sorted(registry.items()):
            print(f"  {name:32s} {item.description}")
    print("scenarios:")
    for name, path in shipped_scenarios().items():
        print(_scenario_line(name, path))
    return 0
