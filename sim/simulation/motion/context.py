"""What Cartesian phases need from the cell and the robot: :class:`CartesianContext`.

Owns the robot's kinematics with its tool, the cell's seams, frames and home, and the frame
conversions into the robot's frame 0 (cell seams and objects are given in the world frame).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sim.errors import ScenarioError


@dataclass
class CartesianContext:
    """What Cartesian phases need from the cell and the robot.

    Attributes:
        kinematics: A :class:`sim.robots.kinematics.model.KinematicModel` of the robot with its tool
            (``fk(q)`` gives the tcp pose in frame 0; used by ``ik_path``).
        seams: Cell seams by name (world frame).
        world_from_frame0: Pose of frame 0 in the world, (4, 4).
        frames: Poses of the cell's objects in the world by name, (4, 4) each: scenario points
            may be given in them (``frame = "<object>"``).
        home_q: The cell's home configuration, rad (where a TP program starts).
        flange_to_tcp: The tcp in the flange frame, (4, 4) (a TP program's UT 0 poses are the
            flange's).
        robot: The robot's registry entry (its maker's joint convention, for TP CONFIG).
        mechanisms: The cell's turntables, positioners and tracks
            (:class:`sim.cells.mechanisms.PlacedMechanism`); their axes follow the robot's
            joints in the motion's joint vector (:mod:`sim.simulation.motion.axes`). Seams,
            frames and ``world_from_frame0`` above are at the mechanisms' home.
        seam_mechanism: The mechanism carrying each seam's object, by seam name.
        frame_mechanism: The mechanism carrying each object, by object name.
        robot_on: The mechanism (a track) carrying the robot's base, or None.
        moving: For a context posed at some axis values (:func:`~sim.simulation.motion.axes.posed`):
            the cell's own context (at home, with its mechanisms); None otherwise.
        partners: The cell's other robots' contexts (their kinematics, frame 0, home and the
            seams as their tools follow them), by name; their motion is planned with them.
        max_phase_s: The longest move a run of the cell can simulate, s
            (:data:`~sim.simulation.motion.checks.MAX_STEPS` steps of its timestep): a
            Cartesian move longer than that is refused before it is sampled.
    """

    kinematics: Any
    seams: dict[str, Any] = field(default_factory=dict)
    world_from_frame0: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    frames: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    home_q: NDArray[np.float64] | None = None
    flange_to_tcp: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    robot: Any = None
    mechanisms: tuple[Any, ...] = ()
    seam_mechanism: dict[str, str] = field(default_factory=dict)
    frame_mechanism: dict[str, str] = field(default_factory=dict)
    robot_on: str | None = None
    moving: Any = None
    partners: dict[str, CartesianContext] = field(default_factory=dict)
    max_phase_s: float = float("inf")

    @property
    def n_axes(self) -> int:
        """The external axes after the robot's joints in the joint vector."""
        return sum(pm.spec.n_axes for pm in self.mechanisms)

    def frame0_from(self, frame: str, label: str) -> NDArray[np.float64]:
        """Pose of a named frame in frame 0, (4, 4): ``frame0`` (the robot's), ``world`` or a
        cell object (:attr:`frames`: each object's pose in world).

        Raises:
            ScenarioError: Unknown frame (the message lists the valid ones).
        """
        if frame == "frame0":
            return np.eye(4)
        if frame == "world":
            return self.frame0_from_world
        if frame not in self.frames:
            from sim.errors import UnknownNameError

            raise ScenarioError(f"{label}.frame: "
                                f"{UnknownNameError('frame', frame, ['frame0', 'world', *self.frames])}")
        return self.frame0_from_world @ self.frames[frame]

    @property
    def frame0_from_world(self) -> NDArray[np.float64]:
        from sim.core.rotations import invert_transform

        return invert_transform(self.world_from_frame0)

    def to_frame0(self, p: ArrayLike) -> NDArray[np.float64]:
        T = self.frame0_from_world
        return T[:3, :3] @ np.asarray(p, dtype=float) + T[:3, 3]

    def rot_to_frame0(self, R: ArrayLike) -> NDArray[np.float64]:
        return self.frame0_from_world[:3, :3] @ np.asarray(R, dtype=float)
