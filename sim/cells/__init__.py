"""Cells layer: tools, seams and the welding and pick cells composed with ``dm_control.mjcf``
(robot + tool + fixtures + parts). May import: planners, :mod:`sim.errors`, :mod:`sim.core`,
:mod:`sim.robots`.

Public API::

    from sim.cells import CELLS, Cell, Seam, build_cell
    cell = build_cell(CELLS["weld_cylinder"], ROBOTS["robot_5r"], mount="floor")
    model = cell.compile()                      # mujoco.MjModel, keyframe "home"

Cells are data (``docs/cell-format.md``): :data:`CELLS` holds the shipped cell files of
``models/cells/`` (written by ``models/cells/generate.py`` from the Python derivations in
:data:`DERIVED`; each module's docstring gives its dimensions and the reasons for them), and a
scenario may name a cell file of its own (:func:`resolve_cell`, :func:`load_cell`; the format's
reader is :mod:`sim.cells.cellfile`, meshes :mod:`sim.cells.meshes`, tool files
:mod:`sim.cells.toolfile`).

===============  ======================  ===============  ================  =================
cell             robots                  default tool     tools allowed     mounts
===============  ======================  ===============  ================  =================
weld_cylinder    robot_5r                mig_torch_long   mig_torch_long    floor, ceiling
weld_table       lrmate100ib, 200ic5l    mig_torch        mig_torch(_long)  floor
pick             lrmate200ic5l           vacuum_gripper   vacuum_gripper    floor
(a cell file)    every robot, or its     its ``tool``     its ``tools``,    its ``[robot]
                 ``[robot] model``                        else any          mount``
(None: bare)     every robot             none             any, or none      floor, ceiling
===============  ======================  ===============  ================  =================

A tool file of the kind a shipped cell works with (a torch for the welding cells) is taken too.

Names in the compiled model: robot joints ``robot/j1..jN``, actuators ``robot/a1..aN`` (the
drives) and ``robot/friction_j1..`` (each joint's Coulomb friction, :mod:`sim.cells.compose`), sites
``robot/frame0``, ``robot/flange``, ``robot/tcp`` (moved onto the tool tip), tool elements
``robot/tool/...`` (tip site ``robot/tool/tip``, suction ``robot/tool/suction``), payload body
``robot/payload``; cell elements keep their plain names (``part0``, cameras ``overview`` and
``tool``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
from dm_control import mjcf
from numpy.typing import NDArray

from planners.registry import Registry
from sim.cells import bare, pick, weld_cylinder, weld_table
from sim.cells.compose import (
    ROBOT_PREFIX,
    Layout,
    Ring,
    RobotRig,
    add_home_keyframe,
    compile_model,
    prepare_robot,
    suction_actuator_name,
    tip_site_name,
)
from sim.cells.seam import Seam
from sim.cells.tools import TOOLS, ToolSpec
from sim.errors import CellError, CellsimError, UnknownNameError
from sim.robots.model import KinematicModel
from sim.robots.registry import ROBOTS, RobotSpec

#: ``tool="none"`` asks for no tool even where the cell has a default one.
NO_TOOL = "none"
MOUNTS = ("floor", "ceiling")


@dataclass(frozen=True)
class CellSpec:
    """Registry entry of a cell.

    Attributes:
        name: Registry name.
        description: One line for ``cellsim list``.
        robots: Names of the robots the cell is built for.
        default_tool: Tool used when none is asked for (None: no tool).
        tools: Tools the cell accepts (besides the default).
        mounts: Robot mounts the cell supports.
        build: Builder ``(RobotRig, mount) -> Layout``.
        needs_tool: The cell's work needs a tool (welding, picking): "no tool" is refused.
        source: The cell file (None for a cell built in Python).
        any_tool: The cell takes any tool (cell files: the scenario chooses).
        any_robot: The cell takes any robot, a robot folder of one's own included (the bare
            scene, a cell file without ``[robot] model``).
    """

    name: str
    description: str
    robots: tuple[str, ...]
    default_tool: ToolSpec | None
    tools: tuple[ToolSpec, ...]
    mounts: tuple[str, ...]
    build: Callable[[RobotRig, str], Layout] = field(repr=False, compare=False)
    needs_tool: bool = True
    source: Path | None = None
    any_tool: bool = False
    any_robot: bool = False


_TORCHES = (TOOLS["mig_torch"], TOOLS["mig_torch_long"])

#: The Python derivations of the shipped cells: each module (``weld_cylinder``, ``weld_table``,
#: ``pick``) derives its cell's numbers; ``models/cells/generate.py`` writes them as the cell
#: files cellsim reads (:data:`CELLS`), and a test keeps the two in step.
DERIVED: Registry[CellSpec] = Registry("cell")
for _spec in (
    CellSpec("weld_cylinder",
             "5R welding of a large cylinder coaxial with J1 (seed 001); floor or ceiling",
             ("robot_5r",), TOOLS["mig_torch_long"], (TOOLS["mig_torch_long"],),
             ("floor", "ceiling"), weld_cylinder.build),
    CellSpec("weld_table", "welding table: a 1F fillet line and a 2F fillet arc",
             ("lrmate100ib", "lrmate200ic5l"), TOOLS["mig_torch"], _TORCHES, ("floor",),
             weld_table.build),
    CellSpec("pick", "vacuum pick-and-place of 4 boxes from an infeed table to a tray",
             ("lrmate200ic5l",), TOOLS["vacuum_gripper"], (TOOLS["vacuum_gripper"],), ("floor",),
             pick.build),
):
    DERIVED.add(_spec.name, _spec)


def cells_dir() -> Path:
    """Folder of the shipped cell files (``models/cells``)."""
    from sim.core.resources import models_dir

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


def _shipped_cells() -> Registry[CellSpec]:
    """The shipped cell files, one entry per cell name: a cell laid out for several robots or
    mounts is one file per variant (``weld_table.lrmate100ib.toml``), chosen when it is built."""
    from sim.cells.cellfile import make_builder, read_cell_file

    groups: dict[str, list] = {}
    for path in sorted(cells_dir().glob("*.toml")):
        cf = read_cell_file(path)
        groups.setdefault(cf.spec.name, []).append(cf)
    reg: Registry[CellSpec] = Registry("cell")
    for name, files in groups.items():
        for cf in files:
            cf.default_tool = None if cf.spec.tool is None else TOOLS[cf.spec.tool]
        build = _Variants(name, {(cf.spec.robot.model, cf.spec.robot.mount): make_builder(cf)
                                 for cf in files})
        first = files[0].spec
        models = [cf.spec.robot.model for cf in files]
        robots = tuple(ROBOTS) if None in models else tuple(dict.fromkeys(models))
        mounts = tuple(m for m in MOUNTS if any(cf.spec.robot.mount == m for cf in files))
        tools = tuple(TOOLS[t] for t in (first.tools or ()))
        reg.add(name, CellSpec(name, first.description, robots,
                               None if first.tool is None else TOOLS[first.tool], tools, mounts,
                               build, any_tool=first.tools is None))
    return reg


#: The shipped cells by name, read from ``models/cells/*.toml``.
CELLS: Registry[CellSpec] = _shipped_cells()

#: The bare scene's entry (``cell=None``): every robot, any tool or none, both mounts.
BARE = CellSpec("bare", "the robot alone: floor, lights, cameras", tuple(ROBOTS), None,
                tuple(TOOLS.values()), MOUNTS, bare.build, needs_tool=False, any_robot=True)


@dataclass
class Cell:
    """A composed cell, not yet compiled (see the package docstring for the names).

    Attributes:
        name: Cell name (``"bare"`` for ``cell=None``).
        robot: The robot.
        tool: The tool, or None.
        mount: ``"floor"`` or ``"ceiling"``.
        mjcf: The composed world (``dm_control`` model).
        joint_names: Robot joints ``robot/j1..``, in order.
        actuator_names: Robot position actuators ``robot/a1..``, in order.
        tcp_site, frame0_site, flange_site: Full site names.
        seams: Weld seams in world, by name (in welding order).
        parts: Free-body names (pick cells), in order.
        slots: Target positions of the parts' centres in world, (P, 3), m.
        cameras: Named cameras.
        world_from_frame0: Pose of frame 0 in world, (4, 4).
        adhesion_actuator: Suction actuator (ctrl 0 = off, 1 = full), or None.
        home_q: Robot joint values of the ``home`` keyframe, rad, (n,).
        start_q: Robot joint values with the tcp at the first seam's start (welding cells),
            rad, (n,); for ``weld_cylinder`` on the floor: seed 001's phase-I end.
        payload_kg: Lumped payload at the tcp, kg.
        tip_site: The tool's own ``tip`` site (coincides with ``tcp_site``), or None.
        dims: Key dimensions for reports (m, deg where the name says so).
        description: The cell's one-line description.
        frictionloss: Coulomb friction of each robot joint, N m, (n,), applied by the friction
            actuators ``robot/friction_jN`` (:mod:`sim.cells.compose`).
        objects: Geom names of each cell object made of several geoms (a ring of staves).
        seam_objects: Objects each seam joins (its workpieces), by seam name.
        frames: Pose in world of each cell object scenario points may be given in, (4, 4).
        source: The cell file the cell came from (None: built in Python).
        rings: Parameters of each object that is a ring of staves (:class:`compose.Ring`).
    """

    name: str
    robot: RobotSpec
    tool: ToolSpec | None
    mount: str
    mjcf: mjcf.RootElement
    joint_names: list[str]
    actuator_names: list[str]
    tcp_site: str
    frame0_site: str
    flange_site: str
    seams: dict[str, Seam]
    parts: list[str]
    slots: NDArray[np.float64]
    cameras: list[str]
    world_from_frame0: NDArray[np.float64]
    adhesion_actuator: str | None
    home_q: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    start_q: NDArray[np.float64] | None = None
    payload_kg: float = 0.0
    tip_site: str | None = None
    dims: dict[str, float] = field(default_factory=dict)
    description: str = ""
    frictionloss: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    objects: dict[str, tuple[str, ...]] = field(default_factory=dict)
    seam_objects: dict[str, tuple[str, ...]] = field(default_factory=dict)
    frames: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    source: Path | None = None
    rings: dict[str, dict] = field(default_factory=dict)
    _rig: RobotRig | None = field(default=None, repr=False)

    def compile(self) -> mujoco.MjModel:
        """Compile the composed world (``mujoco.MjModel`` with keyframe ``home``)."""
        return compile_model(self.mjcf)

    def kinematics(self) -> KinematicModel:
        """Closed-form kinematic model whose tool frame is this cell's tcp (the tool tip).

        Poses are in frame 0: map world targets with ``inv(world_from_frame0)``.
        """
        assert self._rig is not None
        return self._rig.kinematics()


def _check_payload(payload_kg: float) -> float:
    try:
        p = float(payload_kg)
    except (TypeError, ValueError):
        raise CellError(f"payload_kg must be a number >= 0 (kg), got {payload_kg!r}") from None
    if not math.isfinite(p) or p < 0.0:
        raise CellError(f"payload_kg must be a finite number >= 0 (kg), got {payload_kg!r}")
    return p


#: ``build_cell(..., tool=CELL_DEFAULT)``: the cell's default tool.
CELL_DEFAULT = object()


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
    from sim.cells.cellfile import make_builder, read_cell_file

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
    return CellSpec(spec.name, spec.description or f"cell file {path.name}", robots,
                    default_tool, tools, (spec.robot.mount,), make_builder(cf), needs_tool=needs,
                    source=path.resolve(), any_tool=spec.tools is None,
                    any_robot=spec.robot.model is None)


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
    """A shipped tool by name, or a tool file (path relative to ``base``; :mod:`sim.cells.toolfile`)."""
    if is_file_ref(ref):
        from sim.cells.toolfile import load_tool_file

        return load_tool_file(Path(ref) if base is None else base / ref)
    return TOOLS.get(ref)


def resolve_tool(cell: CellSpec, name: str | None, base: Path | None = None
                 ) -> ToolSpec | None:
    """The tool a cell gets for a requested tool name.

    Args:
        cell: The cell (:data:`BARE` for the robot alone).
        name: A tool name, a tool file (``*.toml``, relative to ``base``), ``None`` for the
            cell's default tool, or ``"none"`` for no tool.
        base: Folder that a tool file's path is relative to (the scenario's).

    Raises:
        UnknownNameError: Unknown tool (the message lists the tools).
        CellError: The cell does not take that tool (the message lists the ones it takes).
    """
    if name is None:
        return cell.default_tool
    if name == NO_TOOL:
        return None
    tool = tool_from_ref(name, base)
    _check_tool(cell, tool)
    return tool


def _check_tool(cell: CellSpec, tool: ToolSpec | None) -> None:
    if tool is None:
        if cell.needs_tool:
            raise CellError(f"cell {cell.name!r} needs a tool; tools: "
                            f"{', '.join(t.name for t in cell.tools) or ', '.join(TOOLS)} "
                            "or a tool file")
        return
    if cell.any_tool or cell is BARE:
        return
    if tool.source is not None:  # a tool file: any tool of the kind the cell works with
        kinds = sorted({t.kind for t in cell.tools})
        if tool.kind not in kinds:
            raise CellError(f"cell {cell.name!r} works with a {' or '.join(kinds)}; tool "
                            f"{tool.name!r} ({tool.source}) is a {tool.kind}")
        return
    if tool not in cell.tools and tool != cell.default_tool:
        raise CellError(f"cell {cell.name!r} does not take tool {tool.name!r}; tools: "
                        f"{', '.join(sorted({*(t.name for t in cell.tools), NO_TOOL}))}")


def build_cell(cell: CellSpec | None, robot: RobotSpec, *,
               tool: ToolSpec | None | object = CELL_DEFAULT, mount: str = "floor",
               payload_kg: float = 0.0) -> Cell:
    """Compose a cell for a robot.

    Args:
        cell: The cell (an entry of :data:`CELLS`), or None for the robot's bare scene.
        robot: The robot.
        tool: The tool, None for no tool, or :data:`CELL_DEFAULT` for the cell's default tool
            (bare scene: no tool); :func:`resolve_tool` turns a scenario's tool name into one.
        mount: ``"floor"`` or ``"ceiling"`` (each cell lists the ones it supports).
        payload_kg: Lumped payload at the tcp, kg (>= 0).

    Returns:
        The composed :class:`Cell` (its ``mjcf`` compiles; keyframe ``home`` added).

    Raises:
        UnknownNameError: Unknown mount (the message lists the valid ones).
        CellError: Robot, tool or mount not supported by the cell, negative payload.
    """
    cspec = BARE if cell is None else cell
    spec_r = robot
    if not cspec.any_robot and spec_r.name not in cspec.robots:
        raise CellError(f"cell {cspec.name!r} is not built for robot {spec_r.name!r}; "
                        f"robots: {', '.join(cspec.robots)}")
    if mount not in MOUNTS:
        raise UnknownNameError("mount", str(mount), MOUNTS)
    if mount not in cspec.mounts:
        raise CellError(f"cell {cspec.name!r} does not support mount {mount!r}; "
                        f"mounts: {', '.join(cspec.mounts)}")
    tool_spec = cspec.default_tool if tool is CELL_DEFAULT else tool
    assert tool_spec is None or isinstance(tool_spec, ToolSpec)
    _check_tool(cspec, tool_spec)
    payload = _check_payload(payload_kg)

    rig = prepare_robot(spec_r, tool_spec, payload)
    layout = cspec.build(rig, mount)
    home_q = layout.home_q if layout.home_q is not None else rig.home_q
    add_home_keyframe(layout.world, rig, home_q)
    p = ROBOT_PREFIX
    return Cell(
        name=cspec.name, robot=spec_r, tool=tool_spec, mount=mount, mjcf=layout.world,
        joint_names=[f"{p}/{j}" for j in spec_r.joints],
        actuator_names=[f"{p}/a{i + 1}" for i in range(spec_r.n_joints)],
        tcp_site=f"{p}/tcp", frame0_site=f"{p}/frame0", flange_site=f"{p}/flange",
        seams=layout.seams, parts=layout.parts, slots=layout.slots, cameras=layout.cameras,
        world_from_frame0=layout.world_from_frame0,
        adhesion_actuator=suction_actuator_name(rig), home_q=np.asarray(home_q, float),
        start_q=layout.start_q, payload_kg=payload, tip_site=tip_site_name(rig),
        dims={k: float(v) for k, v in layout.dims.items()}, description=cspec.description,
        frictionloss=rig.statics.frictionloss.copy(),
        objects={name: tuple(g.full_identifier for g in geoms)
                 for name, geoms in layout.objects.items()},
        seam_objects=dict(layout.seam_objects), frames=dict(layout.frames),
        source=cspec.source, _rig=rig,
        rings={name: dict(geoms.params) for name, geoms in layout.objects.items()
               if isinstance(geoms, Ring)})


__all__ = ["BARE", "CELLS", "CELL_DEFAULT", "MOUNTS", "NO_TOOL", "Cell", "CellSpec", "Seam",
           "build_cell", "is_file_ref", "load_cell", "resolve_cell", "resolve_tool", "tool_from_ref"]
