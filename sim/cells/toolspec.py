"""What an end-of-arm tool is: :class:`ToolSpec`, and the names and contact bits a tool model
and a cell agree on (the tip site, the cup body, the suction actuator, the contact bit masks).

The tools themselves are data (tool files, :mod:`sim.cells.toolfile`); the shipped ones are
listed in :mod:`sim.cells.tools`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sim.errors import CellsimError

#: Contact bit masks used across cellsim's cells (MuJoCo ``contype``/``conaffinity``): a contact
#: is generated when ``(contype1 & conaffinity2) | (contype2 & conaffinity1)`` is non-zero.
#: Robot links keep MuJoCo's default (1, 1) and so touch none of these.
CONTACT_FIXTURE = 2  #: static cell geometry (floor, tables, trays): touches parts only
CONTACT_CUP = 4  #: suction-cup lip: touches parts only
CONTACT_PART_TYPE = 2  #: parts: contype
CONTACT_PART_AFFINITY = 2 | 4  #: parts: conaffinity (fixtures, other parts, the cup)

#: Standard gravity, m/s^2, and the factor of its weight a suction cup's holding force must
#: give a part (the margin for the cycle's accelerations and a cup that does not seal
#: perfectly): a suction gripper's rating is its force over twice a part's weight (the
#: vacuum gripper: 40 N, 2.04 kg).
GRAVITY = 9.80665
SUCTION_SAFETY = 2.0
#: Name of the adhesion actuator, the cup body and the tip site inside a tool model.
TIP_SITE = "tip"
CUP_BODY = "cup"
SUCTION_ACTUATOR = "suction"

#: Time constant of the vacuum in the cup, s: suction builds and decays as a first-order lag
#: of the valve command (about 50 ms for a small cup on an ejector); the scenario's 0.3 s dwells
#: leave it at 99.8 %. A step in the adhesion force instead struck the held part against the lip
#: and made the torque peak depend on the timestep.
VACUUM_TIME_CONSTANT_S = 0.05


@dataclass(frozen=True)
class ToolSpec:
    """Static description of one end-of-arm tool.

    Attributes:
        name: Registry name (``--tool`` on the command line, ``tool`` in scenarios).
        description: One line for ``cellsim list``.
        mass_kg: Total mass, kg (the geoms' masses add up to it, see the module docstring).
        length_m: Distance from the flange face to the tool centre point along the flange's
            approach axis, m. The tip lies on that axis (straight tool).
        kind: ``"torch"`` or ``"gripper"``.
        suction_gain_n: Adhesion force at full suction (``ctrl = 1``), N; 0 for a torch.
        work_geoms: The tool's geoms that touch the work by design (names inside the tool
            model): a torch's welding wire, which may touch the seam's workpiece while the arc
            is on; a gripper's cup lip, which may touch the part it picks. Every other geom of
            the tool (nozzle, torch body, ...) must never touch anything
            (:mod:`sim.simulation.collisions`).
        tcp_in_tool: Pose of the tool centre point in the tool frame, (4, 4) as nested tuples,
            for a tool whose tcp is off the flange axis or turned (a tool file's ``tcp_mm`` and
            ``tcp_euler_zyx_deg``); None for a straight tool (tcp at ``(0, 0, length_m)``,
            oriented as the tool frame).
        stickout_m: Nominal wire stick-out of a torch (contact tip to wire tip), m.
        touch_depth_m: How far the wire tip of a torch may press into a workpiece beyond the
            wire's radius with the arc off (touch sensing, the tip set on the root), m
            (:mod:`sim.simulation.collisions`).
        max_payload_kg: The heaviest mass the tool is rated to hold (a gripper's part and
            the scenario's payload), kg; None for a tool that holds nothing (a torch). The
            verdict checks it (:mod:`sim.analysis.verdict`, ``tool_payload``).
        source: The tool file the tool was read from (:mod:`sim.cells.toolfile`).
        shipped: A tool cellsim ships (``models/tools``, :data:`sim.cells.tools.TOOLS`), not a
            user's tool file: a cell takes only the shipped tools it names.
        builder: Builds the tool's MJCF (:class:`sim.cells.toolfile.ToolBuilder`).
    """

    name: str
    description: str
    mass_kg: float
    length_m: float
    kind: str = "torch"
    suction_gain_n: float = 0.0
    work_geoms: tuple[str, ...] = ()
    tcp_in_tool: tuple[tuple[float, ...], ...] | None = None
    stickout_m: float = 0.015
    touch_depth_m: float = 0.0005
    max_payload_kg: float | None = None
    source: Path | None = None
    shipped: bool = False
    builder: Callable[[], object] | None = field(default=None, repr=False, compare=False)

    @property
    def straight(self) -> bool:
        """The tcp lies on the flange axis, oriented as the tool frame."""
        return self.tcp_in_tool is None

    def standoff(self, ctwd: float) -> float:
        """The stand-off of a contact-tip-to-work distance ``ctwd`` (m) with this torch: ``ctwd``
        less its nominal stick-out, m (how far its tool point keeps back from the seam,
        :mod:`sim.cells.seam`).

        Raises:
            CellsimError: ``ctwd`` is shorter than the nominal stick-out: the modelled wire,
                that long, would reach into the work (the message names no key: callers add it).
        """
        if ctwd < self.stickout_m - 1e-12:
            raise CellsimError(f"{ctwd * 1e3:g} mm is shorter than the nominal stick-out of tool "
                               f"{self.name!r}, {self.stickout_m * 1e3:g} mm: its wire would reach "
                               f"{(self.stickout_m - ctwd) * 1e3:g} mm into the work")
        return ctwd - self.stickout_m

    def tcp_pose(self) -> np.ndarray:
        """Pose of the tcp in the tool frame, (4, 4), m."""
        if self.tcp_in_tool is None:
            T = np.eye(4)
            T[2, 3] = self.length_m
            return T
        return np.array(self.tcp_in_tool, dtype=float)


__all__ = ["CONTACT_CUP", "CONTACT_FIXTURE", "CONTACT_PART_AFFINITY", "CONTACT_PART_TYPE",
           "CUP_BODY", "GRAVITY", "SUCTION_ACTUATOR", "SUCTION_SAFETY", "TIP_SITE",
           "VACUUM_TIME_CONSTANT_S", "ToolSpec"]
