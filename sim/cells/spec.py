"""What a cell is: :class:`CellSpec` (a registry entry: the robots, tools and mounts a cell
takes and its builder) and :class:`Cell` (a cell composed for one robot, not yet compiled; the
names in it are listed in :mod:`sim.cells`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from sim.cells.compose import Layout, RobotRig, compile_model
from sim.cells.mechanisms import PlacedMechanism
from sim.cells.partners import CellRobot, PlacedRobot
from sim.cells.seam import Seam
from sim.cells.tools import ToolSpec
from sim.robots.kinematics.model import KinematicModel
from sim.robots.registry import RobotSpec

if TYPE_CHECKING:  # for the annotations only: compose imports them where a model is made
    import mujoco
    from dm_control import mjcf

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
        mechanisms: Its turntables, positioners and tracks (their axes are driven joints after
            the robot's).
        partners: Its other robots (:class:`sim.cells.partners.PlacedRobot`; their joints
            follow the axes).
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
    mechanisms: tuple[PlacedMechanism, ...] = ()
    partners: tuple[PlacedRobot, ...] = ()

    @property
    def axis_names(self) -> tuple[str, ...]:
        """The mechanisms' axes (``<mechanism>_<axis>``), in order."""
        return tuple(n for pm in self.mechanisms for n in pm.joint_names)


@dataclass
class Cell:
    """A composed cell, not yet compiled (see the package docstring for the names).

    Attributes:
        name: Cell name (``"bare"`` for ``cell=None``).
        robot: The robot.
        tool: The tool, or None.
        mount: ``"floor"`` or ``"ceiling"``.
        mjcf: The composed world (``dm_control`` model).
        joint_names: The driven joints: the robot's ``robot/j1..``, then the mechanisms' axes
            (``positioner_tilt``, ...), in order.
        actuator_names: Their position actuators (``robot/a1..``, then the axes' names).
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
        frictionloss: Coulomb friction of each driven joint, N m (N on a linear axis), (n,),
            applied by the friction actuators ``robot/friction_jN`` (:mod:`sim.cells.compose`)
            and ``friction_<axis>`` (:mod:`sim.cells.mechanisms`).
        objects: Geom names of each cell object made of several geoms (a ring of staves).
        seam_objects: Objects each seam joins (its workpieces), by seam name.
        frames: Pose in world of each cell object scenario points may be given in, (4, 4).
        source: The cell file the cell came from (None: built in Python).
        rings: Parameters of each object that is a ring of staves (:class:`compose.Ring`).
        mechanisms: The cell's turntables, positioners and tracks (their axes follow the
            robot's joints in :attr:`joint_names`).
        partners: The cell's other robots (:class:`sim.cells.partners.CellRobot`; their joints
            follow the axes in :attr:`joint_names`, ``<name>/j1``, ...).
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
    mechanisms: tuple[PlacedMechanism, ...] = ()
    partners: tuple[CellRobot, ...] = ()
    _rig: RobotRig | None = field(default=None, repr=False)

    @property
    def axis_names(self) -> tuple[str, ...]:
        """The mechanisms' axes, in order (the driven joints after the robot's)."""
        return tuple(n for pm in self.mechanisms for n in pm.joint_names)

    @property
    def axis_home(self) -> NDArray[np.float64]:
        """The mechanisms' axis values at home, rad or m, in :attr:`axis_names` order."""
        return np.concatenate([pm.home for pm in self.mechanisms]) if self.mechanisms \
            else np.zeros(0)

    def compile(self) -> mujoco.MjModel:
        """Compile the composed world (``mujoco.MjModel`` with keyframe ``home``)."""
        return compile_model(self.mjcf)

    def kinematics(self) -> KinematicModel:
        """Closed-form kinematic model whose tool frame is this cell's tcp (the tool tip).

        Poses are in frame 0: map world targets with ``inv(world_from_frame0)``.
        """
        assert self._rig is not None
        return self._rig.kinematics()


__all__ = ["MOUNTS", "NO_TOOL", "Cell", "CellSpec"]
