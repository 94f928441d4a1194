"""A cell's other robots: :class:`PlacedRobot` (what a cell file's ``[[robots]]`` entry says)
and :class:`CellRobot` (one composed into the cell's world).

A cell's first robot is the scenario's (``[robot]``, prefix ``robot``); each other robot has
its own name, model, tool, base and home, and its own work in the scenario
(``[robots.<name>]``). Its MJCF names are ``<name>/<name in the robot's model>`` (``r2/j1``,
``r2/tool/nozzle``), its joints in the joint vector ``<name>_<joint>`` (``r2_j1``) after the
first robot's joints and the mechanisms' axes. It stands on the floor or hangs from the
ceiling (not on a track), carries no payload and no suction gripper.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from sim.cells.compose import RobotRig
    from sim.cells.toolspec import ToolSpec
    from sim.robots.spec import RobotSpec


@dataclass(frozen=True)
class PlacedRobot:
    """Another robot of a cell file (``[[robots]]``).

    Attributes:
        name: Its name in the cell (the prefix of its names).
        robot: Its registry entry.
        tool: Its tool, or None.
        base_pose: Its base frame in world (mount included), (4, 4).
        home_q: Its joints at the cell's home, rad (None: the robot's own home).
        index: Its index in the file's ``robots``.
    """

    name: str
    robot: RobotSpec
    tool: ToolSpec | None
    base_pose: NDArray[np.float64] = field(compare=False)
    home_q: NDArray[np.float64] | None = field(default=None, compare=False)
    index: int = 0

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Its joints' names in the compiled model (``<name>/j1``, ...)."""
        return tuple(f"{self.name}/{j}" for j in self.robot.joints)

    @property
    def actuator_names(self) -> tuple[str, ...]:
        """Its position actuators' names in the compiled model (``<name>/a1``, ...)."""
        return tuple(f"{self.name}/a{i + 1}" for i in range(self.robot.n_joints))

    @property
    def system_names(self) -> tuple[str, ...]:
        """Its joints' names in the joint vector, reports and ``[drives]`` (``<name>_j1``)."""
        return tuple(f"{self.name}_{j}" for j in self.robot.joints)


@dataclass
class CellRobot:
    """Another robot composed into a cell's world.

    Attributes:
        placed: What the cell file says of it.
        rig: Its model with its tool (:func:`sim.cells.compose.prepare_robot`, prefix its name).
        world_from_frame0: Its frame 0 in world, (4, 4).
        seams: The cell's seams as this robot's tool follows them (its tool's stand-off and
            approach axis), by name, world frame.
        home_q: Its joints at the cell's home, rad.
    """

    placed: PlacedRobot
    rig: RobotRig
    world_from_frame0: NDArray[np.float64]
    seams: dict[str, Any] = field(default_factory=dict)
    home_q: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    @property
    def name(self) -> str:
        return self.placed.name

    @property
    def robot(self) -> RobotSpec:
        return self.placed.robot

    @property
    def tool(self) -> ToolSpec | None:
        return self.placed.tool

    @property
    def tcp_site(self) -> str:
        return f"{self.name}/tcp"

    @property
    def frame0_site(self) -> str:
        return f"{self.name}/frame0"

    @property
    def flange_site(self) -> str:
        return f"{self.name}/flange"

    @property
    def tip_site(self) -> str | None:
        return None if self.tool is None else f"{self.name}/tool/tip"


__all__ = ["CellRobot", "PlacedRobot"]
