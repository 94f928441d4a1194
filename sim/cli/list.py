"""``cellsim list``: robots, mechanisms (turntables, positioners, tracks: kind, axes with their
ranges and speeds, rated payload), cells (with their other robots, mechanisms, objects, seams,
parts and cameras), tools and scenarios."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from sim.core.resources import shipped_scenarios
from sim.core.text import printable
from sim.errors import CellsimError
from sim.robots.mechanisms import AxisSpec, MechanismSpec
from sim.robots.mechanisms.registry import MECHANISMS
from sim.robots.registry import ROBOTS

if TYPE_CHECKING:
    from sim.cells.mechanisms import PlacedMechanism
    from sim.cells.partners import PlacedRobot


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("list", help="list robots, mechanisms, cells, tools and scenarios",
                       description="List the robots, mechanisms (positioners, turntables, "
                                   "tracks), cells, tools and shipped scenarios, one line each; "
                                   "with --cell, one cell file's content.")
    p.add_argument("--cell", metavar="FILE", default=None,
                   help="show a cell file's robot, mechanisms, objects, seams, parts and "
                        "cameras (docs/cell-format.md) instead")
    p.set_defaults(func=run)


def _scenario_line(name: str, path) -> str:
    from sim.scenario import load_scenario

    try:
        sc = load_scenario(path)
        return f"  {name:32s} {sc.robot.name:14s} {sc.description}"
    except CellsimError as exc:  # a broken shipped scenario must not hide the others
        return f"  {name:32s} (invalid: {exc})"


def axis_text(axis: AxisSpec) -> str:
    """One axis as ``cellsim list`` shows it: ``tilt revolute -135..135 deg, 80 deg/s`` (a
    prismatic axis in mm and mm/s)."""
    scale, unit = (math.degrees(1.0), "deg") if axis.kind == "revolute" else (1e3, "mm")
    lo, hi = (scale * v for v in axis.range)
    return (f"{axis.name} {axis.kind} {lo:.6g}..{hi:.6g} {unit}, "
            f"{scale * axis.max_speed:.6g} {unit}/s")


def mechanism_lines(spec: MechanismSpec) -> list[str]:
    """A shipped mechanism: name, kind, axis count, rated payload and description, then its
    axes (:func:`axis_text`)."""
    count = f"{spec.n_axes} {'axes' if spec.n_axes > 1 else 'axis'}"
    head = (f"  {spec.name:32s} {spec.kind:10s} {count}, payload {spec.payload_kg:.6g} kg  "
            f"{spec.description}")
    return [head, f"      axes: {'; '.join(axis_text(a) for a in spec.axes)}"]


def _mechanisms_line(placed: Sequence[PlacedMechanism]) -> str | None:
    """A cell's mechanisms: ``positioner (motopos_d500: tilt, rotate; carries pipe)``."""
    if not placed:
        return None
    items = []
    for pm in placed:
        carries = f"; carries {', '.join(pm.carries)}" if pm.carries else ""
        items.append(f"{pm.name} ({pm.spec.name}: {', '.join(pm.joint_names)}{carries})")
    return f"mechanisms: {', '.join(items)}"


def _partners_line(partners: Sequence[PlacedRobot]) -> str | None:
    """A cell's other robots (``[[robots]]``): ``other robots: r2 (lrmate200ic5l, mig_torch;
    base 0, 700, 0 mm, yaw -90 deg)``."""
    if not partners:
        return None
    items = []
    for pr in partners:
        T = np.asarray(pr.base_pose, dtype=float)
        pos = ", ".join(f"{1e3 * x:.6g}" for x in T[:3, 3])
        yaw = math.degrees(math.atan2(T[1, 0], T[0, 0]))
        tool = pr.tool.name if pr.tool is not None else "no tool"
        items.append(f"{pr.name} ({pr.robot.name}, {tool}; base {pos} mm, yaw {yaw:.6g} deg)")
    return f"other robots: {', '.join(items)}"


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
    robot_prefixes = ("robot/", *(f"{cr.name}/" for cr in getattr(cell, "partners", ())))
    # a mechanism's own solids (its base's and its links'), not objects of the cell
    mech_bodies = {b for pm in cell.mechanisms for b in (pm.name, *pm.joint_names)}
    objects: list[str] = []
    for geom in cell.mjcf.worldbody.find_all("geom"):
        full = geom.full_identifier
        if not geom.name or full.startswith(robot_prefixes) or geom.name == "floor":
            continue
        if getattr(geom.parent, "name", None) in mech_bodies:
            continue
        if geom.name in cell.parts or full in cell.parts:
            continue
        if geom.contype == 0 and geom.conaffinity == 0:  # a painted mark, not an object
            continue
        name = member.get(full, geom.name)
        if name not in objects:
            objects.append(name)
    seams = [f"{s.name} ({s.kind}, {1000.0 * s.length():.0f} mm)" for s in cell.seams.values()]
    lines = [f"robots: {', '.join(spec.robots)}; mounts: {', '.join(spec.mounts)}"]
    others = _partners_line(getattr(spec, "partners", ()))
    if others is not None:
        lines.append(others)
    mech = _mechanisms_line(cell.mechanisms)
    if mech is not None:
        lines.append(mech)
    lines.append(f"objects: {', '.join(objects)}")
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
    _print("mechanisms:")
    for mech in MECHANISMS.values():
        for line in mechanism_lines(mech):
            _print(line)
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
