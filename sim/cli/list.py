"""``cellsim list``: robots, cells, tools and scenarios, one line each."""

from __future__ import annotations

import argparse
import importlib

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


def _registry_lines(module: str, attr: str) -> list[str] | None:
    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError:
        return None
    return [f"  {name:32s} {getattr(item, 'description', '')}"
            for name, item in sorted(getattr(mod, attr).items())]


def run(args: argparse.Namespace) -> int:
    print("robots:")
    for spec in ROBOTS.values():
        print(f"  {spec.name:32s} {spec.n_joints} axes  {spec.description}")
    for title, module, attr in (("cells", "sim.cells", "CELLS"), ("tools", "sim.cells.tools", "TOOLS")):
        lines = _registry_lines(module, attr)
        if lines is not None:
            print(f"{title}:")
            print("\n".join(lines))
    print("scenarios:")
    for name, path in shipped_scenarios().items():
        print(_scenario_line(name, path))
    return 0
