"""``cellsim list``: robots, cells (with their objects, seams, parts and cameras), tools and
scenarios."""

from __future__ import annotations

import argparse

from sim.core.resources import shipped_scenarios
from sim.core.text import printable
from sim.errors import CellsimError
from sim.robots.registry import ROBOTS


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("list", help="list robots, cells, tools and scenarios",
                       description="List the robots, cells, tools and shipped scenarios, "
                                   "one line each; with --cell, one cell file's content.")
    p.add_argument("--cell", metavar="FILE", default=None,
                   help="show a cell file's robot, objects, seams, parts and cameras "
                        "(docs/cell-format.md) instead")
    p.set_defaults(func=run)


def _scenario_line(name: str, path) -> str:
    from sim.scenario import load_scenario

    try:
        sc = load_scenario(path)
        return f"  {name:32s} {sc.robot.name:14s} {sc.description}"
    except CellsimError as exc:  # a broken shipped scenario must not hide the others
        return f"  {name:32s} (invalid: {exc})"


def _cell_lines(spec, strict: bool = False) -> list[str]:
    """A cell's robots, objects (a ring of staves counts once; painted marks are left out),
    seams (kind, length), parts and cameras, from the cell composed for its first robot."""
    from sim.cells import build_cell

    try:
        cell = build_cell(spec, ROBOTS[spec.robots[0]])
    except CellsimError as exc:  # a broken cell must not hide the others
        if strict:
            raise
        return [f"(cannot be built: {exc})"]
    member = {g: obj for obj, geoms in cell.objects.items() for g in geoms}
    objects: list[str] = []
    for geom in cell.mjcf.worldbody.find_all("geom"):
        full = geom.full_identifier
        if not geom.name or full.startswith("robot/") or geom.name == "floor":
            continue
        if geom.name in cell.parts or full in cell.parts:
            continue
        if geom.contype == 0 and geom.conaffinity == 0:  # a painted mark, not an object
            continue
        name = member.get(full, geom.name)
        if name not in objects:
            objects.append(name)
    seams = [f"{s.name} ({s.kind}, {1000.0 * s.length():.0f} mm)" for s in cell.seams.values()]
    lines = [f"robots: {', '.join(spec.robots)}; mounts: {', '.join(spec.mounts)}",
             f"objects: {', '.join(objects)}"]
    if seams:
        lines.append(f"seams: {', '.join(seams)}")
    if cell.parts:
        lines.append(f"parts: {', '.join(cell.parts)}")
    lines.append(f"cameras: {', '.join(cell.cameras)}")
    return lines


def _print(line: str) -> None:
    """A line of the listing, control characters shown as escapes (a path or a name from a
    user's folder is printed as it is, never as a terminal command)."""
    print(printable(line))


def run(args: argparse.Namespace) -> int:
    if getattr(args, "cell", None) is not None:
        from sim.cells import load_cell

        spec = load_cell(args.cell)  # a bad file: one line, exit 2
        _print(f"{spec.name}: {spec.description} ({spec.source})")
        for line in _cell_lines(spec, strict=True):
            _print(f"    {line}")
        return 0
    _print("robots:")
    for spec in ROBOTS.values():
        _print(f"  {spec.name:32s} {spec.n_joints} axes  {spec.description}")
    from sim.cells import CELLS
    from sim.cells.tools import TOOLS

    _print("cells:")
    for name, item in sorted(CELLS.items()):
        _print(f"  {name:32s} {item.description}")
        for line in _cell_lines(item):
            _print(f"      {line}")
    _print("tools:")
    for name, item in sorted(TOOLS.items()):
        _print(f"  {name:32s} {item.description}")
    _print("scenarios:")
    for name, path in shipped_scenarios().items():
        _print(_scenario_line(name, path))
    return 0
