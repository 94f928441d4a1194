"""Generated coordinated welds on a MotoPos D500 (issue 28's first acceptance test): a case
drawn by hypothesis, written as a user writes it (a cell file and a scenario), run, and judged
in the part's frame by :func:`support.axes_cells.judge_part_frame_weld`.

A case: the positioner placed in front of the LR Mate 200iC/5L (``x`` 600-760 mm, ``y``
+-150 mm, turned +-30 deg), a steel plate on its faceplate and on it a workpiece, off the
faceplate's centre:

* ``arc``: a pipe (cylinder, radius 40-75 mm, 60-140 mm long) and the fillet round its foot,
  an arc of 60-120 deg, counter-clockwise or clockwise seen from above the plate, the torch
  leaning outwards (``lean`` chosen so: seen from the torch the pipe is on the other side);
* ``line``: a block (box) and the fillet along the foot of one of its long sides.

The reference surface is the plate (``normal = [0, 0, 1]`` in the workpiece's frame), work
angle 35-60 deg, travel angle -10..10 deg, speed 8-20 mm/s. The scenario: a joint move to a
ready pose, a joint move 30 mm back from the seam's start with ``downhand = true``, a straight
touch onto the start, the weld with ``downhand = true`` and the arc on.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st

from support.axes_cells import (
    D500_FILE,
    HOME_DEG,
    PartFrameWeld,
    Solid,
    judge_part_frame_weld,
    mechanism_file,
    part_in_world,
    pose,
    positioner_cell,
)
from support.scenarios import joint_phase, scenario_text
from support.seam_oracle import SeamGeom

#: The plate on the faceplate (mm): full extents and its centre's height on the mount.
PLATE_MM = (320.0, 320.0, 12.0)
READY_DEG = (0.0, 8.0, -30.0, 0.0, -60.0, 0.0)
D500 = mechanism_file(D500_FILE)


@dataclass(frozen=True)
class WeldCase:
    """One generated coordinated weld (module docstring); lengths mm, angles deg."""

    pos: tuple[float, float]
    yaw: float
    kind: str
    size: tuple[float, float]       # arc: radius, length; line: side length, height
    offset: tuple[float, float]     # the workpiece's centre on the plate
    start_deg: float                # arc: first point's angle; line: which side (0..3 x 90)
    sweep: float                    # arc: sweep (negative: clockwise); line: seam length
    work: float
    travel: float
    speed: float
    shift_mm: float = 0.0           # a planted fault: the judged seam moved this far in x

    def __str__(self) -> str:
        return (f"{self.kind} at pos {self.pos} yaw {self.yaw:.1f}, size {self.size}, offset "
                f"{self.offset}, start {self.start_deg:.1f}, sweep {self.sweep:.1f}, work "
                f"{self.work:.1f}, travel {self.travel:.1f}, {self.speed:.1f} mm/s")

    # ---------------------------------------------------------------- geometry
    def solids(self) -> dict[str, Solid]:
        """The plate and the workpiece in the mount frame."""
        plate = Solid("box", (0.0, 0.0, PLATE_MM[2] / 2), size_mm=PLATE_MM)
        a, h = self.size
        centre = (self.offset[0], self.offset[1], PLATE_MM[2] + h / 2)
        if self.kind == "arc":
            work = Solid("cylinder", centre, (self.start_deg, 0.0, 0.0), radius_mm=a,
                         length_mm=h)
        else:
            work = Solid("box", centre, (self.start_deg, 0.0, 0.0), size_mm=(a, a, h))
        return {"plate": plate, "work": work}

    def seam_points_mm(self) -> list[list[float]]:
        """The seam's points in the workpiece's frame (its z up from the plate)."""
        a, h = self.size
        if self.kind == "arc":
            ang = np.radians([0.0, self.sweep / 2, self.sweep])
            return [[a * math.cos(x), a * math.sin(x), -h / 2] for x in ang]
        half = self.sweep / 2
        return [[-half, -a / 2, -h / 2], [half, -a / 2, -h / 2]]

    def lean(self) -> str:
        """The side away from the workpiece: e = side (n x t) must point out of it. Line along
        +x on the side y = -a/2: n x t = +y (inwards): right. Arc counter-clockwise: n x t
        points to the axis: right; clockwise: left."""
        return "left" if self.kind == "arc" and self.sweep < 0 else "right"

    def cell_text(self) -> str:
        s = self.solids()
        objects = [dict(name="plate", role="workpiece", on="positioner", **s["plate"].fields()),
                   dict(name="work", role="workpiece", on="positioner", **s["work"].fields())]
        seam = dict(name="seam", object="work", kind=self.kind, points_mm=self.seam_points_mm(),
                    normal=[0, 0, 1], work_angle_deg=self.work, travel_angle_deg=self.travel,
                    lean=self.lean(), joins=["plate"])
        return positioner_cell((self.pos[0], self.pos[1], 0.0), self.yaw, objects, [seam])

    def scenario_text(self) -> str:
        weld_kind = "circular" if self.kind == "arc" else "linear"
        phases = [
            joint_phase([HOME_DEG, READY_DEG], name="ready", time_s=[0.0, 1.0]),
            dict(name="to_seam", planner="434", durations_s=[3.0], to_seam="seam",
                 approach_mm=30.0, downhand=True),
            dict(name="touch", kind="linear", to_seam="seam", orientation="seam",
                 speed_mm_s=20.0),
            dict(name="weld", kind=weld_kind, seam="seam", orientation="seam",
                 speed_mm_s=self.speed, downhand=True)]
        return scenario_text("lrmate200ic5l", phases, name="coordinated_weld",
                             cell="cell.toml", tool="mig_torch",
                             actions=[dict(action="arc_on", phase="weld"),
                                      dict(action="arc_off", phase="weld", at="end")])

    def write(self, folder: Path) -> Path:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "cell.toml").write_text(self.cell_text())
        path = folder / "weld.toml"
        path.write_text(self.scenario_text())
        return path

    # ---------------------------------------------------------------- the oracle's view
    def part_local(self) -> np.ndarray:
        """The workpiece's frame in the mount frame (4, 4), m."""
        w = self.solids()["work"]
        return pose(w.pos_mm, w.euler_zyx_deg)

    def base(self) -> np.ndarray:
        """The positioner's base in the world (4, 4), m."""
        return pose((self.pos[0], self.pos[1], 0.0), (self.yaw, 0.0, 0.0))

    def seam_geom(self) -> SeamGeom:
        """The seam in the workpiece's frame, m (moved ``shift_mm`` in x: a planted fault)."""
        pts = np.asarray(self.seam_points_mm()) * 1e-3 + np.array([self.shift_mm * 1e-3, 0, 0])
        return SeamGeom(self.kind, pts, np.array([0.0, 0.0, 1.0]), self.work, self.travel,
                        side=1 if self.lean() == "left" else -1)

    def shifted(self, mm: float) -> WeldCase:
        return replace(self, shift_mm=mm)


def judge_coordinated(case: WeldCase, arrays: Any, weld: Mapping[str, float],
                      axes_offset_deg: float = 0.0, pos_tol_m: float = 0.1e-3,
                      speed_tol: float = 0.01, angle_tol_deg: float = 0.5) -> PartFrameWeld:
    """The part-frame oracle on a run of ``case`` (``weld``: the weld phase's ``t0``, ``t1``):
    the part's frame from the D500's forward kinematics (its file's numbers) at the RECORDED
    axis values (shifted by ``axes_offset_deg``: a planted fault)."""
    q_axes = np.asarray(arrays["q"])[:, 6:] + np.radians(axes_offset_deg)
    T = part_in_world(D500, case.base(), case.part_local(), q_axes)
    return judge_part_frame_weld(case.seam_geom(), arrays["t"], arrays["tcp_pos"],
                                 arrays["tcp_quat"], T, weld["t0"], weld["t1"],
                                 case.speed * 1e-3, pos_tol_m=pos_tol_m,
                                 angle_tol_deg=angle_tol_deg, speed_tol=speed_tol)


@st.composite
def weld_cases(draw: Any, kinds: tuple[str, ...] = ("arc", "line")) -> WeldCase:
    """A generated :class:`WeldCase` (module docstring)."""
    fl = lambda lo, hi: draw(st.floats(lo, hi, allow_nan=False))  # noqa: E731
    kind = draw(st.sampled_from(kinds))
    if kind == "arc":
        size = (fl(40.0, 75.0), fl(60.0, 140.0))
        sweep = fl(60.0, 120.0) * draw(st.sampled_from((1.0, -1.0)))
        start = fl(-180.0, 180.0)
        reach = size[0]
    else:
        size = (fl(90.0, 150.0), fl(40.0, 100.0))
        sweep = fl(50.0, size[0] - 20.0)
        start = 90.0 * draw(st.integers(0, 3))
        reach = size[0] / 2 * math.sqrt(2)
    room = max(0.0, PLATE_MM[0] / 2 - reach - 20.0)
    off = min(40.0, room)
    return WeldCase(pos=(fl(520.0, 660.0), fl(-120.0, 120.0)), yaw=fl(-30.0, 30.0), kind=kind,
                    size=size, offset=(fl(-off, off), fl(-off, off)), start_deg=start,
                    sweep=sweep, work=fl(35.0, 60.0), travel=fl(-10.0, 10.0),
                    speed=fl(8.0, 20.0))


__all__ = ["D500", "PLATE_MM", "READY_DEG", "WeldCase", "judge_coordinated", "weld_cases"]
