"""What a mechanism is: :class:`MechanismSpec` (a turntable, a tilt-rotate positioner, a linear
track), a serial chain of :class:`AxisSpec` with the moving :class:`LinkSpec` each carries, and
the :class:`Shape` solids it is drawn and checked with.

A mechanism is an external axis group of a cell (FANUC's extended axes, ``E1``, ``E2``): it has
the drives, limits and inertias of a robot's joints but no arm kinematics. Its chain is simple
on purpose: each axis's link frame is its parent's frame translated by ``AxisSpec.pos`` (no
rotation at zero), turned (revolute) or moved (prismatic) along ``AxisSpec.axis``. The mount
(:attr:`MechanismSpec.mount`) is where a workpiece (positioner, turntable: the faceplate) or a
robot's base (track: the carriage) is attached, in the last link's frame.

Units are SI: m, rad, kg, kg m^2; prismatic axes' positions in m, speeds in m/s, their drive's
``gear_ratio`` in motor radians per metre of travel and their "torque" a force in N.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from sim.robots.drive import Drive

MECHANISM_KINDS = ("turntable", "positioner", "track")


def _arr(*v: float) -> NDArray[np.float64]:
    return np.array(v, dtype=float)


@dataclass(frozen=True, eq=False)
class Shape:
    """A solid of a mechanism (drawn, and checked for collisions).

    Attributes:
        kind: ``"box"`` or ``"cylinder"``.
        size: Box: half sizes (3,); cylinder: ``(radius, half length, 0)``; m. A cylinder's
            axis is its frame's z axis.
        pos: Centre in the link's (or base's) frame, m, (3,).
        rot: Orientation in that frame, (3, 3).
        rgba: Colour.
        name: Name (unique within the mechanism).
    """

    kind: Literal["box", "cylinder"]
    size: NDArray[np.float64]
    pos: NDArray[np.float64] = field(default_factory=lambda: _arr(0, 0, 0))
    rot: NDArray[np.float64] = field(default_factory=lambda: np.eye(3))
    rgba: tuple[float, float, float, float] = (0.95, 0.6, 0.1, 1.0)
    name: str = ""


@dataclass(frozen=True, eq=False)
class LinkSpec:
    """The rigid body an axis moves (its own mass only: what is mounted on it is the cell's).

    Attributes:
        mass: kg (> 0).
        com: Centre of mass in the link frame, m, (3,).
        inertia: Principal moments at the centre of mass along the link frame's axes,
            kg m^2, (3,).
        shapes: Its solids, in the link frame.
    """

    mass: float
    com: NDArray[np.float64]
    inertia: NDArray[np.float64]
    shapes: tuple[Shape, ...] = ()


@dataclass(frozen=True, eq=False)
class AxisSpec:
    """One axis of a mechanism.

    Attributes:
        name: Axis name (``tilt``, ``rotate``, ``travel``), unique within the mechanism.
        kind: ``"revolute"`` or ``"prismatic"``.
        pos: Origin of the axis (and of its link frame) in the parent frame at zero, m, (3,).
        axis: Unit direction of the axis in the parent frame, (3,).
        range: ``(lower, upper)``, rad or m.
        max_speed: rad/s or m/s.
        max_accel: rad/s^2 or m/s^2.
        drive: Its drive (motor side; prismatic: ``gear_ratio`` in motor rad per m).
        link: The body the axis moves.
        friction: Coulomb friction at the axis, N m or N.
        damping: Viscous damping at the axis, N m s/rad or N s/m.
        maker_name: The controller's name of the axis (``E1``, ``E2``, ...), set by the cell.
    """

    name: str
    kind: Literal["revolute", "prismatic"]
    pos: NDArray[np.float64]
    axis: NDArray[np.float64]
    range: tuple[float, float]
    max_speed: float
    max_accel: float
    drive: Drive
    link: LinkSpec
    friction: float = 0.0
    damping: float = 0.0


@dataclass(frozen=True, eq=False)
class MechanismSpec:
    """A turntable, positioner or track: a serial chain of axes on a fixed base.

    Attributes:
        name: Registry name (``motopos_d500``), or the file's stem.
        title: Human-readable name.
        kind: One of :data:`MECHANISM_KINDS`.
        axes: The chain, base first.
        base_shapes: Solids fixed to the base, in the base frame.
        mount: Pose of the mount (faceplate, carriage top) in the last link's frame, (4, 4).
        payload_kg: Rated payload on the mount, kg.
        description: One line for ``cellsim list``.
        source: The mechanism file.
    """

    name: str
    title: str
    kind: Literal["turntable", "positioner", "track"]
    axes: tuple[AxisSpec, ...]
    base_shapes: tuple[Shape, ...] = ()
    mount: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    payload_kg: float = 0.0
    description: str = ""
    source: Path | None = None

    @property
    def n_axes(self) -> int:
        return len(self.axes)

    @property
    def axis_names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.axes)


__all__ = ["MECHANISM_KINDS", "AxisSpec", "LinkSpec", "MechanismSpec", "Shape"]
