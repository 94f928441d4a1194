"""Cells layer: tools, seams and the welding and pick cells composed with ``dm_control.mjcf``
(robot + tool + fixtures + parts). May import: planners, :mod:`sim.errors`, :mod:`sim.core`,
:mod:`sim.robots`.

Public API::

    from sim.cells import CELLS, Cell, Seam, build_cell
    cell = build_cell(CELLS["weld_cylinder"], ROBOTS["robot_5r"], mount="floor")
    model = cell.compile()                      # mujoco.MjModel, keyframe "home"

Cells (:data:`CELLS`; each module's docstring gives its dimensions and the reasons for them):

===============  ======================  ===============  ================  =================
cell             robots                  default tool     tools allowed     mounts
===============  ======================  ===============  ================  =================
weld_cylinder    robot_5r                mig_torch_long   mig_torch(_long)  floor, ceiling
weld_table       lrmate100ib, 200ic5l    mig_torch        mig_torch(_long)  floor
pick             lrmate200ic5l           vacuum_gripper   vacuum_gripper    floor
(None: bare)     every robot             none             any, or none      floor, ceiling
===============  ======================  ===============  ================  =================

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

import mujoco
import numpy as np
from dm_control import mjcf
from numpy.typing import NDArray

from planners.registry import Registry
from sim.cells import bare, pick, weld_cylinder, weld_table
from sim.cells.compose import (
    ROBOT_PREFIX,
    Layout,
    RobotRig,
    add_home_keyframe,
    compile_model,
    prepare_robot,
    suction_actuator_name,
    tip_site_name,
)
from sim.cells.seam import Seam
from sim.cells.tools import TOOLS, ToolSpec
from sim.errors import CellError, UnknownNameError
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
    """

    name: str
    description: str
    robots: tuple[str, ...]
    default_tool: ToolSpec | None
    tools: tuple[ToolSpec, ...]
    mounts: tuple[str, ...]
    build: Callable[[RobotRig, str], Layout] = field(repr=False, compare=False)
    needs_tool: bool = True


_TORCHES = (TOOLS["mig_torch"], TOOLS["mig_torch_long"])

#: The shipped cells by name.
CELLS: Registry[CellSpec] = Registry("cell")
for _spec in (
    CellSpec("weld_cylinder",
             "5R welding of a large cylinder coaxial with J1 (seed 001); floor or ceiling",
             ("robot_5r",), TOOLS["mig_torch_long"], _TORCHES, ("floor", "ceiling"),
             weld_cylinder.build),
    CellSpec("weld_table", "welding table: a 1F fillet line and a 2F fillet arc",
             ("lrmate100ib", "lrmate200ic5l"), TOOLS["mig_torch"], _TORCHES, ("floor",),
             weld_table.build),
    CellSpec("pick", "vacuum pick-and-place of 4 boxes from an infeed table to a tray",
             ("lrmate200ic5l",), TOOLS["vacuum_gripper"], (TOOLS["vacuum_gripper"],), ("floor",),
             pick.build),
):
    CELLS.add(_spec.name, _spec)

#: The bare scene's entry (``cell=None``): every robot, any tool or none, both mounts.
BARE = CellSpec("bare", "the robot alone: floor, lights, cameras", tuple(ROBOTS), None,
                tuple(TOOLS.values()), MOUNTS, bare.build, needs_tool=False)


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


def resolve_tool(cell: CellSpec, name: str | None) -> ToolSpec | None:
    """The tool a cell gets for a requested tool name.

    Args:
        cell: The cell (:data:`BARE` for the robot alone).
        name: A tool name, ``None`` for the cell's default tool, or ``"none"`` for no tool.

    Raises:
        UnknownNameError: Unknown tool (the message lists the tools).
        CellError: The cell does not take that tool (the message lists the ones it takes).
    """
    if name is None:
        return cell.default_tool
    if name == NO_TOOL:
        return None
    tool = TOOLS.get(name)
    _check_tool(cell, tool)
    return tool


def _check_tool(cell: CellSpec, tool: ToolSpec | None) -> None:
    if tool is None:
        if cell.needs_tool:
            raise CellError(f"cell {cell.name!r} needs a tool; tools: "
                            f"{', '.join(t.name for t in cell.tools)}")
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
    if spec_r.name not in cspec.robots:
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
        seam_objects=dict(layout.seam_objects),
        _rig=rig)


__all__ = ["BARE", "CELLS", "CELL_DEFAULT", "MOUNTS", "NO_TOOL", "Cell", "CellSpec", "Seam",
           "build_cell", "resolve_tool"]
