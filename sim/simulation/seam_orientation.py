"""The torch frame a seam commands, as an orientation law for a Cartesian move along it.

At every point of a seam the torch frame follows from the seam's local frame (tangent, the
reference surface's normal) and its work and travel angles (:meth:`sim.cells.seam.Seam.
torch_rotation`). A move along a seam (a line, an arc, one leg of a polyline) takes that frame
at every point, not an interpolation between its ends: on an arc whose reference surface is
not the arc's plane, or on a full circle, the two differ.

Two things are kept from where the tool arrives:

* **the roll about the torch axis** (6-axis arms): the seam fixes the torch axis; the roll
  about it is a convention (:mod:`sim.cells.seam`), so the tool keeps the roll it arrives
  with, relative to the seam's frame, along the whole seam (and every leg of a polyline);
* **a small misalignment of the torch axis** at the start (a hand-typed approach pose a few
  hundredths of a degree off): it fades out over the start ramp with a quintic smoothstep,
  so the joints start without a jump. A misalignment of more than
  :data:`MAX_START_MISALIGNMENT_DEG` is an error: the previous phase must end in the seam's
  posture (``to_seam``, ``approach_mm``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planners.rotations import axis_angle_matrix, rotation_log

#: Largest angle between the arriving torch axis and the seam's commanded one at the start of
#: a seam move, deg (the start ramp corrects up to this much).
MAX_START_MISALIGNMENT_DEG = 2.0


def _smooth(x: NDArray[np.float64]) -> NDArray[np.float64]:
    from planners.profiles import quintic_smoothstep

    return quintic_smoothstep(x)[0]


def roll_about(R_from: NDArray[np.float64], R_to: NDArray[np.float64], column: int) -> float:
    """The rotation about tool axis ``column`` (0: x, 2: z) of frame ``R_from`` that brings it
    closest to ``R_to``, rad."""
    M = R_from.T @ R_to
    if column == 2:
        return float(np.arctan2(M[1, 0] - M[0, 1], M[0, 0] + M[1, 1]))
    return float(np.arctan2(M[2, 1] - M[1, 2], M[1, 1] + M[2, 2]))


class SeamOrientation:
    """The seam's torch frame along ``[s0, s1]`` of its arc length, in frame 0.

    Args:
        seam: The seam (world frame), :class:`sim.cells.seam.Seam`.
        to_frame0: Rotation from world to frame 0, (3, 3).
        s0, s1: The stretch of the seam the move covers, m.
        column: Tool-frame column along the torch axis (2: 6-axis arms; 0: the 5-axis family,
            whose roll the arm's plane fixes, so no roll is kept).
        roll: Roll about the torch axis kept along the move, rad (module docstring).
        start: The tool frame the move starts from (frame 0): its residual misalignment fades
            out over the first ``settle`` of ``u``. None: start on the seam's frame.
        settle: Share of the move (0..1) over which the start misalignment fades.
    """

    name = "seam"

    def __init__(self, seam: Any, to_frame0: ArrayLike, s0: float, s1: float, *,
                 column: int = 2, roll: float = 0.0, start: ArrayLike | None = None,
                 settle: float = 0.0) -> None:
        self.seam, self.s0, self.s1 = seam, float(s0), float(s1)
        self.to_frame0 = np.asarray(to_frame0, dtype=float)
        self.column = int(column)
        self.roll = float(roll)
        axis = np.zeros(3)
        axis[self.column] = 1.0
        self._roll = axis_angle_matrix(axis, float(roll)) if roll else np.eye(3)
        self._delta = np.zeros(3)
        self.settle = max(float(settle), 1e-9)
        # the torch frame on a line, where it does not change (a 5-axis arm's turns with the
        # point about J1)
        self._constant = None
        if getattr(seam, "kind", None) == "line" and getattr(seam, "tool_axis", 2) == 2:
            self._constant = self.to_frame0 @ seam.torch_rotation(self.s0) @ self._roll
        if start is not None:
            R0 = np.asarray(start, dtype=float)
            self._delta = rotation_log(self._frame(np.array([0.0]))[0].T @ R0)
        self.start = self.evaluate(np.array([0.0]))[0][0]
        self.end = self.evaluate(np.array([1.0]))[0][0]

    @property
    def start_misalignment_deg(self) -> float:
        """Angle between the arriving frame and the seam's at the start, deg."""
        return float(np.degrees(np.linalg.norm(self._delta)))

    def _frame(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        s = self.s0 + np.clip(u, 0.0, 1.0) * (self.s1 - self.s0)
        if self._constant is not None:  # a line's torch frame is the same all along it
            return np.broadcast_to(self._constant, u.shape + (3, 3)).copy()
        R = np.array([self.seam.torch_rotation(float(x)) for x in s.ravel()])
        return (self.to_frame0 @ R @ self._roll).reshape(u.shape + (3, 3))

    def _rotation(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        R = self._frame(u)
        if not np.linalg.norm(self._delta) > 1e-15:  # no start offset to fade (a denormal
            return R                                 # one has no direction to turn about)
        fade = 1.0 - _smooth(np.clip(u / self.settle, 0.0, 1.0))
        return R @ axis_angle_matrix(self._delta, fade * np.linalg.norm(self._delta))

    def evaluate(self, u: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(R, dR/du)`` at ``u`` (..., 3, 3); the derivative by central differences."""
        u = np.asarray(u, dtype=float)
        R = self._rotation(u)
        h = 1e-6
        dR = (self._rotation(u + h) - self._rotation(u - h)) / (2 * h)
        return R, dR


__all__ = ["MAX_START_MISALIGNMENT_DEG", "SeamOrientation", "roll_about"]
