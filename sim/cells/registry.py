"""The cell registries and resolving a scenario's cell and tool references.

:data:`CELLS` holds the shipped cell files of ``models/cells/`` (a cell laid out for several
robots or mounts is one file per variant, chosen when it is built); it is read on first use,
not when this module is imported. :data:`DERIVED` holds the Python derivations those files are
written from, :data:`BARE` the robot alone. :func:`resolve_cell` takes a shipped name or a cell
file of one's own (:func:`load_cell`), :func:`tool_from_ref` a shipped tool or a tool file.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from planners.registry import Registry
from sim.cells import bare, pick, weld_cylinder, weld_table
from sim.cells.cellfile import CellFile, make_builder, read_cell_file
from sim.cells.cellfile.reader import partner_tool
from sim.cells.compose import Layout, RobotRig
from sim.cells.spec import MOUNTS, CellSpec
from sim.cells.toolfile import load_tool_file
from sim.cells.tools import TOOLS, ToolSpec
from sim.core.registry import LazyRegistry
from sim.core.resources import models_dir
from sim.errors import CellError, CellsimError, UnknownNameError
from sim.robots.registry import ROBOTS


def _derived() -> Iterator[tuple[str, CellSpec]]:
    """The derived cells, in order (read on first use: they name the shipped tools, read from
    their files)."""
    torches = (TOOLS["mig_torch"], TOOLS["mig_torch_long"])
    for spec in (
        CellSpec("weld_cylinder",
                 "5R welding of a large cylinder coaxial with J1 (seed 001); floor or ceiling",
                 ("robot_5r",), TOOLS["mig_torch_long"], (TOOLS["mig_torch_long"],),
                 ("floor", "ceiling"), weld_cylinder.build),
        CellSpec("weld_table", "welding table: a 1F fillet line and a 2F fillet arc",
                 ("lrmate100ib", "lrmate200ic5l"), TOOLS["mig_torch"], torches, ("floor",),
                 weld_table.build),
        CellSpec("pick", "vacuum pick-and-place of 4 boxes from an infeed table to a tray",
                 ("lrmate200ic5l",), TOOLS["vacuum_gripper"], (TOOLS["vacuum_gripper"],),
                 ("floor",), pick.build),
    ):
        yield spec.name, spec


#: The Python derivations of the shipped cells: each module (``weld_cylinder``, ``weld_table``,
#: ``pick``) derives its cell's numbers; ``models/cells/generate.py`` writes them as the cell
#: files cellsim reads (:data:`CELLS`), and a test keeps the two in step.
DERIVED: Registry[CellSpec] = LazyRegistry("cell", _derived)


def cells_dir() -> Path:
    """Folder of the shipped cell files (``models/cells``)."""
    return models_dir() / "cells"


class _Variants:
    """Builder of a shipped cell with one file per robot and mount: picks the variant."""

    def __init__(self, name: str, variants: dict) -> None:
        self.name, self.variants = name, variants

    def __call__(self, rig: RobotRig, mount: str) -> Layout:
        b = self.variants.get((rig.spec.name, mount)) or self.variants.get((None, mount))
        if b is None:
            raise CellError(f"cell {self.name!r} has no file for robot {rig.spec.name!r} on "
                            f"the {mount}")
        return b(rig, mount)


def _shipped_cells() -> Iterator[tuple[str, CellSpec]]:
    """The shipped cell files, one entry per cell name: a cell laid out for several robots or
    mounts is one file per variant (``weld_table.lrmate100ib.toml``), chosen when it is built."""
    groups: dict[str, list[CellFile]] = {}
    for path in sorted(cells_dir().glob("*.toml")):
        cf = read_cell_file(path)
        groups.setdefault(cf.spec.name, []).append(cf)
    for name, files in groups.items():
        for cf in files:
            cf.default_tool = None if cf.spec.tool is None else TOOLS[cf.spec.tool]
            cf.partners = {n: partner_tool(cf.spec, cf.path, pr, tool_from_ref)
                           for n, pr in cf.partners.items()}
        build = _Variants(name, {(cf.spec.robot.model, cf.spec.robot.mount): make_builder(cf)
                                 for cf in files})
        first = files[0].spec
        models = [cf.spec.robot.model for cf in files]
        robots = tuple(ROBOTS) if None in models else tuple(dict.fromkeys(models))
        mounts = tuple(m for m in MOUNTS if any(cf.spec.robot.mount == m for cf in files))
        tools = tuple(TOOLS[t] for t in (first.tools or ()))
        yield name, CellSpec(name, first.description, robots,
                             None if first.tool is None else TOOLS[first.tool], tools, mounts,
                             build, any_tool=first.tools is None,
                             mechanisms=tuple(files[0].mechanisms.values()),
                             partners=tuple(files[0].partners.values()))


#: The shipped cells by name, read from ``models/cells/*.toml`` on first use.
CELLS: Registry[CellSpec] = LazyRegistry("cell", _shipped_cells)

#: The bare scene's entry (``cell=None``): any robot, any tool or none, both mounts (no list
#: of them: naming the registries' entries here would read every robot and tool on import).
BARE = CellSpec("bare", "the robot alone: floor, lights, cameras", (), None, (), MOUNTS,
                bare.build, needs_tool=False, any_tool=True, any_robot=True)


def is_file_ref(ref: str) -> bool:
    """A cell or tool reference that names a file (``*.toml`` or with a folder in it) rather
    than a shipped name."""
    return ref.endswith(".toml") or "/" in ref or "\\" in ref


def load_cell(path: str | Path) -> CellSpec:
    """A cell file (:mod:`sim.cells.cellfile`) as a registry-like :class:`CellSpec`.

    It is built for every robot (or the one its ``[robot] model`` names), with the mount of its
    ``[robot]`` table; it takes any tool, its ``tool`` key is the default (a shipped name or a
    tool file relative to the cell file).

    Raises:
        CellError: One line naming the file and the key (:func:`sim.cells.cellfile.read_cell_file`).
    """
    path = Path(path)
    cf = read_cell_file(path)
    spec = cf.spec
    robots = tuple(ROBOTS)
    if spec.robot.model is not None:
        if spec.robot.model not in ROBOTS:
            raise CellError(f"{path}: robot.model: "
                            f"{UnknownNameError('robot', spec.robot.model, tuple(ROBOTS))}")
        robots = (spec.robot.model,)
    default_tool = None
    if spec.tool is not None:
        try:
            default_tool = tool_from_ref(spec.tool, path.parent)
        except CellsimError as exc:
            raise CellError(f"{path}: tool: {exc}") from None
    tools: tuple[ToolSpec, ...] = ()
    for i, ref in enumerate(spec.tools or ()):
        try:
            tools += (tool_from_ref(ref, path.parent),)
        except CellsimError as exc:
            raise CellError(f"{path}: tools[{i}]: {exc}") from None
    needs = bool(spec.seams) or any(o.role == "part" for o in spec.objects)
    cf.default_tool = default_tool
    cf.partners = {name: partner_tool(spec, path, pr, tool_from_ref)
                   for name, pr in cf.partners.items()}
    return CellSpec(spec.name, spec.description or f"cell file {path.name}", robots,
                    default_tool, tools, (spec.robot.mount,), make_builder(cf), needs_tool=needs,
                    source=path.resolve(), any_tool=spec.tools is None,
                    any_robot=spec.robot.model is None,
                    mechanisms=tuple(cf.mechanisms.values()),
                    partners=tuple(cf.partners.values()))


def resolve_cell(ref: str, base: Path | None = None) -> CellSpec:
    """A shipped cell by name, or a cell file (path relative to ``base``, the scenario's folder).

    Raises:
        UnknownNameError: Unknown shipped cell (the message lists them).
        CellError: A cell file that is missing or wrong (one line naming the file and the key).
    """
    if is_file_ref(ref):
        path = Path(ref) if base is None else base / ref
        if not path.exists() or path.is_dir():
            raise CellError(f"{path}: no such cell file (a path is relative to the scenario "
                            f"file; shipped cells: {', '.join(CELLS)})")
        return load_cell(path)
    return CELLS.get(ref)


def tool_from_ref(ref: str, base: Path | None = None) -> ToolSpec:
    """A shipped tool by name, or a tool file (path relative to ``base``;
    :mod:`sim.cells.toolfile`)."""
    if is_file_ref(ref):
        return load_tool_file(Path(ref) if base is None else base / ref)
    return TOOLS.get(ref)


__all__ = ["BARE", "CELLS", "DERIVED", "cells_dir", "is_file_ref", "load_cell", "resolve_cell",
           "tool_from_ref"]
